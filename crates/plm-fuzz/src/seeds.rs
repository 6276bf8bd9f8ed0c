//! The seed corpus: the golden vectors (`tests/vectors/*.jsonl`), images
//! and saved campaigns from the simulator, and well-behaved RFC 2217
//! sessions, each in the input form of its target (`crate::targets`).

use plm_cli::rfc2217::{self, client::com_port, cmd, control};
use plm_core::app::frame::Address;
use plm_core::app::service::Release;
use plm_core::app::update::{Update, UpdateConfig};
use plm_core::app::{AppFrame, LineFrame};
use plm_core::chip::{Chip, St7570, St7580};
use plm_core::decode::app::decode_usart;
use plm_core::decode::{decode_all, decode_line};
use plm_core::file::profile;
use plm_core::json::{self, Json};
use plm_core::link::{Dialect, Source};
use std::path::Path;

/// One seed: its target, a name for its file, its bytes.
pub type Seed = (&'static str, String, Vec<u8>);

/// The image every saved campaign seed was sending (the `saved_campaign`
/// target resumes against it).
pub fn campaign_image() -> Vec<u8> {
    (0..1_000u32).map(|i| (i * 7) as u8).collect()
}

/// A campaign to two boards after `steps` quarter-seconds, one silent.
pub fn saved_campaign(steps: u32) -> Vec<u8> {
    let boards = [Address::from_u64(1), Address::from_u64(2)];
    let v = Release { major: 1, minor: 4 };
    let mut u = Update::new(9, v, campaign_image(), &boards, UpdateConfig::default())
        .expect("a campaign of two boards starts");
    let mut now = 0;
    for _ in 0..steps {
        if u.poll(now).is_some() {
            u.on_answer(now, Err("silent"));
        }
        now += 250_000;
    }
    u.save()
}

/// Each line of a golden vector file: its `hex` bytes and the line.
fn vectors(root: &Path, file: &str) -> Result<Vec<(Vec<u8>, Json)>, String> {
    let path = root.join("tests/vectors").join(file);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for (i, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let v = json::parse(line).map_err(|e| format!("{file} line {}: {e}", i + 1))?;
        let hex = v.get("hex").and_then(Json::as_str).unwrap_or_default();
        let bytes = plm_core::hex::parse(hex).map_err(|e| format!("{file} line {}: {e}", i + 1))?;
        out.push((bytes, v));
    }
    Ok(out)
}

/// The first byte of a host-stream seed: whole input at once, the
/// vector's `from`, the vector's `layer` fixed when it names one.
fn stream_head(v: &Json) -> u8 {
    let from = match v.get("from").and_then(Json::as_str) {
        Some("host") => 0x00,
        Some("modem") => 0x10,
        _ => 0x20,
    };
    let layer = match v.get("layer").and_then(Json::as_str) {
        Some("mac") => 0xC0,
        Some("phy") => 0x80,
        _ => 0,
    };
    from | layer
}

/// A host-engine or device-engine script: receive `bytes` in chunks of 63,
/// with time passing and timers firing between them.
fn engine_script(dialect: u8, bytes: &[u8]) -> Vec<u8> {
    let mut s = vec![dialect, 3, 0x2C, 0];
    for chunk in bytes.chunks(63) {
        s.extend([0, chunk.len() as u8]);
        s.extend(chunk);
        s.extend([2, 0x80, 0x05]);
    }
    s.extend([2, 0x87, 0xD0, 4]);
    s
}

/// Every seed, named after its source.
pub fn all(root: &Path) -> Result<Vec<Seed>, String> {
    let mut seeds: Vec<Seed> = Vec::new();
    let mut json_lines = Vec::new();
    for (file, target, dialect) in [
        ("um0932.jsonl", "st7580_host", Dialect::St7580),
        ("st7570.jsonl", "st7570_host", Dialect::St7570),
    ] {
        for (i, (bytes, v)) in vectors(root, file)?.into_iter().enumerate() {
            let mut input = vec![stream_head(&v)];
            input.extend(&bytes);
            seeds.push((target, format!("{file}-{i}"), input));
            let engine = if dialect == Dialect::St7580 { 0 } else { 1 };
            let name = format!("{file}-{i}");
            seeds.push(("host_engine", name.clone(), engine_script(engine, &bytes)));
            seeds.push(("device_engine", name, engine_script(engine, &bytes)));
            for d in decode_all(dialect, Source::Any, &bytes) {
                json_lines.push(d.to_json().to_string());
            }
        }
    }
    for (i, (bytes, _)) in vectors(root, "steval_app.jsonl")?.into_iter().enumerate() {
        let name = format!("steval_app.jsonl-{i}");
        let mut usart = vec![0x10];
        usart.extend(&bytes);
        seeds.push(("steval_usart", name.clone(), usart));
        seeds.push(("app_frame", name.clone(), bytes.clone()));
        if let Ok(frame) = AppFrame::parse(&bytes) {
            let line = LineFrame::from_app(&frame, Address::from_u64(0x0080_E100_0001));
            seeds.push(("app_frame", format!("{name}-line"), line.emit()));
        }
        for d in decode_usart(&bytes) {
            json_lines.push(d.to_json().to_string());
        }
    }
    for (i, (bytes, _)) in vectors(root, "st7570_line.jsonl")?.into_iter().enumerate() {
        json_lines.push(decode_line(&bytes).to_json().to_string());
        seeds.push(("st7570_mac", format!("st7570_line.jsonl-{i}"), bytes));
    }
    for (i, chunk) in json_lines.chunks(16).enumerate() {
        let text = chunk.join("\n") + "\n";
        seeds.push(("json_lines", format!("decoded-{i}"), text.into_bytes()));
    }
    // Each chip's MIB profile of its defaults, as the Modem view saves it.
    for chip in [&St7580::default() as &dyn Chip, &St7570::default()] {
        let text = profile::to_json(chip, |i| plm_core::chip::object(chip, i).map(|o| o.default));
        let name = format!("profile-{}", chip.name());
        seeds.push(("json_lines", name, text.into_bytes()));
    }
    for (size, release) in [(512, (1, 0)), (2048, (1, 4)), (8192, (2, 11))] {
        let (major, minor) = release;
        let image = plm_sim::rfu::firmware_image(Release { major, minor }, size);
        seeds.push(("rfu_image", format!("firmware-{size}"), image));
    }
    seeds.push((
        "rfu_image",
        "plain-1024".into(),
        plm_sim::rfu::plain_image(3, 1024),
    ));
    for steps in [0, 1, 8, 40] {
        seeds.push((
            "saved_campaign",
            format!("steps-{steps}"),
            saved_campaign(steps),
        ));
    }
    seeds.extend(rfc2217_sessions());
    seeds.extend(pole_lists());
    Ok(seeds)
}

/// Pole lists as people write them: a header, positions, quoted names,
/// semicolons; and a street of 500 lamps.
fn pole_lists() -> Vec<Seed> {
    let street: String = (1..=500u64)
        .map(|n| {
            format!(
                "{},P{n},{}\r\n",
                Address::from_u64(0x0080_E100_0000 + n),
                n * 30
            )
        })
        .collect();
    [
        (
            "header",
            "address,pole,position m\n0080e1000002,P1,0\n0080e1000001,\"Rue Haute, 2\",35\n"
                .to_string(),
        ),
        (
            "semicolons",
            "0080e1000001;\"Le \"\"Grand\"\" m\u{e2}t\";\n00:80:e1:00:00:03;P3;120\n".to_string(),
        ),
        ("street-500", street),
    ]
    .into_iter()
    .map(|(name, text)| ("pole_list", name.to_string(), text.into_bytes()))
    .collect()
}

/// What `plm board` and pyserial send `plm sim`: negotiation, the baud
/// rate, RTS and DTR, purges, data with an escaped IAC.
fn rfc2217_sessions() -> Vec<Seed> {
    use rfc2217::{BINARY, COM_PORT_OPTION, DO, IAC, SGA, WILL};
    let mut open = vec![0u8];
    for (verb, option) in [
        (WILL, COM_PORT_OPTION),
        (DO, BINARY),
        (WILL, BINARY),
        (DO, SGA),
    ] {
        open.extend([IAC, verb, option]);
    }
    open.extend(com_port(cmd::SIGNATURE, b"pyserial"));
    open.extend(com_port(cmd::SET_BAUDRATE, &57_600u32.to_be_bytes()));
    open.extend(com_port(cmd::SET_DATASIZE, &[8]));
    open.extend(com_port(cmd::SET_PARITY, &[1]));
    open.extend(com_port(cmd::SET_STOPSIZE, &[1]));
    open.extend(com_port(cmd::SET_CONTROL, &[control::FLOW_NONE]));
    let mut data = open.clone();
    data.extend(com_port(cmd::SET_CONTROL, &[control::RTS_ON]));
    data.extend([0x02, 0x00, 0x2C, 0x2C, 0x00, IAC, IAC, 0x01]);
    data.extend(com_port(cmd::SET_CONTROL, &[control::RTS_OFF]));
    data.extend(com_port(cmd::PURGE_DATA, &[3]));
    data.extend(com_port(cmd::SET_BAUDRATE, &9_600u32.to_be_bytes()));
    data.extend(com_port(cmd::FLOWCONTROL_SUSPEND, &[]));
    data.extend(com_port(cmd::FLOWCONTROL_RESUME, &[]));
    let mut chunked = data.clone();
    chunked[0] = 3;
    vec![
        ("rfc2217", "open".into(), open),
        ("rfc2217", "session".into(), data),
        ("rfc2217", "session-chunked".into(), chunked),
    ]
}
