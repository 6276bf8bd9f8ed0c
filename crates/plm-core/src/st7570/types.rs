//! Typed sub-fields of the ST7570 commands: access layer, signal and noise
//! estimations, demodulation counters, MAC credits and addresses. Their
//! bytes are read and written through the layouts of [`super::fields`].

use super::fields::{self as f, mac_data, signal_noise};
use crate::field::Field;
use alloc::vec::Vec;

/// The access layer (2.2; MIB 00A1h byte 12; status message LAYER bit).
/// The data layouts of 10h, 50h, 51h and the names of the 52h confirm
/// codes depend on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Layer {
    /// PHY mode: P_Data, P_Sync, P_Alarm services.
    Phy,
    /// MAC mode: M_Data, M_Sync, M_Alarm services.
    Mac,
}

impl Layer {
    /// The layer of MIB 00A1h byte 12 (1 PHY, 2 MAC, Table 137).
    pub fn from_access_layer_mode(byte: u8) -> Option<Layer> {
        match byte {
            1 => Some(Layer::Phy),
            2 => Some(Layer::Mac),
            _ => None,
        }
    }

    /// The byte of MIB 00A1h byte 12.
    pub fn access_layer_mode(self) -> u8 {
        match self {
            Layer::Phy => 1,
            Layer::Mac => 2,
        }
    }

    /// As the manual writes it.
    pub fn name(self) -> &'static str {
        match self {
            Layer::Phy => "PHY",
            Layer::Mac => "MAC",
        }
    }
}

pub(crate) fn get(field: &Field, data: &[u8]) -> u32 {
    field.get(data).unwrap_or(0) as u32
}

pub(crate) fn set(field: &Field, data: &mut [u8], value: u32) {
    field.set(data, value as i64);
}

/// S0, N0, S1, N1: raw estimations on PRE+SSD (3.6.1); dBµV = value / 100
/// ([`f::sn_dbuv`]). 24 bits each on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SignalNoise {
    /// Signal on channel 0 (f0).
    pub s0: u32,
    /// Noise on channel 0.
    pub n0: u32,
    /// Signal on channel 1 (f1).
    pub s1: u32,
    /// Noise on channel 1.
    pub n1: u32,
}

impl SignalNoise {
    /// Reads the 12 bytes at `at`.
    pub fn read(data: &[u8], at: usize) -> Self {
        use signal_noise::*;
        SignalNoise {
            s0: get(&S0.shifted(at), data),
            n0: get(&N0.shifted(at), data),
            s1: get(&S1.shifted(at), data),
            n1: get(&N1.shifted(at), data),
        }
    }

    /// Writes the 12 bytes at `at` (values are cut to 24 bits).
    pub fn write(&self, data: &mut [u8], at: usize) {
        use signal_noise::*;
        set(&S0.shifted(at), data, self.s0);
        set(&N0.shifted(at), data, self.n0);
        set(&S1.shifted(at), data, self.s1);
        set(&N1.shifted(at), data, self.n1);
    }
}

/// ASK0, ASK1 and SFSK counters of one P_SDU (3.6.2): bits decided from
/// one tone alone (value 0 or 1) or from both; they sum to 304.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Demodulation {
    /// ASK0.
    pub ask0: u16,
    /// ASK1.
    pub ask1: u16,
    /// FSK (the SFSK counter).
    pub fsk: u16,
}

impl Demodulation {
    pub(crate) fn read(data: &[u8], at: usize) -> Self {
        let w = |i: usize| u16::from_le_bytes([data[at + i], data[at + i + 1]]);
        Demodulation {
            ask0: w(0),
            ask1: w(2),
            fsk: w(4),
        }
    }

    pub(crate) fn write(&self, out: &mut [u8], at: usize) {
        out[at..at + 2].copy_from_slice(&self.ask0.to_le_bytes());
        out[at + 2..at + 4].copy_from_slice(&self.ask1.to_le_bytes());
        out[at + 4..at + 6].copy_from_slice(&self.fsk.to_le_bytes());
    }
}

/// What a PRE+SSD told: S0..N1, PGA gain and delta-phase (Table 17; MAC
/// SYNC = FOUND, Table 18).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SyncEstimate {
    /// S0, N0, S1, N1.
    pub sn: SignalNoise,
    /// RX PGA gain (0..8).
    pub pga: u8,
    /// Delta-phase code (Table 4; 0 = not valid).
    pub phase: u8,
}

/// CREDIT (4.8, Table 38): initial, current and delta credit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Credit {
    /// IC, 0..7: repetitions the originator asks for.
    pub ic: u8,
    /// CC, 0..7: repetitions still to come.
    pub cc: u8,
    /// DC, 0..3: IC - CC of the last frame from DA to SA.
    pub dc: u8,
}

impl Credit {
    /// The CREDIT byte (b7..b5 IC, b4..b2 CC, b1..b0 DC).
    pub fn byte(&self) -> u8 {
        let mut b = [0u8];
        set(&mac_data::IC, &mut b, self.ic as u32);
        set(&mac_data::CC, &mut b, self.cc as u32);
        set(&mac_data::DC, &mut b, self.dc as u32);
        b[0]
    }

    /// Reads a CREDIT byte.
    pub fn from_byte(b: u8) -> Self {
        Credit {
            ic: get(&mac_data::IC, &[b]) as u8,
            cc: get(&mac_data::CC, &[b]) as u8,
            dc: get(&mac_data::DC, &[b]) as u8,
        }
    }
}

/// The pre-defined group addresses of Table 6 (Table 5 calls FFCh and FFFh
/// "Reserved"; Table 6 gives them their meaning).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Group {
    /// 000h: no node has it; Clients always indicate it, Servers only with
    /// a group address 000h in MIB 0005h.
    NoBody,
    /// FFCh: nodes whose local address is not NEW.
    NotNew,
    /// FFEh: nodes whose local address is NEW.
    New,
    /// FFFh: every node.
    Broadcast,
}

impl Group {
    /// Every group of Table 6.
    pub const ALL: [Group; 4] = [Group::NoBody, Group::NotNew, Group::New, Group::Broadcast];

    /// Its 12-bit address.
    pub const fn address(self) -> u16 {
        match self {
            Group::NoBody => 0x000,
            Group::NotNew => 0xFFC,
            Group::New => 0xFFE,
            Group::Broadcast => 0xFFF,
        }
    }

    /// The group of an address, if it is one of Table 6.
    pub fn of(address: u16) -> Option<Group> {
        Group::ALL.into_iter().find(|g| g.address() == address)
    }

    /// As Table 6 names it.
    pub const fn name(self) -> &'static str {
        match self {
            Group::NoBody => "NO-BODY",
            Group::NotNew => "NOT-NEW",
            Group::New => "NEW",
            Group::Broadcast => "BROADCAST",
        }
    }
}

/// The 24-bit ADDRESS of MAC data (Table 38): 12-bit SA and DA.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Address {
    /// Source address (b23..b12).
    pub sa: u16,
    /// Destination address (b11..b0).
    pub da: u16,
}

impl Address {
    /// The three bytes as sent, MSByte first (SA C00h, DA 001h: C0 00 01).
    pub fn to_bytes(&self) -> [u8; 3] {
        let mut b = [0u8; 4];
        set(&mac_data::SA, &mut b, self.sa as u32);
        set(&mac_data::DA, &mut b, self.da as u32);
        [b[1], b[2], b[3]]
    }

    /// Reads the three bytes.
    pub fn from_bytes(b: [u8; 3]) -> Self {
        let d = [0, b[0], b[1], b[2]];
        Address {
            sa: get(&mac_data::SA, &d) as u16,
            da: get(&mac_data::DA, &d) as u16,
        }
    }
}

/// The data of a MAC CMD_DataRequest or CMD_DataIndication (Tables 38, 41).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct MacData {
    /// CREDIT.
    pub credit: Credit,
    /// ADDRESS.
    pub address: Address,
    /// PAD (00h in a request).
    pub pad: u8,
    /// M_SDU (1..242 bytes for the chip to accept it).
    pub m_sdu: Vec<u8>,
}

impl MacData {
    pub(crate) fn read(data: &[u8]) -> Self {
        MacData {
            credit: Credit::from_byte(data[0]),
            address: Address::from_bytes([data[1], data[2], data[3]]),
            pad: data[4],
            m_sdu: data[mac_data::HEADER_LEN..].to_vec(),
        }
    }

    pub(crate) fn write(&self, out: &mut Vec<u8>) {
        out.push(self.credit.byte());
        out.extend_from_slice(&self.address.to_bytes());
        out.push(self.pad);
        out.extend_from_slice(&self.m_sdu);
    }
}

/// P_Data.Indication (Table 37).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PhyDataIndication {
    /// P_SDU.
    pub p_sdu: [u8; f::P_SDU_LEN],
    /// ASK0, ASK1, FSK.
    pub demodulation: Demodulation,
    /// SNR0 (24 bits; [`f::snr_db`]).
    pub snr0: u32,
    /// SNR1.
    pub snr1: u32,
}

/// SPY_SubframeIndication (Table 52).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SpySubframe {
    /// S0..N1.
    pub sn: SignalNoise,
    /// ASK0, ASK1, FSK.
    pub demodulation: Demodulation,
    /// PGA gain code.
    pub pga: u8,
    /// P_SDU.
    pub p_sdu: [u8; f::P_SDU_LEN],
    /// SNR0.
    pub snr0: u32,
    /// SNR1.
    pub snr1: u32,
}

/// SPY_No_AlarmIndication and SPY_AlarmIndication (Tables 57, 59).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SpyAlarm {
    /// AL_S0, AL_N0, AL_S1, AL_N1.
    pub sn: SignalNoise,
    /// The 7 padding bytes, kept as received.
    pub pad: [u8; 7],
    /// ALARM, 24 bits MSByte first (569E89h).
    pub alarm: u32,
}

/// The RC pattern a Server heard (Table 63, bytes 2..9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct RcHeard {
    /// S, 100·dBµV averaged on both channels (24 bits).
    pub s: u32,
    /// N, 100·dBµV (24 bits).
    pub n: u32,
    /// RX_POS: the sub-timeslot the pattern was heard in.
    pub rx_pos: u16,
}

/// The best initiator of an intelligent synchronization (Table 65).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct IsLocked {
    /// ADD: its MAC address.
    pub add: u16,
    /// S: the highest of S0, S1, 100·dBµV.
    pub s: u16,
}
