//! The views: small components, one concern each. They read the stores
//! of [`crate::stores::Console`] and send requests through it; none of
//! them parses a byte (plm-core does).

pub mod connection_bar;
pub mod data;
pub mod diagnostics;
pub mod files;
pub mod lamp;
pub mod modem;
pub mod network;
pub mod plot;
pub mod serial_port;
pub mod sfsk_data;
pub mod sfsk_setup;
pub mod simulator;
pub mod snr_plot;
pub mod street;
pub mod traffic;
pub mod update;
pub mod widgets;

pub use crate::numbers::{decimal, fixed, millis, seconds, spaced};
