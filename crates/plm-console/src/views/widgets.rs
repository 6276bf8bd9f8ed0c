//! Controls every view uses, written once: each is one non-generic
//! function, so a page of buttons costs one copy of the button's code in
//! the console's wasm instead of one per button (the 350 KiB budget,
//! docs/console.md "Size").

use leptos::prelude::*;

/// A button labelled `label`; `id` and `title` (a tooltip) may be empty.
pub fn button(
    id: &'static str,
    label: &'static str,
    title: &'static str,
    on: impl Fn() + 'static,
) -> AnyView {
    button_boxed(id, "", label, title, Box::new(on))
}

/// A button of a card's actions, named by `data-action` (`read`, `erase`,
/// ...) as each card has its own.
pub fn action_button(
    action: &'static str,
    label: &'static str,
    on: impl Fn() + 'static,
) -> AnyView {
    button_boxed("", action, label, "", Box::new(on))
}

#[inline(never)]
fn button_boxed(
    id: &'static str,
    action: &'static str,
    label: &'static str,
    title: &'static str,
    on: Box<dyn Fn()>,
) -> AnyView {
    view! {
        <button
            id=(!id.is_empty()).then_some(id)
            data-action=(!action.is_empty()).then_some(action)
            title=(!title.is_empty()).then_some(title)
            on:click=on_click(move |_| on())
        >
            {label}
        </button>
    }
    .into_any()
}

/// A text input bound to `value`; `id` and `placeholder` may be empty.
#[inline(never)]
pub fn text_input(
    id: &'static str,
    class: &'static str,
    placeholder: &'static str,
    size: Option<u32>,
    value: RwSignal<String>,
) -> AnyView {
    view! {
        <input
            id=(!id.is_empty()).then_some(id)
            class=(!class.is_empty()).then_some(class)
            placeholder=(!placeholder.is_empty()).then_some(placeholder)
            size=size
            prop:value=move || value.get()
            on:input=on_event(move |ev| value.set(event_target_value(&ev)))
        />
    }
    .into_any()
}

/// A paragraph showing `text`, empty while it is `None`; `id` and `class`
/// may be empty.
#[inline(never)]
pub fn note(id: &'static str, class: &'static str, text: RwSignal<Option<String>>) -> AnyView {
    view! {
        <p id=(!id.is_empty()).then_some(id) class=(!class.is_empty()).then_some(class)>
            {move || text.get().unwrap_or_default()}
        </p>
    }
    .into_any()
}

/// `text` for HTML: `&`, `<`, `>` and `"` escaped (a payload may hold
/// anything).
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

/// The rows of a table of text cells as HTML: `classes` gives each
/// column's cell class; a row's first cell is also its `data-key`.
pub fn rows_html(classes: &[&str], rows: &[Vec<String>]) -> String {
    let mut html = String::new();
    for cells in rows {
        let key = escape(cells.first().map_or("", |c| c));
        html.push_str(&format!("<tr data-key=\"{key}\">"));
        for (text, class) in cells.iter().zip(classes) {
            html.push_str(&format!("<td class=\"{class}\">{}</td>", escape(text)));
        }
        html.push_str("</tr>");
    }
    html
}

/// A table of text cells, redrawn from `rows`: `columns` gives each
/// column's heading and the class of its cells; a row's first cell is
/// also its `data-key` (for finding it). Its body is written as HTML in
/// one go: a table of text needs no element code of its own (each table
/// written as a `view!` of rows costs the console's wasm a copy of it).
#[inline(never)]
pub fn text_table(
    id: &'static str,
    columns: &'static [(&'static str, &'static str)],
    rows: Box<dyn Fn() -> Vec<Vec<String>> + Send + Sync>,
) -> AnyView {
    let classes: Vec<&str> = columns.iter().map(|(_, c)| *c).collect();
    view! {
        <table class="log" id=id>
            <thead><tr>{columns.iter().map(|(h, _)| view! { <th>{*h}</th> }).collect_view()}</tr></thead>
            <tbody inner_html=move || rows_html(&classes, &rows())></tbody>
        </table>
    }
    .into_any()
}

/// A `change` or `input` handler, boxed: tachys's event code is generic
/// over the handler's type, so every `on:change=on_event(..)` of the page
/// shares one instance of it instead of one per closure.
pub fn on_event(f: impl FnMut(web_sys::Event) + 'static) -> Box<dyn FnMut(web_sys::Event)> {
    Box::new(f)
}

/// A `click` handler, boxed (as [`on_event`]).
pub fn on_click(
    f: impl FnMut(web_sys::MouseEvent) + 'static,
) -> Box<dyn FnMut(web_sys::MouseEvent)> {
    Box::new(f)
}

/// A new signal holding `value`: `RwSignal::new` not inlined, so each
/// signal of the page costs a call rather than its own copy of the
/// arena's insertion code (one instance per value type).
#[inline(never)]
pub fn signal<T: Send + Sync + 'static>(value: T) -> RwSignal<T> {
    RwSignal::new(value)
}

/// A `change` or `input` handler keeping the target's value in `value`
/// (a select, an input): one closure for every such form control.
pub fn set_value(value: RwSignal<String>) -> Box<dyn FnMut(web_sys::Event)> {
    Box::new(move |ev| value.set(event_target_value(&ev)))
}

/// A `change` handler keeping a checkbox's state in `value`.
pub fn set_checked(value: RwSignal<bool>) -> Box<dyn FnMut(web_sys::Event)> {
    Box::new(move |ev| value.set(event_target_checked(&ev)))
}

/// HTML from `html()`, redrawn whenever what it reads changes, in a
/// `<span style="display: contents">` (no box of its own: what it holds
/// is laid out as the parent's own children). One render effect's code
/// for every such part of the page, each only a boxed closure.
#[inline(never)]
// The closure, not the box: the bindings' code is instantiated for it.
#[allow(clippy::redundant_closure)]
pub fn html(html: Box<dyn Fn() -> String + Send + Sync>) -> AnyView {
    view! { <span style="display: contents" inner_html=move || html()></span> }.into_any()
}

/// A text redrawn from `text()` (as [`html`], one render effect's code
/// for all).
#[inline(never)]
pub fn text(text: Box<dyn Fn() -> String + Send + Sync>) -> AnyView {
    (move || text()).into_any()
}

/// An `<option>` as HTML, appended to `html`.
pub fn option_html(html: &mut String, value: &str, label: &str, selected: bool) {
    html.push_str(&format!(
        "<option value=\"{}\"{}>{}</option>",
        escape(value),
        if selected { " selected" } else { "" },
        escape(label)
    ));
}

/// A `<select>` whose options are the HTML of `options()` (see
/// [`option_html`]), redrawn as it changes; `on` gets the value chosen.
#[inline(never)]
// The closure, not the box: the bindings' code is instantiated for it.
#[allow(clippy::redundant_closure)]
pub fn select(
    id: &'static str,
    options: Box<dyn Fn() -> String + Send + Sync>,
    on: Box<dyn Fn(String)>,
) -> AnyView {
    view! {
        <select id=id inner_html=move || options() on:change=on_event(move |ev| on(event_target_value(&ev)))></select>
    }
    .into_any()
}

/// A button whose label and `disabled` follow `label()` and `disabled()`.
#[inline(never)]
// The closure, not the box: the bindings' code is instantiated for it.
#[allow(clippy::redundant_closure)]
pub fn live_button(
    id: &'static str,
    label: Box<dyn Fn() -> String + Send + Sync>,
    disabled: Box<dyn Fn() -> bool + Send + Sync>,
    on: Box<dyn Fn()>,
) -> AnyView {
    view! {
        <button id=id disabled=move || disabled() on:click=on_click(move |_| on())>
            {move || label()}
        </button>
    }
    .into_any()
}

/// A checkbox checked as `checked()` says; `on` gets its new state.
#[inline(never)]
// The closure, not the box: the bindings' code is instantiated for it.
#[allow(clippy::redundant_closure)]
pub fn checkbox(
    id: &'static str,
    checked: Box<dyn Fn() -> bool + Send + Sync>,
    on: Box<dyn Fn(bool)>,
) -> AnyView {
    view! {
        <input
            type="checkbox"
            id=id
            prop:checked=move || checked()
            on:change=on_event(move |ev| on(event_target_checked(&ev)))
        />
    }
    .into_any()
}

/// The element an event happened in, or its nearest ancestor matching
/// `selector`: what a listener delegated to a container (a table of HTML
/// rows, a card's HTML buttons) acts on.
pub fn closest(ev: &web_sys::Event, selector: &str) -> Option<web_sys::Element> {
    use wasm_bindgen::JsCast;
    ev.target()?
        .dyn_into::<web_sys::Element>()
        .ok()?
        .closest(selector)
        .ok()?
}

/// Draws the rows of the long table `table_id` that are in view
/// ([`crate::long_table::window`] of `total` rows, scrolled to `top_px`
/// or following the newest): `rows` writes each as HTML with its key
/// ([`patch_keyed`]), and the table's margins keep the room of the
/// others. `drawn` is what the body held; returns what it holds now. The
/// table's `data-rows` says how many rows it has in all.
pub fn draw_rows(
    table_id: &str,
    total: usize,
    top_px: u32,
    follow: bool,
    rows: &mut dyn FnMut(std::ops::Range<usize>) -> Vec<(u64, String)>,
    drawn: Option<Vec<(u64, String)>>,
) -> Vec<(u64, String)> {
    use crate::long_table::ROW_PX;
    // The table's height at most (style.css `.table-wrap`: 100vh - 190px).
    let page_px = window().inner_height().ok().and_then(|h| h.as_f64());
    let view_px = (page_px.unwrap_or(900.0) - 190.0).max(220.0) as u32;
    let w = crate::long_table::window(total, top_px, view_px, follow);
    let (above, below) = (w.start as u32, (total - w.end) as u32);
    let now = rows(w);
    let doc = document();
    if let (Some(table), Ok(Some(body))) = (
        doc.get_element_by_id(table_id),
        doc.query_selector(&format!("#{table_id} tbody")),
    ) {
        let margin = format!("margin: {}px 0 {}px", above * ROW_PX, below * ROW_PX);
        let _ = table.set_attribute("style", &margin);
        let _ = table.set_attribute("data-rows", &total.to_string());
        patch_keyed(&body, drawn.as_deref().unwrap_or_default(), &now);
    }
    now
}

/// Brings `parent`'s children, written as `drawn` (one element's HTML
/// each, with its key), to `now`: an element whose key stays and whose
/// HTML is the same is left alone, one whose HTML changed is written
/// again, the new ones are written in their place and the others removed.
/// A reading of one lamp of 500, or a lamp found among the rows shown,
/// is one or two elements to parse and lay out, not all of them; when
/// most are new (a scroll, a sort) they are written all at once.
pub fn patch_keyed(parent: &web_sys::Element, drawn: &[(u64, String)], now: &[(u64, String)]) {
    let shown = |key: u64| now.iter().any(|(k, _)| *k == key);
    let kept = drawn.iter().filter(|(k, _)| shown(*k)).count();
    if parent.child_element_count() as usize != drawn.len() || kept * 2 < now.len() {
        parent.set_inner_html(&now.iter().map(|(_, h)| h.as_str()).collect::<String>());
        return;
    }
    let mut old = drawn.iter().peekable();
    let mut at = parent.first_element_child();
    for (key, html) in now {
        // The drawn elements no longer shown, before this one, go.
        while let (Some((k, _)), Some(el)) = (old.peek(), at.clone()) {
            if *k == *key || shown(*k) {
                break;
            }
            at = el.next_element_sibling();
            el.remove();
            old.next();
        }
        match (old.peek(), at.clone()) {
            (Some((k, was)), Some(el)) if k == key => {
                at = el.next_element_sibling();
                if was != html {
                    el.set_outer_html(html);
                }
                old.next();
            }
            (_, Some(el)) => {
                let _ = el.insert_adjacent_html("beforebegin", html);
            }
            (_, None) => {
                let _ = parent.insert_adjacent_html("beforeend", html);
            }
        }
    }
    // What is left was drawn and is not shown any more.
    while let Some(el) = at {
        at = el.next_element_sibling();
        el.remove();
    }
}

/// Where the scrolling box of a long table (`wrap`, a selector) that `ev`
/// happened in is scrolled (CSS px), and whether to its end.
pub fn scrolled(ev: &web_sys::Event, wrap: &str) -> Option<(u32, bool)> {
    let wrap = closest(ev, wrap)?;
    // web-sys has scrollTop as an f64 for wasm32, an i32 natively.
    #[allow(clippy::useless_conversion)]
    let at = f64::from(wrap.scroll_top()).max(0.0) as u32;
    let half_row = crate::long_table::ROW_PX as i32 / 2;
    let end = at as i32 + wrap.client_height() + half_row >= wrap.scroll_height();
    Some((at, end))
}
