//! The host engine behind a USB-UART's receive latency ([`UsbUart`]), on
//! plm-core's drive loop: the modem's bytes reach the host a latency timer
//! late, and the host still ACKs every frame within T_ACK (UM0932 3.2.8)
//! and loses nothing.

use plm_core::link::host::Event;
use plm_core::st7580::Command;
use plm_core::time::MS;
use plm_sim::{HostDriver, Outcome, Sim, SimConfig};

#[test]
fn reads_behind_a_16_ms_latency_timer_are_answered_and_acked_in_time() {
    let mut d = HostDriver::new(Sim::new(SimConfig::default())).behind_usb(16 * MS);
    d.run_for(100 * MS);
    let read = Command::MibReadRequest { index: 0x0A };
    let start = d.now();
    for _ in 0..20 {
        let out = d.request(&read, 2_000 * MS);
        assert!(
            matches!(out, Outcome::Answer(Command::MibReadConfirm { .. })),
            "{out:?}"
        );
    }
    let retries = d
        .events
        .iter()
        .filter(|(_, e)| matches!(e, Event::Retry { .. }));
    assert_eq!(retries.count(), 0, "no attempt repeated");
    // Each exchange waits for the timer twice (the status message, the
    // confirm): far slower than the wire, as on a real adapter.
    assert!(d.now() - start > 20 * 2 * 10 * MS, "{} µs", d.now() - start);
    let acks = &d.sim.acks;
    assert!(acks.len() >= 20, "{} ACKs", acks.len());
    // Late by the timer, within T_ACK (40 ms).
    assert!(acks.iter().all(|&a| a > 5 * MS && a < 40 * MS), "{acks:?}");
}
