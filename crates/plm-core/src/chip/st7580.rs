//! The ST7580's host interface as a [`Chip`] (UM0932 3.3, 4).

use super::Chip;
use crate::decode::{Decoded, Decoder};
use crate::link::{Dialect, Element, LocalFrame, Source, Timeouts};
use crate::mib::Object;
use crate::st7580::mib::{index, MibObject};
use crate::st7580::{code, Command};
use crate::time::{Duration, MS};
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

/// The ST7580, with its traffic's decoding context.
#[derive(Debug, Clone)]
pub struct St7580 {
    decoder: Decoder,
}

impl Default for St7580 {
    fn default() -> Self {
        St7580 {
            decoder: Decoder::new(Dialect::St7580, Source::Any),
        }
    }
}

/// What is wrong with an answer, if it is a refusal, in words: an error
/// with its cause (UM0932 Table 14), or CMD_SyntaxError.
pub fn refusal(answer: &Command) -> Option<String> {
    use Command::*;
    match answer {
        BioResetError(e) | MibWriteError(e) | MibReadError(e) | MibEraseError(e)
        | PhyDataError(e) | DlDataError(e) | SsDataError(e) => Some(format!(
            "the modem refused it with {}: {}",
            answer.name().unwrap_or("an error"),
            match e.name() {
                Some(n) => n.to_string(),
                None => format!("error {:02X}h", e.byte()),
            }
        )),
        CmdSyntaxError { error } => Some(format!(
            "the modem does not know command {error:02X}h (CMD_SyntaxError)"
        )),
        _ => None,
    }
}

/// The ST7580's MIB indexes are one byte (UM0932 Table 52).
fn byte(index: u16) -> u8 {
    index as u8
}

impl Chip for St7580 {
    fn name(&self) -> &'static str {
        "ST7580"
    }

    fn dialect(&self) -> Dialect {
        Dialect::St7580
    }

    fn mib(&self) -> &'static [Object] {
        crate::st7580::mib::OBJECTS
    }

    fn mib_read(&self, index: u16) -> LocalFrame {
        Command::MibReadRequest { index: byte(index) }.to_frame()
    }

    fn mib_write(&self, index: u16, data: &[u8]) -> LocalFrame {
        Command::MibWriteRequest {
            index: byte(index),
            data: data.to_vec(),
        }
        .to_frame()
    }

    fn mib_erase(&self, index: u16) -> Option<LocalFrame> {
        Some(Command::MibEraseRequest { index: byte(index) }.to_frame())
    }

    fn reset(&self) -> LocalFrame {
        Command::BioResetRequest.to_frame()
    }

    /// Every frame from the host gets an answer: its confirm or error,
    /// or CMD_SyntaxError for a code the modem does not know (UM0932 3.3).
    fn expects_answer(&self, _request: u8) -> bool {
        true
    }

    fn answers(&self, request: u8, answer: u8) -> bool {
        code::answers(request, answer)
    }

    /// A data request's confirm comes at the end of its power line frame.
    fn answer_timeout(&self, request: u8) -> Duration {
        match request {
            code::PHY_DATA_REQUEST | code::DL_DATA_REQUEST | code::SS_DATA_REQUEST => 10_000 * MS,
            _ => 2_000 * MS,
        }
    }

    fn verdict(&self, answer: &LocalFrame) -> Result<Vec<u8>, String> {
        let command = Command::from_frame(answer)
            .map_err(|e| format!("the modem's answer does not fit: {e}"))?;
        match refusal(&command) {
            Some(why) => Err(why),
            None => Ok(answer.data.clone()),
        }
    }

    fn code_name(&self, code: u8) -> Option<&'static str> {
        code::name(code)
    }

    fn is_reset(&self, frame: &LocalFrame) -> bool {
        frame.code == code::BIO_RESET_INDICATION
    }

    /// UM0932 4.2.10: MIB 09h sets the host interface timeouts.
    fn timeouts_after(
        &self,
        request: &LocalFrame,
        answer: &LocalFrame,
        _baud: u32,
    ) -> Option<Timeouts> {
        let written = request.code == code::MIB_WRITE_REQUEST
            && answer.code == code::MIB_WRITE_CONFIRM
            && request.data.first() == Some(&index::HOST_INTERFACE_TIMEOUT);
        if !written {
            return None;
        }
        MibObject::decode(index::HOST_INTERFACE_TIMEOUT, &request.data[1..])
            .ok()
            .and_then(|o| o.timeouts())
    }

    fn decode(&mut self, source: Source, element: &Element) -> Decoded {
        self.decoder.decode_from(source, element)
    }
}
