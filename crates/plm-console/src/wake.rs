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
//! 1 ms late (issue 13: p50 0.5 ms). So a deadline closer than 2 ms (the
//! next byte of a frame coming in) is waited by the timer's whole
//! milliseconds rounded down, and its last fraction of one by messages,
//! one after the page's other tasks. That loop only runs while a byte is
//! due within the millisecond: with nothing due, the page sleeps on its
//! timer.
//! Natively (the tests) there is no page: nothing is run.

#[cfg(target_arch = "wasm32")]
mod page {
    use crate::clock::page_now_us;
    use gloo_timers::callback::Timeout;
    use std::cell::RefCell;
    use std::rc::Rc;
    use wasm_bindgen::closure::Closure;
    use wasm_bindgen::{JsCast, JsValue};
    use web_sys::Window;

    struct Waker {
        run: Rc<dyn Fn()>,
        /// When to run next, µs of the page's clock (infinite: nothing due).
        due: f64,
        /// A message is on its way.
        posted: bool,
        /// The timer for a later deadline (dropped: cancelled).
        timer: Option<Timeout>,
        window: Window,
        _on_message: Closure<dyn FnMut()>,
    }

    /// Deadlines closer than this (ms) are met to the page's clock's
    /// resolution: a byte arriving, which may end a frame to ACK. Further
    /// ones (the idle wake, the engine's timeouts) may be late by under a
    /// millisecond, and the page does not spin for them.
    const PRECISE_MS: f64 = 2.0;

    thread_local! {
        static WAKER: RefCell<Option<Waker>> = const { RefCell::new(None) };
    }

    pub fn install(run: Rc<dyn Fn()>) {
        let Some(window) = web_sys::window() else {
            return;
        };
        let on_message = Closure::<dyn FnMut()>::new(|| {
            with(|w| w.posted = false);
            arm();
        });
        let _ =
            window.add_event_listener_with_callback("message", on_message.as_ref().unchecked_ref());
        WAKER.with(|w| {
            *w.borrow_mut() = Some(Waker {
                run,
                due: f64::INFINITY,
                posted: false,
                timer: None,
                window,
                _on_message: on_message,
            })
        });
    }

    fn with<R: Default>(f: impl FnOnce(&mut Waker) -> R) -> R {
        WAKER.with(|w| w.borrow_mut().as_mut().map(f).unwrap_or_default())
    }

    /// Runs if due, else waits for the time left: the whole milliseconds
    /// by the one timer, the rest by messages.
    fn arm() {
        let now = page_now_us();
        let run = with(|w| {
            if w.due <= now + 100.0 {
                w.due = f64::INFINITY;
                return Some(w.run.clone());
            }
            let left = (w.due - now) / 1_000.0;
            let ms = if left < PRECISE_MS {
                left.floor()
            } else {
                left.ceil()
            };
            if ms < 1.0 {
                w.post();
            } else if ms.is_finite() && w.timer.is_none() {
                w.timer = Some(Timeout::new(ms as u32, || {
                    with(|w| w.timer = None);
                    arm();
                }));
            }
            None
        });
        if let Some(run) = run {
            run();
        }
    }

    pub fn at(page_us: f64) {
        with(|w| {
            if page_us >= w.due {
                return;
            }
            w.due = page_us;
            w.timer = None;
            w.post();
        });
    }

    impl Waker {
        /// Has the page look again once its tasks queued so far have run.
        fn post(&mut self) {
            if !self.posted {
                self.posted = self.window.post_message(&JsValue::NULL, "*").is_ok();
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

/// Has the browser lay the page out now (style and layout of what the
/// views changed; the paint still comes with the next frame).
pub fn lay_out() {
    #[cfg(target_arch = "wasm32")]
    if let Some(body) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.body())
    {
        let _ = body.offset_height();
    }
}

/// Runs the page's work as soon as the page can (bytes came, the user
/// acted).
pub fn soon() {
    at(0.0);
}

/// Runs the page's work when the page's clock reaches `page_us` (µs), or
/// earlier if asked.
pub fn at(page_us: f64) {
    #[cfg(target_arch = "wasm32")]
    page::at(page_us);
    #[cfg(not(target_arch = "wasm32"))]
    let _ = page_us;
}
