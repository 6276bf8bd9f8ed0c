//! The page's clock: what the sessions, the wake and the WebSerial
//! transport stamp and pace by.

/// The page's clock in µs (`performance.now()`; 0 where there is none).
/// Natively (the tests) it stands where [`set_page_now_us`] put it.
pub fn page_now_us() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        performance_now() * 1_000.0
    }
    #[cfg(not(target_arch = "wasm32"))]
    NATIVE_NOW.get()
}

// `performance.now()` called straight: the drive loop reads the clock at
// every wake and every slice, and going through `window()` and
// `performance()` cost a type check and an object handle each time (5 %
// of the page's time on a busy line).
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen::prelude::wasm_bindgen]
extern "C" {
    #[wasm_bindgen(js_namespace = performance, js_name = now)]
    fn performance_now() -> f64;
}

#[cfg(not(target_arch = "wasm32"))]
thread_local! {
    static NATIVE_NOW: std::cell::Cell<f64> = const { std::cell::Cell::new(0.0) };
}

/// Natively: moves the page's clock to `us`.
#[cfg(not(target_arch = "wasm32"))]
pub fn set_page_now_us(us: f64) {
    NATIVE_NOW.set(us);
}

/// The computer's clock, local time.
pub fn computer_clock() -> plm_core::app::Clock {
    let d = js_sys::Date::new_0();
    plm_core::app::Clock {
        hours: d.get_hours() as u8,
        minutes: d.get_minutes() as u8,
        seconds: d.get_seconds() as u8,
    }
}
