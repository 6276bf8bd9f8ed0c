//! A concentrator (plm-core's [`Concentrator`]) joined to a [`Sim`] in
//! virtual time: what the console does with the page's timers and
//! `plm board` with a serial port, done as fast as possible, over either
//! way in ([`Attach`]). Tests and `cargo xtask bench` use it.

use crate::sim::{Attach, Sim};
use plm_core::app::read_all::ReadAll;
use plm_core::app::{
    Address, AppEvent, Concentrator, Discovery, Happening, Listener, Message, Request, RequestId,
    RequesterConfig,
};
use plm_core::link::host::Transmit;
use plm_core::st7580::TxParams;
use plm_core::time::{earliest, Duration, Instant, MS};
use std::collections::BTreeMap;

/// A concentrator driving a simulated street.
#[derive(Debug, Clone)]
pub struct StreetDriver {
    /// The simulation.
    pub sim: Sim,
    /// The host's concentrator.
    pub conc: Concentrator,
    /// Every happening so far, with its time.
    pub log: Vec<(Instant, Happening)>,
}

impl StreetDriver {
    /// A concentrator for `sim`, of the kind its node 0 needs: over the
    /// board's USART, or speaking the board protocol through the bare
    /// modem from node 0's street address.
    pub fn new(sim: Sim, config: RequesterConfig) -> Self {
        let conc = Self::concentrator(&sim, config);
        StreetDriver {
            sim,
            conc,
            log: Vec::new(),
        }
    }

    fn concentrator(sim: &Sim, config: RequesterConfig) -> Concentrator {
        match sim.attach() {
            Attach::Board => Concentrator::usart(config),
            Attach::Modem => Concentrator::modem(
                config,
                sim.baud(),
                Concentrator::ADDRESS,
                TxParams::default(),
            ),
        }
    }

    /// The host's cable pulled for `gone` µs, then plugged in again: every
    /// request under way is lost, the world goes on without a host (what
    /// it sends the host is lost), and a new concentrator starts.
    pub fn pull_cable(&mut self, gone: Duration) {
        let config = self.conc.requester().config();
        self.conc.abort_all("the cable was pulled");
        while self.conc.poll_happening().is_some() {}
        self.sim.set_treq(false);
        self.sim.advance_to(self.sim.now() + gone);
        self.sim.host_read();
        self.conc = Self::concentrator(&self.sim, config);
    }

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.sim.now()
    }

    /// Queues a request.
    pub fn submit(&mut self, request: Request) -> RequestId {
        let now = self.sim.now();
        let id = self.conc.submit(now, request);
        self.flush();
        id
    }

    /// The simulated world, to act on it (cut a board's supply, ...).
    pub fn sim_mut(&mut self) -> &mut Sim {
        &mut self.sim
    }

    /// Sends a frame without waiting for anything.
    pub fn send(&mut self, frame: plm_core::app::AppFrame) {
        let now = self.sim.now();
        self.conc.send(now, frame);
        self.flush();
    }

    fn flush(&mut self) {
        while let Some(t) = self.conc.poll_transmit() {
            match t {
                Transmit::Bytes(b) => self.sim.write(&b),
                Transmit::TReq { asserted } => self.sim.set_treq(asserted),
            }
        }
    }

    /// Runs one step: to the next deadline of the world or the
    /// concentrator, at most `until`. Returns the happenings of the step.
    pub fn step(&mut self, until: Instant) -> Vec<Happening> {
        let next = earliest(self.sim.next_deadline(), self.conc.poll_timeout())
            .unwrap_or(until)
            .clamp(self.sim.now(), until);
        self.sim.advance_to(next);
        let now = self.sim.now();
        for (at, byte) in self.sim.host_read() {
            self.conc.handle_rx(at, &[byte]);
        }
        if self.conc.poll_timeout().is_some_and(|t| t <= now) {
            self.conc.handle_timeout(now);
        }
        self.flush();
        let mut out = Vec::new();
        while let Some(h) = self.conc.poll_happening() {
            self.log.push((now, h.clone()));
            out.push(h);
        }
        out
    }

    /// Runs until `done` holds for a happening or `limit` µs have passed;
    /// returns whether `done` held.
    pub fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Happening) -> bool) -> bool {
        let until = self.sim.now() + limit;
        while self.sim.now() < until {
            if self.step(until).iter().any(&mut done) {
                return true;
            }
        }
        false
    }

    /// Runs for `d` µs.
    pub fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_| false);
    }

    /// Sends a request and waits for its fate (answer, failure, or sent).
    pub fn request(&mut self, request: Request, limit: Duration) -> Option<AppEvent> {
        let id = self.submit(request);
        let mut fate = None;
        self.run_until(limit, |h| match h {
            Happening::App(e) if e.fate_of() == Some(id) => {
                fate = Some(e.clone());
                true
            }
            _ => false,
        });
        fate
    }

    /// The answer to a request to one board, or why there is none.
    pub fn ask(
        &mut self,
        to: Address,
        message: Message,
        limit: Duration,
    ) -> Result<Message, String> {
        match self.request(Request::to(to, message), limit) {
            Some(AppEvent::Answered { answer, .. }) => Ok(answer),
            Some(AppEvent::Failed { reason, .. }) => Err(reason),
            other => Err(format!("no answer within the time allowed ({other:?})")),
        }
    }

    /// Runs a firmware update campaign to its end: every request the
    /// engine hands out goes through the concentrator, its answer (or
    /// failure) back to the engine.
    pub fn update(&mut self, u: &mut plm_core::app::update::Update) {
        while !u.is_done() {
            let now = self.sim.now();
            match u.poll(now) {
                Some(request) => match self.request(request, 120 * 1_000 * MS) {
                    Some(AppEvent::Answered { answer, .. }) => {
                        u.on_answer(self.sim.now(), Ok(answer))
                    }
                    Some(AppEvent::Failed { reason, .. }) => {
                        u.on_answer(self.sim.now(), Err(reason))
                    }
                    Some(_) => {}
                    None => u.on_answer(self.sim.now(), Err("no answer within 2 minutes".into())),
                },
                None => {
                    let until = u.poll_timeout().unwrap_or(now + 100 * MS);
                    self.run_for(until.saturating_sub(now).max(1));
                }
            }
        }
    }

    /// Reads `boards` in slots (plm-core's [`ReadAll`]): every request
    /// it hands out is broadcast, every HID reply handed back to it.
    /// Returns the finished read: what was heard, and the stragglers for
    /// the caller to ask one by one.
    pub fn read_in_slots(
        &mut self,
        boards: &[Address],
        config: plm_core::app::read_all::ReadConfig,
    ) -> ReadAll {
        let (mut r, first) = ReadAll::start(self.sim.now(), boards, config);
        if let Some(first) = first {
            self.submit(first);
        }
        self.listen(&mut r);
        r
    }

    /// Runs `engine` to its end: what boards send unasked handed to it,
    /// what it hands out sent.
    fn listen(&mut self, engine: &mut impl Listener) {
        while !engine.done() {
            let until = engine.due().unwrap_or(self.sim.now());
            for h in self.step(until) {
                if let Happening::App(AppEvent::Unsolicited {
                    address, message, ..
                }) = h
                {
                    if let Some(answer) = engine.hear(address, &message) {
                        self.send(answer);
                    }
                }
            }
            if let Some(next) = engine.tick(self.sim.now()) {
                self.submit(next);
            }
        }
    }

    /// Discovers the boards on the line (plm-core's rule); returns what
    /// was found.
    pub fn discover(
        &mut self,
        config: plm_core::app::discovery::DiscoveryConfig,
    ) -> BTreeMap<Address, plm_core::app::Discovered> {
        let (mut d, first) = Discovery::start(self.sim.now(), config);
        self.submit(first);
        self.listen(&mut d);
        d.found().iter().copied().collect()
    }
}
