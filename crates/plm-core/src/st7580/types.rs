//! Typed values of the ST7580 command data, read and written through the
//! layouts of [`super::fields`].

use super::fields::{
    confirm_data as cd, indication_data as ind, reset_data as rd, status as st, tx_options as tx,
    ERROR_CAUSES,
};
use crate::field::Field;
use crate::link::{Dialect, StatusMessage};
use alloc::vec;
use alloc::vec::Vec;

macro_rules! total_enum {
    ($(#[$m:meta])* $name:ident { $($(#[$vm:meta])* $v:ident = $n:literal),* $(,)? }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[allow(missing_docs)]
        pub enum $name { $($(#[$vm])* $v = $n),* }
        impl $name {
            /// The value of raw bits (every bit pattern of the field's
            /// width has a variant; wider values wrap).
            pub fn from_bits(raw: u8) -> Self {
                const ALL: &[$name] = &[$($name::$v),*];
                ALL[raw as usize % ALL.len()]
            }
            /// The raw bits.
            pub fn bits(self) -> u8 { self as u8 }
        }
    };
}

total_enum! {
    /// Frame modulation (UM0932 Table 35 bits 4-6, Table 39 bits 0-2).
    Modulation { BPsk = 0, QPsk = 1, EightPsk = 2, BFsk = 3, BPskCoded = 4, QPskCoded = 5, Reserved = 6, BPskCodedPna = 7 }
}
total_enum! {
    /// Temperature class (UM0932 Tables 8, 37).
    Temperature { Below70 = 0, From70To100 = 1, From100To125 = 2, Above125 = 3 }
}
total_enum! {
    /// Reset cause (UM0932 Table 19); 3 is not defined by the manual.
    ResetCause { PowerOn = 0, Watchdog = 1, ResetRequest = 2, Undefined = 3 }
}
total_enum! {
    /// Active layer of the status message (UM0932 Table 8).
    ActiveLayer { Phy = 0, Dl = 1, Ss = 2, NotConfigured = 3 }
}
total_enum! {
    /// Which channel received a frame (UM0932 Table 39).
    Channel { Low = 0, High = 1 }
}
total_enum! {
    /// Which PHY_Config frequency to transmit on (UM0932 Table 35 bit 2).
    FrequencySet { Low = 0, High = 1 }
}

fn get(f: &Field, data: &[u8]) -> u8 {
    f.get(data).unwrap_or(0) as u8
}

/// Error cause of every error command but CMD_SyntaxError (Table 14).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorCause {
    /// 02h: data field length was wrong.
    WrongParameterLength,
    /// 03h: a parameter value was invalid.
    WrongParameterValue,
    /// 04h: the modem is busy.
    Busy,
    /// 0Bh: too hot, transmission refused.
    ThermalError,
    /// FFh: generic error.
    GeneralError,
    /// A value Table 14 does not define, preserved.
    Other(u8),
}

impl ErrorCause {
    /// The cause of a raw byte.
    pub fn from_byte(b: u8) -> Self {
        match b {
            0x02 => ErrorCause::WrongParameterLength,
            0x03 => ErrorCause::WrongParameterValue,
            0x04 => ErrorCause::Busy,
            0x0B => ErrorCause::ThermalError,
            0xFF => ErrorCause::GeneralError,
            other => ErrorCause::Other(other),
        }
    }

    /// The raw byte.
    pub fn byte(self) -> u8 {
        match self {
            ErrorCause::WrongParameterLength => 0x02,
            ErrorCause::WrongParameterValue => 0x03,
            ErrorCause::Busy => 0x04,
            ErrorCause::ThermalError => 0x0B,
            ErrorCause::GeneralError => 0xFF,
            ErrorCause::Other(b) => b,
        }
    }

    /// The name in Table 14.
    pub fn name(self) -> Option<&'static str> {
        let b = self.byte();
        ERROR_CAUSES.iter().find(|(v, _)| *v == b).map(|(_, n)| *n)
    }
}

/// Status message of the ST7580 (UM0932 Table 8), byte 1 decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Status {
    /// Autoreconfiguration had errors, or 00h-02h are still at defaults.
    pub configuration_status: bool,
    /// A power line frame is being transmitted.
    pub transmitting: bool,
    /// A power line frame is being received.
    pub receiving: bool,
    /// The layer received frames are handled at.
    pub active_layer: ActiveLayer,
    /// The last transmission hit the current limit.
    pub overcurrent: bool,
    /// Estimated temperature class.
    pub temperature: Temperature,
}

impl Status {
    /// Decodes a status message.
    pub fn from_message(m: &StatusMessage) -> Self {
        let d = m.data();
        Status {
            configuration_status: get(&st::CONFIGURATION_STATUS, d) != 0,
            transmitting: get(&st::TRANSMISSION_STATUS, d) != 0,
            receiving: get(&st::RECEPTION_STATUS, d) != 0,
            active_layer: ActiveLayer::from_bits(get(&st::ACTIVE_LAYER, d)),
            overcurrent: get(&st::OVERCURRENT_FLAG, d) != 0,
            temperature: Temperature::from_bits(get(&st::ESTIMATED_TEMPERATURE, d)),
        }
    }

    /// The status message carrying these bits.
    pub fn to_message(&self) -> StatusMessage {
        let mut d = [0u8];
        st::CONFIGURATION_STATUS.set(&mut d, self.configuration_status as i64);
        st::TRANSMISSION_STATUS.set(&mut d, self.transmitting as i64);
        st::RECEPTION_STATUS.set(&mut d, self.receiving as i64);
        st::ACTIVE_LAYER.set(&mut d, self.active_layer.bits() as i64);
        st::OVERCURRENT_FLAG.set(&mut d, self.overcurrent as i64);
        st::ESTIMATED_TEMPERATURE.set(&mut d, self.temperature.bits() as i64);
        StatusMessage::new(Dialect::St7580, &d)
    }
}

/// ResetData of BIO_ResetIndication (UM0932 Table 19).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ResetData {
    /// Why the modem reset.
    pub reset_cause: ResetCause,
    /// Autoreconfiguration had errors, or 00h-02h are at their defaults.
    pub autoreconfiguration_error: bool,
    /// The same for MIB 00h.
    pub modem_config_error: bool,
    /// The same for MIB 01h.
    pub phy_config_error: bool,
    /// The same for MIB 02h.
    pub ss_key_error: bool,
}

impl ResetData {
    /// Decodes the ResetData byte.
    pub fn from_byte(b: u8) -> Self {
        let d = [b];
        ResetData {
            reset_cause: ResetCause::from_bits(get(&rd::RESET_CAUSE, &d)),
            autoreconfiguration_error: get(&rd::AUTORECONFIGURATION_ERROR, &d) != 0,
            modem_config_error: get(&rd::MODEM_CONFIG_ERROR, &d) != 0,
            phy_config_error: get(&rd::PHY_CONFIG_ERROR, &d) != 0,
            ss_key_error: get(&rd::SS_KEY_ERROR, &d) != 0,
        }
    }

    /// The ResetData byte.
    pub fn byte(&self) -> u8 {
        let mut d = [0u8];
        rd::RESET_CAUSE.set(&mut d, self.reset_cause.bits() as i64);
        rd::AUTORECONFIGURATION_ERROR.set(&mut d, self.autoreconfiguration_error as i64);
        rd::MODEM_CONFIG_ERROR.set(&mut d, self.modem_config_error as i64);
        rd::PHY_CONFIG_ERROR.set(&mut d, self.phy_config_error as i64);
        rd::SS_KEY_ERROR.set(&mut d, self.ss_key_error as i64);
        d[0]
    }
}

/// How a data request is transmitted: byte 0 and the optional TX frequency
/// and TX gain of UM0932 Tables 35 and 45.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TxParams {
    /// Frame modulation.
    pub modulation: Modulation,
    /// Which PHY_Config frequency to use when `tx_frequency` is `None`.
    pub frequency_set: FrequencySet,
    /// With a custom frequency: also store it in PHY_Config.
    pub frequency_overwrite: bool,
    /// Start after the PHY_Config ZC delay from the zero crossing.
    pub zero_crossing_sync: bool,
    /// Custom TX frequency in Hz (24 bits), or the MIB frequency.
    pub tx_frequency: Option<u32>,
    /// The custom TX gain byte (Table 35 byte 4 or 1), or the MIB gain:
    /// the gain in bits 0-4; bits 5-7 are unused and kept as sent, so that
    /// validation refuses them as it refuses a MIB object's (see protocol
    /// notes). A gain of 0-31 is the whole byte.
    pub tx_gain: Option<u8>,
}

impl Default for TxParams {
    fn default() -> Self {
        TxParams {
            modulation: Modulation::BPsk,
            frequency_set: FrequencySet::High,
            frequency_overwrite: false,
            zero_crossing_sync: false,
            tx_frequency: None,
            tx_gain: None,
        }
    }
}

impl TxParams {
    /// Reads the parameters at the start of `data`; returns them and the
    /// number of bytes they took, or `None` when `data` is too short.
    pub fn parse(data: &[u8]) -> Option<(Self, usize)> {
        let o = data.get(..1)?;
        let custom = get(&tx::CUSTOM_MIB_FREQUENCY, o) == 1;
        let gain = get(&tx::GAIN_SELECTOR, o) == 1;
        let mut at = 1;
        let tx_frequency = if custom {
            let v = tx::TX_FREQUENCY.get(data.get(at..)?)? as u32;
            at += 3;
            Some(v)
        } else {
            None
        };
        let tx_gain = if gain {
            let v = *data.get(at)?;
            at += 1;
            Some(v)
        } else {
            None
        };
        Some((
            TxParams {
                modulation: Modulation::from_bits(get(&tx::FRAME_MODULATION, o)),
                frequency_set: FrequencySet::from_bits(get(&tx::FREQUENCY_SET, o)),
                frequency_overwrite: get(&tx::FREQUENCY_OVERWRITE, o) != 0,
                zero_crossing_sync: get(&tx::ZERO_CROSSING_SYNCHRONIZATION, o) != 0,
                tx_frequency,
                tx_gain,
            },
            at,
        ))
    }

    /// Appends the parameters' bytes.
    pub fn emit(&self, out: &mut Vec<u8>) {
        let mut o = [0u8];
        tx::CUSTOM_MIB_FREQUENCY.set(&mut o, self.tx_frequency.is_some() as i64);
        tx::FREQUENCY_OVERWRITE.set(&mut o, self.frequency_overwrite as i64);
        tx::FREQUENCY_SET.set(&mut o, self.frequency_set.bits() as i64);
        tx::GAIN_SELECTOR.set(&mut o, self.tx_gain.is_some() as i64);
        tx::FRAME_MODULATION.set(&mut o, self.modulation.bits() as i64);
        tx::ZERO_CROSSING_SYNCHRONIZATION.set(&mut o, self.zero_crossing_sync as i64);
        out.push(o[0]);
        if let Some(f) = self.tx_frequency {
            let mut b = [0u8; 3];
            tx::TX_FREQUENCY.set(&mut b, f as i64);
            out.extend_from_slice(&b);
        }
        if let Some(g) = self.tx_gain {
            out.push(g);
        }
    }

    /// Bytes the parameters take.
    pub fn len(&self) -> usize {
        1 + 3 * self.tx_frequency.is_some() as usize + self.tx_gain.is_some() as usize
    }

    /// Never empty: byte 0 is always there.
    pub fn is_empty(&self) -> bool {
        false
    }
}

/// PHY_DataRequest and DL_DataRequest RequestData (UM0932 Table 35).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct DataRequest {
    /// How to transmit.
    pub params: TxParams,
    /// The payload.
    pub payload: Vec<u8>,
}

/// SS_DataRequest RequestData (UM0932 Table 45).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct SsDataRequest {
    /// How to transmit.
    pub params: TxParams,
    /// Bytes of `header_and_payload` sent in clear.
    pub header_length: u8,
    /// Header (clear) then payload (encrypted), as one buffer.
    pub header_and_payload: Vec<u8>,
}

/// ConfirmData of PHY/DL/SS_DataConfirm (UM0932 Table 37) and MIB 05h.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DataConfirm {
    /// Highest temperature class during the transmission.
    pub max_temp: Temperature,
    /// Highest gain used (5 bits).
    pub max_gain: u8,
    /// Lowest temperature class.
    pub min_temp: Temperature,
    /// Lowest gain used (5 bits).
    pub min_gain: u8,
    /// Overcurrent events (7 bits).
    pub overcurrent_events: u8,
    /// The current limit was reached.
    pub overcurrent: bool,
    /// Last UW bit to mains zero crossing, signed, 13 µs steps.
    pub zc_delay: i16,
}

impl Default for DataConfirm {
    fn default() -> Self {
        DataConfirm::decode(&[0; cd::LEN])
    }
}

impl DataConfirm {
    /// Decodes 5 bytes (missing bytes read as 0).
    pub fn decode(d: &[u8]) -> Self {
        DataConfirm {
            max_temp: Temperature::from_bits(get(&cd::MAX_TEMP, d)),
            max_gain: get(&cd::MAX_GAIN, d),
            min_temp: Temperature::from_bits(get(&cd::MIN_TEMP, d)),
            min_gain: get(&cd::MIN_GAIN, d),
            overcurrent_events: get(&cd::OVERCURRENT_EVENTS_NUMBER, d),
            overcurrent: get(&cd::OVERCURRENT_NOTIFICATION, d) != 0,
            zc_delay: cd::ZC_DELAY.get(d).unwrap_or(0) as i16,
        }
    }

    /// The 5 bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut d = vec![0u8; cd::LEN];
        cd::MAX_TEMP.set(&mut d, self.max_temp.bits() as i64);
        cd::MAX_GAIN.set(&mut d, self.max_gain as i64);
        cd::MIN_TEMP.set(&mut d, self.min_temp.bits() as i64);
        cd::MIN_GAIN.set(&mut d, self.min_gain as i64);
        cd::OVERCURRENT_EVENTS_NUMBER.set(&mut d, self.overcurrent_events as i64);
        cd::OVERCURRENT_NOTIFICATION.set(&mut d, self.overcurrent as i64);
        cd::ZC_DELAY.set(&mut d, self.zc_delay as i64);
        d
    }
}

/// The first four bytes of every indication (UM0932 Table 39) and MIB 04h.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct IndicationInfo {
    /// Modulation of the received frame.
    pub modulation: Modulation,
    /// Channel it was received on.
    pub rx_channel: Channel,
    /// PGA value (4 bits).
    pub pga: u8,
    /// Raw SNR byte: signed dB, 255 for FSK frames ("no meaning").
    pub snr: u8,
    /// Last UW bit to mains zero crossing, signed, 13 µs steps.
    pub zc_delay: i16,
}

impl Default for IndicationInfo {
    fn default() -> Self {
        IndicationInfo::decode(&[0; ind::LEN])
    }
}

impl IndicationInfo {
    /// Decodes 4 bytes (missing bytes read as 0).
    pub fn decode(d: &[u8]) -> Self {
        IndicationInfo {
            modulation: Modulation::from_bits(get(&ind::FRAME_MODULATION, d)),
            rx_channel: Channel::from_bits(get(&ind::RX_CHANNEL, d)),
            pga: get(&ind::PGA_VALUE, d),
            snr: d.get(1).copied().unwrap_or(0),
            zc_delay: ind::ZC_DELAY.get(d).unwrap_or(0) as i16,
        }
    }

    /// The 4 bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut d = vec![0u8; ind::LEN];
        ind::FRAME_MODULATION.set(&mut d, self.modulation.bits() as i64);
        ind::RX_CHANNEL.set(&mut d, self.rx_channel.bits() as i64);
        ind::PGA_VALUE.set(&mut d, self.pga as i64);
        d[1] = self.snr;
        ind::ZC_DELAY.set(&mut d, self.zc_delay as i64);
        d
    }

    /// SNR in dB, `None` for a B-FSK frame's 255 (no meaning, Table 39).
    pub fn snr_db(&self) -> Option<i8> {
        match ind::SNR.read(&self.encode()) {
            Some(crate::field::Value::Int(v)) => Some(v as i8),
            _ => None,
        }
    }
}

/// IndicationData of every data and sniffer indication (Tables 39, 48).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct DataIndication {
    /// Reception details.
    pub info: IndicationInfo,
    /// The received payload (for DL_SnifferIndication with the wrong CRC;
    /// for SS indications the header and payload).
    pub payload: Vec<u8>,
}
