//! `plm sim --chip st7570` end to end (issue 12, "Must show"): the real
//! binary serving a simulated S-FSK line of ST7570s over RFC 2217 on
//! loopback, driven by `plm board`'s RFC 2217 client
//! (`plm_cli::rfc2217::client`) and plm-core's host engine in the ST7570
//! dialect, in wall time: T_REQ answered by a status message within
//! T_POLL, a MIB object read, written and read back, the modem made a MAC
//! Client (00A1h), a MAC frame to a Server answered by its echo, and a
//! DTR (RESETn) pulse reported by the status message's RESET bit.

mod common;

use common::st7570::{mac_client, mac_frame, treq_status, Host, BAUD};
use common::Server;
use plm_cli::rfc2217::client::Client;
use plm_core::link::host::LinkError;
use plm_core::st7570::mib::index;
use plm_core::st7570::{Address, Command, Layer};
use std::time::Duration;

/// T_POLL (ST7570 UM Table 14): T_REQ low to the status message.
const T_POLL: Duration = Duration::from_millis(20);

#[test]
fn plm_sim_chip_st7570_through_rfc2217_and_the_host_engine() {
    let mut server = Server::start(&["--chip", "st7570", "--listen", "127.0.0.1:0"]);
    let banner = server.lines_up_to("powers on when the first client connects");
    let text = banner.join("\n");
    assert!(
        server
            .banner
            .contains("simulated ST7570 S-FSK line (node 0 of 4, seed 1)"),
        "{}",
        server.banner
    );
    assert!(
        text.contains("repeaters (000Bh ALWAYS_REPEAT): node 3"),
        "{text}"
    );
    let mut port = Client::open(&server.addr, BAUD).expect("an RFC 2217 port");

    // Nothing without T_REQ: the ST7570 sends no frame at power-on.
    let quiet = port.read_data(Duration::from_millis(300)).unwrap();
    assert!(quiet.is_empty(), "unasked: {quiet:02X?}");
    // T_REQ: the status message, `?` and 3 bytes, within T_POLL (the
    // median of five edges: a loaded machine may schedule one late).
    let mut delays = Vec::new();
    for _ in 0..5 {
        let (bytes, took) = treq_status(&mut port);
        assert_eq!(bytes.len(), 4, "{bytes:02X?}");
        assert_eq!(bytes[0], b'?');
        delays.push(took);
        // Released without a frame: T_SR passes, nothing more comes.
        let more = port.read_data(Duration::from_millis(250)).unwrap();
        assert!(more.is_empty(), "after the status: {more:02X?}");
    }
    delays.sort();
    assert!(delays[2] < T_POLL, "T_REQ -> status: {delays:?}");

    let mut host = Host::new(port);
    // MIB read, write, read back (0085h, Table 131).
    assert_eq!(host.read(0x0085), [8, 2, 9]);
    let st = host.status();
    assert_eq!(
        (st.mode, st.mac, st.reset, st.fw_release),
        (0, false, false, 1)
    );
    assert_eq!(host.write(0x0085, &[4, 3, 5]), [4, 3, 5]);
    assert_eq!(host.read(0x0085), [4, 3, 5]);

    // The modem a MAC Client (00A1h): the status says so.
    host.write(index::PLC_CONFIGURATION, &mac_client());
    host.layer = Layer::Mac;
    assert_eq!(host.read(index::PLC_CONFIGURATION), mac_client());
    let st = host.status();
    assert_eq!((st.mode, st.mac), (1, true), "{st:?}");
    let client = u16::from_le_bytes(
        host.read(index::LOCAL_INIT_MAC_ADD)[..2]
            .try_into()
            .unwrap(),
    );

    // A MAC frame to Server 2, its echo as a MAC data indication.
    let hello = mac_frame(2, b"hello over RFC 2217");
    match host.request(&Command::MacDataRequest(hello.clone())) {
        Command::DataConfirm { confirm_code } => assert_eq!(confirm_code, 0xFF, "LM_OK"),
        other => panic!("{other:?}"),
    }
    let echo = host.frame("the Server's echo", |c| match c {
        Command::MacDataIndication(m) => Some(m),
        _ => None,
    });
    assert_eq!(echo.address, Address { sa: 2, da: client });
    assert_eq!(echo.m_sdu, hello.m_sdu);

    // A DTR pulse resets the modem: held, it answers nothing; released,
    // it boots with its settings restored (7.1) and its status says
    // RESET = 0, hardware. A software reset first, so that the bit
    // changes.
    match host.request(&Command::ResetRequest { reset: 0 }) {
        Command::ResetRequest { reset } => assert_eq!(reset, 0),
        other => panic!("{other:?}"),
    }
    host.read(0x0085);
    assert!(host.status().reset, "RESET = 1 after CMD_ResetRequest");
    host.port.set_dtr(true).unwrap();
    assert_eq!(
        host.unanswered(&Command::ReadDbRequest { index: 0x0085 }),
        LinkError::NoStatus
    );
    host.port.set_dtr(false).unwrap();
    host.idle(Duration::from_millis(100));
    assert_eq!(host.read(0x0085), [4, 3, 5], "auto-reconfiguration");
    let st = host.status();
    assert!(!st.reset, "RESET = 0 after RESETn: {st:?}");
    assert_eq!((st.mode, st.mac), (1, true), "{st:?}");

    drop(host);
    server.interrupt();
}

/// `--alarms 1`: the Servers raise an alarm in turn every second; once
/// they are synchronized (the Client's frame to Server 1), the Client's
/// host receives CMD_AlarmIndication (ST7570 UM 5.3.15).
#[test]
fn plm_sim_st7570_alarms_reach_the_client() {
    let mut server = Server::start(&[
        "--chip",
        "st7570",
        "--alarms",
        "1",
        "--listen",
        "127.0.0.1:0",
    ]);
    let banner = server.lines_up_to("powers on when the first client connects");
    let text = banner.join("\n");
    assert!(
        text.contains("every 1 s a Server raises an alarm (nodes 1-3 in turn)"),
        "{text}"
    );
    let port = Client::open(&server.addr, BAUD).expect("an RFC 2217 port");
    let mut host = Host::new(port);
    host.write(index::PLC_CONFIGURATION, &mac_client());
    host.layer = Layer::Mac;
    let ask = mac_frame(1, b"?");
    match host.request(&Command::MacDataRequest(ask)) {
        Command::DataConfirm { confirm_code } => assert_eq!(confirm_code, 0xFF, "LM_OK"),
        other => panic!("{other:?}"),
    }
    host.frame("an alarm from a Server", |c| match c {
        Command::AlarmIndication { .. } => Some(()),
        _ => None,
    });
    drop(host);
    server.interrupt();
}
