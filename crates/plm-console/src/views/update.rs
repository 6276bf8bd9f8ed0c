//! The Update view: remote firmware update of the street's boards
//! (plm-core's update engine, driven by the street session). An image
//! file is checked before anything is sent; the lamps to update are one,
//! the Street view's selection, every lamp of a release, or all; progress
//! per board and overall with rate and time left; pause, cancel; a
//! campaign cut short (reload, closed tab, pulled cable) is offered again
//! from what the browser kept; the results export as CSV.

use super::files::{chosen_file, download, download_bytes, read_bytes};
use super::widgets::{
    button, escape, live_button, note, on_event, option_html, select, signal, text_input,
};
use crate::campaign_store;
use crate::stores::{use_console, StreetStore};
use crate::tab::Tab;
use leptos::prelude::*;
use plm_core::app::rfu::image::{self, Image};
use plm_core::app::{Address, Release};
use std::cell::RefCell;

thread_local! {
    /// The image chosen, kept out of the reactive graph: a signal of its
    /// own type would bring its own signal code (docs/console.md, "Size").
    /// The view's `chosen` counter tells when it changes.
    static CHOSEN: RefCell<Option<Chosen>> = const { RefCell::new(None) };
}

/// `f` of the image chosen.
fn with_chosen<R>(f: impl FnOnce(Option<&Chosen>) -> R) -> R {
    CHOSEN.with_borrow(|c| f(c.as_ref()))
}

/// The image chosen, and what its check said.
struct Chosen {
    name: String,
    bytes: Vec<u8>,
    check: Result<Image, String>,
}

impl Chosen {
    fn of(name: String, bytes: Vec<u8>) -> Chosen {
        let check = image::check(&bytes);
        Chosen { name, bytes, check }
    }

    fn words(&self) -> String {
        match &self.check {
            Ok(i) if i.described => format!(
                "{}: {} bytes, {}, CRC-32 {:08X} (descriptor checked)",
                self.name,
                i.size,
                i.release_words(),
                i.crc
            ),
            Ok(i) => format!(
                "{}: {} bytes, CRC-32 {:08X}, vector table checked; a plain .bin names no \
                 release: state the one it reports, or each lamp is judged by its swap, \
                 restart and answer",
                self.name, i.size, i.crc
            ),
            Err(why) => format!("{} refused: {why}", self.name),
        }
    }
}

/// `x.y` as a release; `None` for empty text.
fn release(text: &str) -> Result<Option<Release>, String> {
    match text.trim() {
        "" => Ok(None),
        t => Release::parse(t).map(Some),
    }
}

/// The lamps a choice of the target list names.
fn targets(street: StreetStore, choice: &str) -> Vec<Address> {
    let with_release = |r: Option<Release>| {
        street.with_fleet(|f| {
            f.values()
                .filter(|l| r.is_none() || l.discovered.map(|d| d.firmware) == r)
                .map(|l| l.address)
                .collect()
        })
    };
    match choice.split_once(':') {
        Some(("release", r)) => with_release(Release::parse(r).ok()),
        Some(("lamp", a)) => Address::parse(a).into_iter().collect(),
        _ if choice == "selected" => street.selected.get_untracked(),
        _ => with_release(None),
    }
}

/// The view.
#[component]
pub fn UpdateView(tab: RwSignal<String>) -> impl IntoView {
    let street = use_console().street;
    let choice = signal(String::from("all"));
    // The lamps to choose from, listed only while the view is shown (the
    // street's readings would rewrite 500 options for nothing): its tab
    // lists them again, the choice made kept.
    let options = move || match tab.get() == Tab::Update.slug() {
        true => target_options(street, choice),
        false => String::new(),
    };
    let chosen = signal(0u32);
    let choose = move |c: Chosen| {
        CHOSEN.with_borrow_mut(|x| *x = Some(c));
        chosen.set(chosen.get_untracked().wrapping_add(1));
    };
    let checked = move |ok: bool| {
        chosen.track();
        with_chosen(|c| c.is_some_and(|c| c.check.is_ok() == ok))
    };
    let message = signal(None::<String>);
    let make_release = signal(String::from("1.5"));
    let stated = signal(String::new());
    let make_size = signal(String::from("24576"));
    let running = move || {
        street.campaign.track();
        street.read(|s| s.campaign().map(|c| !c.update().is_done()))
    };

    let on_file = move |ev: leptos::ev::Event| {
        let Some(file) = chosen_file(&ev) else {
            return;
        };
        leptos::task::spawn_local(async move {
            match read_bytes(&file).await {
                Ok(bytes) => choose(Chosen::of(file.name(), bytes)),
                Err(e) => message.set(Some(e)),
            }
        });
    };
    let make = move || {
        let v = match release(&make_release.get_untracked()) {
            Ok(v) => v,
            Err(e) => return message.set(Some(format!("{e} (or empty for a plain .bin)"))),
        };
        let size = make_size
            .get_untracked()
            .trim()
            .parse::<usize>()
            .unwrap_or(0);
        if !(image::IMAGE_MIN..=plm_core::app::rfu::IMAGE_MAX).contains(&size) {
            return message.set(Some(format!(
                "the size is {} to {} bytes",
                image::IMAGE_MIN,
                plm_core::app::rfu::IMAGE_MAX
            )));
        }
        let (name, bytes) = match v {
            Some(v) => (
                format!("simulated-{v}.bin"),
                plm_sim::rfu::firmware_image(v, size),
            ),
            None => (
                "simulated-plain.bin".into(),
                plm_sim::rfu::plain_image(0, size),
            ),
        };
        choose(Chosen::of(name, bytes));
        message.set(None);
    };
    let start = move || {
        let Some(bytes) = with_chosen(|c| c.map(|c| c.bytes.clone())) else {
            return message.set(Some("choose an image file first".into()));
        };
        let said = match release(&stated.get_untracked()) {
            Ok(r) => r,
            Err(e) => return message.set(Some(format!("nothing sent: {e}"))),
        };
        let list = targets(street, &choice.get_untracked());
        let r = street.act(|s| s.start_update(bytes, said, &list));
        message.set(Some(match r {
            Ok(()) => format!("update started on {} lamp(s)", list.len()),
            Err(e) => format!("nothing sent: {e}"),
        }));
    };
    // A campaign kept in storage and not running here: after a reload, or
    // a new connection (the cable pulled and plugged in again).
    let discarded = signal(0u32);
    let cut_short = move || {
        street.campaign.track();
        street.port.track();
        discarded.track();
        campaign_store::has_saved() && running().is_none()
    };
    let resume = move || {
        let r = match campaign_store::saved() {
            Some((image, progress)) => street.act(|s| s.resume_update(image, &progress)),
            None => Err("the browser kept no update".into()),
        };
        message.set(Some(match r {
            Ok(()) => "update resumed where it was saved".into(),
            Err(e) => format!("cannot resume: {e}"),
        }));
    };
    let discard = move || {
        campaign_store::discard();
        discarded.update(|n| *n += 1);
    };

    view! {
        <div class="update">
            {move || cut_short().then(|| view! {
                <div class="alerts" id="update-saved" role="alert">
                    <b>{format!("An update was cut short (page closed or reloaded, cable pulled): {}. ", campaign_store::describe())}</b>
                    "Resume it: boards that hold segments keep them; every board's state is asked again. "
                    {button("update-resume", "Resume update", "", resume)}
                    {button("update-discard", "Discard", "the boards keep what they run; segments they hold are dropped at the next update", discard)}
                </div>
            }).map(IntoAny::into_any)}
            <p class="muted" id="update-protocol">"Needs boards whose firmware and bootloader speak this console's board protocol (docs/board-protocol.md), as the simulated ones do."</p>
            <div class="toolbar">
                <label>
                    "Image file "
                    <input type="file" id="update-file" accept=".bin,.img,application/octet-stream" on:change=on_event(on_file)/>
                </label>
                <span class="muted">"or make a simulated one: release (empty: a plain .bin) "</span>
                {text_input("update-make-release", "", "x.y", Some(5), make_release)}
                <span class="muted">" bytes "</span>
                {text_input("update-make-size", "", "", Some(6), make_size)}
                {button("update-make", "Make image", "a firmware image the simulated boards run", make)}
                {button("update-save-image", "Save image file", "", move || {
                    let _ = with_chosen(|c| c.map(|c| download_bytes(&c.name, &c.bytes)));
                })}
            </div>
            <p
                id="update-image"
                class="message"
                class:error=move || checked(false)
            >
                {move || {
                    chosen.track();
                    with_chosen(|c| c.map_or("no image chosen".into(), Chosen::words))
                }}
            </p>
            <div class="toolbar">
                <label title="a plain .bin names no release; a file with a descriptor must name the same">
                    "Release it reports (optional) "
                    {text_input("update-release", "", "x.y", Some(5), stated)}
                </label>
                <label>
                    "Lamps "
                    {select(
                        "update-targets",
                        Box::new(options),
                        Box::new(move |v| choice.set(v)),
                    )}
                </label>
                {live_button(
                    "update-start",
                    Box::new(|| "Start update".to_string()),
                    Box::new(move || running() == Some(true) || !checked(true)),
                    Box::new(start),
                )}
            </div>
            {move || message.with(|m| m.is_some()).then(|| note("update-message", "message", message))}
            <Progress/>
        </div>
    }
}

/// The target list as HTML options: all, the selection, each release,
/// each lamp. Rebuilt when the fleet changes, with the choice made kept
/// selected.
fn target_options(street: StreetStore, choice: RwSignal<String>) -> String {
    street.version.track();
    let selected = street.selected.with(|s| s.len());
    // Each release with its count, in the order first met (a street has
    // few; no sort is worth its code in the page).
    let mut releases: Vec<(Release, usize)> = Vec::new();
    let lamps: Vec<(Address, String)> = street.with_fleet(|f| {
        f.values()
            .map(|l| {
                let r = l.discovered.map(|d| d.firmware);
                if let Some(r) = r {
                    match releases.iter_mut().find(|(x, _)| *x == r) {
                        Some((_, n)) => *n += 1,
                        None => releases.push((r, 1)),
                    }
                }
                (l.address, r.map_or("?".into(), |r| r.to_string()))
            })
            .collect()
    });
    let mut options = vec![("all".to_string(), format!("every lamp ({})", lamps.len()))];
    if selected > 0 {
        options.push((
            "selected".into(),
            format!("lamps selected in the Street view ({selected})"),
        ));
    }
    for (r, n) in releases {
        options.push((
            format!("release:{r}"),
            format!("lamps on release {r} ({n})"),
        ));
    }
    for (a, r) in lamps {
        options.push((format!("lamp:{a}"), format!("lamp {a} (release {r})")));
    }
    let current = choice.get_untracked();
    let mut html = String::new();
    for (value, label) in options {
        option_html(&mut html, &value, &label, value == current);
    }
    html
}

/// One board's line: address, state, its segments held, the result.
type Line = (Address, &'static str, u16, String);

/// What the progress card shows, read from the campaign at once.
struct Snapshot {
    lines: Vec<Line>,
    /// Segments held over every board, thousandths.
    overall: usize,
    paused: bool,
    over: bool,
    summary: String,
}

/// `µs` as `2 min 10 s` or `40 s`.
fn duration(us: u64) -> String {
    let s = us / 1_000_000;
    if s >= 120 {
        format!("{} min {} s", s / 60, s % 60)
    } else {
        format!("{s} s")
    }
}

fn snapshot(street: StreetStore) -> Option<Snapshot> {
    street.campaign.track();
    street.read(|s| {
        let now = s.now();
        let c = s.campaign()?;
        let u = c.update();
        let report = u.report();
        let lines: Vec<Line> = u
            .boards()
            .enumerate()
            .zip(report)
            .map(|((i, (a, st)), (_, words))| (a, st.words(), u.permille(i), words))
            .collect();
        let done = lines.iter().filter(|l| l.1 == "updated").count();
        let failed = lines
            .iter()
            .filter(|l| l.3.starts_with("not updated"))
            .count();
        let overall = lines.iter().map(|l| l.2 as usize).sum::<usize>() / lines.len().max(1);
        let head = format!(
            "{} to {} lamp(s): {done} updated, {failed} not updated",
            plm_core::app::rfu::release_words(u.header().release()),
            lines.len()
        );
        let summary = match c.ended {
            Some(end) => format!("{head} · took {}", duration(end.saturating_sub(c.since))),
            None => {
                let elapsed = now.saturating_sub(c.since).max(1);
                format!(
                    "{head} · {} % · {} B/s · about {} left{}",
                    overall / 10,
                    u.bytes_sent() * 1_000_000 / elapsed,
                    duration(u.time_left(now)),
                    if c.paused { " · paused" } else { "" }
                )
            }
        };
        Some(Snapshot {
            lines,
            overall,
            paused: c.paused,
            over: u.is_done(),
            summary,
        })
    })
}

#[component]
fn Progress() -> impl IntoView {
    let street = use_console().street;
    let export = move || {
        let Some(s) = snapshot(street) else {
            return;
        };
        let mut csv = String::from("address,result\n");
        for (a, _, _, words) in &s.lines {
            csv.push_str(&format!("{a},\"{}\"\n", words.replace('"', "'")));
        }
        let _ = download("update-results.csv", "text/csv", &csv);
    };
    move || {
        let s = snapshot(street)?;
        let (paused, over, overall) = (s.paused, s.over, s.overall);
        Some(view! {
            <div class="card" id="update-progress-card">
                <p id="update-summary"><b>{s.summary.clone()}</b></p>
                <progress id="update-progress" class="wide" max="1000" value=overall.to_string()></progress>
                <div class="toolbar">
                    {(!over).then(|| button(
                        "update-pause",
                        if paused { "Resume sending" } else { "Pause" },
                        "",
                        move || street.act(|x| x.pause_update(!paused)),
                    ))}
                    {(!over).then(|| button(
                        "update-cancel",
                        "Cancel update",
                        "boards not swapped yet keep their release and forget the segments",
                        move || street.act(|x| x.cancel_update()),
                    ))}
                    {over.then(|| button("update-export", "Export results (CSV)", "", export))}
                    {over.then(|| button("update-dismiss", "Close", "", move || street.act(|x| x.dismiss_update())))}
                </div>
                <div class="table-wrap">
                    <table class="log" id="update-boards">
                        <thead><tr><th>"Lamp"</th><th>"State"</th><th>"Segments held"</th><th>"Result"</th></tr></thead>
                        // Written as HTML in one go (as widgets::text_table).
                        <tbody inner_html=s.lines.iter().fold(String::new(), |mut h, (a, st, pm, words)| {
                            h.push_str(&format!(
                                "<tr class=\"{}\"><td>{}</td><td>{}</td><td><progress max=\"1000\" value=\"{pm}\"></progress></td><td>{}</td></tr>",
                                if words.starts_with("not updated") { "trouble" } else { "" },
                                escape(&a.to_string()),
                                escape(st),
                                escape(words),
                            ));
                            h
                        })></tbody>
                    </table>
                </div>
            </div>
        }.into_any())
    }
}
