//! `plm board discover`, `status` and `dim`: requests and their answers
//! in words, or JSON lines with `--json`.

use super::driver::Driver;
use super::{exit, Failure, Target};
use plm_core::app::discovery::DiscoveryConfig;
use plm_core::app::hid::{self, Ballast, Hid};
use plm_core::app::street::Street;
use plm_core::app::sweep::SLOTS_FROM;
use plm_core::app::{Address, AppEvent, Message, Request, Service};
use serde_json::{json, Map, Value};

/// Discovers the boards; prints each as it is found.
pub fn discover(
    d: &mut Driver,
    config: DiscoveryConfig,
    older_rule: bool,
    json: bool,
) -> Result<u8, Failure> {
    tell!(
        "plm board: discovering (about {} boards expected; it ends when the line has been \
         quiet long enough to be sure)",
        config.guess
    );
    let started = std::time::Instant::now();
    let found = d.discover(config, older_rule, |address, info| {
        if json {
            say!(
                "{}",
                json!({
                    "address": address.to_string(),
                    "firmware": info.firmware.to_string(),
                    "stack": info.stack.to_string(),
                    "snr_db": info.snr,
                })
            );
        } else {
            say!(
                "{address}  firmware {}  stack {}  SNR {} dB",
                info.firmware,
                info.stack,
                info.snr
            );
        }
    })?;
    let n = found.found().len();
    let secs = started.elapsed().as_secs_f64();
    if n == 0 {
        tell!(
            "plm board: no board answered in {} frame(s), {secs:.1} s: are the boards powered, \
             and is the port the concentrator's (--via)?",
            found.frames()
        );
        return Ok(exit::FAILED);
    }
    tell!(
        "plm board: {n} board{} found in {} frame(s), {secs:.1} s",
        if n == 1 { "" } else { "s" },
        found.frames()
    );
    Ok(exit::OK)
}

/// `status all`: plm-core's street ([`Street`], what the console's Street
/// page runs) discovers the boards, then reads every lamp found in its
/// first round (docs/board-protocol.md, "A round of reads": in slots, the
/// stragglers one by one); one line (or JSON object) per lamp.
pub fn status_all(d: &mut Driver, config: DiscoveryConfig, json: bool) -> Result<u8, Failure> {
    let started = std::time::Instant::now();
    tell!("plm board: discovering, then reading every lamp found");
    let mut street = Street::<()>::new(d.concentrator());
    street.discover_with(d.now(), config);
    let mut told = false;
    d.run(&mut street, |s, _, _| {
        if !told && s.discovering().is_none() {
            told = true;
            let n = s.fleet().len();
            tell!(
                "plm board: {n} board(s) found in {:.1} s; reading them {}",
                started.elapsed().as_secs_f64(),
                if n < SLOTS_FROM {
                    "one by one"
                } else {
                    "in slots, the lamps not heard in theirs one by one"
                }
            );
        }
        Ok(())
    })?;
    let mut silent = 0;
    for lamp in street.fleet().values() {
        let address = lamp.address;
        let (firmware, snr) = lamp
            .discovered
            .map_or((String::from("?"), 0), |i| (i.firmware.to_string(), i.snr));
        let read = match (lamp.ballast, &lamp.unreachable) {
            (Some(b), _) => Ok(b),
            (None, Some(why)) => Err(why.clone()),
            (None, None) => Err(String::from("not read")),
        };
        silent += usize::from(read.is_err());
        if json {
            let mut o = json!({
                "address": address.to_string(),
                "firmware": firmware,
                "snr_db": snr,
            });
            match &read {
                Ok(b) => {
                    o["state"] = b.state().to_string().into();
                    o["lamp_power_w"] = b.lamp_power.into();
                    o["temperature_c"] = b.temperature.into();
                }
                Err(why) => o["error"] = why.as_str().into(),
            }
            say!("{o}");
        } else {
            let what = match &read {
                Ok(b) => format!("{}, {} W, {} °C", b.state(), b.lamp_power, b.temperature),
                Err(why) => why.clone(),
            };
            say!("{address}  firmware {firmware}  SNR {snr} dB  {what}");
        }
    }
    let n = street.fleet().len();
    tell!(
        "plm board: {} lamp(s) read, {silent} silent, in {:.1} s; {} heard in their slot",
        n - silent,
        started.elapsed().as_secs_f64(),
        street.in_slots()
    );
    Ok(if n == 0 || silent > 0 {
        exit::FAILED
    } else {
        exit::OK
    })
}

/// What one request of `status` gave: the answer, or why there is none.
type Got = Result<Message, String>;

/// An error frame in words, or the other answer as it is.
fn refused(got: Got) -> Got {
    match got {
        Ok(Message::Error(code)) => Err(format!("the board answered with an error: {code}")),
        other => other,
    }
}

/// Reads what a board offers, and prints it.
pub fn status(d: &mut Driver, node: Address, json: bool) -> Result<u8, Failure> {
    let mut ask = |m: Message| d.ask(node, m);
    // The releases first: a board that does not answer them is not asked
    // the rest (each request would wait its full retries).
    let release = ask(Message::Service(Service::FwRelGet))?;
    let silent = release.is_err();
    let (lamp, clock, inputs, io, snr) = if silent {
        let none = || Err(String::from("not asked"));
        (none(), none(), none(), none(), none())
    } else {
        (
            ask(Message::Hid(Hid::Get(hid::ALL)))?,
            ask(Message::Service(Service::ClockGet))?,
            ask(Message::Service(Service::InputsGet))?,
            ask(Message::Service(Service::IoConfigGet))?,
            ask(Message::Service(Service::SnGet))?,
        )
    };
    // Error frames are answers (the board said no); a silence is not.
    let unanswered = [&release, &lamp, &clock, &inputs, &io, &snr]
        .iter()
        .filter(|g| g.is_err())
        .count();
    let (release, lamp, clock, inputs, io, snr) = (
        refused(release),
        refused(lamp),
        refused(clock),
        refused(inputs),
        refused(io),
        refused(snr),
    );
    let mut fields = Map::new();
    let mut errors = Map::new();
    let mut lines = vec![format!("board {node}")];
    let mut line = |label: &str, text: String| lines.push(format!("  {label:<13}{text}"));

    if silent {
        let why = release.as_ref().err().cloned().unwrap_or_default();
        if json {
            say!(
                "{}",
                json!({"address": node.to_string(), "answered": false, "error": why})
            );
        } else {
            tell!("plm board: {why}");
        }
        return Ok(exit::FAILED);
    }
    match release {
        Ok(Message::Service(Service::FwRel { firmware, stack })) => {
            line("firmware", format!("{firmware} (stack {stack})"));
            fields.insert("firmware".into(), firmware.to_string().into());
            fields.insert("stack".into(), stack.to_string().into());
        }
        other => note(&mut line, &mut errors, "firmware", other),
    }
    match lamp {
        Ok(Message::Hid(Hid::Reply { param, value })) if param == hid::ALL => {
            match Ballast::decode(&value) {
                Some(b) => {
                    lamp_lines(&mut line, &b);
                    fields.insert("lamp".into(), lamp_json(&b));
                }
                None => note(
                    &mut line,
                    &mut errors,
                    "lamp",
                    Err(format!("a short reply: {value:02X?}")),
                ),
            }
        }
        other => note(&mut line, &mut errors, "lamp", other),
    }
    match clock {
        Ok(Message::Service(Service::ClockNow(c))) => {
            line("clock", c.to_string());
            fields.insert("clock".into(), c.to_string().into());
        }
        other => note(&mut line, &mut errors, "clock", other),
    }
    let pins = |bits: u8| -> String {
        let on: Vec<String> = (0..8)
            .filter(|i| bits & (1 << i) != 0)
            .map(|i| format!("IO{i}"))
            .collect();
        if on.is_empty() {
            "none".into()
        } else {
            on.join(" ")
        }
    };
    match inputs {
        Ok(Message::Service(Service::Inputs(v))) => {
            line("inputs high", format!("{} ({v:08b}b)", pins(v)));
            fields.insert("inputs".into(), v.into());
        }
        other => note(&mut line, &mut errors, "inputs", other),
    }
    match io {
        Ok(Message::Service(Service::IoConfig(v))) => {
            line("outputs", format!("{} ({v:08b}b)", pins(v)));
            fields.insert("io_config".into(), v.into());
        }
        other => note(&mut line, &mut errors, "io_config", other),
    }
    match snr {
        Ok(Message::Service(Service::Sn(v))) => {
            line("SNR", format!("{v} dB (of the last frame it heard)"));
            fields.insert("snr_db".into(), v.into());
        }
        other => note(&mut line, &mut errors, "snr", other),
    }

    if json {
        let mut obj = Map::new();
        obj.insert("address".into(), node.to_string().into());
        obj.insert("answered".into(), true.into());
        obj.extend(fields);
        if !errors.is_empty() {
            obj.insert("errors".into(), Value::Object(errors));
        }
        say!("{}", Value::Object(obj));
    } else {
        for l in lines {
            say!("{l}");
        }
    }
    Ok(if unanswered == 0 {
        exit::OK
    } else {
        exit::FAILED
    })
}

/// A part of the status that did not come as expected.
fn note(line: &mut impl FnMut(&str, String), errors: &mut Map<String, Value>, key: &str, got: Got) {
    let why = match got {
        Err(why) => why,
        Ok(other) => format!("an unexpected answer: {}", other.name()),
    };
    line(key, format!("? {why}"));
    errors.insert(key.into(), why.into());
}

fn lamp_lines(line: &mut impl FnMut(&str, String), b: &Ballast) {
    line(
        "lamp",
        format!(
            "{}, {} W; lamp {} V, bus {} V, supply {} V",
            b.state(),
            b.lamp_power,
            b.lamp_voltage,
            b.bus_voltage,
            b.supply_voltage
        ),
    );
    line("temperature", format!("{} °C", b.temperature));
    line(
        "lamp life",
        format!("{} h lit, {} power-ons", b.lifetime_hours, b.power_ons),
    );
    let f = &b.last_failure;
    line(
        "last failure",
        if no_failure(b) {
            "none recorded".into()
        } else {
            format!(
                "while {} (bus {} V, lamp {} V)",
                hid::LampState::from_word(f.status),
                f.bus_voltage,
                f.lamp_voltage
            )
        },
    );
    line("ballast", format!("hardware {}", b.hardware_release()));
}

/// A lamp that never failed reports its last failure as all zeros.
fn no_failure(b: &Ballast) -> bool {
    let f = &b.last_failure;
    f.status == 0 && f.bus_voltage == 0 && f.lamp_voltage == 0
}

fn lamp_json(b: &Ballast) -> Value {
    json!({
        "state": b.state().to_string(),
        "power_w": b.lamp_power,
        "lamp_voltage_v": b.lamp_voltage,
        "bus_voltage_v": b.bus_voltage,
        "supply_voltage_v": b.supply_voltage,
        "temperature_c": b.temperature,
        "lifetime_h": b.lifetime_hours,
        "power_ons": b.power_ons,
        "hardware_release": b.hardware_release(),
        "last_failure": if no_failure(b) {
            Value::Null
        } else {
            json!({
                "state": hid::LampState::from_word(b.last_failure.status).to_string(),
                "bus_voltage_v": b.last_failure.bus_voltage,
                "lamp_voltage_v": b.last_failure.lamp_voltage,
            })
        },
    })
}

/// Dims one lamp (acknowledged) or all (a broadcast, no answer).
pub fn dim(d: &mut Driver, target: Target, level: u8, json: bool) -> Result<u8, Failure> {
    let m = Message::Hid(Hid::Dimming(level));
    let (address, request) = match target {
        Target::All => (None, Request::all(m)),
        Target::One(a) => (Some(a), Request::to(a, m)),
    };
    let (ok, words) = match (d.request(request)?, address) {
        (AppEvent::Sent { .. }, None) => (
            true,
            format!(
                "dimming {level} % sent to every board at once (a broadcast has no answer: \
                 read a lamp's status to see it follow)"
            ),
        ),
        (AppEvent::Answered { answer, .. }, Some(a)) => match answer {
            Message::Ack { .. } => (true, format!("{a}: dimmed to {level} %")),
            Message::Error(code) => (false, format!("{a} refused the dimming: {code}")),
            other => (
                false,
                format!("{a} answered the dimming with {}", other.name()),
            ),
        },
        (AppEvent::Failed { reason, .. }, _) => (
            false,
            format!(
                "{} did not answer: {reason}",
                address.map_or("the line".into(), |a| a.to_string())
            ),
        ),
        (other, _) => (false, format!("unexpected: {other:?}")),
    };
    if json {
        say!(
            "{}",
            json!({
                "target": address.map_or("all".into(), |a| a.to_string()),
                "level": level,
                "ok": ok,
                "result": words,
            })
        );
    } else if ok {
        say!("{words}");
    }
    if !ok {
        tell!("plm board: {words}");
    }
    Ok(if ok { exit::OK } else { exit::FAILED })
}
