//! A lamp's own page in the Street view: its history plotted (power,
//! temperature, SNR), read now, dimming, clock, GPIO, parameter groups,
//! ballast reset, and on a simulated street the faults a demo needs.

use super::street::{computer_clock, dimming_value, key_address};
use super::widgets::{button, escape, html, on_event, signal, text_input};
use crate::stores::use_console;
use crate::transport::LampAction;
use leptos::prelude::*;
use plm_core::app::service::Service;
use plm_core::app::{Message, Request};

/// Eight checkboxes, IO7 first, bound to the bits of `mask`.
fn pin_boxes(mask: RwSignal<u32>, id: &'static str) -> impl IntoView {
    (0..8u8)
        .rev()
        .map(|bit| {
            view! {
                <input
                    type="checkbox"
                    id=format!("{id}-{bit}")
                    title=format!("IO{bit}")
                    prop:checked=move || mask.get() & (1 << bit) != 0
                    on:change=on_event(move |ev| {
                        let on = event_target_checked(&ev);
                        mask.update(|m| if on { *m |= 1 << bit } else { *m &= !(1 << bit) });
                    })
                />
            }
        })
        .map(IntoAny::into_any)
        .collect_view()
}

/// The output levels to send: a level on a pin configured as an input
/// is refused (STEVAL UM 4.6.4: bit x = 1 -> IOx output), with the pin.
fn output_levels(config: u8, levels: u8) -> Result<u8, String> {
    match (0..8).find(|b| levels & !config & (1 << b) != 0) {
        Some(b) => Err(format!(
            "nothing sent: IO{b} is an input; configure it as an output (and Set) before driving it"
        )),
        None => Ok(levels),
    }
}

/// One series of a lamp's history as an SVG polyline in a 300 × 60 box.
fn sparkline(points: &[(u64, f64)]) -> (String, String) {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return (String::new(), String::new());
    };
    let span = (last.0 - first.0).max(1) as f64;
    let lo = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let range = (hi - lo).max(1.0);
    let line = points
        .iter()
        .map(|(t, v)| {
            let x = (t - first.0) as f64 / span * 300.0;
            let y = 56.0 - (v - lo) / range * 52.0;
            format!("{},{}", super::fixed(x, 1), super::fixed(y, 1))
        })
        .collect::<Vec<_>>()
        .join(" ");
    (
        line,
        format!("{}…{}", super::fixed(lo, 0), super::fixed(hi, 0)),
    )
}

/// What the street knows of a lamp, as HTML: its state, and its history
/// plotted (power, temperature, SNR). Redrawn as the lamp is read, apart
/// from the page's forms, so that typing in them goes on undisturbed.
fn state_html(lamp: Option<&crate::street::Lamp>) -> String {
    let Some(l) = lamp else {
        return "<p class=\"muted\">This lamp is not on the street any more.</p>".into();
    };
    let state = match (&l.unreachable, l.state()) {
        (Some(u), Some(s)) => format!("Unreachable: {u}. Last read: {s}."),
        (Some(u), None) => format!("Unreachable: {u}."),
        (None, Some(s)) => format!("Lamp {s}"),
        (None, None) => "Not read yet.".to_string(),
    };
    let mut html = format!(
        "<p{}>{}</p>",
        if l.in_trouble() {
            " class=\"problem\""
        } else {
            ""
        },
        escape(&state)
    );
    let series = |f: fn(&crate::street::Sample) -> Option<f64>| {
        let pts: Vec<(u64, f64)> = l
            .history
            .iter()
            .filter_map(|s| f(s).map(|v| (s.at, v)))
            .collect();
        sparkline(&pts)
    };
    for (name, (line, range)) in [
        ("Power W", series(|s| Some(s.power as f64))),
        ("Temperature °C", series(|s| Some(s.temperature as f64))),
        ("SNR dB", series(|s| s.snr.map(f64::from))),
    ] {
        html.push_str(&format!(
            "<figure class=\"spark\"><figcaption>{name} {range}</figcaption><svg viewBox=\"0 0 300 60\" preserveAspectRatio=\"none\"><polyline points=\"{line}\"/></svg></figure>"
        ));
    }
    html
}

/// The page of the lamp `focus` names (by its row key).
#[component]
pub fn LampPanel(focus: RwSignal<Option<u64>>) -> impl IntoView {
    let street = use_console().street;
    let note = signal(None::<String>);
    let level = signal(String::from("50"));
    // u32 signals (a type the page has) holding bytes.
    let io_config = signal(0u32);
    let outputs = signal(0u32);
    let group = signal(2u32);
    let params = signal(String::new());
    let ask = move |m: Message, what: &'static str| {
        let Some(a) = focus.get_untracked().map(key_address) else {
            return;
        };
        note.set(Some(format!("{what}…")));
        let r = street.act(|s| {
            s.request(
                Request::to(a, m),
                Box::new(move |r| {
                    note.set(Some(match r {
                        Ok(Message::Service(Service::ClockNow(c))) => format!("clock: {c}"),
                        Ok(Message::Service(Service::Inputs(v))) => {
                            format!("GPIO levels: {v:08b} (IO7…IO0)")
                        }
                        Ok(Message::Service(Service::IoConfig(v))) => {
                            io_config.set(v.into());
                            format!("GPIO outputs: {v:08b} (IO7…IO0, 1 = output)")
                        }
                        Ok(Message::Service(Service::Params { group, data })) => {
                            params.set(plm_core::hex::encode(&data));
                            format!("parameter group {group}: {} bytes read", data.len())
                        }
                        Ok(Message::Error(e)) => format!("{what}: the board answered {e}"),
                        Ok(_) => format!("{what}: done"),
                        Err(e) => format!("{what}: {e}"),
                    }))
                }),
            )
        });
        if let Err(e) = r {
            note.set(Some(format!("nothing sent: {e}")));
        }
    };
    let sim = move |action: LampAction| {
        let Some(a) = focus.get_untracked().map(key_address) else {
            return;
        };
        street.act(|s| {
            if let Some(sim) = s.transport_mut().and_then(|t| t.simulator()) {
                sim.lamp(a, action);
            }
        });
        note.set(Some(format!("simulator: {} on this lamp", action.label())));
    };
    view! {
        <aside class="details lamp" id="lamp-panel">
            // Rebuilt when another lamp is chosen; its state as it is read.
            {move || focus.get().map(key_address).map(|address| view! {
                        <div class="lamp-head">
                            <h3>{format!("Lamp {address}")}</h3>
                            {button("lamp-close", "✕", "close this lamp's page", move || focus.set(None))}
                        </div>
                        // Read in place at each change of the fleet, not
                        // through a memo of the lamp (a memo type of its own:
                        // 1.8 KiB of the page); the HTML is written only when
                        // it differs.
                        {html(Box::new(move || {
                            street.version.track();
                            street.with_fleet(|f| state_html(f.get(&address)))
                        }))}
                        <div class="form-row">
                            {button("lamp-read", "Read now", "", move || ask(Message::Hid(plm_core::app::Hid::Get(plm_core::app::hid::ALL)), "read"))}
                            <label>
                                "Dimming % "
                                {text_input("lamp-dim-level", "", "", Some(4), level)}
                            </label>
                            {button("lamp-dim", "Dim", "", move || {
                                match dimming_value(&level.get_untracked()) {
                                    Ok(v) => {
                                        let a = focus.get_untracked().map(key_address);
                                        let r = street.act(|s| s.dim(a, v));
                                        note.set(Some(match r { Ok(()) => format!("dimming {v} % sent"), Err(e) => format!("nothing sent: {e}") }));
                                    }
                                    Err(e) => note.set(Some(e)),
                                }
                            })}
                        </div>
                        <div class="form-row">
                            {button("", "Read clock", "", move || ask(Message::Service(Service::ClockGet), "clock"))}
                            {button("", "Set clock from this computer", "", move || ask(Message::Service(Service::ClockSet(computer_clock())), "set clock"))}
                            {button("", "Read GPIO levels", "", move || ask(Message::Service(Service::InputsGet), "GPIO"))}
                            {button("", "Reset ballast", "", move || ask(Message::Hid(plm_core::app::Hid::Reset(plm_core::app::hid::RESET_SOFTWARE)), "ballast reset"))}
                        </div>
                        <h4>"GPIO (IO7 … IO0)"</h4>
                        <div class="form-row pins">
                            <span class="muted">"output"</span>
                            {pin_boxes(io_config, "io-config")}
                            {button("", "Read", "", move || ask(Message::Service(Service::IoConfigGet), "read GPIO configuration"))}
                            {button("lamp-io-config", "Set", "", move || ask(Message::Service(Service::IoConfigSet(io_config.get_untracked() as u8)), "set GPIO configuration"))}
                        </div>
                        <div class="form-row pins">
                            <span class="muted">"level"</span>
                            {pin_boxes(outputs, "io-out")}
                            {button("lamp-io-out", "Set outputs", "", move || {
                                match output_levels(io_config.get_untracked() as u8, outputs.get_untracked() as u8) {
                                    Ok(v) => ask(Message::Service(Service::OutputsSet(v)), "set GPIO outputs"),
                                    Err(e) => note.set(Some(e)),
                                }
                            })}
                        </div>
                        <h4>"Parameters"</h4>
                        <div class="form-row">
                            <select on:change=on_event(move |ev| group.set(event_target_value(&ev).parse().unwrap_or(2)))>
                                {plm_core::app::service::PROG_GROUPS.iter().enumerate().map(|(i, n)| view! {
                                    <option value=i.to_string() selected=i == 2>{*n}</option>
                                }).map(IntoAny::into_any).collect_view()}
                            </select>
                            {button("", "Read", "", move || ask(Message::Service(Service::ParamGet { group: group.get_untracked() as u8 }), "read parameters"))}
                            {button("lamp-params-write", "Write", "", move || {
                                let data = match plm_core::hex::parse(&params.get_untracked()) {
                                    Ok(d) => d,
                                    Err(e) => return note.set(Some(format!("nothing sent: {e}"))),
                                };
                                ask(Message::Service(Service::ParamSet { group: group.get_untracked() as u8, data }), "write parameters")
                            })}
                        </div>
                        {text_input("lamp-params", "payload hex", "32 bytes, hex", None, params)}
                        {move || (street.port.get().contains("simulated")).then(|| view! {
                            <div class="form-row sim-actions">
                                <span class="muted">"Simulator:"</span>
                                {button("lamp-sim-fail", "Break lamp", "", move || sim(LampAction::Fail))}
                                {button("", "Replace lamp", "", move || sim(LampAction::Repair))}
                                {button("lamp-sim-cut", "Cut supply", "", move || sim(LampAction::Cut))}
                                {button("", "Restore supply", "", move || sim(LampAction::Join))}
                            </div>
                        }).map(IntoAny::into_any)}
                        {super::widgets::note("lamp-note", "muted", note)}
            }.into_any())}
        </aside>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_only_on_output_pins() {
        assert_eq!(output_levels(0b1111_0000, 0b0101_0000), Ok(0b0101_0000));
        assert!(output_levels(0b1111_0000, 0b0000_1000)
            .unwrap_err()
            .contains("IO3 is an input"));
    }
}
