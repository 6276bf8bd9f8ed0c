//! The ST7580 host interface: every command of UM0932 3.3 and every MIB
//! object of UM0932 4, typed, with parse, emit and the chip's validation,
//! and the power line frames of UM0932 2.2-2.4 ([`plc`]).

pub mod code;
mod command;
pub mod fields;
pub mod mib;
pub mod plc;
mod types;
pub mod validate;

pub use command::{Command, ParseError};
pub use types::{
    ActiveLayer, Channel, DataConfirm, DataIndication, DataRequest, ErrorCause, FrequencySet,
    IndicationInfo, Modulation, ResetCause, ResetData, SsDataRequest, Status, Temperature,
    TxParams,
};
