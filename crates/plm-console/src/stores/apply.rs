//! The one place that applies what a session did to the stores.

use super::*;

impl Console {
    pub(super) fn refresh_sim(&self) {
        let (events, echoed, plugged, state, servers) = self.with_active(|t, state| {
            let servers = |t: &mut dyn Transport| t.sfsk().map(|s| s.servers());
            match t {
                Some(t) => match t.simulator() {
                    Some(sim) => (
                        sim.line_events(),
                        sim.echoed(),
                        sim.plugged(),
                        Some(state),
                        None,
                    ),
                    None => (Vec::new(), 0, true, None, servers(t)),
                },
                None => (Vec::new(), 0, true, None, None),
            }
        });
        let mut servers = servers.unwrap_or_default();
        {
            let session = self.session();
            let s = session.borrow();
            for (at, _) in servers.iter_mut().flat_map(|v| v.syncs.iter_mut()) {
                *at = s.log_time(*at);
            }
        }
        set_if_changed(self.sim.servers, servers);
        if let Some(state) = state {
            set_if_changed(self.conn.state, state);
        }
        set_if_changed(self.sim.echoed, echoed);
        set_if_changed(self.sim.plugged, plugged);
        if !events.is_empty() {
            self.sim.line_events.update(|l| {
                for e in events {
                    l.push(crate::line_events::describe(&e));
                    if l.len() > LINE_EVENTS {
                        l.remove(0);
                    }
                }
            });
        }
    }

    /// Applies what the street session did to the stores, then calls its
    /// replies (the session is not borrowed any more).
    pub(super) fn apply_street(&self, tick: StreetTick) {
        let StreetTick {
            alerts,
            replies,
            traffic,
            sent,
            campaign,
            found,
            show,
            ..
        } = tick;
        let street = self.street;
        // The progress, the count sent and the lamps are shown together,
        // so that what the page says is of one moment.
        if show {
            let (sweep, discovering) = self.street.read(|s| {
                let packed = s
                    .discovering()
                    .map(|(found, left)| ((found as u64) << 32) | left as u64);
                (s.sweep(), packed)
            });
            set_if_changed(street.sweep, sweep);
            set_if_changed(street.discovering, discovering);
            if sent > 0 {
                street.sent.update(|n| *n += sent);
            }
            street.version.update(|v| *v += 1);
            street.keep_history(false);
        }
        if found {
            let (session, lamps) = self.street.read(|s| s.remembered());
            let r = street_store::Remembered { session, lamps };
            street.kept_as.with_untracked(|id| {
                if !id.is_empty() {
                    street_store::save(id, &r)
                }
            });
        }
        if campaign {
            self.street.read(crate::campaign_store::save);
            street.campaign.update(|v| *v += 1);
        }
        if !traffic.is_empty() {
            self.traffic.log.update(|log| {
                for (at, d) in traffic {
                    log.push(Some(at), d);
                }
            });
        }
        if !alerts.is_empty() {
            let wall = wall_clock();
            street.alerts.update(|l| {
                for alert in alerts {
                    l.push_front(Raised {
                        wall: wall.clone(),
                        alert,
                    });
                }
                l.truncate(ALERTS);
            });
        }
        for (reply, r) in replies {
            reply(r);
        }
    }

    /// Applies notes to the stores, then calls the replies (the session is
    /// not borrowed any more: a reply may send the next request).
    pub(super) fn apply(&self, tick: Tick) {
        let Tick { notes, replies } = tick;
        let mut traffic = Vec::new();
        // The last status message only: the views show the latest, and
        // each one set redrew them (one per exchange).
        let mut status = None;
        for n in notes {
            match n {
                Note::Traffic { at, decoded } => traffic.push((at, *decoded)),
                Note::Status { at, message } => {
                    let data = message.data();
                    status = Some((at, data[0]));
                    if data.len() == 3 {
                        self.modem.network.update(|n| n.on_status(at, data));
                    }
                }
                Note::TReq(level) => set_if_changed(self.conn.treq, level),
                Note::Unsolicited {
                    at,
                    frame,
                    reset: true,
                    ..
                } => {
                    let cause = frame.data.first().copied().unwrap_or(0);
                    self.modem.last_reset.set(Some(stamped(at, cause)));
                }
                Note::Unsolicited { at, frame, .. } => {
                    if self.profile.get_untracked() == Profile::St7570 {
                        self.modem.network.update(|n| n.on_indication(at, &frame));
                    }
                }
                Note::Retry { cause, .. } => {
                    self.conn.retries.update(|r| *r += 1);
                    self.conn.last_problem.set(Some(cause));
                }
                Note::Timeouts(t) => set_if_changed(self.conn.timeouts, t),
                Note::TReqUnanswered(n) => {
                    if n == 2 && self.conn.kind.get_untracked() == "WebSerial" {
                        self.conn.advice.set(Some(TREQ_ADVICE.into()));
                    }
                }
            }
        }
        if status.is_some() {
            self.modem.status.set(status.map(|(at, b)| stamped(at, b)));
        }
        if !traffic.is_empty() {
            self.traffic.log.update(|log| {
                for (at, d) in traffic {
                    log.push(Some(at), d);
                }
            });
        }
        for (reply, outcome) in replies {
            if let Outcome::Failed(why) = &outcome {
                self.conn.last_problem.set(Some(why.clone()));
            }
            reply(outcome);
        }
    }
}
