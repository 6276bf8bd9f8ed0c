//! HID ballast commands (STEVAL-IHP007V1 UM, Appendix A). They travel in
//! APP_DATA_FRAMEs; the payload starts with a command set character:
//!
//! - `'s'` (73h) sets: `['s', 00h, reset_type]` resets the ballast
//!   (software AAh, hardware 0Ch), `['s', 01h, dimming 0-100]` dims;
//!   the board answers with an APP_ACK_FRAME echoing `'s'`;
//! - `'g'` (67h) gets: `['g', param]`, answered by a data frame
//!   `['g', param, value...]` from the lamp's board.
//!
//! Every parameter is described once in [`PARAMS`]: codec, decoder,
//! forms and the simulated ballast read it. Values are 16-bit, high byte
//! first (`_h` then `_l` in the seed).

use crate::field::{Field, Order};
use alloc::vec::Vec;
use core::fmt;

/// Command set character of set commands.
pub const SET: u8 = b's';
/// Command set character of get commands.
pub const GET: u8 = b'g';
/// `'s'` command 00h: reset.
pub const SET_RESET: u8 = 0x00;
/// `'s'` command 01h: dimming.
pub const SET_DIMMING: u8 = 0x01;
/// reset_type: software reset.
pub const RESET_SOFTWARE: u8 = 0xAA;
/// reset_type: hardware reset (the board pulls the ballast's reset pin,
/// GPIO port A pin 6).
pub const RESET_HARDWARE: u8 = 0x0C;
/// Highest dimming value (100 %).
pub const DIMMING_MAX: u8 = 100;
/// `param_to_get` of GET ALL PARAMETERS.
pub const ALL: u8 = 0x0A;

/// hardware_status names, index = value (Appendix A: 00h IDLE, 01h-03h
/// STARTUP, 04h-05h WARMUP, 06h RUN, 07h WAIT, 08h FAILURE).
pub const STATUS_NAMES: &[&str] = &[
    "IDLE", "STARTUP", "STARTUP", "STARTUP", "WARMUP", "WARMUP", "RUN", "WAIT", "FAILURE",
];

/// One parameter of `'g'`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamDesc {
    /// param_to_get.
    pub code: u8,
    /// The seed's name (`LAMP POWER`).
    pub name: &'static str,
    /// Layout of the value after `['g', param]`.
    pub fields: &'static [Field],
    /// Length of the value.
    pub len: usize,
}

/// The value fields, offsets from the first value byte.
pub mod fields {
    use super::*;
    const fn word(name: &'static str, label: &'static str, at: usize) -> Field {
        Field::uint(name, label, at, 2)
    }
    const fn volts(name: &'static str, label: &'static str, at: usize) -> Field {
        word(name, label, at).unit("V")
    }
    const fn status(name: &'static str, label: &'static str, at: usize) -> Field {
        // The state is the low byte; the high byte is 0 in every value the
        // seed lists (decoded as part of the word by `LampState`).
        Field::enumeration(name, label, at + 1, 0, 8, STATUS_NAMES)
    }
    /// Hardware release xx (BCD).
    pub const HW_XX: Field = Field::uint("hardware_release_xx", "Hardware release xx (BCD)", 0, 1);
    /// Hardware release yy (BCD).
    pub const HW_YY: Field = Field::uint("hardware_release_yy", "Hardware release yy (BCD)", 1, 1);
    /// 01h.
    pub const BUS_VOLTAGE: Field = volts("bus_voltage", "Bus voltage", 0);
    /// 02h.
    pub const LAMP_VOLTAGE: Field = volts("lamp_voltage", "Lamp voltage", 0);
    /// 03h.
    pub const HARDWARE_STATUS: Field = status("hardware_status", "Hardware status", 0);
    /// 04h.
    pub const LAMP_POWER: Field = word("lamp_power", "Lamp power", 0).unit("W");
    /// 06h.
    pub const SUPPLY_VOLTAGE: Field = volts("power_supply_voltage", "Power supply voltage", 0);
    /// 07h.
    pub const TEMPERATURE: Field = Field::int("board_temperature", "Board temperature", 0, 2)
        .unit("°C")
        .order(Order::MsbFirst);
    /// 08h.
    pub const POWER_ONS: Field = word("power_on_count", "N° of power on", 0);
    /// 09h.
    pub const LIFETIME: Field = word("lamp_lifetime", "Lamp lifetime", 0).unit("h");
    /// 05h.
    pub const LAST_FAILURE: &[Field] = &[
        status(
            "last_hardware_status",
            "Hardware status before the failure",
            0,
        ),
        volts("last_bus_voltage", "Bus voltage before the failure", 2),
        volts("last_lamp_voltage", "Lamp voltage before the failure", 4),
    ];
    /// 0Ah, in the order of the reply.
    pub const ALL: &[Field] = &[
        HW_XX,
        HW_YY,
        volts("bus_voltage", "Bus voltage", 2),
        volts("lamp_voltage", "Lamp voltage", 4),
        status("hardware_status", "Hardware status", 6),
        word("lamp_power", "Lamp power", 8).unit("W"),
        status(
            "last_hardware_status",
            "Hardware status before the failure",
            10,
        ),
        volts("last_bus_voltage", "Bus voltage before the failure", 12),
        volts("last_lamp_voltage", "Lamp voltage before the failure", 14),
        volts("power_supply_voltage", "Power supply voltage", 16),
        Field::int("board_temperature", "Board temperature", 18, 2).unit("°C"),
        word("power_on_count", "N° of power on", 20),
        word("lamp_lifetime", "Lamp lifetime", 22).unit("h"),
    ];
}

/// Every parameter of `'g'` (Appendix A, "param_to_get value").
pub const PARAMS: &[ParamDesc] = &[
    ParamDesc {
        code: 0x00,
        name: "HARDWARE VERSION",
        fields: &[fields::HW_XX, fields::HW_YY],
        len: 2,
    },
    ParamDesc {
        code: 0x01,
        name: "BUS VOLTAGE",
        fields: &[fields::BUS_VOLTAGE],
        len: 2,
    },
    ParamDesc {
        code: 0x02,
        name: "LAMP VOLTAGE",
        fields: &[fields::LAMP_VOLTAGE],
        len: 2,
    },
    ParamDesc {
        code: 0x03,
        name: "HARDWARE STATUS",
        fields: &[fields::HARDWARE_STATUS],
        len: 2,
    },
    ParamDesc {
        code: 0x04,
        name: "LAMP POWER",
        fields: &[fields::LAMP_POWER],
        len: 2,
    },
    ParamDesc {
        code: 0x05,
        name: "LAST FAILURE",
        fields: fields::LAST_FAILURE,
        len: 6,
    },
    ParamDesc {
        code: 0x06,
        name: "POWER SUPPLY VOLTAGE",
        fields: &[fields::SUPPLY_VOLTAGE],
        len: 2,
    },
    ParamDesc {
        code: 0x07,
        name: "BOARD TEMPERATURE",
        fields: &[fields::TEMPERATURE],
        len: 2,
    },
    ParamDesc {
        code: 0x08,
        name: "N° OF POWER ON",
        fields: &[fields::POWER_ONS],
        len: 2,
    },
    ParamDesc {
        code: 0x09,
        name: "LAMP LIFETIME",
        fields: &[fields::LIFETIME],
        len: 2,
    },
    ParamDesc {
        code: ALL,
        name: "GET ALL PARAMETERS",
        fields: fields::ALL,
        len: 24,
    },
];

/// The description of a parameter code.
pub fn param(code: u8) -> Option<&'static ParamDesc> {
    PARAMS.get(code as usize)
}

/// The lamp's state (hardware_status).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LampState {
    /// 00h: off.
    Idle,
    /// 01h-03h: igniting (the step is kept).
    Startup(u8),
    /// 04h-05h: warming up.
    Warmup(u8),
    /// 06h: lit.
    Run,
    /// 07h: waiting to restrike (a hot lamp cools before it can start).
    Wait,
    /// 08h: failed.
    Failure,
    /// A value the seed does not list.
    Unknown(u16),
}

impl LampState {
    /// From the 16-bit hardware_status.
    pub fn from_word(v: u16) -> LampState {
        match v {
            0 => LampState::Idle,
            1..=3 => LampState::Startup(v as u8),
            4..=5 => LampState::Warmup(v as u8),
            6 => LampState::Run,
            7 => LampState::Wait,
            8 => LampState::Failure,
            v => LampState::Unknown(v),
        }
    }

    /// The 16-bit hardware_status.
    pub fn word(self) -> u16 {
        match self {
            LampState::Idle => 0,
            LampState::Startup(s) | LampState::Warmup(s) => s as u16,
            LampState::Run => 6,
            LampState::Wait => 7,
            LampState::Failure => 8,
            LampState::Unknown(v) => v,
        }
    }

    /// The seed's name (`RUN`).
    pub fn name(self) -> &'static str {
        STATUS_NAMES
            .get(self.word() as usize)
            .copied()
            .unwrap_or("UNKNOWN")
    }
}

impl fmt::Display for LampState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LampState::Unknown(v) => write!(f, "UNKNOWN ({v:04X}h)"),
            s => f.write_str(s.name()),
        }
    }
}

/// What a lamp was doing when it last failed (05h).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LastFailure {
    /// hardware_status before the failure.
    pub status: u16,
    /// Bus voltage before the failure, V.
    pub bus_voltage: u16,
    /// Lamp voltage before the failure, V.
    pub lamp_voltage: u16,
}

/// Every parameter at once (0Ah), as the dashboard shows a lamp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Ballast {
    /// Hardware release xx.yy, BCD.
    pub hardware: (u8, u8),
    /// Bus voltage, V.
    pub bus_voltage: u16,
    /// Lamp voltage, V.
    pub lamp_voltage: u16,
    /// hardware_status.
    pub status: u16,
    /// Lamp power, W.
    pub lamp_power: u16,
    /// The last failure.
    pub last_failure: LastFailure,
    /// Power supply voltage, V.
    pub supply_voltage: u16,
    /// Board temperature, °C.
    pub temperature: i16,
    /// Lamp power-on count.
    pub power_ons: u16,
    /// Lamp lifetime, hours.
    pub lifetime_hours: u16,
}

impl Ballast {
    /// The lamp's state.
    pub fn state(&self) -> LampState {
        LampState::from_word(self.status)
    }

    /// The hardware release as printed (`01.02`).
    pub fn hardware_release(&self) -> alloc::string::String {
        alloc::format!("{:02x}.{:02x}", self.hardware.0, self.hardware.1)
    }

    /// The 24 value bytes of the 0Ah reply.
    pub fn encode(&self) -> Vec<u8> {
        let mut v = alloc::vec![self.hardware.0, self.hardware.1];
        for w in [
            self.bus_voltage,
            self.lamp_voltage,
            self.status,
            self.lamp_power,
            self.last_failure.status,
            self.last_failure.bus_voltage,
            self.last_failure.lamp_voltage,
            self.supply_voltage,
            self.temperature as u16,
            self.power_ons,
            self.lifetime_hours,
        ] {
            v.extend_from_slice(&w.to_be_bytes());
        }
        v
    }

    /// From the 24 value bytes of the 0Ah reply.
    pub fn decode(d: &[u8]) -> Option<Ballast> {
        let w = |i: usize| Some(u16::from_be_bytes([*d.get(2 + 2 * i)?, *d.get(3 + 2 * i)?]));
        Some(Ballast {
            hardware: (*d.first()?, *d.get(1)?),
            bus_voltage: w(0)?,
            lamp_voltage: w(1)?,
            status: w(2)?,
            lamp_power: w(3)?,
            last_failure: LastFailure {
                status: w(4)?,
                bus_voltage: w(5)?,
                lamp_voltage: w(6)?,
            },
            supply_voltage: w(7)?,
            temperature: w(8)? as i16,
            power_ons: w(9)?,
            lifetime_hours: w(10)?,
        })
    }

    /// The value bytes of parameter `code` (`None` for an unknown one).
    pub fn value(&self, code: u8) -> Option<Vec<u8>> {
        let all = self.encode();
        let word = |i: usize| all[2 + 2 * i..4 + 2 * i].to_vec();
        Some(match code {
            0x00 => all[..2].to_vec(),
            0x01..=0x04 => word(code as usize - 1),
            0x05 => all[10..16].to_vec(),
            0x06..=0x09 => word(code as usize + 1),
            ALL => all,
            _ => return None,
        })
    }
}

/// A HID data payload, typed.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Hid {
    /// `'s' 00h reset_type`.
    Reset(u8),
    /// `'s' 01h dimming`: 0-100 %.
    Dimming(u8),
    /// `'g' param`.
    Get(u8),
    /// `'g' param value...` from the board.
    Reply {
        /// param_to_get answered.
        param: u8,
        /// Its value bytes.
        value: Vec<u8>,
    },
}

/// Why a HID request is refused before it is sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HidError(pub alloc::string::String);

impl fmt::Display for HidError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl Hid {
    /// Reads a data frame payload as a HID command or reply; `None` when
    /// it is not one (other user data).
    pub fn parse(payload: &[u8]) -> Option<Hid> {
        match payload {
            [SET, SET_RESET, t] => Some(Hid::Reset(*t)),
            [SET, SET_DIMMING, v] => Some(Hid::Dimming(*v)),
            [GET, p] => Some(Hid::Get(*p)),
            [GET, p, value @ ..] if param(*p).is_some_and(|d| d.len == value.len()) => {
                Some(Hid::Reply {
                    param: *p,
                    value: value.to_vec(),
                })
            }
            _ => None,
        }
    }

    /// The data frame payload.
    pub fn payload(&self) -> Vec<u8> {
        match self {
            Hid::Reset(t) => alloc::vec![SET, SET_RESET, *t],
            Hid::Dimming(v) => alloc::vec![SET, SET_DIMMING, *v],
            Hid::Get(p) => alloc::vec![GET, *p],
            Hid::Reply { param, value } => {
                let mut v = alloc::vec![GET, *param];
                v.extend_from_slice(value);
                v
            }
        }
    }

    /// The seed's name of the command.
    pub fn name(&self) -> &'static str {
        match self {
            Hid::Reset(_) => "HID board reset",
            Hid::Dimming(_) => "Lamp dimming",
            Hid::Get(_) | Hid::Reply { .. } => "Get HID parameter",
        }
    }

    /// The checks before sending (dimming 0-100, known reset type and
    /// parameter), in words.
    pub fn validate(&self) -> Result<(), HidError> {
        match *self {
            Hid::Dimming(v) if v > DIMMING_MAX => Err(HidError(alloc::format!(
                "dimming is 0 to {DIMMING_MAX} %, not {v}"
            ))),
            Hid::Reset(t) if t != RESET_SOFTWARE && t != RESET_HARDWARE => Err(HidError(
                alloc::format!("reset type is AAh (software) or 0Ch (hardware), not {t:02X}h"),
            )),
            Hid::Get(p) if param(p).is_none() => Err(HidError(alloc::format!(
                "there is no HID parameter {p:02X}h (00h-0Ah)"
            ))),
            _ => Ok(()),
        }
    }
}

/// The frame between the board and its ballast on the ballast's USART
/// (Appendix A, "Destination HID ballast"): `[length, payload...]`,
/// length counting itself, no address and no CRC.
pub fn ballast_frame(payload: &[u8]) -> Vec<u8> {
    let mut v = alloc::vec![(payload.len() + 1) as u8];
    v.extend_from_slice(payload);
    v
}

/// The payload of a ballast USART frame, if the length byte is right.
pub fn ballast_payload(frame: &[u8]) -> Option<&[u8]> {
    let (&len, rest) = frame.split_first()?;
    (len as usize == frame.len()).then_some(rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_parameter_value_is_cut_from_the_all_parameters_reply() {
        let b = Ballast {
            hardware: (0x01, 0x02),
            bus_voltage: 400,
            lamp_voltage: 100,
            status: 6,
            lamp_power: 150,
            last_failure: LastFailure {
                status: 4,
                bus_voltage: 390,
                lamp_voltage: 20,
            },
            supply_voltage: 230,
            temperature: -5,
            power_ons: 12,
            lifetime_hours: 3000,
        };
        assert_eq!(Ballast::decode(&b.encode()), Some(b));
        for p in PARAMS {
            let v = b.value(p.code).unwrap();
            assert_eq!(v.len(), p.len, "{}", p.name);
            for f in p.fields {
                // Each field of a single parameter reads what the same
                // field of the 0Ah layout reads.
                let all = fields::ALL.iter().find(|a| a.name == f.name).unwrap();
                assert_eq!(f.read(&v), all.read(&b.encode()), "{}", f.name);
            }
        }
        assert_eq!(b.state(), LampState::Run);
        assert_eq!(b.hardware_release(), "01.02");
    }

    #[test]
    fn dimming_above_100_is_refused() {
        assert_eq!(
            Hid::Dimming(101).validate().unwrap_err().0,
            "dimming is 0 to 100 %, not 101"
        );
        assert!(Hid::Dimming(100).validate().is_ok());
        assert!(Hid::Get(0x0B).validate().is_err());
    }
}
