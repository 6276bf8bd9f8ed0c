//! The test vectors of docs/board-protocol.md are plm-core's own frames:
//! each row of the document's vector table is built here with plm-core's
//! encoders and must be the same bytes, so that the document cannot
//! drift from the code. When a layout changes, this test fails and prints
//! the whole table as it must now read, to paste into the document.

use plm_core::app::rfu::{self, image, Header, RfuReason, RfuState, Status};
use plm_core::app::service::{Discovered, Release, Service, SlotRead};
use plm_core::app::{Address, AppFrame, ErrorCode, FrameType, LineFrame, Message};

const SPEC: &str = include_str!("../../../docs/board-protocol.md");
const BEGIN: &str = "<!-- vectors: begin -->";
const END: &str = "<!-- vectors: end -->";

/// The board every vector is for or from.
const BOARD: Address = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x2A]);
/// The concentrator's own address on the line.
const CONCENTRATOR: Address = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x00]);
const RELEASE: Release = Release { major: 1, minor: 4 };
const STACK: Release = Release { major: 2, minor: 0 };
const CAMPAIGN: u8 = 9;

/// The image of the RFU vectors: 200 bytes, 3 segments (96, 96, 8).
fn image_200() -> Vec<u8> {
    (0..200u32).map(|i| ((i * 7 + 3) & 0xFF) as u8).collect()
}

fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn usart(m: Message) -> Vec<u8> {
    m.to(BOARD).emit().unwrap()
}

/// Every vector: its name and its bytes, from plm-core.
fn vectors() -> Vec<(&'static str, Vec<u8>)> {
    let image = image_200();
    let header = Header::of(CAMPAIGN, Release { major: 1, minor: 5 }, &image);
    let service = |s: Service| usart(Message::Service(s));
    let ack = |code: u8| {
        usart(Message::Ack {
            frame_type: FrameType::Service,
            echo: code,
        })
    };
    let mut bitmap = vec![0u8; rfu::BITMAP_LEN];
    bitmap[0] = 0b011;
    let status = Status {
        campaign: CAMPAIGN,
        state: RfuState::Receiving.byte(),
        reason: RfuReason::None.byte(),
        received: 2,
        bitmap,
    };
    let discover = Message::Service(Service::Discover {
        session: 7,
        window: 2,
    });
    let reply = Message::Service(Service::DiscoverReply(Discovered {
        firmware: RELEASE,
        stack: STACK,
        snr: 22,
    }));
    let mut sealed = image.clone();
    sealed.resize(image::IMAGE_MIN, 0xFF);
    image::seal(&mut sealed, Release { major: 1, minor: 5 });
    vec![
        (
            "crc16-check",
            plm_core::app::crc::crc16(b"123456789")
                .to_be_bytes()
                .to_vec(),
        ),
        (
            "crc32-check",
            rfu::image_crc(b"123456789").to_be_bytes().to_vec(),
        ),
        ("fw-rel-get", service(Service::FwRelGet)),
        (
            "fw-rel",
            service(Service::FwRel {
                firmware: RELEASE,
                stack: STACK,
            }),
        ),
        (
            "malformed",
            service(Service::Raw {
                command: 0x06,
                data: vec![0],
            }),
        ),
        ("error", usart(Message::Error(ErrorCode::SERVICE_CMD_ERROR))),
        (
            "discover-all",
            discover.broadcast(Address::BROADCAST).emit().unwrap(),
        ),
        (
            "discover-one",
            service(Service::Discover {
                session: 7,
                window: 1,
            }),
        ),
        ("discover-reply", usart(reply.clone())),
        ("discover-ack", ack(0x0b)),
        (
            "line-discover-reply",
            LineFrame::from_app(&reply.to(CONCENTRATOR), BOARD).emit(),
        ),
        (
            "read-in-slots",
            Message::Service(Service::ReadInSlots(SlotRead {
                slot_ms: 50,
                param: 0x0A,
                first_ms: 20,
                addresses: vec![BOARD],
            }))
            .broadcast(Address::BROADCAST)
            .emit()
            .unwrap(),
        ),
        ("image-crc32", header.crc.to_be_bytes().to_vec()),
        ("rfu-header", service(Service::RfuHeader(header))),
        ("rfu-header-ack", ack(0x0c)),
        (
            "rfu-data-2",
            service(Service::RfuData {
                campaign: CAMPAIGN,
                segment: 2,
                data: rfu::segment_of(&image, 2).to_vec(),
            }),
        ),
        (
            "rfu-status-get",
            service(Service::RfuStatusGet { campaign: CAMPAIGN }),
        ),
        ("rfu-status", service(Service::RfuStatus(status))),
        (
            "rfu-swap",
            service(Service::RfuSwap {
                campaign: CAMPAIGN,
                crc: header.crc,
            }),
        ),
        ("rfu-swap-ack", ack(0x0e)),
        (
            "rfu-abort",
            service(Service::RfuAbort { campaign: CAMPAIGN }),
        ),
        ("rfu-abort-ack", ack(rfu::RFU_ABORT)),
        (
            "descriptor",
            sealed[image::DESCRIPTOR..image::DESCRIPTOR + image::DESCRIPTOR_LEN].to_vec(),
        ),
    ]
}

/// The table as the document must show it.
fn table() -> String {
    let mut t = String::from("| vector | bytes (hex) |\n| --- | --- |\n");
    for (name, bytes) in vectors() {
        t.push_str(&format!("| `{name}` | `{}` |\n", hex(&bytes)));
    }
    t
}

#[test]
fn the_documents_vectors_are_plm_cores_bytes() {
    let start = SPEC.find(BEGIN).expect("the vector table's begin mark") + BEGIN.len();
    let end = SPEC.find(END).expect("the vector table's end mark");
    let written = SPEC[start..end].trim();
    let want = table();
    assert!(
        written == want.trim(),
        "docs/board-protocol.md's vectors are not plm-core's bytes; the table must read:\n\n{want}"
    );
}

/// Every vector the text names, "(vector `a`)" or "(vectors `a`,
/// `b`)", is in the table, and every vector is named.
#[test]
fn every_vector_named_in_the_text_exists() {
    let names: Vec<&str> = vectors().iter().map(|v| v.0).collect();
    let text = SPEC.replace('\n', " ");
    let mut named = Vec::new();
    for part in text.split("(vector").skip(1) {
        let inside = part.split(')').next().unwrap();
        for name in inside.split('`').skip(1).step_by(2) {
            assert!(
                names.contains(&name),
                "no vector `{name}`: (vector{inside})"
            );
            named.push(name.to_string());
        }
    }
    let unnamed: Vec<&&str> = names
        .iter()
        .filter(|n| !named.iter().any(|m| m == **n))
        .collect();
    assert!(
        unnamed.is_empty(),
        "vectors the text never names: {unnamed:?}"
    );
}

/// The USART frames read back as the message they were made from, so the
/// table is also what a board must parse.
#[test]
fn the_usart_vectors_parse_back() {
    for (name, bytes) in vectors() {
        if bytes.len() < 10 || name.starts_with("line-") || name == "descriptor" {
            continue;
        }
        let frame = AppFrame::parse(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        Message::of(&frame).unwrap_or_else(|e| {
            assert_eq!(name, "malformed", "{name}: {e}");
            Message::Ping
        });
    }
}

/// Every link into protocol-notes.md names one of its headings (GitHub's
/// anchors), so that a renamed section does not leave a dead link here.
#[test]
fn the_links_into_the_protocol_notes_resolve() {
    let notes = include_str!("../../../docs/protocol-notes.md");
    let mut fenced = false;
    let mut anchors = Vec::new();
    for line in notes.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        }
        let level = line.bytes().take_while(|&b| b == b'#').count();
        if !fenced && level > 0 && line[level..].starts_with(' ') {
            let slug: String = line[level..]
                .trim()
                .to_lowercase()
                .chars()
                .filter(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | ' '))
                .map(|c| if c == ' ' { '-' } else { c })
                .collect();
            anchors.push(slug);
        }
    }
    let links: Vec<&str> = SPEC
        .split("protocol-notes.md#")
        .skip(1)
        .map(|s| s.split(')').next().unwrap())
        .collect();
    assert!(links.len() >= 5, "{links:?}");
    for link in links {
        assert!(
            anchors.iter().any(|a| a == link),
            "docs/board-protocol.md links to protocol-notes.md#{link}, which is no heading"
        );
    }
}
