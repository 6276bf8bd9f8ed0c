//! The page's wake in headless Chromium, installed as the console
//! installs it (`app.rs`): a draw holds the line until the page has
//! painted a frame, then the page runs and the line goes on
//! (`wake::Draw`); a deadline the page's clock has not reached is waited
//! for, not run early and asked again through a message after message.
//! A suite of its own: the other suites drive their sessions with their
//! own timers, and a session's draws wait for frames only under the
//! wake.
#![cfg(target_arch = "wasm32")]

use js_sys::Promise;
use plm_console::clock::page_now_us;
use plm_console::wake::{self, Draw};
use std::cell::Cell;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

/// Waits for the page's next frame.
async fn next_frame() {
    let frame = Promise::new(&mut |resolve, _| {
        let _ = web_sys::window()
            .expect("a window")
            .request_animation_frame(&resolve);
    });
    JsFuture::from(frame).await.expect("a frame");
}

/// Waits `ms` on the page's timers.
async fn sleep(ms: i32) {
    let promise = Promise::new(&mut |resolve, _| {
        let _ = web_sys::window()
            .expect("a window")
            .set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, ms);
    });
    JsFuture::from(promise).await.expect("a timer");
}

thread_local! {
    /// Times the page's work ran.
    static RUNS: Cell<u32> = const { Cell::new(0) };
    /// µs ahead the page's work asks to run again (0: it does not).
    static AGAIN_US: Cell<f64> = const { Cell::new(0.0) };
    static INSTALLED: Cell<bool> = const { Cell::new(false) };
}

fn runs() -> u32 {
    RUNS.with(Cell::get)
}

/// The wake installed once for the suite (as the console does, once a
/// page), its work counted.
fn install() {
    if !INSTALLED.with(|i| i.replace(true)) {
        wake::install(|| {
            RUNS.with(|r| r.set(r.get() + 1));
            let ahead = AGAIN_US.with(Cell::get);
            if ahead > 0.0 {
                wake::at(page_now_us() + ahead);
            }
        });
    }
}

#[wasm_bindgen_test]
async fn a_draw_holds_the_line_until_the_page_has_painted_a_frame() {
    install();
    next_frame().await;
    sleep(5).await;
    let (before, ran) = (wake::frames(), runs());
    let mut draw = Draw::default();
    draw.begin();
    draw.settle();
    assert!(draw.pending(), "no frame painted since the draw");
    // The frame the draw asked for is counted once painted (within
    // 100 ms: a draw gives up waiting after 50 ms, but that is not a
    // frame).
    next_frame().await;
    for _ in 0..20 {
        if wake::frames() > before && runs() > ran {
            break;
        }
        sleep(5).await;
    }
    assert!(wake::frames() > before, "the frame after the draw counted");
    // The page ran once it was painted, for what waited for the paint:
    // nothing else asked for it here.
    assert!(runs() > ran, "the page ran after the paint");
    draw.settle();
    assert!(!draw.pending(), "painted: the line goes on");
}

/// A draw handed out in the moment between a frame's callbacks (the
/// wake's among them) and the message that counts the frame: that frame
/// was painted before the draw, which waits for the next.
#[wasm_bindgen_test]
async fn a_draw_handed_out_as_a_frame_is_counted_waits_for_the_next() {
    install();
    next_frame().await;
    sleep(5).await;
    let before = wake::frames();
    let mut first = Draw::default();
    first.begin();
    // The wake asks for a frame; this task's own callback runs after its.
    first.settle();
    next_frame().await;
    let mut draw = Draw::default();
    draw.begin();
    assert!(settled(&mut first).await, "the frame counted");
    draw.settle();
    assert!(
        draw.pending(),
        "painted before the draw: {} frames, {before} before",
        wake::frames()
    );
    assert!(settled(&mut draw).await, "the next frame counted");
}

/// Whether `draw`'s wait ends within 100 ms.
async fn settled(draw: &mut Draw) -> bool {
    for _ in 0..20 {
        draw.settle();
        if !draw.pending() {
            return true;
        }
        sleep(5).await;
    }
    false
}

/// Work that asks to run again 50 µs on, less than the page's clock's step
/// in a page that is not cross-origin isolated (100 µs), runs when the
/// clock has reached it: about once a millisecond by the timer, not at
/// once through a message, run after run, each finding it not due yet.
#[wasm_bindgen_test]
async fn a_deadline_the_clock_has_not_reached_is_waited_for_not_spun_on() {
    install();
    next_frame().await;
    let messages = std::rc::Rc::new(Cell::new(0u32));
    let counted = messages.clone();
    let listener = Closure::<dyn FnMut()>::new(move || counted.set(counted.get() + 1));
    let window = web_sys::window().expect("a window");
    window
        .add_event_listener_with_callback("message", listener.as_ref().unchecked_ref())
        .expect("a listener");
    let ran = runs();
    AGAIN_US.with(|a| a.set(50.0));
    wake::soon();
    sleep(30).await;
    AGAIN_US.with(|a| a.set(0.0));
    let (runs, messages) = (runs() - ran, messages.get());
    window
        .remove_event_listener_with_callback("message", listener.as_ref().unchecked_ref())
        .expect("no listener");
    assert!(runs >= 10, "the work goes on: {runs} runs in 30 ms");
    assert!(
        messages <= runs / 2 + 2,
        "{messages} messages for {runs} runs: the wake spun on messages"
    );
}
