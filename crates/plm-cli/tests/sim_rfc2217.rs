//! `plm sim` end to end: the real binary serving the simulated ST7580 over
//! RFC 2217, driven by the small RFC 2217 client of `common` (written
//! independently of the server's codec, so that a codec bug cannot cancel
//! itself out).
//!
//! Timeouts are generous (seconds) so that a loaded machine does not make
//! the test flaky; the link's own timings (T_ACK 40 ms, T_SR 200 ms) are met
//! by answering at once.

mod common;

use common::{
    com_port, Link, Server, Telnet, BINARY, COM_PORT, DO, DONT, DTR_OFF, DTR_ON, IAC, RTS_OFF,
    RTS_ON, SET_CONTROL, SGA, WAIT, WILL, WONT,
};
use plm_core::link::{checksum, Dialect, Element, LocalFrame, Source, StreamDecoder, Stx};
use std::collections::VecDeque;
use std::io::Read;
use std::net::TcpStream;
use std::process::Command;
use std::time::{Duration, Instant};

/// The modem's host: an RFC 2217 link and a decoder of what the modem
/// sends.
struct Client {
    link: Link,
    modem: StreamDecoder,
    elements: VecDeque<Element>,
    /// Every data byte received (IAC undone), for the record.
    data: Vec<u8>,
    /// The last frame received from the modem.
    last_frame: Option<LocalFrame>,
}

impl Client {
    fn connect(addr: &str) -> Client {
        Client {
            link: Link::connect(addr),
            modem: StreamDecoder::new(Dialect::St7580, Source::Modem),
            elements: VecDeque::new(),
            data: Vec::new(),
            last_frame: None,
        }
    }

    fn send(&mut self, bytes: &[u8]) {
        self.link.send(bytes);
    }

    fn send_data(&mut self, data: &[u8]) {
        self.link.send_data(data);
    }

    /// Takes what came (waiting up to 20 ms when nothing is there yet)
    /// and decodes it.
    fn pump(&mut self) {
        if !self.link.has_data() {
            self.link.pump(Duration::from_millis(20));
        }
        let data = self.link.take_data();
        self.data.extend_from_slice(&data);
        self.modem.push(&data);
        while let Some(e) = self.modem.next() {
            self.elements.push_back(e);
        }
    }

    fn expect_telnet(&mut self, what: &str, want: impl Fn(&Telnet) -> bool) -> Telnet {
        self.link.expect_telnet(what, want)
    }

    fn expect_reply(&mut self, code: u8) -> Vec<u8> {
        self.link.expect_reply(code)
    }

    /// The next element from the modem. A repeat (STX 03h) of the last
    /// frame comes only if our ACK was later than T_ACK (a very loaded
    /// machine): it is ACKed and skipped wherever it comes.
    fn next_element(&mut self) -> Element {
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(e) = self.elements.pop_front() {
                if let Element::Frame { frame, .. } = &e {
                    let repeat = self.last_frame.as_ref().is_some_and(|p| {
                        frame.stx == Stx::Repeat && p.code == frame.code && p.data == frame.data
                    });
                    if repeat {
                        eprintln!("note: the modem repeated {:02X}h (ACK late)", frame.code);
                        self.send_data(&[0x06]);
                        continue;
                    }
                }
                return e;
            }
            assert!(
                Instant::now() < deadline,
                "nothing from the modem; data so far: {:02X?}",
                self.data
            );
            self.pump();
        }
    }

    /// The next frame from the modem, ACKed at once.
    fn next_frame(&mut self) -> LocalFrame {
        match self.next_element() {
            Element::Frame {
                frame, checksum_ok, ..
            } => {
                assert!(checksum_ok, "modem frame with a bad checksum: {frame:?}");
                self.send_data(&[0x06]);
                self.last_frame = Some(frame.clone());
                frame
            }
            other => panic!("expected a frame, got {other:?}"),
        }
    }

    /// RTS (T_REQ) through the client's SET-CONTROL, answered in kind.
    fn set_rts(&mut self, on: bool) {
        self.link.set_rts(on).unwrap();
        let value = if on { RTS_ON } else { RTS_OFF };
        assert_eq!(self.expect_reply(SET_CONTROL), [value], "RTS reply");
    }

    /// DTR (RESETN in `plm sim`) through the client's SET-CONTROL,
    /// answered in kind.
    fn set_dtr(&mut self, on: bool) {
        self.link.set_dtr(on).unwrap();
        let value = if on { DTR_ON } else { DTR_OFF };
        assert_eq!(self.expect_reply(SET_CONTROL), [value], "DTR reply");
    }

    /// T_REQ asserted, the status message awaited, `frame` sent with T_REQ
    /// released right after its STX (UM0932 3.2.8), as one TCP write.
    fn request(&mut self, frame: &[u8]) {
        self.set_rts(true);
        match self.next_element() {
            Element::Status(s) => assert_eq!(s.data().len(), 1, "ST7580 status is 2 bytes"),
            other => panic!("expected the status message, got {other:?}"),
        }
        let mut out = vec![frame[0]];
        out.extend(com_port(SET_CONTROL, &[RTS_OFF]));
        out.extend(common::escape(&frame[1..]));
        self.send(&out);
        assert_eq!(self.expect_reply(SET_CONTROL), [RTS_OFF], "RTS OFF reply");
    }
}

fn frame(code: u8, data: &[u8]) -> Vec<u8> {
    LocalFrame {
        stx: Stx::First,
        code,
        data: data.to_vec(),
    }
    .emit(Dialect::St7580)
    .unwrap()
}

#[test]
fn simulated_st7580_over_rfc2217() {
    let mut server = Server::start(&["--chip", "st7580", "--listen", "127.0.0.1:0"]);
    assert!(
        server.banner.contains("simulated ST7580"),
        "{}",
        server.banner
    );
    let mut c = Client::connect(&server.addr);
    server.line_containing("connected");

    // Telnet: our requests cross the server's; COM-PORT-OPTION is agreed
    // both ways and nothing we asked for is refused.
    c.send(&[
        IAC, WILL, BINARY, IAC, DO, BINARY, IAC, DO, SGA, IAC, WILL, COM_PORT, IAC, DO, COM_PORT,
    ]);
    c.expect_telnet("WILL COM-PORT-OPTION", |t| {
        *t == Telnet::Negotiation(WILL, COM_PORT)
    });
    c.expect_telnet("DO COM-PORT-OPTION", |t| {
        *t == Telnet::Negotiation(DO, COM_PORT)
    });
    c.expect_telnet("WILL BINARY", |t| *t == Telnet::Negotiation(WILL, BINARY));
    c.expect_telnet("DO BINARY", |t| *t == Telnet::Negotiation(DO, BINARY));
    c.expect_telnet("WILL SGA", |t| *t == Telnet::Negotiation(WILL, SGA));
    // With COM-PORT-OPTION agreed, the modem lines are notified once:
    // CTS and DSR on (RFC 2217 NOTIFY-MODEMSTATE, server code 107).
    assert_eq!(c.expect_reply(7), [0x30], "NOTIFY-MODEMSTATE");
    assert!(
        !c.link
            .telnet
            .iter()
            .any(|t| matches!(t, Telnet::Negotiation(WONT | DONT, _))),
        "refused: {:?}",
        c.link.telnet
    );

    // SET-BAUDRATE: 57600 is a BR-pin rate; 115200 is not, the answer is
    // the rate in effect; 0 asks for it.
    for (ask, answer) in [(57600u32, 57600u32), (115200, 57600), (0, 57600)] {
        c.send(&com_port(1, &ask.to_be_bytes()));
        assert_eq!(c.expect_reply(1), answer.to_be_bytes(), "baud {ask}");
    }
    c.send(&com_port(2, &[8]));
    assert_eq!(c.expect_reply(2), [8]);
    c.set_rts(false);

    // 1. The modem powered on with the connection: BIO_ResetIndication.
    let reset = c.next_frame();
    assert_eq!(reset.code, 0x3E, "BIO_ResetIndication: {reset:?}");
    assert_eq!(reset.stx, Stx::First);
    assert_eq!(reset.data.len(), 1, "ResetData");

    // A second client is refused while this one is connected.
    let mut other = TcpStream::connect(&server.addr).unwrap();
    other
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let mut said = String::new();
    let _ = other.read_to_string(&mut said);
    assert!(said.contains("busy"), "second client was told {said:?}");
    server.line_containing("refused");

    // 2. T_REQ through RTS, then MIB_ReadRequest of the firmware version.
    let read = frame(0x0C, &[0x0A]);
    assert_eq!(read, [0x02, 0x01, 0x0C, 0x0A, 0x17, 0x00]);
    c.request(&read);
    assert_eq!(c.next_element(), Element::Ack, "ACK of MIB_ReadRequest");
    let confirm = c.next_frame();
    assert_eq!(confirm.code, 0x0D, "MIB_ReadConfirm: {confirm:?}");
    assert_eq!(confirm.data, [0x00, 0x42, 0x00, 0x97]);

    // 3. PingRequest with FFh in the payload and in the checksum: IAC is
    // doubled both ways.
    let mut payload = vec![0xFF, 0x00, 0xFF, 0x00];
    payload[3] = (0..=255u8)
        .find(|x| {
            let mut p = payload.clone();
            p[3] = *x;
            checksum(&[&[4, 0x2C][..], &p].concat()) & 0xFF == 0xFF
        })
        .unwrap();
    let ping = frame(0x2C, &payload);
    assert_eq!(ping[ping.len() - 2], 0xFF);
    c.request(&ping);
    assert_eq!(c.next_element(), Element::Ack, "ACK of PingRequest");
    let pong = c.next_frame();
    assert_eq!(pong.code, 0x2D, "PingConfirm: {pong:?}");
    assert_eq!(pong.data, payload);

    // 4. A frame with a wrong checksum is NAKed.
    let mut bad = frame(0x2C, &[1, 2, 3]);
    let n = bad.len();
    bad[n - 2] ^= 0x01;
    c.request(&bad);
    assert_eq!(c.next_element(), Element::Nak, "NAK of a bad checksum");

    // The client goes; the server says so and stays up for the next one,
    // whose modem is still running (no second reset indication).
    drop(c);
    server.line_containing("disconnected");
    let mut c = Client::connect(&server.addr);
    server.line_containing("connected");
    c.send(&[IAC, WILL, COM_PORT]);
    c.expect_telnet("DO COM-PORT-OPTION", |t| {
        *t == Telnet::Negotiation(DO, COM_PORT)
    });
    c.request(&read);
    assert_eq!(c.next_element(), Element::Ack);
    assert_eq!(c.next_frame(), confirm);

    drop(c);
    server.line_containing("disconnected");
    server.interrupt();
}

#[test]
fn a_remote_address_needs_allow_remote() {
    let out = Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["sim", "--listen", "0.0.0.0:0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--allow-remote"), "{err}");
}

/// One request of the host: ACKed, then its confirm.
fn ask(c: &mut Client, frame: &[u8]) -> LocalFrame {
    c.request(frame);
    assert_eq!(c.next_element(), Element::Ack, "ACK of {frame:02X?}");
    c.next_frame()
}

#[test]
fn a_dtr_pulse_resets_the_modem_to_its_factory_mib() {
    let mut server = Server::start(&["--chip", "st7580", "--listen", "127.0.0.1:0"]);
    let mut c = Client::connect(&server.addr);
    server.line_containing("connected");
    c.send(&[IAC, WILL, COM_PORT]);
    c.expect_telnet("DO COM-PORT-OPTION", |t| {
        *t == Telnet::Negotiation(DO, COM_PORT)
    });
    c.set_rts(false);
    assert_eq!(c.next_frame().code, 0x3E, "BIO_ResetIndication at power-on");

    // The host configures its modem: MIB 00h (Modem_Config, factory 11h)
    // to 10h.
    let write = frame(0x08, &[0x00, 0x10]);
    assert_eq!(ask(&mut c, &write).code, 0x09, "MIB_WriteConfirm");
    let read = frame(0x0C, &[0x00]);
    assert_eq!(ask(&mut c, &read).data, [0x10]);

    // DTR asserted (RFC 2217 SET-CONTROL 8): RESETN held low, the modem
    // is off and answers nothing, not even T_REQ.
    c.set_dtr(true);
    c.set_rts(true);
    let quiet_until = Instant::now() + Duration::from_millis(400);
    while Instant::now() < quiet_until {
        c.pump();
    }
    assert!(
        c.elements.is_empty(),
        "a modem held in reset said {:?}",
        c.elements
    );
    c.set_rts(false);

    // DTR released (SET-CONTROL 9): the modem boots as at power-on.
    c.set_dtr(false);
    let reset = c.next_frame();
    assert_eq!(reset.code, 0x3E, "BIO_ResetIndication after DTR: {reset:?}");
    // Table 19: cause 0 (power-on / RESETN), every object at its default.
    let data = plm_core::st7580::ResetData::from_byte(reset.data[0]);
    assert_eq!(data.reset_cause, plm_core::st7580::ResetCause::PowerOn);
    assert!(data.modem_config_error && data.phy_config_error && data.ss_key_error);
    assert_eq!(ask(&mut c, &read).data, [0x11], "factory Modem_Config");

    drop(c);
    server.line_containing("disconnected");
    server.interrupt();
}

/// `host:port` of every "node i on rfc2217://" line of `--serve`.
fn node_addrs(server: &mut Server, n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            let line = server.line_containing(&format!("node {i} on rfc2217://"));
            line.split("rfc2217://").nth(1).unwrap().trim().to_string()
        })
        .collect()
}

#[test]
fn serve_2_serves_two_modems_of_one_line_each_on_its_own_port() {
    let mut server = Server::start(&[
        "--chip",
        "st7580",
        "--listen",
        "127.0.0.1:0",
        "--serve",
        "2",
        "--nodes",
        "3",
    ]);
    let addrs = node_addrs(&mut server, 2);
    assert_eq!(addrs[0], server.addr, "node 0 is the first address");
    assert_ne!(addrs[0], addrs[1]);
    let peers = server.line_containing("echo what they hear");
    assert!(
        peers.contains("nodes 2-2") && peers.contains("node 0's MIB"),
        "{peers}"
    );
    let mut clients: Vec<Client> = addrs.iter().map(|a| Client::connect(a)).collect();
    // Each port has its own accepting thread: the lines come in any order.
    let mut said: Vec<String> = (0..2)
        .map(|_| server.line_containing("connected to node"))
        .collect();
    said.sort_by_key(|l| l.chars().last());
    assert!(
        said[0].ends_with("node 0") && said[1].ends_with("node 1"),
        "{said:?}"
    );
    for (i, c) in clients.iter_mut().enumerate() {
        c.send(&[IAC, WILL, COM_PORT]);
        c.expect_telnet("DO COM-PORT-OPTION", |t| {
            *t == Telnet::Negotiation(DO, COM_PORT)
        });
        c.set_rts(false);
        assert_eq!(c.next_frame().code, 0x3E, "node {i}: BIO_ResetIndication");
    }
    // Each port names its node (RFC 2217 SIGNATURE, asked empty).
    for (i, c) in clients.iter_mut().enumerate() {
        c.send(&com_port(0, &[]));
        let said = String::from_utf8(c.expect_reply(0)).unwrap();
        assert!(said.ends_with(&format!("node {i}")), "{said}");
    }
    // Each its own modem: node 1 configured otherwise, node 0 untouched.
    let write = frame(0x08, &[0x00, 0x10]);
    assert_eq!(ask(&mut clients[1], &write).code, 0x09);
    let read = frame(0x0C, &[0x00]);
    assert_eq!(ask(&mut clients[1], &read).data, [0x10]);
    assert_eq!(ask(&mut clients[0], &read).data, [0x11]);
    // A second client of node 1 is refused; node 1's own goes on.
    let mut other = TcpStream::connect(&addrs[1]).unwrap();
    other
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let mut said = String::new();
    let _ = other.read_to_string(&mut said);
    assert!(said.contains("busy"), "{said:?}");
    assert_eq!(ask(&mut clients[1], &read).data, [0x10]);
    drop(clients);
    server.interrupt();
}

#[test]
fn serve_on_a_fixed_port_takes_the_ports_above_it() {
    // A free port with a free one above it.
    let (base, _hold) = loop {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = l.local_addr().unwrap().port();
        if port < u16::MAX && std::net::TcpListener::bind(("127.0.0.1", port + 1)).is_ok() {
            drop(l);
            break (port, ());
        }
    };
    let listen = format!("127.0.0.1:{base}");
    let mut server = Server::start(&[
        "--listen", &listen, "--serve", "2", "--nodes", "3", "--peers", "factory",
    ]);
    let addrs = node_addrs(&mut server, 2);
    let peers = server.line_containing("echo what they hear");
    assert!(
        peers.contains("nodes 2-2") && peers.contains("factory MIB"),
        "{peers}"
    );
    assert_eq!(
        addrs,
        [
            format!("127.0.0.1:{base}"),
            format!("127.0.0.1:{}", base + 1)
        ]
    );
    server.interrupt();
}

/// What node 0's host hears back within `wait` when it sends a DL frame
/// on `plm sim --nodes 2 <args>` (node 1 echoes what it hears): the
/// indication's frame, if any.
fn echo_heard(args: &[&str], wait: Duration) -> Option<LocalFrame> {
    use plm_core::st7580::{Command as Cmd, DataRequest, TxParams};
    let mut server = Server::start(&[&["--nodes", "2", "--listen", "127.0.0.1:0"], args].concat());
    let mut c = Client::connect(&server.addr);
    server.line_containing("connected");
    c.send(&[IAC, WILL, COM_PORT]);
    c.expect_telnet("DO COM-PORT-OPTION", |t| {
        *t == Telnet::Negotiation(DO, COM_PORT)
    });
    c.set_rts(false);
    assert_eq!(c.next_frame().code, 0x3E, "BIO_ResetIndication");
    let request = Cmd::DlDataRequest(DataRequest {
        params: TxParams::default(),
        payload: b"echo me".to_vec(),
    })
    .to_frame()
    .emit(Dialect::St7580)
    .unwrap();
    assert_eq!(ask(&mut c, &request).code, 0x51, "DL_DataConfirm");
    let until = Instant::now() + wait;
    let mut heard = None;
    while Instant::now() < until && heard.is_none() {
        c.pump();
        while let Some(e) = c.elements.pop_front() {
            if let Element::Frame { frame, .. } = e {
                c.send_data(&[0x06]);
                if frame.code == 0x52 {
                    heard = Some(frame);
                }
            }
        }
    }
    drop(c);
    server.line_containing("disconnected");
    server.interrupt();
    heard
}

#[test]
fn loss_applies_to_a_line_of_modems() {
    let echo = echo_heard(&[], WAIT).expect("the echo on a line without loss");
    assert!(echo.data.ends_with(b"echo me"), "{echo:?}");
    // Each frame lost at each receiver 99 times in 100: the frame or its
    // echo is lost (both cross 1 time in 10 000).
    assert_eq!(
        echo_heard(&["--loss", "0.99"], Duration::from_secs(2)),
        None
    );
}
