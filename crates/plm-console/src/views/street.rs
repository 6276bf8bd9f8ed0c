//! The Street view: the fleet of lamps (discover, a background sweep, a
//! sortable and filterable table with failed and unreachable lamps
//! standing out, CSV and JSON export), dimming and clocks for one lamp, a
//! selection or all, alerts, and a lamp's own page with its history.

use super::files::download;
use crate::fleet::{self, Row, COLUMNS};
use crate::stores::use_console;
use crate::transport::LampAction;
use leptos::prelude::*;
use plm_core::app::service::{Clock, Service};
use plm_core::app::{Address, Message, Request};
use std::collections::BTreeSet;

/// The view.
#[component]
pub fn StreetView() -> impl IntoView {
    let street = use_console().street;
    let filter = RwSignal::new(String::new());
    let sort = RwSignal::new(("address", true));
    let selected = RwSignal::new(BTreeSet::<Address>::new());
    let focus = RwSignal::new(None::<Address>);
    let message = RwSignal::new(None::<String>);
    let rows = Memo::new(move |_| {
        street.version.track();
        let now = street.now.get();
        let mut rows: Vec<(Address, Row)> =
            street.with_fleet(|f| f.values().map(|l| (l.address, Row::of(l, now))).collect());
        let (key, asc) = sort.get();
        let mut only: Vec<Row> = rows.iter().map(|r| r.1.clone()).collect();
        fleet::sort(&mut only, key, asc);
        rows.sort_by_key(|(_, r)| only.iter().position(|o| o.address == r.address));
        let f = filter.get();
        rows.retain(|(_, r)| r.matches(&f));
        rows
    });
    let export = move |json: bool| {
        let rows: Vec<Row> = rows.get_untracked().into_iter().map(|r| r.1).collect();
        let r = if json {
            download("street.json", "application/json", &fleet::to_json(&rows))
        } else {
            download("street.csv", "text/csv", &fleet::to_csv(&rows))
        };
        if let Err(e) = r {
            message.set(Some(e));
        }
    };
    view! {
        <div class="street">
            <div class="toolbar">
                <span class="muted" id="street-port">{move || street.port.get()}</span>
                <button id="street-discover" on:click=move |_| street.act(|s| s.discover())>
                    "Discover"
                </button>
                <SweepControl/>
                <input
                    id="street-filter"
                    placeholder="filter: address, state, \"trouble\""
                    prop:value=move || filter.get()
                    on:input=move |ev| filter.set(event_target_value(&ev))
                />
                <button id="street-export-csv" on:click=move |_| export(false)>"Export CSV"</button>
                <button id="street-export-json" on:click=move |_| export(true)>"Export JSON"</button>
            </div>
            <GroupActions selected=selected message=message/>
            <Show when=move || message.with(|m| m.is_some())>
                <p class="message" id="street-message">{move || message.get().unwrap_or_default()}</p>
            </Show>
            <Alerts focus=focus/>
            <div class="street-grid" class:with-lamp=move || focus.with(|f| f.is_some())>
                <div class="table-wrap">
                    <table class="log fleet" id="fleet-table">
                        <thead>
                            <tr>
                                <th>
                                    <input
                                        type="checkbox"
                                        id="fleet-select-all"
                                        title="select every lamp shown"
                                        on:change=move |ev| {
                                            let on = event_target_checked(&ev);
                                            selected.set(if on {
                                                rows.get_untracked().iter().map(|r| r.0).collect()
                                            } else {
                                                BTreeSet::new()
                                            });
                                        }
                                    />
                                </th>
                                {COLUMNS
                                    .iter()
                                    .map(|(key, header)| {
                                        let key = *key;
                                        view! {
                                            <th
                                                class="sortable"
                                                data-key=key
                                                on:click=move |_| sort.update(|s| *s = (key, if s.0 == key { !s.1 } else { true }))
                                            >
                                                {*header}
                                                {move || match sort.get() {
                                                    (k, true) if k == key => " ▲",
                                                    (k, false) if k == key => " ▼",
                                                    _ => "",
                                                }}
                                            </th>
                                        }
                                    })
                                    .collect_view()}
                            </tr>
                        </thead>
                        <tbody>
                            <For
                                each=move || rows.get()
                                key=|(a, r)| (*a, r.clone().numbers.iter().map(|n| n.1.map(|v| v.to_bits())).collect::<Vec<_>>(), r.state.clone(), r.firmware.clone())
                                children=move |(address, row)| {
                                    let class = fleet::state_class(&row.state);
                                    view! {
                                        <tr
                                            data-address=row.address.clone()
                                            class:trouble=row.trouble
                                            class:selected=move || focus.get() == Some(address)
                                            on:click=move |_| focus.set(Some(address))
                                        >
                                            <td on:click=|ev| ev.stop_propagation()>
                                                <input
                                                    type="checkbox"
                                                    prop:checked=move || selected.with(|s| s.contains(&address))
                                                    on:change=move |ev| {
                                                        let on = event_target_checked(&ev);
                                                        selected.update(|s| {
                                                            if on { s.insert(address); } else { s.remove(&address); }
                                                        });
                                                    }
                                                />
                                            </td>
                                            {COLUMNS
                                                .iter()
                                                .map(|(key, _)| {
                                                    let cell = match row.cell(key) {
                                                        c if c.is_empty() => "–".to_string(),
                                                        c => c,
                                                    };
                                                    let cls = match *key {
                                                        "state" => class,
                                                        "address" | "firmware" => "hex",
                                                        _ => "num",
                                                    };
                                                    view! { <td class=cls data-key=*key>{cell}</td> }
                                                })
                                                .collect_view()}
                                        </tr>
                                    }
                                }
                            />
                        </tbody>
                    </table>
                    <Show when=move || rows.with(|r| r.is_empty())>
                        <p class="muted empty">
                            {move || if street.discovering.get().is_some() {
                                "Looking for lamps on the line…"
                            } else {
                                "No lamp matches. Discover finds the lamps on the line."
                            }}
                        </p>
                    </Show>
                </div>
                <Show when=move || focus.with(|f| f.is_some())>
                    <LampPanel focus=focus/>
                </Show>
            </div>
        </div>
    }
}

#[component]
fn SweepControl() -> impl IntoView {
    let street = use_console().street;
    view! {
        <label title="reads every lamp in turn, one request at a time, as fast as the line carries">
            <input
                type="checkbox"
                id="street-sweep"
                prop:checked=move || street.sweep.get().on
                on:change=move |ev| {
                    let on = event_target_checked(&ev);
                    street.act(|s| s.set_sweep(on));
                }
            />
            " Poll the street"
        </label>
        <span id="street-progress" class="muted">
            {move || match (street.discovering.get(), street.sweep.get()) {
                (Some(round), _) => format!("discovering (round {round})…"),
                (None, s) if s.on && s.total > 0 => format!("reading {}/{} (sweep {})", s.done, s.total, s.rounds + 1),
                (None, s) if s.on => format!("{} sweeps done; next in a few seconds", s.rounds),
                _ => String::new(),
            }}
        </span>
        <span id="street-sent" class="muted" title="application frames sent to the street (requests)">
            {move || format!("{} sent", street.sent.get())}
        </span>
    }
}

/// A dimming value typed in a form: a number, whose range plm-core
/// checks (`Hid::validate`) before anything is sent.
fn dimming_value(text: &str) -> Result<u8, String> {
    text.trim().parse::<u8>().map_err(|_| {
        format!(
            "nothing sent: \"{}\" is not a dimming value (a whole number of %)",
            text.trim()
        )
    })
}

/// Eight checkboxes, IO7 first, bound to the bits of `mask`.
fn pin_boxes(mask: RwSignal<u8>, id: &'static str) -> impl IntoView {
    (0..8u8)
        .rev()
        .map(|bit| {
            view! {
                <input
                    type="checkbox"
                    id=format!("{id}-{bit}")
                    title=format!("IO{bit}")
                    prop:checked=move || mask.get() & (1 << bit) != 0
                    on:change=move |ev| {
                        let on = event_target_checked(&ev);
                        mask.update(|m| if on { *m |= 1 << bit } else { *m &= !(1 << bit) });
                    }
                />
            }
        })
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

/// The computer's clock, local time.
fn computer_clock() -> Clock {
    let d = js_sys::Date::new_0();
    Clock {
        hours: d.get_hours() as u8,
        minutes: d.get_minutes() as u8,
        seconds: d.get_seconds() as u8,
    }
}

#[component]
fn GroupActions(
    selected: RwSignal<BTreeSet<Address>>,
    message: RwSignal<Option<String>>,
) -> impl IntoView {
    let street = use_console().street;
    let level = RwSignal::new(String::from("50"));
    let parse = move || dimming_value(&level.get_untracked());
    let dim = move |targets: Option<Vec<Address>>| {
        let v = match parse() {
            Ok(v) => v,
            Err(e) => return message.set(Some(e)),
        };
        let r = street.act(|s| match &targets {
            None => s.dim(None, v),
            Some(list) => list.iter().try_for_each(|a| s.dim(Some(*a), v)),
        });
        message.set(Some(match (r, targets) {
            (Err(e), _) => format!("nothing sent: {e}"),
            (Ok(()), None) => format!("dimming {v} % sent to every lamp (broadcast)"),
            (Ok(()), Some(l)) => format!("dimming {v} % sent to {} lamp(s)", l.len()),
        }));
    };
    let set_clocks = move |_| {
        let c = computer_clock();
        let r = street.act(|s| {
            s.request(
                Request::all(Message::Service(Service::ClockSet(c))),
                Box::new(|_| {}),
            )
        });
        message.set(Some(match r {
            Ok(()) => format!("clock {c} sent to every lamp (broadcast)"),
            Err(e) => format!("nothing sent: {e}"),
        }));
    };
    view! {
        <div class="toolbar group">
            <label>
                "Dimming % "
                <input id="street-dim-level" size="4" prop:value=move || level.get() on:input=move |ev| level.set(event_target_value(&ev))/>
            </label>
            <button
                id="street-dim-selected"
                prop:disabled=move || selected.with(|s| s.is_empty())
                on:click=move |_| dim(Some(selected.get_untracked().into_iter().collect()))
            >
                {move || format!("Dim selected ({})", selected.with(|s| s.len()))}
            </button>
            <button id="street-dim-all" on:click=move |_| dim(None)>"Dim all (broadcast)"</button>
            <button id="street-clock-all" on:click=set_clocks title="sets every lamp's clock to this computer's local time">
                "Set all clocks from this computer"
            </button>
            <button
                id="street-clock-selected"
                prop:disabled=move || selected.with(|s| s.is_empty())
                on:click=move |_| {
                    let c = computer_clock();
                    let list: Vec<Address> = selected.get_untracked().into_iter().collect();
                    let r = street.act(|s| {
                        list.iter().try_for_each(|a| {
                            s.request(Request::to(*a, Message::Service(Service::ClockSet(c))), Box::new(|_| {}))
                        })
                    });
                    message.set(Some(match r {
                        Ok(()) => format!("clock {c} sent to {} lamp(s)", list.len()),
                        Err(e) => format!("nothing sent: {e}"),
                    }));
                }
            >
                "Set clocks of selected"
            </button>
        </div>
    }
}

#[component]
fn Alerts(focus: RwSignal<Option<Address>>) -> impl IntoView {
    let street = use_console().street;
    view! {
        <Show when=move || street.alerts.with(|a| !a.is_empty())>
            <div class="alerts" id="street-alerts" role="alert">
                <div class="alerts-head">
                    <b>{move || format!("{} alert(s)", street.alerts.with(|a| a.len()))}</b>
                    <button on:click=move |_| street.alerts.set(Default::default())>"Clear"</button>
                </div>
                <ul>
                    {move || street.alerts.get().into_iter().take(8).map(|r| {
                        let address = r.alert.address;
                        view! {
                            <li>
                                <a href="#street" on:click=move |_| focus.set(Some(address))>{address.to_string()}</a>
                                {format!(" {} (at {})", r.alert.what, r.wall)}
                            </li>
                        }
                    }).collect_view()}
                </ul>
            </div>
        </Show>
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
            format!("{x:.1},{y:.1}")
        })
        .collect::<Vec<_>>()
        .join(" ");
    (line, format!("{lo:.0}…{hi:.0}"))
}

#[component]
fn LampPanel(focus: RwSignal<Option<Address>>) -> impl IntoView {
    let street = use_console().street;
    let note = RwSignal::new(None::<String>);
    let level = RwSignal::new(String::from("50"));
    let lamp = Memo::new(move |_| {
        street.version.track();
        focus
            .get()
            .and_then(|a| street.with_fleet(|f| f.get(&a).cloned()))
    });
    let io_config = RwSignal::new(0u8);
    let outputs = RwSignal::new(0u8);
    let group = RwSignal::new(2u8);
    let params = RwSignal::new(String::new());
    let ask = move |m: Message, what: &'static str| {
        let Some(a) = focus.get_untracked() else {
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
                            io_config.set(v);
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
        let Some(a) = focus.get_untracked() else {
            return;
        };
        let node = (a.to_u64() - plm_sim::board::ADDRESS_BASE) as usize;
        street.act(|s| {
            if let Some(sim) = s.transport_mut().and_then(|t| t.simulator()) {
                sim.lamp(node, action);
            }
        });
        note.set(Some(format!("simulator: {action:?} on this lamp")));
    };
    view! {
        <aside class="details lamp" id="lamp-panel">
            {move || match lamp.get() {
                None => view! { <p class="muted">"This lamp is not on the street any more."</p> }.into_any(),
                Some(l) => {
                    let series = |f: fn(&crate::street::Sample) -> Option<f64>| {
                        let pts: Vec<(u64, f64)> = l.history.iter().filter_map(|s| f(s).map(|v| (s.at, v))).collect();
                        sparkline(&pts)
                    };
                    let plots = [
                        ("Power W", series(|s| Some(s.power as f64))),
                        ("Temperature °C", series(|s| Some(s.temperature as f64))),
                        ("SNR dB", series(|s| s.snr.map(f64::from))),
                    ];
                    view! {
                        <div class="lamp-head">
                            <h3>{format!("Lamp {}", l.address)}</h3>
                            <button id="lamp-close" title="close this lamp's page" on:click=move |_| focus.set(None)>"✕"</button>
                        </div>
                        <p class:problem=l.in_trouble()>
                            {match (&l.unreachable, l.state()) {
                                (Some(u), Some(s)) => format!("Unreachable: {u}. Last read: {s}."),
                                (Some(u), None) => format!("Unreachable: {u}."),
                                (None, Some(s)) => format!("Lamp {s}"),
                                (None, None) => "Not read yet.".to_string(),
                            }}
                        </p>
                        {plots.into_iter().map(|(name, (line, range))| view! {
                            <figure class="spark">
                                <figcaption>{format!("{name} {range}")}</figcaption>
                                <svg viewBox="0 0 300 60" preserveAspectRatio="none"><polyline points=line/></svg>
                            </figure>
                        }).collect_view()}
                        <div class="form-row">
                            <button id="lamp-read" on:click=move |_| ask(Message::Hid(plm_core::app::Hid::Get(plm_core::app::hid::ALL)), "read")>"Read now"</button>
                            <input id="lamp-dim-level" size="4" prop:value=move || level.get() on:input=move |ev| level.set(event_target_value(&ev))/>
                            <button id="lamp-dim" on:click=move |_| {
                                match dimming_value(&level.get_untracked()) {
                                    Ok(v) => {
                                        let a = focus.get_untracked();
                                        let r = street.act(|s| s.dim(a, v));
                                        note.set(Some(match r { Ok(()) => format!("dimming {v} % sent"), Err(e) => format!("nothing sent: {e}") }));
                                    }
                                    Err(e) => note.set(Some(e)),
                                }
                            }>"Dim"</button>
                        </div>
                        <div class="form-row">
                            <button on:click=move |_| ask(Message::Service(Service::ClockGet), "clock")>"Read clock"</button>
                            <button on:click=move |_| ask(Message::Service(Service::ClockSet(computer_clock())), "set clock")>"Set clock from this computer"</button>
                            <button on:click=move |_| ask(Message::Service(Service::InputsGet), "GPIO")>"Read GPIO levels"</button>
                            <button on:click=move |_| ask(Message::Hid(plm_core::app::Hid::Reset(plm_core::app::hid::RESET_SOFTWARE)), "ballast reset")>"Reset ballast"</button>
                        </div>
                        <h4>"GPIO (IO7 … IO0)"</h4>
                        <div class="form-row pins">
                            <span class="muted">"output"</span>
                            {pin_boxes(io_config, "io-config")}
                            <button on:click=move |_| ask(Message::Service(Service::IoConfigGet), "read GPIO configuration")>"Read"</button>
                            <button id="lamp-io-config" on:click=move |_| ask(Message::Service(Service::IoConfigSet(io_config.get_untracked())), "set GPIO configuration")>"Set"</button>
                        </div>
                        <div class="form-row pins">
                            <span class="muted">"level"</span>
                            {pin_boxes(outputs, "io-out")}
                            <button id="lamp-io-out" on:click=move |_| {
                                match output_levels(io_config.get_untracked(), outputs.get_untracked()) {
                                    Ok(v) => ask(Message::Service(Service::OutputsSet(v)), "set GPIO outputs"),
                                    Err(e) => note.set(Some(e)),
                                }
                            }>"Set outputs"</button>
                        </div>
                        <h4>"Parameters"</h4>
                        <div class="form-row">
                            <select on:change=move |ev| group.set(event_target_value(&ev).parse().unwrap_or(2))>
                                {plm_core::app::service::PROG_GROUPS.iter().enumerate().map(|(i, n)| view! {
                                    <option value=i.to_string() selected=i == 2>{*n}</option>
                                }).collect_view()}
                            </select>
                            <button on:click=move |_| ask(Message::Service(Service::ParamGet { group: group.get_untracked() }), "read parameters")>"Read"</button>
                            <button id="lamp-params-write" on:click=move |_| {
                                let data = match plm_core::hex::parse(&params.get_untracked()) {
                                    Ok(d) => d,
                                    Err(e) => return note.set(Some(format!("nothing sent: {e}"))),
                                };
                                ask(Message::Service(Service::ParamSet { group: group.get_untracked(), data }), "write parameters")
                            }>"Write"</button>
                        </div>
                        <input id="lamp-params" class="payload hex" placeholder="32 bytes, hex" prop:value=move || params.get() on:input=move |ev| params.set(event_target_value(&ev))/>
                        <Show when=move || street.port.get().contains("simulated")>
                            <div class="form-row sim-actions">
                                <span class="muted">"Simulator:"</span>
                                <button id="lamp-sim-fail" on:click=move |_| sim(LampAction::Fail)>"Break lamp"</button>
                                <button on:click=move |_| sim(LampAction::Repair)>"Replace lamp"</button>
                                <button id="lamp-sim-cut" on:click=move |_| sim(LampAction::Cut)>"Cut supply"</button>
                                <button on:click=move |_| sim(LampAction::Join)>"Restore supply"</button>
                            </div>
                        </Show>
                        <p class="muted" id="lamp-note">{move || note.get().unwrap_or_default()}</p>
                    }.into_any()
                }
            }}
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

    #[test]
    fn dimming_values_must_be_numbers() {
        assert_eq!(dimming_value(" 40 "), Ok(40));
        assert!(dimming_value("4o")
            .unwrap_err()
            .contains("not a dimming value"));
    }
}
