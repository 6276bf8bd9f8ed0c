//! How long `plm sim`'s simulated ST7580 takes, seen from its RFC 2217
//! client, to answer T_REQ with its status message (UM0932 3.2.8: the
//! modem answers a falling T_REQ edge with the status message; the
//! ST7570's T_POLL, 20 ms, is the time a host gives it). Shared by
//! `tests/sim_latency.rs` and `examples/bench_sim_latency.rs`.

use plm_cli::rfc2217::client::Client;
use plm_core::link::{Dialect, Element, Source, StreamDecoder};
use std::time::{Duration, Instant};

/// How long any one answer may take before the measurement gives up.
const GIVE_UP: Duration = Duration::from_secs(10);

/// The baud rate measured at (the simulated modem's default, BR pins
/// 57600): the 2-byte status message takes 0.35 ms on the wire.
pub const BAUD: u32 = 57600;

/// Connects to `addr`, takes (and ACKs) the power-on BIO_ResetIndication,
/// then `samples` times: T_REQ asserted (RTS on), the time until the
/// whole status message has come, T_REQ released, a pause. The pauses
/// vary (1 to 7 ms) so that a server that wakes on a fixed tick is met
/// at every phase of it.
pub fn treq_to_status(addr: &str, samples: usize) -> Vec<Duration> {
    let mut c = Client::open(addr, BAUD).expect("plm sim answers as an RFC 2217 server");
    let mut modem = StreamDecoder::new(Dialect::St7580, Source::Modem);
    let mut next = |c: &mut Client| -> Element {
        let deadline = Instant::now() + GIVE_UP;
        loop {
            if let Some(e) = modem.next() {
                return e;
            }
            assert!(Instant::now() < deadline, "nothing from the modem");
            let data = c.read_data(Duration::from_millis(50)).expect("connected");
            modem.push(&data);
        }
    };
    match next(&mut c) {
        Element::Frame { frame, .. } if frame.code == 0x3E => {}
        other => panic!("expected BIO_ResetIndication, got {other:?}"),
    }
    c.send_data(&[0x06]).unwrap();
    std::thread::sleep(Duration::from_millis(5));
    let mut times = Vec::with_capacity(samples);
    for i in 0..samples {
        std::thread::sleep(Duration::from_micros(1000 + (i as u64 * 1777) % 6000));
        let t0 = Instant::now();
        c.set_rts(true).unwrap();
        match next(&mut c) {
            Element::Status(_) => times.push(t0.elapsed()),
            other => panic!("expected the status message, got {other:?}"),
        }
        // Released before any frame: the modem stops waiting for one
        // (UM0932 3.2.8, see the device engine).
        c.set_rts(false).unwrap();
    }
    times
}

/// The `q` quantile of `times` (0.5: the median, 1: the maximum).
pub fn quantile(times: &[Duration], q: f64) -> Duration {
    let mut t = times.to_vec();
    t.sort();
    t[((t.len() - 1) as f64 * q).round() as usize]
}

/// Milliseconds with two decimals.
pub fn ms(d: Duration) -> String {
    format!("{:.2} ms", d.as_secs_f64() * 1e3)
}
