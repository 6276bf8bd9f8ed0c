//! Every ST7580 command (UM0932 3.3) as a typed value with parse and emit.

use super::code as c;
use super::fields::{confirm_data, indication_data, tx_options};
use super::types::{
    DataConfirm, DataIndication, DataRequest, ErrorCause, IndicationInfo, ResetData, SsDataRequest,
    TxParams,
};
use crate::link::LocalFrame;
use alloc::vec::Vec;
use core::fmt;

/// A command of UM0932 Tables 10-15, or an unknown code kept whole.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Command {
    /// 3Ch (3.3.1).
    BioResetRequest,
    /// 3Dh (3.3.2); ConfirmData is always 00h.
    BioResetConfirm {
        /// ConfirmData.
        confirm_data: u8,
    },
    /// 3Fh.
    BioResetError(ErrorCause),
    /// 3Eh (3.3.3).
    BioResetIndication(ResetData),
    /// 08h (3.3.4).
    MibWriteRequest {
        /// MIB object index.
        index: u8,
        /// The object's new value.
        data: Vec<u8>,
    },
    /// 09h (3.3.5).
    MibWriteConfirm,
    /// 0Bh.
    MibWriteError(ErrorCause),
    /// 0Ch (3.3.6).
    MibReadRequest {
        /// MIB object index.
        index: u8,
    },
    /// 0Dh (3.3.7): the object's value; its index is that of the request.
    MibReadConfirm {
        /// The object's value.
        data: Vec<u8>,
    },
    /// 0Fh.
    MibReadError(ErrorCause),
    /// 10h (3.3.8).
    MibEraseRequest {
        /// MIB object index.
        index: u8,
    },
    /// 11h (3.3.9).
    MibEraseConfirm,
    /// 13h.
    MibEraseError(ErrorCause),
    /// 2Ch (3.3.10).
    PingRequest {
        /// Any payload.
        data: Vec<u8>,
    },
    /// 2Dh (3.3.11): the request's payload back.
    PingConfirm {
        /// The payload.
        data: Vec<u8>,
    },
    /// 24h (3.3.12).
    PhyDataRequest(DataRequest),
    /// 25h (3.3.13).
    PhyDataConfirm(DataConfirm),
    /// 27h.
    PhyDataError(ErrorCause),
    /// 26h (3.3.14).
    PhyDataIndication(DataIndication),
    /// 50h (3.3.15).
    DlDataRequest(DataRequest),
    /// 51h (3.3.16).
    DlDataConfirm(DataConfirm),
    /// 53h.
    DlDataError(ErrorCause),
    /// 52h (3.3.17).
    DlDataIndication(DataIndication),
    /// 5Ah (3.3.18): payload followed by the wrong CRC.
    DlSnifferIndication(DataIndication),
    /// 54h (3.3.19).
    SsDataRequest(SsDataRequest),
    /// 55h (3.3.20).
    SsDataConfirm(DataConfirm),
    /// 57h.
    SsDataError(ErrorCause),
    /// 56h (3.3.21).
    SsDataIndication(DataIndication),
    /// 5Eh (3.3.22).
    SsSnifferIndication(DataIndication),
    /// 36h (3.3.23): the code the modem did not know.
    CmdSyntaxError {
        /// The wrong command code.
        error: u8,
    },
    /// A code UM0932 does not define, kept whole.
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
    /// Smallest data length the command takes.
    pub min: usize,
    /// Largest data length the command takes.
    pub max: usize,
    /// The data length received.
    pub got: usize,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = c::name(self.code).unwrap_or("command");
        if self.min == self.max {
            write!(
                f,
                "{name} carries {} data bytes, not {}",
                self.min, self.got
            )
        } else {
            write!(
                f,
                "{name} carries {}..={} data bytes, not {}",
                self.min, self.max, self.got
            )
        }
    }
}

fn exact(code: u8, data: &[u8], n: usize) -> Result<(), ParseError> {
    at_least(code, data, n, n)
}

fn at_least(code: u8, data: &[u8], min: usize, max: usize) -> Result<(), ParseError> {
    if data.len() < min || data.len() > max {
        return Err(ParseError {
            code,
            min,
            max,
            got: data.len(),
        });
    }
    Ok(())
}

fn one(code: u8, data: &[u8]) -> Result<u8, ParseError> {
    exact(code, data, 1)?;
    Ok(data[0])
}

fn error_cause(code: u8, data: &[u8]) -> Result<ErrorCause, ParseError> {
    one(code, data).map(ErrorCause::from_byte)
}

fn confirm(code: u8, data: &[u8]) -> Result<DataConfirm, ParseError> {
    exact(code, data, confirm_data::LEN)?;
    Ok(DataConfirm::decode(data))
}

fn indication(code: u8, data: &[u8]) -> Result<DataIndication, ParseError> {
    at_least(code, data, indication_data::LEN, 255)?;
    let (head, payload) = data.split_at(indication_data::LEN);
    Ok(DataIndication {
        info: IndicationInfo::decode(head),
        payload: payload.to_vec(),
    })
}

fn params(code: u8, data: &[u8], extra: usize) -> Result<(TxParams, usize), ParseError> {
    let short = |min| ParseError {
        code,
        min,
        max: 255,
        got: data.len(),
    };
    let Some((p, n)) = TxParams::parse(data) else {
        // UM0932 Tables 35/45: byte 0 announces 3 TX frequency bytes (bit 0)
        // and a TX gain byte (bit 3); say how many it needs in all.
        let needed = data.first().map_or(1, |b| {
            let o = [*b];
            let set = |f: &crate::field::Field| f.get(&o) == Some(1);
            1 + 3 * set(&tx_options::CUSTOM_MIB_FREQUENCY) as usize
                + set(&tx_options::GAIN_SELECTOR) as usize
        });
        return Err(short(needed + extra));
    };
    if data.len() < n + extra {
        return Err(short(n + extra));
    }
    Ok((p, n))
}

impl Command {
    /// Reads a command from a frame's code and data field.
    pub fn parse(code: u8, data: &[u8]) -> Result<Command, ParseError> {
        use Command::*;
        Ok(match code {
            c::BIO_RESET_REQUEST => exact(code, data, 0).map(|_| BioResetRequest)?,
            c::BIO_RESET_CONFIRM => BioResetConfirm {
                confirm_data: one(code, data)?,
            },
            c::BIO_RESET_ERROR => BioResetError(error_cause(code, data)?),
            c::BIO_RESET_INDICATION => BioResetIndication(ResetData::from_byte(one(code, data)?)),
            c::MIB_WRITE_REQUEST => {
                at_least(code, data, 1, 255)?;
                MibWriteRequest {
                    index: data[0],
                    data: data[1..].to_vec(),
                }
            }
            c::MIB_WRITE_CONFIRM => exact(code, data, 0).map(|_| MibWriteConfirm)?,
            c::MIB_WRITE_ERROR => MibWriteError(error_cause(code, data)?),
            c::MIB_READ_REQUEST => MibReadRequest {
                index: one(code, data)?,
            },
            c::MIB_READ_CONFIRM => MibReadConfirm {
                data: data.to_vec(),
            },
            c::MIB_READ_ERROR => MibReadError(error_cause(code, data)?),
            c::MIB_ERASE_REQUEST => MibEraseRequest {
                index: one(code, data)?,
            },
            c::MIB_ERASE_CONFIRM => exact(code, data, 0).map(|_| MibEraseConfirm)?,
            c::MIB_ERASE_ERROR => MibEraseError(error_cause(code, data)?),
            c::PING_REQUEST => PingRequest {
                data: data.to_vec(),
            },
            c::PING_CONFIRM => PingConfirm {
                data: data.to_vec(),
            },
            c::PHY_DATA_REQUEST | c::DL_DATA_REQUEST => {
                let (params, n) = params(code, data, 0)?;
                let r = DataRequest {
                    params,
                    payload: data[n..].to_vec(),
                };
                if code == c::PHY_DATA_REQUEST {
                    PhyDataRequest(r)
                } else {
                    DlDataRequest(r)
                }
            }
            c::SS_DATA_REQUEST => {
                let (params, n) = params(code, data, 1)?;
                SsDataRequest(super::types::SsDataRequest {
                    params,
                    header_length: data[n],
                    header_and_payload: data[n + 1..].to_vec(),
                })
            }
            c::PHY_DATA_CONFIRM => PhyDataConfirm(confirm(code, data)?),
            c::DL_DATA_CONFIRM => DlDataConfirm(confirm(code, data)?),
            c::SS_DATA_CONFIRM => SsDataConfirm(confirm(code, data)?),
            c::PHY_DATA_ERROR => PhyDataError(error_cause(code, data)?),
            c::DL_DATA_ERROR => DlDataError(error_cause(code, data)?),
            c::SS_DATA_ERROR => SsDataError(error_cause(code, data)?),
            c::PHY_DATA_INDICATION => PhyDataIndication(indication(code, data)?),
            c::DL_DATA_INDICATION => DlDataIndication(indication(code, data)?),
            c::DL_SNIFFER_INDICATION => DlSnifferIndication(indication(code, data)?),
            c::SS_DATA_INDICATION => SsDataIndication(indication(code, data)?),
            c::SS_SNIFFER_INDICATION => SsSnifferIndication(indication(code, data)?),
            c::CMD_SYNTAX_ERROR => CmdSyntaxError {
                error: one(code, data)?,
            },
            _ => Unknown {
                code,
                data: data.to_vec(),
            },
        })
    }

    /// Reads the command of a local frame.
    pub fn from_frame(frame: &LocalFrame) -> Result<Command, ParseError> {
        Command::parse(frame.code, &frame.data)
    }

    /// The command code.
    pub fn code(&self) -> u8 {
        use Command::*;
        match self {
            BioResetRequest => c::BIO_RESET_REQUEST,
            BioResetConfirm { .. } => c::BIO_RESET_CONFIRM,
            BioResetError(_) => c::BIO_RESET_ERROR,
            BioResetIndication(_) => c::BIO_RESET_INDICATION,
            MibWriteRequest { .. } => c::MIB_WRITE_REQUEST,
            MibWriteConfirm => c::MIB_WRITE_CONFIRM,
            MibWriteError(_) => c::MIB_WRITE_ERROR,
            MibReadRequest { .. } => c::MIB_READ_REQUEST,
            MibReadConfirm { .. } => c::MIB_READ_CONFIRM,
            MibReadError(_) => c::MIB_READ_ERROR,
            MibEraseRequest { .. } => c::MIB_ERASE_REQUEST,
            MibEraseConfirm => c::MIB_ERASE_CONFIRM,
            MibEraseError(_) => c::MIB_ERASE_ERROR,
            PingRequest { .. } => c::PING_REQUEST,
            PingConfirm { .. } => c::PING_CONFIRM,
            PhyDataRequest(_) => c::PHY_DATA_REQUEST,
            PhyDataConfirm(_) => c::PHY_DATA_CONFIRM,
            PhyDataError(_) => c::PHY_DATA_ERROR,
            PhyDataIndication(_) => c::PHY_DATA_INDICATION,
            DlDataRequest(_) => c::DL_DATA_REQUEST,
            DlDataConfirm(_) => c::DL_DATA_CONFIRM,
            DlDataError(_) => c::DL_DATA_ERROR,
            DlDataIndication(_) => c::DL_DATA_INDICATION,
            DlSnifferIndication(_) => c::DL_SNIFFER_INDICATION,
            SsDataRequest(_) => c::SS_DATA_REQUEST,
            SsDataConfirm(_) => c::SS_DATA_CONFIRM,
            SsDataError(_) => c::SS_DATA_ERROR,
            SsDataIndication(_) => c::SS_DATA_INDICATION,
            SsSnifferIndication(_) => c::SS_SNIFFER_INDICATION,
            CmdSyntaxError { .. } => c::CMD_SYNTAX_ERROR,
            Unknown { code, .. } => *code,
        }
    }

    /// The data field.
    pub fn data(&self) -> Vec<u8> {
        use Command::*;
        let mut out = Vec::new();
        match self {
            BioResetRequest | MibWriteConfirm | MibEraseConfirm => {}
            BioResetConfirm { confirm_data } => out.push(*confirm_data),
            BioResetIndication(r) => out.push(r.byte()),
            BioResetError(e) | MibWriteError(e) | MibReadError(e) | MibEraseError(e)
            | PhyDataError(e) | DlDataError(e) | SsDataError(e) => out.push(e.byte()),
            MibWriteRequest { index, data } => {
                out.push(*index);
                out.extend_from_slice(data);
            }
            MibReadRequest { index } | MibEraseRequest { index } => out.push(*index),
            MibReadConfirm { data }
            | PingRequest { data }
            | PingConfirm { data }
            | Unknown { data, .. } => out.extend_from_slice(data),
            PhyDataRequest(r) | DlDataRequest(r) => {
                r.params.emit(&mut out);
                out.extend_from_slice(&r.payload);
            }
            SsDataRequest(r) => {
                r.params.emit(&mut out);
                out.push(r.header_length);
                out.extend_from_slice(&r.header_and_payload);
            }
            PhyDataConfirm(cf) | DlDataConfirm(cf) | SsDataConfirm(cf) => out = cf.encode(),
            PhyDataIndication(i)
            | DlDataIndication(i)
            | DlSnifferIndication(i)
            | SsDataIndication(i)
            | SsSnifferIndication(i) => {
                out = i.info.encode();
                out.extend_from_slice(&i.payload);
            }
            CmdSyntaxError { error } => out.push(*error),
        }
        out
    }

    /// The command as a local frame (STX 02h).
    pub fn to_frame(&self) -> LocalFrame {
        LocalFrame::new(self.code(), self.data())
    }

    /// The manual's name, `None` for an unknown code.
    pub fn name(&self) -> Option<&'static str> {
        c::name(self.code())
    }
}
