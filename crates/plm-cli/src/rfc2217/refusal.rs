//! What an RFC 2217 server refuses, in words, and a tally of it per
//! connection: the first of each kind is worth a line, the rest are
//! counted and summed up once (a client that sends noise must not turn
//! the server's log into a copy of it).

use super::{DO, MAX_SB};
use std::fmt;

/// Telnet that breaks RFC 854/855.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Malformed {
    /// IAC followed by a byte below 240 (RFC 854 defines the commands
    /// 240-255 only).
    NotACommand(u8),
    /// IAC SE with no subnegotiation open.
    StraySe,
    /// A subnegotiation of `option` ended by IAC `by` instead of IAC SE.
    Unended { option: u8, by: u8 },
    /// A subnegotiation of `option` longer than [`MAX_SB`] bytes.
    TooLong { option: u8 },
}

/// Something a client asked for or sent that the server did not do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refusal {
    /// Telnet that breaks RFC 854/855.
    Telnet(Malformed),
    /// WILL or DO (`verb`) of an option the server does not serve.
    Option { verb: u8, option: u8 },
    /// A subnegotiation of an option the server does not serve.
    Subnegotiation { option: u8, len: usize },
    /// A COM-PORT-OPTION command RFC 2217 does not define, or one with a
    /// value of the wrong length.
    ComPort { code: u8, len: usize },
    /// SET-BAUDRATE to a rate the port cannot take; `kept` stays.
    Baud { asked: u32, kept: u32 },
    /// SET-DATASIZE, SET-PARITY or SET-STOPSIZE (`what`) other than 8N1.
    LineSetting { what: &'static str, asked: u8 },
    /// A SET-CONTROL value the port does not do (BREAK, flow control) or
    /// RFC 2217 does not define.
    Control(u8),
    /// PURGE-DATA of a value RFC 2217 does not define (1, 2, 3 only).
    Purge(u8),
    /// Bytes past the simulated UART's transmit buffer of `buffer` bytes
    /// at `baud` (the client writes faster than the line carries them):
    /// dropped. Counted by the byte.
    Flood {
        bytes: usize,
        buffer: usize,
        baud: u32,
    },
    /// Modem bytes past the `buffer` bytes held while the client had
    /// suspended the flow (FLOWCONTROL-SUSPEND): lost. Counted by the
    /// byte.
    Overrun { bytes: usize, buffer: usize },
}

/// Kinds of refusal, as a [`Tally`] counts them: (singular, plural).
const KINDS: [(&str, &str); 10] = [
    ("malformed Telnet sequence", "malformed Telnet sequences"),
    ("option not served", "options not served"),
    (
        "subnegotiation of an option not served",
        "subnegotiations of options not served",
    ),
    ("unknown RFC 2217 command", "unknown RFC 2217 commands"),
    ("baud rate refused", "baud rates refused"),
    (
        "line setting other than 8N1",
        "line settings other than 8N1",
    ),
    ("SET-CONTROL value refused", "SET-CONTROL values refused"),
    ("unknown PURGE-DATA value", "unknown PURGE-DATA values"),
    (
        "byte dropped past the UART's transmit buffer",
        "bytes dropped past the UART's transmit buffer",
    ),
    (
        "modem byte lost while the flow was suspended",
        "modem bytes lost while the flow was suspended",
    ),
];

impl Refusal {
    /// Its kind: an index into [`KINDS`].
    fn kind(&self) -> usize {
        match self {
            Refusal::Telnet(_) => 0,
            Refusal::Option { .. } => 1,
            Refusal::Subnegotiation { .. } => 2,
            Refusal::ComPort { .. } => 3,
            Refusal::Baud { .. } => 4,
            Refusal::LineSetting { .. } => 5,
            Refusal::Control(_) => 6,
            Refusal::Purge(_) => 7,
            Refusal::Flood { .. } => 8,
            Refusal::Overrun { .. } => 9,
        }
    }

    /// How much of its kind it is: bytes for a flood or an overrun, one
    /// otherwise.
    fn amount(&self) -> usize {
        match self {
            Refusal::Flood { bytes, .. } | Refusal::Overrun { bytes, .. } => *bytes,
            _ => 1,
        }
    }
}

/// The name of a SET-CONTROL value the port does not do (RFC 2217
/// "SET-CONTROL").
fn control_name(value: u8) -> &'static str {
    match value {
        2 => "XON/XOFF flow control",
        3 => "hardware flow control",
        5 => "BREAK ON",
        15 => "inbound XON/XOFF flow control",
        16 => "inbound hardware flow control",
        17 => "DCD flow control",
        18 => "DTR flow control",
        19 => "DSR flow control",
        _ => "no value RFC 2217 defines",
    }
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Refusal::Telnet(Malformed::NotACommand(b)) => write!(
                f,
                "IAC followed by {b} (RFC 854 has no such command; Telnet commands are \
                 240-255): ignored"
            ),
            Refusal::Telnet(Malformed::StraySe) => {
                write!(f, "IAC SE with no subnegotiation open (RFC 855): ignored")
            }
            Refusal::Telnet(Malformed::Unended { option, by }) => write!(
                f,
                "a subnegotiation of option {option} ended by IAC {by} instead of IAC SE \
                 (RFC 855): taken as ended there"
            ),
            Refusal::Telnet(Malformed::TooLong { option }) => write!(
                f,
                "a subnegotiation of option {option} longer than {MAX_SB} bytes: the rest \
                 dropped"
            ),
            Refusal::Option { verb, option } => write!(
                f,
                "{} {option}: only BINARY (0), SUPPRESS-GO-AHEAD (3) and COM-PORT-OPTION (44) \
                 are served (answered {})",
                if *verb == DO { "DO" } else { "WILL" },
                if *verb == DO { "WONT" } else { "DONT" }
            ),
            Refusal::Subnegotiation { option, len } => write!(
                f,
                "a subnegotiation of option {option} ({len} bytes), which is not served: \
                 ignored"
            ),
            Refusal::ComPort { code, len } => write!(
                f,
                "RFC 2217 command {code} with {len} value byte{}: no such command, or the \
                 wrong length for it: ignored",
                if *len == 1 { "" } else { "s" }
            ),
            Refusal::Baud { asked, kept } => write!(
                f,
                "SET-BAUDRATE {asked}: the port runs at 9600, 19200, 38400 or 57600 baud only \
                 (the modem's BR pins): kept {kept}"
            ),
            Refusal::LineSetting { what, asked } => write!(
                f,
                "{what} {asked}: the UART is 8N1 (UM0932 3.1): answered with what it is"
            ),
            Refusal::Control(value) => write!(
                f,
                "SET-CONTROL {value} ({}): not done, answered with what the port does",
                control_name(*value)
            ),
            Refusal::Purge(value) => write!(
                f,
                "PURGE-DATA {value}: RFC 2217 defines 1 (receive), 2 (transmit) and 3 (both) \
                 only: nothing purged"
            ),
            Refusal::Flood {
                bytes,
                buffer,
                baud,
            } => write!(
                f,
                "{bytes} bytes of data: the simulated UART's transmit buffer holds {buffer} \
                 bytes not yet sent at {baud} baud and the client writes faster (a flood): \
                 what does not fit is dropped"
            ),
            Refusal::Overrun { bytes, buffer } => write!(
                f,
                "{bytes} bytes from the modem: {buffer} bytes are held already while the \
                 client has the flow suspended (FLOWCONTROL-SUSPEND): the rest is lost"
            ),
        }
    }
}

/// The refusals of one connection: how many of each kind, and the first
/// of each kind not yet reported.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    counts: [usize; KINDS.len()],
    news: Vec<Refusal>,
}

impl Tally {
    /// Counts `r`; the first of its kind is kept for [`Tally::take_news`].
    pub fn add(&mut self, r: Refusal) {
        let kind = r.kind();
        if self.counts[kind] == 0 {
            self.news.push(r.clone());
        }
        self.counts[kind] = self.counts[kind].saturating_add(r.amount());
    }

    /// The first refusal of each kind seen since the last call: at most
    /// one per kind over the connection's life.
    pub fn take_news(&mut self) -> Vec<Refusal> {
        std::mem::take(&mut self.news)
    }

    /// Whether nothing was refused.
    pub fn is_empty(&self) -> bool {
        self.counts.iter().all(|&c| c == 0)
    }

    /// How many of `r`'s kind were counted (bytes for floods and
    /// overruns).
    pub fn count_like(&self, r: &Refusal) -> usize {
        self.counts[r.kind()]
    }

    /// Everything refused, in words: "3 malformed Telnet sequences,
    /// 1 baud rate refused, ..."; `None` when nothing was.
    pub fn summary(&self) -> Option<String> {
        let parts: Vec<String> = self
            .counts
            .iter()
            .zip(KINDS)
            .filter(|(&n, _)| n > 0)
            .map(|(&n, (one, many))| format!("{n} {}", if n == 1 { one } else { many }))
            .collect();
        (!parts.is_empty()).then(|| parts.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_of_each_kind_is_news_and_the_rest_are_counted() {
        let mut t = Tally::default();
        assert!(t.is_empty());
        assert_eq!(t.summary(), None);
        t.add(Refusal::Telnet(Malformed::StraySe));
        t.add(Refusal::Telnet(Malformed::NotACommand(7)));
        t.add(Refusal::Baud {
            asked: u32::MAX,
            kept: 57600,
        });
        let flood = Refusal::Flood {
            bytes: 1000,
            buffer: 4096,
            baud: 57600,
        };
        t.add(flood.clone());
        t.add(Refusal::Flood {
            bytes: 24,
            buffer: 4096,
            baud: 57600,
        });
        let news = t.take_news();
        assert_eq!(news.len(), 3, "{news:?}");
        assert_eq!(news[0], Refusal::Telnet(Malformed::StraySe));
        assert!(t.take_news().is_empty(), "reported once");
        t.add(Refusal::Telnet(Malformed::StraySe));
        assert!(
            t.take_news().is_empty(),
            "a kind already seen is only counted"
        );
        assert_eq!(t.count_like(&flood), 1024);
        assert_eq!(
            t.summary().unwrap(),
            "3 malformed Telnet sequences, 1 baud rate refused, \
             1024 bytes dropped past the UART's transmit buffer"
        );
    }

    #[test]
    fn refusals_say_what_was_asked_and_what_was_done() {
        let baud = Refusal::Baud {
            asked: 4294967295,
            kept: 57600,
        }
        .to_string();
        assert!(
            baud.contains("4294967295") && baud.contains("kept 57600"),
            "{baud}"
        );
        let option = Refusal::Option {
            verb: DO,
            option: 24,
        }
        .to_string();
        assert!(
            option.starts_with("DO 24") && option.contains("WONT"),
            "{option}"
        );
        let control = Refusal::Control(5).to_string();
        assert!(control.contains("BREAK ON"), "{control}");
    }
}
