//! The views' requests to the modem, and MIB operations.

use super::*;

/// An answer that is not the one a request waits for, in words.
pub fn unexpected(answer: &Command) -> String {
    match answer.name() {
        Some(n) => format!("unexpected answer {n}"),
        None => format!("unexpected answer, code {:02X}h", answer.code()),
    }
}

/// What is wrong with an ST7580 answer, if it is a refusal, in words.
pub fn refusal(answer: &Command) -> Option<String> {
    plm_core::chip::st7580_refusal(answer)
}

impl Console {
    /// Sends the request `frame` to the modem of any chip; `reply` gets
    /// its outcome.
    pub fn request_frame(&self, frame: LocalFrame, reply: impl FnOnce(Outcome) + 'static) {
        self.session().borrow_mut().request(frame, Box::new(reply));
        self.refresh();
    }

    /// Sends an ST7580 `command` (the views of what only the ST7580 has);
    /// `reply` gets its outcome, the answer read as an ST7580 command.
    pub fn request(&self, command: Command, reply: impl FnOnce(Outcome<Command>) + 'static) {
        self.request_boxed(command, Box::new(reply));
    }

    /// [`Console::request`] for every caller: one copy of the reading of
    /// the answer in the page, not one per reply closure.
    fn request_boxed(&self, command: Command, reply: Box<dyn FnOnce(Outcome<Command>)>) {
        self.request_frame(command.to_frame(), move |o| {
            reply(o.read(|f| {
                Command::from_frame(f).map_err(|e| format!("the modem's answer does not fit: {e}"))
            }))
        });
    }

    /// The transport's clock now (µs), as the traffic log counts it.
    pub fn now(&self) -> Instant {
        let session = self.session();
        let s = session.borrow();
        s.log_time(s.now())
    }

    /// Reads from the chip's host interface description.
    pub fn with_chip<R>(&self, f: impl FnOnce(&dyn Chip) -> R) -> R {
        f(self.session().borrow().chip())
    }

    /// Reads MIB object `index` into the modem store; `done` gets the value
    /// or what went wrong.
    pub fn read_mib(&self, index: u16, done: impl FnOnce(MibResult) + 'static) {
        self.mib_request(MibOp::Read, index, Box::new(done));
    }

    /// Writes `data` to MIB object `index`; the modem store keeps it once
    /// confirmed.
    pub fn write_mib(&self, index: u16, data: Vec<u8>, done: impl FnOnce(MibResult) + 'static) {
        self.mib_request(MibOp::Write(data), index, Box::new(done));
    }

    /// Erases MIB object `index` (a chip without erase says so); the
    /// modem store forgets its value once confirmed.
    pub fn erase_mib(&self, index: u16, done: impl FnOnce(MibResult) + 'static) {
        self.mib_request(MibOp::Erase, index, Box::new(done));
    }

    /// Sends the request of MIB operation `op` on object `index`; `done`
    /// gets what the answer says ([`Chip::verdict`]), and the modem store
    /// what the object holds now: the value read or written, or nothing
    /// once erased. One function for every caller (the callback boxed):
    /// one copy of it in the page.
    fn mib_request(&self, op: MibOp, index: u16, done: Box<dyn FnOnce(MibResult)>) {
        let request = self.with_chip(|c| match &op {
            MibOp::Read => Ok(c.mib_read(index)),
            MibOp::Write(data) => Ok(c.mib_write(index, data)),
            MibOp::Erase => c.mib_erase(index).ok_or(c.name()),
        });
        let frame = match request {
            Ok(frame) => frame,
            Err(chip) => return done(Err(format!("the {chip} has no MIB erase"))),
        };
        let (c, mib) = (*self, self.modem.mib);
        self.request_frame(frame, move |o| {
            let got = match o {
                Outcome::Answer {
                    command: Some(f), ..
                } => c.with_chip(|chip| chip.verdict(&f)),
                Outcome::Answer { command: None, .. } => Ok(Vec::new()),
                Outcome::Failed(why) => Err(why),
            };
            if let Ok(value) = &got {
                match op {
                    MibOp::Read => mib.update(|m| m.insert(index, value.clone())),
                    MibOp::Write(data) => mib.update(|m| m.insert(index, data)),
                    MibOp::Erase => mib.update(|m| m.remove(index)),
                }
            }
            done(got)
        });
    }
}

/// What a MIB request's callback gets: the object's data, or why not.
pub type MibResult = Result<Vec<u8>, String>;

/// A MIB operation of [`Console::mib_request`].
enum MibOp {
    Read,
    Write(Vec<u8>),
    Erase,
}
