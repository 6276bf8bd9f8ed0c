//! `window.plmBench`: the hook `tests/e2e/bench.mjs` (`cargo xtask bench`)
//! drives the console through, so that it measures the session rather
//! than a script clicking buttons. It only does what the views do (change
//! the baud rate, read a MIB object) through the same [`Console`], so it
//! is harmless on any page and always compiled.
//!
//! - `plmBench.setBaud(baud)`: as the connection bar's baud select (UM0932
//!   Table 5 rates only); returns the baud rate in use.
//! - `plmBench.mibReads(n, index, chained)`: `n` reads of MIB object
//!   `index` (the profile's chip: `Chip::mib_read`), all queued at once (the session sends each as soon as the
//!   previous one is answered) or, `chained`, each sent from the previous
//!   one's reply, as a view would. A Promise of `{reads, failed,
//!   firstError, dataLen, elapsedMs}` on the page's clock.
//! - `plmBench.ackLatency()`: [`crate::session::AckLatency`] in ms, with
//!   the T_ACK in use: `{count, link: {p50, p99, max}, page: {…}, tAck}`.
//! - `plmBench.ackSamples()`: the most recent ACK latencies one by one,
//!   `[[writtenMs, linkMs, pageMs], …]`, `writtenMs` on the page's clock
//!   (`performance.now()`) when the tick that wrote the ACK began.
//! - `plmBench.streetSeconds()`: the street's clock, s (a simulated
//!   street's virtual time), for journeys that wait for simulated time.
//! - `plmBench.streetWork()`: the street's time its ticks have run and
//!   the page's time that took (`StreetSession::work`), `{simulatedS,
//!   wallS}`: a simulated street's speed in the page.

use crate::clock::page_now_us;
use crate::driver::ack::Spread;
use crate::session::Outcome;
use crate::stores::Console;
use js_sys::{Function, Object, Promise, Reflect};
use leptos::prelude::GetUntracked;
use plm_core::time::Duration;
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;

/// Puts `window.plmBench` on the page for the console `c`.
pub fn install(c: Console) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let hook = Object::new();
    let set_baud = Closure::<dyn Fn(u32) -> u32>::new(move |baud: u32| {
        if plm_core::link::BAUD_RATES.contains(&baud) {
            c.set_baud(baud);
        }
        c.conn.baud.get_untracked()
    });
    let mib_reads = Closure::<dyn Fn(u32, u16, bool) -> Promise>::new(
        move |n: u32, index: u16, chained: bool| mib_reads(c, n, index, chained),
    );
    let ack_latency = Closure::<dyn Fn() -> JsValue>::new(move || ack_latency(c));
    let ack_samples = Closure::<dyn Fn() -> JsValue>::new(move || ack_samples(c));
    let street_seconds =
        Closure::<dyn Fn() -> f64>::new(move || c.street.read(|s| s.now()) as f64 / 1e6);
    let _ = Reflect::set(&hook, &"setBaud".into(), set_baud.as_ref());
    let _ = Reflect::set(&hook, &"mibReads".into(), mib_reads.as_ref());
    let _ = Reflect::set(&hook, &"ackLatency".into(), ack_latency.as_ref());
    let _ = Reflect::set(&hook, &"ackSamples".into(), ack_samples.as_ref());
    let street_work = Closure::<dyn Fn() -> JsValue>::new(move || {
        let (simulated, wall) = c.street.read(|s| s.work());
        object(&[
            ("simulatedS", (simulated as f64 / 1e6).into()),
            ("wallS", (wall / 1e6).into()),
        ])
    });
    let _ = Reflect::set(&hook, &"streetSeconds".into(), street_seconds.as_ref());
    let _ = Reflect::set(&hook, &"streetWork".into(), street_work.as_ref());
    // The page keeps them for its whole life.
    set_baud.forget();
    mib_reads.forget();
    ack_latency.forget();
    ack_samples.forget();
    street_seconds.forget();
    street_work.forget();
    let _ = Reflect::set(&window, &"plmBench".into(), &hook);
}

fn ms(us: Duration) -> f64 {
    us as f64 / 1_000.0
}

/// A JS object of `fields` (JS values straight from Rust: no JSON text,
/// so no float printing in the console's wasm).
fn object(fields: &[(&str, JsValue)]) -> JsValue {
    let o = Object::new();
    for (k, v) in fields {
        let _ = Reflect::set(&o, &JsValue::from_str(k), v);
    }
    o.into()
}

fn spread(s: Spread) -> JsValue {
    object(&[
        ("p50", ms(s.p50).into()),
        ("p99", ms(s.p99).into()),
        ("max", ms(s.max).into()),
    ])
}

fn ack_latency(c: Console) -> JsValue {
    let l = c.ack_latency();
    object(&[
        ("count", (l.count as f64).into()),
        ("link", spread(l.link)),
        ("page", spread(l.page)),
        ("tAck", ms(c.conn.timeouts.get_untracked().t_ack).into()),
    ])
}

fn ack_samples(c: Console) -> JsValue {
    let all = js_sys::Array::new();
    for (written, link, page) in c.ack_samples() {
        let row = js_sys::Array::new();
        row.push(&(written / 1_000.0).into());
        row.push(&ms(link).into());
        row.push(&ms(page).into());
        all.push(&row);
    }
    all.into()
}

/// One run of `mibReads`.
struct Run {
    n: u32,
    done: u32,
    failed: u32,
    first_error: Option<String>,
    data_len: usize,
    started: f64,
    resolve: Function,
}

fn mib_reads(c: Console, n: u32, index: u16, chained: bool) -> Promise {
    Promise::new(&mut |resolve, _reject| {
        let run = Rc::new(RefCell::new(Run {
            n,
            done: 0,
            failed: 0,
            first_error: None,
            data_len: 0,
            started: page_now_us(),
            resolve,
        }));
        if n == 0 {
            finish(&run.borrow());
        } else if chained {
            read(c, run, index, true);
        } else {
            for _ in 0..n {
                read(c, run.clone(), index, false);
            }
        }
    })
}

fn read(c: Console, run: Rc<RefCell<Run>>, index: u16, chained: bool) {
    // The chip's own MIB read (the profile's), its answer read by the
    // chip's description: the same bench for both chips.
    let frame = c.with_chip(|ch| ch.mib_read(index));
    c.request_frame(frame, move |o| {
        let more = {
            let mut r = run.borrow_mut();
            r.done += 1;
            let value = match o {
                Outcome::Answer {
                    command: Some(answer),
                    ..
                } => c.with_chip(|ch| ch.verdict(&answer)),
                Outcome::Answer { command: None, .. } => Err("no answer".into()),
                Outcome::Failed(why) => Err(why),
            };
            match value {
                Ok(data) => r.data_len = data.len(),
                Err(why) => {
                    r.failed += 1;
                    r.first_error.get_or_insert(why);
                }
            }
            if r.done == r.n {
                finish(&r);
            }
            chained && r.done < r.n
        };
        // The borrow is over: a failure may be replied at once.
        if more {
            read(c, run, index, true);
        }
    });
}

fn finish(r: &Run) {
    let result = object(&[
        ("reads", r.done.into()),
        ("failed", r.failed.into()),
        (
            "firstError",
            r.first_error
                .as_deref()
                .map_or(JsValue::NULL, JsValue::from_str),
        ),
        ("dataLen", (r.data_len as f64).into()),
        ("elapsedMs", ((page_now_us() - r.started) / 1_000.0).into()),
    ]);
    let _ = r.resolve.call1(&JsValue::NULL, &result);
}
