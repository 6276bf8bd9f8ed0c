//! The protocol core of PLM Console.
//!
//! `no_std` + `alloc`, no I/O and no clock: everything that knows a byte of
//! the ST power line modems' host interfaces lives here, once, and the
//! console, the simulator and the `plm` tool all call it.
//!
//! - [`app`]: the street-light controller board's application layer
//!   (STEVAL-IHP007V1): frames, service and HID commands, the concentrator.
//! - [`link`]: local frames, checksum, ACK/NAK, status messages, the stream
//!   decoder and the sans-IO host and device link engines (UM0932 3.2).
//! - [`st7580`]: every ST7580 command (UM0932 3.3) and MIB object (UM0932 4).
//! - [`st7570`]: every ST7570 command (ST7570 UM 5.3) in PHY and MAC mode,
//!   its status message (Table 11) and MIB objects (ST7570 UM 6).
//! - [`chip`]: one chip's host interface as a host program needs it (MIB
//!   requests, which answer closes which request, the decoder), for both.
//! - [`field`]: the declarative field layouts that both the typed codecs and
//!   the generic decoder/forms read, so a bit position is written once.
//! - [`mib`]: the declarative MIB description (objects, access, defaults).
//! - [`decode`]: the named-field view of a stream element that `plm decode`
//!   prints and the console's traffic inspector shows.
//! - [`decode::app`]: the same view of the controller board's application
//!   frames, on its USART and on the power line.
//! - [`file`]: the size cap and the text check of every file read.
//! - [`json`]: the JSON values, writer and parser those views and the
//!   console's files use (byte for byte what serde_json writes).
//!
//! Feature `serde` (default): `Serialize` for the decoded views, for
//! native tools that write with serde_json. The console turns it off:
//! its size budget has no room for serde's code.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

extern crate alloc;
#[cfg(test)]
extern crate std;

/// How the `crc` crate computes the checksums of this crate: with its
/// 256-entry table natively, bit by bit in the browser, where the tables
/// (five algorithms, 3.3 KB that gzip cannot shrink) count against the
/// console's size budget and every checksummed frame is short.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) type CrcImpl = crc::Table<1>;
#[cfg(target_arch = "wasm32")]
pub(crate) type CrcImpl = crc::NoTable;

pub mod app;
pub mod chip;
pub mod decode;
pub mod drive;
pub mod field;
mod field_json;
pub mod file;
pub mod hex;
pub mod json;
pub mod link;
pub mod mib;
pub mod st7570;
pub mod st7580;
pub mod time;
