//! The Street view: the fleet of lamps (discover, a background sweep, a
//! sortable and filterable table with failed and unreachable lamps
//! standing out, CSV and JSON export), dimming and clocks for a selection
//! or all, alerts; a lamp's own page is [`super::lamp`]; the street
//! picture and its pole list are [`picture`].

mod picture;

use super::files::download;
use super::widgets::{
    button, checkbox, closest, draw_rows, live_button, on_click, on_event, scrolled, signal,
    text_input,
};
use crate::clock::computer_clock;
use crate::fleet::{self, dimming_value, key_address, row_key, Row, COLUMNS};
use crate::stores::use_console;
use crate::street::Lamps;
use leptos::prelude::*;
use plm_core::app::Address;

/// The view.
#[component]
pub fn StreetView() -> impl IntoView {
    let street = use_console().street;
    let filter = signal(String::new());
    // The column sorted by, `-` before it when descending: a String signal
    // as the page has many, not one of its own type (docs/console.md, "Size").
    let sort = signal(String::from("address"));
    let selected = street.selected;
    // The lamp whose page is open, by its row key: an Option<u64> signal
    // as the page has (docs/console.md, "Size").
    let focus = signal(None::<u64>);
    let message = signal(None::<String>);
    // The rows shown, sorted and filtered.
    let rows = Memo::new(move |_| {
        street.version.track();
        let epoch = crate::history_store::epoch();
        let mut rows: Vec<Row> =
            street.with_fleet(|f| f.values().map(|l| Row::of(l, epoch)).collect());
        sort.with(|s| match s.strip_prefix('-') {
            Some(key) => fleet::sort(&mut rows, key, false),
            None => fleet::sort(&mut rows, s, true),
        });
        let f = filter.get();
        rows.retain(|r| r.matches(&f));
        rows
    });
    let export = move |json: bool| {
        let rows: Vec<Row> = rows.get_untracked();
        let r = if json {
            download("street.json", "application/json", &fleet::to_json(&rows))
        } else {
            download("street.csv", "text/csv", &fleet::to_csv(&rows))
        };
        if let Err(e) = r {
            message.set(Some(e));
        }
    };
    // Where the table is scrolled; only the rows in view are in the page
    // (`widgets::draw_rows`), each written as HTML, so that 500 lamps lay
    // out as fast as 30.
    let top = signal(0u32);
    Effect::new(move |drawn: Option<Vec<(u64, String)>>| {
        let top = top.get();
        let focused = focus.get();
        selected.with(|picked| {
            rows.with(|all| {
                let mut html = |w: std::ops::Range<usize>| {
                    let row = |r: &Row| {
                        let key = row_key(r.address);
                        let html = row_html(r, picked.contains(&r.address), focused == Some(key));
                        (key, html)
                    };
                    all[w].iter().map(row).collect()
                };
                draw_rows("fleet-table", all.len(), top, false, &mut html, drawn)
            })
        })
    });
    view! {
        <div class="street">
            <div class="toolbar">
                <span class="muted" id="street-port">{move || street.port.get()}</span>
                {button("street-discover", "Discover", "finds every lamp again; the lamps found are kept in this browser for this connection, read at once when it opens again", move || street.act(|s| s.discover()))}
                <SweepControl/>
                {text_input("street-filter", "", "filter: address, state, \"trouble\"", None, filter)}
                {button("street-export-csv", "Export CSV", "", move || export(false))}
                {button("street-export-json", "Export JSON", "", move || export(true))}
            </div>
            <picture::StreetPicture focus=focus/>
            <p class="muted" id="street-protocol">"Discover and Firmware update need boards that speak this console's board protocol (docs/board-protocol.md), as the simulated ones do; a board on ST's own firmware answers only the manual's commands."</p>
            <p class="muted" id="street-energy">{move || {
                street.version.track();
                street.with_fleet(|f| fleet::street_energy(f.values()))
            }}</p>
            <GroupActions selected=selected message=message/>
            {move || (message.with(|m| m.is_some())).then(|| view! {
                {super::widgets::note("street-message", "message", message)}
            }).map(IntoAny::into_any)}
            <Alerts focus=focus/>
            <div class="street-grid" class:with-lamp=move || focus.with(|f| f.is_some())>
                <div
                    class="table-wrap"
                    id="fleet-wrap"
                    on:scroll=on_event(move |ev| {
                        if let Some((at, _)) = scrolled(&ev, "#fleet-wrap") {
                            if top.get_untracked() != at {
                                top.set(at);
                            }
                        }
                    })
                >
                    <table class="log fleet" id="fleet-table">
                        <thead>
                            <tr>
                                <th>
                                    <input
                                        type="checkbox"
                                        id="fleet-select-all"
                                        title="select every lamp shown"
                                        on:change=on_event(move |ev| {
                                            let on = event_target_checked(&ev);
                                            selected.set(if on {
                                                rows.get_untracked().iter().map(|r| r.address).collect()
                                            } else {
                                                Vec::new()
                                            });
                                        })
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
                                                on:click=on_click(move |_| sort.update(|s| *s = if s == key { format!("-{key}") } else { key.to_string() }))
                                            >
                                                {*header}
                                                {move || String::from(sort.with(|s| {
                                                    if s == key {
                                                        " ▲"
                                                    } else if s.strip_prefix('-') == Some(key) {
                                                        " ▼"
                                                    } else {
                                                        ""
                                                    }
                                                }))}
                                            </th>
                                        }
                                    })
                                    .map(IntoAny::into_any).collect_view()}
                            </tr>
                        </thead>
                        // One click and one change listener for every row: a row
                        // is its cells written as HTML (`row_html`), redrawn when
                        // its lamp or its selection changes.
                        <tbody
                            on:click=on_click(move |ev| {
                                // The selection box's cell does not open the lamp.
                                if closest(&ev, "td.pick").is_none() {
                                    if let Some(a) = row_address(&ev) {
                                        focus.set(Some(row_key(a)));
                                    }
                                }
                            })
                            on:change=on_event(move |ev| {
                                let Some(a) = row_address(&ev) else {
                                    return;
                                };
                                let on = event_target_checked(&ev);
                                selected.update(|s| {
                                    s.retain(|x| *x != a);
                                    if on {
                                        s.push(a);
                                    }
                                });
                            })
                        >
                        </tbody>
                    </table>
                    {move || (rows.with(|r| r.is_empty())).then(|| view! {
                        <p class="muted empty">
                            {move || String::from(if street.discovering.get().is_some() {
                                "Looking for lamps on the line…"
                            } else {
                                "No lamp matches. Discover finds the lamps on the line."
                            })}
                        </p>
                    }).map(IntoAny::into_any)}
                </div>
                {move || (focus.with(|f| f.is_some())).then(|| view! {
                    <super::lamp::LampPanel focus=focus/>
                }).map(IntoAny::into_any)}
            </div>
        </div>
    }
}

#[component]
fn SweepControl() -> impl IntoView {
    let street = use_console().street;
    view! {
        <label title="reads every lamp in turn, one request at a time, as fast as the line carries">
            {checkbox(
                "street-sweep",
                Box::new(move || street.sweep.get().on),
                Box::new(move |on| street.act(|s| s.set_sweep(on))),
            )}
            " Poll the street"
        </label>
        <span id="street-progress" class="muted">
            {move || match (street.discovering.get(), street.sweep.get()) {
                (Some(d), _) => format!("discovering: {} found, about {} left…", d >> 32, d & 0xFFFF_FFFF),
                (None, s) if s.on && s.total > 0 => format!("reading {}/{} (sweep {})", s.done, s.total, s.rounds + 1),
                (None, s) if s.on => format!(
                    "{} sweep{} done; next in a few seconds",
                    s.rounds,
                    if s.rounds == 1 { "" } else { "s" }
                ),
                _ => String::new(),
            }}
        </span>
        <span id="street-sent" class="muted" title="application frames sent to the street (requests)">
            {move || format!("{} sent", street.sent.get())}
        </span>
    }
}

#[component]
fn GroupActions(
    selected: RwSignal<Vec<Address>>,
    message: RwSignal<Option<String>>,
) -> impl IntoView {
    let street = use_console().street;
    let level = signal(String::from("50"));
    let parse = move || dimming_value(&level.get_untracked());
    let dim = move |targets: Option<Vec<Address>>| {
        let v = match parse() {
            Ok(v) => v,
            Err(e) => return message.set(Some(e)),
        };
        let r = street.act(|s| match &targets {
            None => s.dim(Lamps::All, v),
            Some(list) => s.dim(Lamps::These(list), v),
        });
        message.set(Some(match (r, targets) {
            (Err(e), _) => format!("nothing sent: {e}"),
            (Ok(()), None) => format!("dimming {v} % sent to every lamp (broadcast)"),
            (Ok(()), Some(l)) => format!("dimming {v} % sent to {} lamp(s)", l.len()),
        }));
    };
    let set_clocks = move || {
        let c = computer_clock();
        let r = street.act(|s| s.set_clock(Lamps::All, c));
        message.set(Some(match r {
            Ok(()) => format!("clock {c} sent to every lamp (broadcast)"),
            Err(e) => format!("nothing sent: {e}"),
        }));
    };
    view! {
        <div class="toolbar group">
            <label>
                "Dimming % "
                {text_input("street-dim-level", "", "", Some(4), level)}
            </label>
            {live_button(
                "street-dim-selected",
                Box::new(move || format!("Dim selected ({})", selected.with(|s| s.len()))),
                Box::new(move || selected.with(|s| s.is_empty())),
                Box::new(move || dim(Some(selected.get_untracked()))),
            )}
            {button("street-dim-all", "Dim all (broadcast)", "", move || dim(None))}
            {button("street-clock-all", "Set all clocks from this computer", "sets every lamp's clock to this computer's local time", set_clocks)}
            {live_button(
                "street-clock-selected",
                Box::new(|| "Set clocks of selected".to_string()),
                Box::new(move || selected.with(|s| s.is_empty())),
                Box::new(move || {
                    let c = computer_clock();
                    let list = selected.get_untracked();
                    let r = street.act(|s| s.set_clock(Lamps::These(&list), c));
                    message.set(Some(match r {
                        Ok(()) => format!("clock {c} sent to {} lamp(s)", list.len()),
                        Err(e) => format!("nothing sent: {e}"),
                    }));
                }),
            )}
        </div>
    }
}

#[component]
fn Alerts(focus: RwSignal<Option<u64>>) -> impl IntoView {
    let street = use_console().street;
    view! {
        {move || (street.alerts.with(|a| !a.is_empty())).then(|| view! {
            <div class="alerts" id="street-alerts" role="alert">
                <div class="alerts-head">
                    <b>{move || format!("{} alert(s)", street.alerts.with(|a| a.len()))}</b>
                    {button("", "Clear", "", move || street.alerts.set(Default::default()))}
                </div>
                <ul>
                    {move || street.alerts.get().into_iter().take(8).map(|r| {
                        let address = r.alert.address;
                        view! {
                            <li>
                                <a href="#street" on:click=on_click(move |_| focus.set(Some(row_key(address))))>{address.to_string()}</a>
                                {format!(" {} (at {})", r.alert.what, r.wall)}
                            </li>
                        }
                    }).map(IntoAny::into_any).collect_view()}
                </ul>
            </div>
        }).map(IntoAny::into_any)}
    }
}

/// A fleet row as HTML: the lamp's address and marks on the line, the
/// selection checkbox, then each of [`COLUMNS`] (`–` where the lamp has
/// no value yet).
fn row_html(row: &Row, picked: bool, focus: bool) -> String {
    let class = match (row.trouble, focus) {
        (true, true) => " class=\"trouble selected\"",
        (true, false) => " class=\"trouble\"",
        (false, true) => " class=\"selected\"",
        (false, false) => "",
    };
    let mut html = format!(
        "<tr data-address=\"{}\"{class}><td class=\"pick\"><input type=\"checkbox\"{}></td>",
        row.address,
        if picked { " checked" } else { "" }
    );
    for (key, _) in COLUMNS {
        let class = match *key {
            "state" => row.look.class(),
            "address" | "firmware" => "hex",
            _ => "num",
        };
        let cell = row.cell(key);
        let cell = if cell.is_empty() { "–" } else { &cell };
        html.push_str(&format!(
            "<td class=\"{class}\" data-key=\"{key}\">{}</td>",
            super::widgets::escape(cell)
        ));
    }
    html.push_str("</tr>");
    html
}

/// The lamp of the fleet row an event happened in (its `data-address`).
fn row_address(ev: &web_sys::Event) -> Option<Address> {
    let hex = closest(ev, "tr[data-address]")?.get_attribute("data-address")?;
    u64::from_str_radix(&hex, 16).ok().map(key_address)
}
