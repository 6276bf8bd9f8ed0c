//! The WebSerial transport in headless Chromium, the real transport code
//! on a scripted `navigator.serial`: the same shim the browser journeys
//! use (`tests/e2e/serial-shim.mjs`), whose one adapter is wired here to
//! plm-sim's modem running in the page in real time. RTS drives the
//! simulated modem's T_REQ, so the order of bytes and RTS changes, the
//! polarity switch, baud changes and a lost port are all checked against
//! a modem that depends on them (UM0932 3.2.8). `cargo xtask test` runs
//! this with wasm-bindgen-test-runner.
#![cfg(target_arch = "wasm32")]

mod browser;

use browser::{sleep, Driven, Exclusive};
use js_sys::{Array, Function, Promise, Reflect, Uint8Array};
use plm_console::clock::page_now_us;
use plm_console::session::{Outcome, Session};
use plm_console::transport::webserial::{self, OnLost, Settings, TReqPolarity, WebSerialTransport};
use plm_console::transport::{LinkState, Transport};
use plm_core::st7580::Command;
use plm_sim::{Fault, Sim, SimConfig};
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;
use wasm_bindgen_test::*;
use web_sys::SerialPort;

wasm_bindgen_test_configure!(run_in_browser);

/// The shim, as the browser journeys inject it.
const SHIM: &str = include_str!("../../../tests/e2e/serial-shim.mjs");
/// The shim's one adapter.
const ADAPTER: &str = "ftdi-0";

/// What reached the adapter, in order.
#[derive(Debug, Clone, PartialEq)]
enum Wire {
    /// Opened: baud, data bits, stop bits, parity, flow control.
    Open(u32, u32, u32, String, String),
    Write(Vec<u8>),
    /// RTS level, `true` = asserted.
    Rts(bool),
    Close,
}

struct Modem {
    sim: Sim,
    /// Page time (µs) at which the simulation's clock read 0.
    origin: f64,
    /// An inverting level shifter between RTS and T_REQ.
    inverted: bool,
    wire: Vec<Wire>,
}

impl Modem {
    /// Lets the simulated modem's time catch up with the page's clock and
    /// hands what it sent to the adapter.
    fn advance(&mut self) {
        let now = (page_now_us() - self.origin).max(0.0) as u64;
        self.sim.advance_to(now);
        let bytes: Vec<u8> = self.sim.host_read().into_iter().map(|(_, b)| b).collect();
        if !bytes.is_empty() {
            let shim = Reflect::get(&window(), &"__plmSerialShim".into()).expect("the shim");
            let receive: Function = Reflect::get(&shim, &"receive".into())
                .expect("receive")
                .unchecked_into();
            receive
                .call2(&shim, &ADAPTER.into(), &Uint8Array::from(&bytes[..]))
                .expect("receive");
        }
    }
}

/// A simulated ST7580 behind the shim's adapter, running while it lives.
struct Adapter {
    modem: Rc<RefCell<Modem>>,
    interval: i32,
    _closures: Vec<Closure<dyn FnMut(JsValue, JsValue) -> Promise>>,
    _pump: Closure<dyn FnMut()>,
}

/// A flag of the shim's `state()` of the adapter (`open`, `plugged`).
fn shim_state(flag: &str) -> bool {
    let shim = Reflect::get(&window(), &"__plmSerialShim".into()).expect("the shim");
    let f: Function = Reflect::get(&shim, &"state".into())
        .expect("state")
        .unchecked_into();
    let state = f.call1(&shim, &ADAPTER.into()).expect("state");
    Reflect::get(&state, &flag.into())
        .ok()
        .and_then(|v| v.as_bool())
        .unwrap_or(false)
}

fn window() -> web_sys::Window {
    web_sys::window().expect("a window")
}

fn text(v: &JsValue, key: &str) -> String {
    Reflect::get(v, &key.into())
        .ok()
        .and_then(|v| v.as_string())
        .unwrap_or_default()
}

fn number(v: &JsValue, key: &str) -> u32 {
    Reflect::get(v, &key.into())
        .ok()
        .and_then(|v| v.as_f64())
        .unwrap_or(0.0) as u32
}

impl Adapter {
    /// Installs the shim once, grants its adapter to this page, and wires
    /// the adapter to a fresh simulated modem once the last test's port is
    /// closed.
    async fn new(inverted: bool) -> Adapter {
        let w = window();
        if !Reflect::has(&w, &"__plmSerialShim".into()).unwrap_or(false) {
            Function::new_no_args(SHIM)
                .call0(&JsValue::NULL)
                .expect("the shim runs");
        }
        let started = page_now_us();
        while shim_state("open") {
            assert!(
                page_now_us() - started < 1e6,
                "the last test's port stays open"
            );
            sleep(1).await;
        }
        w.local_storage()
            .ok()
            .flatten()
            .expect("localStorage")
            .set_item("plm-e2e-shim.granted", &format!("[\"{ADAPTER}\"]"))
            .expect("granted");
        let modem = Rc::new(RefCell::new(Modem {
            sim: Sim::new(SimConfig {
                seed: 11,
                nodes: 1,
                baud: 57_600,
                ..SimConfig::default()
            }),
            origin: page_now_us(),
            inverted,
            wire: Vec::new(),
        }));
        let resolved = || Promise::resolve(&JsValue::TRUE);
        let binding = |f: Binding| {
            let modem = modem.clone();
            let mut f = f;
            Closure::<dyn FnMut(JsValue, JsValue) -> Promise>::new(
                move |_id: JsValue, arg: JsValue| {
                    let mut m = modem.borrow_mut();
                    m.advance();
                    f(&mut m, arg);
                    resolved()
                },
            )
        };
        let closures = vec![
            // The modem's UART follows the baud rate the port opens at, as
            // `plm sim` follows RFC 2217's SET-BAUDRATE.
            binding(Box::new(|m, s| {
                let baud = number(&s, "baudRate");
                m.sim.set_baud(baud);
                m.wire.push(Wire::Open(
                    baud,
                    number(&s, "dataBits"),
                    number(&s, "stopBits"),
                    text(&s, "parity"),
                    text(&s, "flowControl"),
                ));
            })),
            binding(Box::new(|m, bytes| {
                let bytes: Vec<u8> = Array::from(&bytes)
                    .iter()
                    .map(|b| b.as_f64().unwrap_or(0.0) as u8)
                    .collect();
                m.sim.write(&bytes);
                m.wire.push(Wire::Write(bytes));
            })),
            binding(Box::new(|m, signals| {
                let rts = Reflect::get(&signals, &"rts".into())
                    .ok()
                    .and_then(|v| v.as_bool())
                    .unwrap_or(false);
                let treq = rts ^ m.inverted;
                m.sim.set_treq(treq);
                m.wire.push(Wire::Rts(rts));
            })),
            binding(Box::new(|m, _| m.wire.push(Wire::Close))),
        ];
        for (name, c) in [
            "__plmSerialOpen",
            "__plmSerialWrite",
            "__plmSerialSignals",
            "__plmSerialClose",
        ]
        .iter()
        .zip(&closures)
        {
            Reflect::set(&w, &(*name).into(), c.as_ref()).expect("binding");
        }
        let pumped = modem.clone();
        let pump = Closure::<dyn FnMut()>::new(move || pumped.borrow_mut().advance());
        let interval = w
            .set_interval_with_callback_and_timeout_and_arguments_0(
                pump.as_ref().unchecked_ref(),
                1,
            )
            .expect("setInterval");
        let adapter = Adapter {
            modem,
            interval,
            _closures: closures,
            _pump: pump,
        };
        adapter.shim("replug");
        adapter
    }

    fn shim(&self, method: &str) {
        let shim = Reflect::get(&window(), &"__plmSerialShim".into()).expect("the shim");
        let f: Function = Reflect::get(&shim, &method.into())
            .expect("method")
            .unchecked_into();
        f.call1(&shim, &ADAPTER.into()).expect("shim call");
    }

    fn wire(&self) -> Vec<Wire> {
        self.modem.borrow().wire.clone()
    }

    fn inject(&self, fault: Fault) {
        let mut m = self.modem.borrow_mut();
        m.advance();
        m.sim.inject(fault);
    }

    /// The granted port, as the port chooser gets it.
    async fn port(&self) -> SerialPort {
        let serial = webserial::serial().expect("navigator.serial (the shim)");
        let ports = JsFuture::from(serial.get_ports()).await.expect("getPorts");
        Array::from(&ports).get(0).unchecked_into()
    }
}

impl Drop for Adapter {
    fn drop(&mut self) {
        window().clear_interval_with_handle(self.interval);
    }
}

type Lost = Rc<RefCell<Vec<String>>>;
/// What one of the shim's bindings does to the modem.
type Binding = Box<dyn FnMut(&mut Modem, JsValue)>;

async fn open(adapter: &Adapter, settings: Settings) -> (WebSerialTransport, Lost) {
    let lost = Lost::default();
    let seen = lost.clone();
    let on_lost: OnLost = Rc::new(move |why| seen.borrow_mut().push(why));
    let t = WebSerialTransport::open(adapter.port().await, "FTDI".into(), settings, on_lost)
        .await
        .expect("the port opens");
    (t, lost)
}

const DEFAULT: Settings = Settings {
    baud: 57_600,
    polarity: TReqPolarity::RtsAssertedIsLow,
    rts_twice: false,
};

/// Index of the first element of `wire` after `from` that `f` picks.
fn find(wire: &[Wire], from: usize, f: impl Fn(&Wire) -> bool) -> Option<usize> {
    wire.iter().skip(from).position(f).map(|i| i + from)
}

#[wasm_bindgen_test]
async fn a_port_opens_8n1_with_treq_released_and_a_ping_toggles_rts_around_the_stx() {
    let _page = Exclusive::take().await;
    let adapter = Adapter::new(false).await;
    let (t, lost) = open(&adapter, DEFAULT).await;
    assert_eq!(t.kind(), "WebSerial");
    assert_eq!(t.port(), "FTDI (WebSerial)");
    // UM0932 3.1: 8 data bits, no parity, 1 stop bit; RTS is T_REQ, not
    // flow control. T_REQ released (RTS not asserted) before anything.
    assert_eq!(
        adapter.wire()[..2],
        [
            Wire::Open(57_600, 8, 1, "none".into(), "none".into()),
            Wire::Rts(false)
        ]
    );
    let mut d = Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ));
    // The modem powered on with the adapter (20 ms boot): its reset
    // indication comes through the port first.
    d.booted(1_000.0).await;
    assert_eq!(
        d.answer(Command::PingRequest {
            data: vec![1, 2, 3]
        })
        .await,
        Command::PingConfirm {
            data: vec![1, 2, 3]
        }
    );
    // UM0932 3.2.8: T_REQ low, the status message, the frame's STX, T_REQ
    // high again; then the host ACKs the modem's confirm.
    let wire = adapter.wire();
    let asserted = find(&wire, 2, |w| *w == Wire::Rts(true)).expect("T_REQ asserted");
    let stx = find(
        &wire,
        asserted,
        |w| matches!(w, Wire::Write(b) if b.first() == Some(&0x02)),
    )
    .expect("the request's STX");
    let released = find(&wire, asserted, |w| *w == Wire::Rts(false)).expect("T_REQ released");
    assert!(asserted < stx && stx < released, "{wire:?}");
    let first_write = find(&wire, asserted, |w| matches!(w, Wire::Write(_)));
    assert_eq!(
        first_write,
        Some(stx),
        "the frame is the first thing written: {wire:?}"
    );
    // The ACK of the confirm goes out through the output queue.
    let acked = d
        .run_until(200.0, |_| {
            adapter.wire().last() == Some(&Wire::Write(vec![0x06]))
        })
        .await;
    assert!(acked, "the confirm ACKed: {:?}", adapter.wire());
    assert!(lost.borrow().is_empty());
    let acks = d.session.ack_latency();
    assert!(acks.count >= 1 && acks.page.max < 40_000, "{acks:?}");
}

#[wasm_bindgen_test]
async fn the_inverted_polarity_drives_rts_the_other_way_and_the_modem_still_answers() {
    let _page = Exclusive::take().await;
    let adapter = Adapter::new(true).await;
    let settings = Settings {
        polarity: TReqPolarity::RtsAssertedIsHigh,
        ..DEFAULT
    };
    let (t, _) = open(&adapter, settings).await;
    assert_eq!(
        adapter.wire()[1],
        Wire::Rts(true),
        "T_REQ released = RTS asserted"
    );
    let mut d = Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ));
    assert_eq!(
        d.answer(Command::PingRequest { data: vec![9] }).await,
        Command::PingConfirm { data: vec![9] }
    );
    let rts: Vec<bool> = adapter
        .wire()
        .iter()
        .filter_map(|w| match w {
            Wire::Rts(r) => Some(*r),
            _ => None,
        })
        .collect();
    assert_eq!(rts[..3], [true, false, true], "{rts:?}");
}

#[wasm_bindgen_test]
async fn a_modem_reset_is_reported_through_the_port() {
    let _page = Exclusive::take().await;
    let adapter = Adapter::new(false).await;
    let (t, _) = open(&adapter, DEFAULT).await;
    let mut d = Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ));
    d.run_until(100.0, |_| false).await;
    adapter.inject(Fault::ModemReset);
    d.booted(1_000.0).await;
}

#[wasm_bindgen_test]
async fn a_baud_change_reopens_the_port_at_the_new_rate_and_keeps_talking() {
    let _page = Exclusive::take().await;
    let adapter = Adapter::new(false).await;
    let (t, _) = open(&adapter, DEFAULT).await;
    let mut d = Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ));
    d.session.set_baud(19_200);
    assert_eq!(d.session.transport().map(|t| t.baud()), Some(19_200));
    let reopened = d
        .run_until(1_000.0, |_| {
            adapter
                .wire()
                .iter()
                .any(|w| matches!(w, Wire::Open(19_200, ..)))
        })
        .await;
    assert!(reopened, "{:?}", adapter.wire());
    let wire = adapter.wire();
    let close = find(&wire, 0, |w| *w == Wire::Close).expect("closed first");
    let open = find(&wire, 0, |w| matches!(w, Wire::Open(19_200, ..))).expect("reopened");
    assert!(close < open);
    assert_eq!(adapter.modem.borrow().sim.baud(), 19_200);
    assert_eq!(
        d.answer(Command::PingRequest { data: vec![7; 20] }).await,
        Command::PingConfirm { data: vec![7; 20] }
    );
}

#[wasm_bindgen_test]
async fn a_port_unplugged_mid_command_fails_it_in_words_and_opens_again_once_back() {
    let _page = Exclusive::take().await;
    let adapter = Adapter::new(false).await;
    let (t, lost) = open(&adapter, DEFAULT).await;
    let mut d = Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ));
    let outcomes = d.outcomes.clone();
    d.session.request(
        Command::PingRequest { data: vec![1] }.to_frame(),
        Driven::keep(outcomes),
    );
    d.tick();
    assert_eq!(d.session.outstanding(), 1, "in flight");
    adapter.shim("unplug");
    let started = page_now_us();
    let failed = d
        .run_until(1_000.0, |d| !d.outcomes.borrow().is_empty())
        .await;
    assert!(failed, "the request is stuck");
    // Well before the link's own timeouts (T_SR 200 ms, repeated) would
    // have given up.
    assert!(page_now_us() - started < 100_000.0);
    let why = match &d.outcomes.borrow()[0] {
        Outcome::Failed(why) => why.clone(),
        other => panic!("{other:?}"),
    };
    assert!(why.starts_with("the serial port was unplugged"), "{why}");
    assert_eq!(
        lost.borrow().as_slice(),
        std::slice::from_ref(&why),
        "told once"
    );
    assert_eq!(d.session.state(), LinkState::Disconnected(why));
    assert_eq!(d.session.outstanding(), 0);
    // Nothing is stuck: once back, the same port opens again and works.
    adapter.shim("replug");
    let (t, _) = open(&adapter, DEFAULT).await;
    d.session
        .replace_transport(Some(Box::new(t)), plm_core::link::Dialect::St7580);
    assert_eq!(
        d.answer(Command::PingRequest { data: vec![2] }).await,
        Command::PingConfirm { data: vec![2] }
    );
}

#[wasm_bindgen_test]
async fn closing_lets_go_of_the_port_and_an_open_port_is_refused_in_words() {
    let _page = Exclusive::take().await;
    let adapter = Adapter::new(false).await;
    let (t, _) = open(&adapter, DEFAULT).await;
    let mut d = Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ));
    // The same port twice: Web Serial refuses, the console says why.
    let second = WebSerialTransport::open(
        adapter.port().await,
        "FTDI".into(),
        DEFAULT,
        Rc::new(|_| {}),
    )
    .await;
    match second {
        Err(why) => assert!(why.starts_with("the port is already open"), "{why}"),
        Ok(_) => panic!("opened twice"),
    }
    d.session
        .replace_transport(None, plm_core::link::Dialect::St7580);
    let closed = d
        .run_until(1_000.0, |_| adapter.wire().last() == Some(&Wire::Close))
        .await;
    assert!(closed, "{:?}", adapter.wire());
    sleep(10).await;
    let (t, lost) = open(&adapter, DEFAULT).await;
    drop(t);
    sleep(10).await;
    assert!(lost.borrow().is_empty(), "closing on purpose is not a loss");
}
