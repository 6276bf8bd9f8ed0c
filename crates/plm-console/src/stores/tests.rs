//! The console's coordinator, natively: what the stores hold, as the
//! views read them, after the page's clock has run, on the simulated
//! modem and street. Each test is a page: a console on its own reactive
//! owner, ticked as the page's wake does ([`Console::tick`]).

use super::*;
use crate::clock::set_page_now_us;
use crate::street::{STREET_DRAW_LATE_US, STREET_DRAW_US};
use crate::transport::LampAction;
use plm_core::link::Timeouts;
use plm_core::st7580::mib::index;
use plm_sim::Fault;

/// A console showing `profile`, its simulated world `speed` times as fast
/// as the page's clock, which starts at 0.
fn console(profile: Profile, speed: u32) -> (Owner, Console) {
    set_page_now_us(0.0);
    let owner = Owner::new();
    let c = owner.with(provide_console);
    c.sim.speed.set(speed);
    c.set_profile(profile);
    (owner, c)
}

/// Moves the page's clock to each tick, as the page's wake does: when
/// a session has something due, 4 ms later at most (a busy page's
/// timers), until `done` holds or `limit_s` seconds of the page's clock
/// have passed; whether `done` held.
fn run_until(c: &Console, limit_s: f64, mut done: impl FnMut(&Console) -> bool) -> bool {
    let end = crate::clock::page_now_us() + limit_s * 1e6;
    while !done(c) {
        let now = crate::clock::page_now_us();
        let wake = [
            c.session().borrow().next_wake(),
            c.street.read(|s| s.next_wake()),
        ]
        .into_iter()
        .flatten()
        .fold(now + 4_000.0, f64::min);
        let t = wake.max(now + 10.0);
        if t > end {
            return false;
        }
        set_page_now_us(t);
        c.tick();
    }
    true
}

/// The titles of the traffic store's entries, oldest first.
fn titles(c: &Console) -> Vec<String> {
    c.traffic
        .log
        .with_untracked(|l| l.iter().map(|e| e.title()).collect())
}

/// Sends `command`; the outcome lands in the returned cell.
fn ask(c: &Console, command: Command) -> Rc<RefCell<Option<Outcome<Command>>>> {
    let got = Rc::new(RefCell::new(None));
    let g = got.clone();
    c.request(command, move |o| *g.borrow_mut() = Some(o));
    got
}

#[test]
fn a_request_is_answered_and_its_exchange_reaches_the_traffic_and_connection_stores() {
    let (_owner, c) = console(Profile::Modem, 1);
    let data = vec![1, 2, 3];
    let got = ask(&c, Command::PingRequest { data: data.clone() });
    assert!(run_until(&c, 2.0, |_| got.borrow().is_some()));
    match got.borrow_mut().take() {
        Some(Outcome::Answer {
            command: Command::PingConfirm { data: echoed },
            ..
        }) => assert_eq!(echoed, data),
        other => panic!("{other:?}"),
    }
    // The notes are handed out once the answer came and the page's
    // pace allows.
    assert!(run_until(&c, 1.0, |c| titles(c).contains(&"PingConfirm".into())));
    let t = titles(&c);
    let at = |name: &str| t.iter().position(|x| x == name).expect(name);
    assert!(at("PingRequest") < at("PingConfirm"), "{t:?}");
    assert!(t.contains(&"status message".into()), "{t:?}");
    assert!(c.conn.state.get_untracked().is_connected());
    assert_eq!(c.conn.kind.get_untracked(), "Simulated");
    assert!(
        !c.conn.treq.get_untracked(),
        "T_REQ released after the exchange"
    );
    assert!(
        c.modem.status.get_untracked().is_some(),
        "the status message kept"
    );
    assert!(c.ack_latency().count >= 1, "the confirm's ACK timed");
}

#[test]
fn a_mib_write_is_kept_in_the_modem_store_and_retunes_the_links_timeouts() {
    let (_owner, c) = console(Profile::Modem, 1);
    let data = vec![150, 30, 8];
    let got = Rc::new(RefCell::new(None));
    let g = got.clone();
    c.write_mib(
        index::HOST_INTERFACE_TIMEOUT.into(),
        data.clone(),
        move |r| *g.borrow_mut() = Some(r),
    );
    assert!(run_until(&c, 2.0, |_| got.borrow().is_some()));
    assert_eq!(got.borrow_mut().take(), Some(Ok(Vec::new())));
    let kept = c
        .modem
        .mib
        .with_untracked(|m| m.get(&index::HOST_INTERFACE_TIMEOUT.into()).cloned());
    assert_eq!(kept, Some(data));
    assert!(run_until(&c, 1.0, |c| c.conn.timeouts.get_untracked()
        == Timeouts::from_ms(150, 30, 8)));
}

#[test]
fn a_request_over_an_unplugged_cable_fails_and_the_connection_store_says_why() {
    let (_owner, c) = console(Profile::Modem, 1);
    c.with_simulator(|s| s.inject(Fault::Unplug));
    assert!(!c.conn.state.get_untracked().is_connected());
    let got = ask(&c, Command::PingRequest { data: vec![] });
    assert!(run_until(&c, 1.0, |_| got.borrow().is_some()));
    let Some(Outcome::Failed(why)) = got.borrow_mut().take() else {
        panic!("answered over an unplugged cable")
    };
    assert_eq!(c.conn.last_problem.get_untracked(), Some(why));
    c.with_simulator(|s| s.inject(Fault::Plug));
    assert!(c.conn.state.get_untracked().is_connected());
}

#[test]
fn the_street_is_found_through_the_stores_at_most_five_redraws_a_second() {
    let (_owner, c) = console(Profile::StreetBoard, 4);
    assert_eq!(
        c.street.port.get_untracked(),
        format!("concentrator board (simulated, {STREET_LAMPS} lamps)")
    );
    assert!(!c.street.kept_as.get_untracked().is_empty());
    // Each redraw of the Street view is a new version: five a second at
    // most (STREET_DRAW_US), however often the page ticks.
    let mut shown = Vec::new();
    let mut progress = false;
    let found = run_until(&c, 60.0, |c| {
        let v = c.street.version.get_untracked();
        if shown.last().is_none_or(|(_, w)| *w != v) {
            shown.push((crate::clock::page_now_us(), v));
        }
        progress |= c.street.discovering.get_untracked().is_some();
        c.street
            .read(|s| s.discovering().is_none() && s.fleet().len() == STREET_LAMPS)
    });
    assert!(found, "{} lamps found", c.street.read(|s| s.fleet().len()));
    assert!(progress, "the discovery's progress was shown");
    assert!(shown.len() > 3, "{shown:?}");
    for w in shown.windows(2) {
        assert!(w[1].0 - w[0].0 >= STREET_DRAW_US, "{shown:?}");
    }
    assert!(c.street.sent.get_untracked() > 0);
    assert!(
        titles(&c).iter().any(|t| t == "SERVICE_NET_DISCOVER_REQ"),
        "{:?}",
        titles(&c)
    );
    // The concentrator board ACKs its own modem: no ACK of the console's.
    assert_eq!(c.ack_latency().count, 0);
}

#[test]
fn a_lamp_failing_is_raised_as_an_alert_in_the_street_store() {
    let (_owner, c) = console(Profile::StreetBoard, 4);
    assert!(run_until(&c, 60.0, |c| c.street.read(|s| s.fleet().len()
        == STREET_LAMPS
        && s.discovering().is_none())));
    let lamp = c.street.with_fleet(|f| *f.keys().next().expect("a lamp"));
    c.with_simulator(|s| s.lamp(lamp, LampAction::Fail));
    c.street.act(|s| s.read(lamp));
    assert!(
        run_until(&c, 20.0, |c| c
            .street
            .alerts
            .with_untracked(|a| a.iter().any(|r| r.alert.address == lamp))),
        "no alert for the broken lamp"
    );
}

#[test]
fn the_street_over_a_bare_modem_times_the_consoles_acks_and_a_new_profile_lets_it_go() {
    let (_owner, c) = console(Profile::StreetModem, 1);
    assert!(run_until(&c, 10.0, |c| c.ack_latency().count >= 3));
    let street = c.ack_latency();
    assert!(street.link.p99 < 2_000, "{street:?}");
    c.set_profile(Profile::Modem);
    assert_eq!(c.street.port.get_untracked(), "");
    assert_eq!(c.street.kept_as.get_untracked(), "");
    assert!(c.street.read(|s| s.fleet().is_empty()));
    // The modem session's driver is new: its own ACKs only.
    assert_eq!(c.ack_latency().count, 0);
    let got = ask(&c, Command::PingRequest { data: vec![9] });
    assert!(run_until(&c, 2.0, |_| got.borrow().is_some()));
    assert!(matches!(*got.borrow(), Some(Outcome::Answer { .. })));
}

#[test]
fn a_stamped_byte_keeps_its_time_and_value() {
    for (at, byte) in [(0, 0), (12_000_345, 0x3f), ((1 << 56) - 1, 0xff)] {
        assert_eq!(unstamped(stamped(at, byte)), (at, byte));
    }
}

/// A page whose every redraw of the street or of its Traffic table takes
/// `draw_us` of its clock (its layout and paint, [`crate::wake::Draw`]),
/// through discovery and two sweeps over a bare ST7580: the ACKs of the
/// console's host engine, on the page's clock, the longest the views
/// went undrawn during discovery (µs), and how many times the Traffic
/// table got rows without the street's draw (at a moment not quiet).
fn acks_with_redraws(draw_us: f64) -> (AckLatency, f64, usize) {
    let (_owner, c) = console(Profile::StreetModem, 1);
    let versions = |c: &Console| {
        let rows = c.traffic.log.with_untracked(|l| l.next_seq());
        (c.street.version.get_untracked(), rows)
    };
    let mut version = versions(&c);
    let (mut drawn, mut longest, mut rows_alone) = (0.0, 0.0f64, 0);
    run_until(&c, 30.0, |c| {
        let v = versions(c);
        rows_alone += (v.0 == version.0 && v.1 != version.1) as usize;
        if v != version {
            // While discovery or the sweep has the line, a draw comes
            // while its requests wait, or right after an ACK.
            let now = crate::clock::page_now_us();
            let quiet = c
                .street
                .read(|s| !s.busy_over_modem() || s.drawing() || s.driver().just_acked(now));
            assert!(quiet, "a draw at {now} µs while the line may be busy");
            version = v;
            if c.street.read(|s| s.discovering().is_some()) {
                longest = longest.max(now - drawn);
            }
            drawn = now + draw_us;
            set_page_now_us(drawn);
        }
        c.street.read(|s| s.sweep().rounds > 1)
    });
    (c.ack_latency(), longest, rows_alone)
}

#[test]
fn the_streets_redraws_come_while_the_line_is_quiet_and_hold_up_no_ack() {
    let (acks, longest, rows_alone) = acks_with_redraws(10_000.0);
    assert!(acks.count >= 40, "{acks:?}");
    assert_eq!(rows_alone, 0, "Traffic rows handed out between draws");
    assert!(acks.page.p99 < 2_000, "{acks:?}");
    // The views still follow the street.
    assert!(
        longest <= STREET_DRAW_LATE_US + 10_000.0,
        "{longest} µs undrawn"
    );
}
