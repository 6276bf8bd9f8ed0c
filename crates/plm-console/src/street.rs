//! The street session: plm-core's [`Street`] (discovery, the sweep,
//! dimming, clocks, the update campaign, the fleet and its alerts) on the
//! console's one drive loop ([`crate::driver`]) over a transport with the
//! page's timers, its frames named for the Traffic view, and its views
//! drawn at the line's quiet moments.
//!
//! Like [`crate::session`], it has no browser in it: time comes in as an
//! argument, so its tests run natively against a simulated street.

mod campaign;

pub use plm_core::app::street::{Alert, Campaign, Lamp, Lamps, Sample, Sweep, HISTORY};

use crate::driver::{self, earliest, AnyEngine, Budget, Driver, Layer};
use crate::throttle::Throttle;
use crate::transport::{LinkState, Transport};
use plm_core::app::service::{Clock, Discovered};
use plm_core::app::street::Street;
use plm_core::app::{Address, Concentrator, Happening, Message, Request, RequesterConfig};
use plm_core::decode::{Decoded, Decoder};
use plm_core::link::host;
use plm_core::link::{Dialect, Element, Source};
use plm_core::time::{Duration, Instant};

/// The Street and Firmware update views are drawn again at most five
/// times a second; a change waits at most this and one tick
/// (`stores::IDLE_WAKE_US`).
pub const STREET_DRAW_US: f64 = 200_000.0;
/// Through a bare modem, while the discovery or the sweep has the line,
/// the views are drawn at its quiet moments ([`StreetSession::draw_first`]);
/// without one, after this at the latest.
pub const STREET_DRAW_LATE_US: f64 = 1_000_000.0;

/// Called once with the answer to a request made from a view.
pub type StreetReply = Box<dyn FnOnce(Result<Message, String>)>;

/// What a tick produced.
#[derive(Default)]
pub struct StreetTick {
    /// The fleet changed.
    pub changed: bool,
    /// New alerts.
    pub alerts: Vec<Alert>,
    /// Replies for the views, with their outcomes.
    pub replies: Vec<(StreetReply, Result<Message, String>)>,
    /// Frames on the wire (USART elements, or the modem's link), as
    /// `plm decode` names them, with their times.
    pub traffic: Vec<(Instant, Decoded)>,
    /// Frames the console sent towards the street (in [`StreetSession::hand_out`]'s
    /// ticks: since the views were last drawn).
    pub sent: u64,
    /// The update campaign changed (to save it, and to show it).
    pub campaign: bool,
    /// The street found changed: a lamp heard, a new session, a new
    /// release (to remember it, [`StreetSession::remembered`]; in
    /// [`StreetSession::hand_out`]'s ticks, when the views are drawn).
    pub found: bool,
    /// The street's views are to be drawn now (at most every
    /// [`STREET_DRAW_US`]).
    pub show: bool,
}

/// What the session itself adds to a tick, beside the street's
/// [`plm_core::app::street::Changes`].
#[derive(Default)]
struct Pending {
    /// Kept, with `sent` and `found`, until the views are drawn
    /// ([`StreetSession::hand_out`]): the Traffic table's rows too.
    traffic: Vec<(Instant, Decoded)>,
    sent: u64,
    found: bool,
    show: bool,
}

/// The street session.
pub struct StreetSession {
    /// The transport, the page's clock on it, the ACK latency, the work.
    drive: Driver,
    conc: Concentrator,
    /// The street's orchestration, plm-core's.
    street: Street<StreetReply>,
    /// Names the modem's host-interface traffic (bare modem profile).
    decoder: Decoder,
    out: Pending,
    /// When the street's views were last drawn, and whether a change
    /// waits.
    shown: Throttle,
    /// A draw was handed out at a quiet moment of the line: nothing is
    /// sent until the page has painted it.
    hold: crate::wake::Draw,
}

impl StreetSession {
    /// A session over `transport` with `conc` (a board USART or a bare
    /// modem concentrator, as the connection profile says).
    pub fn new(transport: Box<dyn Transport>, conc: Concentrator) -> Self {
        Self::over(Some(transport), conc)
    }

    fn over(transport: Option<Box<dyn Transport>>, conc: Concentrator) -> Self {
        StreetSession {
            drive: Driver::new(transport),
            street: Street::new(&conc),
            conc,
            decoder: Decoder::new(Dialect::St7580, Source::Any),
            out: Pending::default(),
            shown: Throttle::new(STREET_DRAW_US),
            hold: Default::default(),
        }
    }

    /// A session with nothing connected (another profile is in use).
    pub fn idle() -> Self {
        Self::over(None, Concentrator::usart(RequesterConfig::default()))
    }

    /// A session through a concentrator board's USART.
    pub fn via_board(transport: Box<dyn Transport>) -> Self {
        Self::new(transport, Concentrator::usart(RequesterConfig::default()))
    }

    /// Runs a simulated street `speed` times as fast as the page's clock.
    pub fn set_speed(&mut self, speed: u32) {
        self.drive.pacer.speed = speed;
    }

    /// The transport.
    pub fn transport_mut(&mut self) -> Option<&mut (dyn Transport + 'static)> {
        self.drive.transport.as_deref_mut()
    }

    /// Whether bytes flow.
    pub fn state(&self) -> LinkState {
        self.drive
            .transport
            .as_ref()
            .map_or(LinkState::Disconnected("not connected".into()), |t| {
                t.state()
            })
    }

    /// The transport's clock.
    pub fn now(&self) -> Instant {
        self.drive.now()
    }

    /// Transport time the page's ticks have run (µs), and the page's
    /// time that took (µs, the views' not counted): with a simulated
    /// street, its simulated seconds per wall second.
    pub fn work(&self) -> (Duration, f64) {
        self.drive.work()
    }

    /// Its drive loop: how quickly the console ACKs the bare modem's
    /// frames (none through a board, which ACKs its modem itself).
    pub fn driver(&self) -> &Driver {
        &self.drive
    }

    /// The lamps known so far.
    pub fn fleet(&self) -> &std::collections::BTreeMap<Address, Lamp> {
        self.street.fleet()
    }

    /// The sweep's progress.
    pub fn sweep(&self) -> Sweep {
        self.street.sweep()
    }

    /// Whether a discovery is running: the boards found so far and how
    /// many it believes are left ([`Street::discovering`]).
    pub fn discovering(&self) -> Option<(usize, usize)> {
        self.street.discovering()
    }

    /// Requests not yet answered.
    pub fn pending(&self) -> usize {
        self.conc.requester().pending()
    }

    /// The campaign, if one was started.
    pub fn campaign(&self) -> Option<&Campaign> {
        self.street.campaign()
    }

    /// Starts a discovery (a new session: every board answers again).
    pub fn discover(&mut self) {
        let now = self.now();
        self.street.discover(now);
        self.at(now);
        driver::flush(self, now);
    }

    /// Numbers the sessions of the discoveries to come from `last` on
    /// (the next is `last + 1`).
    pub fn set_session(&mut self, last: u8) {
        self.street.set_session(last);
    }

    /// Starts from a street found earlier ([`Street::recall`]).
    pub fn recall(&mut self, session: u8, known: Vec<(Address, Discovered)>) {
        let now = self.now();
        self.street.recall(now, session, known);
    }

    /// What to remember of the street ([`Street::remembered`]).
    pub fn remembered(&self) -> (u8, Vec<(Address, Discovered)>) {
        self.street.remembered()
    }

    /// Turns the background sweep on or off.
    pub fn set_sweep(&mut self, on: bool) {
        let now = self.now();
        self.street.set_sweep(now, on);
    }

    /// Has the street send something now (`f`), and what it sent written
    /// at once.
    fn send<T>(
        &mut self,
        f: impl FnOnce(&mut Street<StreetReply>, &mut Concentrator, Instant) -> T,
    ) -> T {
        let now = self.now();
        let out = f(&mut self.street, &mut self.conc, now);
        driver::flush(self, now);
        out
    }

    /// Reads every parameter of one lamp now.
    pub fn read(&mut self, address: Address) {
        self.send(|s, conc, now| s.read(conc, now, address))
    }

    /// Dims `lamps` ([`Street::dim`]). Refused before anything is sent
    /// when the value is not 0-100.
    pub fn dim(&mut self, lamps: Lamps<'_>, level: u8) -> Result<(), String> {
        self.send(|s, conc, now| s.dim(conc, now, lamps, level))
    }

    /// Sets the clocks of `lamps` to `clock`.
    pub fn set_clock(&mut self, lamps: Lamps<'_>, clock: Clock) -> Result<(), String> {
        self.send(|s, conc, now| s.set_clock(conc, now, lamps, clock))
    }

    /// Sends any request from a view; `reply` gets the answer. Refused
    /// before anything is sent when the board would refuse it.
    pub fn request(&mut self, request: Request, reply: StreetReply) -> Result<(), String> {
        self.send(|s, conc, now| s.request(conc, now, request, reply))
    }

    /// Whether the views' draw is under way at a quiet moment of the
    /// line, to be painted before the street's next request
    /// ([`StreetSession::draw_first`]).
    pub fn drawing(&self) -> bool {
        self.hold.pending()
    }

    /// Whether the discovery or the sweep has the line through a bare
    /// modem: the views are drawn at its quiet moments.
    pub fn busy_over_modem(&self) -> bool {
        self.street.via_modem() && self.street.is_busy()
    }

    /// Whether the street's next requests wait for the page: through a
    /// bare modem, while the views are to be drawn or a draw waits to be
    /// painted ([`StreetSession::draw_first`]).
    fn holds(&self) -> bool {
        self.hold.pending() || self.draw_first()
    }

    /// Tells the street whether the cable is out, and fails what was under
    /// way if it is.
    fn follow_link(&mut self) {
        let down = match self.state() {
            LinkState::Disconnected(why) => Some(why),
            LinkState::Connected => None,
        };
        if let Some(why) = &down {
            if self.conc.requester().pending() > 0 {
                self.conc.abort_all(why);
                let now = self.now();
                driver::flush(self, now);
            }
        }
        self.street.set_down(down);
    }

    /// Whether the street's next requests are to wait for its views to
    /// be drawn: through a bare modem, when they are due, so that the
    /// draw is handed out at the line's quiet moment (the tick's end) and
    /// the requests go once the page has painted it ([`crate::wake::Draw`]).
    /// A draw while the modem's frames may end would hold up their ACKs
    /// (T_ACK, UM0932 3.2.8). Through a board, the board ACKs its modem:
    /// nothing waits.
    fn draw_first(&self) -> bool {
        let changed =
            self.street.changes().changed || self.out.sent > 0 || !self.out.traffic.is_empty();
        self.street.via_modem() && self.shown.due(changed, self.drive.tick_at())
    }

    /// What happened since the last call, without letting time pass.
    pub fn take(&mut self) -> StreetTick {
        let c = self.street.take();
        let out = std::mem::take(&mut self.out);
        StreetTick {
            changed: c.changed,
            alerts: c.alerts,
            replies: c.replies,
            campaign: c.campaign,
            found: c.found || out.found,
            traffic: out.traffic,
            sent: out.sent,
            show: out.show,
        }
    }

    /// What happened since the last call, without letting time pass, and
    /// whether the views are to be drawn at the page's clock `page_us`:
    /// through a bare modem, while the discovery or the sweep has the
    /// line, at its quiet moments ([`StreetSession::draw_first`]) or, after
    /// [`STREET_DRAW_LATE_US`], right after an ACK (a round's replies come
    /// a slot apart: the draw is painted before the next frame ends);
    /// else at most every [`STREET_DRAW_US`].
    pub fn hand_out(&mut self, page_us: f64) -> StreetTick {
        let (after, quiet) = if self.busy_over_modem() {
            (STREET_DRAW_LATE_US, self.drive.just_acked(page_us))
        } else {
            (STREET_DRAW_US, true)
        };
        let mut tick = self.take();
        let changed = tick.changed || tick.sent > 0 || !tick.traffic.is_empty();
        tick.show |= quiet && self.shown.show_after(changed, page_us, after);
        // Counted on until the views show it; the street found is kept
        // then too (the browser's storage written at a quiet moment), and
        // the Traffic table's rows (a redraw of it while a modem's frame
        // may end holds up its ACK).
        if !tick.show {
            self.out.sent = tick.sent;
            self.out.found = tick.found;
            self.out.traffic = std::mem::take(&mut tick.traffic);
        }
        tick
    }

    /// Lets the transport's time catch up with the page's clock.
    pub fn tick(&mut self, page_us: f64, budget: Budget) -> StreetTick {
        self.hold.settle();
        self.follow_link();
        driver::tick(self, page_us, budget);
        self.hand_out(page_us)
    }

    /// Runs the street as fast as possible up to `target` (tests).
    /// The replies wait in [`StreetSession::take`].
    pub fn run_until(&mut self, start: Instant, target: Instant) {
        let mut t = start;
        while t < target && self.drive.transport.is_some() {
            self.hold.settle();
            self.follow_link();
            driver::run_within(self, t, target, Budget::UNLIMITED);
            t = self.now();
        }
    }

    /// The next instant on the transport's clock at which something is
    /// due: the concentrator's, the street's (what a draw holds goes once
    /// the page has painted it, which runs the page again) and the
    /// transport's next event.
    pub fn next_due(&self) -> Option<Instant> {
        earliest([
            self.conc.poll_timeout(),
            self.street.poll_timeout(self.now(), self.holds()),
            self.drive.transport.as_ref().and_then(|t| t.next_event()),
        ])
    }

    /// [`StreetSession::next_due`] on the page's clock (µs).
    pub fn next_wake(&self) -> Option<f64> {
        self.next_due().and_then(|t| self.drive.pacer.page_at(t))
    }

    fn link_traffic(&mut self, now: Instant, el: &Element, from: &str) {
        let mut d = self.decoder.decode(el);
        d.from = Some(from.to_string());
        self.out.traffic.push((now, d));
    }
}

/// The street on the console's one drive loop.
impl Layer for StreetSession {
    /// Through a bare modem the console's host engine ACKs its frames;
    /// through a board, the board does.
    fn acks(&self) -> bool {
        self.street.via_modem()
    }

    fn parts(&mut self) -> (&mut AnyEngine, &mut Driver) {
        (&mut self.conc, &mut self.drive)
    }

    /// The frame named for the Traffic view; then the street has it.
    fn on_event(&mut self, now: Instant, h: Happening) {
        match &h {
            Happening::Usart { to_board, element } => {
                let d = plm_core::decode::app::decode_element(element);
                let from = if *to_board { "host" } else { "board" };
                self.out.sent += *to_board as u64;
                self.out.traffic.push((now, d.to_decoded(from)));
            }
            Happening::Link(host::Event::Sent(el)) => {
                self.out.sent += matches!(el, Element::Frame { .. }) as u64;
                self.link_traffic(now, el, "host");
            }
            Happening::Link(host::Event::Received(el)) => self.link_traffic(now, el, "modem"),
            _ => {}
        }
        self.street.handle(&mut self.conc, now, h);
    }

    fn next_due(&self) -> Option<Instant> {
        StreetSession::next_due(self)
    }

    /// The street's next requests, as the line allows; a request held
    /// for the views' draw has it handed out at the tick's end, and
    /// nothing is sent until the page has painted it.
    fn at(&mut self, now: Instant) {
        // Painted already (or no page paints: a test's own loop).
        self.hold.settle();
        let hold = self.holds();
        self.street.pump(&mut self.conc, now, hold);
        if self.street.is_held() && !self.hold.pending() {
            self.out.show = self.shown.show_after(true, self.drive.tick_at(), 0.0);
            self.hold.begin();
        }
    }

    /// Replies go to the views at the instant they came: a reply may send
    /// the next request.
    fn stop(&self) -> bool {
        !self.street.changes().replies.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fleet::Look;
    use crate::transport::sim::SimTransport;
    use crate::transport::LampAction;
    use plm_core::app::{Clock, LampState, Service};
    use plm_core::st7580::TxParams;
    use plm_core::time::MS;
    use plm_sim::board::street_address;
    use plm_sim::{Attach, StreetProfile};

    const S: Duration = 1_000 * MS;
    const LAMPS: usize = 50;

    fn session(via: Attach) -> StreetSession {
        let t = Box::new(SimTransport::street(
            LAMPS,
            via,
            57_600,
            3,
            StreetProfile::Uniform,
        ));
        let conc = match via {
            Attach::Board => Concentrator::usart(RequesterConfig::default()),
            Attach::Modem => Concentrator::modem(
                RequesterConfig::default(),
                57_600,
                street_address(0),
                TxParams::default(),
            ),
        };
        StreetSession::new(t, conc)
    }

    /// Runs `d` of the street's time; calls the replies, as the console
    /// does, and returns the alerts.
    fn run(s: &mut StreetSession, d: Duration) -> Vec<Alert> {
        let start = s.now();
        s.run_until(start, start + d);
        let tick = s.take();
        for (reply, r) in tick.replies {
            reply(r);
        }
        tick.alerts
    }

    /// A street of 50: discovery, the sweep reading every lamp, dimming
    /// one and all (broadcast), every clock set, a failed lamp and an
    /// unreachable one raised as alerts: through the board's USART and
    /// through a bare modem. All of it is plm-core's `Street`, the machine
    /// `plm board status all` and plm-sim's `tests/street_machine.rs`
    /// run, here on the console's driver.
    #[test]
    fn a_street_is_found_read_dimmed_and_watched_by_plm_cores_street() {
        for via in [Attach::Board, Attach::Modem] {
            let mut s = session(via);
            s.discover();
            run(&mut s, 90 * S);
            assert_eq!(s.fleet().len(), LAMPS, "{via:?}: every lamp found");
            assert!(s.sweep().on, "a street just found is swept");
            run(&mut s, 60 * S);
            for lamp in s.fleet().values() {
                assert_eq!(
                    lamp.state(),
                    Some(LampState::Run),
                    "{via:?} {}",
                    lamp.address
                );
                assert!(lamp.snr.is_some(), "{via:?} {}: SNR known", lamp.address);
            }
            let a3 = street_address(3);
            let full = s.fleet()[&a3].ballast.unwrap().lamp_power;
            s.dim(Lamps::These(&[a3]), 20).unwrap();
            run(&mut s, 10 * S);
            let dimmed = s.fleet()[&a3].ballast.unwrap().lamp_power;
            assert!(
                dimmed < full,
                "{via:?}: {dimmed} W after dimming, {full} W before"
            );
            assert_eq!(s.fleet()[&a3].dimming, Some(20));

            assert!(
                s.dim(Lamps::All, 101).is_err(),
                "refused before anything is sent"
            );
            s.dim(Lamps::All, 60).unwrap();
            run(&mut s, 60 * S);
            assert!(s.fleet().values().all(|l| l.dimming == Some(60)));
            let full = s.fleet()[&street_address(40)].ballast.unwrap().lamp_power;
            assert_eq!(full, 120, "{via:?}: 150 W × (0.5 + 0.5 × 60 %)");

            let noon = Clock {
                hours: 12,
                minutes: 0,
                seconds: 0,
            };
            let set = Request::all(Message::Service(Service::ClockSet(noon)));
            s.request(set, Box::new(|_| {})).unwrap();
            run(&mut s, 2 * S);
            let clock = std::rc::Rc::new(std::cell::Cell::new(None));
            let got = clock.clone();
            let get = Request::to(street_address(LAMPS), Message::Service(Service::ClockGet));
            s.request(get, Box::new(move |r| got.set(Some(r)))).unwrap();
            run(&mut s, 10 * S);
            match clock.take() {
                Some(Ok(Message::Service(Service::ClockNow(c)))) => {
                    assert!(
                        c.seconds_of_day().abs_diff(noon.seconds_of_day()) < 20,
                        "{via:?}: {c}"
                    )
                }
                other => panic!("{via:?}: {other:?}"),
            }

            let t = s.transport_mut().unwrap().simulator().unwrap();
            t.lamp(street_address(5), LampAction::Fail);
            t.lamp(street_address(8), LampAction::Cut);
            let alerts = run(&mut s, 60 * S);
            let about = |n: usize| {
                alerts
                    .iter()
                    .filter(move |a| a.address == street_address(n))
            };
            assert!(
                about(5).any(|a| a.what.starts_with("lamp failed")),
                "{via:?}: {alerts:?}"
            );
            assert!(
                about(8).any(|a| a.what.starts_with("stopped answering")),
                "{via:?}: {alerts:?}"
            );
            assert!(Look::of(&s.fleet()[&street_address(5)]).in_trouble());
            assert!(Look::of(&s.fleet()[&street_address(8)]).in_trouble());
            assert!(!Look::of(&s.fleet()[&street_address(6)]).in_trouble());
        }
    }

    /// A round of the sweep reads 50 lamps in slots (four requests at most), asks
    /// the SNR of at most five (one in ten) through the board and none
    /// through a bare modem, and ends with one probe frame: about a tenth
    /// of the frames and half the line time of one round trip per lamp.
    #[test]
    fn a_round_reads_the_street_in_slots() {
        for via in [Attach::Board, Attach::Modem] {
            let mut s = session(via);
            s.discover();
            // Past the first minute: every SNR figure is old.
            run(&mut s, 90 * S);
            // 10 ms of the street; the frames sent towards it.
            let step = |s: &mut StreetSession| {
                let start = s.now();
                s.run_until(start, start + 10 * MS);
                s.take().sent
            };
            while s.sweep().total > 0 {
                step(&mut s);
            }
            let rounds = s.sweep().rounds;
            let mut sent = 0;
            while s.sweep().total == 0 {
                sent = step(&mut s);
            }
            let start = s.now();
            while s.sweep().rounds == rounds {
                sent += step(&mut s);
            }
            let took = s.now() - start;
            // At most four requests in slots (15 lamps a request at
            // least) and the probe; through the board, the SNR of five.
            let (snr, slots) = match via {
                Attach::Board => (5, 1..=4),
                Attach::Modem => (0, 1..=4),
            };
            assert!(
                slots.contains(&(sent - snr - 1)),
                "{via:?}: {sent} frames sent in a round"
            );
            assert!(took < 5 * S, "{via:?}: a round took {} ms", took / MS);
            assert!(s.fleet().values().all(|l| l.unreachable.is_none()));
        }
    }

    /// A street remembered after a reload: its lamps in the fleet at once
    /// and read before any discovery frame; then a discovery of the same
    /// session finds the lamp that was off before, while the lamps heard
    /// in that session stay quiet (what was recalled of them is not
    /// overwritten by a new reply). Discover then starts a new session,
    /// which every lamp answers.
    #[test]
    fn a_street_remembered_is_read_at_once_and_only_new_lamps_are_looked_for() {
        let usart = || Concentrator::usart(RequesterConfig::default());
        let t = Box::new(SimTransport::street(
            6,
            Attach::Board,
            57_600,
            5,
            StreetProfile::Uniform,
        ));
        let mut s = StreetSession::new(t, usart());
        let late = street_address(6);
        let sim = s.transport_mut().unwrap().simulator().unwrap();
        sim.lamp(late, LampAction::Cut);
        s.discover();
        run(&mut s, 30 * S);
        let (session, mut known) = s.remembered();
        assert_eq!((session, known.len()), (1, 5));
        // What was kept says stack 9.9: a lamp that answers again says 1.x.
        for (_, d) in known.iter_mut() {
            d.stack = plm_core::app::Release { major: 9, minor: 9 };
        }

        // The page reloads; the boards keep what they were told.
        let mut t = s.drive.transport.take().unwrap();
        t.simulator().unwrap().lamp(late, LampAction::Join);
        let mut s = StreetSession::new(t, usart());
        s.recall(session, known.clone());
        assert_eq!(s.fleet().len(), 5, "the lamps are in the fleet at once");
        assert!(s.take().changed);
        let mut discovery_seen = false;
        for _ in 0..300 {
            run(&mut s, 100 * MS);
            if s.discovering().is_some() {
                discovery_seen = true;
                let unread: Vec<_> = known
                    .iter()
                    .filter(|(a, _)| s.fleet()[a].state().is_none())
                    .collect();
                assert!(unread.is_empty(), "read before any discovery: {unread:?}");
            }
        }
        assert!(discovery_seen, "a discovery looked for new lamps");
        assert!(s.discovering().is_none());
        assert_eq!(s.fleet().len(), 6, "the lamp powered later is found");
        assert!(s.fleet()[&late].discovered.is_some());
        for (a, d) in &known {
            assert_eq!(s.fleet()[a].discovered, Some(*d), "{a} stayed quiet");
        }
        assert_eq!(s.remembered().0, session, "the same session");
        assert_eq!(s.remembered().1.len(), 6);

        s.discover();
        run(&mut s, 30 * S);
        assert_eq!(s.remembered().0, session + 1, "Discover: a new session");
        for (a, _) in &known {
            let stack = s.fleet()[a].discovered.unwrap().stack;
            assert_ne!(stack.major, 9, "{a} answered the new session");
        }
    }

    /// A lamp powered after the discovery is found by a sweep's probe (one
    /// short frame of the same session after each round), without a
    /// discovery the page shows; the lamps already heard stay quiet.
    #[test]
    fn a_lamp_powered_later_is_found_by_the_sweep() {
        let usart = Concentrator::usart(RequesterConfig::default());
        let t = Box::new(SimTransport::street(
            6,
            Attach::Board,
            57_600,
            7,
            StreetProfile::Uniform,
        ));
        let mut s = StreetSession::new(t, usart);
        let late = street_address(4);
        let sim = s.transport_mut().unwrap().simulator().unwrap();
        sim.lamp(late, LampAction::Cut);
        s.discover();
        run(&mut s, 30 * S);
        assert_eq!(s.fleet().len(), 5);
        let sim = s.transport_mut().unwrap().simulator().unwrap();
        sim.lamp(late, LampAction::Join);
        let mut shown = false;
        for _ in 0..400 {
            run(&mut s, 100 * MS);
            shown |= s.discovering().is_some() && s.fleet().len() == 5;
            if s.fleet().contains_key(&late) {
                break;
            }
        }
        assert!(
            s.fleet().contains_key(&late),
            "the lamp powered later is found"
        );
        assert!(!shown, "a sweep's probe is not a discovery the page shows");
        assert_eq!(s.remembered().0, 1, "in the same session");
    }

    /// A street remembered with no lamp is discovered again, in a new
    /// session.
    #[test]
    fn a_street_remembered_empty_is_discovered_again() {
        let t = Box::new(SimTransport::street(
            3,
            Attach::Board,
            57_600,
            6,
            StreetProfile::Uniform,
        ));
        let mut s = StreetSession::new(t, Concentrator::usart(RequesterConfig::default()));
        s.recall(4, Vec::new());
        assert_eq!(s.remembered().0, 5);
        run(&mut s, 30 * S);
        assert_eq!(s.fleet().len(), 3);
    }

    /// Random failures set from the console (the Simulator view's rate)
    /// reach every lamp of the street and come back as alerts; at rate 0
    /// nothing fails.
    #[test]
    fn random_failures_at_the_rate_set_are_raised() {
        let failures_at = |rate: f64| {
            let t = Box::new(SimTransport::street(
                6,
                Attach::Board,
                57_600,
                4,
                StreetProfile::Uniform,
            ));
            let mut s = StreetSession::new(t, Concentrator::usart(RequesterConfig::default()));
            s.discover();
            run(&mut s, 30 * S);
            assert_eq!(s.fleet().len(), 6);
            let sim = s.transport_mut().unwrap().simulator().unwrap();
            sim.set_failure_rate(rate);
            let alerts = run(&mut s, 180 * S);
            alerts
                .iter()
                .filter(|a| a.what.starts_with("lamp failed"))
                .count()
        };
        assert_eq!(failures_at(0.0), 0);
        // 60 per lit hour: each lamp fails about once a minute.
        assert!(failures_at(60.0) >= 2);
    }
}
