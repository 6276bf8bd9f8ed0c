//! Golden vectors of the STEVAL-IHP007V1 application frames (seed 004:
//! UM 4.6, Appendix A, Appendix C): tests/vectors/steval_app.jsonl, written
//! by tests/vectors/make_steval.py from the seed's buffer[] listings, with
//! frames built independently of plm-core. Each vector is read as the
//! typed message below, emitted back to the same bytes, and decoded by
//! `decode::app` as the seed names it.

use plm_core::app::crc::{crc16, SEED_TABLE_TYPOS};
use plm_core::app::hid::{self, Hid};
use plm_core::app::rfu;
use plm_core::app::service::{
    self, Answer, Clock, Discovered, Release, Service, SlotFrame, SlotRead,
};
use plm_core::app::{Address, AppFrame, ErrorCode, FrameType, Message};
use plm_core::decode::app::decode_usart;
use serde_json::Value;

const VECTORS: &str = include_str!("../../../tests/vectors/steval_app.jsonl");

/// The board address every vector uses.
const ADDR: Address = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x2A]);

/// Appendix C, bit by bit: X^16 + X^15 + X^2 + 1 reflected (A001h), init 0.
fn crc_bitwise(bytes: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &b in bytes {
        crc ^= b as u16;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xA001
            } else {
                crc >> 1
            };
        }
    }
    crc
}

/// `TableCRC16` exactly as Appendix C prints it.
const SEED_TABLE: [u16; 256] = [
    0x0000, 0xC0C1, 0xC181, 0x0140, 0xC301, 0x03C0, 0x0280, 0xC241, 0xC601, 0x06C0, 0x0780, 0xC741,
    0x0500, 0xC5C1, 0xC481, 0x0440, 0xCC01, 0x0CC0, 0x0D80, 0xCD41, 0x0F00, 0xCF41, 0xCE81, 0x0E40,
    0x0A00, 0xCAC1, 0xCB81, 0x0B40, 0xC901, 0x09C0, 0x0880, 0xC841, 0xD801, 0x18C0, 0x1980, 0xD941,
    0x1B00, 0xDB41, 0xDA81, 0x1A40, 0x1E00, 0xDE41, 0xDF81, 0x1F40, 0xDD01, 0x1DC0, 0x1C80, 0xDC41,
    0x1400, 0xD4C1, 0xD581, 0x1540, 0xD701, 0x17C0, 0x1680, 0xD641, 0xD201, 0x12C0, 0x1380, 0xD341,
    0x1100, 0xD141, 0xD081, 0x1040, 0xF001, 0x30C0, 0x3180, 0xF141, 0x3300, 0xF341, 0xF281, 0x3240,
    0x3600, 0xF6C1, 0xF781, 0x3740, 0xF501, 0x35C0, 0x3480, 0xF441, 0x3C00, 0xFCC1, 0xFD81, 0x3D40,
    0xFF01, 0x3FC0, 0x3E80, 0xFE41, 0xFA01, 0x3AC0, 0x3B80, 0xFB41, 0x3900, 0xF941, 0xF881, 0x3840,
    0x2800, 0xE8C1, 0xE981, 0x2940, 0xEB01, 0x2BC0, 0x2A80, 0xEA41, 0xEE01, 0x2EC0, 0x2F80, 0xEF41,
    0x2D00, 0xED41, 0xEC81, 0x2C40, 0xE401, 0x24C0, 0x2580, 0xE541, 0x2700, 0xE741, 0xE681, 0x2640,
    0x2200, 0xE2C1, 0xE381, 0x2340, 0xE101, 0x21C0, 0x2080, 0xE041, 0xA001, 0x60C0, 0x6180, 0xA141,
    0x6300, 0xA341, 0xA281, 0x6240, 0x6600, 0xA6C1, 0xA781, 0x6740, 0xA501, 0x65C0, 0x6480, 0xA441,
    0x6C00, 0xACC1, 0xAD81, 0x6D40, 0xAF01, 0x6FC0, 0x6E80, 0xAE41, 0xAA01, 0x6AC0, 0x6B80, 0xAB41,
    0x6900, 0xA941, 0xA881, 0x6840, 0x7800, 0xB8C1, 0xB981, 0x7940, 0xBB01, 0x7BC0, 0x7A80, 0xBA41,
    0xBE01, 0x7EC0, 0x7F80, 0xBF41, 0x7D00, 0xBDC1, 0xBC81, 0x7C40, 0xB401, 0x74C0, 0x7580, 0xB541,
    0x7700, 0xB741, 0xB681, 0x7640, 0x7200, 0xB2C1, 0xB381, 0x7340, 0xB101, 0x71C0, 0x7080, 0xB041,
    0x5000, 0x90C1, 0x9181, 0x5140, 0x9301, 0x53C0, 0x5280, 0x9241, 0x9601, 0x56C0, 0x5780, 0x9741,
    0x5500, 0x95C1, 0x9481, 0x5440, 0x9C01, 0x5CC0, 0x5D80, 0x9D41, 0x5F00, 0x9FC1, 0x9E81, 0x5E40,
    0x5A00, 0x9AC1, 0x9B81, 0x5B40, 0x9901, 0x99C0, 0x9880, 0x9841, 0x8801, 0x48C0, 0x4980, 0x8941,
    0x4B00, 0x8BC1, 0x8A81, 0x4A40, 0x4E00, 0x8EC1, 0x8F81, 0x4F40, 0x8D01, 0x4DC0, 0x4C80, 0x8C41,
    0x4400, 0x84C1, 0x8581, 0x4540, 0x8701, 0x47C0, 0x4680, 0x8641, 0x8201, 0x42C0, 0x4380, 0x8341,
    0x4100, 0x8141, 0x8081, 0x4040,
];

#[test]
fn crc16_check_value() {
    assert_eq!(crc_bitwise(b"123456789"), 0xBB3D);
    assert_eq!(crc16(b"123456789"), 0xBB3D);
    // Appendix C's CalcCRC16 starts from 0: no bytes, no CRC.
    assert_eq!(crc16(&[]), 0);
    for len in 0..64u8 {
        let bytes: Vec<u8> = (0..len).map(|i| i.wrapping_mul(37) ^ len).collect();
        assert_eq!(crc16(&bytes), crc_bitwise(&bytes), "{bytes:02x?}");
    }
}

#[test]
fn the_seed_table_differs_from_the_polynomial_exactly_at_the_known_typos() {
    // Entry i of a right-shifting table is the CRC of the byte i alone.
    let generated: Vec<u16> = (0..=255u8).map(|i| crc_bitwise(&[i])).collect();
    let differ: Vec<(u8, u16)> = (0..=255u8)
        .filter(|&i| SEED_TABLE[i as usize] != generated[i as usize])
        .map(|i| (i, SEED_TABLE[i as usize]))
        .collect();
    assert_eq!(differ, SEED_TABLE_TYPOS);
    // The seed's CalcCRC16 with the generated table is the bitwise CRC;
    // with the printed table it still gives the check value (no byte of
    // "123456789" meets a typo), so only the table comparison above, not
    // the check value, shows the typos. Bytes that meet one differ.
    let seed_calc = |bytes: &[u8]| {
        bytes.iter().fold(0u16, |crc, &b| {
            (crc >> 8) ^ SEED_TABLE[((crc ^ b as u16) & 0xFF) as usize]
        })
    };
    let fixed_calc = |bytes: &[u8]| {
        bytes.iter().fold(0u16, |crc, &b| {
            (crc >> 8) ^ generated[((crc ^ b as u16) & 0xFF) as usize]
        })
    };
    assert_eq!(fixed_calc(b"123456789"), 0xBB3D);
    assert_eq!(seed_calc(b"123456789"), 0xBB3D);
    for &(i, _) in SEED_TABLE_TYPOS {
        // From CRC 0 a byte i lands on entry i.
        assert_eq!(fixed_calc(&[i]), crc_bitwise(&[i]));
        assert_ne!(seed_calc(&[i]), crc16(&[i]), "{i:02X}h");
    }
}

/// The image of the RFU vectors (make_steval.py): 200 bytes, 3 segments.
fn rfu_image() -> Vec<u8> {
    (0..200u32).map(|i| ((i * 7 + 3) & 0xFF) as u8).collect()
}

/// CRC-32/ISO-HDLC bit by bit (reflected polynomial EDB88320h, init and
/// final XOR FFFFFFFFh), written here apart from plm-core's.
fn crc32_bitwise(data: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in data {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn the_rfu_crc_is_the_standard_crc32() {
    assert_eq!(crc32_bitwise(b"123456789"), 0xCBF4_3926);
    assert_eq!(rfu::image_crc(&rfu_image()), crc32_bitwise(&rfu_image()));
}

/// The typed message each vector is, written from the seed.
fn typed(name: &str) -> Option<Message> {
    use Service::*;
    let s = |x: Service| Some(Message::Service(x));
    let ack = |t: FrameType, echo: u8| {
        Some(Message::Ack {
            frame_type: t,
            echo,
        })
    };
    let h = |x: Hid| Some(Message::Hid(x));
    let reply = |param: u8, value: Vec<u8>| h(Hid::Reply { param, value });
    let user_data: Vec<u8> = (0x20..0x40).collect();
    let params: Vec<u8> = (0..32).map(|i| 0xA0 ^ i).collect();
    let all: Vec<u8> = [
        vec![0x01, 0x02],
        vec![0x01, 0x90],
        vec![0x00, 0x64],
        vec![0x00, 0x06],
        vec![0x00, 0x96],
        vec![0x00, 0x04],
        vec![0x01, 0x86],
        vec![0x00, 0x14],
        vec![0x00, 0xE6],
        vec![0xFF, 0xFB],
        vec![0x00, 0x0C],
        vec![0x0B, 0xB8],
    ]
    .concat();
    if let Some(code) = name.strip_prefix("APP_ERROR_FRAME ") {
        return Some(Message::Error(ErrorCode(
            u16::from_str_radix(code, 16).ok()?,
        )));
    }
    if let Some(p) = name
        .strip_prefix("Get HID parameter ")
        .and_then(|r| r.strip_suffix(" request"))
    {
        return h(Hid::Get(u8::from_str_radix(p, 16).ok()?));
    }
    match name {
        "SERVICE_SOFTWARE_RESET request" => s(SoftwareReset),
        "SERVICE_HARDWARE_RESET request" => s(HardwareReset),
        "SERVICE_PARAM_SET request" => s(ParamSet {
            group: 2,
            data: user_data,
        }),
        "SERVICE_PARAM_GET request" => s(ParamGet { group: 2 }),
        "SERVICE_PARAM_GET reply" => s(Params {
            group: 2,
            data: params,
        }),
        "SERVICE_IO_CONFIG_GET request" => s(IoConfigGet),
        "SERVICE_IO_CONFIG_GET reply" => s(IoConfig(0x0F)),
        "SERVICE_IO_CONFIG_SET request" => s(IoConfigSet(0xF0)),
        "SERVICE_INPUTS_GET request" => s(InputsGet),
        "SERVICE_INPUTS_GET reply" => s(Inputs(0xA5)),
        "SERVICE_OUTPUTS_SET request" => s(OutputsSet(0x3C)),
        "SERVICE_FW_REL_GET request" => s(FwRelGet),
        "SERVICE_FW_REL_GET reply" => s(FwRel {
            firmware: Release { major: 1, minor: 2 },
            stack: Release { major: 3, minor: 4 },
        }),
        "SERVICE_PLM_CLOCK_GET request" => s(ClockGet),
        "SERVICE_PLM_CLOCK_GET reply" => s(ClockNow(Clock {
            hours: 12,
            minutes: 34,
            seconds: 56,
        })),
        "SERVICE_PLM_CLOCK_SET request" => s(ClockSet(Clock {
            hours: 23,
            minutes: 59,
            seconds: 58,
        })),
        "SERVICE_SN_GET request" => s(SnGet),
        "SERVICE_SN_GET reply" => s(Sn(31)),
        "SERVICE_SN_SET request" => s(SnSet(10)),
        "SERVICE_NET_DISCOVER_REQ request" => s(Discover {
            session: 5,
            window: 10,
        }),
        "SERVICE_NET_DISCOVER_REQ request, rule 2" => s(DiscoverFrame(SlotFrame {
            session: 5,
            frame: 0,
            slots: 16,
            slot_ms: 33,
            share: 255,
            heard: vec![lamp(1), lamp(2)],
        })),
        "SERVICE_NET_DISCOVER_REQ request, bare" => s(DiscoverAny),
        "SERVICE_READ_IN_SLOTS request" => s(ReadInSlots(SlotRead {
            slot_ms: 62,
            param: 0x0A,
            first_ms: 20,
            addresses: vec![lamp(1), lamp(2)],
        })),
        "SERVICE_NET_DISCOVER_REQ reply" => s(DiscoverReply(Discovered {
            firmware: Release { major: 1, minor: 2 },
            stack: Release { major: 3, minor: 4 },
            snr: 20,
        })),
        "SERVICE_RFU_SET_IMG_HEADER request" => s(RfuHeader(rfu::Header {
            campaign: 7,
            size: 200,
            version: Release { major: 1, minor: 5 },
            crc: crc32_bitwise(&rfu_image()),
            segment: 96,
        })),
        "SERVICE_RFU_SET_IMG_DATA request (a full segment)" => s(RfuData {
            campaign: 7,
            segment: 1,
            data: rfu_image()[96..192].to_vec(),
        }),
        "SERVICE_RFU_SET_IMG_DATA request (the last, short segment)" => s(RfuData {
            campaign: 7,
            segment: 2,
            data: rfu_image()[192..].to_vec(),
        }),
        "SERVICE_RFU_SWAP_IMG request" => s(RfuSwap {
            campaign: 7,
            crc: crc32_bitwise(&rfu_image()),
        }),
        "RFU_STATUS_GET request" => s(RfuStatusGet { campaign: 7 }),
        "RFU_STATUS_GET reply" => s(RfuStatus(rfu::Status {
            campaign: 7,
            state: 1,
            reason: 3,
            received: 2,
            bitmap: [vec![0b101], vec![0; 79]].concat(),
        })),
        "RFU_ABORT request" => s(RfuAbort { campaign: 7 }),
        "SERVICE_RFU_SET_IMG_HEADER ACK" => ack(FrameType::Service, 0x0C),
        "SERVICE_RFU_SWAP_IMG ACK" => ack(FrameType::Service, 0x0E),
        "RFU_ABORT ACK" => ack(FrameType::Service, 0x12),
        "SERVICE_PARAM_SET ACK" => ack(FrameType::Service, 0x02),
        "SERVICE_IO_CONFIG_SET ACK" => ack(FrameType::Service, 0x09),
        "SERVICE_OUTPUTS_SET ACK" => ack(FrameType::Service, 0x05),
        "SERVICE_PLM_CLOCK_SET ACK" => ack(FrameType::Service, 0x07),
        "SERVICE_SN_SET ACK" => ack(FrameType::Service, 0x0F),
        "APP_PING_FRAME" => Some(Message::Ping),
        "APP_PING_FRAME ACK" => ack(FrameType::Ping, 0),
        "APP_DATA_FRAME user data" => Some(Message::Data(b"Hello".to_vec())),
        "HID board reset software" => h(Hid::Reset(0xAA)),
        "HID board reset hardware" => h(Hid::Reset(0x0C)),
        "HID set ACK" => ack(FrameType::Data, b's'),
        "Lamp dimming broadcast" => h(Hid::Dimming(50)),
        "Lamp dimming" => h(Hid::Dimming(100)),
        "Get HID parameter 00 reply" => reply(0x00, vec![0x01, 0x02]),
        "Get HID parameter 01 reply" => reply(0x01, vec![0x01, 0x90]),
        "Get HID parameter 02 reply" => reply(0x02, vec![0x00, 0x64]),
        "Get HID parameter 03 reply" => reply(0x03, vec![0x00, 0x06]),
        "Get HID parameter 04 reply" => reply(0x04, vec![0x00, 0x96]),
        "Get HID parameter 05 reply" => reply(0x05, vec![0x00, 0x04, 0x01, 0x86, 0x00, 0x14]),
        "Get HID parameter 06 reply" => reply(0x06, vec![0x00, 0xE6]),
        "Get HID parameter 07 reply" => reply(0x07, vec![0xFF, 0xFB]),
        "Get HID parameter 08 reply" => reply(0x08, vec![0x00, 0x0C]),
        "Get HID parameter 09 reply" => reply(0x09, vec![0x0B, 0xB8]),
        "Get HID parameter 0a reply" => reply(0x0A, all),
        _ => None,
    }
}

struct Vector {
    name: String,
    bytes: Vec<u8>,
    length: usize,
    broadcast: bool,
    expect: Value,
}

fn vectors() -> Vec<Vector> {
    VECTORS
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let v: Value = serde_json::from_str(line).expect("vector line is JSON");
            Vector {
                name: v["name"].as_str().unwrap().to_string(),
                bytes: plm_core::hex::parse(v["hex"].as_str().unwrap()).unwrap(),
                length: v["length"].as_u64().unwrap() as usize,
                broadcast: v["broadcast"].as_bool().unwrap(),
                expect: v["expect"].clone(),
            }
        })
        .collect()
}

#[test]
fn every_vector_is_its_typed_message_and_emits_back_to_the_same_bytes() {
    let mut failures = Vec::new();
    let vs = vectors();
    assert!(vs.len() >= 60, "only {} vectors", vs.len());
    for v in &vs {
        let b = &v.bytes;
        let n = b.len();
        let fail = |what: String| format!("{}: {what}", v.name);
        // The vector itself: length byte as the seed states it, CRC-16 by
        // the polynomial, high byte first.
        assert_eq!(b[0] as usize, v.length, "{}", v.name);
        assert_eq!(n, v.length, "{}", v.name);
        assert_eq!(
            u16::from_be_bytes([b[n - 2], b[n - 1]]),
            crc_bitwise(&b[..n - 2]),
            "{}",
            v.name
        );
        let Some(want) = typed(&v.name) else {
            failures.push(fail("no typed expectation".into()));
            continue;
        };
        let frame = match AppFrame::parse(b) {
            Ok(f) => f,
            Err(e) => {
                failures.push(fail(format!("does not parse: {e}")));
                continue;
            }
        };
        if frame.address != ADDR || frame.broadcast != v.broadcast {
            failures.push(fail(format!("address/broadcast {frame:?}")));
        }
        match Message::of(&frame) {
            Ok(m) if m == want => {}
            got => failures.push(fail(format!("read as {got:?}, want {want:?}"))),
        }
        let built = if v.broadcast {
            want.broadcast(ADDR)
        } else {
            want.to(ADDR)
        };
        match built.emit() {
            Ok(e) if e == *b => {}
            got => failures.push(fail(format!("emits {got:02x?}"))),
        }
    }
    assert!(
        failures.is_empty(),
        "{} vectors fail:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Every layout the seed gives has a vector: each service command's
/// request and its answer (00h-10h, with the RFU commands 0Ch-0Eh whose
/// layouts are the project's, and its user-defined 11h-12h), each HID
/// command and each 'g' reply, ping, ACKs, error and data frames.
#[test]
fn the_vectors_cover_every_layout() {
    let messages: Vec<Message> = vectors()
        .iter()
        .map(|v| Message::of(&AppFrame::parse(&v.bytes).unwrap()).unwrap())
        .collect();
    let has = |f: &dyn Fn(&Message) -> bool| messages.iter().any(f);
    for d in service::COMMANDS {
        assert!(
            has(&|m| matches!(m, Message::Service(s) if s.command() == d.code && s.is_request())),
            "{} request",
            d.name
        );
        match d.answer {
            Answer::Ack => assert!(
                has(&|m| *m
                    == Message::Ack {
                        frame_type: FrameType::Service,
                        echo: d.code
                    }),
                "{} ACK",
                d.name
            ),
            Answer::Reply(..) => assert!(
                has(
                    &|m| matches!(m, Message::Service(s) if s.command() == d.code && !s.is_request())
                ),
                "{} reply",
                d.name
            ),
            Answer::None | Answer::Undefined => {}
        }
    }
    for p in hid::PARAMS {
        assert!(has(&|m| *m == Message::Hid(Hid::Get(p.code))), "{}", p.name);
        assert!(
            has(&|m| matches!(m, Message::Hid(Hid::Reply { param, .. }) if *param == p.code)),
            "{} reply",
            p.name
        );
    }
    for m in [
        Message::Hid(Hid::Reset(hid::RESET_SOFTWARE)),
        Message::Hid(Hid::Reset(hid::RESET_HARDWARE)),
        Message::Ping,
        Message::Ack {
            frame_type: FrameType::Ping,
            echo: 0,
        },
        Message::Ack {
            frame_type: FrameType::Data,
            echo: hid::SET,
        },
    ] {
        assert!(has(&|x| *x == m), "{m:?}");
    }
    assert!(has(&|m| matches!(m, Message::Hid(Hid::Dimming(_)))));
    assert!(has(&|m| matches!(m, Message::Error(_))));
    assert!(has(&|m| matches!(m, Message::Data(_))));
}

#[test]
fn the_lengths_the_seed_states() {
    // buffer[0] as printed: 44 PARAM_SET, 15 FW_REL reply, 36 HID get-all
    // reply, 18 last failure, 12 ACK and error frames, 10 ping.
    let len = |m: Message| m.to(ADDR).emit().unwrap()[0];
    assert_eq!(
        len(Message::Service(Service::ParamSet {
            group: 2,
            data: vec![0; 32]
        })),
        44
    );
    assert_eq!(
        len(Message::Service(Service::FwRel {
            firmware: Release::default(),
            stack: Release::default()
        })),
        15
    );
    assert_eq!(
        len(Message::Hid(Hid::Reply {
            param: hid::ALL,
            value: vec![0; 24]
        })),
        36
    );
    assert_eq!(
        len(Message::Hid(Hid::Reply {
            param: 0x05,
            value: vec![0; 6]
        })),
        18
    );
    assert_eq!(len(Message::Service(Service::ClockGet).ack()), 12);
    assert_eq!(len(Message::Error(ErrorCode(4))), 12);
    assert_eq!(len(Message::Ping), 10);
}

/// Whether every key of `want` is in `got` with the same value; `fields`
/// must match exactly (but the words of `meaning`, checked apart).
fn check(want: &Value, got: &Value, errors: &mut Vec<String>) {
    for (k, w) in want.as_object().unwrap() {
        let g = got.get(k);
        if k == "fields" {
            let mut g = g.cloned().unwrap_or(Value::Null);
            if let Some(m) = g.as_object_mut() {
                if let Some(words) = m.remove("meaning") {
                    if words.as_str().is_none_or(|s| s.len() <= 10) {
                        errors.push(format!("meaning: {words}"));
                    }
                }
            }
            if g != *w {
                errors.push(format!("fields: want {w}, got {g}"));
            }
        } else if g != Some(w) {
            errors.push(format!("{k}: want {w}, got {g:?}"));
        }
    }
}

#[test]
fn every_vector_decodes_as_the_seed_names_it() {
    let mut failures = Vec::new();
    for v in vectors() {
        let got = decode_usart(&v.bytes);
        if got.len() != 1 {
            failures.push(format!("{}: {} elements", v.name, got.len()));
            continue;
        }
        let got = serde_json::to_value(&got[0]).unwrap();
        let mut errors = Vec::new();
        check(&v.expect, &got, &mut errors);
        if got.get("error").is_some() {
            errors.push(format!("error: {}", got["error"]));
        }
        if !errors.is_empty() {
            failures.push(format!("{}: {}", v.name, errors.join("; ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} vectors fail:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn a_whole_capture_of_the_vectors_decodes_frame_by_frame() {
    let vs = vectors();
    let capture: Vec<u8> = vs.iter().flat_map(|v| v.bytes.clone()).collect();
    let got = decode_usart(&capture);
    assert_eq!(got.len(), vs.len());
    for (g, v) in got.iter().zip(&vs) {
        assert_eq!(g.hex, plm_core::hex::encode(&v.bytes), "{}", v.name);
        assert_eq!(g.crc_ok, Some(true), "{}", v.name);
    }
}

/// Lamp `n` of the vectors (0080E10000nnh).
fn lamp(n: u8) -> Address {
    Address([0x00, 0x80, 0xE1, 0x00, 0x00, n])
}
