//! The traffic inspector: every element both ways, timestamped, decoded
//! by plm-core, with hex, filters, pause, clear, export and import.

use super::files;
use super::widgets::{button, on_click, on_event, option_html, signal};
use super::{seconds, spaced};
use crate::app::Tab;
use crate::stores::use_console;
use crate::traffic::{Entry, Filter, CAPACITY};
use leptos::prelude::*;
use std::sync::Arc;

/// Rows rendered at most; the log keeps [`CAPACITY`].
pub const MAX_ROWS: usize = 500;

/// The inspector, on the page's `tab`.
#[component]
pub fn TrafficView(tab: RwSignal<Tab>) -> impl IntoView {
    let c = use_console();
    // The filter's three choices as String signals (a signal type the page
    // has, rather than one of `Filter`'s own).
    let filter = FilterChoice {
        from: signal(String::new()),
        kind: signal(String::new()),
        command: signal(String::new()),
    };
    let selected = signal(None::<u64>);
    let message = signal(None::<String>);
    // Hidden, the table keeps its rows and does not even look at the log:
    // redrawing it would only hold up the host's next ACK (issue 13), and
    // its tab brings it up to date.
    let shown = move || tab.get() == Tab::Traffic;
    // Rows compared by what they are (their sequence numbers), not field
    // by field: the log only ever appends, drops or clears.
    let rows = Memo::new_with_compare(
        move |prev: Option<&(usize, Vec<Arc<Entry>>)>| {
            if let Some(p) = prev.filter(|_| !shown()) {
                return p.clone();
            }
            let f = filter.get();
            let paused = c.traffic.paused_at.get();
            c.traffic.log.with(|log| {
                let matching: Vec<&Arc<Entry>> = log
                    .iter()
                    .filter(|e| paused.is_none_or(|p| e.seq <= p))
                    .filter(|e| f.matches(e))
                    .collect();
                let total = matching.len();
                let shown: Vec<Arc<Entry>> = matching[total.saturating_sub(MAX_ROWS)..]
                    .iter()
                    .map(|e| Arc::clone(e))
                    .collect();
                (total, shown)
            })
        },
        crate::traffic::rows_changed,
    );

    view! {
        <div class="toolbar" id="traffic-toolbar">
            <FilterControls filter=filter/>
            <PauseButton/>
            <button
                id="traffic-clear"
                on:click=on_click(move |_| {
                    c.traffic.log.update(|l| l.clear());
                    c.traffic.paused_at.set(None);
                    selected.set(None);
                    message.set(None);
                })
            >
                "Clear"
            </button>
            <ExportImport message=message/>
        </div>
        <p class="counts" id="traffic-counts">
            {move || {
                if shown() {
                    c.traffic.log.track();
                }
                let (total, shown) = rows.with(|(t, s)| (*t, s.len()));
                c.traffic
                    .log
                    .with_untracked(|l| {
                        let mut s = format!("{} elements kept (of {CAPACITY})", l.len());
                        if l.dropped() > 0 {
                            s.push_str(&format!(", {} oldest dropped", l.dropped()));
                        }
                        s.push_str(&format!("; {total} match the filters"));
                        if shown < total {
                            s.push_str(&format!(", the last {shown} shown"));
                        }
                        s
                    })
            }}
            {move || c.traffic.paused_at.get().map(|_| " · PAUSED".to_string())}
        </p>
        {move || message.get().map(|m| view! { <p class="message" id="traffic-message">{m}</p> })}
        <div class="traffic">
            <div class="table-wrap">
                <table class="log" id="traffic-table">
                    <thead>
                        <tr>
                            <th>"#"</th>
                            <th>"Time"</th>
                            <th>"Way"</th>
                            <th>"Element"</th>
                            <th>"Fields"</th>
                            <th>"Hex"</th>
                        </tr>
                    </thead>
                    <tbody>
                        {super::widgets::keyed_rows(
                            move || rows.with(|r| r.1.iter().map(|e| e.seq).collect()),
                            move |seq| {
                                // The row of an entry shown (the log holds them in order).
                                let entry = rows.with_untracked(|r| {
                                    r.1.binary_search_by_key(&seq, |e| e.seq).ok().map(|i| Arc::clone(&r.1[i]))
                                });
                                entry.map(|e| view! { <Row entry=e selected=selected/> }).into_any()
                            },
                        )}
                    </tbody>
                </table>
            </div>
            <Details selected=selected/>
        </div>
    }
}

/// The filter as chosen in the toolbar.
#[derive(Clone, Copy)]
struct FilterChoice {
    from: RwSignal<String>,
    kind: RwSignal<String>,
    command: RwSignal<String>,
}

impl FilterChoice {
    /// The filter now (tracked).
    fn get(&self) -> Filter {
        Filter {
            from: self.from.get(),
            kind: self.kind.get(),
            command: self.command.get(),
        }
    }
}

#[component]
fn FilterControls(filter: FilterChoice) -> impl IntoView {
    let c = use_console();
    // The commands of the chip the profile talks to, by its description's
    // names; a command the new chip does not have stops filtering.
    let commands = move || {
        let chip = plm_core::chip::for_dialect(c.profile.get().dialect());
        let chosen = filter.command.get_untracked();
        let mut html = String::from("<option value=\"\">all</option>");
        let mut kept = chosen.is_empty();
        for name in (0..=255u8).filter_map(|code| chip.code_name(code)) {
            kept |= name == chosen;
            option_html(&mut html, name, name, name == chosen);
        }
        if !kept {
            filter.command.set(String::new());
        }
        html
    };
    view! {
        <label>
            "Way "
            <select
                id="filter-from"
                on:change=on_event(move |ev| filter.from.set(event_target_value(&ev)))
            >
                <option value="">"both"</option>
                <option value="host">"host → modem"</option>
                <option value="modem">"modem → host"</option>
            </select>
        </label>
        <label>
            "Kind "
            <select
                id="filter-kind"
                on:change=on_event(move |ev| filter.kind.set(event_target_value(&ev)))
            >
                <option value="">"all"</option>
                <option value="frame">"frames"</option>
                <option value="ack">"ACK"</option>
                <option value="nak">"NAK"</option>
                <option value="status">"status messages"</option>
                <option value="garbage">"garbage"</option>
            </select>
        </label>
        <label>
            "Command "
            <select
                id="filter-command"
                inner_html=commands
                on:change=on_event(move |ev| filter.command.set(event_target_value(&ev)))
            ></select>
        </label>
    }
}

#[component]
fn PauseButton() -> impl IntoView {
    let c = use_console();
    let paused = c.traffic.paused_at;
    view! {
        <button
            id="traffic-pause"
            aria-pressed=move || paused.get().is_some().to_string()
            on:click=on_click(move |_| {
                if paused.get_untracked().is_some() {
                    paused.set(None);
                } else {
                    let last = c.traffic.log.with_untracked(|l| l.next_seq().saturating_sub(1));
                    paused.set(Some(last));
                }
            })
        >
            {move || String::from(if paused.get().is_some() { "Resume" } else { "Pause" })}
        </button>
    }
}

#[component]
fn ExportImport(message: RwSignal<Option<String>>) -> impl IntoView {
    let c = use_console();
    let export = move || {
        let text = c.traffic.log.with_untracked(|l| l.export());
        let lines = text.lines().count();
        match files::download("plm-traffic.jsonl", "application/x-ndjson", &text) {
            Ok(()) => message.set(Some(format!(
                "Exported {lines} elements as JSON Lines (plm-traffic.jsonl)."
            ))),
            Err(e) => message.set(Some(e)),
        }
    };
    let import = move |ev: leptos::ev::Event| {
        let Some(file) = files::chosen_file(&ev) else {
            return;
        };
        leptos::task::spawn_local(async move {
            let name = file.name();
            let text = match files::read_text(&file).await {
                Ok(t) => t,
                Err(e) => {
                    message.set(Some(e));
                    return;
                }
            };
            let mut result = None;
            c.traffic.log.update(|l| result = Some(l.import(&text)));
            match result {
                Some(Ok(got)) => {
                    let last = c
                        .traffic
                        .log
                        .with_untracked(|l| l.next_seq().saturating_sub(1));
                    c.traffic.paused_at.set(Some(last));
                    let mut m = format!(
                        "Imported {} elements from {name}; live traffic is paused (Resume to follow the modem).",
                        got.count
                    );
                    if let Some(first) = got.skipped.first() {
                        m.push_str(&format!(
                            " {} lines skipped, e.g. {first}.",
                            got.skipped.len()
                        ));
                    }
                    message.set(Some(m));
                }
                Some(Err(e)) => message.set(Some(format!("Nothing imported from {name}: {e}."))),
                None => {}
            }
        });
    };
    view! {
        {button("traffic-export", "Export JSONL", "", export)}
        <label class="button">
            "Import JSONL…"
            <input
                id="traffic-import"
                type="file"
                accept=".jsonl,.json,.txt,application/x-ndjson"
                on:change=on_event(import)
            />
        </label>
    }
}

#[component]
fn Row(entry: Arc<Entry>, selected: RwSignal<Option<u64>>) -> impl IntoView {
    let seq = entry.seq;
    let from = entry.from().to_string();
    let way = match from.as_str() {
        "host" => "→",
        "modem" => "←",
        _ => "·",
    };
    let bad = entry.decoded.checksum_ok == Some(false)
        || entry.decoded.kind == "garbage"
        || entry.decoded.kind == "nak"
        || entry.decoded.error.is_some();
    view! {
        <tr
            class=format!("from-{from} kind-{}", entry.decoded.kind)
            class:bad=bad
            class:selected=move || selected.get() == Some(seq)
            on:click=on_click(move |_| selected.set(Some(seq)))
        >
            <td class="num">{seq}</td>
            <td class="time">{entry.at.map(seconds).unwrap_or_else(|| "–".into())}</td>
            <td class="way" title=from.clone()>{way}</td>
            <td class="title">{entry.title()}</td>
            <td class="fields">{entry.summary.clone()}</td>
            <td class="hex">{spaced(&entry.decoded.hex)}</td>
        </tr>
    }
}

#[component]
fn Details(selected: RwSignal<Option<u64>>) -> impl IntoView {
    let c = use_console();
    let json = move || {
        let seq = selected.get()?;
        c.traffic.log.with(|l| Some(l.get(seq)?.to_json().pretty()))
    };
    view! {
        <aside class="details" id="traffic-details">
            <h3>"Element"</h3>
            {move || match json() {
                Some(j) => view! { <pre>{j}</pre> }.into_any(),
                None => view! { <p class="muted">"Click a row to see every field."</p> }.into_any(),
            }}
        </aside>
    }
}
