//! What both chips' host interfaces share (UM0932 3.2, ST7570 UM 5.2):
//! local frames and their checksum, ACK/NAK, status messages, the stream
//! decoder, and the sans-IO link engines.

mod dialect;
mod element;
mod frame;
mod stream;

pub mod device;
pub mod host;
mod rx;
mod timeouts;

pub use dialect::{Answer, Dialect, Reaction};

/// Baud rates of the host UART, chosen by the BR1/BR0 pins at reset: the
/// same four on both chips (UM0932 Table 5, ST7570 UM Table 9).
pub const BAUD_RATES: [u32; 4] = [9_600, 19_200, 38_400, 57_600];
pub use element::{Element, GarbageReason, Source, StatusMessage};
pub use frame::{checksum, EmitError, Frame, FrameError, LocalFrame, Stx};
pub use stream::StreamDecoder;
pub use timeouts::{TicSelector, Timeouts};

/// Acknowledgement character (UM0932 Table 7).
pub const ACK: u8 = 0x06;
/// Not-acknowledgement character (UM0932 Table 7).
pub const NAK: u8 = 0x15;
/// First byte of every status message: `?` (UM0932 3.2.4).
pub const STATUS_FIRST: u8 = 0x3F;
