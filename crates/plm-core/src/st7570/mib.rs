//! The ST7570 MIB (ST7570 UM 6, Table 71 and Tables 72-148): the 35
//! objects in the one declarative description of [`crate::mib`], and typed
//! values of the objects other modules act on (00A1h, 000Bh). Values are
//! LSByte first (6.1: "both index and data field must be sent LSByte
//! first"). Where Table 71 and an object's own table disagree, the
//! object's table wins (docs/protocol-notes.md).

use super::fields::{in_dbuv, REPEATER_STATES};
use super::Layer;
use crate::field::{Field, Order};
use crate::link::TicSelector;
use crate::mib::{self as m, Object, Scope};
use alloc::vec::Vec;

mod table;

/// Operating mode bits of [`Scope::write_modes`] (00A1h byte 0 b0..b2).
pub mod modes {
    /// IDLE.
    pub const IDLE: u8 = 1 << 0;
    /// Client.
    pub const CLIENT: u8 = 1 << 1;
    /// Server.
    pub const SERVER: u8 = 1 << 2;
    /// Monitor.
    pub const MONITOR: u8 = 1 << 3;
    /// Every mode.
    pub const ALL: u8 = 0xFF;
}

pub(super) const BOTH: Scope = Scope::ANY;
pub(super) const MAC: Scope = Scope {
    phy: false,
    mac: true,
    write_modes: modes::ALL,
};
// 6.5.3-6.5.5, 6.5.10: "ERR_REQUEST_NOT_ALLOWED: the modem is configured
// as Monitor".
pub(super) const MAC_NOT_MONITOR: Scope = Scope {
    phy: false,
    mac: true,
    write_modes: !modes::MONITOR,
};
// 6.5.22: "ERR_REQUEST_NOT_ALLOWED: the modem is not configured as Monitor".
pub(super) const MAC_MONITOR: Scope = Scope {
    phy: false,
    mac: true,
    write_modes: modes::MONITOR,
};

const fn le(f: Field) -> Field {
    f.order(Order::LsbFirst)
}
const fn u16le(name: &'static str, label: &'static str, offset: usize) -> Field {
    le(Field::uint(name, label, offset, 2))
}
const fn address(name: &'static str, label: &'static str, offset: usize) -> Field {
    u16le(name, label, offset).range(0, 0x0FFF)
}
/// b0..b19 of a 3-byte value (00ACh, 00C2h, 00D1h); b20..b23 unused.
const fn twenty_bits(name: &'static str, label: &'static str, unit: &'static str) -> Field {
    le(Field::uint(name, label, 0, 3)).within(0, 20).unit(unit)
}
pub(super) const UNUSED_B20: Field = le(Field::uint("unused", "b20..23: unused", 0, 3))
    .within(20, 4)
    .range(0, 0);

/// 4 PAD bytes of any value: a write resets a counter (6.5.7).
pub(super) const PAD4: &[Field] = &[Field::bytes("pad", "PAD", 0, 4)];
const fn counter(name: &'static str, label: &'static str) -> [Field; 1] {
    [le(Field::uint(name, label, 0, 4))]
}

/// The indexes of Table 71.
pub mod index {
    /// 0000h FIMA / LIMA.
    pub const FIMA_LIMA: u16 = 0x0000;
    /// 0001h LocalMacAdd / InitMacAdd.
    pub const LOCAL_INIT_MAC_ADD: u16 = 0x0001;
    /// 000Bh TIC selector / repeater settings.
    pub const TIC_REPEATER: u16 = 0x000B;
    /// 00A0h New synchronization.
    pub const NEW_SYNCHRONIZATION: u16 = 0x00A0;
    /// 00A1h PLC configuration.
    pub const PLC_CONFIGURATION: u16 = 0x00A1;
}

/// Operating modes of 00A1h byte 0 b0..b2 (Table 137); 7 is undefined.
pub const OPERATING_MODES: &[&str] = &[
    "IDLE",
    "Client",
    "Server",
    "Monitor",
    "Test on Ch.0",
    "Test on Ch.1",
    "Test on Ch.0 and Ch.1",
];

/// 0000h (Table 72).
pub(super) const FIMA_LIMA: &[Field] = &[address("fima", "FIMA", 0), address("lima", "LIMA", 2)];
/// 0001h (Table 74).
pub const LOCAL_INIT: &[Field] = &[
    address("local_mac_add", "LocalMACAdd", 0),
    address("init_mac_add", "InitMACAdd", 2),
];
pub(super) const SYNCHRO_CONFIRMATION: &[Field] = &[u16le(
    "timeout_synchro_confirmation",
    "Timeout synchro confirmation",
    0,
)
.unit("s")];
pub(super) const FRAME_NOT_OK: &[Field] =
    &[u16le("timeout_frame_not_ok", "Timeout frame not ok", 0).unit("s")];
pub(super) const NOT_ADDRESSED: &[Field] =
    &[u16le("timeout_not_addressed", "Timeout not addressed", 0).unit("min")];
pub(super) const GROUPS: &[Field] = &[
    address("mac_group_address_0", "MAC group address 0", 0),
    address("mac_group_address_1", "MAC group address 1", 2),
    address("mac_group_address_2", "MAC group address 2", 4),
    address("mac_group_address_3", "MAC group address 3", 6),
    address("mac_group_address_4", "MAC group address 4", 8),
];
pub(super) const INVALID_FRAMES: [Field; 1] =
    counter("invalid_frame_counter", "Invalid frame counter");
pub(super) const MIN_DELTA_CREDIT: &[Field] =
    &[Field::uint("minimum_delta_credit", "Minimum delta credit", 0, 1).range(0, 7)];
pub(super) const MIN_DELTA_CREDIT_WRITE: &[Field] = &[Field::bytes("pad", "PAD", 0, 1)];
/// 0008h (Table 90): b2..b3 are accepted (range 00h..0Fh) with no meaning.
pub(super) const CHECKS: &[Field] = &[
    Field::flag("disable_frame_type_check", "Disable frame type check", 0, 0),
    Field::flag("disable_crc_check", "Disable CRC check", 0, 1),
    Field::bits_uint("unused", "b2..b3", 0, 2, 2),
    Field::reserved("reserved", "b4..b7", 0, 4, 4),
];
pub(super) const IS_TIMEOUT: &[Field] = &[u16le(
    "timeout_intelligent_synchronization",
    "Timeout intelligent synchronization",
    0,
)
.unit("min")];
pub(super) const VALID_FRAMES: [Field; 1] = counter("valid_frame_counter", "Valid frame counter");
/// 000Bh (Table 97).
pub const TIC_REPEATER: &[Field] = &[
    Field::enumeration(
        "repeater_settings",
        "Repeater settings",
        0,
        0,
        2,
        REPEATER_STATES,
    ),
    Field::bits_uint("unused", "b2..b6: unused", 0, 2, 5),
    Field::enumeration(
        "tic_selector",
        "TIC selector",
        0,
        7,
        1,
        &["5 characters", "10 ms"],
    ),
];
pub(super) const RC_THRESHOLD: &[Field] = &[
    in_dbuv(u16le("rc_threshold", "RC threshold", 0)),
    u16le("pad", "PAD", 2).range(0, 0),
];
const fn estimation(name: &'static str, label: &'static str, offset: usize) -> Field {
    in_dbuv(le(Field::uint(name, label, offset, 4)).range(0, 0x0FF_FFFF))
}
pub(super) const S0_N0_PGA: &[Field] = &[
    estimation("s0", "S0", 0),
    estimation("n0", "N0", 4),
    u16le("pga", "PGA", 8).range(0, 8),
];
pub(super) const S1_N1_PHASE: &[Field] = &[
    estimation("s1", "S1", 0),
    estimation("n1", "N1", 4),
    u16le("phase", "Phase", 8).range(0, 0xFF),
];
pub(super) const TRANSMITTED: [Field; 1] =
    counter("transmitted_frame_counter", "Transmitted frame counter");
pub(super) const REPEATED: [Field; 1] = counter("repeated_frame_counter", "Repeated frame counter");
pub(super) const BAD_FI: [Field; 1] =
    counter("bad_frame_indicator_counter", "Bad frame indicator counter");
pub(super) const FRAME_INDICATOR: &[Field] = &[u16le("frame_indicator", "Frame indicator", 0)];
pub(super) const SMART_PHASE: &[Field] = &[Field::enumeration(
    "smart_phase_detect",
    "Smart-phase detect",
    0,
    0,
    8,
    &["SMART_DISABLED", "SMART_TX", "SMART_RX", "SMART_TXXR"],
)];
pub(super) const PHASE: &[Field] = &[Field::uint("phase", "Phase", 0, 1).range(0, 0x0F)];
pub(super) const AUTO_SYNCHRO_REJECT: &[Field] = &[Field::enumeration(
    "auto_synchro_reject",
    "Auto synchro reject",
    0,
    0,
    8,
    &["disabled", "enabled"],
)];
pub(super) const IS_THRESHOLD: &[Field] = &[in_dbuv(
    le(Field::uint("is_threshold", "IS threshold", 0, 4)).range(0, 0x0FFF_FFFF),
)];
pub(super) const ON_OFF: &[&str] = &["disabled", "enabled"];
pub(super) const CURRENT_LIMITING: Field =
    Field::enumeration("current_limiting", "Current limiting", 0, 0, 8, ON_OFF);
pub(super) const TARGET_OUTPUT_GAIN: Field =
    Field::uint("target_output_gain", "Target output gain", 1, 1).range(0, 31);
pub(super) const TX_GAIN: &[Field] = &[
    CURRENT_LIMITING,
    TARGET_OUTPUT_GAIN,
    Field::uint("actual_output_gain", "Actual output gain", 2, 1).range(0, 31),
];
pub(super) const TX_GAIN_WRITE: &[Field] = &[CURRENT_LIMITING, TARGET_OUTPUT_GAIN];
pub(super) const ALARMS_RECEIVED: [Field; 1] =
    counter("received_alarm_counter", "Received alarm counter");
pub(super) const ALARMS_SENT: [Field; 1] =
    counter("transmitted_alarm_counter", "Transmitted alarm counter");
pub(super) const ALARM_PARAMETERS: &[Field] = &[
    Field::uint("alarm_repetition", "Alarm repetition (N_TX)", 0, 1),
    Field::uint(
        "alarm_before_indication",
        "Alarm before indication (N_RX)",
        1,
        1,
    ),
    Field::uint("alarm_reject_window", "Alarm reject window (N_REJ)", 2, 1),
];
pub(super) const ENABLED_DISABLED: &[&str] = &["enabled", "disabled"];
pub(super) const ALARM_FLAGS: &[Field] = &[
    Field::enumeration(
        "alarm_indication",
        "Alarm indication",
        0,
        0,
        1,
        ENABLED_DISABLED,
    ),
    Field::enumeration(
        "alarm_repetition",
        "Alarm repetition",
        0,
        1,
        1,
        ENABLED_DISABLED,
    ),
    Field::enumeration(
        "alarm_s_n_indication",
        "Alarm S N indication",
        0,
        2,
        1,
        ENABLED_DISABLED,
    ),
    Field::reserved("reserved", "b3..b7", 0, 3, 5),
];
pub(super) const NEW_SYNC: &[Field] = &[Field::enumeration(
    "new_synchronization",
    "New synchronization",
    0,
    0,
    8,
    &["no effect", "discard current sync and look for a new sync"],
)];
/// 00A1h (Table 137).
pub mod plc {
    use super::*;
    /// Byte 0 b0..b2.
    pub const OPERATING_MODE: Field =
        Field::enumeration("operating_mode", "Operating mode", 0, 0, 3, OPERATING_MODES);
    /// Byte 0 b3..b4: 24 or 48 bits per mains period.
    pub const BIT_RATE: Field = Field::enumeration(
        "bit_rate",
        "Bit rate",
        0,
        3,
        2,
        &["1200 bit/s", "2400 bit/s"],
    );
    /// Byte 1 b3.
    pub const MAINS_FREQUENCY: Field = Field::enumeration(
        "zero_crossing_synchronization",
        "Zero-crossing synchronization (PLL)",
        1,
        3,
        1,
        &["50 Hz", "60 Hz"],
    );
    /// Byte 2: attenuation from -31 dB (0) to 0 dB (31).
    pub const TARGET_OUTPUT_GAIN: Field =
        Field::uint("target_output_gain", "Target output gain", 2, 1).range(0, 0x1F);
    /// Bytes 3-5: "any value in CENELEC band A, B, C" (3 kHz to 140 kHz).
    pub const F0: Field = le(Field::uint("f0", "f0", 3, 3))
        .range(3_000, 140_000)
        .unit("Hz");
    /// Bytes 6-8.
    pub const F1: Field = le(Field::uint("f1", "f1", 6, 3))
        .range(3_000, 140_000)
        .unit("Hz");
    /// Byte 12: 1 PHY, 2 MAC.
    pub const ACCESS_LAYER_MODE: Field = Field::enumeration(
        "access_layer_mode",
        "Access layer mode",
        12,
        0,
        8,
        &["", "PHY", "MAC"],
    );
    /// Byte 13.
    pub const TX_CURRENT_LIMITING: Field = Field::enumeration(
        "tx_current_limiting",
        "TX current limiting",
        13,
        0,
        8,
        ON_OFF,
    );
    /// Table 137.
    pub const LAYOUT: &[Field] = &[
        OPERATING_MODE,
        BIT_RATE,
        Field::reserved("unused_0", "b5..7: unused", 0, 5, 3),
        Field::reserved("reserved_1", "b0..b2: reserved", 1, 0, 3),
        MAINS_FREQUENCY,
        Field::reserved("reserved_1_b4", "b4: reserved", 1, 4, 1),
        Field::reserved("unused_1", "b5..7: unused", 1, 5, 3),
        TARGET_OUTPUT_GAIN,
        F0,
        F1,
        Field::uint("pad", "PAD", 9, 3).range(0, 0),
        ACCESS_LAYER_MODE,
        TX_CURRENT_LIMITING,
    ];
}
/// 00A4h (Table 139).
pub(super) const DIGITAL_OUTPUT: &[Field] = &[
    Field::enumeration(
        "preslot_zc_ts_bit",
        "PRESLOT/ZC/TS/BIT",
        0,
        0,
        3,
        &["PRESLOT", "ZC", "TS", "BIT", "TXP", "RXP", "TXRXP"],
    ),
    Field::enumeration(
        "zc_in_d",
        "ZC_IN_D",
        0,
        3,
        1,
        &["ZC_IN_D_OFF", "ZC_IN_D_ON"],
    ),
    Field::reserved("reserved", "b4..b7: reserved", 0, 4, 4),
];
pub(super) const MAX_PGA_GAIN: &[Field] = &[
    u16le("gain", "GAIN", 0).range(0, 8),
    u16le("pad", "PAD", 2).range(0, 0),
];
pub(super) const SOFT_START: &[Field] = &[
    twenty_bits("soft_start", "Soft Start", "× 13 µs"),
    UNUSED_B20,
];
pub(super) const TIME_SLOT_DELAY: &[Field] = &[
    twenty_bits("time_slot_delay_bit", "Time-slot delay bit", "bit"),
    UNUSED_B20,
];
pub(super) const ZC_DELAY: &[Field] = &[
    twenty_bits("zc_delay_compensation", "ZC delay compensation", "× 13 µs"),
    UNUSED_B20,
];

pub use table::OBJECTS;

/// The object with this index.
pub fn object(index: u16) -> Option<&'static Object> {
    m::find(OBJECTS, index)
}

/// Whether the object exists with `layer` (ERR_UNAVAILABLE_RESOURCE
/// otherwise).
pub fn in_layer(o: &Object, layer: Layer) -> bool {
    match layer {
        Layer::Phy => o.scope.phy,
        Layer::Mac => o.scope.mac,
    }
}

/// MIB 00A1h as values (Table 137).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PlcConfiguration {
    /// Operating mode, 0..6 ([`OPERATING_MODES`]).
    pub operating_mode: u8,
    /// 2400 bit/s (48 bits per mains period) rather than 1200.
    pub bit_rate_2400: bool,
    /// 60 Hz mains rather than 50 Hz.
    pub mains_60_hz: bool,
    /// Target output gain, 0..31.
    pub target_output_gain: u8,
    /// f0 in Hz.
    pub f0: u32,
    /// f1 in Hz.
    pub f1: u32,
    /// Access layer mode: 1 PHY, 2 MAC.
    pub access_layer_mode: u8,
    /// TX current limiting.
    pub tx_current_limiting: bool,
}

impl PlcConfiguration {
    /// Reads the 14 bytes (shorter data reads as 0).
    pub fn decode(d: &[u8]) -> Self {
        use plc::*;
        let g = |f: &Field| f.get(d).unwrap_or(0);
        PlcConfiguration {
            operating_mode: g(&OPERATING_MODE) as u8,
            bit_rate_2400: g(&BIT_RATE) == 1,
            mains_60_hz: g(&MAINS_FREQUENCY) == 1,
            target_output_gain: g(&TARGET_OUTPUT_GAIN) as u8,
            f0: g(&F0) as u32,
            f1: g(&F1) as u32,
            access_layer_mode: g(&ACCESS_LAYER_MODE) as u8,
            tx_current_limiting: g(&TX_CURRENT_LIMITING) == 1,
        }
    }

    /// The 14 bytes.
    pub fn encode(&self) -> Vec<u8> {
        use plc::*;
        let mut d = alloc::vec![0u8; 14];
        for (f, v) in [
            (&OPERATING_MODE, self.operating_mode as i64),
            (&BIT_RATE, self.bit_rate_2400 as i64),
            (&MAINS_FREQUENCY, self.mains_60_hz as i64),
            (&TARGET_OUTPUT_GAIN, self.target_output_gain as i64),
            (&F0, self.f0 as i64),
            (&F1, self.f1 as i64),
            (&ACCESS_LAYER_MODE, self.access_layer_mode as i64),
            (&TX_CURRENT_LIMITING, self.tx_current_limiting as i64),
        ] {
            f.set(&mut d, v);
        }
        d
    }

    /// The access layer, `None` for a value Table 137 does not define.
    pub fn layer(&self) -> Option<Layer> {
        Layer::from_access_layer_mode(self.access_layer_mode)
    }
}

/// MIB 000Bh as values (Table 97).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct TicRepeater {
    /// b1..b0: 0 NEVER_REPEAT, 1 ALWAYS_REPEAT, 2 NO_REPEAT, 3 REPEAT.
    pub repeater_settings: u8,
    /// b6..b2, unused (kept as written).
    pub unused: u8,
    /// b7: T_IC is 10 ms rather than 5 characters.
    pub tic_10_ms: bool,
}

impl TicRepeater {
    /// Reads the byte.
    pub fn from_byte(b: u8) -> Self {
        TicRepeater {
            repeater_settings: b & 0x03,
            unused: (b >> 2) & 0x1F,
            tic_10_ms: b & 0x80 != 0,
        }
    }

    /// The byte.
    pub fn byte(&self) -> u8 {
        (self.repeater_settings & 0x03) | (self.unused & 0x1F) << 2 | (self.tic_10_ms as u8) << 7
    }

    /// The T_IC selector of b7, as the link engines read it (one reading:
    /// [`TicSelector::from_mib_000b`]).
    pub fn tic_selector(&self) -> TicSelector {
        TicSelector::from_mib_000b(self.byte())
    }

    /// Whether the node is a repeater (ALWAYS_REPEAT or REPEAT).
    pub fn is_repeater(&self) -> bool {
        self.repeater_settings & 1 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thirty_five_objects_whose_defaults_fit_their_layouts() {
        assert_eq!(OBJECTS.len(), 35);
        for o in OBJECTS {
            assert_eq!(o.default.len(), o.len, "{}", o.name);
            o.check_value(o.default)
                .unwrap_or_else(|e| panic!("{}: {e}", o.name));
            let end = o.fields.iter().map(Field::end).max().unwrap();
            assert_eq!(end, o.len, "{} layout ends at {end}", o.name);
        }
    }

    #[test]
    fn plc_configuration_default_is_phy_idle_74_and_63_3_khz() {
        let o = object(index::PLC_CONFIGURATION).unwrap();
        let p = PlcConfiguration::decode(o.default);
        assert_eq!((p.f0, p.f1, p.target_output_gain), (74_000, 63_300, 0x10));
        assert_eq!((p.operating_mode, p.layer()), (0, Some(Layer::Phy)));
        assert_eq!(p.encode(), o.default);
    }

    #[test]
    fn tic_selector_and_repeater_of_000bh() {
        let d = object(index::TIC_REPEATER).unwrap().default[0];
        assert_eq!(
            TicRepeater::from_byte(d).tic_selector(),
            TicSelector::FACTORY_DEFAULT
        );
        let t = TicRepeater::from_byte(0x83);
        assert_eq!(
            (t.tic_selector(), t.is_repeater()),
            (TicSelector::TenMs, true)
        );
        assert_eq!(t.byte(), 0x83);
        assert!(!TicRepeater::from_byte(0x02).is_repeater(), "NO_REPEAT");
    }
}
