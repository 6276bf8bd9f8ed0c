//! A street of simulated controller boards driven by plm-core's
//! concentrator in virtual time, through both ways in: a concentrator
//! board's USART and a bare ST7580 (docs/architecture.md, "Connection
//! profiles").

use plm_core::app::hid::{self, Hid, LampState};
use plm_core::app::service::{Clock, Service};
use plm_core::app::{AppEvent, Ballast, Message, Request, RequesterConfig};
use plm_core::time::{Duration, MS};
use plm_sim::board::street_address;
use plm_sim::{Attach, ByteFaults, Dir, LineConfig, Sim, SimConfig, StreetDriver};

const S: Duration = 1_000 * MS;

fn street(lamps: usize, via: Attach, seed: u64) -> StreetDriver {
    let sim = Sim::new(SimConfig {
        seed,
        ..SimConfig::street(lamps, via)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2 * S);
    d
}

fn all_parameters(d: &mut StreetDriver, node: usize) -> Result<Ballast, String> {
    match d.ask(
        street_address(node),
        Message::Hid(Hid::Get(hid::ALL)),
        30 * S,
    )? {
        Message::Hid(Hid::Reply { value, .. }) => {
            Ballast::decode(&value).ok_or("short reply".into())
        }
        m => Err(format!("{m:?}")),
    }
}

fn journey(via: Attach) {
    let lamps = 50;
    let mut d = street(lamps, via, 7);

    // Discover every board.
    let found = d.discover(plm_core::app::discovery::DiscoveryConfig::new(1, lamps));
    let missing: Vec<usize> = (1..=lamps)
        .filter(|n| !found.contains_key(&street_address(*n)))
        .collect();
    assert!(missing.is_empty(), "{via:?}: lamps not found: {missing:?}");
    assert_eq!(
        found.len(),
        lamps,
        "{via:?}: nothing but the street's lamps"
    );

    // Read every lamp: all lit.
    for node in 1..=lamps {
        let b = all_parameters(&mut d, node).unwrap_or_else(|e| panic!("{via:?} node {node}: {e}"));
        assert_eq!(b.state(), LampState::Run, "{via:?} node {node}");
        assert!(b.lamp_power > 0);
    }

    // Dim every lamp by broadcast; the power follows.
    let full = all_parameters(&mut d, 3).unwrap().lamp_power;
    let sent = d.request(Request::all(Message::Hid(Hid::Dimming(30))), 10 * S);
    assert!(matches!(sent, Some(AppEvent::Sent { .. })), "{sent:?}");
    d.run_for(5 * S);
    for node in [1, 17, lamps] {
        let b = all_parameters(&mut d, node).unwrap();
        assert!(
            b.lamp_power < full,
            "{via:?} node {node}: {} W dimmed vs {full} W",
            b.lamp_power
        );
        assert_eq!(d.sim.board(node).unwrap().ballast().unwrap().dimming(), 30);
    }

    // Set every clock by broadcast.
    let noon = Clock {
        hours: 12,
        minutes: 0,
        seconds: 0,
    };
    d.request(
        Request::all(Message::Service(Service::ClockSet(noon))),
        10 * S,
    );
    d.run_for(2 * S);
    for node in [2, lamps] {
        match d.ask(
            street_address(node),
            Message::Service(Service::ClockGet),
            30 * S,
        ) {
            Ok(Message::Service(Service::ClockNow(c))) => {
                let drift = c.seconds_of_day().abs_diff(noon.seconds_of_day());
                assert!(drift <= 5, "{via:?} node {node}: {c} after setting {noon}");
            }
            other => panic!("{via:?} node {node}: {other:?}"),
        }
    }

    // A lamp fails: its state says so.
    let now = d.now();
    d.sim
        .with_board(11, |b, _| b.ballast_mut().unwrap().fail(now));
    let b = all_parameters(&mut d, 11).unwrap();
    assert_eq!(b.state(), LampState::Failure, "{via:?}");
    assert_eq!(b.lamp_power, 0);

    // A board loses its supply: the request fails in words.
    d.sim.set_cut(23, true);
    let e = all_parameters(&mut d, 23).unwrap_err();
    assert!(e.contains("did not answer"), "{via:?}: {e}");
}

#[test]
fn a_street_of_50_through_the_concentrator_board() {
    journey(Attach::Board);
}

#[test]
fn a_street_of_50_through_a_bare_modem() {
    journey(Attach::Modem);
}

/// A street 25 times the console's first guess (12): every lamp is found.
/// Each board waits for a quiet line to send its reply (its modem's "not
/// now"); a crowd's replies used to spill past their frame onto the next
/// request, which no board then heard, and the silence ended the
/// discovery with 1 lamp of 300 found (seed 7). A reply not gone by its
/// frame's slots' end is given up now ([`Responder::on_request`]).
///
/// [`Responder::on_request`]: plm_core::app::discovery::Responder::on_request
#[test]
fn a_street_far_larger_than_guessed_is_found_whole() {
    for (via, seed) in [(Attach::Board, 7), (Attach::Modem, 7580)] {
        let lamps = 300;
        let mut d = street(lamps, via, seed);
        let found = d.discover(plm_core::app::discovery::DiscoveryConfig::new(1, 12));
        assert_eq!(found.len(), lamps, "{via:?}, seed {seed}");
    }
}

/// UART faults on the concentrator's cable and losses on the line: no
/// dimming the concentrator saw acknowledged is missing on its lamp.
#[test]
fn faults_lose_no_acknowledged_command() {
    for via in [Attach::Board, Attach::Modem] {
        let mut d = street(8, via, 11);
        d.sim.set_line(LineConfig {
            loss: 0.05,
            ..d.sim.line().clone()
        });
        let faults = ByteFaults {
            drop: 0.002,
            corrupt: 0.002,
            ..ByteFaults::default()
        };
        d.sim.set_byte_faults(Dir::HostToModem, faults);
        d.sim.set_byte_faults(Dir::ModemToHost, faults);
        let (mut acked, mut failed) = (0, 0);
        for i in 0..60u8 {
            let node = 1 + i as usize % 8;
            let level = 10 + i;
            match d.request(
                Request::to(street_address(node), Message::Hid(Hid::Dimming(level))),
                60 * S,
            ) {
                Some(AppEvent::Answered {
                    answer: Message::Ack { .. },
                    ..
                }) => {
                    acked += 1;
                    let dim = d.sim.board(node).unwrap().ballast().unwrap().dimming();
                    assert_eq!(
                        dim, level,
                        "{via:?}: an acknowledged dimming is on the lamp"
                    );
                }
                Some(AppEvent::Failed { .. }) => failed += 1,
                other => panic!("{via:?}: {other:?}"),
            }
        }
        assert!(acked > 40, "{via:?}: {acked} acknowledged, {failed} failed");
    }
}

/// SERVICE_RFU_SET_IMG_DATA with segment `n` of `image`.
fn rfu_segment(campaign: u8, image: &[u8], n: usize) -> Service {
    Service::RfuData {
        campaign,
        segment: n as u16,
        data: plm_core::app::rfu::segment_of(image, n).to_vec(),
    }
}

/// Remote firmware update of one lamp over the power line, through the
/// concentrator board: header, segments (one held back), the status
/// naming what is missing, the swap, and the new release reported once
/// the board has restarted; its neighbour keeps the old one.
#[test]
fn one_lamp_is_updated_over_the_line() {
    use plm_core::app::rfu::{self, Header, RfuState};
    use plm_core::app::Release;
    use plm_sim::rfu::{firmware_image, CONFIRM_AFTER, SWAP_RESET};

    let mut d = street(3, Attach::Board, 11);
    let lamp = street_address(2);
    let new = Release { major: 1, minor: 5 };
    let image = firmware_image(new, 2_000);
    let h = Header::of(1, new, &image);
    let ack = |s: &Service| Message::Service(s.clone()).ack();
    let header = Service::RfuHeader(h);
    assert_eq!(
        d.ask(lamp, Message::Service(header.clone()), 30 * S),
        Ok(ack(&header))
    );

    let segment = |n: usize| rfu_segment(1, &image, n);
    let status = |d: &mut StreetDriver| match d.ask(
        lamp,
        Message::Service(Service::RfuStatusGet { campaign: 1 }),
        30 * S,
    ) {
        Ok(Message::Service(Service::RfuStatus(s))) => s,
        other => panic!("{other:?}"),
    };
    for n in (0..h.segments()).filter(|n| *n != 5) {
        d.send(Message::Service(segment(n)).to(lamp));
        d.run_for(250 * MS);
    }
    let missing: Vec<usize> = status(&mut d).missing(h.segments()).collect();
    assert!(missing.contains(&5), "{missing:?}");
    for n in missing {
        d.send(Message::Service(segment(n)).to(lamp));
        d.run_for(250 * MS);
    }
    assert_eq!(status(&mut d).state(), Some(RfuState::Complete));

    let swap = Service::RfuSwap {
        campaign: 1,
        crc: rfu::image_crc(&image),
    };
    assert_eq!(
        d.ask(lamp, Message::Service(swap.clone()), 30 * S),
        Ok(ack(&swap))
    );
    d.run_for(SWAP_RESET + CONFIRM_AFTER + S);
    let release = |d: &mut StreetDriver, node: usize| match d.ask(
        street_address(node),
        Message::Service(Service::FwRelGet),
        30 * S,
    ) {
        Ok(Message::Service(Service::FwRel { firmware, .. })) => firmware,
        other => panic!("{other:?}"),
    };
    assert_eq!(release(&mut d, 2), new);
    assert_eq!(release(&mut d, 1), plm_sim::board::FIRMWARE);
    assert_eq!(status(&mut d).state(), Some(RfuState::Done));

    // A second update, cut off by a supply cut halfway: the board comes
    // back on the release it ran, with no campaign, and takes the update
    // again from its header.
    let newer = Release { major: 1, minor: 6 };
    let image = firmware_image(newer, 1_500);
    let h = Header::of(2, newer, &image);
    let header = Service::RfuHeader(h);
    assert_eq!(
        d.ask(lamp, Message::Service(header.clone()), 30 * S),
        Ok(ack(&header))
    );
    let segment = |n: usize| rfu_segment(2, &image, n);
    for n in 0..h.segments() / 2 {
        d.send(Message::Service(segment(n)).to(lamp));
        d.run_for(250 * MS);
    }
    d.sim_mut().set_cut(2, true);
    d.run_for(2 * S);
    d.sim_mut().set_cut(2, false);
    d.run_for(2 * S);
    assert_eq!(release(&mut d, 2), new);
    let s = match d.ask(
        lamp,
        Message::Service(Service::RfuStatusGet { campaign: 2 }),
        30 * S,
    ) {
        Ok(Message::Service(Service::RfuStatus(s))) => s,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        (s.campaign, s.state(), s.received),
        (2, Some(RfuState::Idle), 0)
    );
    assert_eq!(
        d.ask(lamp, Message::Service(header.clone()), 30 * S),
        Ok(ack(&header))
    );
    for n in 0..h.segments() {
        d.send(Message::Service(segment(n)).to(lamp));
        d.run_for(250 * MS);
    }
    let swap = Service::RfuSwap {
        campaign: 2,
        crc: h.crc,
    };
    assert_eq!(
        d.ask(lamp, Message::Service(swap.clone()), 30 * S),
        Ok(ack(&swap))
    );
    d.run_for(SWAP_RESET + CONFIRM_AFTER + S);
    assert_eq!(release(&mut d, 2), newer);
}

/// The update engine puts a new release on a whole street (segments
/// broadcast, then each board's missing ones repaired, swaps one by one),
/// on a line that loses frames; an image that does not start is reported
/// per board in words, and the boards keep their release.
#[test]
fn a_street_is_updated_by_the_engine() {
    use plm_core::app::update::{BoardState, Update, UpdateConfig};
    use plm_core::app::Release;
    use plm_sim::rfu::firmware_image;

    let mut d = street(5, Attach::Board, 13);
    let line = LineConfig {
        loss: 0.1,
        ..d.sim_mut().line().clone()
    };
    d.sim_mut().set_line(line);
    let targets: Vec<_> = (1..=5).map(street_address).collect();
    let new = Release { major: 1, minor: 5 };
    let mut u = Update::new(
        3,
        new,
        firmware_image(new, 4_000),
        &targets,
        UpdateConfig::default(),
    )
    .unwrap();
    let start = d.now();
    d.update(&mut u);
    let took = (d.now() - start) as f64 / 1e6;
    for (a, s) in u.boards() {
        assert_eq!(*s, BoardState::Done, "{a}: {:?}", u.report());
    }
    assert!(took < 120.0, "{took:.1} s");

    // An image without the firmware's mark: every board goes back.
    let bad: Vec<u8> = (0..3_000u32).map(|i| (i * 7) as u8).collect();
    let newer = Release { major: 1, minor: 6 };
    let mut u = Update::new(4, newer, bad, &targets[..2], UpdateConfig::default()).unwrap();
    d.update(&mut u);
    for (a, words) in u.report() {
        assert!(words.contains("came back on release 1.5"), "{a}: {words}");
    }
}
