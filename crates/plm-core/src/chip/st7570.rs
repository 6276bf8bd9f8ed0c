//! The ST7570's host interface as a [`Chip`] (ST7570 UM 5.3, 6). Its
//! frames are read in the access layer the traffic set (MIB 00A1h, the
//! status message), which the decoder follows: one context for both.

use super::Chip;
use crate::decode::{Decoded, Decoder};
use crate::link::{Dialect, Element, LocalFrame, Source, Timeouts};
use crate::mib::Object;
use crate::st7570::code as c;
use crate::st7570::fields as f;
use crate::st7570::mib::{index, TicRepeater};
use crate::st7570::{Command, Layer};
use crate::time::{Duration, MS};
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

/// The ST7570, with its traffic's decoding context.
#[derive(Debug, Clone)]
pub struct St7570 {
    decoder: Decoder,
}

impl Default for St7570 {
    fn default() -> Self {
        St7570 {
            decoder: Decoder::new(Dialect::St7570, Source::Any),
        }
    }
}

impl St7570 {
    /// The access layer the traffic has set (PHY until it says otherwise).
    pub fn layer(&self) -> Layer {
        self.decoder.layer().unwrap_or(Layer::Phy)
    }
}

/// A confirm code's name, or its value.
fn code_word(names: &[&'static str; 256], code: u8) -> String {
    match names[code as usize] {
        "" => format!("code {code:02X}h"),
        n => n.into(),
    }
}

impl Chip for St7570 {
    fn name(&self) -> &'static str {
        "ST7570"
    }

    fn dialect(&self) -> Dialect {
        Dialect::St7570
    }

    fn mib(&self) -> &'static [Object] {
        crate::st7570::mib::OBJECTS
    }

    fn has(&self, object: &Object) -> bool {
        crate::st7570::mib::in_layer(object, self.layer())
    }

    fn mib_read(&self, index: u16) -> LocalFrame {
        Command::ReadDbRequest { index }.to_frame()
    }

    fn mib_write(&self, index: u16, data: &[u8]) -> LocalFrame {
        Command::WriteDbRequest {
            index,
            data: data.to_vec(),
        }
        .to_frame()
    }

    /// The ST7570 has no erase: counters are reset by a write (6.5).
    fn mib_erase(&self, _index: u16) -> Option<LocalFrame> {
        None
    }

    /// CMD_ResetRequest with RESET = 0: the configuration kept (Table 24).
    fn reset(&self) -> LocalFrame {
        Command::ResetRequest { reset: 0 }.to_frame()
    }

    /// Table 21, 5.3.2, 5.3.23: some requests draw no answer in some
    /// layers; a code Table 15 does not define draws CMD_SyntaxError.
    fn expects_answer(&self, request: u8) -> bool {
        c::lookup(request).is_none() || !c::answers_to(request, self.layer()).is_empty()
    }

    fn answers(&self, request: u8, answer: u8) -> bool {
        c::answers(request, answer, self.layer())
    }

    /// A data request's confirm comes after its frame's subframes and
    /// repetitions on the line (up to 7 slots of 300 ms, IC + 1 copies:
    /// 5.3.13); an alarm's after its 3-slot window; a repeater call after
    /// its 21 sub-slots (5.3.23).
    fn answer_timeout(&self, request: u8) -> Duration {
        match request {
            c::CMD_DATA_REQUEST | c::CMD_ALARM_REQUEST | c::CMD_RC_REQUEST => 20_000 * MS,
            _ => 2_000 * MS,
        }
    }

    fn verdict(&self, answer: &LocalFrame) -> Result<Vec<u8>, String> {
        use Command::*;
        let layer = self.layer();
        let command = Command::from_frame(answer, layer)
            .map_err(|e| format!("the modem's answer does not fit: {e}"))?;
        let name = command.name().unwrap_or("an error");
        let refused = |what: String| Err(format!("the modem refused it with {name}: {what}"));
        match command {
            WriteDbError { error } | ReadDbError { error } => {
                refused(code_word(&f::MIB_ERRORS, error))
            }
            SyntaxError { error } => Err(format!(
                "the modem did not take the frame (CMD_SyntaxError, error {error:02X}h)"
            )),
            DataConfirm { confirm_code } if confirm_code != 0xFF => refused(code_word(
                match layer {
                    Layer::Phy => &f::PHY_CONFIRM_CODES,
                    Layer::Mac => &f::MAC_CONFIRM_CODES,
                },
                confirm_code,
            )),
            AlarmConfirm { confirm_code } if confirm_code != 0xFF => {
                refused(code_word(&f::ALARM_CONFIRM_CODES, confirm_code))
            }
            WriteDbConfirm { data, .. } | ReadDbConfirm { data, .. } => Ok(data),
            _ => Ok(answer.data.clone()),
        }
    }

    fn code_name(&self, code: u8) -> Option<&'static str> {
        c::name(code)
    }

    /// 5.3.4: after a reset the modem sends CMD_ResetRequest, RESET = 0.
    fn is_reset(&self, frame: &LocalFrame) -> bool {
        frame.code == c::CMD_RESET_REQUEST
    }

    /// 6.5.11, Table 97: 000Bh b7 selects T_IC.
    fn timeouts_after(
        &self,
        request: &LocalFrame,
        answer: &LocalFrame,
        baud: u32,
    ) -> Option<Timeouts> {
        let written = request.code == c::CMD_WRITE_DB_REQUEST
            && answer.code == c::CMD_WRITE_DB_CONFIRM
            && request.data.get(..2) == Some(&index::TIC_REPEATER.to_le_bytes()[..]);
        let value = *request.data.get(2)?;
        written.then(|| {
            Timeouts::at_reset(Dialect::St7570, baud)
                .with_tic(TicRepeater::from_byte(value).tic_selector(), baud)
        })
    }

    fn decode(&mut self, source: Source, element: &Element) -> Decoded {
        self.decoder.decode_from(source, element)
    }
}
