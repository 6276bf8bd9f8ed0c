//! The streets found, kept in the browser's storage per connection, so
//! that a reload or a reconnection reads the lamps at once and discovery
//! only looks for new ones (docs/console.md, "A street remembered").
//!
//! A connection is what identifies it: the profile, the port in words
//! (a WebSerial port's USB ids, a simulated street's size), the baud
//! rate and a simulated street's seed. One key holds a line per
//! connection, the one used last first (the oldest goes beyond
//! [`CONNECTIONS`]): its name, a tab, then `1 SS HEX`: the record's
//! layout, the discovery session (two hex digits) and, per lamp, its
//! 6-byte address then its discovery reply's data (board protocol 0Bh,
//! as plm-core writes it).

use crate::storage::{load, store};
use plm_core::app::service::{Discovered, Service};
use plm_core::app::Address;
use plm_core::hex;

/// Connections remembered at most.
pub const CONNECTIONS: usize = 4;
/// Lamps of one street remembered at most; a larger street is not kept.
pub const LAMPS: usize = 1000;

const KEY: &str = "plm-console.streets";
/// Bytes of one lamp: its address and its reply's data.
const LAMP_BYTES: usize = 6 + 5;

/// A street remembered.
#[derive(Debug, Clone, PartialEq)]
pub struct Remembered {
    /// The discovery session its lamps were heard in (they stay quiet in
    /// it).
    pub session: u8,
    /// Each lamp and what discovery said of it.
    pub lamps: Vec<(Address, Discovered)>,
}

/// What identifies a connection, in words: `profile`, the transport's
/// port and baud rate, and a simulated world's `seed`.
pub fn connection(profile: &str, port: &str, baud: u32, seed: Option<u64>) -> String {
    match seed {
        Some(s) => format!("{profile} · {port} · {baud} Bd · seed {s}"),
        None => format!("{profile} · {port} · {baud} Bd"),
    }
}

/// A session number for a street this browser does not know: from the
/// computer's clock, so that two consoles seldom pick the same one.
pub fn fresh_session() -> u8 {
    #[cfg(target_arch = "wasm32")]
    {
        (js_sys::Date::now() as u64 % 256) as u8
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        0
    }
}

/// The record of `r`, or `None` when the street is beyond [`LAMPS`].
pub fn encode(r: &Remembered) -> Option<String> {
    if r.lamps.len() > LAMPS {
        return None;
    }
    let mut bytes = Vec::with_capacity(r.lamps.len() * LAMP_BYTES);
    for (a, d) in &r.lamps {
        bytes.extend_from_slice(&a.0);
        bytes.extend_from_slice(&Service::DiscoverReply(*d).payload()[1..]);
    }
    Some(format!("1 {:02x} {}", r.session, hex::encode(&bytes)))
}

/// Reads a record, or says in words what is wrong with it.
pub fn decode(text: &str) -> Result<Remembered, String> {
    let fields: Vec<&str> = text.split(' ').collect();
    let ["1", session, lamps] = fields[..] else {
        return Err("it is not a street record of this console".into());
    };
    let session = match hex::parse(session) {
        Ok(b) if session.len() == 2 => b[0],
        _ => return Err("its session is not two hex digits".into()),
    };
    let bytes = hex::parse(lamps).map_err(|_| "its lamps are not hex digits".to_string())?;
    if bytes.len() % LAMP_BYTES != 0 {
        return Err("its lamps are not 11 bytes each".into());
    }
    if bytes.len() > LAMPS * LAMP_BYTES {
        return Err("it has more than 1000 lamps".into());
    }
    let mut r = Remembered {
        session,
        lamps: Vec::new(),
    };
    for c in bytes.chunks(LAMP_BYTES) {
        let mut payload = vec![0x0b];
        payload.extend_from_slice(&c[6..]);
        let Ok(Service::DiscoverReply(d)) = Service::parse(&payload) else {
            return Err("a lamp's discovery reply cannot be read".into());
        };
        let mut a = Address::default();
        a.0.copy_from_slice(&c[..6]);
        r.lamps.push((a, d));
    }
    Ok(r)
}

/// The streets kept, `all`, after connection `id` was used: its
/// `record` first (none: forgotten), at most [`CONNECTIONS`].
pub fn put(all: &str, id: &str, record: Option<&str>) -> String {
    let mut lines: Vec<String> = record.map(|r| format!("{id}\t{r}")).into_iter().collect();
    lines.extend(
        all.lines()
            .filter(|l| l.split('\t').next() != Some(id))
            .map(String::from),
    );
    lines.truncate(CONNECTIONS);
    lines.join("\n")
}

/// The record kept for connection `id` in `all`, if any.
pub fn find<'a>(all: &'a str, id: &str) -> Option<&'a str> {
    all.lines()
        .find_map(|l| l.strip_prefix(id)?.strip_prefix('\t'))
}

/// The street remembered for connection `id`, if any; a record that
/// cannot be read is forgotten, and why is returned in words.
pub fn recall(id: &str) -> Result<Option<Remembered>, String> {
    let all = load(KEY).unwrap_or_default();
    let Some(text) = find(&all, id) else {
        return Ok(None);
    };
    decode(text).map(Some).map_err(|why| {
        store(KEY, Some(&put(&all, id, None)));
        format!("The street kept in this browser for {id} cannot be read ({why}); it is forgotten and the street is discovered again.")
    })
}

/// Remembers `r` for connection `id` (a street beyond [`LAMPS`] is
/// forgotten instead: its lamps left out would stay quiet).
pub fn save(id: &str, r: &Remembered) {
    let all = load(KEY).unwrap_or_default();
    store(KEY, Some(&put(&all, id, encode(r).as_deref())));
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::app::Release;

    fn lamp(n: u64, snr: u8) -> (Address, Discovered) {
        let d = Discovered {
            firmware: Release { major: 1, minor: 4 },
            stack: Release {
                major: 2,
                minor: n as u8,
            },
            snr,
        };
        (Address::from_u64(0x0080_e100_0000 + n), d)
    }

    fn street(session: u8, lamps: u64) -> Remembered {
        Remembered {
            session,
            lamps: (1..=lamps).map(|n| lamp(n, (n % 32) as u8)).collect(),
        }
    }

    #[test]
    fn a_street_comes_back_as_it_was_kept() {
        for r in [
            street(0, 0),
            street(7, 1),
            street(255, 12),
            street(3, LAMPS as u64),
        ] {
            let text = encode(&r).unwrap();
            assert_eq!(decode(&text), Ok(r.clone()), "{text:.60}");
            let all = put("", "a connection", Some(&text));
            assert_eq!(find(&all, "a connection").map(decode), Some(Ok(r)));
        }
        let one = encode(&street(0x2a, 1)).unwrap();
        // Address, firmware 1.4, stack 2.1, SNR 1.
        assert_eq!(one, "1 2a 0080e10000010104020101");
    }

    #[test]
    fn a_street_beyond_the_bound_is_not_kept() {
        assert!(encode(&street(1, LAMPS as u64 + 1)).is_none());
        let over = format!("1 01 {}", "0080e10000010104020101".repeat(LAMPS + 1));
        assert_eq!(decode(&over), Err("it has more than 1000 lamps".into()));
        // Saved beyond the bound, a street is forgotten.
        assert_eq!(put("a\t1 01 ", "a", None), "");
    }

    #[test]
    fn the_connections_used_last_are_kept() {
        let mut all = String::new();
        for id in ["a", "b", "c", "d", "b", "e", "f"] {
            all = put(&all, id, Some("1 01 "));
        }
        assert_eq!(all, "f\t1 01 \ne\t1 01 \nb\t1 01 \nd\t1 01 ");
        assert_eq!(all.lines().count(), CONNECTIONS);
        assert_eq!(find(&all, "b"), Some("1 01 "));
        assert_eq!(find(&all, "a"), None, "the oldest went");
        assert_eq!(find(&all, "c"), None, "the oldest went");
        let all = put(&all, "b", None);
        assert_eq!(find(&all, "b"), None, "forgotten");
        assert_eq!(find(&all, "d"), Some("1 01 "), "the others stay");
        // A name that begins another is not it.
        let both = put("ab\t1 02 ", "a", Some("1 03 "));
        assert_eq!(find(&both, "ab"), Some("1 02 "));
        assert_eq!(find(&both, "a"), Some("1 03 "));
    }

    #[test]
    fn a_corrupt_record_is_refused_in_words() {
        let cases = [
            ("", "it is not a street record of this console"),
            ("2 01 ", "it is not a street record of this console"),
            ("1 01", "it is not a street record of this console"),
            ("1 01 00 extra", "it is not a street record of this console"),
            ("1 1 ", "its session is not two hex digits"),
            ("1 zz ", "its session is not two hex digits"),
            ("1 01 0080e1zz", "its lamps are not hex digits"),
            ("1 01 0080e1000001", "its lamps are not 11 bytes each"),
        ];
        for (text, why) in cases {
            assert_eq!(decode(text), Err(why.to_string()), "{text:?}");
        }
        // An empty street is a street.
        assert_eq!(decode("1 01 "), Ok(street(1, 0)));
    }

    #[test]
    fn a_connection_is_named_by_what_identifies_it() {
        let sim = connection(
            "board",
            "concentrator board (simulated, 12 lamps)",
            57_600,
            Some(7580),
        );
        assert_eq!(
            sim,
            "board · concentrator board (simulated, 12 lamps) · 57600 Bd · seed 7580"
        );
        let port = connection("board", "USB 0483:5740 (WebSerial)", 57_600, None);
        assert_ne!(
            port,
            connection("board", "USB 0483:5740 (WebSerial)", 19_200, None)
        );
        assert_ne!(
            port,
            connection("concentrator", "USB 0483:5740 (WebSerial)", 57_600, None)
        );
    }
}
