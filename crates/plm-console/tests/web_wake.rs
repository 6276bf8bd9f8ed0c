//! The page's wake in headless Chromium, installed as the console
//! installs it (`app.rs`): a draw holds the line until the page has
//! painted a frame, then the page runs and the line goes on
//! (`wake::Draw`). A suite of its own: the other suites drive their
//! sessions with their own timers, and a session's draws wait for frames
//! only under the wake.
#![cfg(target_arch = "wasm32")]

use js_sys::Promise;
use plm_console::wake::{self, Draw};
use std::cell::Cell;
use std::rc::Rc;
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

#[wasm_bindgen_test]
async fn a_draw_holds_the_line_until_the_page_has_painted_a_frame() {
    let runs = Rc::new(Cell::new(0u32));
    let counted = runs.clone();
    wake::install(move || counted.set(counted.get() + 1));
    next_frame().await;
    sleep(5).await;
    let (before, ran) = (wake::frames(), runs.get());
    let mut draw = Draw::default();
    draw.begin();
    draw.settle();
    assert!(draw.pending(), "no frame painted since the draw");
    // The frame the draw asked for is counted once painted (within
    // 100 ms: a draw gives up waiting after 50 ms, but that is not a
    // frame).
    next_frame().await;
    for _ in 0..20 {
        if wake::frames() > before {
            break;
        }
        sleep(5).await;
    }
    assert!(wake::frames() > before, "the frame after the draw counted");
    // The page ran once it was painted, for what waited for the paint:
    // nothing else asked for it here.
    assert!(runs.get() > ran, "the page ran after the paint");
    draw.settle();
    assert!(!draw.pending(), "painted: the line goes on");
}
