//! Building the transport of a profile and the session over it.

use super::*;

impl Console {
    /// Connects the simulated world of the current profile: a street of
    /// [`STREET_LAMPS`] lamps, or a modem with `sim.nodes - 1` echoing
    /// peers.
    pub fn connect_simulated(&self) {
        let profile = self.profile.get_untracked();
        let baud = self.conn.baud.get_untracked();
        let t: Box<dyn Transport> = if profile.is_street() {
            let mut street = SimTransport::street(
                self.sim.lamps.get_untracked(),
                profile.attach(),
                baud,
                SIM_SEED,
                match self.sim.uniform.get_untracked() {
                    true => StreetProfile::Uniform,
                    false => StreetProfile::Realistic,
                },
            );
            street.set_failure_rate(f64::from_bits(self.sim.failure_rate.get_untracked()));
            Box::new(street)
        } else if profile == Profile::St7570 {
            Box::new(crate::transport::sfsk::SfskTransport::new(
                plm_sim::st7570::net::SERVED_LINE_NODES,
                baud,
                SIM_SEED,
            ))
        } else {
            Box::new(SimTransport::new(
                self.sim.nodes.get_untracked(),
                baud,
                SIM_SEED,
            ))
        };
        self.sim.line_events.set(Vec::new());
        self.connect_transport(t);
        let speed = self.sim.speed.get_untracked();
        self.street.act(|s| s.set_speed(speed));
    }

    /// Connects over `transport` (the simulated world, or a WebSerial
    /// port the port chooser opened, `views::serial_port`) with the
    /// current profile; the other session lets go of its transport.
    pub fn connect_transport(&self, transport: Box<dyn Transport>) {
        let profile = self.profile.get_untracked();
        let mut problem = None;
        // The street left behind keeps its readings.
        self.street.keep_history(true);
        if profile.is_street() {
            self.session()
                .borrow_mut()
                .replace_transport(None, profile.dialect());
            let baud = transport.baud();
            let conc = match profile {
                Profile::StreetBoard => Concentrator::usart(RequesterConfig::default()),
                _ => Concentrator::modem(
                    RequesterConfig::default(),
                    baud,
                    Concentrator::ADDRESS,
                    TxParams::default(),
                ),
            };
            self.street.port.set(transport.port());
            let simulated = transport.kind() == "Simulated";
            let id = street_store::connection(
                profile.key(),
                &transport.port(),
                baud,
                simulated.then_some(SIM_SEED),
            );
            let mut street = StreetSession::new(transport, conc);
            match street_store::recall(&id) {
                Ok(Some(r)) => street.recall(r.session, r.lamps),
                kept => {
                    problem = kept.err();
                    // Boards heard in a session stay quiet in it: a street
                    // this browser does not know may have been found in
                    // session 1 by another.
                    if !simulated {
                        street.set_session(street_store::fresh_session());
                    }
                    street.discover();
                }
            }
            if let Some(p) = history_store::start(&id, street.now()) {
                problem = Some(problem.map_or(p.clone(), |q| format!("{q} {p}")));
            }
            self.street.kept_as.set(id);
            *self.street.session().borrow_mut() = street;
            self.street.alerts.set(VecDeque::new());
            self.street.sent.set(0);
        } else {
            *self.street.session().borrow_mut() = StreetSession::idle();
            self.street.port.set(String::new());
            self.street.kept_as.set(String::new());
            history_store::start("", 0);
            self.session()
                .borrow_mut()
                .replace_transport(Some(transport), profile.dialect());
        }
        self.street.version.update(|v| *v += 1);
        self.modem.mib.set(Default::default());
        self.modem.status.set(None);
        self.modem.network.update(|n| n.clear());
        self.conn.retries.set(0);
        self.conn.last_problem.set(None);
        self.conn.advice.set(problem);
        self.refresh();
        let wired = load(&self.resetn_key()).is_some();
        self.conn.resetn_on_dtr.set(false);
        self.set_resetn_on_dtr(wired);
    }

    /// Where the RESETN-on-DTR setting of the port in use is kept.
    fn resetn_key(&self) -> String {
        let port = self.conn.port.get_untracked();
        // The port's name without what follows it in brackets.
        let name = port.as_bytes().windows(2).position(|w| w == b" (");
        format!(
            "plm-console.resetn-on-dtr.{}",
            &port[..name.unwrap_or(port.len())]
        )
    }

    /// Says whether this port's DTR is wired to the modem's RESETN, and
    /// remembers it for the port. Wired, DTR is released at once (the OS
    /// asserts DTR when it opens a port, which holds such a modem in
    /// reset).
    pub fn set_resetn_on_dtr(&self, wired: bool) {
        if wired && !self.conn.resetn_on_dtr.get_untracked() {
            self.with_active(|t, _| t.map(|t| t.set_dtr(false)));
        }
        crate::storage::store(&self.resetn_key(), wired.then_some("1"));
        self.conn.resetn_on_dtr.set(wired);
        self.refresh();
    }

    /// A hardware reset: DTR (RESETN) asserted for [`RESETN_PULSE_MS`],
    /// then released; the modem boots and sends BIO_ResetIndication
    /// (UM0932 Table 19, cause 0).
    pub fn pulse_resetn(&self) {
        if !self.conn.resetn_on_dtr.get_untracked() {
            return;
        }
        self.with_active(|t, _| t.map(|t| t.set_dtr(true)));
        self.refresh();
        let c = *self;
        gloo_timers::callback::Timeout::new(RESETN_PULSE_MS as u32, move || {
            c.with_active(|t, _| t.map(|t| t.set_dtr(false)));
            c.refresh();
        })
        .forget();
    }

    /// Changes the profile and connects its simulated world.
    pub fn set_profile(&self, profile: Profile) {
        crate::storage::store(PROFILE_KEY, Some(profile.key()));
        if self.profile.get_untracked() != profile {
            self.profile.set(profile);
            self.traffic.log.update(|l| l.clear());
        }
        self.connect_simulated();
    }

    /// Closes the connection.
    pub fn disconnect(&self) {
        let dialect = self.profile.get_untracked().dialect();
        self.session().borrow_mut().replace_transport(None, dialect);
        *self.street.session().borrow_mut() = StreetSession::idle();
        self.street.port.set(String::new());
        self.street.kept_as.set(String::new());
        self.refresh();
    }

    /// Changes the baud rate.
    pub fn set_baud(&self, baud: u32) {
        self.session().borrow_mut().set_baud(baud);
        if let Some(t) = self.street.session().borrow_mut().transport_mut() {
            t.set_baud(baud);
        }
        self.conn.baud.set(baud);
        self.refresh();
    }
}
