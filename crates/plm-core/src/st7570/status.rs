//! The ST7570 status message (ST7570 UM 5.2.1, Tables 11 and 12): `?` and
//! three bytes whose layout is the row of Table 11 that the MODE and LAYER
//! bits of byte 1 select. Offsets here count from byte 1 (the bytes after
//! `?`, as [`crate::link::StatusMessage::data`] gives them).

use super::types::Layer;
use crate::field::{Field, Value};
use crate::link::{Dialect, StatusMessage};

/// MODE (Table 11).
pub const MODES: &[&str] = &["Idle mode, Test modes", "Client", "Server", "Monitor"];
/// DELTA_PHASE (Table 12); 7 is undefined.
pub const DELTA_PHASES: &[&str] = &[
    "Not measured",
    "0°",
    "+60°",
    "+120°",
    "±180°",
    "-120°",
    "-60°",
];

/// Byte 1 b7.
pub const OVERCURRENT: Field = Field::flag("overcurrent", "OVERCURRENT", 0, 7);
/// Byte 1 b6.
pub const THERMAL_STOP: Field = Field::flag("thermal_stop", "THERMAL STOP", 0, 6);
/// Byte 1 b5..b4.
pub const MODE: Field = Field::enumeration("mode", "MODE", 0, 4, 2, MODES);
/// Byte 1 b3, Server MAC only: the local address is NEW (FFEh).
pub const NEW: Field = Field::flag("new", "NEW", 0, 3);
/// Byte 1 b2: inverted, 0 = synchronized.
pub const SYNC: Field = Field::enumeration(
    "sync",
    "SYNC",
    0,
    2,
    1,
    &["modem synchronized", "modem not synchronized"],
);
/// Byte 1 b1.
pub const LAYER: Field = Field::enumeration("layer", "LAYER", 0, 1, 1, &["PHY layer", "MAC layer"]);
/// Byte 1 b0.
pub const BUSY: Field = Field::flag("busy", "BUSY", 0, 0);
/// Byte 2 b7..b5, MAC rows.
pub const TS_COUNTER: Field = Field::bits_uint("ts_counter", "TS_COUNTER", 1, 5, 3);
/// Byte 2 b4 (see docs/protocol-notes.md: the row has 7 cells for 8 bits;
/// RESET is the 1-bit cell, FW_RELEASE the 2-bit one).
pub const RESET: Field = Field::enumeration(
    "reset",
    "RESET",
    1,
    4,
    1,
    &["Hardware Reset", "Software Reset"],
);
/// Byte 2 b3..b2; 1 in this manual.
pub const FW_RELEASE: Field = Field::bits_uint("fw_release", "FW_RELEASE", 1, 2, 2);
/// Byte 2 b1: an alarm since the previous status message (once only).
pub const ALARM: Field = Field::flag("alarm", "ALARM", 1, 1);
/// Byte 2 b0: the ZC PLL is not locked.
pub const ZC_FAIL: Field = Field::flag("zc_fail", "ZC_FAIL", 1, 0);
/// Byte 3, Client MAC: LSByte of MIB 0006h.
pub const INVALID_FRAME: Field = Field::uint("invalid_frame", "INVALID_FRAME", 2, 1);
/// Byte 3 b7..b5, Server and Monitor rows.
pub const DELTA_PHASE: Field =
    Field::enumeration("delta_phase", "DELTA_PHASE", 2, 5, 3, DELTA_PHASES);
/// Byte 3 b4..b1, Server MAC: 0..7 (MIB 0007h).
pub const MIN_CREDIT: Field = Field::bits_uint("min_credit", "MIN_CREDIT", 2, 1, 4).range(0, 7);
/// Byte 3 b0, Server MAC.
pub const REPEATER: Field = Field::flag("repeater", "REPEATER", 2, 0);

/// A row of Table 11.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Row {
    /// MODE 0, either layer.
    NotSet,
    /// MODE 1, LAYER 0.
    ClientPhy,
    /// MODE 1, LAYER 1.
    ClientMac,
    /// MODE 2, LAYER 0.
    ServerPhy,
    /// MODE 2, LAYER 1.
    ServerMac,
    /// MODE 3. Table 11 has a row for PHY only; a MAC Monitor's message is
    /// read with it too (docs/protocol-notes.md).
    Monitor,
}

const NOT_SET: &[Field] = &[
    OVERCURRENT,
    THERMAL_STOP,
    MODE,
    LAYER,
    RESET,
    FW_RELEASE,
    ZC_FAIL,
];
const CLIENT_PHY: &[Field] = &[
    OVERCURRENT,
    THERMAL_STOP,
    MODE,
    SYNC,
    LAYER,
    BUSY,
    RESET,
    FW_RELEASE,
    ALARM,
    ZC_FAIL,
];
const CLIENT_MAC: &[Field] = &[
    OVERCURRENT,
    THERMAL_STOP,
    MODE,
    SYNC,
    LAYER,
    BUSY,
    TS_COUNTER,
    RESET,
    FW_RELEASE,
    ALARM,
    ZC_FAIL,
    INVALID_FRAME,
];
const SERVER_PHY: &[Field] = &[
    OVERCURRENT,
    THERMAL_STOP,
    MODE,
    SYNC,
    LAYER,
    BUSY,
    RESET,
    FW_RELEASE,
    ALARM,
    ZC_FAIL,
    DELTA_PHASE,
];
const SERVER_MAC: &[Field] = &[
    OVERCURRENT,
    THERMAL_STOP,
    MODE,
    NEW,
    SYNC,
    LAYER,
    BUSY,
    TS_COUNTER,
    RESET,
    FW_RELEASE,
    ALARM,
    ZC_FAIL,
    DELTA_PHASE,
    MIN_CREDIT,
    REPEATER,
];

impl Row {
    /// Every row.
    pub const ALL: [Row; 6] = [
        Row::NotSet,
        Row::ClientPhy,
        Row::ClientMac,
        Row::ServerPhy,
        Row::ServerMac,
        Row::Monitor,
    ];

    /// The row byte 1 selects.
    pub fn of(byte1: u8) -> Row {
        let d = [byte1];
        let mac = LAYER.get(&d) == Some(1);
        match (MODE.get(&d), mac) {
            (Some(1), false) => Row::ClientPhy,
            (Some(1), true) => Row::ClientMac,
            (Some(2), false) => Row::ServerPhy,
            (Some(2), true) => Row::ServerMac,
            (Some(3), _) => Row::Monitor,
            _ => Row::NotSet,
        }
    }

    /// The row's fields; the bits of no field are 0 in the manual.
    pub fn layout(self) -> &'static [Field] {
        match self {
            Row::NotSet => NOT_SET,
            Row::ClientPhy => CLIENT_PHY,
            Row::ClientMac => CLIENT_MAC,
            Row::ServerPhy | Row::Monitor => SERVER_PHY,
            Row::ServerMac => SERVER_MAC,
        }
    }

    /// The row's title in Table 11.
    pub fn name(self) -> &'static str {
        match self {
            Row::NotSet => "Not set",
            Row::ClientPhy => "Client (PHY mode)",
            Row::ClientMac => "Client (MAC mode)",
            Row::ServerPhy => "Server (PHY mode)",
            Row::ServerMac => "Server (MAC mode)",
            Row::Monitor => "Monitor (only PHY mode)",
        }
    }

    /// Bits the row gives a field, per byte.
    pub fn mask(self) -> [u8; 3] {
        let mut m = [0u8; 3];
        for f in self.layout() {
            f.set(&mut m, -1);
        }
        m
    }

    fn has(self, field: &Field) -> bool {
        self.layout().iter().any(|f| f.name == field.name)
    }
}

/// A decoded status message. A field that the message's row of Table 11
/// does not have reads 0 and is not sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Status {
    /// A transmitted frame was current limited.
    pub overcurrent: bool,
    /// A thermal shutdown occurred.
    pub thermal_stop: bool,
    /// MODE: 0 idle or test, 1 Client, 2 Server, 3 Monitor.
    pub mode: u8,
    /// LAYER.
    pub mac: bool,
    /// NEW (Server MAC).
    pub new: bool,
    /// The SYNC bit as sent: `true` = NOT synchronized.
    pub sync: bool,
    /// BUSY.
    pub busy: bool,
    /// TS_COUNTER (MAC rows).
    pub ts_counter: u8,
    /// RESET: `true` = the last reset was a software reset.
    pub reset: bool,
    /// FW_RELEASE.
    pub fw_release: u8,
    /// ALARM.
    pub alarm: bool,
    /// ZC_FAIL.
    pub zc_fail: bool,
    /// INVALID_FRAME (Client MAC).
    pub invalid_frame: u8,
    /// DELTA_PHASE (Server and Monitor rows).
    pub delta_phase: u8,
    /// MIN_CREDIT (Server MAC).
    pub min_credit: u8,
    /// REPEATER (Server MAC).
    pub repeater: bool,
    /// Bits set where the row has a fixed 0, kept so that nothing is lost.
    pub stray: [u8; 3],
}

impl Status {
    /// Reads the three bytes after `?`; `None` for another length.
    pub fn parse(data: &[u8]) -> Option<Status> {
        let d: [u8; 3] = data.try_into().ok()?;
        let row = Row::of(d[0]);
        let get = |f: &Field| {
            if row.has(f) {
                f.get(&d).unwrap_or(0)
            } else {
                0
            }
        };
        let mask = row.mask();
        Some(Status {
            overcurrent: get(&OVERCURRENT) != 0,
            thermal_stop: get(&THERMAL_STOP) != 0,
            mode: get(&MODE) as u8,
            mac: get(&LAYER) != 0,
            new: get(&NEW) != 0,
            sync: get(&SYNC) != 0,
            busy: get(&BUSY) != 0,
            ts_counter: get(&TS_COUNTER) as u8,
            reset: get(&RESET) != 0,
            fw_release: get(&FW_RELEASE) as u8,
            alarm: get(&ALARM) != 0,
            zc_fail: get(&ZC_FAIL) != 0,
            invalid_frame: get(&INVALID_FRAME) as u8,
            delta_phase: get(&DELTA_PHASE) as u8,
            min_credit: get(&MIN_CREDIT) as u8,
            repeater: get(&REPEATER) != 0,
            stray: [d[0] & !mask[0], d[1] & !mask[1], d[2] & !mask[2]],
        })
    }

    /// Reads a status message of the ST7570 dialect.
    pub fn from_message(m: &StatusMessage) -> Option<Status> {
        Status::parse(m.data())
    }

    /// The row of Table 11 the message follows.
    pub fn row(&self) -> Row {
        Row::of(self.emit()[0])
    }

    /// The three bytes after `?`.
    pub fn emit(&self) -> [u8; 3] {
        let mut d = [0u8; 3];
        MODE.set(&mut d, self.mode as i64);
        LAYER.set(&mut d, self.mac as i64);
        let row = Row::of(d[0]);
        let values: [(&Field, i64); 16] = [
            (&OVERCURRENT, self.overcurrent as i64),
            (&THERMAL_STOP, self.thermal_stop as i64),
            (&MODE, self.mode as i64),
            (&LAYER, self.mac as i64),
            (&NEW, self.new as i64),
            (&SYNC, self.sync as i64),
            (&BUSY, self.busy as i64),
            (&TS_COUNTER, self.ts_counter as i64),
            (&RESET, self.reset as i64),
            (&FW_RELEASE, self.fw_release as i64),
            (&ALARM, self.alarm as i64),
            (&ZC_FAIL, self.zc_fail as i64),
            (&INVALID_FRAME, self.invalid_frame as i64),
            (&DELTA_PHASE, self.delta_phase as i64),
            (&MIN_CREDIT, self.min_credit as i64),
            (&REPEATER, self.repeater as i64),
        ];
        for (f, v) in values {
            if row.has(f) {
                f.set(&mut d, v);
            }
        }
        let mask = row.mask();
        for i in 0..3 {
            d[i] |= self.stray[i] & !mask[i];
        }
        d
    }

    /// The whole message as sent, `?` first.
    pub fn to_message(&self) -> StatusMessage {
        StatusMessage::new(Dialect::St7570, &self.emit())
    }

    /// The access layer LAYER names.
    pub fn layer(&self) -> Layer {
        if self.mac {
            Layer::Mac
        } else {
            Layer::Phy
        }
    }

    /// Whether the modem is synchronized (SYNC is inverted; the "Not set"
    /// row has no SYNC and is never synchronized).
    pub fn synchronized(&self) -> bool {
        self.row() != Row::NotSet && !self.sync
    }
}

/// The named values of a status message's three bytes, by its row. Bits
/// set where the row has a fixed 0 are not among them: they are
/// [`Status::stray`] (the decoder shows them as `stray_byte_1..3`).
pub fn describe(data: &[u8]) -> alloc::vec::Vec<(&'static Field, Value)> {
    let Some(first) = data.first() else {
        return alloc::vec::Vec::new();
    };
    crate::mib::describe(Row::of(*first).layout(), data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn section_10_4_1_server_mac() {
        // 10.4.1: 3F 22 E4 80 = MAC Server, not NEW, synchronized, not
        // busy; TS_COUNTER 7, no alarm, no ZC_FAIL, hardware reset, FW 1;
        // phase 4 (180°), delta credit 0, no repeater.
        let s = Status::parse(&[0x22, 0xE4, 0x80]).unwrap();
        assert_eq!(s.row(), Row::ServerMac);
        assert!(s.synchronized() && !s.new && !s.busy && !s.reset);
        assert_eq!((s.ts_counter, s.fw_release, s.delta_phase), (7, 1, 4));
        assert_eq!((s.min_credit, s.repeater, s.stray), (0, false, [0; 3]));
        assert_eq!(s.emit(), [0x22, 0xE4, 0x80]);
    }

    #[test]
    fn zero_cells_are_kept_as_stray_bits() {
        // Not set: SYNC and BUSY cells are 0; a set bit is kept, not read.
        let s = Status::parse(&[0x05, 0xE6, 0xFF]).unwrap();
        assert_eq!(s.row(), Row::NotSet);
        assert!(!s.sync && !s.busy && !s.alarm && !s.synchronized());
        assert_eq!(s.stray, [0x05, 0xE2, 0xFF]);
        assert_eq!(s.emit(), [0x05, 0xE6, 0xFF]);
    }
}
