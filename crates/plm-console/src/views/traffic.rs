//! The traffic inspector: every element both ways, timestamped, decoded
//! by plm-core, with hex, filters, pause, clear, export and import.

use super::files;
use super::widgets::{
    button, closest, draw_rows, escape, on_click, on_event, option_html, scrolled, signal,
};
use super::{seconds, spaced};
use crate::stores::use_console;
use crate::tab::Tab;
use crate::traffic::{Entry, Filter, CAPACITY};
use leptos::prelude::*;
use std::sync::Arc;

/// The inspector, on the page's `tab`.
#[component]
pub fn TrafficView(tab: RwSignal<String>) -> impl IntoView {
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
    let shown = move || tab.get() == Tab::Traffic.slug();
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
                let matching: Vec<Arc<Entry>> = log
                    .iter()
                    .filter(|e| paused.is_none_or(|p| e.seq <= p))
                    .filter(|e| f.matches(e))
                    .map(Arc::clone)
                    .collect();
                (matching.len(), matching)
            })
        },
        crate::traffic::rows_changed,
    );
    // Where the table is scrolled, and whether it follows the newest rows
    // (scrolled to the bottom, as it opens).
    let top = signal(0u32);
    let follow = signal(true);
    // Only the rows in view are in the page (`widgets::draw_rows`).
    Effect::new(move |drawn: Option<Vec<(u64, String)>>| {
        let follow = follow.get();
        let top = if follow { 0 } else { top.get() };
        let chosen = selected.get();
        let drawn = rows.with(|(_, all)| {
            let mut html = |w: std::ops::Range<usize>| {
                all[w]
                    .iter()
                    .map(|e| (e.seq, row_html(e, chosen)))
                    .collect()
            };
            draw_rows("traffic-table", all.len(), top, follow, &mut html, drawn)
        });
        // Scrolled now, with the rows just drawn: the layout this forces
        // falls at the quiet moment the session handed its notes out at,
        // not at the next frame, when a modem frame may be ending.
        if follow {
            if let Some(wrap) = document().get_element_by_id("traffic-wrap") {
                wrap.scroll_to_with_x_and_y(0.0, 1e9);
            }
        }
        drawn
    });

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
                let total = rows.with(|r| r.0);
                c.traffic
                    .log
                    .with_untracked(|l| {
                        let mut s = format!("{} elements kept (of {CAPACITY})", l.len());
                        if l.dropped() > 0 {
                            s.push_str(&format!(", {} oldest dropped", l.dropped()));
                        }
                        s.push_str(&format!("; {total} match the filters"));
                        s
                    })
            }}
            {move || c.traffic.paused_at.get().map_or(String::new(), |_| " · PAUSED".to_string())}
        </p>
        {move || message.get().map(|m| view! { <p class="message" id="traffic-message">{m}</p> }.into_any())}
        <div class="traffic">
            <div
                class="table-wrap"
                id="traffic-wrap"
                on:scroll=on_event(move |ev| {
                    let Some((at, bottom)) = scrolled(&ev, "#traffic-wrap") else {
                        return;
                    };
                    let was = top.get_untracked();
                    if was != at {
                        top.set(at);
                    }
                    // Only a scroll up leaves the newest rows: rows coming in
                    // grow the table under a scroll position that the next
                    // frame moves to the bottom, and a scroll event between
                    // the two is not the user's.
                    let follows = bottom || (follow.get_untracked() && at >= was);
                    if follow.get_untracked() != follows {
                        follow.set(follows);
                    }
                })
            >
                <table class="log" id="traffic-table">
                    <thead>
                        <tr>
                            <th class="num">"#"</th>
                            <th class="time">"Time"</th>
                            <th class="way">"Way"</th>
                            <th class="title">"Element"</th>
                            <th class="fields">"Fields"</th>
                            <th class="hex">"Hex"</th>
                        </tr>
                    </thead>
                    <tbody on:click=on_click(move |ev| {
                        let seq = closest(&ev, "tr")
                            .and_then(|tr| tr.get_attribute("data-seq"))
                            .and_then(|s| s.parse().ok());
                        if seq.is_some() {
                            selected.set(seq);
                        }
                    })></tbody>
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

/// Characters of a Fields or Hex cell laid out: more than its line can
/// show on the widest screen (the browser shapes the text it is given,
/// shown or not).
const CELL_CHARS: usize = 160;

/// One element of the log as the HTML of its row; the whole element is
/// in the Details panel when the row is clicked.
fn row_html(e: &Entry, selected: Option<u64>) -> String {
    let from = e.from();
    let way = match from {
        "host" => "→",
        "modem" => "←",
        _ => "·",
    };
    let d = &e.decoded;
    let bad =
        d.checksum_ok == Some(false) || d.kind == "garbage" || d.kind == "nak" || d.error.is_some();
    // What a line can show; the whole text is the cell's tooltip.
    let clip = |t: &str| {
        let shown: String = t.chars().take(CELL_CHARS).collect();
        (escape(&shown), escape(t))
    };
    let (fields, all_fields) = clip(&e.summary);
    let (hex, all_hex) = clip(&spaced(&d.hex));
    format!(
        "<tr data-seq=\"{seq}\" class=\"from-{from} kind-{kind}{bad}{chosen}\"><td class=\"num\">{seq}</td><td class=\"time\">{time}</td><td class=\"way\" title=\"{from}\">{way}</td><td class=\"title\">{title}</td><td class=\"fields\" title=\"{all_fields}\">{fields}</td><td class=\"hex\" title=\"{all_hex}\">{hex}</td></tr>",
        seq = e.seq,
        from = escape(from),
        kind = escape(&d.kind),
        bad = if bad { " bad" } else { "" },
        chosen = if selected == Some(e.seq) { " selected" } else { "" },
        time = e.at.map(seconds).unwrap_or_else(|| "–".into()),
        title = escape(&e.title()),
    )
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
