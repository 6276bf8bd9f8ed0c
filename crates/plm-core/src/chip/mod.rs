//! What a host program needs to know of a chip's host interface, once per
//! chip: its link dialect, the request frames of the operations every
//! console offers (MIB read, write and erase, reset), which answer closes
//! which request, what an answer says, and the decoder of its traffic.
//!
//! The console's session, traffic inspector, MIB forms and profile files
//! work through [`Chip`] alone; only views of what one chip has and the
//! other has not (the ST7580's data services, the ST7570's network) name
//! the chip's own commands.

mod st7580;
pub use self::st7580::{refusal as st7580_refusal, St7580};
#[cfg(feature = "st7570")]
mod st7570;
#[cfg(feature = "st7570")]
pub use self::st7570::St7570;

use crate::decode::Decoded;
use crate::link::{Dialect, Element, LocalFrame, Source, Timeouts};
use crate::mib::Object;
use crate::time::Duration;
use alloc::boxed::Box;
use alloc::string::String;
use alloc::vec::Vec;

/// One chip's host interface, with the context its frames need that a
/// single frame lacks (the ST7570's access layer): one per connection.
pub trait Chip {
    /// The chip's name, `ST7580`.
    fn name(&self) -> &'static str;
    /// Its link dialect.
    fn dialect(&self) -> Dialect;
    /// Its MIB objects (the declarative MIB).
    fn mib(&self) -> &'static [Object];
    /// Whether the modem has `object` as it is configured now (the ST7570
    /// knows some objects only in one access layer, 6.5).
    fn has(&self, object: &Object) -> bool {
        let _ = object;
        true
    }
    /// The request that reads MIB object `index`.
    fn mib_read(&self, index: u16) -> LocalFrame;
    /// The request that writes `data` to MIB object `index`.
    fn mib_write(&self, index: u16, data: &[u8]) -> LocalFrame;
    /// The request that erases MIB object `index`, if the chip has one.
    fn mib_erase(&self, index: u16) -> Option<LocalFrame>;
    /// The software reset request (the configuration kept).
    fn reset(&self) -> LocalFrame;
    /// Whether the modem answers `request` at all (else the request is
    /// done once the modem acknowledged it).
    fn expects_answer(&self, request: u8) -> bool;
    /// Whether a frame with code `answer` closes `request`.
    fn answers(&self, request: u8, answer: u8) -> bool;
    /// How long an answer may take once the modem acknowledged `request`.
    fn answer_timeout(&self, request: u8) -> Duration;
    /// What an answer says: the data of a confirm (a MIB value, a ping's
    /// data), or the refusal in words.
    fn verdict(&self, answer: &LocalFrame) -> Result<Vec<u8>, String>;
    /// The manual's name of a code, as the modem would take it now.
    fn code_name(&self, code: u8) -> Option<&'static str>;
    /// Whether `frame`, from the modem, says that it reset.
    fn is_reset(&self, frame: &LocalFrame) -> bool;
    /// The host's link timeouts after `request` was answered with `answer`
    /// (a MIB write that sets them), at `baud`; `None` when unchanged.
    fn timeouts_after(
        &self,
        request: &LocalFrame,
        answer: &LocalFrame,
        baud: u32,
    ) -> Option<Timeouts>;
    /// Decodes one element sent by `source`, keeping the context.
    fn decode(&mut self, source: Source, element: &Element) -> Decoded;
}

/// The chip of `dialect`, fresh (its decoding context at the modem's
/// factory defaults).
pub fn for_dialect(dialect: Dialect) -> Box<dyn Chip> {
    match dialect {
        #[cfg(feature = "st7570")]
        Dialect::St7570 => Box::new(St7570::default()),
        _ => Box::new(St7580::default()),
    }
}

/// The MIB object of `chip` with `index`.
pub fn object(chip: &dyn Chip, index: u16) -> Option<&'static Object> {
    crate::mib::find(chip.mib(), index)
}
