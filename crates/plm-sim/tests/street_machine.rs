//! plm-core's street orchestration (`app::street::Street`: discovery, the
//! sweep, dimming, the update campaign, the fleet and its alerts) driven
//! by plm-core's one loop (`job::drive`) over a simulated street, through
//! a board's USART and through a bare ST7580. The console's street
//! session and `plm board status all` run the same machine.

use plm_core::app::job::Router;
use plm_core::app::street::{Lamps, Street};
use plm_core::app::update::BoardState;
use plm_core::app::{
    Clock, Concentrator, Happening, LampState, Message, Release, Request, RequesterConfig, Service,
};
use plm_core::time::{Duration, Instant, MS};
use plm_sim::board::street_address;
use plm_sim::rfu::firmware_image;
use plm_sim::{Attach, Sim, SimConfig, StreetDriver};

const S: Duration = 1_000 * MS;

/// The street driven for a given time, not only until it is idle (its
/// next sweep waited for too).
struct For<'a>(&'a mut Street<()>);

impl Router for For<'_> {
    fn pump(&mut self, conc: &mut Concentrator, now: Instant) {
        self.0.pump(conc, now, false)
    }
    fn handle(&mut self, conc: &mut Concentrator, now: Instant, h: &Happening) {
        self.0.handle(conc, now, h.clone())
    }
    fn poll_timeout(&self, now: Instant) -> Option<Instant> {
        self.0.poll_timeout(now, false)
    }
    fn is_done(&self) -> bool {
        false
    }
}

fn street(lamps: usize, via: Attach) -> (StreetDriver, Street<()>) {
    let sim = Sim::new(SimConfig {
        seed: 21,
        ..SimConfig::street(lamps, via)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2 * S);
    let street = Street::new(&d.conc);
    (d, street)
}

/// A street of 60 found and read in one go (discovery, then the sweep's
/// first round, in slots), one lamp dimmed and read again, the clocks of
/// a selection set (one read back by a caller's request), two lamps
/// updated while the sweep waits (it comes back after, the fleet showing
/// the new release), and a lamp failing raised as an alert by a later
/// round.
#[test]
fn plm_cores_street_finds_reads_dims_updates_and_watches_a_street() {
    for via in [Attach::Board, Attach::Modem] {
        let lamps = 60;
        let (mut d, mut s) = street(lamps, via);
        s.discover(d.now());
        let start = d.now();
        assert!(d.drive(&mut s, 300 * S), "{via:?}: idle again");
        let took = d.now() - start;
        assert_eq!(s.fleet().len(), lamps, "{via:?}: every lamp found");
        assert!(
            s.fleet()
                .values()
                .all(|l| l.state() == Some(LampState::Run)),
            "{via:?}: every lamp read"
        );
        let sweep = s.sweep();
        assert_eq!(sweep.rounds, 1, "{via:?}");
        assert!(s.in_slots() > lamps / 2, "{via:?}: {}", s.in_slots());
        assert!(took < 60 * S, "{via:?}: {} s", took / S);

        let a = street_address(7);
        let full = s.fleet()[&a].ballast.unwrap().lamp_power;
        let now = d.now();
        s.dim(&mut d.conc, now, Lamps::These(&[a]), 20).unwrap();
        assert!(s.dim(&mut d.conc, now, Lamps::All, 101).is_err());
        assert!(d.drive(&mut s, 30 * S), "{via:?}");
        let lamp = &s.fleet()[&a];
        assert_eq!(lamp.dimming, Some(20), "{via:?}");
        assert!(
            lamp.ballast.unwrap().lamp_power < full,
            "{via:?}: read again"
        );

        // The clocks of a selection set, one read back.
        let noon = Clock {
            hours: 12,
            minutes: 0,
            seconds: 0,
        };
        let picked = [street_address(3), street_address(4)];
        let now = d.now();
        s.set_clock(&mut d.conc, now, Lamps::These(&picked), noon)
            .unwrap();
        assert!(d.drive(&mut s, 30 * S), "{via:?}");
        s.take();
        let get = Request::to(picked[1], Message::Service(Service::ClockGet));
        let now = d.now();
        s.request(&mut d.conc, now, get, ()).unwrap();
        assert!(d.drive(&mut s, 30 * S), "{via:?}");
        match &s.take().replies[..] {
            [((), Ok(Message::Service(Service::ClockNow(c))))] => assert!(
                c.seconds_of_day().abs_diff(noon.seconds_of_day()) < 10,
                "{via:?}: {c}"
            ),
            other => panic!("{via:?}: {other:?}"),
        }

        let new = Release { major: 1, minor: 7 };
        let targets = [street_address(1), street_address(2)];
        s.start_update(d.now(), firmware_image(new, 3_000), None, &targets)
            .unwrap();
        assert!(!s.sweep().on, "{via:?}: the sweep waits for the update");
        assert!(d.drive(&mut s, 600 * S), "{via:?}");
        let c = s.campaign().unwrap();
        let u = c.update();
        assert!(
            u.boards().all(|(_, st)| *st == BoardState::Done),
            "{via:?}: {:?}",
            u.report()
        );
        assert!(c.ended.is_some());
        for t in targets {
            assert_eq!(s.fleet()[&t].discovered.unwrap().firmware, new, "{via:?}");
        }
        assert!(s.sweep().on, "{via:?}: the sweep is back");
        s.dismiss_update();
        assert!(s.campaign().is_none());

        let failing = street_address(9);
        d.sim_mut()
            .with_board(9, |b, now| b.ballast_mut().unwrap().fail(now));
        s.take();
        let until = d.now() + 20 * S;
        d.drive(&mut For(&mut s), until - d.now());
        let alerts = s.take().alerts;
        assert!(
            alerts
                .iter()
                .any(|x| x.address == failing && x.what.starts_with("lamp failed")),
            "{via:?}: {alerts:?}"
        );
    }
}
