//! Every ST7570 command (ST7570 UM 5.3, Table 15) as a typed value with
//! parse and emit, in both access layers.

use super::code as c;
use super::fields::{self as f, alarm_indication, is_indication, mac_sync, rc_confirm, spy_alarm};
use super::types::{
    get, Demodulation, IsLocked, Layer, MacData, PhyDataIndication, RcHeard, SignalNoise, SpyAlarm,
    SpySubframe, SyncEstimate,
};
use crate::link::LocalFrame;
use alloc::vec::Vec;
use core::fmt;

/// What a MAC CMD_SynchroIndication says (Table 18), by SYNC.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum MacSync {
    /// SYNC = 1: time-slot synchronization found (estimates of the PRE+SSD;
    /// all 0 on a Client's own first transmission, 10.3.1).
    Found(SyncEstimate),
    /// SYNC = 2: confirmed by the frame from SA to DA.
    Confirmed {
        /// PAD, kept as received.
        pad: u8,
        /// Source address of the confirming frame.
        sa: u16,
        /// Destination address of the confirming frame.
        da: u16,
    },
    /// SYNC = 4: lost.
    Lost {
        /// CAUSE 1..5 ([`f::LOST_CAUSES`]).
        cause: u8,
        /// ADD1: local address (CAUSE 4: the frame's source address).
        add1: u16,
        /// ADD2: initiator address (CAUSE 4: the frame's destination).
        add2: u16,
    },
    /// SYNC = 5: intelligent synchronization.
    Intelligent {
        /// CAUSE 06h..08h ([`f::INTELLIGENT_CAUSES`]).
        cause: u8,
        /// ADD: the initiator's address.
        add: u16,
        /// S: the highest of S0, S1, 100·dBµV.
        s: u16,
    },
    /// A SYNC value Table 18 does not define, with the bytes after it.
    Other {
        /// SYNC.
        sync: u8,
        /// The bytes after SYNC.
        data: Vec<u8>,
    },
}

/// A command of Table 15 (in the layout of its access layer), or an
/// unknown code kept whole.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Command {
    /// 10h in PHY mode (Table 17): sent on every valid PRE+SSD.
    PhySynchroIndication(SyncEstimate),
    /// 10h in MAC mode (Table 18): a change of the synchronization state.
    MacSynchroIndication(MacSync),
    /// 11h (Table 22); RESET = 1 rejects the current synchronization.
    DesynchroRequest {
        /// RESET.
        reset: u8,
    },
    /// 85h from the host, no data (Table 19).
    SynchroStatusRequest,
    /// 85h from the modem (Table 20).
    SynchroStatus {
        /// STATUS: 1 LP_SYNC_FOUND, 2 LP_SYNC_LOSS.
        status: u8,
    },
    /// 21h, both ways (Tables 24, 25): from the host RESET 0 keeps the
    /// configuration, 1 loads the factory defaults; from the modem RESET 0
    /// says the reset was taken into account.
    ResetRequest {
        /// RESET.
        reset: u8,
    },
    /// 41h (Table 27).
    WriteDbRequest {
        /// INDEX.
        index: u16,
        /// DATA.
        data: Vec<u8>,
    },
    /// 42h (5.3.6): the request's INDEX and DATA back.
    WriteDbConfirm {
        /// INDEX.
        index: u16,
        /// DATA.
        data: Vec<u8>,
    },
    /// 43h (Table 30).
    WriteDbError {
        /// ERROR ([`f::MIB_ERRORS`]).
        error: u8,
    },
    /// 90h (Table 32).
    ReadDbRequest {
        /// INDEX.
        index: u16,
    },
    /// 91h (5.3.9): INDEX and the object's value.
    ReadDbConfirm {
        /// INDEX.
        index: u16,
        /// DATA.
        data: Vec<u8>,
    },
    /// 92h (Table 35).
    ReadDbError {
        /// ERROR.
        error: u8,
    },
    /// 50h in PHY mode (Table 37).
    PhyDataIndication(PhyDataIndication),
    /// 50h in MAC mode (Table 38).
    MacDataIndication(MacData),
    /// 51h in PHY mode (Table 40); the chip takes exactly 38 bytes and
    /// answers LM_SE to any other length.
    PhyDataRequest {
        /// P_SDU.
        p_sdu: Vec<u8>,
    },
    /// 51h in MAC mode (Table 41).
    MacDataRequest(MacData),
    /// 52h (Table 43); the code's name depends on the layer.
    DataConfirm {
        /// CONFIRM_CODE.
        confirm_code: u8,
    },
    /// 88h, no data (5.3.15).
    AlarmRequest,
    /// 89h (Table 48).
    AlarmConfirm {
        /// CONFIRM_CODE.
        confirm_code: u8,
    },
    /// 8Ah (Table 45): short (CNT) or long (CNT, S0..N1, PAD).
    AlarmIndication {
        /// CNT: alarms received.
        cnt: u32,
        /// The long form's estimations and PAD byte.
        long: Option<(SignalNoise, u8)>,
    },
    /// A0h (Table 50).
    SpyNoSubframeIndication {
        /// S0..N1.
        sn: SignalNoise,
        /// The 58 padding bytes, kept as received.
        pad: Vec<u8>,
    },
    /// B0h (Table 52).
    SpySubframeIndication(SpySubframe),
    /// C0h, no data (5.3.19).
    SpySearchSynchroIndication,
    /// D0h (Table 55).
    SpySynchroFoundIndication {
        /// S0..N1.
        sn: SignalNoise,
        /// ASK0, ASK1, FSK.
        demodulation: Demodulation,
        /// PGA gain code.
        pga: u8,
    },
    /// E0h (Table 57).
    SpyNoAlarmIndication(SpyAlarm),
    /// F0h (Table 59).
    SpyAlarmIndication(SpyAlarm),
    /// 61h (Table 61).
    RcRequest {
        /// TX_POS.
        tx_pos: u16,
        /// RC_THRESHOLD, 100·dBµV.
        rc_threshold: u16,
    },
    /// 62h (Table 63).
    RcConfirm {
        /// RESULT ([`f::RC_RESULTS`]).
        result: u8,
        /// REPEATER STATE ([`f::REPEATER_STATES`]).
        repeater_state: u8,
        /// What a Server heard, with LP_OK.
        heard: Option<RcHeard>,
    },
    /// 15h (Table 65).
    IsIndication {
        /// IS_STATUS ([`f::IS_STATUSES`]).
        is_status: u8,
        /// With LM_LOCKED: the best initiator.
        locked: Option<IsLocked>,
    },
    /// 20h (Table 67); ERROR is 01h.
    SyntaxError {
        /// ERROR.
        error: u8,
    },
    /// A code Table 15 does not define, kept whole.
    Unknown {
        /// The code.
        code: u8,
        /// The data field.
        data: Vec<u8>,
    },
}

/// Why a frame's data field does not fit its command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParseError {
    /// The command code.
    pub code: u8,
    /// The lengths the command takes (for two forms, both).
    pub expected: &'static [usize],
    /// Smallest length when the command takes a range (else 0).
    pub min: usize,
    /// The data length received.
    pub got: usize,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = c::name(self.code).unwrap_or("command");
        match self.expected {
            [] => write!(
                f,
                "{name} carries at least {} data bytes, not {}",
                self.min, self.got
            ),
            [n] => write!(f, "{name} carries {n} data bytes, not {}", self.got),
            [a, b] => write!(f, "{name} carries {a} or {b} data bytes, not {}", self.got),
            // `[a, b, c]` written out: a slice's Debug is the console's
            // only use of core's list formatting.
            more => {
                write!(f, "{name} carries one of [")?;
                for (i, n) in more.iter().enumerate() {
                    write!(f, "{}{n}", if i == 0 { "" } else { ", " })?;
                }
                write!(f, "] data bytes, not {}", self.got)
            }
        }
    }
}

fn exact(code: u8, data: &[u8], n: &'static [usize]) -> Result<usize, ParseError> {
    if n.contains(&data.len()) {
        Ok(data.len())
    } else {
        Err(ParseError {
            code,
            expected: n,
            min: 0,
            got: data.len(),
        })
    }
}

fn at_least(code: u8, data: &[u8], min: usize) -> Result<(), ParseError> {
    if data.len() >= min {
        Ok(())
    } else {
        Err(ParseError {
            code,
            expected: &[],
            min,
            got: data.len(),
        })
    }
}

fn one(code: u8, data: &[u8]) -> Result<u8, ParseError> {
    exact(code, data, &[1])?;
    Ok(data[0])
}

fn le16(data: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([data[at], data[at + 1]])
}

fn le24(data: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([data[at], data[at + 1], data[at + 2], 0])
}

fn sync_estimate(data: &[u8], at: usize) -> SyncEstimate {
    SyncEstimate {
        sn: SignalNoise::read(data, at),
        pga: data[at + 12],
        phase: data[at + 13],
    }
}

fn p_sdu(data: &[u8], at: usize) -> [u8; f::P_SDU_LEN] {
    let mut p = [0u8; f::P_SDU_LEN];
    p.copy_from_slice(&data[at..at + f::P_SDU_LEN]);
    p
}

fn spy_alarm(code: u8, data: &[u8]) -> Result<SpyAlarm, ParseError> {
    exact(code, data, &[spy_alarm::LEN])?;
    let mut pad = [0u8; 7];
    pad.copy_from_slice(&data[12..19]);
    Ok(SpyAlarm {
        sn: SignalNoise::read(data, 0),
        pad,
        alarm: get(&spy_alarm::LAYOUT[5], data),
    })
}

fn mac_synchro(code: u8, data: &[u8]) -> Result<MacSync, ParseError> {
    at_least(code, data, 1)?;
    const FOUND: &[usize] = &[mac_sync::FOUND_LEN];
    const SHORT: &[usize] = &[mac_sync::SHORT_LEN];
    Ok(match data[0] {
        1 => {
            exact(code, data, FOUND)?;
            MacSync::Found(sync_estimate(data, 1))
        }
        2 => {
            exact(code, data, SHORT)?;
            MacSync::Confirmed {
                pad: data[1],
                sa: le16(data, 2),
                da: le16(data, 4),
            }
        }
        4 => {
            exact(code, data, SHORT)?;
            MacSync::Lost {
                cause: data[1],
                add1: le16(data, 2),
                add2: le16(data, 4),
            }
        }
        5 => {
            exact(code, data, SHORT)?;
            MacSync::Intelligent {
                cause: data[1],
                add: le16(data, 2),
                s: le16(data, 4),
            }
        }
        sync => MacSync::Other {
            sync,
            data: data[1..].to_vec(),
        },
    })
}

impl Command {
    /// Reads a command from a frame's code and data field, in the layout
    /// of `layer` (10h, 50h and 51h differ between PHY and MAC mode; the
    /// other codes have one layout). 85h is told apart by its length (the
    /// request has no data), 21h has one layout both ways.
    pub fn parse(code: u8, data: &[u8], layer: Layer) -> Result<Command, ParseError> {
        use Command::*;
        Ok(match code {
            c::CMD_SYNCHRO_INDICATION => match layer {
                Layer::Phy => {
                    exact(code, data, &[14])?;
                    PhySynchroIndication(sync_estimate(data, 0))
                }
                Layer::Mac => MacSynchroIndication(mac_synchro(code, data)?),
            },
            c::CMD_DESYNCHRO_REQUEST => DesynchroRequest {
                reset: one(code, data)?,
            },
            c::CMD_SYNCHRO_STATUS => match exact(code, data, &[0, 1])? {
                0 => SynchroStatusRequest,
                _ => SynchroStatus { status: data[0] },
            },
            c::CMD_RESET_REQUEST => ResetRequest {
                reset: one(code, data)?,
            },
            c::CMD_WRITE_DB_REQUEST | c::CMD_WRITE_DB_CONFIRM | c::CMD_READ_DB_CONFIRM => {
                at_least(code, data, 2)?;
                let (index, data) = (le16(data, 0), data[2..].to_vec());
                match code {
                    c::CMD_WRITE_DB_REQUEST => WriteDbRequest { index, data },
                    c::CMD_WRITE_DB_CONFIRM => WriteDbConfirm { index, data },
                    _ => ReadDbConfirm { index, data },
                }
            }
            c::CMD_READ_DB_REQUEST => {
                exact(code, data, &[2])?;
                ReadDbRequest {
                    index: le16(data, 0),
                }
            }
            c::CMD_WRITE_DB_ERROR => WriteDbError {
                error: one(code, data)?,
            },
            c::CMD_READ_DB_ERROR => ReadDbError {
                error: one(code, data)?,
            },
            c::CMD_DATA_INDICATION => match layer {
                Layer::Phy => {
                    exact(code, data, &[f::PHY_DATA_INDICATION_LEN])?;
                    PhyDataIndication(super::types::PhyDataIndication {
                        p_sdu: p_sdu(data, 0),
                        demodulation: Demodulation::read(data, 38),
                        snr0: le24(data, 44),
                        snr1: le24(data, 47),
                    })
                }
                Layer::Mac => {
                    at_least(code, data, f::mac_data::HEADER_LEN)?;
                    MacDataIndication(MacData::read(data))
                }
            },
            c::CMD_DATA_REQUEST => match layer {
                Layer::Phy => PhyDataRequest {
                    p_sdu: data.to_vec(),
                },
                Layer::Mac => {
                    at_least(code, data, f::mac_data::HEADER_LEN)?;
                    MacDataRequest(MacData::read(data))
                }
            },
            c::CMD_DATA_CONFIRM => DataConfirm {
                confirm_code: one(code, data)?,
            },
            c::CMD_ALARM_REQUEST => exact(code, data, &[0]).map(|_| AlarmRequest)?,
            c::CMD_ALARM_CONFIRM => AlarmConfirm {
                confirm_code: one(code, data)?,
            },
            c::CMD_ALARM_INDICATION => {
                const FORMS: &[usize] = &[alarm_indication::SHORT_LEN, alarm_indication::LONG_LEN];
                let n = exact(code, data, FORMS)?;
                AlarmIndication {
                    cnt: u32::from_le_bytes([data[0], data[1], data[2], data[3]]),
                    long: (n == alarm_indication::LONG_LEN)
                        .then(|| (SignalNoise::read(data, 4), data[16])),
                }
            }
            c::SPY_NO_SUBFRAME_INDICATION => {
                exact(code, data, &[f::SPY_NO_SUBFRAME_LEN])?;
                SpyNoSubframeIndication {
                    sn: SignalNoise::read(data, 0),
                    pad: data[signal_noise_len()..].to_vec(),
                }
            }
            c::SPY_SUBFRAME_INDICATION => {
                exact(code, data, &[f::SPY_SUBFRAME_LEN])?;
                SpySubframeIndication(SpySubframe {
                    sn: SignalNoise::read(data, 0),
                    demodulation: Demodulation::read(data, 12),
                    pga: data[18],
                    p_sdu: p_sdu(data, 19),
                    snr0: le24(data, 57),
                    snr1: le24(data, 60),
                })
            }
            c::SPY_SEARCH_SYNCHRO_INDICATION => {
                exact(code, data, &[0]).map(|_| SpySearchSynchroIndication)?
            }
            c::SPY_SYNCHRO_FOUND_INDICATION => {
                exact(code, data, &[f::SPY_SYNCHRO_FOUND_LEN])?;
                SpySynchroFoundIndication {
                    sn: SignalNoise::read(data, 0),
                    demodulation: Demodulation::read(data, 12),
                    pga: data[18],
                }
            }
            c::SPY_NO_ALARM_INDICATION => SpyNoAlarmIndication(spy_alarm(code, data)?),
            c::SPY_ALARM_INDICATION => SpyAlarmIndication(spy_alarm(code, data)?),
            c::CMD_RC_REQUEST => {
                exact(code, data, &[4])?;
                RcRequest {
                    tx_pos: le16(data, 0),
                    rc_threshold: le16(data, 2),
                }
            }
            c::CMD_RC_CONFIRM => {
                const FORMS: &[usize] = &[rc_confirm::SHORT_LEN, rc_confirm::LONG_LEN];
                let n = exact(code, data, FORMS)?;
                RcConfirm {
                    result: data[0],
                    repeater_state: data[1],
                    heard: (n == rc_confirm::LONG_LEN).then(|| RcHeard {
                        s: le24(data, 2),
                        n: le24(data, 5),
                        rx_pos: le16(data, 8),
                    }),
                }
            }
            c::CMD_IS_INDICATION => {
                const FORMS: &[usize] = &[1, is_indication::LONG_LEN];
                let n = exact(code, data, FORMS)?;
                IsIndication {
                    is_status: data[0],
                    locked: (n == is_indication::LONG_LEN).then(|| IsLocked {
                        add: le16(data, 1),
                        s: le16(data, 3),
                    }),
                }
            }
            c::CMD_SYNTAX_ERROR => SyntaxError {
                error: one(code, data)?,
            },
            _ => Unknown {
                code,
                data: data.to_vec(),
            },
        })
    }

    /// Reads the command of a local frame.
    pub fn from_frame(frame: &LocalFrame, layer: Layer) -> Result<Command, ParseError> {
        Command::parse(frame.code, &frame.data, layer)
    }

    /// The command code.
    pub fn code(&self) -> u8 {
        use Command::*;
        match self {
            PhySynchroIndication(_) | MacSynchroIndication(_) => c::CMD_SYNCHRO_INDICATION,
            DesynchroRequest { .. } => c::CMD_DESYNCHRO_REQUEST,
            SynchroStatusRequest | SynchroStatus { .. } => c::CMD_SYNCHRO_STATUS,
            ResetRequest { .. } => c::CMD_RESET_REQUEST,
            WriteDbRequest { .. } => c::CMD_WRITE_DB_REQUEST,
            WriteDbConfirm { .. } => c::CMD_WRITE_DB_CONFIRM,
            WriteDbError { .. } => c::CMD_WRITE_DB_ERROR,
            ReadDbRequest { .. } => c::CMD_READ_DB_REQUEST,
            ReadDbConfirm { .. } => c::CMD_READ_DB_CONFIRM,
            ReadDbError { .. } => c::CMD_READ_DB_ERROR,
            PhyDataIndication(_) | MacDataIndication(_) => c::CMD_DATA_INDICATION,
            PhyDataRequest { .. } | MacDataRequest(_) => c::CMD_DATA_REQUEST,
            DataConfirm { .. } => c::CMD_DATA_CONFIRM,
            AlarmRequest => c::CMD_ALARM_REQUEST,
            AlarmConfirm { .. } => c::CMD_ALARM_CONFIRM,
            AlarmIndication { .. } => c::CMD_ALARM_INDICATION,
            SpyNoSubframeIndication { .. } => c::SPY_NO_SUBFRAME_INDICATION,
            SpySubframeIndication(_) => c::SPY_SUBFRAME_INDICATION,
            SpySearchSynchroIndication => c::SPY_SEARCH_SYNCHRO_INDICATION,
            SpySynchroFoundIndication { .. } => c::SPY_SYNCHRO_FOUND_INDICATION,
            SpyNoAlarmIndication(_) => c::SPY_NO_ALARM_INDICATION,
            SpyAlarmIndication(_) => c::SPY_ALARM_INDICATION,
            RcRequest { .. } => c::CMD_RC_REQUEST,
            RcConfirm { .. } => c::CMD_RC_CONFIRM,
            IsIndication { .. } => c::CMD_IS_INDICATION,
            SyntaxError { .. } => c::CMD_SYNTAX_ERROR,
            Unknown { code, .. } => *code,
        }
    }

    /// The access layer whose layout this value has, `None` for the
    /// commands whose layout is the same in both.
    pub fn layer(&self) -> Option<Layer> {
        use Command::*;
        match self {
            PhySynchroIndication(_) | PhyDataIndication(_) | PhyDataRequest { .. } => {
                Some(Layer::Phy)
            }
            MacSynchroIndication(_) | MacDataIndication(_) | MacDataRequest(_) => Some(Layer::Mac),
            _ => None,
        }
    }

    /// The manual's name, `None` for an unknown code.
    pub fn name(&self) -> Option<&'static str> {
        c::name(self.code())
    }
}

fn signal_noise_len() -> usize {
    f::signal_noise::LEN
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::format;
    use alloc::string::ToString;

    #[test]
    fn a_length_refused_names_the_lengths_the_command_takes() {
        let e = |expected: &'static [usize], min| ParseError {
            code: c::CMD_ALARM_INDICATION,
            expected,
            min,
            got: 3,
        };
        let name = c::name(c::CMD_ALARM_INDICATION).unwrap();
        assert_eq!(
            e(&[], 5).to_string(),
            format!("{name} carries at least 5 data bytes, not 3")
        );
        assert_eq!(
            e(&[4], 0).to_string(),
            format!("{name} carries 4 data bytes, not 3")
        );
        assert_eq!(
            e(&[4, 17], 0).to_string(),
            format!("{name} carries 4 or 17 data bytes, not 3")
        );
        assert_eq!(
            e(&[1, 4, 17], 0).to_string(),
            format!("{name} carries one of [1, 4, 17] data bytes, not 3")
        );
    }
}
