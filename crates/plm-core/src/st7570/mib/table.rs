//! Table 71: the 35 ST7570 MIB objects, each with its layout (from
//! [`super`]), length, access, factory default, write layout and
//! scope. Where Table 71 and an object's own table disagree, the object's
//! table wins (docs/protocol-notes.md): 0014h is read-only (6.5.21), the
//! default of 0016h is 0FFFFFFFh (Table 120), of 00ACh 000000h (Table 143).

use super::*;
use crate::mib::{Access, Object};

macro_rules! object {
    ($index:literal, $name:literal, $section:literal, $len:literal, $access:ident, $default:expr, $fields:expr, $write:expr, $scope:expr) => {
        Object {
            index: $index,
            name: $name,
            section: $section,
            len: $len,
            access: Access::$access,
            default: &$default,
            fields: &$fields,
            write: $write,
            scope: $scope,
        }
    };
}

/// Table 71: the 35 objects with the layouts of Tables 72-147.
pub const OBJECTS: &[Object] = &[
    object!(
        0x0000,
        "FIMA / LIMA",
        "ST7570 UM 6.5.1, Table 72",
        4,
        RW,
        [0x00, 0x0C, 0xFF, 0x0D],
        *FIMA_LIMA,
        None,
        MAC
    ),
    object!(
        0x0001,
        "LocalMacAdd / InitMacAdd",
        "ST7570 UM 6.5.2, Table 74",
        4,
        RW,
        [0xFE, 0x0F, 0x00, 0x00],
        *LOCAL_INIT,
        None,
        MAC
    ),
    object!(
        0x0002,
        "Timeout synchro confirmation",
        "ST7570 UM 6.5.3, Table 76",
        2,
        RW,
        [3, 0],
        *SYNCHRO_CONFIRMATION,
        None,
        MAC_NOT_MONITOR
    ),
    object!(
        0x0003,
        "Timeout frame not ok",
        "ST7570 UM 6.5.4, Table 78",
        2,
        RW,
        [40, 0],
        *FRAME_NOT_OK,
        None,
        MAC_NOT_MONITOR
    ),
    object!(
        0x0004,
        "Timeout not addressed",
        "ST7570 UM 6.5.5, Table 80",
        2,
        RW,
        [0x68, 0x01],
        *NOT_ADDRESSED,
        None,
        MAC_NOT_MONITOR
    ),
    object!(
        0x0005,
        "MAC group addresses",
        "ST7570 UM 6.5.6, Table 82",
        10,
        RW,
        [0; 10],
        *GROUPS,
        None,
        MAC
    ),
    object!(
        0x0006,
        "Invalid frame counter",
        "ST7570 UM 6.5.7, Tables 84-85",
        4,
        RW,
        [0; 4],
        INVALID_FRAMES,
        Some(PAD4),
        MAC
    ),
    object!(
        0x0007,
        "Minimum delta credit",
        "ST7570 UM 6.5.8, Tables 87-88",
        1,
        RW,
        [7],
        *MIN_DELTA_CREDIT,
        Some(MIN_DELTA_CREDIT_WRITE),
        MAC
    ),
    object!(
        0x0008,
        "Disable frame type check / Disable CRC check",
        "ST7570 UM 6.5.9, Table 90",
        1,
        RW,
        [0],
        *CHECKS,
        None,
        MAC
    ),
    object!(
        0x0009,
        "Timeout intelligent synchronization",
        "ST7570 UM 6.5.10, Table 92",
        2,
        RW,
        [0, 0],
        *IS_TIMEOUT,
        None,
        MAC_NOT_MONITOR
    ),
    object!(
        0x000A,
        "Valid frame counter",
        "ST7570 UM 6.5.11, Tables 94-95",
        4,
        RW,
        [0; 4],
        VALID_FRAMES,
        Some(PAD4),
        MAC
    ),
    object!(
        0x000B,
        "TIC selector / Repeater settings",
        "ST7570 UM 6.5.12, Table 97",
        1,
        RW,
        [0],
        *TIC_REPEATER,
        None,
        BOTH
    ),
    object!(
        0x000C,
        "RC threshold",
        "ST7570 UM 6.5.13, Table 99",
        4,
        RW,
        [0xA0, 0x28, 0, 0],
        *RC_THRESHOLD,
        None,
        MAC
    ),
    object!(
        0x000D,
        "S0, N0, PGA",
        "ST7570 UM 6.5.14, Table 101",
        10,
        R,
        [0; 10],
        *S0_N0_PGA,
        None,
        BOTH
    ),
    object!(
        0x000E,
        "S1, N1, phase",
        "ST7570 UM 6.5.15, Table 102",
        10,
        R,
        [0; 10],
        *S1_N1_PHASE,
        None,
        BOTH
    ),
    object!(
        0x000F,
        "Transmitted frame counter",
        "ST7570 UM 6.5.16, Tables 103-104",
        4,
        RW,
        [0; 4],
        TRANSMITTED,
        Some(PAD4),
        MAC
    ),
    object!(
        0x0010,
        "Repeated frame counter",
        "ST7570 UM 6.5.17, Tables 106-107",
        4,
        RW,
        [0; 4],
        REPEATED,
        Some(PAD4),
        MAC
    ),
    object!(
        0x0011,
        "Bad frame indicator counter",
        "ST7570 UM 6.5.18, Tables 109-110",
        4,
        RW,
        [0; 4],
        BAD_FI,
        Some(PAD4),
        MAC
    ),
    object!(
        0x0012,
        "Frame indicator",
        "ST7570 UM 6.5.19, Table 112",
        2,
        RW,
        [0, 0],
        *FRAME_INDICATOR,
        None,
        MAC
    ),
    object!(
        0x0013,
        "Smart-phase detect",
        "ST7570 UM 6.5.20, Table 114",
        1,
        RW,
        [0],
        *SMART_PHASE,
        None,
        MAC
    ),
    object!(
        0x0014,
        "Phase",
        "ST7570 UM 6.5.21, Table 116",
        1,
        R,
        [0],
        *PHASE,
        None,
        MAC
    ),
    object!(
        0x0015,
        "Auto synchronization reject",
        "ST7570 UM 6.5.22, Table 118",
        1,
        RW,
        [0],
        *AUTO_SYNCHRO_REJECT,
        None,
        MAC_MONITOR
    ),
    object!(
        0x0016,
        "Intelligent synchronization threshold",
        "ST7570 UM 6.5.23, Table 120",
        4,
        RW,
        [0xFF, 0xFF, 0xFF, 0x0F],
        *IS_THRESHOLD,
        None,
        MAC
    ),
    object!(
        0x0082,
        "TX output gain / Current limiting",
        "ST7570 UM 6.5.24, Tables 122-123",
        3,
        RW,
        [0x00, 0x10, 0x10],
        *TX_GAIN,
        Some(TX_GAIN_WRITE),
        BOTH
    ),
    object!(
        0x0083,
        "Received alarm counter",
        "ST7570 UM 6.5.25, Tables 125-126",
        4,
        RW,
        [0; 4],
        ALARMS_RECEIVED,
        Some(PAD4),
        BOTH
    ),
    object!(
        0x0084,
        "Transmitted alarm counter",
        "ST7570 UM 6.5.26, Tables 128-129",
        4,
        RW,
        [0; 4],
        ALARMS_SENT,
        Some(PAD4),
        BOTH
    ),
    object!(
        0x0085,
        "Alarm repeater / Alarm before indication / Alarm reject window",
        "ST7570 UM 6.5.27, Table 131",
        3,
        RW,
        [8, 2, 9],
        *ALARM_PARAMETERS,
        None,
        BOTH
    ),
    object!(
        0x0086,
        "Alarm indication / Repetition disable / SN indication disable",
        "ST7570 UM 6.5.28, Table 133",
        1,
        RW,
        [0x04],
        *ALARM_FLAGS,
        None,
        BOTH
    ),
    object!(
        0x00A0,
        "New synchronization",
        "ST7570 UM 6.5.29, Table 135",
        1,
        W,
        [0],
        *NEW_SYNC,
        None,
        BOTH
    ),
    object!(
        0x00A1,
        "PLC configuration",
        "ST7570 UM 6.5.30, Table 137",
        14,
        RW,
        [0x00, 0x00, 0x10, 0x10, 0x21, 0x01, 0x44, 0xF7, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00],
        *plc::LAYOUT,
        None,
        BOTH
    ),
    object!(
        0x00A4,
        "Programmable digital I/O pins",
        "ST7570 UM 6.5.31, Table 139",
        1,
        RW,
        [0],
        *DIGITAL_OUTPUT,
        None,
        BOTH
    ),
    object!(
        0x00AB,
        "Max PGA Gain",
        "ST7570 UM 6.5.32, Table 141",
        4,
        RW,
        [0x08, 0, 0, 0],
        *MAX_PGA_GAIN,
        None,
        BOTH
    ),
    object!(
        0x00AC,
        "Soft start",
        "ST7570 UM 6.5.33, Table 143",
        3,
        RW,
        [0, 0, 0],
        *SOFT_START,
        None,
        BOTH
    ),
    object!(
        0x00C2,
        "Time-slot delay bit",
        "ST7570 UM 6.5.34, Table 145",
        3,
        RW,
        [1, 0, 0],
        *TIME_SLOT_DELAY,
        None,
        BOTH
    ),
    object!(
        0x00D1,
        "ZC delay compensation",
        "ST7570 UM 6.5.35, Table 147",
        3,
        RW,
        [0, 0, 0],
        *ZC_DELAY,
        None,
        BOTH
    ),
];
