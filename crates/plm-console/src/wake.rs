//! When the page runs the sessions: when bytes arrive, at the engines'
//! next deadline, and at once after the user acts; never on a fixed
//! timer, and not at all while nothing is due (issue 13, "event-driven
//! link").
//!
//! Browsers clamp a `setTimeout` set from inside another timer's callback
//! to 4 ms once five are nested, which would make every ACK (UM0932
//! 3.2.8) and every chained request up to 4 ms late. So the wake is
//! always asked for through a message the page posts to itself
//! (`postMessage`: a task of its own, never clamped), and the timer for a
//! later deadline is set from that message's task, where timers do not
//! nest. Any message to the page looks whether something is due, which
//! costs nothing when nothing is.
//!
//! A timer waits whole milliseconds, and rounded up that made an ACK up to
//! 1 ms late (issue 13: p50 0.5 ms). So the deadline at which the host
//! must act at once ([`next`]: the last byte on the UART either way
//! arrives, where a frame may end, to be ACKed or answered) is waited,
//! when closer than 2 ms, by the timer's whole milliseconds rounded down
//! and its last fraction of one spun in the task that finds it, the clock
//! read about every 25 µs. Every other deadline (the world's next byte,
//! the engine's timeouts, the idle wake) is waited by the timer rounded
//! up. Garbage is what makes ACKs late: the page collects it, 3-8 ms at a
//! time, in the middle of a modem's frame. Spinning on messages for every
//! byte of a frame left 45 MB in 300 reads; for the last fraction before a
//! frame's end, 1.7 MB (a `MessageEvent` each, and a number from the clock
//! at each look); spun in the task, next to none.
//!
//! A deadline is run once the page's clock has reached it, not before
//! (the clock is coarse, 100 µs, in a page that is not cross-origin
//! isolated): run early, the sessions found nothing to do and asked again
//! at once, through a message after message. What the page's work asks
//! for while it runs is armed once it returns: a later deadline by a
//! timer set from that task (nested timers are clamped, so every few
//! through a message), one due at once through a message, after the
//! page's other tasks.
//!
//! A draw handed out holds the line until the page has painted it
//! ([`Draw`]): the page's next frame, counted by the message it posts
//! from `requestAnimationFrame`, which runs once the frame is painted.
//! Natively (the tests) there is no page: nothing is run.

#[cfg(target_arch = "wasm32")]
mod page {
    use crate::clock::page_now_us;
    use std::cell::{Cell, OnceCell};
    use wasm_bindgen::prelude::*;

    // The page's own `postMessage`, `setTimeout` and
    // `requestAnimationFrame`, called straight: web-sys's wraps each call
    // in a closure over its arguments, to catch what cannot be thrown
    // here, and passes the origin as a new string, and gloo-timers'
    // `Timeout` made a closure for each wait.
    #[wasm_bindgen]
    extern "C" {
        #[wasm_bindgen(js_name = postMessage)]
        fn post_message(message: &JsValue, origin: &JsValue);
        #[wasm_bindgen(js_name = setTimeout)]
        fn set_timeout(run: &JsValue, ms: u32, nesting: u32);
        #[wasm_bindgen(js_name = requestAnimationFrame)]
        fn request_animation_frame(run: &JsValue);
    }

    /// What the page gave the wake, once.
    struct Page {
        run: Box<dyn Fn()>,
        /// `postMessage`'s origin ("*").
        origin: JsValue,
        /// Runs at each message: looks whether something is due (kept
        /// alive here: the page's message listener).
        _on_wake: Closure<dyn FnMut()>,
        /// Runs at each timer, given its nesting level.
        on_timer: Closure<dyn FnMut(u32)>,
        on_frame: Closure<dyn FnMut()>,
    }

    /// How long a draw waits for the page's next frame (µs): a hidden or
    /// throttled page paints none, and its line goes on.
    const FRAME_WAIT_US: f64 = 50_000.0;

    /// An exact deadline closer than this (ms) is met to the page's
    /// clock's resolution; a further one is first waited by the timer.
    const PRECISE_MS: f64 = 2.0;

    /// While a wait spins, the clock is read about every this many µs
    /// (each read leaves the collector a number).
    const SPIN_READ_US: f64 = 25.0;

    thread_local! {
        static PAGE: OnceCell<Page> = const { OnceCell::new() };
        /// When to run next, µs of the page's clock (infinite: nothing due).
        static DUE: Cell<f64> = const { Cell::new(f64::INFINITY) };
        /// Whether `DUE` is met to the clock's resolution ([`super::exactly`]).
        static EXACT: Cell<bool> = const { Cell::new(false) };
        /// A message is on its way.
        static POSTED: Cell<bool> = const { Cell::new(false) };
        /// When the timer set last fires (infinite: none is set). One set
        /// for a deadline moved earlier since is left to run and find
        /// nothing due: cheaper than keeping and clearing it.
        static TIMER_AT: Cell<f64> = const { Cell::new(f64::INFINITY) };
        /// Frames painted since the page opened ([`super::Draw`]).
        static FRAMES: Cell<u64> = const { Cell::new(0) };
        /// When the next frame was asked for, while it has not come
        /// (infinite: none is asked for).
        static FRAME_ASKED: Cell<f64> = const { Cell::new(f64::INFINITY) };
        /// A frame is being painted: the next message comes after it.
        static PAINTING: Cell<bool> = const { Cell::new(false) };
        /// Turns of [`spin`] between two reads of the clock, measured at
        /// [`install`].
        static SPIN: Cell<u32> = const { Cell::new(1_000) };
        /// The timer nesting level of the task running now (HTML, "timer
        /// initialisation steps": 0 outside a timer's task).
        static NEST: Cell<u32> = const { Cell::new(0) };
        /// The page's work is running: what it asks for is armed after.
        static RUNNING: Cell<bool> = const { Cell::new(false) };
    }

    /// Timers nested this deep are clamped to 4 ms (HTML, "timer
    /// initialisation steps": nesting level above 5; Chromium from 5): the
    /// next is set from a message's task instead.
    const NEST_MAX: u32 = 4;

    /// About [`SPIN_READ_US`] of work that reads nothing.
    fn spin() {
        for i in 0..SPIN.get() {
            std::hint::black_box(i);
        }
    }

    pub fn install(run: Box<dyn Fn()>) {
        let on_wake = Closure::<dyn FnMut()>::new(|| {
            POSTED.set(false);
            NEST.set(0);
            // Tasks queued during a frame run once it is painted; then the
            // page runs, for what waited for the paint.
            if PAINTING.replace(false) {
                FRAMES.set(FRAMES.get() + 1);
                DUE.set(0.0);
            }
            arm();
        });
        let on_timer = Closure::<dyn FnMut(u32)>::new(|nesting| {
            NEST.set(nesting);
            // The timer waited for has fired, whatever the page's coarse
            // clock reads: left set, the next would never be (an earlier
            // one still pending at worst runs the page once for nothing).
            TIMER_AT.set(f64::INFINITY);
            arm();
        });
        let on_frame = Closure::<dyn FnMut()>::new(|| {
            FRAME_ASKED.set(f64::INFINITY);
            PAINTING.set(true);
            POSTED.set(false);
            post();
        });
        let Some(window) = web_sys::window() else {
            return;
        };
        let _ =
            window.add_event_listener_with_callback("message", on_wake.as_ref().unchecked_ref());
        PAGE.with(|p| {
            let _ = p.set(Page {
                run,
                origin: JsValue::from_str("*"),
                _on_wake: on_wake,
                on_timer,
                on_frame,
            });
        });
        // How many turns of the spin take SPIN_READ_US (the clock may
        // be coarse, 100 µs: a few ms are measured, once).
        let (turns, start) = (SPIN.get(), page_now_us());
        for _ in 0..1_000 {
            spin();
        }
        let took = (page_now_us() - start).max(100.0);
        SPIN.set((f64::from(turns) * 1_000.0 * SPIN_READ_US / took).max(1.0) as u32);
        // What was asked for before.
        post();
    }

    /// Frames painted so far, one being counted included: a draw handed
    /// out after its paint and before its message waits for the next.
    pub fn frames() -> u64 {
        FRAMES.get() + PAINTING.get() as u64
    }

    /// Whether a frame was painted since `frames` were, or the page
    /// paints none (one asked for has not come within [`FRAME_WAIT_US`]);
    /// if not, the next is asked for, and the page runs once it is
    /// painted.
    pub fn painted_since(frames: u64) -> bool {
        let now = page_now_us();
        if FRAMES.get() > frames || now - FRAME_ASKED.get() > FRAME_WAIT_US {
            return true;
        }
        if FRAME_ASKED.get() == f64::INFINITY && !PAINTING.get() {
            // Without the page's loop (a test driving a session), no
            // frame is waited for.
            let asked = PAGE.with(|p| {
                p.get()
                    .map(|p| request_animation_frame(p.on_frame.as_ref()))
            });
            if asked.is_none() {
                return true;
            }
            FRAME_ASKED.set(now);
            at(now + FRAME_WAIT_US, false);
        }
        false
    }

    /// Runs if due, else waits for the time left: the whole milliseconds
    /// by a timer, the rest of an exact wait spun here. What the page's
    /// work asks for is armed once it has run: at once, through a message
    /// (the page's other tasks go first); later, by a timer set here
    /// (nested timers are clamped: every few, through a message).
    fn arm() {
        let due = DUE.get();
        let mut now = page_now_us();
        if EXACT.get() && due - now < 1_000.0 {
            while now < due {
                spin();
                now = page_now_us();
            }
        }
        if TIMER_AT.get() <= now + 100.0 {
            TIMER_AT.set(f64::INFINITY);
        }
        // Due when the page's clock has reached it, not before: the
        // sessions run their time up to that clock (coarse in a page that
        // is not cross-origin isolated, 100 µs), and run early they would
        // find nothing to do and ask again at once.
        if due <= now {
            DUE.set(f64::INFINITY);
            RUNNING.set(true);
            PAGE.with(|p| p.get().map(|p| (p.run)()));
            RUNNING.set(false);
            now = page_now_us();
        }
        let due = DUE.get();
        if due == f64::INFINITY {
            return;
        }
        if due <= now || NEST.get() >= NEST_MAX {
            return post();
        }
        let left = (due - now) / 1_000.0;
        let ms = if EXACT.get() && left < PRECISE_MS {
            left.floor()
        } else {
            left.ceil()
        };
        if now + ms * 1_000.0 < TIMER_AT.get() {
            TIMER_AT.set(now + ms * 1_000.0);
            let nesting = NEST.get() + 1;
            PAGE.with(|p| {
                p.get()
                    .map(|p| set_timeout(p.on_timer.as_ref(), ms as u32, nesting))
            });
        }
    }

    pub fn at(page_us: f64, exact: bool) {
        let due = DUE.get();
        if page_us < due || (exact && page_us == due) {
            DUE.set(page_us);
            EXACT.set(exact);
            // Armed once the page's work has run, if it is running.
            if !RUNNING.get() {
                post();
            }
        }
    }

    /// Has the page look again once its tasks queued so far have run.
    fn post() {
        if !POSTED.get() {
            PAGE.with(|p| {
                if let Some(p) = p.get() {
                    post_message(&JsValue::NULL, &p.origin);
                    POSTED.set(true);
                }
            });
        }
    }
}

/// Makes `run` the page's work: [`soon`] and [`at`] call it.
pub fn install(run: impl Fn() + 'static) {
    #[cfg(target_arch = "wasm32")]
    page::install(Box::new(run));
    #[cfg(not(target_arch = "wasm32"))]
    let _ = run;
}

/// A draw handed to the page: the line waits until the page has painted
/// it (issue 13: the paint of a redrawn Traffic table, 2-4 ms at the next
/// frame, held up the ACK of a frame ending under it). Natively (the
/// tests) there are no frames: it waits until the next tick.
#[derive(Debug, Clone, Copy, Default)]
pub struct Draw {
    /// The frames painted when the draw was handed out.
    since: Option<u64>,
}

impl Draw {
    /// A draw was handed out now.
    pub fn begin(&mut self) {
        self.since = Some(frames());
    }

    /// Whether the line waits for the draw.
    pub fn pending(&self) -> bool {
        self.since.is_some()
    }

    /// At a tick: the wait ends once a frame has been painted since the
    /// draw; until then, the page is asked to run after the next one.
    pub fn settle(&mut self) {
        if self.since.is_some_and(painted_since) {
            self.since = None;
        }
    }
}

/// Frames the page has painted so far, under its own loop ([`install`];
/// natively: none).
pub fn frames() -> u64 {
    #[cfg(target_arch = "wasm32")]
    return page::frames();
    #[cfg(not(target_arch = "wasm32"))]
    0
}

/// Whether the page has painted a frame since `frames` were, else asks
/// to run once it has (natively: always, there are no frames).
fn painted_since(frames: u64) -> bool {
    #[cfg(target_arch = "wasm32")]
    return page::painted_since(frames);
    #[cfg(not(target_arch = "wasm32"))]
    {
        let _ = frames;
        true
    }
}

/// Runs the page's work as soon as the page can (bytes came, the user
/// acted).
pub fn soon() {
    at(0.0);
}

/// Runs the page's work when the page's clock reaches `page_us` (µs), within a
/// millisecond after, or earlier if asked.
pub fn at(page_us: f64) {
    #[cfg(target_arch = "wasm32")]
    page::at(page_us, false);
    #[cfg(not(target_arch = "wasm32"))]
    let _ = page_us;
}

/// Runs the page's work when it is next due: at `due` (µs of the page's
/// clock, within a millisecond), or at `exact` to the clock's resolution
/// (`exactly`). A deadline met within a millisecond (a byte in a
/// modem's frame, an engine's timeout) waits for the exact one when that
/// comes within the millisecond: met exactly, it covers both, with one
/// wake rather than two.
pub fn next(due: f64, exact: Option<f64>) {
    match plan(due, exact) {
        (t, true) => exactly(t),
        (t, false) => at(t),
    }
}

/// When [`next`] wakes the page, and whether exactly.
fn plan(due: f64, exact: Option<f64>) -> (f64, bool) {
    match exact {
        Some(e) if e < due + 1_000.0 => (e, true),
        _ => (due, false),
    }
}

/// Runs the page's work when the page's clock reaches `page_us` (µs), to
/// the clock's resolution: a modem's frame may end then, to be ACKed at
/// once ([`crate::transport::Transport::uart_due`]).
fn exactly(page_us: f64) {
    #[cfg(target_arch = "wasm32")]
    page::at(page_us, true);
    #[cfg(not(target_arch = "wasm32"))]
    let _ = page_us;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The end of a run of bytes within a millisecond of the next
    /// deadline is the one wake, met exactly; a later one waits for its
    /// turn.
    #[test]
    fn one_wake_covers_a_deadline_and_the_exact_one_right_after() {
        assert_eq!(plan(10_000.0, None), (10_000.0, false));
        assert_eq!(plan(10_000.0, Some(10_600.0)), (10_600.0, true));
        assert_eq!(plan(10_000.0, Some(9_000.0)), (9_000.0, true));
        assert_eq!(plan(10_000.0, Some(11_000.0)), (10_000.0, false));
    }
}
