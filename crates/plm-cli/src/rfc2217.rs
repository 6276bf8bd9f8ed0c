//! The server side of RFC 2217 (Telnet COM-PORT-OPTION) as a pure state
//! machine: no sockets, no clock, no simulator.
//!
//! - [`Decoder`] turns the bytes a client sends into [`Event`]s: data with
//!   doubled IAC undone (RFC 854 "The TELNET command structure"), option
//!   negotiation (RFC 854/855), and COM-PORT-OPTION subnegotiations (RFC 2217
//!   "Client to Access Server"). Sequences may be split across reads anywhere.
//! - [`Server`] answers them: it negotiates BINARY (RFC 856), SUPPRESS-GO-AHEAD
//!   (RFC 858) and COM-PORT-OPTION, replies to every COM-PORT command with
//!   the server code (client code + 100, RFC 2217 "Access Server to Client")
//!   and tells its driver what to do with the serial port as [`Action`]s.
//! - [`escape`] doubles IAC in data going to the client.
//!
//! The connection is treated as binary both ways whatever the client agreed
//! to: the bytes of the modem's host interface are not text, and neither
//! pyserial nor telnet(1) in binary mode applies NVT CR rules.
//!
//! [`client`] is the other side: what `plm board` and the tests connect
//! with.

pub mod client;
pub mod refusal;

pub use refusal::{Malformed, Refusal, Tally};

/// Interpret As Command (RFC 854).
pub const IAC: u8 = 255;
/// Negotiation commands (RFC 854).
pub const DONT: u8 = 254;
pub const DO: u8 = 253;
pub const WONT: u8 = 252;
pub const WILL: u8 = 251;
/// Subnegotiation begin and end (RFC 855).
pub const SB: u8 = 250;
pub const SE: u8 = 240;

/// Options (RFC 856 BINARY, RFC 857 ECHO, RFC 858 SUPPRESS-GO-AHEAD,
/// RFC 2217 COM-PORT-OPTION).
pub const BINARY: u8 = 0;
pub const ECHO: u8 = 1;
pub const SGA: u8 = 3;
pub const COM_PORT_OPTION: u8 = 44;

/// The server code of a COM-PORT command is the client code plus this
/// (RFC 2217 "Access Server to Client").
pub const SERVER_OFFSET: u8 = 100;

/// COM-PORT-OPTION command codes as the client sends them (RFC 2217).
pub mod cmd {
    pub const SIGNATURE: u8 = 0;
    pub const SET_BAUDRATE: u8 = 1;
    pub const SET_DATASIZE: u8 = 2;
    pub const SET_PARITY: u8 = 3;
    pub const SET_STOPSIZE: u8 = 4;
    pub const SET_CONTROL: u8 = 5;
    pub const NOTIFY_LINESTATE: u8 = 6;
    pub const NOTIFY_MODEMSTATE: u8 = 7;
    pub const FLOWCONTROL_SUSPEND: u8 = 8;
    pub const FLOWCONTROL_RESUME: u8 = 9;
    pub const SET_LINESTATE_MASK: u8 = 10;
    pub const SET_MODEMSTATE_MASK: u8 = 11;
    pub const PURGE_DATA: u8 = 12;
}

/// SET-CONTROL values (RFC 2217 "SET-CONTROL").
pub mod control {
    pub const FLOW_QUERY: u8 = 0;
    pub const FLOW_NONE: u8 = 1;
    pub const BREAK_QUERY: u8 = 4;
    pub const BREAK_ON: u8 = 5;
    pub const BREAK_OFF: u8 = 6;
    pub const DTR_QUERY: u8 = 7;
    pub const DTR_ON: u8 = 8;
    pub const DTR_OFF: u8 = 9;
    pub const RTS_QUERY: u8 = 10;
    pub const RTS_ON: u8 = 11;
    pub const RTS_OFF: u8 = 12;
    pub const INBOUND_FLOW_QUERY: u8 = 13;
    pub const INBOUND_FLOW_NONE: u8 = 14;
}

/// A subnegotiation longer than this is cut (its tail is dropped): no
/// COM-PORT command needs more, and a client cannot make us buffer forever.
pub const MAX_SB: usize = 256;

/// What the client sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// Data for the serial port, IAC doubling undone.
    Data(Vec<u8>),
    /// `IAC WILL/WONT/DO/DONT option` (RFC 854).
    Will(u8),
    Wont(u8),
    Do(u8),
    Dont(u8),
    /// Another Telnet command (`IAC NOP`, `IAC BRK`, `IAC AYT`, ...).
    Command(u8),
    /// A COM-PORT-OPTION subnegotiation (RFC 2217).
    ComPort(ComPort),
    /// A subnegotiation of another option (RFC 855), unescaped.
    Subnegotiation {
        option: u8,
        data: Vec<u8>,
    },
    /// Telnet that breaks RFC 854/855, read past as described.
    Malformed(Malformed),
}

/// A COM-PORT-OPTION command from the client (RFC 2217). Zero values are
/// queries where the RFC says so.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ComPort {
    /// The client's signature, or (empty) a request for ours.
    Signature(Vec<u8>),
    /// Baud rate, 4 bytes big-endian; 0 asks the current one.
    SetBaudRate(u32),
    /// 0 query, 5..=8 bits.
    SetDataSize(u8),
    /// 0 query, 1 NONE, 2 ODD, 3 EVEN, 4 MARK, 5 SPACE.
    SetParity(u8),
    /// 0 query, 1 one, 2 two, 3 one and a half.
    SetStopSize(u8),
    /// Flow control, BREAK, DTR and RTS (see [`control`]).
    SetControl(u8),
    /// Not a client command in the RFC; pyserial sends these to poll the
    /// states, and we answer with the current state.
    NotifyLineState(u8),
    NotifyModemState(u8),
    FlowControlSuspend,
    FlowControlResume,
    SetLineStateMask(u8),
    SetModemStateMask(u8),
    /// 1 receive buffer, 2 transmit buffer, 3 both.
    PurgeData(u8),
    /// A command we do not know, or a known one with the wrong length.
    Unknown {
        code: u8,
        data: Vec<u8>,
    },
}

impl ComPort {
    /// Reads the bytes after `IAC SB COM-PORT-OPTION` (unescaped, before
    /// `IAC SE`).
    pub fn parse(sb: &[u8]) -> ComPort {
        let unknown = || ComPort::Unknown {
            code: sb.first().copied().unwrap_or(0),
            data: sb.get(1..).unwrap_or_default().to_vec(),
        };
        let Some((&code, data)) = sb.split_first() else {
            return unknown();
        };
        let byte = |f: fn(u8) -> ComPort| match data {
            [b] => f(*b),
            _ => unknown(),
        };
        match code {
            cmd::SIGNATURE => ComPort::Signature(data.to_vec()),
            cmd::SET_BAUDRATE => match data {
                [a, b, c, d] => ComPort::SetBaudRate(u32::from_be_bytes([*a, *b, *c, *d])),
                _ => unknown(),
            },
            cmd::SET_DATASIZE => byte(ComPort::SetDataSize),
            cmd::SET_PARITY => byte(ComPort::SetParity),
            cmd::SET_STOPSIZE => byte(ComPort::SetStopSize),
            cmd::SET_CONTROL => byte(ComPort::SetControl),
            // A poll may come with or without a (meaningless) value byte.
            cmd::NOTIFY_LINESTATE => ComPort::NotifyLineState(data.first().copied().unwrap_or(0)),
            cmd::NOTIFY_MODEMSTATE => ComPort::NotifyModemState(data.first().copied().unwrap_or(0)),
            cmd::FLOWCONTROL_SUSPEND if data.is_empty() => ComPort::FlowControlSuspend,
            cmd::FLOWCONTROL_RESUME if data.is_empty() => ComPort::FlowControlResume,
            cmd::SET_LINESTATE_MASK => byte(ComPort::SetLineStateMask),
            cmd::SET_MODEMSTATE_MASK => byte(ComPort::SetModemStateMask),
            cmd::PURGE_DATA => byte(ComPort::PurgeData),
            _ => unknown(),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Data,
    /// After IAC.
    Iac,
    /// After IAC WILL/WONT/DO/DONT: the option byte comes next.
    Negotiation(u8),
    /// After IAC SB: the option byte comes next.
    SbOption,
    /// Inside a subnegotiation of `option`.
    Sb(u8),
    /// IAC inside a subnegotiation.
    SbIac(u8),
}

/// The Telnet decoder of the client-to-server direction.
#[derive(Debug, Clone)]
pub struct Decoder {
    state: State,
    data: Vec<u8>,
    sb: Vec<u8>,
    /// The open subnegotiation was cut at [`MAX_SB`] bytes.
    sb_cut: bool,
}

impl Default for Decoder {
    fn default() -> Self {
        Decoder::new()
    }
}

impl Decoder {
    pub fn new() -> Self {
        Decoder {
            state: State::Data,
            data: Vec::new(),
            sb: Vec::new(),
            sb_cut: false,
        }
    }

    /// Feeds bytes as they came off the socket; returns the events they
    /// complete, in order. Consecutive data bytes come as one `Data`.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<Event> {
        let mut events = Vec::new();
        for &b in bytes {
            self.byte(b, &mut events);
        }
        self.flush(&mut events);
        events
    }

    fn flush(&mut self, events: &mut Vec<Event>) {
        if !self.data.is_empty() {
            events.push(Event::Data(std::mem::take(&mut self.data)));
        }
    }

    fn emit(&mut self, events: &mut Vec<Event>, event: Event) {
        self.flush(events);
        events.push(event);
    }

    fn byte(&mut self, b: u8, events: &mut Vec<Event>) {
        self.state = match self.state {
            State::Data if b == IAC => State::Iac,
            State::Data => {
                self.data.push(b);
                State::Data
            }
            State::Iac => self.command(b, events),
            State::Negotiation(verb) => {
                let event = match verb {
                    WILL => Event::Will(b),
                    WONT => Event::Wont(b),
                    DO => Event::Do(b),
                    _ => Event::Dont(b),
                };
                self.emit(events, event);
                State::Data
            }
            State::SbOption => {
                self.sb.clear();
                self.sb_cut = false;
                State::Sb(b)
            }
            State::Sb(option) if b == IAC => State::SbIac(option),
            State::Sb(option) => {
                self.push_sb(option, b, events);
                State::Sb(option)
            }
            // IAC IAC inside SB is a data 255 (RFC 855).
            State::SbIac(option) if b == IAC => {
                self.push_sb(option, b, events);
                State::Sb(option)
            }
            State::SbIac(option) => {
                let data = std::mem::take(&mut self.sb);
                let event = if option == COM_PORT_OPTION {
                    Event::ComPort(ComPort::parse(&data))
                } else {
                    Event::Subnegotiation { option, data }
                };
                self.emit(events, event);
                // Anything but SE is a broken SB: it ends there, and the
                // byte is read as the command it is (RFC 855 leaves this
                // open; this is what keeps us in sync).
                if b == SE {
                    State::Data
                } else {
                    let broken = Malformed::Unended { option, by: b };
                    self.emit(events, Event::Malformed(broken));
                    self.command(b, events)
                }
            }
        }
    }

    /// The byte after IAC (outside SB).
    fn command(&mut self, b: u8, events: &mut Vec<Event>) -> State {
        match b {
            IAC => {
                self.data.push(IAC);
                State::Data
            }
            WILL | WONT | DO | DONT => State::Negotiation(b),
            SB => State::SbOption,
            // A stray SE ends nothing.
            SE => {
                self.emit(events, Event::Malformed(Malformed::StraySe));
                State::Data
            }
            // RFC 854's commands are 240-255.
            0..SE => {
                self.emit(events, Event::Malformed(Malformed::NotACommand(b)));
                State::Data
            }
            _ => {
                self.emit(events, Event::Command(b));
                State::Data
            }
        }
    }

    /// One byte of a subnegotiation of `option`; past [`MAX_SB`] it is
    /// dropped, which is said once.
    fn push_sb(&mut self, option: u8, b: u8, events: &mut Vec<Event>) {
        if self.sb.len() < MAX_SB {
            self.sb.push(b);
        } else if !self.sb_cut {
            self.sb_cut = true;
            self.emit(events, Event::Malformed(Malformed::TooLong { option }));
        }
    }
}

/// Data for the client with every IAC doubled (RFC 854).
pub fn escape(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len() + data.len() / 16);
    for &b in data {
        out.push(b);
        if b == IAC {
            out.push(IAC);
        }
    }
    out
}

/// `IAC SB COM-PORT-OPTION code value... IAC SE`, value escaped (RFC 2217).
pub fn com_port_reply(server_code: u8, value: &[u8]) -> Vec<u8> {
    let mut out = vec![IAC, SB, COM_PORT_OPTION, server_code];
    out.extend(escape(value));
    out.extend([IAC, SE]);
    out
}

/// What the driver must do with the serial port, in the order the client
/// asked for it (data and RTS changes interleave: a host releases T_REQ
/// right after the STX of its frame).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// Write these bytes to the port.
    Write(Vec<u8>),
    /// Switch the port to this baud rate (already accepted).
    SetBaud(u32),
    /// Set RTS (true = ON, the line asserted).
    SetRts(bool),
    /// Set DTR (true = ON, the line asserted).
    SetDtr(bool),
    /// Drop data received from the port and not yet sent to the client.
    PurgeReceive,
    /// Drop data from the client not yet written to the port.
    PurgeTransmit,
    /// The client asks us to stop (true) or resume (false) sending data.
    Suspend(bool),
}

/// Our side of the option negotiation of one option (RFC 854 "General
/// considerations": acknowledge only a change, so that no loop can start).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Side {
    enabled: bool,
    /// We asked (WILL or DO) and wait for the answer.
    requested: bool,
}

/// Line state we report: transmit holding and shift registers empty
/// (RFC 2217 "NOTIFY-LINESTATE").
pub const LINESTATE: u8 = 0x60;
/// Modem state we report: CTS and DSR on (RFC 2217 "NOTIFY-MODEMSTATE").
pub const MODEMSTATE: u8 = 0x30;

/// The server side of one RFC 2217 connection.
#[derive(Debug, Clone)]
pub struct Server {
    decoder: Decoder,
    signature: Vec<u8>,
    /// Baud rates the port accepts.
    rates: &'static [u32],
    baud: u32,
    rts: bool,
    dtr: bool,
    linestate_mask: u8,
    modemstate_mask: u8,
    suspended: bool,
    /// Per option: whether we do it (`us`) and whether the client does.
    us: [Side; 256],
    him: [Side; 256],
    client_signature: Option<Vec<u8>>,
    /// Whether the first modem state was notified.
    notified: bool,
    /// What was refused on this connection.
    refusals: Tally,
}

/// Options we do (and let the client do).
fn supported(option: u8) -> bool {
    matches!(option, BINARY | SGA | COM_PORT_OPTION)
}

impl Server {
    /// A connection to a port running at `baud` that accepts only `rates`,
    /// RTS off. `signature` answers a SIGNATURE request.
    pub fn new(signature: &str, baud: u32, rates: &'static [u32]) -> Self {
        Server {
            decoder: Decoder::new(),
            signature: signature.as_bytes().to_vec(),
            rates,
            baud,
            rts: false,
            dtr: false,
            linestate_mask: 0,
            // RFC 2217 "SET-MODEMSTATE-MASK": initially 255; the
            // line state mask initially 0.
            modemstate_mask: 255,
            suspended: false,
            us: [Side::default(); 256],
            him: [Side::default(); 256],
            client_signature: None,
            notified: false,
            refusals: Tally::default(),
        }
    }

    /// What we send first: WILL BINARY, DO BINARY, WILL SGA and WILL
    /// COM-PORT-OPTION (RFC 2217 "Telnet negotiation": either side may
    /// start; pyserial waits for our WILL).
    pub fn greeting(&mut self) -> Vec<u8> {
        let mut out = Vec::new();
        for option in [BINARY, SGA, COM_PORT_OPTION] {
            self.us[option as usize].requested = true;
            out.extend([IAC, WILL, option]);
        }
        self.him[BINARY as usize].requested = true;
        out.extend([IAC, DO, BINARY]);
        out
    }

    /// The baud rate in effect.
    pub fn baud(&self) -> u32 {
        self.baud
    }

    /// Whether RTS is on.
    pub fn rts(&self) -> bool {
        self.rts
    }

    /// Whether the client asked us to hold data (FLOWCONTROL-SUSPEND).
    pub fn suspended(&self) -> bool {
        self.suspended
    }

    /// The signature the client sent, if any.
    pub fn client_signature(&self) -> Option<&[u8]> {
        self.client_signature.as_deref()
    }

    /// What was refused on this connection so far.
    pub fn refusals(&self) -> &Tally {
        &self.refusals
    }

    /// Counts something the driver refused on this connection (a flood
    /// past its buffers, ...), in the same tally.
    pub fn refuse(&mut self, r: Refusal) {
        self.refusals.add(r);
    }

    /// The first refusal of each kind not yet reported ([`Tally::take_news`]).
    pub fn take_refusal_news(&mut self) -> Vec<Refusal> {
        self.refusals.take_news()
    }

    /// Whether the client agreed to COM-PORT-OPTION either way (RFC 2217
    /// names no direction as the one that counts; pyserial asks both).
    pub fn com_port_agreed(&self) -> bool {
        let i = COM_PORT_OPTION as usize;
        self.us[i].enabled || self.him[i].enabled
    }

    /// Handles bytes from the client: appends what to send back to
    /// `reply` and returns what to do with the port.
    pub fn receive(&mut self, bytes: &[u8], reply: &mut Vec<u8>) -> Vec<Action> {
        let mut actions = Vec::new();
        for event in self.decoder.feed(bytes) {
            self.handle(event, reply, &mut actions);
        }
        actions
    }

    fn handle(&mut self, event: Event, reply: &mut Vec<u8>, actions: &mut Vec<Action>) {
        match event {
            Event::Data(data) => actions.push(Action::Write(data)),
            Event::Do(option) | Event::Dont(option) => {
                let on = matches!(event, Event::Do(_));
                if on && !supported(option) {
                    self.refusals.add(Refusal::Option { verb: DO, option });
                }
                let side = &mut self.us[option as usize];
                if let Some(verb) = Self::negotiate(side, on, supported(option)) {
                    reply.extend([IAC, verb, option]);
                }
            }
            Event::Will(option) | Event::Wont(option) => {
                let on = matches!(event, Event::Will(_));
                if on && !supported(option) {
                    self.refusals.add(Refusal::Option { verb: WILL, option });
                }
                let side = &mut self.him[option as usize];
                // The answer to WILL/WONT is DO/DONT.
                if let Some(verb) = Self::negotiate(side, on, supported(option)) {
                    reply.extend([IAC, verb + 2, option]);
                }
            }
            Event::Command(_) => {}
            Event::Subnegotiation { option, data } => {
                let len = data.len();
                self.refusals.add(Refusal::Subnegotiation { option, len });
            }
            Event::Malformed(m) => self.refusals.add(Refusal::Telnet(m)),
            Event::ComPort(c) => self.com_port(c, reply, actions),
        }
        // Once COM-PORT-OPTION is agreed, the modem lines are notified
        // once (RFC 2217 "NOTIFY-MODEMSTATE"; they never change after):
        // pyserial reads CTS/DSR only from such notifications.
        if self.com_port_agreed() && !self.notified {
            self.notified = true;
            let state = MODEMSTATE & self.modemstate_mask;
            reply.extend(com_port_reply(
                cmd::NOTIFY_MODEMSTATE + SERVER_OFFSET,
                &[state],
            ));
        }
    }

    /// One side of one option receives a request to enable (`on`) or
    /// disable it; returns WILL or WONT to send (DO/DONT are WILL/WONT + 2),
    /// or nothing when the request only confirms the state we are in or
    /// asked for.
    fn negotiate(side: &mut Side, on: bool, supported: bool) -> Option<u8> {
        let requested = std::mem::take(&mut side.requested);
        if on && !supported {
            return Some(WONT);
        }
        if side.enabled == on {
            return None;
        }
        side.enabled = on;
        // The answer to our own request needs no answer (RFC 854).
        (!requested).then_some(if on { WILL } else { WONT })
    }

    fn com_port(&mut self, c: ComPort, reply: &mut Vec<u8>, actions: &mut Vec<Action>) {
        use control::*;
        let answer = |reply: &mut Vec<u8>, code: u8, value: &[u8]| {
            reply.extend(com_port_reply(code + SERVER_OFFSET, value))
        };
        match c {
            // RFC 2217 "SIGNATURE": an empty one asks for ours; a client's
            // own signature needs no answer.
            ComPort::Signature(text) if text.is_empty() => {
                answer(reply, cmd::SIGNATURE, &self.signature)
            }
            ComPort::Signature(text) => self.client_signature = Some(text),
            // RFC 2217 "SET-BAUDRATE": answer with the rate in effect,
            // which is the old one when the port cannot do the new one.
            ComPort::SetBaudRate(rate) => {
                if rate != 0 && rate != self.baud && self.rates.contains(&rate) {
                    self.baud = rate;
                    actions.push(Action::SetBaud(rate));
                } else if rate != 0 && !self.rates.contains(&rate) {
                    let kept = self.baud;
                    self.refusals.add(Refusal::Baud { asked: rate, kept });
                }
                answer(reply, cmd::SET_BAUDRATE, &self.baud.to_be_bytes())
            }
            // The UART is 8N1 (UM0932 3.1): every request gets what it
            // is; a request for something else (not a query, 0) is refused.
            ComPort::SetDataSize(asked)
            | ComPort::SetParity(asked)
            | ComPort::SetStopSize(asked) => {
                let (code, what, is) = match c {
                    ComPort::SetDataSize(_) => (cmd::SET_DATASIZE, "SET-DATASIZE", 8),
                    ComPort::SetParity(_) => (cmd::SET_PARITY, "SET-PARITY", 1),
                    _ => (cmd::SET_STOPSIZE, "SET-STOPSIZE", 1),
                };
                if asked != 0 && asked != is {
                    self.refusals.add(Refusal::LineSetting { what, asked });
                }
                answer(reply, code, &[is])
            }
            ComPort::SetControl(value) => {
                if matches!(value, 2 | 3 | BREAK_ON | 15..) {
                    self.refusals.add(Refusal::Control(value));
                }
                let now = match value {
                    // No flow control either way, whatever is asked: RTS
                    // is T_REQ, not a handshake line.
                    FLOW_QUERY..=3 | 17 | 19 => FLOW_NONE,
                    INBOUND_FLOW_QUERY..=16 | 18 => INBOUND_FLOW_NONE,
                    // BREAK is not simulated: it stays off.
                    BREAK_QUERY..=BREAK_OFF => BREAK_OFF,
                    DTR_QUERY..=DTR_OFF => {
                        if value != DTR_QUERY && self.dtr != (value == DTR_ON) {
                            self.dtr = value == DTR_ON;
                            actions.push(Action::SetDtr(self.dtr));
                        }
                        if self.dtr {
                            DTR_ON
                        } else {
                            DTR_OFF
                        }
                    }
                    RTS_QUERY..=RTS_OFF => {
                        if value != RTS_QUERY && self.rts != (value == RTS_ON) {
                            self.rts = value == RTS_ON;
                            actions.push(Action::SetRts(self.rts));
                        }
                        if self.rts {
                            RTS_ON
                        } else {
                            RTS_OFF
                        }
                    }
                    // Unknown values: say what we did (nothing).
                    other => other,
                };
                answer(reply, cmd::SET_CONTROL, &[now])
            }
            ComPort::NotifyLineState(_) => answer(reply, cmd::NOTIFY_LINESTATE, &[LINESTATE]),
            ComPort::NotifyModemState(_) => answer(reply, cmd::NOTIFY_MODEMSTATE, &[MODEMSTATE]),
            ComPort::FlowControlSuspend => {
                self.suspended = true;
                actions.push(Action::Suspend(true));
                answer(reply, cmd::FLOWCONTROL_SUSPEND, &[])
            }
            ComPort::FlowControlResume => {
                self.suspended = false;
                actions.push(Action::Suspend(false));
                answer(reply, cmd::FLOWCONTROL_RESUME, &[])
            }
            // The lines never change, so nothing is ever notified; the
            // masks are kept and echoed (RFC 2217 "SET-LINESTATE-MASK").
            ComPort::SetLineStateMask(mask) => {
                self.linestate_mask = mask;
                answer(reply, cmd::SET_LINESTATE_MASK, &[mask])
            }
            ComPort::SetModemStateMask(mask) => {
                self.modemstate_mask = mask;
                answer(reply, cmd::SET_MODEMSTATE_MASK, &[mask])
            }
            ComPort::PurgeData(which) => {
                if !(1..=3).contains(&which) {
                    self.refusals.add(Refusal::Purge(which));
                } else {
                    if which & 1 != 0 {
                        actions.push(Action::PurgeReceive);
                    }
                    if which & 2 != 0 {
                        actions.push(Action::PurgeTransmit);
                    }
                }
                answer(reply, cmd::PURGE_DATA, &[which])
            }
            // RFC 2217 defines no answer to what it does not define.
            ComPort::Unknown { code, data } => {
                let len = data.len();
                self.refusals.add(Refusal::ComPort { code, len });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sb(code: u8, value: &[u8]) -> Vec<u8> {
        let mut v = vec![IAC, SB, COM_PORT_OPTION, code];
        v.extend(escape(value));
        v.extend([IAC, SE]);
        v
    }

    fn server() -> Server {
        Server::new("plm sim", 57600, &[9600, 19200, 38400, 57600])
    }

    /// The reply and actions to `bytes` sent in one piece.
    fn send(s: &mut Server, bytes: &[u8]) -> (Vec<u8>, Vec<Action>) {
        let mut reply = Vec::new();
        let actions = s.receive(bytes, &mut reply);
        (reply, actions)
    }

    #[test]
    fn escape_doubles_iac_only() {
        assert_eq!(
            escape(&[1, 255, 2, 255, 255]),
            [1, 255, 255, 2, 255, 255, 255, 255]
        );
        assert_eq!(escape(&[]), Vec::<u8>::new());
    }

    #[test]
    fn doubled_iac_is_one_data_byte() {
        let mut d = Decoder::new();
        assert_eq!(d.feed(&[1, IAC, IAC, 2]), [Event::Data(vec![1, 255, 2])]);
    }

    #[test]
    fn every_split_of_a_stream_gives_the_same_events() {
        let mut stream = vec![0x02, IAC, IAC, 0x2C];
        stream.extend([IAC, DO, BINARY, IAC, WILL, COM_PORT_OPTION, IAC, 241]);
        stream.extend(sb(cmd::SET_BAUDRATE, &[0, 0, 0xE1, 0x00]));
        stream.extend(sb(cmd::SIGNATURE, b"a\xffb"));
        stream.extend([IAC, SB, 24, 1, IAC, SE, 7, 8]);
        let expected = vec![
            Event::Data(vec![0x02, 0xFF, 0x2C]),
            Event::Do(BINARY),
            Event::Will(COM_PORT_OPTION),
            Event::Command(241),
            Event::ComPort(ComPort::SetBaudRate(57600)),
            Event::ComPort(ComPort::Signature(b"a\xffb".to_vec())),
            Event::Subnegotiation {
                option: 24,
                data: vec![1],
            },
            Event::Data(vec![7, 8]),
        ];
        assert_eq!(Decoder::new().feed(&stream), expected);
        // Byte by byte, and cut once at every position.
        let mut d = Decoder::new();
        let mut got: Vec<Event> = stream.iter().flat_map(|b| d.feed(&[*b])).collect();
        merge_data(&mut got);
        assert_eq!(got, expected);
        for cut in 0..=stream.len() {
            let mut d = Decoder::new();
            let mut got = d.feed(&stream[..cut]);
            got.extend(d.feed(&stream[cut..]));
            merge_data(&mut got);
            assert_eq!(got, expected, "cut at {cut}");
        }
    }

    /// Joins adjacent `Data` events (a split inside data yields two).
    fn merge_data(events: &mut Vec<Event>) {
        let mut out: Vec<Event> = Vec::new();
        for e in events.drain(..) {
            match (out.last_mut(), e) {
                (Some(Event::Data(a)), Event::Data(b)) => a.extend(b),
                (_, e) => out.push(e),
            }
        }
        *events = out;
    }

    #[test]
    fn a_broken_subnegotiation_ends_at_the_next_command() {
        let mut d = Decoder::new();
        assert_eq!(
            d.feed(&[
                IAC,
                SB,
                COM_PORT_OPTION,
                cmd::SET_CONTROL,
                11,
                IAC,
                DO,
                SGA,
                5
            ]),
            [
                Event::ComPort(ComPort::SetControl(11)),
                Event::Malformed(Malformed::Unended {
                    option: COM_PORT_OPTION,
                    by: DO
                }),
                Event::Do(SGA),
                Event::Data(vec![5]),
            ]
        );
    }

    #[test]
    fn malformed_telnet_is_named_and_read_past() {
        let mut d = Decoder::new();
        // IAC then a byte below 240, a stray SE, an SB ended by IAC DO.
        let got = d.feed(&[1, IAC, 7, 2, IAC, SE, IAC, SB, 24, 9, IAC, DO, SGA, 3]);
        assert_eq!(
            got,
            [
                Event::Data(vec![1]),
                Event::Malformed(Malformed::NotACommand(7)),
                Event::Data(vec![2]),
                Event::Malformed(Malformed::StraySe),
                Event::Subnegotiation {
                    option: 24,
                    data: vec![9]
                },
                Event::Malformed(Malformed::Unended { option: 24, by: DO }),
                Event::Do(SGA),
                Event::Data(vec![3]),
            ]
        );
        // An endless SB is cut once, said once, and ends at IAC SE.
        let mut long = vec![IAC, SB, COM_PORT_OPTION];
        long.extend([0x41; 3 * MAX_SB]);
        let mut got = d.feed(&long);
        got.extend(d.feed(&[0x41; 1000]));
        assert_eq!(
            got,
            [Event::Malformed(Malformed::TooLong {
                option: COM_PORT_OPTION
            })]
        );
        let got = d.feed(&[IAC, SE, 5]);
        assert!(
            matches!(&got[..], [Event::ComPort(ComPort::Unknown { code: 0x41, data }), Event::Data(x)]
                if data.len() == MAX_SB - 1 && x == &[5]),
            "{got:?}"
        );
    }

    #[test]
    fn the_server_counts_what_it_refuses() {
        let mut s = server();
        let mut bytes = vec![IAC, DO, 24, IAC, 7];
        bytes.extend(sb(cmd::SET_BAUDRATE, &u32::MAX.to_be_bytes()));
        bytes.extend(sb(cmd::SET_BAUDRATE, &0u32.to_be_bytes()));
        bytes.extend(sb(cmd::SET_BAUDRATE, &[1, 2]));
        bytes.extend(sb(cmd::SET_DATASIZE, &[7]));
        bytes.extend(sb(cmd::SET_DATASIZE, &[8]));
        bytes.extend(sb(cmd::SET_CONTROL, &[control::BREAK_ON]));
        bytes.extend(sb(cmd::SET_CONTROL, &[control::RTS_ON]));
        bytes.extend(sb(cmd::PURGE_DATA, &[4]));
        let (_, actions) = send(&mut s, &bytes);
        // RTS is done; PURGE-DATA 4 purges nothing.
        assert_eq!(actions, [Action::SetRts(true)]);
        let news = s.take_refusal_news();
        assert_eq!(
            news,
            [
                Refusal::Option {
                    verb: DO,
                    option: 24
                },
                Refusal::Telnet(Malformed::NotACommand(7)),
                Refusal::Baud {
                    asked: u32::MAX,
                    kept: 57600
                },
                Refusal::ComPort {
                    code: cmd::SET_BAUDRATE,
                    len: 2
                },
                Refusal::LineSetting {
                    what: "SET-DATASIZE",
                    asked: 7
                },
                Refusal::Control(control::BREAK_ON),
                Refusal::Purge(4),
            ]
        );
        // A query (baud 0, data size 0) and what is served are no refusal.
        let (_, _) = send(&mut s, &sb(cmd::SET_BAUDRATE, &[0, 0, 0, 0]));
        assert!(s.take_refusal_news().is_empty());
        assert_eq!(
            s.refusals().summary().unwrap(),
            "1 malformed Telnet sequence, 1 option not served, 1 unknown RFC 2217 command, \
             1 baud rate refused, 1 line setting other than 8N1, 1 SET-CONTROL value refused, \
             1 unknown PURGE-DATA value"
        );
    }

    #[test]
    fn wrong_lengths_are_unknown() {
        assert_eq!(
            ComPort::parse(&[cmd::SET_BAUDRATE, 0, 0, 0x25]),
            ComPort::Unknown {
                code: 1,
                data: vec![0, 0, 0x25]
            }
        );
        assert_eq!(
            ComPort::parse(&[cmd::SET_CONTROL]),
            ComPort::Unknown {
                code: 5,
                data: vec![]
            }
        );
        assert_eq!(
            ComPort::parse(&[]),
            ComPort::Unknown {
                code: 0,
                data: vec![]
            }
        );
    }

    #[test]
    fn greeting_and_negotiation() {
        let mut s = server();
        assert_eq!(
            s.greeting(),
            [
                IAC,
                WILL,
                BINARY,
                IAC,
                WILL,
                SGA,
                IAC,
                WILL,
                COM_PORT_OPTION,
                IAC,
                DO,
                BINARY
            ]
        );
        // Answers to our requests need no answer.
        let (reply, actions) = send(
            &mut s,
            &[
                IAC,
                DO,
                BINARY,
                IAC,
                WILL,
                BINARY,
                IAC,
                DO,
                SGA,
                IAC,
                DO,
                COM_PORT_OPTION,
            ],
        );
        // ... but the agreement brings the first modem state notification.
        assert_eq!(reply, sb(107, &[MODEMSTATE]));
        assert!(actions.is_empty());
        assert!(s.com_port_agreed());
        // The client offers COM-PORT-OPTION and SGA: we agree, once.
        let (reply, _) = send(&mut s, &[IAC, WILL, COM_PORT_OPTION, IAC, WILL, SGA]);
        assert_eq!(reply, [IAC, DO, COM_PORT_OPTION, IAC, DO, SGA]);
        let (reply, _) = send(&mut s, &[IAC, WILL, COM_PORT_OPTION]);
        assert!(reply.is_empty());
        // Unknown options are refused; ECHO is not ours to do.
        let (reply, _) = send(&mut s, &[IAC, DO, ECHO, IAC, WILL, 24, IAC, DO, 31]);
        assert_eq!(reply, [IAC, WONT, ECHO, IAC, DONT, 24, IAC, WONT, 31]);
        // Refusals of what is off need no answer; turning off what is on
        // is acknowledged.
        let (reply, _) = send(&mut s, &[IAC, DONT, ECHO, IAC, WONT, 24]);
        assert!(reply.is_empty());
        let (reply, _) = send(&mut s, &[IAC, DONT, SGA, IAC, WONT, BINARY]);
        assert_eq!(reply, [IAC, WONT, SGA, IAC, DONT, BINARY]);
    }

    #[test]
    fn a_client_that_starts_gets_answers() {
        let mut s = server();
        let (reply, _) = send(&mut s, &[IAC, DO, COM_PORT_OPTION, IAC, DO, BINARY]);
        let mut expected = vec![IAC, WILL, COM_PORT_OPTION];
        expected.extend(sb(107, &[MODEMSTATE]));
        expected.extend([IAC, WILL, BINARY]);
        assert_eq!(reply, expected);
        assert!(s.com_port_agreed());
    }

    #[test]
    fn set_baudrate_accepts_the_modem_rates_only() {
        let mut s = server();
        let (reply, actions) = send(&mut s, &sb(cmd::SET_BAUDRATE, &9600u32.to_be_bytes()));
        assert_eq!(reply, sb(101, &[0, 0, 0x25, 0x80]));
        assert_eq!(actions, [Action::SetBaud(9600)]);
        // Unsupported: the current rate; query: the current rate.
        let (reply, actions) = send(&mut s, &sb(cmd::SET_BAUDRATE, &115200u32.to_be_bytes()));
        assert_eq!(reply, sb(101, &9600u32.to_be_bytes()));
        assert!(actions.is_empty());
        let (reply, actions) = send(&mut s, &sb(cmd::SET_BAUDRATE, &[0, 0, 0, 0]));
        assert_eq!(reply, sb(101, &9600u32.to_be_bytes()));
        assert!(actions.is_empty());
        assert_eq!(s.baud(), 9600);
        // The same rate again is no change.
        let (_, actions) = send(&mut s, &sb(cmd::SET_BAUDRATE, &9600u32.to_be_bytes()));
        assert!(actions.is_empty());
    }

    #[test]
    fn a_reply_value_with_iac_is_escaped() {
        // 0x0000FF00 would be an odd baud rate; the escaping is what counts.
        assert_eq!(
            com_port_reply(101, &[0, 0, 0xFF, 0]),
            [IAC, SB, 44, 101, 0, 0, 0xFF, 0xFF, 0, IAC, SE]
        );
    }

    #[test]
    fn line_settings_answer_8n1() {
        let mut s = server();
        for (code, ask, answer) in [
            (cmd::SET_DATASIZE, 7, 8),
            (cmd::SET_DATASIZE, 0, 8),
            (cmd::SET_DATASIZE, 8, 8),
            (cmd::SET_PARITY, 3, 1),
            (cmd::SET_PARITY, 0, 1),
            (cmd::SET_STOPSIZE, 2, 1),
            (cmd::SET_STOPSIZE, 0, 1),
        ] {
            let (reply, actions) = send(&mut s, &sb(code, &[ask]));
            assert_eq!(reply, sb(code + 100, &[answer]), "{code} {ask}");
            assert!(actions.is_empty());
        }
    }

    #[test]
    fn set_control_rts_dtr_break_and_flow() {
        let mut s = server();
        let mut ask = |value: u8| send(&mut s, &sb(cmd::SET_CONTROL, &[value]));
        assert_eq!(ask(10), (sb(105, &[12]), vec![]));
        assert_eq!(ask(11), (sb(105, &[11]), vec![Action::SetRts(true)]));
        assert_eq!(ask(11), (sb(105, &[11]), vec![]));
        assert_eq!(ask(10), (sb(105, &[11]), vec![]));
        assert_eq!(ask(12), (sb(105, &[12]), vec![Action::SetRts(false)]));
        assert_eq!(ask(7), (sb(105, &[9]), vec![]));
        assert_eq!(ask(8), (sb(105, &[8]), vec![Action::SetDtr(true)]));
        assert_eq!(ask(8), (sb(105, &[8]), vec![]));
        assert_eq!(ask(7), (sb(105, &[8]), vec![]));
        assert_eq!(ask(9), (sb(105, &[9]), vec![Action::SetDtr(false)]));
        for (value, answer) in [
            (0, 1),
            (1, 1),
            (2, 1),
            (3, 1),
            (17, 1),
            (19, 1),
            (4, 6),
            (5, 6),
            (6, 6),
            (13, 14),
            (14, 14),
            (15, 14),
            (16, 14),
            (18, 14),
            (99, 99),
        ] {
            assert_eq!(ask(value), (sb(105, &[answer]), vec![]), "value {value}");
        }
    }

    #[test]
    fn rts_change_keeps_its_place_between_data() {
        let mut s = server();
        let mut bytes = vec![0x02];
        bytes.extend(sb(cmd::SET_CONTROL, &[control::RTS_OFF]));
        bytes.extend(sb(cmd::SET_CONTROL, &[control::RTS_ON]));
        bytes.extend([0x01, IAC, IAC]);
        let (_, actions) = send(&mut s, &bytes);
        assert_eq!(
            actions,
            [
                Action::Write(vec![0x02]),
                Action::SetRts(true),
                Action::Write(vec![0x01, 0xFF]),
            ]
        );
    }

    #[test]
    fn states_masks_flow_purge_signature() {
        let mut s = server();
        let mut ask = |code: u8, value: &[u8]| send(&mut s, &sb(code, value));
        assert_eq!(ask(6, &[]), (sb(106, &[LINESTATE]), vec![]));
        assert_eq!(ask(7, &[0]), (sb(107, &[MODEMSTATE]), vec![]));
        assert_eq!(ask(10, &[0x1F]), (sb(110, &[0x1F]), vec![]));
        assert_eq!(ask(11, &[0xFF]), (sb(111, &[0xFF]), vec![]));
        assert_eq!(ask(8, &[]), (sb(108, &[]), vec![Action::Suspend(true)]));
        assert_eq!(ask(9, &[]), (sb(109, &[]), vec![Action::Suspend(false)]));
        assert_eq!(ask(12, &[1]), (sb(112, &[1]), vec![Action::PurgeReceive]));
        assert_eq!(ask(12, &[2]), (sb(112, &[2]), vec![Action::PurgeTransmit]));
        assert_eq!(
            ask(12, &[3]),
            (
                sb(112, &[3]),
                vec![Action::PurgeReceive, Action::PurgeTransmit]
            )
        );
        assert_eq!(ask(0, &[]), (sb(100, b"plm sim"), vec![]));
        assert_eq!(ask(0, b"pyserial"), (vec![], vec![]));
        assert_eq!(ask(42, &[1, 2]), (vec![], vec![]));
        assert_eq!(s.client_signature(), Some(&b"pyserial"[..]));
        assert!(!s.suspended());
    }
}
