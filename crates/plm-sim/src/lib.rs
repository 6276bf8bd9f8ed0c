//! Simulated ST7580 power line modems on a simulated power line.
//!
//! The simulated modem behaves like the chip of UM0932 at the byte level:
//! its host interface is plm-core's device link engine, its commands and
//! MIB are plm-core's codecs and validation, its power line frames are
//! plm-core's PHY/DL/SS codec. What is simulated here is only what lies
//! around them: the modem's state (MIB, counters, status bits, reset), the
//! UART at byte level with faults, and the power line (airtime, hearing,
//! SNR, losses, the mains zero crossing).
//!
//! Everything is deterministic: one seeded RNG and virtual time in
//! microseconds. Tests run it as fast as they like; the console and
//! `plm sim` drive it in real time with [`Sim::advance_to`].
//!
//! - [`sim`]: the world and its event queue; node 0's host is outside.
//! - [`modem`]: the ST7580 model.
//! - [`line`]: the power line.
//! - [`uart`]: a UART direction with fault injection.
//! - [`echo`]: the echoing host of simulated peers.
//! - [`ballast`]: the HID ballast of a board and its lamp model;
//!   [`profile`]: how a street's lamps differ.
//! - [`board`]: the street-light controller board (STEVAL-IHP007V1) whose
//!   firmware drives its modem, and a concentrator board's USART;
//!   [`breach`]: one that breaks a rule of the board protocol, on demand.
//! - [`drive`]: plm-core's host engine driving node 0 in virtual time.
//! - [`ports`]: the served nodes' UARTs, as `plm sim` reaches them.
//! - [`street`]: plm-core's concentrator driving a street in virtual time.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod ballast;
pub mod board;
pub mod breach;
pub mod drive;
pub mod echo;
pub mod flash;
pub mod line;
pub mod modem;
pub mod ports;
pub mod profile;
pub mod rfu;
pub mod rng;
pub mod sim;
pub mod st7570;
pub mod street;
pub mod uart;

pub use drive::{HostDriver, Outcome, UsbUart};
pub use line::LineConfig;
pub use ports::Ports;
pub use profile::StreetProfile;
pub use sim::{Attach, Dir, Fault, LineEvent, Peers, Sim, SimConfig};
pub use street::StreetDriver;
pub use uart::{ByteFaults, BAUD_RATES};
