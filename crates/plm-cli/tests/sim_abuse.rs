//! `plm sim` under abuse: clients that flood it with noise, send
//! malformed Telnet and RFC 2217 subnegotiations, toggle RTS and DTR,
//! read nothing, or drop at once, connecting again and again, while a
//! well-behaved host on the other served node keeps working, and one
//! connects to the abused node after each abuser leaves. Every request of
//! the well-behaved hosts is answered, T_REQ within [`PROMPT`] (what a
//! departed client sent is purged, not fed to the modem); the server
//! never panics, stays within [`MEMORY`], and says in words what it
//! refused, a few lines per client, not one per byte.
//!
//! `cargo test -p plm-cli --test sim_abuse` runs it for [`SHORT`]; the
//! soak of minutes is ignored by default:
//!
//! ```text
//! PLM_SOAK_SECS=300 cargo test -p plm-cli --test sim_abuse -- --ignored --nocapture
//! ```

mod common;

use common::{com_port, Link, Server, WAIT};
use plm_cli::rfc2217::{cmd, control, DO, IAC, SB, SE, WILL};
use plm_core::link::{Dialect, Element, LocalFrame, Source, StreamDecoder, Stx};
use std::collections::VecDeque;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long the run of `cargo xtask test` abuses the server.
const SHORT: Duration = Duration::from_secs(20);
/// Longest wait from T_REQ asserted to the modem's status message.
const PROMPT: Duration = Duration::from_millis(100);
/// Most resident memory the server may use (VmRSS).
const MEMORY: u64 = 64 * 1024 * 1024;
/// Most lines the server may print about one abusive client: connected,
/// disconnected, the first refusal of each kind (ten kinds) and the
/// summary.
const LINES_PER_CLIENT: usize = 13;

/// A reproducible stream of noise (xorshift64).
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// A well-behaved host: an RFC 2217 link and a decoder of what its modem
/// sends, ACKing every frame.
struct Host {
    link: Link,
    modem: StreamDecoder,
    elements: VecDeque<Element>,
}

impl Host {
    /// Connects and agrees COM-PORT-OPTION; `None` while the port is
    /// busy (the previous client not yet gone).
    fn connect(addr: &str) -> Option<Host> {
        let mut link = Link::connect(addr);
        link.pump(Duration::from_millis(200));
        if link.has_data() {
            return None; // "plm sim: busy ..."
        }
        link.agree();
        link.set_rts(false).unwrap();
        link.expect_reply(cmd::SET_CONTROL);
        Some(Host {
            link,
            modem: StreamDecoder::new(Dialect::St7580, Source::Modem),
            elements: VecDeque::new(),
        })
    }

    fn pump(&mut self) {
        if !self.link.has_data() {
            self.link.pump(Duration::from_millis(2));
        }
        self.link.telnet.clear();
        let data = self.link.take_data();
        self.modem.push(&data);
        while let Some(e) = self.modem.next() {
            self.elements.push_back(e);
        }
    }

    /// The next element from the modem within `wait`; frames are ACKed.
    /// A repeat (STX 03h) comes only if our ACK was later than T_ACK (a
    /// loaded machine): it is ACKed and skipped.
    fn next(&mut self, wait: Duration, what: &str) -> Element {
        let deadline = Instant::now() + wait;
        loop {
            if let Some(e) = self.elements.pop_front() {
                if let Element::Frame { frame, .. } = &e {
                    self.link.send_data(&[0x06]);
                    if frame.stx == Stx::Repeat {
                        eprintln!("note: the modem repeated {:02X}h (ACK late)", frame.code);
                        continue;
                    }
                }
                return e;
            }
            assert!(Instant::now() < deadline, "{what}: nothing within {wait:?}");
            self.pump();
        }
    }

    /// T_REQ asserted; returns how long the status message took (a reset
    /// indication before it, after an abuser's DTR, is taken in passing).
    fn t_req(&mut self) -> Duration {
        let asked = Instant::now();
        self.link
            .send(&com_port(cmd::SET_CONTROL, &[control::RTS_ON]));
        loop {
            match self.next(WAIT, "the status message after T_REQ") {
                Element::Status(_) => return asked.elapsed(),
                // What the modem was saying to the previous client (its
                // reset indication, the tail of a frame it repeats for
                // want of that client's ACK) is passed.
                Element::Frame { .. } | Element::Garbage { .. } => {}
                other => panic!("expected the status message, got {other:?}"),
            }
        }
    }

    /// One request: T_REQ, the frame (T_REQ released after its STX,
    /// UM0932 3.2.8), its ACK and the confirm `answer`; returns the
    /// status message's wait.
    fn request(&mut self, code: u8, data: &[u8], answer: u8) -> Duration {
        let took = self.t_req();
        let frame = LocalFrame {
            stx: Stx::First,
            code,
            data: data.to_vec(),
        }
        .emit(Dialect::St7580)
        .unwrap();
        let mut out = vec![frame[0]];
        out.extend(com_port(cmd::SET_CONTROL, &[control::RTS_OFF]));
        out.extend(common::escape(&frame[1..]));
        self.link.send(&out);
        assert_eq!(self.next(WAIT, "the ACK"), Element::Ack, "{code:02X}h");
        loop {
            match self.next(WAIT, "the confirm") {
                Element::Frame { frame, .. } if frame.code == answer => return took,
                // An indication of the modem's own (a reset, a frame it
                // heard) is ACKed and passed.
                Element::Frame { .. } => {}
                other => panic!("expected {answer:02X}h, got {other:?}"),
            }
        }
    }

    /// A ping and a MIB read of the firmware version (UM0932 Table 26),
    /// both answered; the longer status wait.
    fn work(&mut self, n: u8) -> Duration {
        let a = self.request(0x2C, &[n, 0xFF, 0x00, n], 0x2D);
        let b = self.request(0x0C, &[0x0A], 0x0D);
        a.max(b)
    }
}

/// One abusive client at node 0 (`kind` in 0..7); returns the bytes it
/// sent and the address it came from, once it has gone.
fn abuse(addr: &str, kind: u64, noise: &mut Noise) -> (usize, String) {
    let mut s = loop {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(WAIT)).unwrap();
        let mut first = [0u8; 1];
        s.read_exact(&mut first).unwrap();
        if first[0] == IAC {
            break s; // the greeting: served, not told busy
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let me = s.local_addr().unwrap().to_string();
    s.set_write_timeout(Some(Duration::from_secs(2))).unwrap();
    let mut out: Vec<u8> = Vec::new();
    match kind {
        // 200 KB of noise, Telnet commands and all.
        0 => out = noise.bytes(200_000),
        // Noise with RTS, DTR and baud rate changes in between.
        1 => {
            for _ in 0..200 {
                out.extend(noise.bytes(1000));
                let value = [
                    control::RTS_ON,
                    control::RTS_OFF,
                    control::DTR_ON,
                    control::DTR_OFF,
                ][noise.below(4) as usize];
                out.extend(com_port(cmd::SET_CONTROL, &[value]));
                let baud = [0, u32::MAX, 9600, 57600, 12345][noise.below(5) as usize];
                out.extend(com_port(cmd::SET_BAUDRATE, &baud.to_be_bytes()));
            }
        }
        // Malformed Telnet: IAC then no command, a stray SE, an SB that
        // ends in another command, an SB of 2000 bytes, options not
        // served.
        2 => {
            for _ in 0..300 {
                out.extend([IAC, 7, IAC, SE, IAC, SB, 44, 5, IAC, DO, 3]);
                out.extend([IAC, SB, 24]);
                out.extend(noise.bytes(2000).into_iter().filter(|&b| b != IAC));
                out.extend([IAC, SE, IAC, DO, 24, IAC, WILL, 31]);
            }
        }
        // RFC 2217 subnegotiations the port refuses, and a suspended
        // flow never resumed.
        3 => {
            for _ in 0..300 {
                out.extend(com_port(cmd::SET_BAUDRATE, &0u32.to_be_bytes()));
                out.extend(com_port(cmd::SET_BAUDRATE, &u32::MAX.to_be_bytes()));
                out.extend(com_port(cmd::SET_BAUDRATE, &[1, 2]));
                out.extend(com_port(42, &[1, 2, 3]));
                out.extend(com_port(cmd::SET_CONTROL, &[control::BREAK_ON]));
                out.extend(com_port(cmd::SET_CONTROL, &[99]));
                out.extend(com_port(cmd::PURGE_DATA, &[7]));
                out.extend(com_port(cmd::SET_DATASIZE, &[7]));
                out.extend(com_port(cmd::SIGNATURE, &[b'x'; 300]));
                out.extend(com_port(cmd::FLOWCONTROL_SUSPEND, &[]));
            }
        }
        // Escapes only: 100 KB of IAC IAC, data 255 for the modem.
        4 => out = vec![IAC; 200_000],
        // Requests that each bring an answer, never read, until the
        // server drops the client (the answers fill the kernel's buffers
        // first, some megabytes).
        5 => {
            let asks: Vec<u8> = (0..10_000)
                .flat_map(|_| com_port(cmd::SIGNATURE, &[]))
                .collect();
            let mut sent = 0;
            while sent < 20_000_000 && s.write_all(&asks).is_ok() {
                sent += asks.len();
            }
            return (sent, me);
        }
        // Gone at once, after other clients tried the busy port.
        _ => {
            for _ in 0..3 {
                let mut other = TcpStream::connect(addr).unwrap();
                other.set_read_timeout(Some(WAIT)).unwrap();
                let mut said = String::new();
                let _ = other.read_to_string(&mut said);
                assert!(said.contains("busy"), "{said:?}");
            }
        }
    }
    let mut sent = 0;
    for chunk in out.chunks(8192) {
        if s.write_all(chunk).is_err() {
            break; // dropped by the server (it read nothing, say)
        }
        sent += chunk.len();
    }
    drop(s);
    (sent, me)
}

/// VmRSS of process `pid`, bytes.
fn rss(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("VmRSS in /proc/PID/status");
    kb * 1024
}

/// Takes `server`'s lines until one contains `text`, keeping them all.
fn until(server: &mut Server, log: &mut Vec<String>, text: &str) {
    let lines = server.lines_up_to(text);
    log.extend(lines);
}

/// Abuses node 0 of `plm sim --serve 2` for `length`, a host on node 1
/// working all the while and one on node 0 after each abuser; prints
/// the figures.
fn soak(length: Duration) {
    let mut server = Server::start_with_stderr(&[
        "--chip",
        "st7580",
        "--listen",
        "127.0.0.1:0",
        "--serve",
        "2",
        "--nodes",
        "2",
    ]);
    let addrs: Vec<String> = (0..2)
        .map(|i| {
            let line = server.line_containing(&format!("node {i} on rfc2217://"));
            line.split("rfc2217://").nth(1).unwrap().trim().to_string()
        })
        .collect();
    let mut log = Vec::new();
    let mut steady = Host::connect(&addrs[1]).expect("node 1 free");
    let reset = steady.next(WAIT, "BIO_ResetIndication");
    assert!(
        matches!(&reset, Element::Frame { frame, .. } if frame.code == 0x3E),
        "{reset:?}"
    );
    let start = Instant::now();
    let mut noise = Noise(0x2917_2217);
    let (mut abusers, mut busy, mut bytes, mut answered) = (0usize, 0usize, 0usize, 0usize);
    // The longest T_REQ waits: node 1's while node 0 is abused, node 0's
    // after.
    let (mut worst_during, mut worst_after, mut peak) = (Duration::ZERO, Duration::ZERO, 0u64);
    while start.elapsed() < length {
        let kind = abusers as u64 % 7;
        let seed = noise.next();
        let addr = addrs[0].clone();
        let done = Arc::new(AtomicBool::new(false));
        let flag = done.clone();
        let abuser = std::thread::spawn(move || {
            let got = abuse(&addr, kind, &mut Noise(seed | 1));
            flag.store(true, Ordering::SeqCst);
            got
        });
        // Node 1's host works while node 0 is abused.
        let mut n = 0u8;
        while !done.load(Ordering::SeqCst) || n == 0 {
            let took = steady.work(n);
            assert!(took <= PROMPT, "node 1: T_REQ answered after {took:?}");
            worst_during = worst_during.max(took);
            answered += 2;
            n = n.wrapping_add(1);
        }
        let (sent, who) = abuser.join().expect("the abuser ran");
        abusers += 1;
        bytes += sent;
        if kind == 6 {
            busy += 3;
        }
        until(&mut server, &mut log, &format!("client {who} disconnected"));
        // Node 0's next host is served at once: nothing of the abuser's
        // reaches its modem.
        let mut next = loop {
            if let Some(h) = Host::connect(&addrs[0]) {
                break h;
            }
        };
        let took = next.work(kind as u8);
        assert!(
            took <= PROMPT,
            "node 0 after abuser {abusers} (kind {kind}, {sent} bytes): T_REQ answered \
             after {took:?}"
        );
        worst_after = worst_after.max(took);
        answered += 2;
        // A host that goes lets its last bytes (the ACK) drain first:
        // what is still on the way when it closes is purged.
        std::thread::sleep(Duration::from_millis(5));
        drop(next);
        // The only other client to go: node 1's stays.
        until(&mut server, &mut log, "disconnected");
        peak = peak.max(rss(server.pid()));
        assert!(peak <= MEMORY, "plm sim uses {} KiB", peak / 1024);
        server.running().unwrap();
    }
    std::thread::sleep(Duration::from_millis(200));
    log.extend(server.lines_so_far());
    let panicked: Vec<&String> = log.iter().filter(|l| l.contains("panick")).collect();
    assert!(panicked.is_empty(), "{panicked:?}");
    // In words, once per kind and client, and summed up.
    for words in [
        "refused SET-BAUDRATE 4294967295",
        "refused IAC followed by 7",
        "refused RFC 2217 command 1 with 2 value bytes",
        "the simulated UART's transmit buffer holds 4096 bytes",
        "it reads nothing",
        "refused, in all:",
    ] {
        assert!(
            log.iter().any(|l| l.contains(words)),
            "no line with {words:?} in {} lines",
            log.len()
        );
    }
    let clients = abusers * 2 + busy + 1;
    assert!(
        log.len() <= clients * LINES_PER_CLIENT,
        "{} lines for {clients} clients",
        log.len()
    );
    println!(
        "plm sim under abuse: {} s, {abusers} abusive clients ({} busy refusals among them), \
         {bytes} bytes of abuse, {answered} requests of the well-behaved hosts all answered \
         (T_REQ within {} ms at worst during the abuse, {} ms after it), peak VmRSS {} KiB, \
         {} lines of log",
        start.elapsed().as_secs(),
        busy,
        worst_during.as_millis(),
        worst_after.as_millis(),
        peak / 1024,
        log.len()
    );
    drop(steady);
    server.interrupt();
}

#[test]
fn plm_sim_keeps_serving_while_abused() {
    soak(SHORT);
}

/// The soak of minutes: `PLM_SOAK_SECS` (300 by default).
#[test]
#[ignore = "minutes long: PLM_SOAK_SECS=300 cargo test -p plm-cli --test sim_abuse -- --ignored"]
fn plm_sim_soak_for_minutes() {
    let secs = std::env::var("PLM_SOAK_SECS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    soak(Duration::from_secs(secs));
}
