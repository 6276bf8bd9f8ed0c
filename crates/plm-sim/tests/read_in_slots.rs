//! Reads in slots (docs/protocol-notes.md, "Reads in slots"): a street
//! of 100 simulated lamps found by discovery, then every lamp read with
//! SERVICE_READ_IN_SLOTS broadcasts through the concentrator board, the
//! stragglers asked one by one; the line time printed against
//! stop-and-wait.

use plm_core::app::discovery::DiscoveryConfig;
use plm_core::app::hid::{self, Hid, LampState};
use plm_core::app::read_all::ReadConfig;
use plm_core::app::service::{Service, SlotRead};
use plm_core::app::{Address, Ballast, Message, Request, RequesterConfig};
use plm_core::time::{Duration, MS};
use plm_sim::board::street_address;
use plm_sim::{Attach, Sim, SimConfig, StreetDriver};

const S: Duration = 1_000 * MS;

fn street(lamps: usize, seed: u64) -> StreetDriver {
    let sim = Sim::new(SimConfig {
        seed,
        ..SimConfig::street(lamps, Attach::Board)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2 * S);
    d
}

fn lit(value: &[u8]) -> bool {
    Ballast::decode(value).is_some_and(|b| b.state() == LampState::Run && b.lamp_power > 0)
}

fn ask_one(d: &mut StreetDriver, a: Address) -> Result<Vec<u8>, String> {
    match d.ask(a, Message::Hid(Hid::Get(hid::ALL)), 30 * S)? {
        Message::Hid(Hid::Reply { value, .. }) => Ok(value),
        m => Err(format!("{m:?}")),
    }
}

#[test]
fn a_street_of_100_is_read_in_slots_faster_than_stop_and_wait() {
    let lamps = 100;
    let mut d = street(lamps, 11);
    let found = d.discover(DiscoveryConfig::new(1, lamps));
    assert_eq!(found.len(), lamps, "every lamp found");
    let boards: Vec<Address> = found.keys().copied().collect();

    // In slots, then the stragglers one by one.
    let t0 = d.now();
    let r = d.read_in_slots(&boards, ReadConfig::ALL);
    let slotted = d.now() - t0;
    let stragglers = r.stragglers();
    for (a, v) in r.heard() {
        assert!(lit(v), "{a}: {v:?}");
    }
    for a in &stragglers {
        let v = ask_one(&mut d, *a).unwrap_or_else(|e| panic!("straggler {a}: {e}"));
        assert!(lit(&v), "{a}");
    }
    let with_stragglers = d.now() - t0;
    assert_eq!(r.heard().len() + stragglers.len(), lamps);
    assert_eq!(
        r.requests(),
        2,
        "50 boards a request (their addresses share five bytes)"
    );

    // Stop-and-wait, as before.
    let t1 = d.now();
    for a in &boards {
        let v = ask_one(&mut d, *a).unwrap_or_else(|e| panic!("{a}: {e}"));
        assert!(lit(&v), "{a}");
    }
    let one_by_one = d.now() - t1;
    println!(
        "100 lamps read: in slots {:.2} s ({} heard, {} stragglers asked alone, {:.2} s in all), stop-and-wait {:.2} s",
        slotted as f64 / 1e6,
        r.heard().len(),
        stragglers.len(),
        with_stragglers as f64 / 1e6,
        one_by_one as f64 / 1e6,
    );
    assert!(stragglers.len() <= 2, "stragglers: {stragglers:?}");
    assert!(
        with_stragglers * 10 < one_by_one * 7,
        "slots {with_stragglers} µs, stop-and-wait {one_by_one} µs"
    );
}

#[test]
fn a_board_not_named_stays_silent_and_one_named_answers_in_its_slot() {
    let mut d = street(3, 5);
    let named = street_address(2);
    let read = SlotRead {
        slot_ms: ReadConfig::ALL.slot_ms(),
        param: hid::ALL,
        first_ms: 20,
        addresses: vec![street_address(3), named],
    };
    let t0 = d.now();
    d.submit(Request::all(Message::Service(Service::ReadInSlots(read))));
    d.run_for(2 * S);
    let heard: Vec<(u64, Address)> = d
        .log
        .iter()
        .filter_map(|(t, h)| match h {
            plm_core::app::Happening::App(plm_core::app::AppEvent::Unsolicited {
                address,
                message: Message::Hid(Hid::Reply { .. }),
                ..
            }) => Some((*t - t0, *address)),
            _ => None,
        })
        .collect();
    let from: Vec<Address> = heard.iter().map(|h| h.1).collect();
    assert_eq!(from, [street_address(3), named], "node 1 is not named");
    // The second reply comes one slot after the first.
    let gap = heard[1].0 - heard[0].0;
    let slot = ReadConfig::ALL.slot_ms() as u64 * MS;
    assert!(
        (slot - 5 * MS..slot + 5 * MS).contains(&gap),
        "{gap} µs apart"
    );
}

#[test]
fn a_board_whose_ballast_is_late_for_its_slot_stays_silent() {
    let mut d = street(3, 6);
    // Slot 0 begins as the request is heard: the ballast (5 ms) is late
    // for it; slot 1, 62 ms later, is not.
    let read = SlotRead {
        slot_ms: ReadConfig::ALL.slot_ms(),
        param: hid::ALL,
        first_ms: 0,
        addresses: vec![street_address(2), street_address(3)],
    };
    d.submit(Request::all(Message::Service(Service::ReadInSlots(read))));
    d.run_for(2 * S);
    let from: Vec<Address> = d
        .log
        .iter()
        .filter_map(|(_, h)| match h {
            plm_core::app::Happening::App(plm_core::app::AppEvent::Unsolicited {
                address,
                message: Message::Hid(Hid::Reply { .. }),
                ..
            }) => Some(*address),
            _ => None,
        })
        .collect();
    assert_eq!(from, [street_address(3)]);
}
