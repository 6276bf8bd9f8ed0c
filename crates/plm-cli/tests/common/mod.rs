//! What the `plm` tests share: the real binary run with arguments and
//! standard input (`plm decode`), or started on a free loopback port
//! (`plm sim`) with a minimal RFC 2217 client written here, independently
//! of the server's codec, so that a codec bug cannot cancel itself out.
//!
//! Timeouts are generous (seconds) so that a loaded machine does not make
//! a test flaky.

// Each test file uses part of this module.
#![allow(dead_code)]

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, ErrorKind, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

pub const IAC: u8 = 255;
pub const WILL: u8 = 251;
pub const WONT: u8 = 252;
pub const DO: u8 = 253;
pub const DONT: u8 = 254;
pub const SB: u8 = 250;
pub const SE: u8 = 240;
pub const BINARY: u8 = 0;
pub const SGA: u8 = 3;
pub const COM_PORT: u8 = 44;

/// RFC 2217 client codes used here (the server answers with code + 100).
pub const SET_CONTROL: u8 = 5;
pub const NOTIFY_MODEMSTATE: u8 = 7;
/// SET-CONTROL values: RTS on and off.
pub const RTS_ON: u8 = 11;
pub const RTS_OFF: u8 = 12;

/// How long any one expected thing may take to come.
pub const WAIT: Duration = Duration::from_secs(10);

/// The running `plm sim` and the lines it prints.
pub struct Server {
    child: Child,
    lines: Receiver<String>,
    /// `host:port` it listens on (the real port, not 0).
    pub addr: String,
    /// The line that named the address.
    pub banner: String,
}

impl Server {
    /// Starts `plm sim <args>` and waits for the address it prints.
    pub fn start(args: &[&str]) -> Server {
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
            banner: String::new(),
        };
        let banner = server.line_containing("rfc2217://");
        server.addr = banner
            .split("rfc2217://")
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .expect("address after rfc2217://")
            .to_string();
        assert!(!server.addr.ends_with(":0"), "port 0 is not the real port");
        server.banner = banner;
        server
    }

    /// Waits for a line of output containing `text`.
    pub fn line_containing(&mut self, text: &str) -> String {
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
    pub fn interrupt(mut self) {
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
pub enum Telnet {
    Negotiation(u8, u8),
    /// A COM-PORT-OPTION subnegotiation: server code and value.
    ComPort(u8, Vec<u8>),
}

/// Data with IAC doubled (RFC 854; RFC 2217 "Data transfer").
pub fn escape(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len());
    for &b in data {
        out.push(b);
        if b == IAC {
            out.push(IAC);
        }
    }
    out
}

/// A COM-PORT-OPTION command from the client (IAC doubled in the value).
pub fn com_port(code: u8, value: &[u8]) -> Vec<u8> {
    let mut out = vec![IAC, SB, COM_PORT, code];
    out.extend(escape(value));
    out.extend([IAC, SE]);
    out
}

/// A minimal RFC 2217 client: the TCP connection with Telnet taken apart.
pub struct Link {
    stream: TcpStream,
    /// Bytes not yet taken apart (a sequence may be split across reads).
    raw: Vec<u8>,
    /// Telnet items not yet looked at.
    pub telnet: VecDeque<Telnet>,
    /// Serial data received (IAC undone) and not yet taken.
    data: Vec<u8>,
}

impl Link {
    /// Connects to `addr`.
    pub fn connect(addr: &str) -> Link {
        let stream = TcpStream::connect(addr).expect("connects");
        stream.set_nodelay(true).unwrap();
        Link {
            stream,
            raw: Vec::new(),
            telnet: VecDeque::new(),
            data: Vec::new(),
        }
    }

    /// Writes bytes as they are (Telnet commands, or data already escaped).
    pub fn send(&mut self, bytes: &[u8]) {
        self.stream.write_all(bytes).unwrap();
    }

    /// Writes serial data, IAC doubled.
    pub fn send_data(&mut self, data: &[u8]) {
        self.send(&escape(data));
    }

    /// Whether serial data is waiting to be taken.
    pub fn has_data(&self) -> bool {
        !self.data.is_empty()
    }

    /// The serial data received so far and not yet taken.
    pub fn take_data(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.data)
    }

    /// Reads what is there (waiting up to `wait`, at least 1 ms) and takes
    /// it apart into Telnet items and serial data.
    pub fn pump(&mut self, wait: Duration) {
        self.stream
            .set_read_timeout(Some(wait.max(Duration::from_millis(1))))
            .unwrap();
        let mut buf = [0u8; 4096];
        match self.stream.read(&mut buf) {
            Ok(0) => panic!("plm sim closed the connection"),
            Ok(n) => self.raw.extend_from_slice(&buf[..n]),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => return,
            Err(e) if e.kind() == ErrorKind::Interrupted => return,
            Err(e) => panic!("read: {e}"),
        }
        let mut i = 0;
        while i < self.raw.len() {
            let rest = &self.raw[i..];
            if rest[0] != IAC {
                self.data.push(rest[0]);
                i += 1;
                continue;
            }
            let Some(&cmd) = rest.get(1) else { break };
            match cmd {
                IAC => {
                    self.data.push(IAC);
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
    }

    /// Waits for the next Telnet item satisfying `want`, skipping others
    /// (they stay queued; serial data stays to be taken).
    pub fn expect_telnet(&mut self, what: &str, want: impl Fn(&Telnet) -> bool) -> Telnet {
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
            self.pump(Duration::from_millis(20));
        }
    }

    /// The server's answer to a COM-PORT command of client code `code`.
    pub fn expect_reply(&mut self, code: u8) -> Vec<u8> {
        match self.expect_telnet(
            &format!("COM-PORT reply {}", code + 100),
            |t| matches!(t, Telnet::ComPort(c, _) if *c == code + 100),
        ) {
            Telnet::ComPort(_, value) => value,
            _ => unreachable!(),
        }
    }

    /// Answers the server's greeting (it offers BINARY, SGA and
    /// COM-PORT-OPTION and asks for BINARY) and waits for the modem-state
    /// notification that follows once COM-PORT-OPTION is agreed.
    pub fn agree(&mut self) {
        self.send(&[
            IAC, DO, BINARY, IAC, DO, SGA, IAC, DO, COM_PORT, IAC, WILL, BINARY,
        ]);
        assert_eq!(
            self.expect_reply(NOTIFY_MODEMSTATE),
            [0x30],
            "NOTIFY-MODEMSTATE: CTS and DSR on"
        );
        assert!(
            !self
                .telnet
                .iter()
                .any(|t| matches!(t, Telnet::Negotiation(WONT | DONT, _))),
            "refused: {:?}",
            self.telnet
        );
    }
}

/// Runs `plm` with `args`, feeding `stdin` when given.
pub fn plm(args: &[&str], stdin: Option<&str>) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("plm runs");
    {
        let mut input = child.stdin.take().unwrap();
        if let Some(text) = stdin {
            input.write_all(text.as_bytes()).unwrap();
        }
    }
    child.wait_with_output().unwrap()
}

/// The JSON lines of a successful `plm` run.
pub fn decode(args: &[&str], stdin: Option<&str>) -> Vec<serde_json::Value> {
    let out = plm(args, stdin);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "plm {args:?} failed: {stderr}");
    assert!(stderr.is_empty(), "unexpected stderr: {stderr}");
    String::from_utf8(out.stdout)
        .expect("UTF-8 output")
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON ({e}): {l}")))
        .collect()
}
