//! The street picture above the fleet table ([`crate::fleet::picture`]),
//! with the pole list's import (`plm_core::file::poles`), kept in the
//! browser's storage. The picture is written as HTML when the fleet, the
//! list or the lamp whose page is open changes, only what differs; one
//! click listener opens the page of the lamp clicked, by its
//! `data-address`.

use crate::fleet::picture::{Cell, Grid, Picture, WIDTH};
use crate::fleet::{key_address, row_key};
use crate::stores::use_console;
use crate::views::files;
use crate::views::widgets::{button, closest, note, on_click, on_event, signal};
use leptos::prelude::*;
use plm_core::app::Address;
use plm_core::file::poles::{self, POLE_LIST_MAX};
use std::cell::RefCell;

thread_local! {
    /// The small marks' cells as last drawn, for the pointer (`cell_at`).
    static GRID: RefCell<Grid> = RefCell::default();
}

/// Where the pole list is kept (its text, as imported).
const KEY: &str = "plm-console.poles";

/// The picture, its order's controls and their message.
#[component]
pub fn StreetPicture(focus: RwSignal<Option<u64>>) -> impl IntoView {
    let street = use_console().street;
    let message = signal(None::<String>);
    // The pole list's text: a String signal as the page has many.
    let list = signal(crate::storage::load(KEY).unwrap_or_default());
    if !list.get_untracked().is_empty() {
        if let Err(e) = poles::parse(list.get_untracked().as_bytes()) {
            crate::storage::store(KEY, None);
            list.set(String::new());
            message.set(Some(format!(
                "the pole list kept in this browser cannot be read ({e}); it is forgotten"
            )));
        }
    }
    // Drawn when the fleet, the list or the open lamp changes: the heading
    // and the street each when it differs.
    Effect::new(move |drawn: Option<Picture>| {
        street.version.track();
        let open = focus.get().map(key_address);
        let mut now = list.with(|text| {
            let poles = (!text.is_empty())
                .then(|| poles::parse(text.as_bytes()).ok())
                .flatten();
            street.with_fleet(|f| crate::fleet::picture::picture(f, poles.as_deref(), open))
        });
        let doc = document();
        let (Some(head), Some(svg)) = (
            doc.get_element_by_id("street-picture-head"),
            doc.get_element_by_id("street-picture-street"),
        ) else {
            return Picture::default();
        };
        let drawn = drawn.unwrap_or_default();
        if drawn.head != now.head {
            head.set_inner_html(&now.head);
        }
        if drawn.street != now.street {
            svg.set_inner_html(&now.street);
        }
        GRID.set(std::mem::take(&mut now.grid));
        now
    });
    let import = move |ev: web_sys::Event| {
        let Some(file) = files::chosen_file(&ev) else {
            return;
        };
        let name = file.name();
        let refuse = move |e: String| {
            message.set(Some(format!(
                "pole list {name} refused, nothing changed: {e}"
            )))
        };
        if file.size() > POLE_LIST_MAX as f64 {
            // The same words as the parser's, before the file is read.
            return refuse(poles::parse(&[b' '; POLE_LIST_MAX + 1]).unwrap_err());
        }
        leptos::task::spawn_local(async move {
            let bytes = match files::read_bytes(&file).await {
                Ok(b) => b,
                Err(e) => return refuse(e),
            };
            match poles::parse(&bytes) {
                Err(e) => refuse(e),
                Ok(p) => {
                    // Read once more on every load: kept as its text.
                    let text = plm_core::file::text(&bytes).unwrap_or_default();
                    let kept = crate::storage::store(KEY, Some(text));
                    list.set(text.to_string());
                    message.set(Some(format!(
                        "pole list {}: {} pole(s){}",
                        file.name(),
                        p.len(),
                        if kept {
                            ""
                        } else {
                            "; the browser would not keep it, so it lasts until the page is closed"
                        }
                    )));
                }
            }
        });
    };
    view! {
        <div class="toolbar pk-tools">
            <label class="button" title="a CSV of lamp address, pole name and position in metres (optional), one pole a line, in the street's order">
                "Import pole list…"
                <input id="street-poles" type="file" accept=".csv,.txt,text/csv" on:change=on_event(import)/>
            </label>
            {move || (list.with(|l| !l.is_empty())).then(|| button("street-poles-clear", "Forget pole list", "back to address order", move || {
                crate::storage::store(KEY, None);
                list.set(String::new());
                message.set(Some("pole list forgotten: address order".into()));
            }))}
        </div>
        {move || (message.with(|m| m.is_some())).then(|| note("street-poles-note", "muted", message))}
        <div
            id="street-picture"
            inner_html="<div id=\"street-picture-head\"></div><div id=\"street-picture-street\"></div>"
            on:click=on_click(move |ev| {
                let address = closest(&ev, "[data-address]")
                    .and_then(|el| el.get_attribute("data-address"))
                    .and_then(|hex| Address::parse(&hex).ok())
                    .or_else(|| cell_at(&ev, |c| c.address).flatten());
                if let Some(a) = address {
                    focus.set(Some(row_key(a)));
                }
            })
            on:mousemove=on_click(|ev| {
                // A small mark's words, as a tooltip.
                let title = cell_at(&ev, |c| c.title.clone());
                if let Some(el) = closest(&ev, "#street-picture-street") {
                    let _ = match title {
                        Some(t) => el.set_attribute("title", &t),
                        None => el.remove_attribute("title"),
                    };
                }
            })
        ></div>
    }
}

/// What `read` says of the small mark's cell under the pointer of `ev`
/// (none over a named mark, a margin or no picture).
fn cell_at<T>(ev: &web_sys::MouseEvent, read: impl FnOnce(&Cell) -> T) -> Option<T> {
    let r = closest(ev, "svg.pk")?.get_bounding_client_rect();
    if r.width() <= 0.0 {
        return None;
    }
    // The picture keeps its proportions: one scale for both axes.
    let scale = f64::from(WIDTH) / r.width();
    // web-sys has clientX as an f64 for wasm32, an i32 natively.
    #[allow(clippy::useless_conversion)]
    let (x, y) = (
        (f64::from(ev.client_x()) - r.left()) * scale,
        (f64::from(ev.client_y()) - r.top()) * scale,
    );
    GRID.with_borrow(|g| g.at(x, y).map(read))
}
