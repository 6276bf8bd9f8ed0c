//! The street picture above the fleet table ([`crate::fleet::picture`]),
//! with the pole list's import (`plm_core::file::poles`), kept in the
//! browser's storage. The picture is written as HTML when the fleet or
//! the list changes; one click listener opens the page of the lamp
//! clicked, by its `data-address`.

use super::row_key;
use crate::stores::use_console;
use crate::views::files;
use crate::views::widgets::{button, closest, note, on_click, on_event, signal};
use leptos::prelude::*;
use plm_core::app::Address;
use plm_core::file::poles::{self, POLE_LIST_MAX};

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
    Effect::new(move |drawn: Option<String>| {
        street.version.track();
        let html = list.with(|text| {
            let poles = (!text.is_empty())
                .then(|| poles::parse(text.as_bytes()).ok())
                .flatten();
            street.with_fleet(|f| crate::fleet::picture::html(f, poles.as_deref()))
        });
        let Some(el) = document().get_element_by_id("street-picture") else {
            return String::new();
        };
        if drawn.as_ref() != Some(&html) {
            el.set_inner_html(&html);
        }
        html
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
            on:click=on_click(move |ev| {
                let address = closest(&ev, "[data-address]")
                    .and_then(|el| el.get_attribute("data-address"))
                    .and_then(|hex| Address::parse(&hex).ok());
                if let Some(a) = address {
                    focus.set(Some(row_key(a)));
                }
            })
        ></div>
    }
}
