//! The browser's local storage, for what the console keeps across
//! reloads (the serial port's settings, an update campaign). Natively
//! (the tests) there is none: nothing is kept.

/// The value kept under `key`.
pub fn load(key: &str) -> Option<String> {
    #[cfg(target_arch = "wasm32")]
    {
        web_sys::window()?
            .local_storage()
            .ok()??
            .get_item(key)
            .ok()?
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let _ = key;
        None
    }
}

/// Keeps `value` under `key`; `None` forgets it. Whether it was kept
/// (the storage may be full or refused).
pub fn store(key: &str, value: Option<&str>) -> bool {
    #[cfg(target_arch = "wasm32")]
    {
        let Some(s) = web_sys::window().and_then(|w| w.local_storage().ok().flatten()) else {
            return false;
        };
        match value {
            Some(v) => s.set_item(key, v).is_ok(),
            None => s.remove_item(key).is_ok(),
        }
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let _ = (key, value);
        false
    }
}
