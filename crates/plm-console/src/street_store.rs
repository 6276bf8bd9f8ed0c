//! The streets found, kept in the browser's storage per connection, so
//! that a reload or a reconnection reads the lamps at once and discovery
//! only looks for new ones (docs/console.md, "A street remembered").
//!
//! A connection is what identifies it: the profile, the port in words
//! (a WebSerial port's USB ids, a simulated street's size), the baud
//! rate and a simulated street's seed. Each is kept under its own key,
//! `1 SS HEX`: the record's layout, the discovery session (two hex digits)
//! and, per lamp, its 6-byte address then its discovery reply's data
//! (board protocol 0Bh, as plm-core writes it). An index lists the
//! connections, the one used last first; the oldest goes beyond
//! [`CONNECTIONS`].

use crate::storage::{load, store};
use plm_core::app::service::{Discovered, Service};
use plm_core::app::Address;
use plm_core::hex;

/// Connections remembered at most.
pub const CONNECTIONS: usize = 4;
/// Lamps of one street remembered at most; a larger street is not kept.
pub const LAMPS: usize = 1000;

const INDEX: &str = "plm-console.streets";
const PREFIX: &str = "plm-console.street.";
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
    let mut id = format!("{profile} · {port} · {baud} Bd");
    if let Some(s) = seed {
        id.push_str(&format!(" · seed {s}"));
    }
    id.replace('\n', " ")
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
    let mut parts = text.split(' ');
    if parts.next() != Some("1") {
        return Err("it is not a street record of this console".into());
    }
    let session = parts
        .next()
        .filter(|s| s.len() == 2)
        .and_then(|s| u8::from_str_radix(s, 16).ok())
        .ok_or("its session is not two hex digits")?;
    let bytes = hex::parse(parts.next().unwrap_or(""))
        .map_err(|_| "its lamps are not hex digits".to_string())?;
    if parts.next().is_some() {
        return Err("it has more fields than a record has".into());
    }
    if bytes.len() % LAMP_BYTES != 0 {
        return Err(format!(
            "its lamps are {} bytes, not a multiple of {LAMP_BYTES}",
            bytes.len()
        ));
    }
    if bytes.len() / LAMP_BYTES > LAMPS {
        return Err(format!("it has more than {LAMPS} lamps"));
    }
    let lamps = bytes
        .chunks(LAMP_BYTES)
        .map(|c| {
            let mut payload = vec![0x0b];
            payload.extend_from_slice(&c[6..]);
            match Service::parse(&payload) {
                Ok(Service::DiscoverReply(d)) => Ok((Address(c[..6].try_into().unwrap()), d)),
                _ => Err("a lamp's discovery reply cannot be read".to_string()),
            }
        })
        .collect::<Result<_, _>>()?;
    Ok(Remembered { session, lamps })
}

/// The index after `id` was used: first, at most [`CONNECTIONS`]; and
/// the connections that fell out of it.
pub fn reorder(index: &str, id: &str) -> (String, Vec<String>) {
    let mut ids: Vec<&str> = vec![id];
    ids.extend(index.lines().filter(|l| !l.is_empty() && *l != id));
    let dropped = ids.split_off(ids.len().min(CONNECTIONS));
    (
        ids.join("\n"),
        dropped.into_iter().map(String::from).collect(),
    )
}

/// The street remembered for connection `id`, if any; a record that
/// cannot be read is forgotten, and why is returned in words.
pub fn recall(id: &str) -> Result<Option<Remembered>, String> {
    let Some(text) = load(&format!("{PREFIX}{id}")) else {
        return Ok(None);
    };
    decode(&text).map(Some).map_err(|why| {
        forget(id);
        format!("The street kept in this browser for {id} cannot be read ({why}); it is forgotten and the street is discovered again.")
    })
}

/// Remembers `r` for connection `id` (a street beyond [`LAMPS`] is
/// forgotten instead: its lamps left out would stay quiet).
pub fn save(id: &str, r: &Remembered) {
    let Some(text) = encode(r) else {
        return forget(id);
    };
    let index = load(INDEX).unwrap_or_default();
    if index.lines().next() != Some(id) {
        let (index, dropped) = reorder(&index, id);
        for old in dropped {
            store(&format!("{PREFIX}{old}"), None);
        }
        store(INDEX, Some(&index));
    }
    store(&format!("{PREFIX}{id}"), Some(&text));
}

/// Forgets what was kept for connection `id`.
pub fn forget(id: &str) {
    store(&format!("{PREFIX}{id}"), None);
    let index = load(INDEX).unwrap_or_default();
    let rest: Vec<&str> = index.lines().filter(|l| *l != id).collect();
    store(INDEX, Some(&rest.join("\n")));
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
        }
        let one = encode(&street(0x2a, 1)).unwrap();
        // Address, firmware 1.4, stack 2.1, SNR 1.
        assert_eq!(one, "1 2a 0080e10000010104020101");
    }

    #[test]
    fn a_street_beyond_the_bound_is_not_kept() {
        assert!(encode(&street(1, LAMPS as u64 + 1)).is_none());
        let over = format!("1 01 {}", "0080e10000010104020101".repeat(LAMPS + 1));
        assert_eq!(
            decode(&over),
            Err(format!("it has more than {LAMPS} lamps"))
        );
    }

    #[test]
    fn the_index_keeps_the_connections_used_last() {
        let mut index = String::new();
        let mut dropped = Vec::new();
        for id in ["a", "b", "c", "d", "b", "e", "f"] {
            let (i, d) = reorder(&index, id);
            index = i;
            dropped.extend(d);
        }
        assert_eq!(index, "f\ne\nb\nd");
        assert_eq!(dropped, ["a", "c"]);
        assert_eq!(index.lines().count(), CONNECTIONS);
    }

    #[test]
    fn a_corrupt_record_is_refused_in_words() {
        let cases = [
            ("", "it is not a street record of this console"),
            ("2 01 ", "it is not a street record of this console"),
            ("1 1 ", "its session is not two hex digits"),
            ("1 zz ", "its session is not two hex digits"),
            ("1 01 0080e1zz", "its lamps are not hex digits"),
            (
                "1 01 0080e1000001 extra",
                "it has more fields than a record has",
            ),
            (
                "1 01 0080e1000001",
                "its lamps are 6 bytes, not a multiple of 11",
            ),
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
            "street-board",
            "concentrator board (simulated, 12 lamps)",
            57_600,
            Some(7580),
        );
        assert_eq!(
            sim,
            "street-board · concentrator board (simulated, 12 lamps) · 57600 Bd · seed 7580"
        );
        let port = connection("street-board", "USB 0483:5740 (WebSerial)", 57_600, None);
        assert_ne!(
            port,
            connection("street-board", "USB 0483:5740 (WebSerial)", 19_200, None)
        );
        assert_ne!(
            port,
            connection("street-modem", "USB 0483:5740 (WebSerial)", 57_600, None)
        );
        assert!(!connection("p", "a\nb", 1, None).contains('\n'));
    }
}
