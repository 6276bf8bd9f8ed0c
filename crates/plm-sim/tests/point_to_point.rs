//! Issue 15, "Must show": two host programs that behave as the ST7580
//! reference host driver does (`vendor_host`: T_REQ released and pulled
//! again at once after a status with bit 1 or 2 set, released right after
//! STX, modem frames ACKed after T_ACK, each confirm paired with the
//! request before it) run the point-to-point demo (21-byte DL trigger,
//! 17-byte DL answer) on nodes 0 and 1 of one simulated line, both
//! served, for a simulated minute in virtual time.

mod vendor_host;

use plm_core::link::host::Transmit;
use plm_core::time::{Instant, MS};
use plm_sim::{Peers, Sim, SimConfig};
use vendor_host::{Role, Stats, VendorHost};

/// Runs the demo for `minutes` of virtual time; returns both programs.
fn run(seed: u64, until: Instant) -> (Sim, Vec<VendorHost>) {
    // The demo until `until`, then 1.5 s to finish what is under way.
    let stop_at = until;
    let until = until + 1_500 * MS;
    let mut sim = Sim::new(SimConfig {
        seed,
        nodes: 2,
        served: 2,
        peers: Peers::EchoFollowing,
        ..SimConfig::default()
    });
    let baud = sim.baud();
    let mut hosts = vec![
        VendorHost::new(Role::Master, baud, 0),
        VendorHost::new(Role::Slave, baud, 0),
    ];
    loop {
        let now = sim.now();
        if now >= stop_at {
            hosts[0].stop();
        }
        for (node, h) in hosts.iter_mut().enumerate() {
            for (at, b) in sim.host_read_of(node) {
                // Bytes are read at their arrival (the loop stops there).
                h.handle_rx(at, now, &[b]);
            }
            if h.poll_timeout().is_some_and(|t| t <= now) {
                h.handle_timeout(now);
            }
            while let Some(t) = h.poll_transmit(now) {
                match t {
                    Transmit::Bytes(b) => sim.write_to(node, &b),
                    Transmit::TReq { asserted } => sim.set_treq_of(node, asserted),
                }
            }
        }
        let next = hosts
            .iter()
            .filter_map(|h| h.poll_timeout())
            .chain(sim.next_deadline())
            .min()
            .unwrap_or(until)
            .max(now);
        if next > until {
            break;
        }
        // Something due now again would loop: time must move on.
        sim.advance_to(if next == now { now + 1 } else { next });
    }
    (sim, hosts)
}

fn print(name: &str, s: &Stats) {
    println!(
        "{name}: requests {} acked {} failed {} | confirms paired {} mispaired {} refused {} | \
         T_REQ edges {} statuses {} (not now {}) late (>20 ms) {} max wait {:.1} ms \
         (raw, modem's own exchange first: {:.1} ms) | modem frames {} repeats {} | \
         triggers {} answers {}",
        s.requests,
        s.acked,
        s.failed,
        s.paired,
        s.mispaired,
        s.refused,
        s.edges,
        s.statuses,
        s.not_now,
        s.late_statuses,
        s.max_status_wait as f64 / 1000.0,
        s.max_raw_status_wait as f64 / 1000.0,
        s.frames,
        s.repeats,
        s.triggers,
        s.answers,
    );
}

/// The checks of issue 15 on both programs.
pub fn check(hosts: &[VendorHost]) {
    let (master, slave) = (&hosts[0].stats, &hosts[1].stats);
    for h in hosts {
        let s = &h.stats;
        assert_eq!(s.failed, 0, "a request not ACKed");
        assert_eq!(s.acked + h.in_flight(), s.requests, "every request ACKed");
        assert_eq!(s.mispaired, 0, "a confirm paired with another request");
        assert_eq!(
            s.late_statuses, 0,
            "a status more than 20 ms after its T_REQ"
        );
        assert!(s.not_now > 0, "the 'not now' path was not exercised");
        assert!(s.repeats > 0, "late ACKs brought no repeat");
    }
    assert!(
        master.triggers > 10,
        "too few triggers: {}",
        master.triggers
    );
    assert_eq!(slave.triggers, master.triggers, "every trigger heard");
    assert_eq!(master.answers, master.triggers, "every trigger answered");
    assert_eq!(
        slave.answers, master.answers,
        "every answer confirmed and heard"
    );
}

#[test]
fn point_to_point_demo_for_a_simulated_minute() {
    let started = std::time::Instant::now();
    let (_sim, hosts) = run(15, 60_000 * MS);
    print("master (node 0)", &hosts[0].stats);
    print("slave (node 1)", &hosts[1].stats);
    println!("a simulated minute in {:.1?}", started.elapsed());
    check(&hosts);
}
