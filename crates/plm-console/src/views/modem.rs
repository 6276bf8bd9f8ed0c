//! The Modem view: every MIB object of the chip connected (ST7580 or
//! ST7570), rendered from plm-core's declarative description. No object
//! has a hand-written form: the rows, inputs, ranges, enums, access and
//! defaults all come from the chip's MIB (`plm_core::chip::Chip::mib`),
//! a value is checked by `crate::mibform` (plm-core's `Field::check` and
//! `Object::check_value`) before anything is sent, and the requests are
//! the chip's own (`Console::read_mib` and friends).

use super::files;
use super::widgets::{button, escape, on_click, on_event, signal};
use crate::mibform;
use crate::stores::use_console;
use leptos::prelude::*;
use plm_core::field::Kind;
use plm_core::file::profile;
use plm_core::link::Dialect;
use plm_core::mib::Object;
use plm_core::st7580::mib::index;
use std::rc::Rc;

type Inputs = mibform::Texts;

fn inputs_of(object: &'static Object, data: &[u8]) -> Inputs {
    mibform::editable(object)
        .map(|f| (f.name, mibform::input_text(f, data)))
        .collect()
}

/// The view.
#[component]
pub fn ModemView() -> impl IntoView {
    let c = use_console();
    let progress = signal(None::<String>);
    // The chip (ST7570 or not), its objects redrawn when it changes: a
    // memo of a type the page has anyway.
    let st7570 = Memo::new(move |_| c.profile.get().dialect() == Dialect::St7570);
    let read_all = move || {
        // What the modem has as configured now (an ST7570 in PHY mode
        // has no MAC objects).
        let readable: Vec<u16> = c.with_chip(|ch| {
            ch.mib()
                .iter()
                .filter(|o| o.access.read && ch.has(o))
                .map(|o| o.index)
                .collect()
        });
        let total = readable.len();
        let done = signal(0usize);
        let failed = signal(0usize);
        progress.set(Some(format!("Reading 0 of {total}…")));
        for i in readable {
            c.read_mib(i, move |r| {
                if r.is_err() {
                    failed.update(|f| *f += 1);
                }
                done.update(|d| *d += 1);
                let (d, f) = (done.get_untracked(), failed.get_untracked());
                progress.set(Some(if d < total {
                    format!("Reading {d} of {total}…")
                } else if f == 0 {
                    format!("Read all {total} objects.")
                } else {
                    format!(
                        "Read {} of {total} objects; {f} failed (see each object).",
                        d - f
                    )
                }));
            });
        }
    };
    view! {
        <div class="toolbar">
            {button("mib-read-all", "Read all", "", read_all)}
            <span class="muted" id="mib-progress">{move || progress.get().unwrap_or_default()}</span>
            <Profiles/>
            <span class="muted">
                {move || String::from(if st7570.get() {
                    "ST7570 MIB (ST7570 UM 6, Table 71)."
                } else {
                    "ST7580 MIB (UM0932 4, Table 52)."
                })}
                " Values are checked as the modem checks them before anything is sent."
            </span>
        </div>
        <div class="cards" hidden=move || !st7570.get()>
            <super::sfsk_setup::SetupCard/>
        </div>
        <div class="mib-list">
            {move || {
                let dialect = if st7570.get() { Dialect::St7570 } else { Dialect::St7580 };
                plm_core::chip::for_dialect(dialect).mib().iter()
                    .map(|o| view! { <MibCard object=o dialect=dialect/> })
                    .map(IntoAny::into_any)
                    .collect_view()
            }}
        </div>
    }
}

/// Profiles: the writable objects' values saved to a JSON file, and loaded
/// back, checked, then written as a batch with progress and cancel.
#[component]
fn Profiles() -> impl IntoView {
    let c = use_console();
    let message = signal(None::<String>);
    let running = signal(false);
    let cancel = signal(false);
    let save = move || {
        let values = c.modem.mib.get_untracked();
        let writable: Vec<u16> = c.with_chip(|ch| profile::objects(ch).map(|o| o.index).collect());
        let have = writable.iter().filter(|i| values.contains_key(i)).count();
        if have == 0 {
            message.set(Some(
                "Nothing to save yet: read the objects first (Read all).".into(),
            ));
            return;
        }
        let text = c.with_chip(|ch| profile::to_json(ch, |i| values.get(&i).map(|v| &v[..])));
        message.set(Some(
            match files::download("plm-profile.json", "application/json", &text) {
                Ok(()) if have == writable.len() => {
                    format!("Saved the {have} writable objects to plm-profile.json.")
                }
                Ok(()) => format!(
                    "Saved {have} of {} writable objects (read the others to include them).",
                    writable.len()
                ),
                Err(e) => e,
            },
        ));
    };
    let load = move |ev: leptos::ev::Event| {
        let Some(file) = files::chosen_file(&ev) else {
            return;
        };
        leptos::task::spawn_local(async move {
            let name = file.name();
            let list = match files::read_text(&file)
                .await
                .and_then(|t| c.with_chip(|ch| profile::parse(ch, &t)))
            {
                Ok(list) => list,
                Err(e) => {
                    message.set(Some(format!("Nothing written from {name}: {e}.")));
                    return;
                }
            };
            cancel.set(false);
            running.set(true);
            apply_profile(c, Rc::new(list), 0, message, running, cancel);
        });
    };
    view! {
        {button("profile-save", "Save profile", "", save)}
        <label class="button">
            "Load profile…"
            <input id="profile-load" type="file" accept=".json,application/json" on:change=on_event(load)/>
        </label>
        {move || (running.get()).then(|| view! {
            {button("profile-cancel", "Cancel", "", move || cancel.set(true))}
        }).map(IntoAny::into_any)}
        <span class="muted" id="profile-message">{move || message.get().unwrap_or_default()}</span>
    }
}

/// Writes object `i` of a loaded profile, then the next, reading each one
/// back into the store; stops at the first refusal or on cancel.
fn apply_profile(
    c: crate::stores::Console,
    list: Rc<Vec<(u16, Vec<u8>)>>,
    i: usize,
    message: RwSignal<Option<String>>,
    running: RwSignal<bool>,
    cancel: RwSignal<bool>,
) {
    let n = list.len();
    if cancel.get_untracked() {
        running.set(false);
        message.set(Some(format!("Cancelled after {i} of {n} objects.")));
        return;
    }
    let Some((index, data)) = list.get(i).cloned() else {
        running.set(false);
        message.set(Some(format!(
            "Profile applied: {n} objects written and read back."
        )));
        return;
    };
    let at = c.with_chip(|ch| profile::index_text(ch.dialect(), index));
    message.set(Some(format!("Writing {} of {n} ({at}h)…", i + 1)));
    c.write_mib(index, data, move |r| match r {
        Ok(_) => c.read_mib(index, move |_| {
            apply_profile(c, list, i + 1, message, running, cancel)
        }),
        Err(why) => {
            running.set(false);
            message.set(Some(format!(
                "Stopped at object {at}h ({} of {n}): {why}",
                i + 1
            )));
        }
    });
}

/// One MIB object: its fields, read, write, erase and factory default.
#[component]
fn MibCard(object: &'static Object, dialect: Dialect) -> impl IntoView {
    let c = use_console();
    let idx = object.index;
    let secret = dialect == Dialect::St7580 && idx == index::SS_KEY as u16;
    // The value last read, untracked: the effect below redraws the form
    // (through `inputs`) when it changes (no memo type of its own).
    let read_value = move || c.modem.mib.with_untracked(|m| m.get(&idx).cloned());
    let inputs = signal(inputs_of(object, object.default));
    const NOT_READ: &str = "not read yet: the form shows the factory default";
    let status = signal(String::from(NOT_READ));
    Effect::new(move |last: Option<Option<Vec<u8>>>| {
        let value = c.modem.mib.with(|m| m.get(&idx).cloned());
        if last.as_ref() != Some(&value) {
            match &value {
                Some(v) => {
                    inputs.set(inputs_of(object, v));
                    // Read elsewhere (Read all, a profile, the set-up
                    // card): say so instead of "not read yet".
                    if status.with_untracked(|s| s == NOT_READ) {
                        status.set("read from the modem".into());
                    }
                }
                // Forgotten (a new connection): the form redrawn as such.
                None => inputs.update(|_| {}),
            }
        }
        value
    });
    // Why the form was refused, by field name; the object's own reason
    // under "" (a signal of the inputs' type: no signal type of its own).
    let problems = signal(Inputs::default());
    let reveal = signal(false);
    let base = move || read_value().unwrap_or_else(|| object.default.to_vec());

    let read = move || {
        status.set("reading…".into());
        c.read_mib(idx, move |r| {
            status.set(match r {
                Ok(_) => "read from the modem".into(),
                Err(e) => format!("not read: {e}"),
            })
        });
    };
    let write = move || {
        let data = match mibform::build(object, &base(), &inputs.get_untracked()) {
            Ok(d) => d,
            Err(p) => {
                let n = p.fields.len();
                status.set(match &p.object {
                    Some(why) => format!("nothing sent: {why}"),
                    None => format!("nothing sent: {n} field(s) need fixing (see the reasons)"),
                });
                let mut why = p.fields;
                if let Some(o) = p.object {
                    why.insert("", o);
                }
                problems.set(why);
                return;
            }
        };
        problems.set(Inputs::default());
        status.set("writing…".into());
        let sent = data.clone();
        c.write_mib(idx, mibform::write_data(object, &data), move |r| match r {
            Ok(_) if !object.access.read => {
                status.set("written (the object cannot be read back)".into())
            }
            Ok(_) => {
                status.set("written; reading back…".into());
                c.read_mib(idx, move |r| {
                    status.set(match r {
                        Ok(v) if v == sent => "written and read back: the modem has it".into(),
                        Ok(_) => "written, but the modem reads back another value".into(),
                        Err(e) => format!("written, but not read back: {e}"),
                    })
                });
            }
            Err(why) => status.set(format!("not written: {why}")),
        });
    };
    let erase = move || {
        status.set("erasing…".into());
        c.erase_mib(idx, move |r| match r {
            Ok(_) => {
                status.set("erased; reading back…".into());
                c.read_mib(idx, move |r| {
                    status.set(match r {
                        Ok(_) => "erased and read back".into(),
                        Err(e) => format!("erased, but not read back: {e}"),
                    })
                });
            }
            Err(why) => status.set(format!("not erased: {why}")),
        });
    };
    let load_default = move || {
        inputs.set(inputs_of(object, object.default));
        problems.set(Inputs::default());
        status.set("factory default loaded into the form: Write to send it".into());
    };
    view! {
        <article class="card mib" id=format!("mib-{}", profile::index_text(dialect, idx).to_ascii_lowercase())>
            <header inner_html=header_html(object, dialect)></header>
            // The actions as HTML, their clicks handled by one listener
            // by the `data-action` clicked.
            <div
                class="actions"
                inner_html=actions_html(object, secret)
                on:click=on_click(move |ev| match action_of(&ev).as_str() {
                    "read" => read(),
                    "write" => write(),
                    "default" => load_default(),
                    "erase" => erase(),
                    "reveal" => reveal.set(event_target_checked(&ev)),
                    _ => {}
                })
            ></div>
            // Status, the form and what differs, written as HTML in one go;
            // what is typed goes to `inputs` untracked (the form is not
            // rewritten under the typing), read back by the delegated
            // listener from the input's `name`.
            <div
                inner_html=move || {
                    card_html(
                        object,
                        &status.get(),
                        &problems.get(),
                        read_value().as_deref(),
                        &inputs.get(),
                        secret && !reveal.get(),
                    )
                }
                on:input=on_event(move |ev| typed(object, inputs, &ev))
            ></div>
        </article>
    }
}

/// A card's heading: index, name, access and where the manual has it.
fn header_html(object: &'static Object, dialect: Dialect) -> String {
    format!(
        "<h3><span class=\"index\">{}h</span> {}</h3><span class=\"access\" title=\"Access\">{}</span><span class=\"muted\">{}</span>",
        profile::index_text(dialect, object.index),
        escape(object.name),
        escape(object.access.label()),
        escape(object.section)
    )
}

/// A card's buttons, by what the object allows, and the key's Reveal.
fn actions_html(object: &'static Object, secret: bool) -> String {
    let a = &object.access;
    let mut h = String::new();
    for (on, action, label) in [
        (a.read, "read", "Read"),
        (a.write, "write", "Write"),
        (a.write, "default", "Factory default"),
        (a.erase, "erase", "Erase"),
    ] {
        if on {
            h.push_str(&format!(
                "<button data-action=\"{action}\">{label}</button>"
            ));
        }
    }
    if secret {
        h.push_str("<label class=\"reveal\"><input type=\"checkbox\" data-action=\"reveal\"> Reveal key</label>");
    }
    h
}

/// The `data-action` of what a click was on (a button, the Reveal box).
fn action_of(ev: &web_sys::MouseEvent) -> String {
    super::widgets::closest(ev, "[data-action]")
        .and_then(|e| e.get_attribute("data-action"))
        .unwrap_or_default()
}

/// What is typed into a field's input (found by its `name`), into
/// `inputs` without redrawing the form.
fn typed(object: &'static Object, inputs: RwSignal<Inputs>, ev: &web_sys::Event) {
    let name = super::widgets::closest(ev, "[name]")
        .and_then(|e| e.get_attribute("name"))
        .unwrap_or_default();
    let Some(field) = object.fields.iter().find(|f| f.name == name) else {
        return;
    };
    let text = match field.kind {
        Kind::Flag => String::from(if event_target_checked(ev) { "1" } else { "0" }),
        _ => event_target_value(ev),
    };
    inputs.update_untracked(|m| m.insert(field.name, text));
}

/// A card's status, refusal, fields table and differences from the
/// factory default, as HTML: one row per field with its label, input (or
/// value), what is allowed, the factory default, and why the form refused
/// it. `read` is the value last read, `masked` hides the key's values.
fn card_html(
    object: &'static Object,
    status: &str,
    problems: &Inputs,
    read: Option<&[u8]>,
    inputs: &Inputs,
    masked: bool,
) -> String {
    use std::fmt::Write;
    let secret = |text: String| {
        if masked {
            "••••••••".to_string()
        } else {
            escape(&text)
        }
    };
    let current = read.unwrap_or(object.default);
    let mut h = format!(
        "<p class=\"status\" data-role=\"status\">{}</p>",
        escape(status)
    );
    if let Some(o) = problems.get("") {
        let _ = write!(h, "<p class=\"problem\">{}</p>", escape(o));
    }
    h.push_str("<table class=\"fields\"><thead><tr><th>Field</th><th>Value</th><th>Allowed</th><th>Factory default</th><th></th></tr></thead><tbody>");
    for field in object.fields {
        let name = field.name;
        let editable = object.access.write && field.settable;
        // Reserved and unused bits are shown only when they are not zero.
        let visible = field.settable || field.get(current).is_some_and(|v| v != 0);
        let differs = read.is_some_and(|v| field.read(v) != field.read(object.default));
        let invalid = problems.get(name);
        // An input takes the raw number; a value shown reads in its unit
        // (S0 in dBµV).
        let unit = if editable {
            field.unit
        } else {
            field.shown_unit()
        };
        let _ = write!(
            h,
            "<tr data-field=\"{name}\" class=\"{}{}\"{}><th>{}{}</th><td>",
            if differs { "differs " } else { "" },
            if invalid.is_some() { "invalid" } else { "" },
            if visible { "" } else { " hidden" },
            escape(field.label),
            match unit {
                "" => String::new(),
                unit => escape(&format!(" ({unit})")),
            },
        );
        let value = escape(&inputs.get(name).cloned().unwrap_or_default());
        match field.kind {
            _ if !editable => {
                let _ = write!(
                    h,
                    "<span class=\"value\">{}</span>",
                    secret(mibform::show(field, current))
                );
            }
            Kind::Enum(names) => {
                let _ = write!(h, "<select name=\"{name}\">");
                for (i, n) in names.iter().enumerate() {
                    if !n.is_empty() && *n != "Reserved" {
                        let i = i.to_string();
                        let _ = write!(
                            h,
                            "<option value=\"{i}\"{}>{}</option>",
                            if value == i { " selected" } else { "" },
                            escape(n)
                        );
                    }
                }
                h.push_str("</select>");
            }
            Kind::Flag => {
                let _ = write!(
                    h,
                    "<input type=\"checkbox\" name=\"{name}\"{}>",
                    if value == "1" { " checked" } else { "" }
                );
            }
            Kind::Bytes => {
                let _ = write!(
                    h,
                    "<input type=\"{}\" class=\"hex\" name=\"{name}\" autocomplete=\"off\" spellcheck=\"false\" size=\"34\" value=\"{value}\">",
                    if masked { "password" } else { "text" }
                );
            }
            _ => {
                let _ = write!(
                    h,
                    "<input type=\"text\" inputmode=\"numeric\" name=\"{name}\" size=\"10\" value=\"{value}\">"
                );
            }
        }
        let allowed = match field.kind {
            Kind::Bytes => format!("{} bytes, hex", field.size),
            Kind::Flag => "yes / no".to_string(),
            // The select lists the choices.
            Kind::Enum(_) if editable => String::new(),
            _ => field.allowed(),
        };
        let _ = write!(
            h,
            "</td><td class=\"muted\">{}</td><td class=\"muted\">{}</td><td class=\"problem\" data-role=\"problem\">{}</td></tr>",
            escape(&allowed),
            secret(mibform::show(field, object.default)),
            escape(invalid.map_or("", |s| s))
        );
    }
    h.push_str("</tbody></table><p class=\"diff\" data-role=\"diff\">");
    if let Some(v) = read {
        let d = mibform::differences(object, v, object.default);
        if d.is_empty() {
            h.push_str("equal to the factory default");
        } else {
            let names: Vec<_> = d.iter().map(|f| f.label).collect();
            let _ = write!(
                h,
                "{} field(s) differ from the factory default: {}",
                d.len(),
                escape(&names.join(", "))
            );
        }
    }
    h.push_str("</p>");
    h
}
