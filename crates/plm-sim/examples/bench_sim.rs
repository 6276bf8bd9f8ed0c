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
//! 3. The same reads through a USB-UART adapter's receive latency (an FTDI
//!    chip's default 16 ms latency timer, [`plm_sim::UsbUart`]) on
//!    plm-core's drive loop: every read answered, the retries counted, and
//!    the ACK latency the modem sees (its frame's last byte at the adapter
//!    to the host's ACK) against T_ACK.

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

/// The FTDI default latency timer.
const FTDI_LATENCY: u64 = 16 * MS;

/// MIB reads behind a USB-UART: (reads, answered, retries, ACK latencies
/// as the modem sees them, reads per second).
fn mib_reads_behind_usb() -> (usize, usize, usize, Vec<u64>, f64) {
    let mut d = HostDriver::new(Sim::new(SimConfig::default())).behind_usb(FTDI_LATENCY);
    d.run_for(100 * MS);
    let read = Command::MibReadRequest { index: 0x0A };
    let n = 500;
    let start = d.now();
    let mut answered = 0;
    for _ in 0..n {
        if let Outcome::Answer(Command::MibReadConfirm { .. }) = d.request(&read, 2_000 * MS) {
            answered += 1;
        }
    }
    let rate = n as f64 / ((d.now() - start) as f64 / 1e6);
    let retries = d
        .events
        .iter()
        .filter(|(_, e)| matches!(e, Event::Retry { .. }))
        .count();
    let mut acks = d.sim.acks.clone();
    acks.sort_unstable();
    (n, answered, retries, acks, rate)
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
    let (n, answered, retries, acks, rate) = mib_reads_behind_usb();
    let at = |p: usize| acks[(acks.len() * p).div_ceil(100).max(1) - 1] as f64 / 1e3;
    let t_ack = plm_core::link::Timeouts::at_reset(Dialect::St7580, 57_600).t_ack as f64 / 1e3;
    println!(
        "MIB reads through a USB-UART's {} ms receive latency (FTDI's default latency timer), \
         plm-core's drive loop: {answered} of {n} answered, {retries} attempts repeated, {rate:.1}/s; \
         ACK latency the modem sees ({} frames): p50 {:.1} ms, p99 {:.1} ms, max {:.1} ms, \
         ratio {:.2} of T_ACK {t_ack:.0} ms",
        FTDI_LATENCY / MS,
        acks.len(),
        at(50),
        at(99),
        acks.last().map_or(0.0, |&m| m as f64 / 1e3),
        at(99) / t_ack,
    );
}
