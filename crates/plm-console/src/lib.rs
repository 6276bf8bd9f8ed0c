//! PLM Console: the browser console for ST power line modems.
//!
//! - [`transport`]: byte transports with T_REQ (the simulated modem,
//!   WebSerial).
//! - [`session`]: plm-core's host link engine over a transport, requests
//!   matched with their answers.
//! - [`street`]: plm-core's concentrator over a transport, and the fleet
//!   of lamps it learns about.
//! - [`traffic`]: the inspector's bounded, filterable, exportable log.
//! - [`mibform`]: MIB forms read from plm-core's declarative description.
//! - [`network`]: what an ST7570 tells of its S-FSK network.
//! - [`app`], [`stores`], [`views`]: the Leptos application.
//! - [`bench_hook`]: `window.plmBench`, for `cargo xtask bench`.
//! - [`wake`]: when the page runs the sessions (bytes, deadlines, the
//!   user), instead of a fixed timer.

/// Talc instead of dlmalloc: smaller and faster in WebAssembly.
#[cfg(all(target_arch = "wasm32", not(target_feature = "atomics")))]
#[global_allocator]
static ALLOCATOR: talc::wasm::WasmDynamicTalc = talc::wasm::new_wasm_dynamic_allocator();

pub mod clock;
pub mod driver;
pub mod fleet;
pub mod line_events;
pub mod long_table;
pub mod mibform;
pub mod network;
pub mod numbers;
pub mod profile;
pub mod session;
pub mod storage;
pub mod street;
pub mod tab;
pub mod throttle;
pub mod traffic;
pub mod transport;

pub mod app;
pub mod bench_hook;
pub mod campaign_store;
pub mod history_store;
pub mod stores;
pub mod street_store;
pub mod views;
pub mod wake;
