//! A street's lamp readings (what a lamp's page plots) kept in the
//! browser's storage, so that a reload keeps them (docs/console.md,
//! "Plots").
//!
//! The session stamps a reading on the transport's clock, which starts
//! again at each connection; the history's clock is that clock plus an
//! epoch set at the connection ([`start`]): the computer's clock then
//! (µs since the Unix epoch), or the newest reading kept if that is later
//! (a simulated street run faster than the page), so it never runs
//! backwards.
//!
//! One key holds the history of the connection used last: a header line
//! `plm-console history 1`, a tab and the connection
//! ([`crate::street_store::connection`]), then a line per lamp: its
//! address (12 hex digits), the time of its first reading (ms since the
//! Unix epoch, decimal) and its readings in hex, 9 bytes each: ms since
//! the reading before (u32), power W (u16), temperature °C (i16) and SNR
//! dB (i8, -128 when unknown), big-endian. At most [`HISTORY`] readings
//! a lamp and [`BOUND`] characters in all, the oldest readings of the
//! street dropped first; written at most every [`EVERY_US`] and when the
//! page is left.

use crate::storage::{load, store};
use crate::street::{Lamp, Sample, HISTORY};
use plm_core::app::Address;
use plm_core::hex;
use plm_core::time::Instant;
use std::cell::RefCell;
use std::collections::{BTreeMap, VecDeque};

/// Characters kept at most (2 MB: the record is ASCII).
pub const BOUND: usize = 2_000_000;
/// The page's time between two writes at most, µs.
pub const EVERY_US: f64 = 30e6;

const KEY: &str = "plm-console.history";
const HEADER: &str = "plm-console history 1\t";
/// Bytes of one reading.
const READING: usize = 9;
/// SNR byte of a reading without one.
const NO_SNR: i8 = i8::MIN;

/// Each lamp's readings, oldest first, on the history's clock (µs since
/// the Unix epoch).
pub type Kept = Vec<(Address, Vec<Sample>)>;

/// Characters of a lamp's line: address, first time, readings, newline.
fn line_len(first_ms: u64, readings: usize) -> usize {
    12 + 1 + first_ms.to_string().len() + 1 + 2 * READING * readings + 1
}

/// The record of `lamps` for connection `id`, within [`BOUND`]: the
/// oldest readings of the street are left out first.
pub fn encode(id: &str, lamps: &Kept) -> String {
    let id = id.replace(['\n', '\t'], " ");
    // Where each lamp's readings kept begin (the newest HISTORY at most).
    let mut from: Vec<usize> = lamps
        .iter()
        .map(|(_, s)| s.len().saturating_sub(HISTORY))
        .collect();
    let len = |i: usize, from: usize| {
        let s = &lamps[i].1[from..];
        s.first().map_or(0, |f| line_len(f.at / 1000, s.len()))
    };
    let mut total = HEADER.len() + id.len() + 1;
    total += (0..lamps.len()).map(|i| len(i, from[i])).sum::<usize>();
    while total > BOUND {
        // The oldest reading left of the street.
        let Some(i) = (0..lamps.len())
            .filter(|&i| from[i] < lamps[i].1.len())
            .min_by_key(|&i| lamps[i].1[from[i]].at)
        else {
            break;
        };
        total -= len(i, from[i]);
        from[i] += 1;
        total += len(i, from[i]);
    }
    let mut text = format!("{HEADER}{id}\n");
    for ((address, samples), from) in lamps.iter().zip(from) {
        let samples = &samples[from..];
        let Some(first) = samples.first() else {
            continue;
        };
        let mut bytes = Vec::with_capacity(READING * samples.len());
        let mut was = first.at / 1000;
        for s in samples {
            let ms = s.at / 1000;
            let delta = u32::try_from(ms.saturating_sub(was)).unwrap_or(u32::MAX);
            was = ms;
            bytes.extend_from_slice(&delta.to_be_bytes());
            bytes.extend_from_slice(&s.power.to_be_bytes());
            bytes.extend_from_slice(&s.temperature.to_be_bytes());
            bytes.push(s.snr.unwrap_or(NO_SNR) as u8);
        }
        text.push_str(&format!(
            "{} {} {}\n",
            hex::encode(&address.0),
            first.at / 1000,
            hex::encode(&bytes)
        ));
    }
    text
}

/// Reads a record: its connection and readings, or what is wrong with it
/// in words.
pub fn decode(text: &str) -> Result<(String, Kept), String> {
    if text.len() > BOUND {
        return Err(format!("it is larger than the bound of {BOUND} characters"));
    }
    let mut lines = text.lines();
    let Some(id) = lines.next().and_then(|h| h.strip_prefix(HEADER)) else {
        return Err("it is not a history record of this console".into());
    };
    let mut kept: Kept = Vec::new();
    for (n, line) in lines.enumerate() {
        let bad = |what: &str| format!("line {} {what}", n + 2);
        let [address, first, readings] = line.split(' ').collect::<Vec<_>>()[..] else {
            return Err(bad("is not an address, a time and readings"));
        };
        let address = match hex::parse(address) {
            Ok(b) if b.len() == 6 => Address(b.try_into().unwrap_or_default()),
            _ => return Err(bad("has no address of 12 hex digits")),
        };
        if kept.iter().any(|(a, _)| *a == address) {
            return Err(bad(&format!("names lamp {address} again")));
        }
        let first: u64 = match first.bytes().all(|b| b.is_ascii_digit()) && first.len() <= 15 {
            true if !first.is_empty() => first.bytes().fold(0, |n, b| n * 10 + u64::from(b - b'0')),
            _ => return Err(bad("has no time in whole ms of at most 15 digits")),
        };
        let bytes = match hex::parse(readings) {
            Ok(b) if !b.is_empty() && b.len() % READING == 0 => b,
            _ => return Err(bad("has no readings of 9 bytes each in hex")),
        };
        if bytes.len() / READING > HISTORY {
            return Err(bad(&format!("has more than {HISTORY} readings")));
        }
        let mut ms = first;
        let mut samples = Vec::with_capacity(bytes.len() / READING);
        for r in bytes.chunks(READING) {
            let word = |i: usize| u16::from_be_bytes([r[i], r[i + 1]]);
            ms += u64::from(u32::from_be_bytes([r[0], r[1], r[2], r[3]]));
            samples.push(Sample {
                at: ms * 1000,
                power: word(4),
                temperature: word(6) as i16,
                snr: Some(r[8] as i8).filter(|&s| s != NO_SNR),
            });
        }
        kept.push((address, samples));
    }
    Ok((id.to_string(), kept))
}

/// `kept` then the session's `live` readings on the history's clock (the
/// transport's clock plus `epoch`), the newest [`HISTORY`].
pub fn merge(kept: &[Sample], epoch: Instant, live: &VecDeque<Sample>) -> Vec<Sample> {
    let mut all: Vec<Sample> = kept.to_vec();
    all.extend(live.iter().map(|s| Sample {
        at: s.at + epoch,
        ..*s
    }));
    all.drain(..all.len().saturating_sub(HISTORY));
    all
}

/// The history of the connection in use.
#[derive(Default)]
struct State {
    id: String,
    epoch: Instant,
    /// A list, not a map: no ordered map of its own in the page's wasm
    /// (docs/console.md, "Size").
    kept: Kept,
    written_at: Option<f64>,
}

thread_local! {
    static STATE: RefCell<State> = RefCell::default();
}

/// At a connection `id` (none: no street) whose transport's clock reads
/// `now`: the readings kept for it, and the history's clock. A record
/// that cannot be read is forgotten, and the reason returned in words.
pub fn start(id: &str, now: Instant) -> Option<String> {
    let (kept, problem) = match load(KEY).map(|t| decode(&t)) {
        Some(Ok((kept_id, kept))) if kept_id == id => (kept, None),
        Some(Err(why)) => {
            store(KEY, None);
            (
                Vec::new(),
                Some(format!(
                    "The lamps' readings kept in this browser cannot be read ({why}); they are forgotten."
                )),
            )
        }
        _ => (Vec::new(), None),
    };
    let newest = kept
        .iter()
        .filter_map(|(_, s)| s.last().map(|s| s.at))
        .max()
        .unwrap_or(0);
    let epoch = (wall_us().saturating_sub(now)).max(newest);
    STATE.with_borrow_mut(|s| {
        *s = State {
            id: id.to_string(),
            epoch,
            kept,
            written_at: None,
        }
    });
    problem
}

/// The history's clock at the street's 0 (µs since the Unix epoch).
pub fn epoch() -> Instant {
    STATE.with_borrow(|s| s.epoch)
}

/// A lamp's readings on the history's clock, oldest first: those kept
/// from before, then the session's.
pub fn of(lamp: &Lamp) -> Vec<Sample> {
    STATE.with_borrow(|s| {
        let kept = s
            .kept
            .iter()
            .find(|(a, _)| *a == lamp.address)
            .map_or(&[][..], |(_, k)| &k[..]);
        merge(kept, s.epoch, &lamp.history)
    })
}

/// Writes the readings of `fleet` if [`EVERY_US`] of the page's clock
/// (`page_us`) passed since the last write, or at once if `now`.
pub fn keep(fleet: &BTreeMap<Address, Lamp>, page_us: f64, now: bool) {
    let due = STATE.with_borrow(|s| {
        !s.id.is_empty() && (now || s.written_at.is_none_or(|t| page_us - t >= EVERY_US))
    });
    if !due {
        return;
    }
    let lamps: Kept = fleet.values().map(|l| (l.address, of(l))).collect();
    let text = STATE.with_borrow_mut(|s| {
        s.written_at = Some(page_us);
        encode(&s.id, &lamps)
    });
    store(KEY, Some(&text));
}

/// The computer's clock, µs since the Unix epoch (0 natively).
fn wall_us() -> Instant {
    #[cfg(target_arch = "wasm32")]
    {
        (js_sys::Date::now() * 1000.0) as Instant
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T0: Instant = 1_764_288_000_000_000; // 2025-11-28 00:00 UTC, µs

    fn sample(at: Instant, power: u16, snr: Option<i8>) -> Sample {
        Sample {
            at,
            power,
            temperature: -12,
            snr,
        }
    }

    fn lamp(n: u64) -> Address {
        Address::from_u64(0x0080_e100_0000 + n)
    }

    /// `count` readings 5 s apart from `start`.
    fn readings(start: Instant, count: usize) -> Vec<Sample> {
        (0..count)
            .map(|i| sample(start + i as u64 * 5_000_000, 100 + i as u16, Some(20)))
            .collect()
    }

    #[test]
    fn a_record_reads_back_as_written_to_the_ms() {
        let kept: Kept = vec![
            (
                lamp(1),
                vec![
                    sample(T0, 150, Some(31)),
                    sample(T0 + 5_000_999, 90, None),
                    sample(T0 + 3_600_000_000, 0, Some(-4)),
                ],
            ),
            (lamp(2), vec![sample(T0 + 7_000, 75, Some(12))]),
        ];
        let text = encode(
            "board · simulated street (12 lamps) · 57600 Bd · seed 1",
            &kept,
        );
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "plm-console history 1\tboard · simulated street (12 lamps) · 57600 Bd · seed 1"
        );
        assert_eq!(lines[2], "0080e1000002 1764288000007 00000000004bfff40c");
        let (id, back) = decode(&text).unwrap();
        assert!(id.starts_with("board · simulated street"));
        assert_eq!(back[0].1[1].at, T0 + 5_000_000);
        assert_eq!(back[0].1[1].snr, None);
        assert_eq!(back[0].1[2], sample(T0 + 3_600_000_000, 0, Some(-4)));
        assert_eq!(back[1], kept[1]);
    }

    #[test]
    fn the_bound_drops_the_oldest_readings_of_the_street_first() {
        // 500 lamps of 240 readings: 2.2 MB, over the bound.
        let kept: Kept = (0..500)
            .map(|n| (lamp(n), readings(T0 + n * 1000, HISTORY)))
            .collect();
        let text = encode("id", &kept);
        assert!(text.len() <= BOUND, "{}", text.len());
        assert!(text.len() > BOUND - 100, "as much as fits: {}", text.len());
        let (_, back) = decode(&text).unwrap();
        let oldest_kept = back.iter().map(|(_, s)| s[0].at).min().unwrap();
        let newest_dropped = kept
            .iter()
            .zip(&back)
            .filter_map(|((_, all), (_, k))| all[..all.len() - k.len()].last().map(|s| s.at))
            .max()
            .unwrap();
        assert!(newest_dropped <= oldest_kept);
        // Every lamp keeps its newest readings.
        for ((_, all), (_, k)) in kept.iter().zip(&back) {
            assert_eq!(k.last(), all.last());
        }
        // More than HISTORY readings of a lamp: the newest HISTORY.
        let long = vec![(lamp(1), readings(T0, HISTORY + 10))];
        let (_, back) = decode(&encode("id", &long)).unwrap();
        assert_eq!(back[0].1[..], long[0].1[10..]);
    }

    #[test]
    fn a_damaged_record_is_refused_in_words() {
        let good = encode("id", &vec![(lamp(1), readings(T0, 2))]);
        let line = good.lines().nth(1).unwrap().to_string();
        let with = |l: &str| format!("{HEADER}id\n{l}\n");
        let cases = [
            ("", "it is not a history record of this console".to_string()),
            (
                "plm-console history 2\tid\n",
                "it is not a history record of this console".into(),
            ),
            (
                &with("0080e1000001 17"),
                "line 2 is not an address, a time and readings".into(),
            ),
            (
                &with(&line.replacen("0080e1000001", "0080e10000zz", 1)),
                "line 2 has no address of 12 hex digits".into(),
            ),
            (
                &with(&line.replacen("0080e1000001", "0080e10001", 1)),
                "line 2 has no address of 12 hex digits".into(),
            ),
            (
                &with(&line.replacen(" 1764", " -1764", 1)),
                "line 2 has no time in whole ms of at most 15 digits".into(),
            ),
            (
                &with(&line.replacen(" 1764", " 99999991764", 1)),
                "line 2 has no time in whole ms of at most 15 digits".into(),
            ),
            // Cut short in a reading, as a write interrupted would leave it.
            (
                &good[..good.len() - 5],
                "line 2 has no readings of 9 bytes each in hex".into(),
            ),
            (
                &with(&format!("{line}\n{line}")),
                "line 3 names lamp 0080e1000001 again".into(),
            ),
            (
                &with(&format!(
                    "0080e1000001 1 {}",
                    "00".repeat(9 * (HISTORY + 1))
                )),
                format!("line 2 has more than {HISTORY} readings"),
            ),
            (
                &"x".repeat(BOUND + 1),
                format!("it is larger than the bound of {BOUND} characters"),
            ),
        ];
        for (text, why) in cases {
            assert_eq!(
                decode(text).map(|_| ()),
                Err(why),
                "{:?}",
                &text[..text.len().min(80)]
            );
        }
        // The largest deltas a record can hold still read, without overflow.
        let far = with(&format!(
            "0080e1000001 999999999999999 {}",
            "ffffffff0000000000".repeat(HISTORY)
        ));
        let (_, back) = decode(&far).unwrap();
        assert_eq!(back[0].1.len(), HISTORY);
    }

    #[test]
    fn the_session_s_readings_follow_those_kept_on_one_clock() {
        let kept = readings(T0, 3);
        let live: VecDeque<Sample> = [sample(2_000_000, 60, None)].into();
        let epoch = T0 + 60_000_000;
        let all = merge(&kept, epoch, &live);
        assert_eq!(all.len(), 4);
        assert_eq!(all[3].at, T0 + 62_000_000);
        assert_eq!(all[3].power, 60);
        // At most HISTORY, the newest.
        let live: VecDeque<Sample> = readings(0, HISTORY).into();
        let all = merge(&kept, epoch, &live);
        assert_eq!(all.len(), HISTORY);
        assert_eq!(all[0].at, epoch);
    }
}
