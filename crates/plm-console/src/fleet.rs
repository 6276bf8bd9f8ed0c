//! The fleet table: one row per lamp as the Street view shows, sorts,
//! filters and exports it (CSV and JSON). Pure, so its rules are tested
//! natively. [`picture`]: the same fleet as the street picture.

pub mod picture;

use crate::street::Lamp;
use plm_core::app::energy::Meter;
use plm_core::app::hid::LampState;
use plm_core::app::Address;
use plm_core::json::{self, Json};
use plm_core::time::Instant;

/// The columns, in order: (key, header).
pub const COLUMNS: &[(&str, &str)] = &[
    ("address", "Address"),
    ("firmware", "Firmware"),
    ("state", "Lamp"),
    ("dimming", "Dimming %"),
    ("power", "Power W"),
    ("energy", "Energy Wh (est.)"),
    ("bus_voltage", "Bus V"),
    ("lamp_voltage", "Lamp V"),
    ("supply_voltage", "Supply V"),
    ("temperature", "Temp °C"),
    ("hours", "Hours"),
    ("power_ons", "Power-ons"),
    ("snr", "SNR dB"),
    ("last_seen", "Last seen"),
];

/// A lamp's state at a glance, decided once for the table's colours and
/// the street picture's marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Look {
    /// Lit (RUN), at full power as far as this console set it.
    Running,
    /// Lit, with a dimming below 100 % last set from this console (the
    /// board has no dimming read, seed 004 Appendix A).
    Dimmed,
    /// Igniting, warming up, waiting to restrike, or a state the seed
    /// does not list.
    Between,
    /// Off (IDLE).
    Off,
    /// FAILURE.
    Failed,
    /// It stopped answering.
    Unreachable,
    /// Not read yet.
    NotRead,
}

impl Look {
    /// Every look, in the legend's order.
    pub const ALL: [Look; 7] = [
        Look::Running,
        Look::Dimmed,
        Look::Between,
        Look::Off,
        Look::Failed,
        Look::Unreachable,
        Look::NotRead,
    ];

    /// The look of `lamp`.
    pub fn of(lamp: &Lamp) -> Look {
        match (&lamp.unreachable, lamp.state()) {
            (Some(_), _) => Look::Unreachable,
            (None, None) => Look::NotRead,
            (None, Some(LampState::Run)) if lamp.dimming.is_some_and(|d| d < 100) => Look::Dimmed,
            (None, Some(LampState::Run)) => Look::Running,
            (None, Some(LampState::Failure)) => Look::Failed,
            (None, Some(LampState::Idle)) => Look::Off,
            (None, Some(_)) => Look::Between,
        }
    }

    /// Whether it needs a technician's eye.
    pub fn in_trouble(self) -> bool {
        matches!(self, Look::Failed | Look::Unreachable)
    }

    /// Its name in words.
    pub fn name(self) -> &'static str {
        match self {
            Look::Running => "running",
            Look::Dimmed => "dimmed",
            Look::Between => "starting or waiting",
            Look::Off => "off",
            Look::Failed => "failed",
            Look::Unreachable => "not answering",
            Look::NotRead => "not read yet",
        }
    }

    /// Its class in the table's colours (style.css).
    pub fn class(self) -> &'static str {
        match self {
            Look::Running | Look::Dimmed => "lamp-run",
            Look::Failed | Look::Unreachable => "lamp-bad",
            Look::Off => "lamp-off",
            Look::Between => "lamp-busy",
            Look::NotRead => "",
        }
    }
}

/// One lamp as a row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The lamp's board.
    pub address: Address,
    /// `1.4`, empty when unknown.
    pub firmware: String,
    /// `RUN`, `FAILURE`, `UNREACHABLE`, or empty.
    pub state: String,
    /// Its state at a glance.
    pub look: Look,
    /// Whether it needs a technician's eye.
    pub trouble: bool,
    /// Numbers by column key, `None` when unknown.
    pub numbers: Vec<(&'static str, Option<i64>)>,
}

impl Row {
    /// The row of `lamp`, its last answer on the history's clock
    /// (`epoch` plus the street's: [`crate::history_store::epoch`], the
    /// plots' clock). A time, not an age: a row changes when its lamp
    /// answers, not every second, so a redraw of 500 lamps lays out and
    /// paints the rows read since the last one, not every row in view.
    pub fn of(lamp: &Lamp, epoch: Instant) -> Row {
        let b = lamp.ballast;
        let watched = lamp.energy.watched() > 0;
        let look = Look::of(lamp);
        let state = match (&lamp.unreachable, lamp.state()) {
            (Some(_), _) => "UNREACHABLE".to_string(),
            (None, Some(s)) => s.name().to_string(),
            (None, None) => String::new(),
        };
        Row {
            address: lamp.address,
            firmware: lamp
                .discovered
                .map(|d| d.firmware.to_string())
                .unwrap_or_default(),
            look,
            trouble: look.in_trouble(),
            state,
            numbers: vec![
                ("dimming", lamp.dimming.map(i64::from)),
                ("power", b.map(|b| i64::from(b.lamp_power))),
                ("energy", watched.then(|| lamp.energy.watt_hours() as i64)),
                ("bus_voltage", b.map(|b| i64::from(b.bus_voltage))),
                ("lamp_voltage", b.map(|b| i64::from(b.lamp_voltage))),
                ("supply_voltage", b.map(|b| i64::from(b.supply_voltage))),
                ("temperature", b.map(|b| i64::from(b.temperature))),
                ("hours", b.map(|b| i64::from(b.lifetime_hours))),
                ("power_ons", b.map(|b| i64::from(b.power_ons))),
                ("snr", lamp.snr.map(i64::from)),
                // Not a column: the span the estimate covers, in the JSON.
                (
                    "energy_watched_s",
                    watched.then(|| (lamp.energy.watched() / 1_000_000) as i64),
                ),
                // Seconds since the Unix epoch; a local clock time in a cell.
                (
                    "last_seen",
                    lamp.last_seen.map(|t| ((epoch + t) / 1_000_000) as i64),
                ),
            ],
        }
    }

    /// The number in column `key`.
    pub fn number(&self, key: &str) -> Option<i64> {
        self.numbers
            .iter()
            .find(|(k, _)| *k == key)
            .and_then(|(_, v)| *v)
    }

    /// The cell of column `key` as text (empty when unknown).
    pub fn cell(&self, key: &str) -> String {
        match key {
            "address" => self.address.to_string(),
            "firmware" => self.firmware.clone(),
            "state" => self.state.clone(),
            "last_seen" => self.number(key).map_or_else(String::new, |t| {
                crate::numbers::clock_label(t as f64 + crate::numbers::zone_offset(), 1.0)
            }),
            k => self.number(k).map(|v| format!("{v}")).unwrap_or_default(),
        }
    }

    /// Whether the row matches a filter text (address, state or
    /// firmware, case-insensitive; empty matches all).
    pub fn matches(&self, filter: &str) -> bool {
        let f = filter.trim().to_ascii_lowercase();
        f.is_empty()
            || has_text(&self.address.to_string(), &f)
            || has_text(&self.state.to_ascii_lowercase(), &f)
            || has_text(&self.firmware, &f)
            || (f == "trouble" && self.trouble)
    }
}

/// Whether `text` holds `part`: byte by byte, which for the short texts
/// of a row and a port's name is as quick as core's substring search and
/// leaves its searcher out of the page (docs/console.md, "Size").
pub fn has_text(text: &str, part: &str) -> bool {
    let (t, p) = (text.as_bytes(), part.as_bytes());
    p.is_empty() || t.windows(p.len()).any(|w| w == p)
}

/// Sorts rows by column `key`, unknown values last, equal values by
/// address (so the order never depends on where a row was before).
///
/// An insertion sort: the table has at most 500 rows, sorted on a click,
/// and std's sort would bring 3 KiB of code into the page for this one
/// type (docs/console.md, "Size").
pub fn sort(rows: &mut [Row], key: &str, ascending: bool) {
    use std::cmp::Ordering;
    let direction = |o: Ordering| if ascending { o } else { o.reverse() };
    let order = |a: &Row, b: &Row| {
        let o = match key {
            "address" => direction(a.address.cmp(&b.address)),
            "firmware" => direction(a.firmware.cmp(&b.firmware)),
            "state" => direction(a.state.cmp(&b.state)),
            k => match (a.number(k), b.number(k)) {
                (Some(x), Some(y)) => direction(x.cmp(&y)),
                (Some(_), None) => Ordering::Less,
                (None, Some(_)) => Ordering::Greater,
                (None, None) => Ordering::Equal,
            },
        };
        o.then_with(|| a.address.cmp(&b.address))
    };
    for i in 1..rows.len() {
        let mut j = i;
        while j > 0 && order(&rows[j - 1], &rows[j]) == Ordering::Greater {
            rows.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// The rows as CSV (RFC 4180: comma separated, header first, CRLF).
pub fn to_csv(rows: &[Row]) -> String {
    let mut s = COLUMNS.iter().map(|c| c.1).collect::<Vec<_>>().join(",");
    s.push_str("\r\n");
    for r in rows {
        let cells: Vec<String> = COLUMNS.iter().map(|c| r.cell(c.0)).collect();
        s.push_str(&cells.join(","));
        s.push_str("\r\n");
    }
    s
}

/// The rows as a JSON array of objects keyed by column.
pub fn to_json(rows: &[Row]) -> String {
    let v = rows
        .iter()
        .map(|r| {
            let mut o = json::Object::new();
            o.insert("address", Json::from(r.address.to_string()));
            o.insert("firmware", Json::from(r.firmware.as_str()));
            o.insert("state", Json::from(r.state.as_str()));
            o.insert("trouble", Json::from(r.trouble));
            for (k, v) in &r.numbers {
                o.insert(*k, Json::from(*v));
            }
            Json::Object(o)
        })
        .collect();
    Json::Array(v).pretty()
}

/// The street's energy as the console estimated it, in words: the sum of
/// its lamps' (plm_core::app::energy), and over how long it was watched.
pub fn street_energy<'a>(lamps: impl Iterator<Item = &'a Lamp>) -> String {
    let mut street = Meter::default();
    lamps.for_each(|l| street.add(&l.energy));
    let tenths = street.tenths_of_watt_hours();
    let seconds = street.watched() / 1_000_000;
    let span = if seconds < 120 {
        format!("{seconds} s")
    } else {
        format!("{} min", seconds / 60)
    };
    format!(
        "Energy: {}.{} Wh over the {span} this console watched (estimated from its power readings: the boards keep no energy counter)",
        tenths / 10,
        tenths % 10
    )
}

/// A dimming value typed in a form: a number, whose range plm-core
/// checks (`Hid::validate`) before anything is sent.
pub fn dimming_value(text: &str) -> Result<u8, String> {
    text.trim().parse::<u8>().map_err(|_| {
        format!(
            "nothing sent: \"{}\" is not a dimming value (a whole number of %)",
            text.trim()
        )
    })
}

/// A board address as the key of its row (6 bytes in a u64), and back.
pub fn row_key(a: Address) -> u64 {
    let mut k = [0; 8];
    k[2..].copy_from_slice(&a.0);
    u64::from_be_bytes(k)
}

pub fn key_address(key: u64) -> Address {
    let mut a = [0; 6];
    a.copy_from_slice(&key.to_be_bytes()[2..]);
    Address(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A text holds a part anywhere in it, the empty part always, a part
    /// longer than it never; UTF-8 is matched whole.
    #[test]
    fn a_text_holds_its_parts() {
        assert!(has_text(
            "ST7580 concentrator (simulated, 12 lamps)",
            "simulated"
        ));
        assert!(has_text("abc", "") && has_text("abc", "abc") && has_text("abc", "c"));
        assert!(!has_text("ab", "abc") && !has_text("simulate", "simulated"));
        assert!(has_text("Pont-l’Évêque (COM3)", "Évê"));
    }

    #[test]
    fn dimming_values_must_be_numbers() {
        assert_eq!(dimming_value(" 40 "), Ok(40));
        assert!(dimming_value("4o")
            .unwrap_err()
            .contains("not a dimming value"));
    }

    #[test]
    fn a_row_key_gives_its_address_back() {
        for a in [
            Address([0; 6]),
            Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x01]),
            Address::BROADCAST,
        ] {
            assert_eq!(key_address(row_key(a)), a);
        }
        // Distinct addresses, distinct rows.
        assert_ne!(
            row_key(Address([0, 0, 0, 0, 0, 1])),
            row_key(Address([1, 0, 0, 0, 0, 0]))
        );
    }
    use plm_core::app::Ballast;

    /// The history's clock at the street's 0: 2026-11-28 12:03:05 UTC.
    const EPOCH: Instant = 1_795_867_385_000_000;

    fn lamp(n: u64, power: u16, status: u16) -> Lamp {
        Lamp {
            address: Address::from_u64(0x0080_e100_0000 + n),
            ballast: Some(Ballast {
                lamp_power: power,
                status,
                ..Ballast::default()
            }),
            last_seen: Some(1_000_000),
            ..Lamp::default()
        }
    }

    #[test]
    fn rows_sort_filter_and_export() {
        let mut rows: Vec<Row> = [lamp(1, 150, 6), lamp(2, 0, 8), lamp(3, 75, 6)]
            .iter()
            .map(|l| Row::of(l, EPOCH))
            .collect();
        sort(&mut rows, "power", true);
        assert_eq!(
            rows.iter().map(|r| r.cell("power")).collect::<Vec<_>>(),
            ["0", "75", "150"]
        );
        assert!(rows[0].trouble && rows[0].state == "FAILURE");
        assert_eq!(rows.iter().filter(|r| r.matches("fail")).count(), 1);
        assert_eq!(rows.iter().filter(|r| r.matches("trouble")).count(), 1);
        let csv = to_csv(&rows);
        let lines: Vec<&str> = csv.split("\r\n").collect();
        assert_eq!(lines[0], "Address,Firmware,Lamp,Dimming %,Power W,Energy Wh (est.),Bus V,Lamp V,Supply V,Temp °C,Hours,Power-ons,SNR dB,Last seen");
        assert!(
            lines[1].starts_with("0080e1000002,,FAILURE,,0,"),
            "{}",
            lines[1]
        );
        assert!(
            lines[1].ends_with(",12:03:06"),
            "last seen at 12:03:05 plus the 1 s of the street's clock: {}",
            lines[1]
        );
        let json = to_json(&rows);
        assert!(json.contains("\"last_seen\": 1795867386"), "{json}");
        let Ok(Json::Array(json)) = json::parse(&to_json(&rows)) else {
            panic!("not a JSON array: {}", to_json(&rows));
        };
        assert_eq!(json[2].get("power"), Some(&Json::Int(150)));
        assert_eq!(json[0].get("trouble"), Some(&Json::Bool(true)));
        assert_eq!(json[0].get("energy"), Some(&Json::Null), "never watched");
    }

    #[test]
    fn energy_follows_the_readings() {
        let mut a = lamp(1, 150, 6);
        let mut b = lamp(2, 100, 6);
        for m in 0..=30u64 {
            a.energy.record(m * 60_000_000, 150);
            b.energy.record(m * 60_000_000, 100);
        }
        let row = Row::of(&a, 0);
        assert_eq!(row.number("energy"), Some(75));
        assert_eq!(row.number("energy_watched_s"), Some(1800));
        assert!(to_csv(&[row]).contains(",150,75,"));
        assert!(
            street_energy([a, b].iter()).starts_with("Energy: 125.0 Wh over the 30 min"),
            "{}",
            street_energy([lamp(1, 1, 6)].iter())
        );
    }
}
