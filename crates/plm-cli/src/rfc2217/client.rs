//! The client side of RFC 2217 (Telnet COM-PORT-OPTION) over a TCP
//! connection: what `plm board --port rfc2217://HOST:PORT` talks through,
//! and what the tests of `plm sim` drive the server with.
//!
//! What comes from the server is taken apart here, by code written apart
//! from the server's [`super::Decoder`], so that a bug in one cannot
//! cancel itself out in the tests; only the constants and [`super::escape`]
//! (whose output each side's own parser checks) are shared.
//!
//! - [`Client::connect`] only opens the connection: the tests write
//!   Telnet by hand with [`Client::send`] and read it back as [`Telnet`]
//!   items with [`Client::pump`].
//! - [`Client::open`] is what a tool wants: the connection, the options
//!   agreed (BINARY, SUPPRESS-GO-AHEAD, COM-PORT-OPTION), the port set to
//!   a baud rate and 8N1, RTS off; then [`Client::read_data`] and
//!   [`Client::send_data`] move serial data (IAC doubled, RFC 854) and
//!   [`Client::set_rts`] drives RTS (SET-CONTROL 11/12), [`Client::set_dtr`]
//!   DTR (SET-CONTROL 8/9).

use super::{
    cmd, control, escape, BINARY, COM_PORT_OPTION, DO, DONT, IAC, SB, SE, SGA, WILL, WONT,
};
use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

/// The server code of a COM-PORT command: the client code plus 100
/// (RFC 2217 "Access Server to Client").
pub const fn reply_code(client_code: u8) -> u8 {
    client_code + super::SERVER_OFFSET
}

/// Something Telnet that came from the server.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Telnet {
    /// `IAC WILL/WONT/DO/DONT option` (RFC 854): the verb and the option.
    Negotiation(u8, u8),
    /// A COM-PORT-OPTION subnegotiation: the server code and its value,
    /// IAC doubling undone.
    ComPort(u8, Vec<u8>),
    /// A subnegotiation of another option: the option and its bytes.
    Subnegotiation(u8, Vec<u8>),
    /// Another Telnet command (`IAC NOP`, `IAC GA`, ...), or an `IAC x`
    /// inside a subnegotiation that ended it.
    Command(u8),
}

/// A COM-PORT-OPTION command from the client, value escaped (RFC 2217).
pub fn com_port(code: u8, value: &[u8]) -> Vec<u8> {
    let mut out = vec![IAC, SB, COM_PORT_OPTION, code];
    out.extend(escape(value));
    out.extend([IAC, SE]);
    out
}

/// A Telnet subnegotiation longer than this is cut (no COM-PORT reply
/// needs more; a server cannot make us buffer forever).
const MAX_SB: usize = 1024;

/// How long [`Client::open`] waits for each answer of the server.
pub const NEGOTIATION_WAIT: Duration = Duration::from_secs(5);

/// Options we accept, either way.
fn supported(option: u8) -> bool {
    matches!(option, BINARY | SGA | COM_PORT_OPTION)
}

/// One direction of one option (RFC 854 "General considerations":
/// acknowledge only a change, so that no negotiation loop can start).
#[derive(Debug, Clone, Copy, Default)]
struct Side {
    enabled: bool,
    /// We asked (WILL or DO) and wait for the answer.
    requested: bool,
}

/// An RFC 2217 connection, Telnet taken apart.
#[derive(Debug)]
pub struct Client {
    stream: TcpStream,
    /// Bytes not yet taken apart (a sequence may be split across reads).
    raw: Vec<u8>,
    /// Telnet items not yet looked at.
    pub telnet: VecDeque<Telnet>,
    /// Serial data received (IAC undone) and not yet taken.
    data: Vec<u8>,
    /// Whether negotiations are answered as they come ([`Client::open`]
    /// turns it on; the tests that write Telnet by hand leave it off).
    answer: bool,
    /// Per option: whether we do it, and whether the server does.
    us: [Side; 256],
    him: [Side; 256],
}

impl Client {
    /// Opens the TCP connection to `addr` (`host:port`), nothing sent.
    pub fn connect(addr: &str) -> io::Result<Client> {
        let mut last = io::Error::new(ErrorKind::NotFound, "the name resolves to no address");
        for a in addr.to_socket_addrs()? {
            match TcpStream::connect_timeout(&a, NEGOTIATION_WAIT) {
                Ok(stream) => {
                    // Bytes go out as they come: Nagle's delay would eat
                    // the modem's T_ACK (40 ms, UM0932 3.2.7).
                    stream.set_nodelay(true)?;
                    stream.set_write_timeout(Some(NEGOTIATION_WAIT))?;
                    return Ok(Client {
                        stream,
                        raw: Vec::new(),
                        telnet: VecDeque::new(),
                        data: Vec::new(),
                        answer: false,
                        us: [Side::default(); 256],
                        him: [Side::default(); 256],
                    });
                }
                Err(e) => last = e,
            }
        }
        Err(last)
    }

    /// Connects to `addr` and makes it a serial port: BINARY both ways,
    /// SUPPRESS-GO-AHEAD and COM-PORT-OPTION agreed (RFC 2217 "Telnet
    /// negotiation"), then `baud`, 8 data bits, no parity, 1 stop bit, no
    /// flow control, RTS off. Fails in words when the server is no RFC
    /// 2217 server, refuses the option, or runs the port at another rate.
    pub fn open(addr: &str, baud: u32) -> io::Result<Client> {
        let mut c = Client::connect(addr)?;
        c.answer = true;
        let mut hello = Vec::new();
        for option in [BINARY, SGA, COM_PORT_OPTION] {
            c.us[option as usize].requested = true;
            hello.extend([IAC, WILL, option]);
        }
        for option in [BINARY, SGA] {
            c.him[option as usize].requested = true;
            hello.extend([IAC, DO, option]);
        }
        c.send(&hello)?;
        let deadline = Instant::now() + NEGOTIATION_WAIT;
        // The server agrees with DO COM-PORT-OPTION (its own WILL is an
        // offer, which we take too).
        loop {
            let side = c.us[COM_PORT_OPTION as usize];
            if side.enabled {
                break;
            }
            if !side.requested {
                return Err(io::Error::other(
                    "the server refuses COM-PORT-OPTION: it is not an RFC 2217 serial port server \
                     (ser2net needs 'telnet(rfc2217)' in its connection)",
                ));
            }
            c.wait_for(deadline, "agree to COM-PORT-OPTION")?;
        }
        let mut setup = com_port(cmd::SET_BAUDRATE, &baud.to_be_bytes());
        setup.extend(com_port(cmd::SET_DATASIZE, &[8]));
        // Parity 1 = NONE, stop size 1 = one bit.
        setup.extend(com_port(cmd::SET_PARITY, &[1]));
        setup.extend(com_port(cmd::SET_STOPSIZE, &[1]));
        setup.extend(com_port(cmd::SET_CONTROL, &[control::FLOW_NONE]));
        setup.extend(com_port(cmd::SET_CONTROL, &[control::RTS_OFF]));
        c.send(&setup)?;
        let deadline = Instant::now() + NEGOTIATION_WAIT;
        let rate = loop {
            let code = reply_code(cmd::SET_BAUDRATE);
            if let Some(i) = c
                .telnet
                .iter()
                .position(|t| matches!(t, Telnet::ComPort(c, _) if *c == code))
            {
                match c.telnet.remove(i) {
                    Some(Telnet::ComPort(_, v)) if v.len() == 4 => {
                        break u32::from_be_bytes([v[0], v[1], v[2], v[3]])
                    }
                    _ => {
                        return Err(io::Error::other(
                            "the server's answer to SET-BAUDRATE is not 4 bytes",
                        ))
                    }
                }
            }
            c.wait_for(deadline, "answer SET-BAUDRATE")?;
        };
        if rate != baud {
            return Err(io::Error::other(format!(
                "the server runs the port at {rate} baud and would not change to {baud} \
                 (try --baud {rate})"
            )));
        }
        // The answers to the rest are of no interest.
        c.telnet.clear();
        Ok(c)
    }

    /// Waits for more from the server until `deadline`, then fails saying
    /// what it did not do (and what it said instead, if it said anything).
    fn wait_for(&mut self, deadline: Instant, what: &str) -> io::Result<()> {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(io::Error::new(
                ErrorKind::TimedOut,
                format!(
                    "the server did not {what} within {} s: is it an RFC 2217 server?{}",
                    NEGOTIATION_WAIT.as_secs(),
                    self.said()
                ),
            ));
        }
        self.pump(left.min(Duration::from_millis(50)))
            .map_err(|e| io::Error::new(e.kind(), format!("{e}{}", self.said())))
    }

    /// What the server sent as data during the negotiation, as text (a
    /// busy server says why before it closes).
    fn said(&self) -> String {
        let text: String = String::from_utf8_lossy(&self.data)
            .chars()
            .filter(|c| !c.is_control())
            .collect();
        if text.trim().is_empty() {
            String::new()
        } else {
            format!(" (it said: \"{}\")", text.trim())
        }
    }

    /// Writes bytes as they are (Telnet commands, or data escaped).
    pub fn send(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)
    }

    /// Writes serial data, IAC doubled.
    pub fn send_data(&mut self, data: &[u8]) -> io::Result<()> {
        self.send(&escape(data))
    }

    /// Sets RTS (SET-CONTROL 11 on, 12 off). The server's answer is
    /// taken by a later read.
    pub fn set_rts(&mut self, on: bool) -> io::Result<()> {
        let value = if on {
            control::RTS_ON
        } else {
            control::RTS_OFF
        };
        self.send(&com_port(cmd::SET_CONTROL, &[value]))
    }

    /// Sets DTR (SET-CONTROL 8 on, 9 off): on a port whose DTR is wired
    /// to the modem's RESETN (`plm sim`, many USB-UART boards), on holds
    /// the modem in reset and off lets it boot. The server's answer is
    /// taken by a later read.
    pub fn set_dtr(&mut self, on: bool) -> io::Result<()> {
        let value = if on {
            control::DTR_ON
        } else {
            control::DTR_OFF
        };
        self.send(&com_port(cmd::SET_CONTROL, &[value]))
    }

    /// Whether serial data is waiting to be taken.
    pub fn has_data(&self) -> bool {
        !self.data.is_empty()
    }

    /// The serial data received so far and not yet taken.
    pub fn take_data(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.data)
    }

    /// Serial data: what is there, or what comes within `wait`. Telnet
    /// items are answered (negotiations) or dropped (COM-PORT answers
    /// and notifications).
    pub fn read_data(&mut self, wait: Duration) -> io::Result<Vec<u8>> {
        if self.data.is_empty() {
            self.pump(wait)?;
        }
        self.telnet.clear();
        Ok(self.take_data())
    }

    /// Reads what is there, waiting up to `wait` (at least 1 ms), and
    /// takes it apart into Telnet items and serial data. A closed
    /// connection is an error.
    pub fn pump(&mut self, wait: Duration) -> io::Result<()> {
        self.stream
            .set_read_timeout(Some(wait.max(Duration::from_millis(1))))?;
        let mut buf = [0u8; 4096];
        match self.stream.read(&mut buf) {
            Ok(0) => {
                return Err(io::Error::new(
                    ErrorKind::UnexpectedEof,
                    "the server closed the connection",
                ))
            }
            Ok(n) => self.raw.extend_from_slice(&buf[..n]),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Ok(())
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => return Ok(()),
            Err(e) => return Err(e),
        }
        let before = self.telnet.len();
        let used = self.parse();
        self.raw.drain(..used);
        if self.answer {
            self.answer_negotiations(before)?;
        }
        Ok(())
    }

    /// Takes apart as much of `raw` as is complete; returns the bytes used.
    fn parse(&mut self) -> usize {
        let mut i = 0;
        while i < self.raw.len() {
            let rest = &self.raw[i..];
            if rest[0] != IAC {
                // A run of data up to the next IAC.
                let n = rest.iter().position(|&b| b == IAC).unwrap_or(rest.len());
                self.data.extend_from_slice(&rest[..n]);
                i += n;
                continue;
            }
            let Some(&verb) = rest.get(1) else { break };
            match verb {
                IAC => {
                    self.data.push(IAC);
                    i += 2;
                }
                WILL | WONT | DO | DONT => {
                    let Some(&option) = rest.get(2) else { break };
                    self.telnet.push_back(Telnet::Negotiation(verb, option));
                    i += 3;
                }
                SB => {
                    // Up to IAC SE, IAC IAC undone; another IAC x ends it
                    // there (a broken subnegotiation), x read as a command.
                    let mut value = Vec::new();
                    let mut j = 2;
                    let end = loop {
                        match (rest.get(j), rest.get(j + 1)) {
                            (Some(&IAC), Some(&SE)) => break Some(j + 2),
                            (Some(&IAC), Some(&IAC)) => {
                                if value.len() < MAX_SB {
                                    value.push(IAC);
                                }
                                j += 2;
                            }
                            (Some(&IAC), Some(_)) => break Some(j),
                            (Some(&IAC), None) | (None, _) => break None,
                            (Some(&b), _) => {
                                if value.len() < MAX_SB {
                                    value.push(b);
                                }
                                j += 1;
                            }
                        }
                    };
                    let Some(end) = end else { break };
                    self.telnet.push_back(match value.split_first() {
                        Some((&COM_PORT_OPTION, [code, v @ ..])) => {
                            Telnet::ComPort(*code, v.to_vec())
                        }
                        Some((&option, v)) => Telnet::Subnegotiation(option, v.to_vec()),
                        None => Telnet::Subnegotiation(0, Vec::new()),
                    });
                    i += end;
                }
                other => {
                    self.telnet.push_back(Telnet::Command(other));
                    i += 2;
                }
            }
        }
        i
    }

    /// Answers the server's negotiations queued from `from` on: accept
    /// what we support, refuse the rest, confirm nothing twice.
    fn answer_negotiations(&mut self, from: usize) -> io::Result<()> {
        let mut reply = Vec::new();
        for t in self.telnet.iter().skip(from) {
            let Telnet::Negotiation(verb, option) = *t else {
                continue;
            };
            let on = matches!(verb, WILL | DO);
            // DO/DONT are about what we do; WILL/WONT about the server.
            let (side, yes, no) = if matches!(verb, DO | DONT) {
                (&mut self.us[option as usize], WILL, WONT)
            } else {
                (&mut self.him[option as usize], DO, DONT)
            };
            let requested = std::mem::take(&mut side.requested);
            if on && !supported(option) {
                reply.extend([IAC, no, option]);
                continue;
            }
            if side.enabled == on {
                continue;
            }
            side.enabled = on;
            // The answer to our own request needs no answer (RFC 854).
            if !requested {
                reply.extend([IAC, if on { yes } else { no }, option]);
            }
        }
        if reply.is_empty() {
            Ok(())
        } else {
            self.send(&reply)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    /// A client and the server end of its connection.
    fn pair() -> (Client, TcpStream) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let client = Client::connect(&addr).unwrap();
        let (server, _) = listener.accept().unwrap();
        (client, server)
    }

    /// Reads until `n` data bytes and `items` Telnet items came.
    fn read_all(c: &mut Client, n: usize, items: usize) {
        let deadline = Instant::now() + Duration::from_secs(5);
        while c.data.len() < n || c.telnet.len() < items {
            assert!(Instant::now() < deadline, "{:?} {:?}", c.data, c.telnet);
            c.pump(Duration::from_millis(10)).unwrap();
        }
    }

    #[test]
    fn every_split_of_a_stream_gives_the_same_items() {
        let stream: Vec<u8> = [
            &[0x02, IAC, IAC, 0x05][..],
            &[IAC, WILL, COM_PORT_OPTION, IAC, DONT, 1],
            // SET-BAUDRATE's answer, 57600 = 0000E100h, and a value
            // byte FFh doubled.
            &[IAC, SB, COM_PORT_OPTION, 101, 0, 0, 0xE1, 0, IAC, SE],
            &[IAC, SB, COM_PORT_OPTION, 105, IAC, IAC, IAC, SE],
            &[IAC, 241, 0x06], // NOP, then data
        ]
        .concat();
        let want_items = vec![
            Telnet::Negotiation(WILL, COM_PORT_OPTION),
            Telnet::Negotiation(DONT, 1),
            Telnet::ComPort(101, vec![0, 0, 0xE1, 0]),
            Telnet::ComPort(105, vec![IAC]),
            Telnet::Command(241),
        ];
        for split in 0..=stream.len() {
            let (mut c, mut server) = pair();
            server.write_all(&stream[..split]).unwrap();
            server.flush().unwrap();
            std::thread::sleep(Duration::from_millis(2));
            c.pump(Duration::from_millis(10)).unwrap();
            server.write_all(&stream[split..]).unwrap();
            read_all(&mut c, 4, want_items.len());
            assert_eq!(c.take_data(), [0x02, IAC, 0x05, 0x06], "split at {split}");
            assert_eq!(Vec::from(c.telnet.clone()), want_items, "split at {split}");
        }
    }

    #[test]
    fn a_broken_subnegotiation_ends_at_the_next_command() {
        let (mut c, mut server) = pair();
        server
            .write_all(&[IAC, SB, COM_PORT_OPTION, 107, 0x30, IAC, WILL, SGA, 0x41])
            .unwrap();
        read_all(&mut c, 1, 2);
        assert_eq!(
            Vec::from(c.telnet.clone()),
            [
                Telnet::ComPort(107, vec![0x30]),
                Telnet::Negotiation(WILL, SGA)
            ]
        );
        assert_eq!(c.take_data(), [0x41]);
    }

    /// Once negotiating, the client accepts what it supports, refuses the
    /// rest, and never confirms its own requests (no loop can start).
    #[test]
    fn negotiations_are_answered_once() {
        let (mut c, mut server) = pair();
        c.answer = true;
        c.us[BINARY as usize].requested = true;
        server
            .write_all(&[IAC, DO, BINARY, IAC, WILL, SGA, IAC, DO, 1, IAC, WILL, SGA])
            .unwrap();
        read_all(&mut c, 0, 4);
        server
            .set_read_timeout(Some(Duration::from_millis(300)))
            .unwrap();
        let mut got = Vec::new();
        let mut buf = [0u8; 64];
        while let Ok(n) = server.read(&mut buf) {
            if n == 0 {
                break;
            }
            got.extend_from_slice(&buf[..n]);
        }
        // DO BINARY answered our WILL: nothing; WILL SGA: DO SGA once;
        // DO ECHO: WONT ECHO.
        assert_eq!(got, [IAC, DO, SGA, IAC, WONT, 1]);
    }

    /// RTS and DTR as RFC 2217 SET-CONTROL (command 5) values: RTS
    /// 11/12, DTR 8/9.
    #[test]
    fn rts_and_dtr_are_set_control_commands() {
        let (mut c, mut server) = pair();
        c.set_dtr(true).unwrap();
        c.set_dtr(false).unwrap();
        c.set_rts(true).unwrap();
        c.set_rts(false).unwrap();
        let mut got = vec![0u8; 4 * 7];
        server.read_exact(&mut got).unwrap();
        let want: Vec<u8> = [8, 9, 11, 12]
            .iter()
            .flat_map(|&v| [IAC, SB, COM_PORT_OPTION, 5, v, IAC, SE])
            .collect();
        assert_eq!(got, want);
    }

    #[test]
    fn a_closed_connection_is_an_error() {
        let (mut c, server) = pair();
        drop(server);
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            match c.pump(Duration::from_millis(10)) {
                Err(e) => {
                    assert_eq!(e.kind(), ErrorKind::UnexpectedEof);
                    break;
                }
                Ok(()) => assert!(Instant::now() < deadline),
            }
        }
    }
}
