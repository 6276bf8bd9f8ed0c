//! What the `plm` tests share: the real binary run with arguments and
//! standard input (`plm decode`), or started on a free loopback port
//! (`plm sim`) and reached with `plm board`'s own RFC 2217 client
//! ([`plm_cli::rfc2217::client`], whose parser is written apart from the
//! server's codec, so that a codec bug cannot cancel itself out).
//!
//! Timeouts are generous (seconds) so that a loaded machine does not make
//! a test flaky.

// Each test file uses part of this module.
#![allow(dead_code, unused_imports)]

pub mod latency;
pub mod st7570;

pub use plm_cli::rfc2217::client::{com_port, Client, Telnet};
pub use plm_cli::rfc2217::control::{DTR_OFF, DTR_ON, RTS_OFF, RTS_ON};
pub use plm_cli::rfc2217::escape;
pub use plm_cli::rfc2217::{BINARY, DO, DONT, IAC, SGA, WILL, WONT};
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

pub const COM_PORT: u8 = plm_cli::rfc2217::COM_PORT_OPTION;
/// RFC 2217 client codes used here (the server answers with code + 100).
pub const SET_CONTROL: u8 = plm_cli::rfc2217::cmd::SET_CONTROL;
pub const NOTIFY_MODEMSTATE: u8 = plm_cli::rfc2217::cmd::NOTIFY_MODEMSTATE;

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
        Server::spawn(args, false)
    }

    /// As [`Server::start`], its standard error read too, line by line
    /// among the others (in no set order with them).
    pub fn start_with_stderr(args: &[&str]) -> Server {
        Server::spawn(args, true)
    }

    fn spawn(args: &[&str], stderr: bool) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_plm"))
            .arg("sim")
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(if stderr {
                Stdio::piped()
            } else {
                Stdio::inherit()
            })
            .spawn()
            .expect("plm runs");
        let (tx, lines) = channel();
        let stdout = child.stdout.take().unwrap();
        let tx_err = tx.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        if let Some(err) = child.stderr.take() {
            std::thread::spawn(move || {
                for line in BufReader::new(err).lines() {
                    let Ok(line) = line else { break };
                    if tx_err.send(line).is_err() {
                        break;
                    }
                }
            });
        }
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

    /// The lines up to the first containing `text`, that one included.
    pub fn lines_up_to(&mut self, text: &str) -> Vec<String> {
        let deadline = Instant::now() + WAIT;
        let mut lines = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    let last = line.contains(text);
                    lines.push(line);
                    if last {
                        return lines;
                    }
                }
                Err(e) => panic!("no line with {text:?} from plm sim after {lines:?}: {e}"),
            }
        }
    }

    /// The lines printed so far and not yet looked at (no waiting).
    pub fn lines_so_far(&mut self) -> Vec<String> {
        self.lines.try_iter().collect()
    }

    /// Its process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Whether it is still running (`Err`: how it ended).
    pub fn running(&mut self) -> Result<(), String> {
        match self.child.try_wait() {
            Ok(None) => Ok(()),
            Ok(Some(status)) => Err(format!("plm sim exited with {status}")),
            Err(e) => Err(e.to_string()),
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

/// The RFC 2217 client of `plm board` ([`plm_cli::rfc2217::client`]),
/// whose failures here are test failures: every read also checks that
/// the server sent nothing but negotiations, COM-PORT answers and data.
pub struct Link {
    client: Client,
}

/// `link.telnet` and the other fields and methods of the client.
impl std::ops::Deref for Link {
    type Target = Client;
    fn deref(&self) -> &Client {
        &self.client
    }
}

impl std::ops::DerefMut for Link {
    fn deref_mut(&mut self) -> &mut Client {
        &mut self.client
    }
}

impl Link {
    /// Connects to `addr` (nothing sent).
    pub fn connect(addr: &str) -> Link {
        Link {
            client: Client::connect(addr).expect("connects"),
        }
    }

    /// Writes bytes as they are (Telnet commands, or data already escaped).
    pub fn send(&mut self, bytes: &[u8]) {
        self.client.send(bytes).unwrap();
    }

    /// Writes serial data, IAC doubled.
    pub fn send_data(&mut self, data: &[u8]) {
        self.client.send_data(data).unwrap();
    }

    /// Reads what is there (waiting up to `wait`) and takes it apart.
    pub fn pump(&mut self, wait: Duration) {
        if let Err(e) = self.client.pump(wait) {
            panic!("plm sim: {e}");
        }
        let odd: Vec<&Telnet> = self
            .client
            .telnet
            .iter()
            .filter(|t| matches!(t, Telnet::Command(_) | Telnet::Subnegotiation(..)))
            .collect();
        assert!(odd.is_empty(), "unexpected Telnet from the server: {odd:?}");
    }

    /// Waits for the next Telnet item satisfying `want`, skipping others
    /// (they stay queued; serial data stays to be taken).
    pub fn expect_telnet(&mut self, what: &str, want: impl Fn(&Telnet) -> bool) -> Telnet {
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(i) = self.client.telnet.iter().position(&want) {
                return self.client.telnet.remove(i).unwrap();
            }
            assert!(
                Instant::now() < deadline,
                "no {what}; got {:?}",
                self.client.telnet
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
                .client
                .telnet
                .iter()
                .any(|t| matches!(t, Telnet::Negotiation(WONT | DONT, _))),
            "refused: {:?}",
            self.client.telnet
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
