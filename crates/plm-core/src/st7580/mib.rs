//! The ST7580 MIB (UM0932 4, Tables 52-62): the declarative table and a
//! typed struct per object. Multi-byte values are MSByte first (the
//! factory default of 01h, 014FF0h = 86000 Hz, shows it; see
//! docs/protocol-notes.md).

use super::fields::{confirm_data, indication_data};
use super::types::{DataConfirm, IndicationInfo};
use super::ErrorCause;
use crate::field::Field;
use crate::link::Timeouts;
use crate::mib::{self as m, Access, MibError, Object, Scope};
use alloc::vec::Vec;

/// MIB object indexes (Table 52).
pub mod index {
    /// 00h Modem configuration.
    pub const MODEM_CONFIG: u8 = 0x00;
    /// 01h PHY configuration.
    pub const PHY_CONFIG: u8 = 0x01;
    /// 02h SS key.
    pub const SS_KEY: u8 = 0x02;
    /// 03h Reserved.
    pub const RESERVED: u8 = 0x03;
    /// 04h Last data indication.
    pub const LAST_DATA_INDICATION: u8 = 0x04;
    /// 05h Last TX confirm.
    pub const LAST_TX_CONFIRM: u8 = 0x05;
    /// 06h PHY_Data counters.
    pub const PHY_DATA: u8 = 0x06;
    /// 07h DL_Data counters.
    pub const DL_DATA: u8 = 0x07;
    /// 08h SS_Data counters.
    pub const SS_DATA: u8 = 0x08;
    /// 09h Host interface timeout.
    pub const HOST_INTERFACE_TIMEOUT: u8 = 0x09;
    /// 0Ah Firmware version.
    pub const FIRMWARE_VERSION: u8 = 0x0A;
}

const PREAMBLES: &[&str] = &["16 bit", "24 bit", "32 bit", "40 bit"];
const RX_MODULATIONS: &[&str] = &["FSK", "PSK"];

/// Table 53, MIB 00h.
pub mod modem_config {
    use super::*;
    /// Bits 0-1: layer of received frames.
    pub const ACCESS_MODE: Field = Field::enumeration(
        "access_mode",
        "Access mode",
        0,
        0,
        2,
        &["PHY layer", "DL layer", "SS layer"],
    );
    /// Bit 2.
    pub const SNIFFER_MODE: Field = Field::flag("sniffer_mode", "Sniffer mode", 0, 2);
    /// Bits 3-4.
    pub const CRC_LENGTH: Field = Field::enumeration(
        "crc_length",
        "CRC length",
        0,
        3,
        2,
        &[
            "1 byte (CRC-8)",
            "2 byte (CRC-16), big endian",
            "4 byte (CRC-32), little endian",
            "4 byte (CRC-32), big endian",
        ],
    );
    /// Bit 5: "always equal to 0".
    pub const RESERVED: Field = Field::reserved("reserved", "Reserved", 0, 5, 1);
    /// Bit 6.
    pub const DL_CRC_ON_PHY_LENGTH: Field =
        Field::flag("dl_crc_on_phy_length", "DL CRC on PHY length", 0, 6);
    /// Bit 7.
    pub const UNUSED: Field = Field::reserved("unused", "Unused", 0, 7, 1);
    /// Table 53.
    pub const LAYOUT: &[Field] = &[
        ACCESS_MODE,
        SNIFFER_MODE,
        CRC_LENGTH,
        RESERVED,
        DL_CRC_ON_PHY_LENGTH,
        UNUSED,
    ];
}

/// Table 54, MIB 01h.
pub mod phy_config {
    use super::*;
    /// Bytes 0-2, MSByte first: any value in CENELEC A-D.
    pub const HIGH_FREQUENCY: Field = Field::uint("high_frequency", "High frequency", 0, 3)
        .range(3_000, 148_500)
        .unit("Hz");
    /// Bytes 3-5.
    pub const LOW_FREQUENCY: Field = Field::uint("low_frequency", "Low frequency", 3, 3)
        .range(3_000, 148_500)
        .unit("Hz");
    /// Byte 6 bit 0.
    pub const RX_MODE: Field = Field::enumeration(
        "rx_mode",
        "RX mode",
        6,
        0,
        1,
        &["high channel only", "dual channel"],
    );
    /// Byte 6 bit 1.
    pub const RX_HIGH_CHANNEL_MODULATION: Field = Field::enumeration(
        "rx_high_channel_modulation",
        "RX high channel modulation",
        6,
        1,
        1,
        RX_MODULATIONS,
    );
    /// Byte 6 bit 2.
    pub const RX_LOW_CHANNEL_MODULATION: Field = Field::enumeration(
        "rx_low_channel_modulation",
        "RX low channel modulation",
        6,
        2,
        1,
        RX_MODULATIONS,
    );
    /// Byte 6 bit 3.
    pub const CURRENT_CONTROL: Field = Field::flag("current_control", "Current control", 6, 3);
    /// Byte 6 bits 4-7.
    pub const UNUSED_6: Field = Field::reserved("unused_6", "Unused", 6, 4, 4);
    /// Byte 7 bits 0-4.
    pub const TX_GAIN: Field = Field::bits_uint("tx_gain", "TX gain", 7, 0, 5);
    /// Byte 7 bits 5-7.
    pub const RESERVED_7: Field = Field::reserved("reserved_7", "Reserved", 7, 5, 3);
    /// Bytes 8-9, signed, 13 µs steps.
    pub const ZC_DELAY: Field = Field::int("zc_delay", "ZC delay", 8, 2).unit("× 13 µs");
    /// Byte 10 bits 0-1.
    pub const PSK_PREAMBLE_LENGTH: Field = Field::enumeration(
        "psk_preamble_length",
        "PSK preamble length",
        10,
        0,
        2,
        PREAMBLES,
    );
    /// Byte 10 bits 2-7.
    pub const UNUSED_10: Field = Field::reserved("unused_10", "Unused", 10, 2, 6);
    /// Byte 11 bits 0-1.
    pub const FSK_BIT_RATE: Field = Field::enumeration(
        "fsk_bit_rate",
        "FSK bit rate",
        11,
        0,
        2,
        &["1200 bps", "2400 bps", "4800 bps", "9600 bps"],
    );
    /// Byte 11 bit 2.
    pub const FSK_DEVIATION: Field =
        Field::enumeration("fsk_deviation", "FSK deviation", 11, 2, 1, &["0.5", "1"]);
    /// Byte 11 bits 3-4.
    pub const FSK_PREAMBLE_LENGTH: Field = Field::enumeration(
        "fsk_preamble_length",
        "FSK preamble length",
        11,
        3,
        2,
        PREAMBLES,
    );
    /// Byte 11 bit 5.
    pub const FSK_UNIQUE_WORD_LENGTH: Field = Field::enumeration(
        "fsk_unique_word_length",
        "FSK unique word length",
        11,
        5,
        1,
        &["8 bit", "16 bit"],
    );
    /// Byte 11 bits 6-7 (the manual: bit 6 reserved, "7-8" unused).
    pub const RESERVED_11: Field = Field::reserved("reserved_11", "Reserved", 11, 6, 2);
    /// Byte 12.
    pub const FSK_UNIQUE_WORD_MSBYTE: Field =
        Field::uint("fsk_unique_word_msbyte", "FSK unique word MSByte", 12, 1);
    /// Byte 13.
    pub const FSK_UNIQUE_WORD_LSBYTE: Field =
        Field::uint("fsk_unique_word_lsbyte", "FSK unique word LSByte", 13, 1);
    /// Table 54.
    pub const LAYOUT: &[Field] = &[
        HIGH_FREQUENCY,
        LOW_FREQUENCY,
        RX_MODE,
        RX_HIGH_CHANNEL_MODULATION,
        RX_LOW_CHANNEL_MODULATION,
        CURRENT_CONTROL,
        UNUSED_6,
        TX_GAIN,
        RESERVED_7,
        ZC_DELAY,
        PSK_PREAMBLE_LENGTH,
        UNUSED_10,
        FSK_BIT_RATE,
        FSK_DEVIATION,
        FSK_PREAMBLE_LENGTH,
        FSK_UNIQUE_WORD_LENGTH,
        RESERVED_11,
        FSK_UNIQUE_WORD_MSBYTE,
        FSK_UNIQUE_WORD_LSBYTE,
    ];
}

const SS_KEY_LAYOUT: &[Field] = &[Field::bytes("ss_key", "SS Key", 0, 16)];
const RESERVED_LAYOUT: &[Field] = &[Field::uint("reserved", "Reserved", 0, 1)];
const PHY_DATA_LAYOUT: &[Field] = &[
    Field::uint(
        "received_unique_word_counter",
        "Received unique word counter",
        0,
        2,
    ),
    Field::uint(
        "phy_valid_received_frames_counter",
        "PHY valid received frames counter",
        2,
        2,
    ),
    Field::uint(
        "phy_transmitted_frames_counter",
        "PHY transmitted frames counter",
        4,
        2,
    ),
    Field::uint(
        "phy_refused_transmission_counter",
        "PHY refused transmission counter",
        6,
        2,
    ),
    Field::uint("network_period", "Network period", 8, 2).unit("× 13 µs"),
];
const DL_DATA_LAYOUT: &[Field] = &[
    Field::uint(
        "dl_valid_received_frames_counter",
        "DL valid received frames counter",
        0,
        2,
    ),
    Field::uint(
        "dl_invalid_received_frames_counter",
        "DL invalid received frames counter",
        2,
        2,
    ),
    Field::uint(
        "dl_transmitted_frames_counter",
        "DL transmitted frames counter",
        4,
        2,
    ),
    Field::uint(
        "dl_refused_transmission_counter",
        "DL refused transmission counter",
        6,
        2,
    ),
];
const SS_DATA_LAYOUT: &[Field] = &[
    Field::uint(
        "ss_valid_received_frames_counter",
        "SS valid received frames counter",
        0,
        2,
    ),
    Field::uint(
        "ss_not_authentic_received_frames_counter",
        "SS not authentic received frames counter",
        2,
        2,
    ),
    Field::uint(
        "ss_malformed_received_frames",
        "SS malformed received frames",
        4,
        2,
    ),
    Field::uint(
        "ss_transmitted_frames_counter",
        "SS transmitted frames counter",
        6,
        2,
    ),
    Field::uint(
        "ss_refused_transmission_counter",
        "SS refused transmission counter",
        8,
        2,
    ),
];
/// Table 61, MIB 09h. A zero timeout is refused (protocol notes).
pub mod host_interface_timeout {
    use super::*;
    /// Byte 0.
    pub const T_SR: Field = Field::uint("t_sr", "T SR", 0, 1).range(1, 255).unit("ms");
    /// Byte 1.
    pub const T_ACK: Field = Field::uint("t_ack", "T ACK", 1, 1).range(1, 255).unit("ms");
    /// Byte 2.
    pub const T_IC: Field = Field::uint("t_ic", "T IC", 2, 1).range(1, 255).unit("ms");
    /// Table 61.
    pub const LAYOUT: &[Field] = &[T_SR, T_ACK, T_IC];
}
const FIRMWARE_VERSION_LAYOUT: &[Field] = &[Field::bytes("fw_version", "FW version", 0, 4)];

/// Table 52 with the layouts of Tables 53-62.
pub const OBJECTS: &[Object] = &[
    Object {
        index: 0x00,
        name: "Modem configuration",
        section: "UM0932 4.2.1, Table 53",
        len: 1,
        access: Access::RW,
        default: &[0x11],
        fields: modem_config::LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x01,
        name: "PHY configuration",
        section: "UM0932 4.2.2, Table 54",
        len: 14,
        access: Access::RW,
        default: &[
            0x01, 0x4F, 0xF0, 0x01, 0x19, 0x40, 0x0E, 0x15, 0x00, 0x00, 0x02, 0x35, 0x9B, 0x58,
        ],
        fields: phy_config::LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x02,
        name: "SS key",
        section: "UM0932 4.2.3, Table 55",
        len: 16,
        access: Access::RW,
        default: &[0; 16],
        fields: SS_KEY_LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x03,
        name: "Reserved",
        section: "UM0932 Table 52",
        len: 1,
        access: Access::R,
        default: &[0],
        fields: RESERVED_LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x04,
        name: "Last data indication",
        section: "UM0932 4.2.4, Table 56",
        len: 4,
        access: Access::R,
        default: &[0; 4],
        fields: indication_data::LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x05,
        name: "Last TX confirm",
        section: "UM0932 4.2.5, Table 57",
        len: 5,
        access: Access::R,
        default: &[0; 5],
        fields: confirm_data::LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x06,
        name: "PHY_Data",
        section: "UM0932 4.2.6, Table 58",
        len: 10,
        access: Access::RE,
        default: &[0; 10],
        fields: PHY_DATA_LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x07,
        name: "DL_Data",
        section: "UM0932 4.2.7, Table 59",
        len: 8,
        access: Access::RE,
        default: &[0; 8],
        fields: DL_DATA_LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x08,
        name: "SS_Data",
        section: "UM0932 4.2.8, Table 60",
        len: 10,
        access: Access::RE,
        default: &[0; 10],
        fields: SS_DATA_LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x09,
        name: "Host interface timeout",
        section: "UM0932 4.2.9, Table 61",
        len: 3,
        access: Access::RW,
        default: &[0xC8, 0x28, 0x0A],
        fields: host_interface_timeout::LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
    Object {
        index: 0x0A,
        name: "Firmware version",
        section: "UM0932 4.2.10, Table 62",
        len: 4,
        access: Access::R,
        default: &[0x00, 0x42, 0x00, 0x97],
        fields: FIRMWARE_VERSION_LAYOUT,
        write: None,
        scope: Scope::ANY,
    },
];

/// The object with this index.
pub fn object(index: u8) -> Option<&'static Object> {
    m::find(OBJECTS, index as u16)
}

/// The Table 14 error cause the chip answers for a refused MIB operation:
/// WPL for a wrong length, WPV for everything else (protocol notes).
pub fn error_cause(e: &MibError) -> ErrorCause {
    match e {
        MibError::WrongLength { .. } => ErrorCause::WrongParameterLength,
        _ => ErrorCause::WrongParameterValue,
    }
}

/// Checks a MIB_WriteRequest as the chip does (3.3.4).
pub fn check_write(index: u8, data: &[u8]) -> Result<&'static Object, MibError> {
    let o = object(index).ok_or(MibError::UnknownObject(index as u16))?;
    o.check_write(data)?;
    Ok(o)
}

/// Checks a MIB_ReadRequest as the chip does (3.3.6).
pub fn check_read(index: u8) -> Result<&'static Object, MibError> {
    object(index).ok_or(MibError::UnknownObject(index as u16))
}

/// Checks a MIB_EraseRequest as the chip does (3.3.8).
pub fn check_erase(index: u8) -> Result<&'static Object, MibError> {
    let o = object(index).ok_or(MibError::UnknownObject(index as u16))?;
    o.check_erase()?;
    Ok(o)
}

fn get(f: &Field, d: &[u8]) -> i64 {
    f.get(d).unwrap_or(0)
}

fn put(fields: &[(&Field, i64)], len: usize) -> Vec<u8> {
    let mut d = alloc::vec![0u8; len];
    for (f, v) in fields {
        f.set(&mut d, *v);
    }
    d
}

/// MIB 00h (Table 53).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ModemConfig {
    /// Access mode: 0 PHY, 1 DL, 2 SS (3 is refused).
    pub access_mode: u8,
    /// Sniffer indications on.
    pub sniffer_mode: bool,
    /// CRC length code (0..3, Table 53).
    pub crc_length: u8,
    /// CRC also over the PHY length byte.
    pub dl_crc_on_phy_length: bool,
}

impl ModemConfig {
    /// Decodes the object.
    pub fn decode(d: &[u8]) -> Self {
        use modem_config::*;
        ModemConfig {
            access_mode: get(&ACCESS_MODE, d) as u8,
            sniffer_mode: get(&SNIFFER_MODE, d) != 0,
            crc_length: get(&CRC_LENGTH, d) as u8,
            dl_crc_on_phy_length: get(&DL_CRC_ON_PHY_LENGTH, d) != 0,
        }
    }

    /// Encodes the object.
    pub fn encode(&self) -> Vec<u8> {
        use modem_config::*;
        put(
            &[
                (&ACCESS_MODE, self.access_mode as i64),
                (&SNIFFER_MODE, self.sniffer_mode as i64),
                (&CRC_LENGTH, self.crc_length as i64),
                (&DL_CRC_ON_PHY_LENGTH, self.dl_crc_on_phy_length as i64),
            ],
            1,
        )
    }
}

/// MIB 01h (Table 54).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PhyConfig {
    /// High frequency, Hz.
    pub high_frequency: u32,
    /// Low frequency, Hz.
    pub low_frequency: u32,
    /// Dual channel reception.
    pub rx_mode_dual: bool,
    /// PSK (not FSK) on the high channel.
    pub rx_high_psk: bool,
    /// PSK (not FSK) on the low channel.
    pub rx_low_psk: bool,
    /// TX current limiting.
    pub current_control: bool,
    /// Default TX gain (0..31).
    pub tx_gain: u8,
    /// ZC delay, signed, 13 µs steps.
    pub zc_delay: i16,
    /// PSK preamble length code (0..3: 16..40 bit).
    pub psk_preamble_length: u8,
    /// FSK bit rate code (0..3: 1200..9600 bps).
    pub fsk_bit_rate: u8,
    /// FSK deviation 1 (not 0.5).
    pub fsk_deviation_1: bool,
    /// FSK preamble length code (0..3).
    pub fsk_preamble_length: u8,
    /// 16-bit (not 8-bit) FSK unique word.
    pub fsk_unique_word_16: bool,
    /// FSK unique word, MSByte then LSByte.
    pub fsk_unique_word: u16,
}

impl PhyConfig {
    /// Decodes the object.
    pub fn decode(d: &[u8]) -> Self {
        use phy_config::*;
        PhyConfig {
            high_frequency: get(&HIGH_FREQUENCY, d) as u32,
            low_frequency: get(&LOW_FREQUENCY, d) as u32,
            rx_mode_dual: get(&RX_MODE, d) != 0,
            rx_high_psk: get(&RX_HIGH_CHANNEL_MODULATION, d) != 0,
            rx_low_psk: get(&RX_LOW_CHANNEL_MODULATION, d) != 0,
            current_control: get(&CURRENT_CONTROL, d) != 0,
            tx_gain: get(&TX_GAIN, d) as u8,
            zc_delay: get(&ZC_DELAY, d) as i16,
            psk_preamble_length: get(&PSK_PREAMBLE_LENGTH, d) as u8,
            fsk_bit_rate: get(&FSK_BIT_RATE, d) as u8,
            fsk_deviation_1: get(&FSK_DEVIATION, d) != 0,
            fsk_preamble_length: get(&FSK_PREAMBLE_LENGTH, d) as u8,
            fsk_unique_word_16: get(&FSK_UNIQUE_WORD_LENGTH, d) != 0,
            fsk_unique_word: (get(&FSK_UNIQUE_WORD_MSBYTE, d) << 8
                | get(&FSK_UNIQUE_WORD_LSBYTE, d)) as u16,
        }
    }

    /// Encodes the object.
    pub fn encode(&self) -> Vec<u8> {
        use phy_config::*;
        put(
            &[
                (&HIGH_FREQUENCY, self.high_frequency as i64),
                (&LOW_FREQUENCY, self.low_frequency as i64),
                (&RX_MODE, self.rx_mode_dual as i64),
                (&RX_HIGH_CHANNEL_MODULATION, self.rx_high_psk as i64),
                (&RX_LOW_CHANNEL_MODULATION, self.rx_low_psk as i64),
                (&CURRENT_CONTROL, self.current_control as i64),
                (&TX_GAIN, self.tx_gain as i64),
                (&ZC_DELAY, self.zc_delay as i64),
                (&PSK_PREAMBLE_LENGTH, self.psk_preamble_length as i64),
                (&FSK_BIT_RATE, self.fsk_bit_rate as i64),
                (&FSK_DEVIATION, self.fsk_deviation_1 as i64),
                (&FSK_PREAMBLE_LENGTH, self.fsk_preamble_length as i64),
                (&FSK_UNIQUE_WORD_LENGTH, self.fsk_unique_word_16 as i64),
                (&FSK_UNIQUE_WORD_MSBYTE, (self.fsk_unique_word >> 8) as i64),
                (
                    &FSK_UNIQUE_WORD_LSBYTE,
                    (self.fsk_unique_word & 0xFF) as i64,
                ),
            ],
            14,
        )
    }
}

/// Counters of MIB 06h, 07h or 08h (Tables 58-60), in table order.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Counters(pub Vec<u16>);

/// Every ST7580 MIB object as a typed value.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum MibObject {
    /// 00h.
    ModemConfig(ModemConfig),
    /// 01h.
    PhyConfig(PhyConfig),
    /// 02h.
    SsKey([u8; 16]),
    /// 03h.
    Reserved(u8),
    /// 04h.
    LastDataIndication(IndicationInfo),
    /// 05h.
    LastTxConfirm(DataConfirm),
    /// 06h.
    PhyData(Counters),
    /// 07h.
    DlData(Counters),
    /// 08h.
    SsData(Counters),
    /// 09h.
    HostInterfaceTimeout {
        /// T_SR in ms.
        t_sr: u8,
        /// T_ACK in ms.
        t_ack: u8,
        /// T_IC in ms.
        t_ic: u8,
    },
    /// 0Ah.
    FirmwareVersion(u32),
}

impl MibObject {
    /// Decodes the value of object `index`; the length must be the
    /// object's (Table 52).
    pub fn decode(index: u8, d: &[u8]) -> Result<MibObject, MibError> {
        let o = object(index).ok_or(MibError::UnknownObject(index as u16))?;
        if d.len() != o.len {
            return Err(MibError::WrongLength {
                object: o.name,
                expected: o.len,
                got: d.len(),
            });
        }
        let counters = || {
            Counters(
                d.chunks(2)
                    .map(|c| u16::from_be_bytes([c[0], c[1]]))
                    .collect(),
            )
        };
        Ok(match index {
            index::MODEM_CONFIG => MibObject::ModemConfig(ModemConfig::decode(d)),
            index::PHY_CONFIG => MibObject::PhyConfig(PhyConfig::decode(d)),
            index::SS_KEY => {
                let mut k = [0u8; 16];
                k.copy_from_slice(d);
                MibObject::SsKey(k)
            }
            index::RESERVED => MibObject::Reserved(d[0]),
            index::LAST_DATA_INDICATION => MibObject::LastDataIndication(IndicationInfo::decode(d)),
            index::LAST_TX_CONFIRM => MibObject::LastTxConfirm(DataConfirm::decode(d)),
            index::PHY_DATA => MibObject::PhyData(counters()),
            index::DL_DATA => MibObject::DlData(counters()),
            index::SS_DATA => MibObject::SsData(counters()),
            index::HOST_INTERFACE_TIMEOUT => MibObject::HostInterfaceTimeout {
                t_sr: d[0],
                t_ack: d[1],
                t_ic: d[2],
            },
            _ => MibObject::FirmwareVersion(u32::from_be_bytes([d[0], d[1], d[2], d[3]])),
        })
    }

    /// The object's index.
    pub fn index(&self) -> u8 {
        match self {
            MibObject::ModemConfig(_) => index::MODEM_CONFIG,
            MibObject::PhyConfig(_) => index::PHY_CONFIG,
            MibObject::SsKey(_) => index::SS_KEY,
            MibObject::Reserved(_) => index::RESERVED,
            MibObject::LastDataIndication(_) => index::LAST_DATA_INDICATION,
            MibObject::LastTxConfirm(_) => index::LAST_TX_CONFIRM,
            MibObject::PhyData(_) => index::PHY_DATA,
            MibObject::DlData(_) => index::DL_DATA,
            MibObject::SsData(_) => index::SS_DATA,
            MibObject::HostInterfaceTimeout { .. } => index::HOST_INTERFACE_TIMEOUT,
            MibObject::FirmwareVersion(_) => index::FIRMWARE_VERSION,
        }
    }

    /// Encodes the object's value.
    pub fn encode(&self) -> Vec<u8> {
        match self {
            MibObject::ModemConfig(c) => c.encode(),
            MibObject::PhyConfig(c) => c.encode(),
            MibObject::SsKey(k) => k.to_vec(),
            MibObject::Reserved(b) => alloc::vec![*b],
            MibObject::LastDataIndication(i) => i.encode(),
            MibObject::LastTxConfirm(c) => c.encode(),
            MibObject::PhyData(c) | MibObject::DlData(c) | MibObject::SsData(c) => {
                c.0.iter().flat_map(|v| v.to_be_bytes()).collect()
            }
            MibObject::HostInterfaceTimeout { t_sr, t_ack, t_ic } => {
                alloc::vec![*t_sr, *t_ack, *t_ic]
            }
            MibObject::FirmwareVersion(v) => v.to_be_bytes().to_vec(),
        }
    }

    /// The factory default of object `index` (Table 52).
    pub fn factory_default(index: u8) -> Option<MibObject> {
        let o = object(index)?;
        MibObject::decode(index, o.default).ok()
    }

    /// The host-interface timeouts of a MIB 09h value.
    pub fn timeouts(&self) -> Option<Timeouts> {
        match *self {
            MibObject::HostInterfaceTimeout { t_sr, t_ack, t_ic } => {
                Some(Timeouts::from_ms(t_sr, t_ack, t_ic))
            }
            _ => None,
        }
    }
}
