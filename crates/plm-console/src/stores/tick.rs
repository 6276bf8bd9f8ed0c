//! Letting the sessions' time run with the page's clock, and when to run
//! again.

use super::*;

impl Console {
    /// Does something to the simulated world, if that is what is connected.
    pub fn with_simulator(&self, f: impl FnOnce(&mut dyn Simulator)) {
        self.with_active(|t, _| {
            if let Some(sim) = t.and_then(|t| t.simulator()) {
                f(sim);
            }
        });
        self.refresh();
    }

    /// Does something to the simulated S-FSK network, if that is what is
    /// connected.
    pub fn with_sfsk(&self, f: impl FnOnce(&mut crate::transport::sfsk::SfskTransport)) {
        self.with_active(|t, _| {
            if let Some(net) = t.and_then(|t| t.sfsk()) {
                f(net);
            }
        });
        self.refresh();
    }

    /// The drive loop of the profile in use.
    fn with_driver<R>(&self, f: impl FnOnce(&Driver) -> R) -> R {
        if self.profile.get_untracked().is_street() {
            f(self.street.session().borrow().driver())
        } else {
            f(self.session().borrow().driver())
        }
    }

    /// How quickly the console has ACKed the modem's frames since
    /// connecting (the bare modem of the street's concentrator profile
    /// included).
    pub fn ack_latency(&self) -> AckLatency {
        self.with_driver(Driver::ack_latency)
    }

    /// [`Driver::ack_samples`].
    pub fn ack_samples(&self) -> Vec<(f64, plm_core::time::Duration, plm_core::time::Duration)> {
        self.with_driver(Driver::ack_samples)
    }

    /// Lets time pass up to the page's clock, then asks to be run again
    /// when something is next due ([`crate::wake`]).
    pub fn tick(&self) {
        let budget = || Budget::wall(page_now_us, TICK_BUDGET_US);
        let tick = self.session().borrow_mut().tick(page_now_us(), budget());
        self.apply(tick);
        let street = self
            .street
            .session()
            .borrow_mut()
            .tick(page_now_us(), budget());
        self.apply_street(street);
        self.refresh_sim();
        let now = page_now_us();
        let due = [
            self.session().borrow().next_wake(),
            self.street.session().borrow().next_wake(),
        ]
        .into_iter()
        .flatten()
        .fold(now + IDLE_WAKE_US, f64::min);
        crate::wake::next(due, self.with_driver(Driver::exact_wake));
    }

    /// Applies what happened without letting time pass, and has the
    /// sessions run at once (a request may wait to be sent).
    pub(super) fn refresh(&self) {
        crate::wake::soon();
        let tick = self.session().borrow_mut().take_due(page_now_us());
        let street = self.street.session().borrow_mut().hand_out(page_now_us());
        let (state, kind, port) = self.with_active(|t, state| {
            let (kind, port) = t.map_or((String::new(), String::new()), |t| {
                (t.kind().into(), t.port())
            });
            (state, kind, port)
        });
        set_if_changed(self.conn.state, state);
        set_if_changed(self.conn.kind, kind);
        set_if_changed(self.conn.port, port);
        self.apply(tick);
        self.apply_street(street);
        self.refresh_sim();
    }

    /// Calls `f` with the transport of the profile in use (the street
    /// session's or the modem session's) and its state; no session is
    /// borrowed once it returns.
    pub(super) fn with_active<R>(
        &self,
        f: impl FnOnce(Option<&mut (dyn Transport + 'static)>, LinkState) -> R,
    ) -> R {
        if self.profile.get_untracked().is_street() {
            let street = self.street.session();
            let mut s = street.borrow_mut();
            let state = s.state();
            f(s.transport_mut(), state)
        } else {
            let session = self.session();
            let mut s = session.borrow_mut();
            let state = s.state();
            f(s.transport_mut(), state)
        }
    }
}
