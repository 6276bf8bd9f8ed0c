//! The library half of `plm`: what the subcommands are made of, so that it
//! can be unit-tested on its own.
//!
//! - [`rfc2217`]: the Telnet COM-PORT-OPTION server as a pure state
//!   machine, and its client.
//! - [`sim_server`]: `plm sim`, the simulated modem behind an RFC 2217 port.
//! - [`port`]: a serial device or an RFC 2217 port behind one trait.
//! - [`board`]: `plm board`, boards driven through a port on the wall clock.

pub mod board;
pub mod port;
pub mod rfc2217;
pub mod sim_server;
