//! The WebSerial transport: a real modem on a USB-UART adapter, through the
//! browser's Web Serial API (web-sys with `web_sys_unstable_apis`).
//!
//! The [`Transport`] trait is synchronous and the Web Serial API is not, so
//! the transport keeps a small shared state between the session and two
//! tasks of the page:
//!
//! - a **read loop** that takes every chunk the port delivers, stamps it
//!   with the page's clock (`performance.now()`, µs) and buffers it until
//!   the session's next [`Transport::poll`];
//! - an **output queue** that carries out writes, RTS changes and baud
//!   changes strictly in the order the link engine asked for them: the host
//!   engine releases T_REQ right after the STX of its frame (UM0932 3.2.8),
//!   so the order of bytes and RTS changes on the wire is part of the
//!   protocol.
//!
//! T_REQ is on RTS (docs/console.md, "Real adapters"), with a selectable
//! polarity. A lost port (the `disconnect` event of `navigator.serial`, a
//! fatal read error, a failed write) turns the state into
//! `Disconnected("the serial port was unplugged: …")` at once: the queue is
//! emptied, the reader is cancelled, both stream locks are released and the
//! port is closed, so that nothing stays stuck and the same port can be
//! opened again once it is back.

use super::{LinkState, Transport};
use crate::clock::page_now_us;
use js_sys::{Reflect, Uint8Array};
use plm_core::time::Instant;
use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::{Rc, Weak};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_futures::spawn_local;
use web_sys::{
    FlowControlType, ParityType, ReadableStream, ReadableStreamDefaultReader,
    ReadableStreamReadResult, Serial, SerialOptions, SerialOutputSignals, SerialPort,
    WritableStreamDefaultWriter,
};

/// Which level of RTS asserts T_REQ.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TReqPolarity {
    /// RTS asserted drives T_REQ low (asserted): RTS is active low at the
    /// adapter's pin, wired straight to T_REQ. The usual wiring.
    #[default]
    RtsAssertedIsLow,
    /// RTS asserted drives T_REQ high (released): an inverting level
    /// shifter or transistor between the adapter and the modem.
    RtsAssertedIsHigh,
}

impl TReqPolarity {
    /// Both choices, default first.
    pub const ALL: [TReqPolarity; 2] = [
        TReqPolarity::RtsAssertedIsLow,
        TReqPolarity::RtsAssertedIsHigh,
    ];

    /// The RTS level (`true` = asserted) that puts T_REQ at `treq_asserted`.
    pub fn rts(self, treq_asserted: bool) -> bool {
        treq_asserted ^ (self == TReqPolarity::RtsAssertedIsHigh)
    }

    /// In words, for the polarity switch.
    pub fn label(self) -> &'static str {
        match self {
            TReqPolarity::RtsAssertedIsLow => "RTS asserted = T_REQ low",
            TReqPolarity::RtsAssertedIsHigh => "RTS asserted = T_REQ high (inverted)",
        }
    }

    /// A short stable name, for storage and form values.
    pub fn key(self) -> &'static str {
        match self {
            TReqPolarity::RtsAssertedIsLow => "low",
            TReqPolarity::RtsAssertedIsHigh => "high",
        }
    }

    /// The polarity of a [`TReqPolarity::key`].
    pub fn from_key(key: &str) -> Option<TReqPolarity> {
        TReqPolarity::ALL.into_iter().find(|p| p.key() == key)
    }
}

/// How to open the port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Settings {
    /// UART baud rate (the modem's BR0/BR1 pins, UM0932 3.1).
    pub baud: u32,
    /// Which RTS level asserts T_REQ.
    pub polarity: TReqPolarity,
    /// Each RTS change is sent twice: Windows' usbser driver applies the
    /// RTS level of the call before (docs/console.md, "Real adapters").
    pub rts_twice: bool,
}

/// Called once, with the reason in words, when the port is lost.
pub type OnLost = Rc<dyn Fn(String)>;

/// A modem T_IC under which a frame's bytes are written together, T_REQ
/// released after them instead of between STX and the rest: WebSerial
/// gives no timing between a write and a signal change (each a USB
/// transfer, queued by the browser), while the ST7570's T_IC of 5
/// characters is 869 µs at 57600 baud (ST7570 UM 5.2.2, 6.5.12). The
/// ST7580's 10 ms (UM0932 3.2.6) keeps the manual's order.
pub const WHOLE_FRAMES_BELOW: plm_core::time::Duration = 10_000;

/// How late a USB-UART adapter behind WebSerial may deliver bytes: an
/// FTDI chip holds received bytes up to its latency timer (16 ms by
/// default), and the browser queues reads, writes and signal changes
/// behind it (each a USB transfer; through the e2e suite's scripted port
/// a T_REQ-to-status round trip took up to about 40 ms on a busy
/// machine). The host waits this much longer for the modem (T_POLL,
/// T_ACK, T_IC between received bytes); the ST7570's T_POLL of 20 ms
/// (ST7570 UM Table 14) is otherwise shorter than one held packet. Only a
/// slower retry is lost when the modem really is silent.
pub const LATENCY: plm_core::time::Duration = 50_000;

/// What the output queue carries out, in order.
enum Op {
    Write(Vec<u8>),
    /// RTS level (`true` = asserted).
    Rts(bool),
    /// DTR level (`true` = asserted).
    Dtr(bool),
    /// Close and open the port again at this baud rate.
    Reopen(u32),
}

struct Shared {
    port: SerialPort,
    state: LinkState,
    /// Received bytes with their arrival time on the page's clock, µs.
    rx: VecDeque<(f64, u8)>,
    ops: VecDeque<Op>,
    /// Whether the output task is running.
    busy: bool,
    reader: Option<ReadableStreamDefaultReader>,
    writer: Option<WritableStreamDefaultWriter>,
    /// Bumped whenever the reader is given up on purpose (baud change,
    /// close, loss): an older read loop then ends quietly.
    generation: u32,
    /// The RTS level last asked for.
    rts: bool,
    /// The DTR level to set, if DTR is the modem's RESETN.
    dtr: Option<bool>,
    /// Whether each RTS change is sent twice ([`Settings::rts_twice`]).
    rts_twice: bool,
    /// Whether a frame's bytes are written together even when T_REQ is
    /// to change between them ([`WHOLE_FRAMES_BELOW`]).
    whole_frames: bool,
    /// Non-fatal receive errors (framing, parity, break, overrun) so far.
    receive_errors: u32,
    disconnect_listener: Option<Closure<dyn FnMut(web_sys::Event)>>,
    on_lost: Option<OnLost>,
}

/// A granted Web Serial port, open, as a [`Transport`].
///
/// Dropping it (the session switching to another transport) closes the
/// port.
pub struct WebSerialTransport {
    shared: Rc<RefCell<Shared>>,
    label: String,
    baud: u32,
    polarity: TReqPolarity,
    /// The transport's clock: how far the session has let time run, µs of
    /// the page's clock. Arrival times are clamped into the slice polled.
    polled: Instant,
}

/// `navigator.serial`, if this browser has WebSerial (and the page is a
/// secure context, which it requires).
pub fn serial() -> Option<Serial> {
    let navigator = web_sys::window()?.navigator();
    let serial = Reflect::get(&navigator, &"serial".into()).ok()?;
    (!serial.is_undefined() && !serial.is_null()).then(|| serial.unchecked_into())
}

/// A port in words: its USB ids when it has them.
pub fn describe(port: &SerialPort) -> String {
    let info = port.get_info();
    match (info.get_usb_vendor_id(), info.get_usb_product_id()) {
        (Some(v), Some(p)) => format!("USB {v:04X}:{p:04X}"),
        (Some(v), None) => format!("USB {v:04X}"),
        _ => "serial port (no USB ids)".to_string(),
    }
}

/// A JavaScript error in words (`NetworkError: The device has been lost.`).
pub fn js_error(e: &JsValue) -> String {
    let text = |k: &str| {
        Reflect::get(e, &k.into())
            .ok()
            .and_then(|v| v.as_string())
            .filter(|s| !s.is_empty())
    };
    match (text("name"), text("message")) {
        (Some(n), Some(m)) => format!("{n}: {m}"),
        (None, Some(m)) => m,
        (Some(n), None) => n,
        (None, None) => e.as_string().unwrap_or_else(|| "unknown error".to_string()),
    }
}

fn error_name(e: &JsValue) -> String {
    Reflect::get(e, &"name".into())
        .ok()
        .and_then(|v| v.as_string())
        .unwrap_or_default()
}

/// Why a port could not be opened, with what to do.
fn open_error(e: &JsValue) -> String {
    match error_name(e).as_str() {
        "InvalidStateError" => format!(
            "the port is already open ({}): close the other tab or program that uses it and try again",
            js_error(e)
        ),
        "NetworkError" => format!(
            "the port could not be opened ({}): is the adapter plugged in, and not used by another program?",
            js_error(e)
        ),
        _ => format!("the port could not be opened: {}", js_error(e)),
    }
}

fn unplugged(detail: &str) -> String {
    format!(
        "the serial port was unplugged: {detail}. Plug it back in and connect again (WebSerial), or use the simulated modem"
    )
}

/// Opens `port` at 8N1 (UM0932 3.1: 8 data bits, no parity, 1 stop bit)
/// and `baud`, with no flow control: RTS is T_REQ, not a handshake line.
async fn open_port(port: &SerialPort, baud: u32) -> Result<(), String> {
    let options = SerialOptions::new(baud);
    options.set_data_bits(8);
    options.set_stop_bits(1);
    options.set_parity(ParityType::None);
    options.set_flow_control(FlowControlType::None);
    port.open(&options)
        .await
        .map(|_| ())
        .map_err(|e| open_error(&e))
}

/// Sets RTS, and DTR when `dtr` says, in one call.
async fn set_signals(port: &SerialPort, rts: bool, dtr: Option<bool>) -> Result<(), String> {
    let signals = SerialOutputSignals::new();
    signals.set_request_to_send(rts);
    if let Some(dtr) = dtr {
        signals.set_data_terminal_ready(dtr);
    }
    port.set_signals_with_signals(&signals)
        .await
        .map(|_| ())
        .map_err(|e| format!("RTS (T_REQ) could not be set: {}", js_error(&e)))
}

/// The port's streams, locked for us.
fn lock_streams(
    port: &SerialPort,
) -> Result<(ReadableStreamDefaultReader, WritableStreamDefaultWriter), String> {
    let writer = port
        .writable()
        .get_writer()
        .map_err(|e| format!("the port cannot be written: {}", js_error(&e)))?;
    let reader: ReadableStreamDefaultReader = port.readable().get_reader().unchecked_into();
    Ok((reader, writer))
}

impl WebSerialTransport {
    /// Opens a granted `port` (described as `label`) with `settings`, T_REQ
    /// released, and starts reading. `on_lost` is called once if the port
    /// is lost later (unplugged, failed), with the reason in words.
    pub async fn open(
        port: SerialPort,
        label: String,
        settings: Settings,
        on_lost: OnLost,
    ) -> Result<WebSerialTransport, String> {
        closed(&port).await;
        open_port(&port, settings.baud).await?;
        // T_REQ released before anything else happens (UM0932 3.2.8: the
        // host asserts it only to send a frame); signals can only be set
        // once the port is open, and nothing is written before. DTR is
        // left alone until the console says it is RESETN
        // (`Transport::set_dtr`).
        let rts = settings.polarity.rts(false);
        let streams = match set_signals(&port, rts, None).await {
            Ok(()) => lock_streams(&port),
            Err(e) => Err(e),
        };
        let (reader, writer) = match streams {
            Ok(s) => s,
            Err(e) => {
                let _ = port.close().await;
                return Err(e);
            }
        };
        let shared = Rc::new(RefCell::new(Shared {
            port,
            state: LinkState::Connected,
            rx: VecDeque::new(),
            ops: VecDeque::new(),
            busy: false,
            reader: Some(reader.clone()),
            writer: Some(writer),
            generation: 0,
            rts,
            dtr: None,
            rts_twice: settings.rts_twice,
            whole_frames: false,
            receive_errors: 0,
            disconnect_listener: None,
            on_lost: Some(on_lost),
        }));
        listen_for_disconnect(&shared);
        spawn_local(read_loop(Rc::downgrade(&shared), reader, 0));
        Ok(WebSerialTransport {
            shared,
            label,
            baud: settings.baud,
            polarity: settings.polarity,
            polled: page_now_us().max(0.0) as Instant,
        })
    }

    /// Which RTS level asserts T_REQ.
    pub fn polarity(&self) -> TReqPolarity {
        self.polarity
    }

    /// Non-fatal receive errors (framing, parity, break, overrun) so far.
    pub fn receive_errors(&self) -> u32 {
        self.shared.borrow().receive_errors
    }

    fn push(&mut self, op: Op) {
        {
            let mut s = self.shared.borrow_mut();
            if !s.state.is_connected() {
                return;
            }
            // Bytes written one after the other go out as one chunk.
            if let (Op::Write(more), Some(Op::Write(queued))) = (&op, s.ops.back_mut()) {
                queued.extend_from_slice(more);
                return;
            }
            // STX, T_REQ released, the rest (UM0932 3.2.8, ST7570 UM
            // 5.2.2): with a modem that allows less than WebSerial can time
            // between two writes, the rest joins the STX and T_REQ is
            // released just after (docs/console.md, "Real adapters").
            if let (true, Op::Write(more)) = (s.whole_frames, &op) {
                let n = s.ops.len();
                if n >= 2 && matches!(s.ops[n - 1], Op::Rts(_)) {
                    if let Op::Write(queued) = &mut s.ops[n - 2] {
                        queued.extend_from_slice(more);
                        return;
                    }
                }
            }
            s.ops.push_back(op);
        }
        kick(&self.shared);
    }
}

impl Transport for WebSerialTransport {
    fn kind(&self) -> &'static str {
        "WebSerial"
    }

    fn port(&self) -> String {
        format!("{} (WebSerial)", self.label)
    }

    fn state(&self) -> LinkState {
        self.shared.borrow().state.clone()
    }

    fn now(&self) -> Instant {
        self.polled
    }

    fn baud(&self) -> u32 {
        self.baud
    }

    fn set_baud(&mut self, baud: u32) {
        if baud != self.baud {
            self.baud = baud;
            self.push(Op::Reopen(baud));
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        if !bytes.is_empty() {
            self.push(Op::Write(bytes.to_vec()));
        }
    }

    fn set_treq(&mut self, asserted: bool) {
        let rts = self.polarity.rts(asserted);
        self.push(Op::Rts(rts));
    }

    fn latency(&self) -> plm_core::time::Duration {
        LATENCY
    }

    fn set_byte_gap_limit(&mut self, t_ic: plm_core::time::Duration) {
        self.shared.borrow_mut().whole_frames = t_ic < WHOLE_FRAMES_BELOW;
    }

    /// Every byte received so far. Its time is when the page got it,
    /// clamped into the slice polled: a byte is never held back for a
    /// later slice (it would wait if the session's clock lags the page's
    /// after a stall, and T_ACK is only 40 ms), and bytes that came in one
    /// chunk share one time, which only ever shortens the gaps that T_IC
    /// (UM0932 3.2.6) measures.
    fn set_dtr(&mut self, asserted: bool) {
        self.push(Op::Dtr(asserted));
    }

    fn poll(&mut self, until: Instant) -> Vec<(Instant, u8)> {
        let from = self.polled;
        self.polled = self.polled.max(until);
        let to = self.polled;
        let mut s = self.shared.borrow_mut();
        s.rx.drain(..)
            .map(|(at, b)| ((at.max(0.0) as Instant).clamp(from, to), b))
            .collect()
    }
}

impl Drop for WebSerialTransport {
    fn drop(&mut self) {
        give_up(
            &self.shared,
            "the serial port was closed".to_string(),
            false,
        );
    }
}

/// Ends the connection: the state says `why`, nothing more is sent, the
/// reader is cancelled, the locks released and the port closed. With
/// `report`, the `on_lost` callback hears of it.
fn give_up(shared: &Rc<RefCell<Shared>>, why: String, report: bool) {
    let callback = {
        let mut s = shared.borrow_mut();
        if !s.state.is_connected() {
            return;
        }
        s.state = LinkState::Disconnected(why.clone());
        s.generation = s.generation.wrapping_add(1);
        s.ops.clear();
        s.on_lost.take()
    };
    closing(shared.clone());
    if report {
        if let Some(f) = callback {
            f(why);
        }
    }
}

thread_local! {
    /// Ports being closed, each with a promise that settles once it is:
    /// opening the same port again must wait for it (Web Serial refuses to
    /// open a port that is still open).
    static CLOSING: RefCell<Vec<(SerialPort, js_sys::Promise)>> = const { RefCell::new(Vec::new()) };
}

/// Starts closing the port of `shared`, in the background.
fn closing(shared: Rc<RefCell<Shared>>) {
    let port = shared.borrow().port.clone();
    let done = port.clone();
    let task = std::panic::AssertUnwindSafe(async move {
        release(shared).await;
        CLOSING.with(|c| {
            c.borrow_mut()
                .retain(|(p, _)| JsValue::from(p) != JsValue::from(&done))
        });
        Ok(JsValue::UNDEFINED)
    });
    let promise = wasm_bindgen_futures::future_to_promise(task);
    CLOSING.with(|c| c.borrow_mut().push((port, promise)));
}

/// Waits until `port` is closed if we are closing it.
async fn closed(port: &SerialPort) {
    let pending: Vec<js_sys::Promise> = CLOSING.with(|c| {
        c.borrow()
            .iter()
            .filter(|(p, _)| JsValue::from(p) == JsValue::from(port))
            .map(|(_, promise)| promise.clone())
            .collect()
    });
    for promise in pending {
        let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
    }
}

/// Cancels the reader, releases both locks and closes the port; every
/// step may fail on a port that is gone, and none of that matters then.
async fn release(shared: Rc<RefCell<Shared>>) {
    let (reader, writer, port, listener) = {
        let mut s = shared.borrow_mut();
        (
            s.reader.take(),
            s.writer.take(),
            s.port.clone(),
            s.disconnect_listener.take(),
        )
    };
    if let Some(r) = reader {
        let _ = wasm_bindgen_futures::JsFuture::from(r.cancel()).await;
        r.release_lock();
    }
    if let Some(w) = writer {
        w.release_lock();
    }
    let _ = port.close().await;
    if let (Some(l), Some(serial)) = (listener, serial()) {
        let _ =
            serial.remove_event_listener_with_callback("disconnect", l.as_ref().unchecked_ref());
    }
}

/// Listens for the `disconnect` event of `navigator.serial` (it comes
/// from the port and bubbles there) and gives up when it is our port.
fn listen_for_disconnect(shared: &Rc<RefCell<Shared>>) {
    let Some(serial) = serial() else { return };
    let weak = Rc::downgrade(shared);
    let listener = Closure::<dyn FnMut(web_sys::Event)>::new(move |ev: web_sys::Event| {
        let Some(shared) = weak.upgrade() else { return };
        let ours = ev
            .target()
            .is_some_and(|t| JsValue::from(t) == JsValue::from(shared.borrow().port.clone()));
        if ours {
            give_up(
                &shared,
                unplugged("the adapter went away (disconnect event)"),
                true,
            );
        }
    });
    if serial
        .add_event_listener_with_callback("disconnect", listener.as_ref().unchecked_ref())
        .is_ok()
    {
        shared.borrow_mut().disconnect_listener = Some(listener);
    }
}

/// Reads until the port is lost or the reader is given up on purpose.
async fn read_loop(
    weak: Weak<RefCell<Shared>>,
    mut reader: ReadableStreamDefaultReader,
    generation: u32,
) {
    loop {
        let result = wasm_bindgen_futures::JsFuture::from(reader.read()).await;
        let at = page_now_us();
        let Some(shared) = weak.upgrade() else { return };
        if shared.borrow().generation != generation {
            return;
        }
        match result {
            Ok(v) => {
                let r: ReadableStreamReadResult = v.unchecked_into();
                if r.get_done().unwrap_or(false) {
                    give_up(&shared, unplugged("the port stopped delivering data"), true);
                    return;
                }
                let chunk = Uint8Array::new(&r.get_value()).to_vec();
                shared
                    .borrow_mut()
                    .rx
                    .extend(chunk.into_iter().map(|b| (at, b)));
                crate::wake::soon();
            }
            Err(e) => {
                // Web Serial: after a non-fatal error (framing, parity,
                // break, buffer overrun) `readable` is a fresh stream; after
                // a fatal one (the device is lost) it is null.
                let port = shared.borrow().port.clone();
                let readable = Reflect::get(&port, &"readable".into()).unwrap_or(JsValue::NULL);
                if readable.is_null() || readable.is_undefined() {
                    give_up(&shared, unplugged(&js_error(&e)), true);
                    return;
                }
                reader.release_lock();
                let stream: ReadableStream = readable.unchecked_into();
                reader = stream.get_reader().unchecked_into();
                let mut s = shared.borrow_mut();
                s.receive_errors += 1;
                s.reader = Some(reader.clone());
            }
        }
    }
}

/// Starts the output task unless it runs already.
fn kick(shared: &Rc<RefCell<Shared>>) {
    {
        let mut s = shared.borrow_mut();
        if s.busy || s.ops.is_empty() {
            return;
        }
        s.busy = true;
    }
    let shared = shared.clone();
    spawn_local(async move {
        loop {
            let op = {
                let mut s = shared.borrow_mut();
                match s.ops.pop_front() {
                    Some(op) if s.state.is_connected() => op,
                    _ => {
                        s.busy = false;
                        return;
                    }
                }
            };
            if let Err(why) = carry_out(&shared, op).await {
                give_up(&shared, why, true);
            }
        }
    });
}

/// One operation of the output queue.
async fn carry_out(shared: &Rc<RefCell<Shared>>, op: Op) -> Result<(), String> {
    match op {
        Op::Write(bytes) => {
            let Some(writer) = shared.borrow().writer.clone() else {
                return Ok(());
            };
            let chunk = Uint8Array::from(&bytes[..]);
            wasm_bindgen_futures::JsFuture::from(writer.write_with_chunk(&chunk))
                .await
                .map(|_| ())
                .map_err(|e| unplugged(&format!("writing failed ({})", js_error(&e))))
        }
        Op::Rts(rts) => {
            let (port, dtr, twice) = {
                let mut s = shared.borrow_mut();
                s.rts = rts;
                (s.port.clone(), s.dtr, s.rts_twice)
            };
            for _ in 0..1 + u8::from(twice) {
                set_signals(&port, rts, dtr)
                    .await
                    .map_err(|e| unplugged(&e))?;
            }
            Ok(())
        }
        Op::Dtr(dtr) => {
            let (port, rts) = {
                let mut s = shared.borrow_mut();
                s.dtr = Some(dtr);
                (s.port.clone(), s.rts)
            };
            set_signals(&port, rts, Some(dtr))
                .await
                .map_err(|e| unplugged(&e))
        }
        Op::Reopen(baud) => reopen(shared, baud).await,
    }
}

/// Closes the port and opens it again at `baud` (Web Serial fixes the
/// baud rate at `open`), keeping the RTS level.
async fn reopen(shared: &Rc<RefCell<Shared>>, baud: u32) -> Result<(), String> {
    let (reader, writer, port, rts, dtr, generation) = {
        let mut s = shared.borrow_mut();
        s.generation = s.generation.wrapping_add(1);
        (
            s.reader.take(),
            s.writer.take(),
            s.port.clone(),
            s.rts,
            s.dtr,
            s.generation,
        )
    };
    let still_ours = || {
        let s = shared.borrow();
        s.state.is_connected() && s.generation == generation
    };
    if let Some(r) = reader {
        let _ = wasm_bindgen_futures::JsFuture::from(r.cancel()).await;
        r.release_lock();
    }
    if let Some(w) = writer {
        w.release_lock();
    }
    port.close().await.map_err(|e| {
        format!(
            "the port could not be closed to change the baud rate: {}",
            js_error(&e)
        )
    })?;
    if !still_ours() {
        return Ok(());
    }
    open_port(&port, baud).await?;
    if !still_ours() {
        let _ = port.close().await;
        return Ok(());
    }
    set_signals(&port, rts, dtr).await?;
    let (reader, writer) = lock_streams(&port)?;
    {
        let mut s = shared.borrow_mut();
        s.reader = Some(reader.clone());
        s.writer = Some(writer);
    }
    spawn_local(read_loop(Rc::downgrade(shared), reader, generation));
    Ok(())
}
