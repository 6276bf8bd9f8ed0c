//! Field layouts of the ST7580 command data (UM0932 Tables 8, 19, 35-51)
//! and the enumerations they use. Each `LAYOUT` is the one description of
//! its table: typed codecs, the decoder and forms all read it.

use crate::field::{Absent, Field};

/// Frame modulation names (Tables 35, 39, 45, 48, 56), index = raw value.
pub const MODULATIONS: &[&str] = &[
    "B-PSK",
    "Q-PSK",
    "8-PSK",
    "B-FSK",
    "B-PSK coded",
    "Q-PSK coded",
    "Reserved",
    "B-PSK coded with Peak Noise Avoidance",
];

/// Temperature classes (Tables 8, 37).
pub const TEMPERATURES: &[&str] = &[
    "T < 70 °C",
    "70 °C < T < 100 °C",
    "100 °C < T < 125 °C",
    "T > 125 °C",
];

/// Error causes of Table 14, by value (a sparse table).
pub const ERROR_CAUSES: &[(u8, &str)] = &[
    (0x02, "Wrong parameter length (WPL)"),
    (0x03, "Wrong parameter value (WPV)"),
    (0x04, "Busy"),
    (0x0B, "Thermal error"),
    (0xFF, "General error"),
];

/// Status message byte 1 (UM0932 Table 8); offsets count from byte 1.
pub mod status {
    use super::*;
    /// Bit 0.
    pub const CONFIGURATION_STATUS: Field =
        Field::flag("configuration_status", "Configuration status", 0, 0);
    /// Bit 1.
    pub const TRANSMISSION_STATUS: Field =
        Field::flag("transmission_status", "Transmission status", 0, 1);
    /// Bit 2.
    pub const RECEPTION_STATUS: Field = Field::flag("reception_status", "Reception status", 0, 2);
    /// Bits 3-4.
    pub const ACTIVE_LAYER: Field = Field::enumeration(
        "active_layer",
        "Active layer",
        0,
        3,
        2,
        &["PHY layer", "DL layer", "SS layer", "ST7580 not configured"],
    );
    /// Bit 5.
    pub const OVERCURRENT_FLAG: Field = Field::flag("overcurrent_flag", "Overcurrent flag", 0, 5);
    /// Bits 6-7.
    pub const ESTIMATED_TEMPERATURE: Field = Field::enumeration(
        "estimated_st7580_temperature",
        "Estimated ST7580 temperature",
        0,
        6,
        2,
        TEMPERATURES,
    );
    /// Table 8.
    pub const LAYOUT: &[Field] = &[
        CONFIGURATION_STATUS,
        TRANSMISSION_STATUS,
        RECEPTION_STATUS,
        ACTIVE_LAYER,
        OVERCURRENT_FLAG,
        ESTIMATED_TEMPERATURE,
    ];
}

/// BIO_ResetIndication ResetData (UM0932 Table 19).
pub mod reset_data {
    use super::*;
    /// Bits 0-1.
    pub const RESET_CAUSE: Field = Field::enumeration(
        "reset_cause",
        "Reset Cause",
        0,
        0,
        2,
        &["RESETN pin or Power-ON", "Watchdog", "BIO_ResetRequest"],
    );
    /// Bit 2.
    pub const AUTORECONFIGURATION_ERROR: Field = Field::flag(
        "autoreconfiguration_error",
        "Autoreconfiguration Error",
        0,
        2,
    );
    /// Bit 3.
    pub const MODEM_CONFIG_ERROR: Field = Field::flag(
        "autoreconfiguration_modem_config_object_error",
        "Autoreconfiguration: Modem Config Object Error",
        0,
        3,
    );
    /// Bit 4.
    pub const PHY_CONFIG_ERROR: Field = Field::flag(
        "autoreconfiguration_phy_config_object_error",
        "Autoreconfiguration: PHY Config Object Error",
        0,
        4,
    );
    /// Bit 5.
    pub const SS_KEY_ERROR: Field = Field::flag(
        "autoreconfiguration_ss_key_object_error",
        "Autoreconfiguration: SS KeyObject Error",
        0,
        5,
    );
    /// Bits 6-7.
    pub const UNUSED: Field = Field::reserved("unused", "Unused", 0, 6, 2);
    /// Table 19.
    pub const LAYOUT: &[Field] = &[
        RESET_CAUSE,
        AUTORECONFIGURATION_ERROR,
        MODEM_CONFIG_ERROR,
        PHY_CONFIG_ERROR,
        SS_KEY_ERROR,
        UNUSED,
    ];
}

/// Byte 0 of PHY/DL/SS_DataRequest (UM0932 Tables 35 and 45).
pub mod tx_options {
    use super::*;
    /// Bit 0: 0 = frequency from MIB 01h, 1 = TX frequency in bytes 1-3.
    pub const CUSTOM_MIB_FREQUENCY: Field = Field::enumeration(
        "custom_mib_frequency",
        "Custom / MIB frequency",
        0,
        0,
        1,
        &["MIB", "Custom"],
    );
    /// Bit 1.
    pub const FREQUENCY_OVERWRITE: Field =
        Field::flag("frequency_overwrite", "Frequency overwrite", 0, 1);
    /// Bit 2.
    pub const FREQUENCY_SET: Field = Field::enumeration(
        "frequency_set",
        "Frequency set",
        0,
        2,
        1,
        &["LowFrequency", "HighFrequency"],
    );
    /// Bit 3: 0 = TX gain from MIB 01h, 1 = TX gain byte present.
    pub const GAIN_SELECTOR: Field = Field::enumeration(
        "gain_selector",
        "Gain selector",
        0,
        3,
        1,
        &["MIB", "Custom"],
    );
    /// Bits 4-6.
    pub const FRAME_MODULATION: Field =
        Field::enumeration("frame_modulation", "Frame modulation", 0, 4, 3, MODULATIONS);
    /// Bit 7.
    pub const ZERO_CROSSING_SYNCHRONIZATION: Field = Field::flag(
        "zero_crossing_synchronization",
        "Zero crossing synchronization",
        0,
        7,
    );
    /// Byte 0 of Table 35.
    pub const LAYOUT: &[Field] = &[
        CUSTOM_MIB_FREQUENCY,
        FREQUENCY_OVERWRITE,
        FREQUENCY_SET,
        GAIN_SELECTOR,
        FRAME_MODULATION,
        ZERO_CROSSING_SYNCHRONIZATION,
    ];
    /// Bytes 1-3 when custom (offset relative to the field): the carrier in
    /// Hz, MSByte first like MIB 01h; any value in CENELEC A-D (MIB 01h).
    pub const TX_FREQUENCY: Field = Field::uint("tx_frequency", "TX frequency", 0, 3)
        .range(3_000, 148_500)
        .unit("Hz");
    /// Byte 4 (or 1) when the gain selector is 1 (offset relative).
    pub const TX_GAIN: Field = Field::bits_uint("tx_gain", "TX gain", 0, 0, 5);
    /// Bits 5-7 of the TX gain byte, "Unused": written 0, a request with
    /// one set is refused (see protocol notes, "Reserved and unused bits").
    pub const TX_GAIN_UNUSED: Field = Field::reserved("unused", "Unused", 0, 5, 3);
    /// The TX gain byte of Tables 35 and 45.
    pub const GAIN_BYTE: &[Field] = &[TX_GAIN, TX_GAIN_UNUSED];
    /// SS_DataRequest header length (offset relative).
    pub const HEADER_LENGTH: Field = Field::uint("header_length", "Header length", 0, 1);
}

/// PHY/DL/SS_DataConfirm ConfirmData (UM0932 Table 37), also MIB 05h.
pub mod confirm_data {
    use super::*;
    /// Byte 0 bits 0-1.
    pub const MAX_TEMP: Field = Field::enumeration("max_temp", "Max. temp.", 0, 0, 2, TEMPERATURES);
    /// Byte 0 bits 2-6.
    pub const MAX_GAIN: Field = Field::bits_uint("max_gain", "Max. gain", 0, 2, 5);
    /// Byte 1 bits 0-1.
    pub const MIN_TEMP: Field = Field::enumeration("min_temp", "Min. temp", 1, 0, 2, TEMPERATURES);
    /// Byte 1 bits 2-6.
    pub const MIN_GAIN: Field = Field::bits_uint("min_gain", "Min. gain", 1, 2, 5);
    /// Byte 2 bits 0-6.
    pub const OVERCURRENT_EVENTS_NUMBER: Field = Field::bits_uint(
        "overcurrent_events_number",
        "Overcurrent events number",
        2,
        0,
        7,
    );
    /// Byte 2 bit 7.
    pub const OVERCURRENT_NOTIFICATION: Field =
        Field::flag("overcurrent_notification", "Overcurrent notification", 2, 7);
    /// Bytes 3-4, signed, 13 µs steps.
    pub const ZC_DELAY: Field = Field::int("zc_delay", "ZC delay", 3, 2).unit("13 µs");
    /// Table 37.
    pub const LAYOUT: &[Field] = &[
        MAX_TEMP,
        MAX_GAIN,
        MIN_TEMP,
        MIN_GAIN,
        OVERCURRENT_EVENTS_NUMBER,
        OVERCURRENT_NOTIFICATION,
        ZC_DELAY,
    ];
    /// Bytes of ConfirmData.
    pub const LEN: usize = 5;
}

/// The first four bytes of every data/sniffer indication (UM0932 Tables 39
/// and 48), also MIB 04h.
pub mod indication_data {
    use super::*;
    /// Byte 0 bits 0-2.
    pub const FRAME_MODULATION: Field =
        Field::enumeration("frame_modulation", "Frame modulation", 0, 0, 3, MODULATIONS);
    /// Byte 0 bit 3.
    pub const RX_CHANNEL: Field = Field::enumeration(
        "rx_channel",
        "RX channel",
        0,
        3,
        1,
        &["low channel", "high channel"],
    );
    /// Byte 0 bits 4-7.
    pub const PGA_VALUE: Field = Field::bits_uint("pga_value", "PGA value", 0, 4, 4);
    /// Byte 1: signed dB, "valid for PSK received frames only, equal to
    /// 255 – no meaning – for FSK received frames" (Tables 39, 48): 255 is
    /// no value after a B-FSK frame, and -1 dB after a PSK one.
    pub const SNR: Field = Field::int("snr", "SNR", 1, 1)
        .unit("dB")
        .absent_when(&Absent {
            raw: 0xFF,
            only_while: Some((&FRAME_MODULATION, 3)), // B-FSK
        });
    /// Bytes 2-3, signed, 13 µs steps.
    pub const ZC_DELAY: Field = Field::int("zc_delay", "ZC delay", 2, 2).unit("13 µs");
    /// Bytes 0-3 of Table 39.
    pub const LAYOUT: &[Field] = &[FRAME_MODULATION, RX_CHANNEL, PGA_VALUE, SNR, ZC_DELAY];
    /// Bytes before the payload.
    pub const LEN: usize = 4;
}
