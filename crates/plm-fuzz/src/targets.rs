//! The target bodies. Each takes any bytes; what it asserts holds for
//! every input (a panic is a finding).

use crate::input::{chunks, Input};
use plm_cli::rfc2217::{self, ComPort};
use plm_core::app::rfu::image;
use plm_core::app::update::Update;
use plm_core::app::{AppFrame, LineFrame, Message, UsartDecoder};
use plm_core::chip::{Chip, St7570, St7580};
use plm_core::decode::app::{decode_element, decode_usart, AppDecoded};
use plm_core::decode::{self, Decoded, Decoder, LineDecoded};
use plm_core::file::{poles, profile};
use plm_core::json::{self, Json};
use plm_core::link::device::DeviceEngine;
use plm_core::link::host::{HostConfig, HostEngine};
use plm_core::link::{
    Dialect, LocalFrame, Source, StatusMessage, TicSelector, Timeouts, BAUD_RATES,
};
use plm_core::st7570::mac::{LongFrame, MacFrame};
use plm_core::st7570::Layer;
use plm_core::time::{Instant, MS};

/// Most events or transmissions one step of an engine may queue: more
/// means a poll that never runs dry.
const DRAIN_LIMIT: usize = 10_000;

/// The source a script's first byte names (bits 4-5).
fn source(b: u8) -> Source {
    match (b >> 4) & 3 {
        0 => Source::Host,
        1 => Source::Modem,
        _ => Source::Any,
    }
}

/// An element the decoder shows must come back from its JSON export (the
/// console's Traffic export, then import).
fn reimports(d: &Decoded) {
    let exported = d.to_json();
    let text = exported.to_string();
    let parsed = json::parse(&text).expect("an export is JSON");
    assert_eq!(parsed, exported, "the export reads back as written");
    if let Err(why) = Decoded::from_json(&parsed) {
        panic!("an exported element does not import: {why}\n{text}");
    }
}

fn host_stream(dialect: Dialect, data: &[u8]) {
    let head = data.first().copied().unwrap_or(0);
    let mut decoder = Decoder::new(dialect, source(head));
    if dialect == Dialect::St7570 && head & 0x80 != 0 {
        decoder.fix_layer(if head & 0x40 != 0 {
            Layer::Mac
        } else {
            Layer::Phy
        });
    }
    for chunk in chunks(data) {
        decoder.push(chunk);
        while let Some(d) = decoder.next() {
            reimports(&d);
        }
    }
    decoder.finish();
    while let Some(d) = decoder.next() {
        reimports(&d);
    }
}

/// ST7580 host-interface bytes (UM0932 3.2) through the link stream
/// decoder and the decoder of `plm decode`. First byte: chunk size (bits
/// 0-3), source (bits 4-5).
pub fn st7580_host(data: &[u8]) {
    host_stream(Dialect::St7580, data);
}

/// ST7570 host-interface bytes (ST7570 UM 5) as [`st7580_host`]; bit 7 of
/// the first byte fixes the layer, bit 6 which (MAC or PHY).
pub fn st7570_host(data: &[u8]) {
    host_stream(Dialect::St7570, data);
}

/// The STEVAL board's USART bytes (UM 4.3): the USART decoder, each
/// element as an application frame and message, and its decoded view's
/// export. First byte: chunk size (bits 0-3), an idle line after each
/// chunk (bit 4).
pub fn steval_usart(data: &[u8]) {
    let head = data.first().copied().unwrap_or(0);
    let mut usart = UsartDecoder::new();
    for chunk in chunks(data) {
        usart.push(chunk);
        if head & 0x10 != 0 {
            usart.idle();
        }
        while let Some(e) = usart.next() {
            app_frame(e.bytes());
            let d = decode_element(&e);
            let json = d.to_json();
            if let Err(why) = AppDecoded::from_json(&json) {
                panic!("an exported application element does not import: {why}");
            }
        }
    }
    let _ = decode_usart(data);
}

/// One application frame (UM 4.3) or line frame: parsed, its message read
/// and checked, emitted again and re-parsed to the same frame.
pub fn app_frame(data: &[u8]) {
    if let Ok(frame) = AppFrame::parse(data) {
        if let Ok(m) = Message::of(&frame) {
            let _ = m.validate();
            let _ = (m.name(), m.expects(), m.payload(), m.ack());
        }
        if let Ok(bytes) = frame.emit() {
            assert_eq!(AppFrame::parse(&bytes).as_ref(), Ok(&frame));
        }
    }
    let _ = AppFrame::parse_unchecked(data);
    if let Some(line) = LineFrame::parse(data) {
        let _ = decode::app::decode_line_frame(&line);
        let app = line.to_app();
        let _ = Message::of(&app);
        assert_eq!(LineFrame::parse(&line.emit()), Some(line));
    }
}

/// A MAC frame from the power line (ST7570 UM 10.3): the long frame's
/// fields, the MAC frame (emitted again, it parses to itself) and `plm
/// decode --line`'s view and its export.
pub fn st7570_mac(data: &[u8]) {
    if let Ok(long) = LongFrame::new_checked(data) {
        let _ = (long.ns(), long.credit(), long.address(), long.pad_len());
        let _ = (long.m_sdu(), long.pad(), long.fcs_ok(), long.fcs_form());
        let _ = MacFrame::parse(&long);
    }
    if let Ok(frame) = MacFrame::parse_bytes(data) {
        let again = frame.emit().expect("a parsed MAC frame emits");
        assert_eq!(MacFrame::parse_bytes(&again).as_ref(), Ok(&frame));
    }
    let line = decode::decode_line(data);
    if let Err(why) = LineDecoded::from_json(&line.to_json()) {
        panic!("an exported line frame does not import: {why}");
    }
}

/// A JSON Lines file (a traffic log, `plm decode` output) or a MIB
/// profile: the file's text, each line and the whole as JSON, each value
/// read as every kind of element, the whole as either chip's profile. A
/// parsed value prints and parses back to itself; a profile read saves as
/// one that reads back.
pub fn json_lines(data: &[u8]) {
    let Ok(text) = plm_core::file::text(data) else {
        return;
    };
    for chip in [&St7580::default() as &dyn Chip, &St7570::default()] {
        if let Ok(values) = profile::parse(chip, text) {
            let saved = profile::to_json(chip, |i| {
                values.iter().find(|(x, _)| *x == i).map(|(_, v)| &v[..])
            });
            let again = profile::parse(chip, &saved).expect("a saved profile reads back");
            assert!(again.iter().all(|v| values.contains(v)), "{saved}");
        }
    }
    let whole = json::parse(text);
    for line in text.lines().chain(whole.is_ok().then_some(text)) {
        let Ok(v) = json::parse(line) else {
            continue;
        };
        let printed = v.to_string();
        assert_eq!(json::parse(&printed).as_ref(), Ok(&v), "{printed}");
        let _ = v.pretty();
        read_as_elements(&v);
    }
}

fn read_as_elements(v: &Json) {
    if let Ok(d) = Decoded::from_json(v) {
        reimports(&d);
    }
    let _ = AppDecoded::from_json(v);
    let _ = LineDecoded::from_json(v);
}

/// A firmware image file (UM 4.6.6): checked, its descriptor's release
/// read and stated.
pub fn rfu_image(data: &[u8]) {
    let release = image::release_of(data);
    if let Ok(img) = image::check(data) {
        let _ = (img.campaign(), img.release_words());
        let _ = img.stating(release);
        let _ = img.stating(None);
    }
}

/// A saved campaign file (`plm board rfu --state`, the Update view's
/// save): resumed against its image and, when taken, run to its end with
/// every board silent: a save that resumes must not panic later.
pub fn saved_campaign(data: &[u8]) {
    let Ok(mut update) = Update::resume(crate::seeds::campaign_image(), data, 0) else {
        return;
    };
    let mut now = 0;
    for _ in 0..5_000 {
        if update.is_done() {
            break;
        }
        if update.poll(now).is_some() {
            update.on_answer(now, Err("silent"));
        }
        let _ = (update.bytes_sent(), update.time_left(now), update.report());
        now += 100 * MS;
    }
}

/// A pole list file (the Street view's import): read, and what it
/// accepts holds what the picture relies on: at least one pole, each lamp
/// once, a name of 1 to [`poles::NAME_MAX`] characters, positions within
/// the bound that never go back along the street.
pub fn pole_list(data: &[u8]) {
    let Ok(list) = poles::parse(data) else {
        return;
    };
    assert!(!list.is_empty(), "a list accepted with no pole");
    let mut last = 0;
    for (i, p) in list.iter().enumerate() {
        assert!(
            list[..i].iter().all(|q| q.address != p.address),
            "{} listed twice",
            p.address
        );
        let chars = p.name.chars().count();
        assert!((1..=poles::NAME_MAX).contains(&chars), "name {:?}", p.name);
        assert_eq!(p.name.trim(), p.name, "a name kept with its spaces");
        if let Some(m) = p.position {
            assert!(
                m >= last && m <= poles::POSITION_MAX,
                "position {m} after {last}"
            );
            last = m;
        }
    }
}

/// What a TCP client sends `plm sim`: the Telnet and COM-PORT-OPTION
/// decoder (RFC 854, RFC 2217) and the server state machine, fed in
/// chunks (first byte: chunk size), and the whole as one subnegotiation.
pub fn rfc2217(data: &[u8]) {
    let mut decoder = rfc2217::Decoder::new();
    let mut server = rfc2217::Server::new("plm sim", 57_600, &BAUD_RATES);
    let _ = server.greeting();
    let mut reply = Vec::new();
    for chunk in chunks(data) {
        let _ = decoder.feed(chunk);
        for action in server.receive(chunk, &mut reply) {
            if let rfc2217::Action::SetBaud(baud) = action {
                assert!(BAUD_RATES.contains(&baud), "accepted baud {baud}");
            }
        }
        let _ = server.take_refusal_news();
        reply.clear();
    }
    let _ = (server.baud(), server.rts(), server.client_signature());
    let _ = server.refusals().summary();
    let _ = ComPort::parse(data);
}

/// The engine's dialect and baud rate from a script's first byte.
fn link_setup(input: &mut Input<'_>) -> (Dialect, u32) {
    let b = input.u8();
    let dialect = if b & 1 == 0 {
        Dialect::St7580
    } else {
        Dialect::St7570
    };
    (dialect, BAUD_RATES[(b >> 1) as usize % BAUD_RATES.len()])
}

/// A frame from a script: code, length, data.
fn local_frame(input: &mut Input<'_>) -> LocalFrame {
    let code = input.u8();
    let len = input.u8() as usize;
    LocalFrame::new(code, input.take(len).to_vec())
}

/// Time passing: up to 65 535 µs, or ms with bit 15 of the step.
fn advance(now: Instant, input: &mut Input<'_>) -> Instant {
    let step = input.u16() as u64;
    let by = if step & 0x8000 != 0 {
        (step & 0x7FFF) * MS
    } else {
        step
    };
    now.saturating_add(by)
}

fn drained<T>(mut poll: impl FnMut() -> Option<T>) {
    let mut n = 0;
    while poll().is_some() {
        n += 1;
        assert!(n < DRAIN_LIMIT, "a poll that never runs dry");
    }
}

/// The host engine (UM0932 3.2, ST7570 UM 5) driven by a script of
/// arbitrary modem bytes, frames to send, settings and timings (one op
/// byte, then its arguments). Its timers go off when due, or at any
/// moment the script says.
pub fn host_engine(data: &[u8]) {
    let mut input = Input::new(data);
    let (dialect, baud) = link_setup(&mut input);
    let mut engine = HostEngine::new(dialect, HostConfig::at_reset(dialect, baud));
    let mut now: Instant = 0;
    while !input.is_empty() {
        match input.u8() % 7 {
            0 | 1 => {
                let n = input.u8() as usize % 64;
                engine.handle_rx(now, input.take(n));
            }
            2 => {
                now = advance(now, &mut input);
                if engine.poll_timeout().is_some_and(|t| t <= now) {
                    engine.handle_timeout(now);
                }
            }
            3 => {
                let _ = engine.submit(now, local_frame(&mut input));
            }
            4 => engine.handle_timeout(now),
            5 => {
                let (mask, again) = (input.u8(), input.u16() as u64 * MS);
                engine.set_not_now(mask, again);
            }
            _ => {
                let b = input.u8();
                let baud = BAUD_RATES[b as usize % BAUD_RATES.len()];
                let mut config = HostConfig::at_reset(dialect, baud);
                config.max_attempts = b >> 2;
                if b & 0x80 != 0 {
                    config.timeouts = Timeouts::default();
                }
                engine.set_config(config);
            }
        }
        drained(|| engine.poll_transmit());
        drained(|| engine.poll_event());
        let _ = (engine.pending(), engine.last_status());
    }
}

/// The device engine (the modem's side, in the simulator) driven by a
/// script of arbitrary host bytes, frames to send, T_REQ changes,
/// settings and timings, as [`host_engine`].
pub fn device_engine(data: &[u8]) {
    let mut input = Input::new(data);
    let (dialect, baud) = link_setup(&mut input);
    let mut engine = DeviceEngine::new(dialect, baud);
    let mut now: Instant = 0;
    while !input.is_empty() {
        match input.u8() % 9 {
            0 | 1 => {
                let n = input.u8() as usize % 64;
                engine.handle_rx(now, input.take(n));
            }
            2 => {
                now = advance(now, &mut input);
                if engine.poll_timeout().is_some_and(|t| t <= now) {
                    engine.handle_timeout(now);
                }
            }
            3 => engine.submit(now, local_frame(&mut input)),
            4 => {
                let asserted = input.u8() & 1 != 0;
                engine.set_treq(now, asserted);
            }
            5 => engine.handle_timeout(now),
            6 => {
                let status = StatusMessage::new(dialect, input.take(3));
                engine.set_status(status);
            }
            7 => {
                let b = input.u8();
                engine.set_tic(TicSelector::from_mib_000b(b));
                engine.set_baud(BAUD_RATES[b as usize % BAUD_RATES.len()]);
            }
            _ => engine.reset(),
        }
        drained(|| engine.poll_transmit());
        drained(|| engine.poll_event());
        let _ = (engine.is_idle(), engine.timeouts());
    }
}
