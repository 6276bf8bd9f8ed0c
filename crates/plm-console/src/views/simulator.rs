//! The Simulator view: the simulated world behind the Simulated transport.
//! Topology (this modem alone or with echoing peers), line conditions,
//! UART byte faults, modem reset and unplug, and what happens on the line.

use super::widgets::{button, escape, on_click, on_event, signal};
use crate::stores::use_console;
use leptos::prelude::*;
use plm_core::st7580::Temperature;
use plm_core::time::MS;
use plm_sim::{ByteFaults, Dir, Fault, LineConfig};

/// The view.
#[component]
pub fn SimulatorView(tab: RwSignal<String>) -> impl IntoView {
    let profile = use_console().profile;
    view! {
        <div class="cards">
            // Echoing peers belong to the bare-modem world; a street has
            // its own card.
            {move || (!profile.get().is_street()).then(|| view! { <TopologyCard/> }).map(IntoAny::into_any)}
            <StreetCard/>
            <ModemFaultsCard/>
            <LineCard/>
            <UartCard/>
            <LineEventsCard tab=tab/>
        </div>
    }
}

/// The simulated street: how many lamps (a restart of the street).
#[component]
fn StreetCard() -> impl IntoView {
    let c = use_console();
    let choice = signal(c.sim.lamps.get_untracked());
    view! {
        <article class="card" id="sim-street">
            <h3>"Street"</h3>
            <p class="muted">
                "Street-light controller boards along the line behind the concentrator (node 0), on the three mains phases in turn. Each lamp can be broken, repaired or cut off from its own page (Street view)."
            </p>
            <label>
                "Lamps "
                <select
                    id="sim-lamps"
                    on:change=on_event(move |ev| {
                        if let Ok(n) = event_target_value(&ev).parse() {
                            choice.set(n);
                        }
                    })
                >
                    {[6usize, 12, 50, 100, 500]
                        .into_iter()
                        .map(|n| view! {
                            <option value=n.to_string() selected=move || choice.get() == n>{n.to_string()}</option>
                        })
                        .map(IntoAny::into_any).collect_view()}
                </select>
            </label>
            {button("sim-apply-street", "Restart the street", "", move || {
                c.sim.lamps.set(choice.get_untracked());
                if c.profile.get_untracked().is_street() {
                    c.connect_simulated();
                } else {
                    c.set_profile(crate::profile::Profile::StreetBoard);
                }
            })}
            <FailureRate/>
        </article>
    }
}

/// Random lamp failures per lamp per lit hour, on the running street and
/// the next ones.
#[component]
fn FailureRate() -> impl IntoView {
    let c = use_console();
    let text = signal(super::fixed(
        f64::from_bits(c.sim.failure_rate.get_untracked()),
        2,
    ));
    let message = signal(None::<String>);
    let apply = move || match super::decimal(&text.get_untracked()) {
        Some(rate) if (0.0..=60.0).contains(&rate) => {
            c.sim.failure_rate.set(rate.to_bits());
            c.with_simulator(|s| s.set_failure_rate(rate));
            message.set(Some(if rate == 0.0 {
                "no random failures".to_string()
            } else {
                format!(
                    "each burning lamp fails about every {} minutes (it stays in FAILURE until reset)",
                    super::fixed(60.0 / rate, 1)
                )
            }));
        }
        _ => message.set(Some(
            "nothing changed: the rate is a number of failures per lamp per lit hour, 0 to 60"
                .to_string(),
        )),
    };
    view! {
        <div class="form-row">
            <label title="Random lamp failures, per lamp per hour of burning (0: none). A failed lamp stays in FAILURE until a reset or a power cycle relights it.">
                "Random failures per lamp per lit hour "
                {super::widgets::text_input("sim-failure-rate", "", "", Some(5), text)}
            </label>
            {button("sim-apply-failures", "Apply", "", apply)}
        </div>
        {super::widgets::note("sim-failure-note", "muted", message)}
    }
}

#[component]
fn TopologyCard() -> impl IntoView {
    let c = use_console();
    let choice = signal(c.sim.nodes.get_untracked());
    view! {
        <article class="card" id="sim-topology">
            <h3>"Topology"</h3>
            <p class="muted">
                "Node 0 is this console's modem. Peers (nodes 1…) sit along a street and send back every frame they receive, at the same layer and modulation."
            </p>
            <label>
                "Modems "
                <select
                    id="sim-nodes"
                    on:change=on_event(move |ev| {
                        if let Ok(n) = event_target_value(&ev).parse() {
                            choice.set(n);
                        }
                    })
                >
                    {[1usize, 2, 3, 5]
                        .into_iter()
                        .map(|n| {
                            let label = match n {
                                1 => "this modem alone".to_string(),
                                2 => "with 1 echoing peer".to_string(),
                                n => format!("with {} echoing peers", n - 1),
                            };
                            view! {
                                <option value=n.to_string() selected=move || choice.get() == n>
                                    {label}
                                </option>
                            }
                        })
                        .map(IntoAny::into_any).collect_view()}
                </select>
            </label>
            {button("sim-apply-topology", "Restart the simulation", "", move || {
                c.sim.nodes.set(choice.get_untracked());
                c.set_profile(crate::profile::Profile::Modem);
            })}
            <p>
                {move || format!("Running: {} modem(s); peers echoed {} frame(s).", c.sim.nodes.get(), c.sim.echoed.get())}
            </p>
        </article>
    }
}

#[component]
fn ModemFaultsCard() -> impl IntoView {
    let c = use_console();
    let inject = move |f: Fault| c.with_simulator(|s| s.inject(f));
    view! {
        <article class="card" id="sim-modem">
            <h3>"Modem and cable"</h3>
            <div class="buttons">
                {button("sim-reset", "Pull RESETN (power-on reset)", "", move || inject(Fault::ModemReset))}
                {button("sim-watchdog", "Watchdog reset", "", move || inject(Fault::Watchdog))}
                <button
                    id="sim-plug"
                    on:click=on_click(move |_| {
                        inject(if c.sim.plugged.get_untracked() { Fault::Unplug } else { Fault::Plug })
                    })
                >
                    {move || String::from(if c.sim.plugged.get() { "Unplug the cable" } else { "Plug the cable in" })}
                </button>
            </div>
            <label>
                "Temperature "
                <select
                    id="sim-temperature"
                    on:change=on_event(move |ev| {
                        if let Ok(t) = event_target_value(&ev).parse::<u8>() {
                            inject(Fault::Temperature(Temperature::from_bits(t)));
                        }
                    })
                >
                    <option value="0" selected>"below 70 °C"</option>
                    <option value="1">"70-100 °C"</option>
                    <option value="2">"100-125 °C"</option>
                    <option value="3">"above 125 °C (refuses to transmit)"</option>
                </select>
            </label>
        </article>
    }
}

fn percent(text: &str) -> Option<f64> {
    let v = super::decimal(text)?;
    (0.0..=100.0).contains(&v).then_some(v / 100.0)
}

#[component]
fn LineCard() -> impl IntoView {
    let c = use_console();
    let defaults = LineConfig::default();
    let noise = signal(super::fixed(defaults.noise_dbuv, 0));
    let loss = signal("0".to_string());
    let corruption = signal("0".to_string());
    let message = signal(None::<String>);
    let apply = move || {
        let noise_dbuv = match super::decimal(&noise.get_untracked()) {
            Some(v) if (0.0..=130.0).contains(&v) => v,
            _ => {
                message.set(Some("noise floor: a number of dBµV from 0 to 130".into()));
                return;
            }
        };
        let (Some(loss), Some(corruption)) = (
            percent(&loss.get_untracked()),
            percent(&corruption.get_untracked()),
        ) else {
            message.set(Some(
                "loss and corruption: percentages from 0 to 100".into(),
            ));
            return;
        };
        c.with_simulator(|s| {
            s.set_line(LineConfig {
                noise_dbuv,
                loss,
                corruption,
                ..s.line()
            })
        });
        message.set(Some("applied".into()));
    };
    view! {
        <article class="card" id="sim-line">
            <h3>"Power line"</h3>
            <p class="muted">
                "TX level 100 dBµV at full gain, 30 dB between neighbours, 2 dB more per node in between."
            </p>
            {text_field("Noise floor (dBµV) ", "sim-noise", 5, noise)}
            {text_field("Frame loss (%) ", "sim-loss", 4, loss)}
            {text_field("Corruption (%) ", "sim-corruption", 4, corruption)}
            {button("sim-apply-line", "Apply", "", apply)}
            {super::widgets::note("", "muted", message)}
        </article>
    }
}

#[component]
fn UartCard() -> impl IntoView {
    let c = use_console();
    // Modem to host when set (a bool: a signal type the page has).
    let up = signal(false);
    let dir = move || {
        if up.get_untracked() {
            Dir::ModemToHost
        } else {
            Dir::HostToModem
        }
    };
    let drop = signal("0".to_string());
    let corrupt = signal("0".to_string());
    let delay = signal("0".to_string());
    let message = signal(None::<String>);
    let inject = move |f: Fault| {
        c.with_simulator(|s| s.inject(f));
        message.set(Some("armed: it hits the next byte".into()));
    };
    let apply = move || {
        let (Some(drop), Some(corrupt), Some(delay)) = (
            percent(&drop.get_untracked()),
            percent(&corrupt.get_untracked()),
            percent(&delay.get_untracked()),
        ) else {
            message.set(Some("percentages from 0 to 100".into()));
            return;
        };
        let d = dir();
        c.with_simulator(|s| {
            s.set_byte_faults(
                d,
                ByteFaults {
                    drop,
                    corrupt,
                    delay,
                    ..ByteFaults::default()
                },
            )
        });
        message.set(Some("applied to every byte this way".into()));
    };
    view! {
        <article class="card" id="sim-uart">
            <h3>"UART faults"</h3>
            <label>
                "Direction "
                <select
                    id="sim-dir"
                    on:change=on_event(move |ev| {
                        up.set(event_target_value(&ev) == "up")
                    })
                >
                    <option value="down" selected>"host → modem"</option>
                    <option value="up">"modem → host"</option>
                </select>
            </label>
            <div class="buttons">
                {button("sim-drop", "Drop next byte", "", move || inject(Fault::DropByte(dir())))}
                {button("sim-corrupt", "Corrupt next byte", "", move || inject(Fault::CorruptByte(dir(), 0x10)))}
                {button("sim-delay", "Delay next byte 15 ms", "", move || inject(Fault::DelayByte(dir(), 15 * MS)))}
            </div>
            <p class="muted">"At random, for every byte this way:"</p>
            {text_field("drop % ", "sim-p-drop", 4, drop)}
            {text_field("corrupt % ", "sim-p-corrupt", 4, corrupt)}
            {text_field("delay % ", "sim-p-delay", 4, delay)}
            {button("sim-apply-uart", "Apply", "", apply)}
            {super::widgets::note("", "muted", message)}
        </article>
    }
}

#[component]
fn LineEventsCard(tab: RwSignal<String>) -> impl IntoView {
    let c = use_console();
    // Written only while the view is shown: on a street every frame on the
    // line is an event, and the list would be written again for nothing.
    let shown = move || tab.with(|t| t == crate::tab::Tab::Simulator.slug());
    view! {
        <article class="card wide" id="sim-events">
            <h3>"On the power line"</h3>
            {move || shown().then(|| {
                let events = c.sim.line_events.get();
                if events.is_empty() {
                    view! {
                        <p class="muted">
                            "Nothing sent on the line yet. Data requests (PHY/DL/SS) put frames on it; peers echo them."
                        </p>
                    }
                        .into_any()
                } else {
                    view! {
                        <ul class="events" inner_html=events.iter().rev().fold(String::new(), |mut h, e| {
                            h.push_str(&format!("<li>{}</li>", escape(e)));
                            h
                        })></ul>
                    }
                        .into_any()
                }
            })}
        </article>
    }
}

/// A labelled text input bound to `value` (checked when applied); a
/// plain function rather than a component: no props type to build.
fn text_field(
    label: &'static str,
    id: &'static str,
    size: u32,
    value: RwSignal<String>,
) -> AnyView {
    view! {
        <label>
            {label}
            {super::widgets::text_input(id, "", "", Some(size), value)}
        </label>
    }
    .into_any()
}
