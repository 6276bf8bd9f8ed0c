//! The ST7570 host interface (ST7570 UM, seed `003_2edea85fed0bdf2a`):
//! every command of Table 15 in both access layers, the 4-byte status
//! message of Table 11, and every MIB object of Table 71 with the checks
//! the chip applies (6.3), typed, with parse and emit. Every layout is a
//! list of [`crate::field::Field`]s in [`fields`], [`status`] and [`mib`],
//! read by the typed codecs, the decoder, console forms and the simulator.
//! [`mac`] and [`phy_frame`] are the IEC 61334-5-1 frames on the line
//! itself (4.4, 3.2), for the simulated line and for line captures.

pub mod code;
mod command;
mod emit;
pub mod fields;
mod layout;
pub mod mac;
pub mod mib;
pub mod phy_frame;
pub mod status;
mod types;
pub mod validate;

pub use command::{Command, MacSync, ParseError};
pub use layout::{describe, layout};
pub use status::Status;
pub use types::{
    Address, Credit, Demodulation, Group, IsLocked, Layer, MacData, PhyDataIndication, RcHeard,
    SignalNoise, SpyAlarm, SpySubframe, SyncEstimate,
};
