//! The manual's own set-up through `plm sim --chip st7570 --nodes 3`: a
//! host writes seed 003 section 8's CMD_WriteDBRequest of 00A1h byte for
//! byte (MAC Client, 2400 bit/s), gets the section's CMD_WriteDBConfirm
//! byte for byte, then sends a MAC frame to a Server and gets its echo
//! indicated: the Servers take on the Client's bit rate, f0 and f1
//! (docs/protocol-notes.md, "ST7570: simulated network"). With
//! `--factory-servers` they keep 1200 bit/s and hear nothing of it.

mod common;

use common::st7570::{mac_frame, status_on_treq, Host, BAUD};
use common::Server;
use plm_cli::rfc2217::client::Client;
use plm_core::st7570::{Address, Command, Layer, Status};
use std::time::{Duration, Instant};

/// Seed 003 section 8: the host's CMD_WriteDBRequest of 00A1h (MAC
/// Client, 2400 bit/s, 50 Hz, gain 10h, f0 74 kHz, f1 63.3 kHz, current
/// limiting enabled), as the section prints it.
const REQUEST: [u8; 21] = [
    0x02, 0x13, 0x41, 0xA1, 0x00, 0x09, 0x00, 0x10, 0x10, 0x21, 0x01, 0x44, 0xF7, 0x00, 0x00, 0x00,
    0x00, 0x02, 0x01, 0x7E, 0x02,
];
/// Seed 003 section 8: the modem's CMD_WriteDBConfirm.
const CONFIRM: [u8; 21] = [
    0x02, 0x13, 0x42, 0xA1, 0x00, 0x09, 0x00, 0x10, 0x10, 0x21, 0x01, 0x44, 0xF7, 0x00, 0x00, 0x00,
    0x00, 0x02, 0x01, 0x7F, 0x02,
];
/// ACK (ST7570 UM Table 10).
const ACK: u8 = 0x06;
/// How long the Client waits for a Server's echo: a frame and its answer
/// take a few 150 ms slots at 2400 bit/s.
const ECHO_WAIT: Duration = Duration::from_secs(4);

/// Section 8's exchange by hand, as its Figure 28 runs: T_REQ, the
/// status message (MODE 0, "Not set": the section's NOT_SET), the
/// request, T_REQ released; the modem's ACK and its confirm, which the
/// host ACKs. Returns what came after the status message.
fn section_8(port: &mut Client) -> Vec<u8> {
    let (status, _) = status_on_treq(port);
    let st = Status::parse(&status[1..]).expect("a status message");
    assert_eq!(st.mode, 0, "{st:?}");
    port.send_data(&REQUEST).unwrap();
    port.set_rts(false).unwrap();
    let deadline = Instant::now() + common::WAIT;
    let mut got = Vec::new();
    while got.len() < 1 + CONFIRM.len() {
        assert!(Instant::now() < deadline, "after the request: {got:02X?}");
        got.extend(port.read_data(Duration::from_millis(5)).unwrap());
    }
    port.send_data(&[ACK]).unwrap();
    // Nothing else comes.
    got.extend(port.read_data(Duration::from_millis(200)).unwrap());
    got
}

/// `plm sim --chip st7570 --nodes 3 [extra]` set up as section 8 says:
/// what it printed at start, and its host, in the MAC layer.
fn set_up(extra: &[&str]) -> (Server, String, Host) {
    let args = [
        &[
            "--chip",
            "st7570",
            "--nodes",
            "3",
            "--listen",
            "127.0.0.1:0",
        ][..],
        extra,
    ]
    .concat();
    let mut server = Server::start(&args);
    let banner = server
        .lines_up_to("powers on when the first client connects")
        .join("\n");
    let mut port = Client::open(&server.addr, BAUD).expect("an RFC 2217 port");
    let got = section_8(&mut port);
    assert_eq!(got[0], ACK, "{got:02X?}");
    assert_eq!(got[1..], CONFIRM, "the seed's confirm, byte for byte");
    let mut host = Host::new(port);
    host.layer = Layer::Mac;
    (server, banner, host)
}

/// Sends `m_sdu` to Server 2 (confirmed LM_OK); its echo, if one is
/// indicated within [`ECHO_WAIT`].
fn ask_server_2(host: &mut Host, m_sdu: &[u8]) -> Option<Vec<u8>> {
    let frame = mac_frame(2, m_sdu);
    match host.request(&Command::MacDataRequest(frame)) {
        Command::DataConfirm { confirm_code } => assert_eq!(confirm_code, 0xFF, "LM_OK"),
        other => panic!("{other:?}"),
    }
    let until = Instant::now() + ECHO_WAIT;
    let mut seen = 0;
    while Instant::now() < until {
        host.step();
        for e in &host.events[seen..] {
            if let plm_core::link::host::Event::Frame(f) = e {
                if let Ok(Command::MacDataIndication(m)) = Command::from_frame(f, Layer::Mac) {
                    assert_eq!(m.address, Address { sa: 2, da: 0x0C00 });
                    return Some(m.m_sdu);
                }
            }
        }
        seen = host.events.len();
    }
    None
}

#[test]
fn the_section_8_set_up_reaches_the_servers_and_their_echo_comes_back() {
    let (server, banner, mut host) = set_up(&[]);
    assert!(
        banner.contains("the Servers take on node 0's bit rate, f0 and f1"),
        "{banner}"
    );
    assert_eq!(
        ask_server_2(&mut host, b"written from section 8").as_deref(),
        Some(&b"written from section 8"[..]),
        "Server 2's echo"
    );
    drop(host);
    server.interrupt();
}

#[test]
fn factory_servers_do_not_hear_the_section_8_set_up() {
    let (server, banner, mut host) = set_up(&["--factory-servers"]);
    assert!(
        banner.contains("the Servers keep the factory bit rate, f0 and f1"),
        "{banner}"
    );
    assert_eq!(ask_server_2(&mut host, b"written from section 8"), None);
    // They are there, at 1200 bit/s: the same Client at the factory rate
    // is answered.
    let mut at_1200 = CONFIRM[5..19].to_vec();
    at_1200[0] = 0x01;
    host.write(0x00A1, &at_1200);
    assert_eq!(
        ask_server_2(&mut host, b"1200").as_deref(),
        Some(&b"1200"[..])
    );
    drop(host);
    server.interrupt();
}
