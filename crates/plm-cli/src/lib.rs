//! The library half of `plm`: what the subcommands are made of, so that it
//! can be unit-tested on its own.
//!
//! - [`rfc2217`]: the Telnet COM-PORT-OPTION server as a pure state machine.
//! - [`sim_server`]: `plm sim`, the simulated modem behind an RFC 2217 port.

pub mod rfc2217;
pub mod sim_server;
