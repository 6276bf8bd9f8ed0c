//! When the page runs the sessions: when bytes arrive, at the engines'
//! next deadline, and at once after the user acts; never on a fixed
//! timer, and not at all while nothing is due (issue 13, "event-driven
//! link").
//!
//! Browsers clamp a `setTimeout` set from inside another timer's callback
//! to 4 ms once five are nested, which would make every ACK (UM0932
//! 3.2.8) and every chained request up to 4 ms late. So the wake is always asked for through a message the
//! page posts to itself (`postMessage`: a task of its own, never clamped),
//! and the timer for a later deadline is set from that message's task,
//! where timers do not nest. Any message to the page looks whether
//! something is due, which costs nothing when nothing is.
//!
//! A timer waits whole milliseconds, and rounded up that made an ACK up to
//! 1 ms late (issue 13: p50 0.5 ms). So the deadline at which the host
//! must act at once ([`exactly`]: the last byte on the UART either way
//! arrives, where a frame may end, to be ACKed or answered) is waited, when closer than 2 ms, by the timer's
//! whole milliseconds rounded down and its last fraction of one by
//! messages, one after the page's other tasks. Every other deadline (the
//! world's next byte, the engine's timeouts, the idle wake) is waited by
//! the timer rounded up: spinning on messages for every byte of a frame
//! left so much garbage (45 MB in 300 reads) that the page collected it
//! every few hundred ms, 3-8 ms each, in the middle of a modem's frame.
//! Natively (the tests) there is no page: nothing is run.

#[cfg(target_arch = "wasm32")]
mod page {
    use crate::clock::page_now_us;
    use std::cell::RefCell;
    use std::rc::Rc;
    use wasm_bindgen::prelude::*;

    // The page's own `postMessage` and timers, called straight: web-sys's
    // wrap each call in a closure over its arguments to catch what cannot
    // be thrown here, and pass the origin as a new string, and a timer
    // each time made a closure of its own. Waiting a fraction of a
    // millisecond posts a message every few µs, and that garbage (35 MB
    // in 300 reads) had the page collect it every few hundred ms,
    // 3-8 ms each, in the middle of a modem's frame.
    #[wasm_bindgen]
    extern "C" {
        #[wasm_bindgen(js_name = postMessage)]
        fn post_message(message: &JsValue, origin: &JsValue);
        #[wasm_bindgen(js_name = setTimeout)]
        fn set_timeout(run: &JsValue, ms: u32);
    }

    struct Waker {
        run: Rc<dyn Fn()>,
        /// When to run next, µs of the page's clock (infinite: nothing due).
        due: f64,
        /// Whether `due` is met to the clock's resolution ([`super::exactly`]).
        exact: bool,
        /// A message is on its way.
        posted: bool,
        /// When the timer set last fires (infinite: none is set). One set
        /// for a deadline moved earlier since is left to run and find
        /// nothing due: cheaper than keeping and clearing it.
        timer_at: f64,
        /// `postMessage`'s origin ("*"), made once.
        origin: JsValue,
        window: web_sys::Window,
        /// Frames painted since the page opened ([`super::Draw`]).
        frames: u64,
        /// When the next frame was asked for, while it has not come.
        frame_asked: Option<f64>,
        /// A frame is being painted: the next message comes after it.
        painting: bool,
        /// Runs at each message and timer: looks whether something is due.
        on_wake: Closure<dyn FnMut()>,
        on_frame: Closure<dyn FnMut()>,
    }

    /// How long a draw waits for the page's next frame (µs): a hidden or
    /// throttled page paints none, and its line goes on.
    const FRAME_WAIT_US: f64 = 50_000.0;

    /// An exact deadline closer than this (ms) is met to the page's
    /// clock's resolution; a further one is first waited by the timer.
    const PRECISE_MS: f64 = 2.0;

    thread_local! {
        static WAKER: RefCell<Option<Waker>> = const { RefCell::new(None) };
    }

    pub fn install(run: Rc<dyn Fn()>) {
        let on_wake = Closure::<dyn FnMut()>::new(|| {
            with(|w| {
                w.posted = false;
                // Tasks queued during a frame run once it is painted.
                if std::mem::take(&mut w.painting) {
                    w.frames += 1;
                }
            });
            arm();
        });
        let Some(window) = web_sys::window() else {
            return;
        };
        let _ =
            window.add_event_listener_with_callback("message", on_wake.as_ref().unchecked_ref());
        let on_frame = Closure::<dyn FnMut()>::new(|| {
            with(|w| {
                w.frame_asked = None;
                w.painting = true;
                w.posted = false;
                w.post();
            })
        });
        WAKER.with(|w| {
            *w.borrow_mut() = Some(Waker {
                run,
                due: f64::INFINITY,
                exact: false,
                posted: false,
                timer_at: f64::INFINITY,
                origin: JsValue::from_str("*"),
                window,
                frames: 0,
                frame_asked: None,
                painting: false,
                on_wake,
                on_frame,
            })
        });
    }

    /// Frames painted so far.
    pub fn frames() -> u64 {
        with(|w| w.frames)
    }

    /// Whether a frame was painted since `frames` were (one asked for
    /// that has not come within [`FRAME_WAIT_US`] counts); if not, the
    /// next is asked for, and the page runs once it is painted.
    pub fn painted_since(frames: u64) -> bool {
        let now = page_now_us();
        let asked = with(|w| {
            if w.frame_asked.is_some_and(|t| now - t > FRAME_WAIT_US) {
                w.frame_asked = None;
                w.frames += 1;
            }
            if w.frames > frames {
                return None;
            }
            let ask = w.frame_asked.is_none() && !w.painting;
            if ask {
                w.frame_asked = Some(now);
                let _ = w.window.request_animation_frame(w.on_frame.as_ref().unchecked_ref());
            }
            Some(ask)
        });
        if asked == Some(true) {
            at(now + FRAME_WAIT_US, false);
        }
        asked.is_none()
    }

    fn with<R: Default>(f: impl FnOnce(&mut Waker) -> R) -> R {
        WAKER.with(|w| w.borrow_mut().as_mut().map(f).unwrap_or_default())
    }

    /// Runs if due, else waits for the time left: the whole milliseconds
    /// by a timer, the rest by messages.
    fn arm() {
        let now = page_now_us();
        let run = with(|w| {
            if w.timer_at <= now + 100.0 {
                w.timer_at = f64::INFINITY;
            }
            if w.due <= now + 100.0 {
                w.due = f64::INFINITY;
                return Some(w.run.clone());
            }
            let left = (w.due - now) / 1_000.0;
            let ms = if w.exact && left < PRECISE_MS {
                left.floor()
            } else {
                left.ceil()
            };
            if ms < 1.0 {
                w.post();
            } else if now + ms * 1_000.0 < w.timer_at {
                w.timer_at = now + ms * 1_000.0;
                set_timeout(w.on_wake.as_ref(), ms as u32);
            }
            None
        });
        if let Some(run) = run {
            run();
        }
    }

    pub fn at(page_us: f64, exact: bool) {
        with(|w| {
            if page_us > w.due || (page_us == w.due && !exact) {
                return;
            }
            w.due = page_us;
            w.exact = exact;
            w.post();
        });
    }

    impl Waker {
        /// Has the page look again once its tasks queued so far have run.
        fn post(&mut self) {
            if !self.posted {
                post_message(&JsValue::NULL, &self.origin);
                self.posted = true;
            }
        }
    }
}

/// Makes `run` the page's work: [`soon`] and [`at`] call it.
pub fn install(run: impl Fn() + 'static) {
    #[cfg(target_arch = "wasm32")]
    page::install(std::rc::Rc::new(run));
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

/// Frames the page has painted so far (natively: none).
fn frames() -> u64 {
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

/// Runs the page's work when the page's clock reaches `page_us` (µs), to
/// the clock's resolution: a modem's frame may end then, to be ACKed at
/// once ([`crate::transport::Transport::uart_due`]).
pub fn exactly(page_us: f64) {
    #[cfg(target_arch = "wasm32")]
    page::at(page_us, true);
    #[cfg(not(target_arch = "wasm32"))]
    let _ = page_us;
}
