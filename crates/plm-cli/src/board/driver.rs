//! plm-core's [`Concentrator`] driven over a real port on the wall
//! clock: what `plm_sim::street::StreetDriver` does in virtual time.
//!
//! Concentrator time is microseconds since the driver started. One turn
//! ([`Driver::step`]) reads what the port has (waiting at most
//! [`TICK`]), feeds it in, runs what is due and writes what that
//! produced: bytes, and T_REQ as RTS.

use super::Failure;
use crate::port::Port;
use plm_core::app::discovery::{DiscoveryConfig, Rounds};
use plm_core::app::sweep::Round;
use plm_core::app::{
    Address, AppEvent, AppFrame, Concentrator, Discovered, Discovery, Happening, Listener, Message,
    Request, RequestId,
};
use plm_core::link::host::Transmit;
use plm_core::time::Instant;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The longest one turn waits for bytes before it looks at the clock
/// again: well under the 40 ms a modem gives its host to ACK a frame
/// (UM0932 T_ACK).
pub const TICK: Duration = Duration::from_millis(5);

/// Set by the Ctrl-C handler; every turn looks at it.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether Ctrl-C was pressed.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// The requester gives up by itself after its attempts (1.5 + 3 + 4.5 s
/// by default); this only guards against a request that never ends.
const REQUEST_GUARD: Duration = Duration::from_secs(60);

/// A concentrator on a port.
pub struct Driver {
    port: Box<dyn Port>,
    conc: Concentrator,
    /// The port as the user named it, for messages.
    url: String,
    start: std::time::Instant,
}

impl Driver {
    /// Drives `conc` over `port` (opened from `url`), time 0 now.
    pub fn new(port: Box<dyn Port>, conc: Concentrator, url: &str) -> Driver {
        Driver {
            port,
            conc,
            url: url.to_string(),
            start: std::time::Instant::now(),
        }
    }

    /// Concentrator time: microseconds since the driver started.
    pub fn now(&self) -> Instant {
        self.start.elapsed().as_micros() as Instant
    }

    fn lost(&self, e: std::io::Error) -> Failure {
        Failure::port(format!("lost the port {}: {e}", self.url))
    }

    /// Writes what the concentrator has for the port.
    fn flush(&mut self) -> Result<(), Failure> {
        while let Some(t) = self.conc.poll_transmit() {
            let r = match t {
                Transmit::Bytes(b) => self.port.write(&b),
                Transmit::TReq { asserted } => self.port.set_rts(asserted),
            };
            r.map_err(|e| self.lost(e))?;
        }
        Ok(())
    }

    /// One turn, waiting for bytes at most until `until` (and [`TICK`]).
    /// Fails when the port is lost or Ctrl-C was pressed.
    pub fn step(&mut self, until: Option<Instant>) -> Result<Vec<Happening>, Failure> {
        if interrupted() {
            return Err(Failure::interrupted());
        }
        let now = self.now();
        let due = [self.conc.poll_timeout(), until]
            .into_iter()
            .flatten()
            .min()
            .map_or(TICK, |t| Duration::from_micros(t.saturating_sub(now)));
        let bytes = self.port.read(due.min(TICK)).map_err(|e| self.lost(e))?;
        let now = self.now();
        if !bytes.is_empty() {
            self.conc.handle_rx(now, &bytes);
        }
        if self.conc.poll_timeout().is_some_and(|t| t <= now) {
            self.conc.handle_timeout(now);
        }
        self.flush()?;
        let mut out = Vec::new();
        while let Some(h) = self.conc.poll_happening() {
            out.push(h);
        }
        Ok(out)
    }

    /// Runs turns until `until`.
    pub fn run_until(&mut self, until: Instant) -> Result<(), Failure> {
        while self.now() < until {
            self.step(Some(until))?;
        }
        Ok(())
    }

    /// Queues a request.
    pub fn submit(&mut self, request: Request) -> Result<RequestId, Failure> {
        let id = self.conc.submit(self.now(), request);
        self.flush()?;
        Ok(id)
    }

    /// Sends a frame that answers nothing (a discovery ACK).
    pub fn send(&mut self, frame: AppFrame) -> Result<(), Failure> {
        self.conc.send(self.now(), frame);
        self.flush()
    }

    /// Sends a request and waits for its fate: answered, failed, or (for
    /// a request that expects no answer) sent.
    pub fn request(&mut self, request: Request) -> Result<AppEvent, Failure> {
        let address = request.address;
        let id = self.submit(request)?;
        let give_up = self.now() + REQUEST_GUARD.as_micros() as Instant;
        while self.now() < give_up {
            for h in self.step(None)? {
                if let Happening::App(e) = h {
                    if e.fate_of() == Some(id) {
                        return Ok(e);
                    }
                }
            }
        }
        Ok(AppEvent::Failed {
            id,
            address,
            reason: format!(
                "no answer within {} s (the requester never gave up: a bug)",
                REQUEST_GUARD.as_secs()
            ),
        })
    }

    /// The answer of one board, or why there is none, in words.
    pub fn ask(
        &mut self,
        to: Address,
        message: Message,
    ) -> Result<Result<Message, String>, Failure> {
        Ok(match self.request(Request::to(to, message))? {
            AppEvent::Answered { answer, .. } => Ok(answer),
            AppEvent::Failed { reason, .. } => Err(reason),
            other => Err(format!("no answer ({other:?})")),
        })
    }

    /// Discovery (plm-core's rule), then with `older_rule` a round of the
    /// older rule: each board is handed to `found` the first time it is
    /// heard.
    pub fn discover(
        &mut self,
        config: DiscoveryConfig,
        older_rule: bool,
        mut found: impl FnMut(Address, Discovered),
    ) -> Result<Discovery, Failure> {
        let (mut d, first) = Discovery::start(self.now(), config);
        self.submit(first)?;
        let mut told = 0;
        self.listen(&mut d, |d| {
            for (a, info) in &d.found()[told..] {
                found(*a, *info);
            }
            told = d.found().len();
        })?;
        if older_rule {
            // A round of rule 1 for boards still on it (protocol notes,
            // "Discovery").
            let (mut r, first) = Rounds::start(self.now(), config.session, 1, 3);
            self.submit(first)?;
            self.listen(&mut r, |_| {})?;
            for (a, info) in r.found() {
                if d.record_found(*a, *info) {
                    found(*a, *info);
                }
            }
        }
        Ok(d)
    }

    /// Runs a round of reads (plm-core's [`Round`]) to its end: each
    /// request it gives sent, the fate of each unicast one and what boards
    /// send unasked handed back; what was read stays in it.
    pub fn run_round(&mut self, round: &mut Round) -> Result<(), Failure> {
        let mut asked = None;
        while !round.is_done() {
            if asked.is_none() {
                if let Some(q) = round.poll(self.now()) {
                    let unicast = !q.broadcast;
                    let id = self.submit(q)?;
                    asked = unicast.then_some(id);
                    continue;
                }
            }
            for h in self.step(round.poll_timeout())? {
                let Happening::App(e) = h else { continue };
                match e {
                    AppEvent::Unsolicited {
                        address, message, ..
                    } => {
                        if let Some(answer) = round.hear(address, &message) {
                            self.send(answer)?;
                        }
                    }
                    AppEvent::Answered { id, answer, .. } if Some(id) == asked => {
                        asked = None;
                        round.on_answer(Ok(answer));
                    }
                    AppEvent::Failed { id, reason, .. } if Some(id) == asked => {
                        asked = None;
                        round.on_answer(Err(reason));
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }

    /// Runs `engine` to its end: what boards send unasked handed to it
    /// (and `heard` called after each), what it hands out sent.
    fn listen<L: Listener>(
        &mut self,
        engine: &mut L,
        mut heard: impl FnMut(&L),
    ) -> Result<(), Failure> {
        while !engine.done() {
            for h in self.step(engine.due())? {
                if let Happening::App(AppEvent::Unsolicited {
                    address, message, ..
                }) = h
                {
                    if let Some(answer) = engine.hear(address, &message) {
                        self.send(answer)?;
                    }
                    heard(engine);
                }
            }
            if let Some(next) = engine.tick(self.now()) {
                self.submit(next)?;
            }
        }
        Ok(())
    }
}
