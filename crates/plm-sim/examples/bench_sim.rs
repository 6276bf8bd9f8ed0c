//! `cargo xtask bench`, simulator part:
//!
//! 1. Simulated seconds per wall second on a busy line: 10 modems, node 0's
//!    host sending 100-byte DL frames back to back (each after the
//!    previous confirm), the 9 peers echoing every frame they hear (their
//!    echoes collide, as on a real line). 20 simulated seconds, median of
//!    5 runs after a warm-up.
//! 2. The MIB-read command rate of plm-core's host engine against the
//!    simulated modem at 57600 baud, in virtual time, divided by the
//!    wire-time limit: the bytes one MIB_ReadRequest exchange puts on the
//!    UART (status message, request, ACK, confirm, ACK) at 10 bits a byte,
//!    with nothing between them.

use plm_core::link::host::Event;
use plm_core::link::Dialect;
use plm_core::st7580::{Command, DataRequest, TxParams};
use plm_core::time::{wire_time, MS};
use plm_sim::{HostDriver, LineEvent, Outcome, Sim, SimConfig};
use std::time::Instant;

const SECONDS: u64 = 20;

fn busy_line() -> (f64, usize, usize, usize) {
    let mut d = HostDriver::new(Sim::new(SimConfig {
        nodes: 10,
        seed: 7,
        ..SimConfig::default()
    }));
    d.run_for(100 * MS);
    let frame = Command::DlDataRequest(DataRequest {
        params: TxParams::default(),
        payload: vec![0xA5; 100],
    });
    let (mut sent, mut heard, mut missed) = (0, 0, 0);
    let wall = Instant::now();
    while d.now() < SECONDS * 1_000_000 {
        d.submit(&frame);
        d.run_until(
            1_000 * MS,
            |e| matches!(e, Event::Frame(f) if f.code == 0x51),
        );
        d.events.clear();
        while let Some(e) = d.sim.poll_line_event() {
            match e {
                LineEvent::Sent { .. } => sent += 1,
                LineEvent::Heard { .. } => heard += 1,
                LineEvent::Missed { .. } => missed += 1,
            }
        }
    }
    let secs = d.now() as f64 / 1e6;
    (secs / wall.elapsed().as_secs_f64(), sent, heard, missed)
}

fn mib_reads() -> (f64, f64) {
    let mut d = HostDriver::new(Sim::new(SimConfig::default()));
    d.run_for(100 * MS);
    let read = Command::MibReadRequest { index: 0x0A };
    let n = 2_000;
    let start = d.now();
    for _ in 0..n {
        match d.request(&read, 1_000 * MS) {
            Outcome::Answer(Command::MibReadConfirm { .. }) => {}
            other => panic!("MIB read failed: {other:?}"),
        }
    }
    let rate = n as f64 / ((d.now() - start) as f64 / 1e6);
    let len = |c: Command| c.to_frame().emit(Dialect::St7580).unwrap().len();
    let confirm = Command::MibReadConfirm { data: vec![0; 4] };
    // Status message (2) + request + ACK + confirm + ACK.
    let bytes = 2 + len(read) + 1 + len(confirm) + 1;
    let limit = 1e6 / wire_time(bytes, 57_600) as f64;
    (rate, limit)
}

fn main() {
    busy_line();
    let mut runs: Vec<_> = (0..5).map(|_| busy_line()).collect();
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (speed, sent, heard, missed) = runs[2];
    println!(
        "busy 10-modem line: {speed:.0} simulated seconds per wall second \
         ({SECONDS} s simulated: {sent} frames sent, {heard} receptions, {missed} missed)"
    );
    let (rate, limit) = mib_reads();
    println!(
        "MIB reads at 57600 baud (host engine vs simulated modem, virtual time): \
         {rate:.1}/s, wire-time limit {limit:.1}/s, {:.0} % of the limit",
        100.0 * rate / limit
    );
}
