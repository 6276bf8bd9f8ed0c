//! The street-light controller board's application layer
//! (STEVAL-IHP007V1 user manual, seed 004): what the console, `plm board`
//! and the simulated boards say to each other.
//!
//! - [`frame`]: application frames on the board's USART, addresses,
//!   frame types; [`crc`]: their CRC-16.
//! - [`message`]: a frame's payload typed ([`Message`]) and the answer a
//!   request waits for; [`service`] and [`hid`]: the one description of
//!   every service command and HID ballast parameter; [`error`]: error
//!   codes in words.
//! - [`line`]: how a frame travels over the power line in a DL frame.
//! - [`usart`]: the USART stream decoder; [`requester`]: requests and
//!   answers, timeouts and retries; [`concentrator`]: both over a board's
//!   USART or a bare ST7580; [`discovery`]: finding the boards on a line;
//!   [`read_all`]: reading many boards in slots; [`job`]: any of these
//!   run on a concentrator by one loop; [`street`]: the street
//!   orchestrated (discovery, the sweep, dimming, the update campaign,
//!   the fleet and its alerts).
//! - [`energy`]: a lamp's energy estimated from its power readings.
//! - [`rfu`]: remote firmware update, the layouts of its commands;
//!   [`update`]: the engine that updates one board or a street.
//!
//! Decisions where the seed is silent are in docs/protocol-notes.md
//! ("STEVAL-IHP007V1 application layer").

pub mod concentrator;
pub mod crc;
pub mod discovery;
pub mod energy;
pub mod error;
pub mod frame;
pub mod hid;
pub mod job;
pub mod line;
pub mod message;
pub mod read_all;
mod release;
pub mod requester;
pub mod rfu;
pub mod service;
pub mod street;
pub mod sweep;
pub mod update;
pub mod usart;

pub use concentrator::{Carrier, Concentrator, Happening};
pub use discovery::Discovery;
pub use error::ErrorCode;
pub use frame::{Address, AppFrame, FrameError, FrameType};
pub use hid::{Ballast, Hid, LampState};
pub use job::{Job, Run};
pub use line::LineFrame;
pub use message::{Expect, Message, MessageError};
pub use release::Release;
pub use requester::{AppEvent, Request, RequestId, Requester, RequesterConfig};
pub use service::{Clock, Discovered, Service};
pub use usart::{UsartDecoder, UsartElement};
