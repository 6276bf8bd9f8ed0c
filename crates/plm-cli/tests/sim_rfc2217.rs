//! `plm sim` end to end: the real binary serving the simulated ST7580 over
//! RFC 2217, driven by a small RFC 2217 client written here (independently
//! of the server's codec, so that a codec bug cannot cancel itself out).
//!
//! Timeouts are generous (seconds) so that a loaded machine does not make
//! the test flaky; the link's own timings (T_ACK 40 ms, T_SR 200 ms) are met
//! by answering at once.

use plm_core::link::{checksum, Dialect, Element, LocalFrame, Source, StreamDecoder, Stx};
use std::collections::VecDeque;
use std::io::{BufRead, BufReader, ErrorKind, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

const IAC: u8 = 255;
const WILL: u8 = 251;
const WONT: u8 = 252;
const DO: u8 = 253;
const DONT: u8 = 254;
const SB: u8 = 250;
const SE: u8 = 240;
const BINARY: u8 = 0;
const SGA: u8 = 3;
const COM_PORT: u8 = 44;

const WAIT: Duration = Duration::from_secs(10);

/// The running `plm sim` and the lines it prints.
struct Server {
    child: Child,
    lines: Receiver<String>,
    addr: String,
}

impl Server {
    fn start(args: &[&str]) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_plm"))
            .arg("sim")
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("plm runs");
        let (tx, lines) = channel();
        let stdout = child.stdout.take().unwrap();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let mut server = Server {
            child,
            lines,
            addr: String::new(),
        };
        let banner = server.line_containing("rfc2217://");
        assert!(banner.contains("simulated ST7580"), "{banner}");
        server.addr = banner
            .split("rfc2217://")
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .expect("address after rfc2217://")
            .to_string();
        assert!(!server.addr.ends_with(":0"), "port 0 is not the real port");
        server
    }

    /// Waits for a line of output containing `text`.
    fn line_containing(&mut self, text: &str) -> String {
        let deadline = Instant::now() + WAIT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) if line.contains(text) => return line,
                Ok(_) => {}
                Err(e) => panic!("no line with {text:?} from plm sim: {e}"),
            }
        }
    }

    /// Stops it as Ctrl-C would; it must exit 0.
    fn interrupt(mut self) {
        let pid = self.child.id().to_string();
        let sent = Command::new("kill").args(["-INT", &pid]).status();
        if !sent.is_ok_and(|s| s.success()) {
            self.child.kill().unwrap();
            return;
        }
        self.line_containing("stopped");
        let status = self.child.wait().unwrap();
        assert!(status.success(), "plm sim exited with {status}");
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// What arrived from the server, Telnet taken apart.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Telnet {
    Negotiation(u8, u8),
    /// A COM-PORT-OPTION subnegotiation: server code and value.
    ComPort(u8, Vec<u8>),
}

/// A minimal RFC 2217 client.
struct Client {
    stream: TcpStream,
    /// Bytes not yet taken apart (a sequence may be split across reads).
    raw: Vec<u8>,
    telnet: VecDeque<Telnet>,
    modem: StreamDecoder,
    elements: VecDeque<Element>,
    /// Every data byte received (IAC undone), for the record.
    data: Vec<u8>,
    /// The last frame received from the modem.
    last_frame: Option<LocalFrame>,
}

impl Client {
    fn connect(addr: &str) -> Client {
        let stream = TcpStream::connect(addr).expect("connects");
        stream.set_nodelay(true).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_millis(20)))
            .unwrap();
        Client {
            stream,
            raw: Vec::new(),
            telnet: VecDeque::new(),
            modem: StreamDecoder::new(Dialect::St7580, Source::Modem),
            elements: VecDeque::new(),
            data: Vec::new(),
            last_frame: None,
        }
    }

    fn send(&mut self, bytes: &[u8]) {
        self.stream.write_all(bytes).unwrap();
    }

    /// Data with IAC doubled.
    fn send_data(&mut self, data: &[u8]) {
        let mut out = Vec::new();
        for &b in data {
            out.push(b);
            if b == IAC {
                out.push(IAC);
            }
        }
        self.send(&out);
    }

    fn com_port(code: u8, value: &[u8]) -> Vec<u8> {
        let mut out = vec![IAC, SB, COM_PORT, code];
        for &b in value {
            out.push(b);
            if b == IAC {
                out.push(IAC);
            }
        }
        out.extend([IAC, SE]);
        out
    }

    /// Reads what is there (waiting up to 20 ms) and takes it apart.
    fn pump(&mut self) {
        let mut buf = [0u8; 4096];
        match self.stream.read(&mut buf) {
            Ok(0) => panic!("plm sim closed the connection"),
            Ok(n) => self.raw.extend_from_slice(&buf[..n]),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => return,
            Err(e) => panic!("read: {e}"),
        }
        let mut data = Vec::new();
        let mut i = 0;
        while i < self.raw.len() {
            let rest = &self.raw[i..];
            if rest[0] != IAC {
                data.push(rest[0]);
                i += 1;
                continue;
            }
            let Some(&cmd) = rest.get(1) else { break };
            match cmd {
                IAC => {
                    data.push(IAC);
                    i += 2;
                }
                WILL | WONT | DO | DONT => {
                    let Some(&option) = rest.get(2) else { break };
                    self.telnet.push_back(Telnet::Negotiation(cmd, option));
                    i += 3;
                }
                SB => {
                    // Find IAC SE, undoing IAC IAC inside.
                    let mut value = Vec::new();
                    let mut j = 2;
                    let mut end = None;
                    while j + 1 < rest.len() {
                        match (rest[j], rest[j + 1]) {
                            (IAC, SE) => {
                                end = Some(j + 2);
                                break;
                            }
                            (IAC, IAC) => {
                                value.push(IAC);
                                j += 2;
                            }
                            (IAC, other) => panic!("IAC {other} inside SB"),
                            (b, _) => {
                                value.push(b);
                                j += 1;
                            }
                        }
                    }
                    let Some(end) = end else { break };
                    assert_eq!(value.first(), Some(&COM_PORT), "SB of another option");
                    assert!(value.len() >= 2, "SB without a command");
                    self.telnet
                        .push_back(Telnet::ComPort(value[1], value[2..].to_vec()));
                    i += end;
                }
                other => panic!("unexpected IAC {other}"),
            }
        }
        self.raw.drain(..i);
        self.data.extend_from_slice(&data);
        self.modem.push(&data);
        while let Some(e) = self.modem.next() {
            self.elements.push_back(e);
        }
    }

    /// Waits for the next Telnet item satisfying `want`, skipping others.
    fn expect_telnet(&mut self, what: &str, want: impl Fn(&Telnet) -> bool) -> Telnet {
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(i) = self.telnet.iter().position(&want) {
                return self.telnet.remove(i).unwrap();
            }
            assert!(
                Instant::now() < deadline,
                "no {what}; got {:?}",
                self.telnet
            );
            self.pump();
        }
    }

    /// The server's answer to a COM-PORT command of client code `code`.
    fn expect_reply(&mut self, code: u8) -> Vec<u8> {
        match self.expect_telnet(
            &format!("COM-PORT reply {}", code + 100),
            |t| matches!(t, Telnet::ComPort(c, _) if *c == code + 100),
        ) {
            Telnet::ComPort(_, value) => value,
            _ => unreachable!(),
        }
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

    fn set_rts(&mut self, on: bool) {
        let value = if on { 11 } else { 12 };
        self.send(&Self::com_port(5, &[value]));
        assert_eq!(self.expect_reply(5), [value], "RTS reply");
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
        out.extend(Self::com_port(5, &[12]));
        for &b in &frame[1..] {
            out.push(b);
            if b == IAC {
                out.push(IAC);
            }
        }
        self.send(&out);
        assert_eq!(self.expect_reply(5), [12], "RTS OFF reply");
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
        !c.telnet
            .iter()
            .any(|t| matches!(t, Telnet::Negotiation(WONT | DONT, _))),
        "refused: {:?}",
        c.telnet
    );

    // SET-BAUDRATE: 57600 is a BR-pin rate; 115200 is not, the answer is
    // the rate in effect; 0 asks for it.
    for (ask, answer) in [(57600u32, 57600u32), (115200, 57600), (0, 57600)] {
        c.send(&Client::com_port(1, &ask.to_be_bytes()));
        assert_eq!(c.expect_reply(1), answer.to_be_bytes(), "baud {ask}");
    }
    c.send(&Client::com_port(2, &[8]));
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
fn st7570_is_not_simulated_yet() {
    let out = Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["sim", "--chip", "st7570", "--listen", "127.0.0.1:0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("not simulated yet"), "{err}");
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
