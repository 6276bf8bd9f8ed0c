//! Diagnostics: ping with round-trip time, the live status message bits,
//! the host's ACK latency, firmware version, reset with the last reset
//! cause, and the counters of MIB 06h-08h with erase.

use super::widgets::{
    action_button, button, checkbox, escape, html, note, on_click, signal, text, text_input,
};
use super::{millis, seconds, spaced};
use crate::driver::ack::ACK_SAMPLES;
use crate::session::Outcome;
use crate::stores::{refusal, unstamped, use_console};
use leptos::prelude::*;
use plm_core::field::Field;
use plm_core::st7580::fields::{reset_data, status};
use plm_core::st7580::mib::{index, object};
use plm_core::st7580::Command;
use plm_core::time::MS;

/// The view.
#[component]
pub fn DiagnosticsView() -> impl IntoView {
    view! {
        <div class="cards">
            <PingCard/>
            <StatusCard/>
            <AckLatencyCard/>
            <FirmwareCard/>
            <ResetCard/>
            <CountersCard/>
        </div>
    }
}

/// Named values of `data` under `layout`, as the HTML rows of a table.
pub(crate) fn fields_html(layout: &'static [Field], data: &[u8]) -> String {
    plm_core::mib::describe(layout, data)
        .into_iter()
        .fold(String::new(), |mut html, (f, v)| {
            html.push_str(&format!(
                "<tr data-field=\"{}\"><th>{}</th><td>{}</td></tr>",
                f.name,
                escape(f.label),
                escape(&f.show(&v))
            ));
            html
        })
}

/// Named values of `data` under `layout` as the HTML of a table (`id`
/// may be empty).
fn table_html(id: &str, layout: &'static [Field], data: &[u8]) -> String {
    let id = if id.is_empty() {
        String::new()
    } else {
        format!(" id=\"{id}\"")
    };
    format!(
        "<table class=\"kv\"{id}>{}</table>",
        fields_html(layout, data)
    )
}

#[component]
fn PingCard() -> impl IntoView {
    let c = use_console();
    let payload = signal(String::from("50 4c 4d 21"));
    // What came of it, and whether that is a problem: two signals of types
    // the page has anyway rather than one `Option<Result<String, String>>`
    // (each signal type brings its own code, docs/console.md "Size").
    let result = signal(None::<String>);
    let problem = signal(false);
    let show = move |r: Result<String, String>| {
        problem.set(r.is_err());
        result.set(Some(r.unwrap_or_else(|e| e)));
    };
    // The last round trips, as written (a signal type the page has).
    let history = signal(Vec::<String>::new());
    let ping = move || {
        let data = match plm_core::hex::parse(&payload.get_untracked()) {
            Ok(d) if d.len() <= 255 => d,
            Ok(d) => {
                show(Err(format!(
                    "nothing sent: a frame carries at most 255 bytes, not {}",
                    d.len()
                )));
                return;
            }
            Err(e) => {
                show(Err(format!("nothing sent: {e}")));
                return;
            }
        };
        show(Ok("sent, waiting for the answer…".into()));
        let sent = data.clone();
        c.request(Command::PingRequest { data }, move |o| {
            show(match o {
                Outcome::Answer {
                    command: Command::PingConfirm { data },
                    rtt,
                } => {
                    history.update(|h| {
                        h.push(millis(rtt));
                        if h.len() > 10 {
                            h.remove(0);
                        }
                    });
                    let same = if data == sent {
                        "payload echoed intact"
                    } else {
                        "payload differs from the one sent!"
                    };
                    Ok(format!(
                        "PingConfirm in {} ({same}): {}",
                        millis(rtt),
                        spaced(&plm_core::hex::encode(&data))
                    ))
                }
                Outcome::Answer { command, .. } => {
                    Err(refusal(&command).unwrap_or_else(|| crate::stores::unexpected(&command)))
                }
                Outcome::Failed(why) => Err(why),
            })
        });
    };
    view! {
        <article class="card" id="ping">
            <h3>"Ping"</h3>
            <p class="muted">"PingRequest (2Ch): the modem sends the payload back (UM0932 3.3.10)."</p>
            <label>
                "Payload (hex) "
                {text_input("ping-payload", "hex", "", Some(30), payload)}
            </label>
            {button("ping-send", "Ping", "", ping)}
            {html(Box::new(move || {
                let history = history.with(|h| {
                    if h.is_empty() {
                        String::new()
                    } else {
                        format!("Last round trips: {}", h.join(", "))
                    }
                });
                format!(
                    "<p id=\"ping-result\"{}>{}</p><p class=\"muted\" id=\"ping-history\">{history}</p>",
                    if problem.get() { " class=\"problem\"" } else { "" },
                    escape(&result.get().unwrap_or_default())
                )
            }))}
        </article>
    }
}

#[component]
fn StatusCard() -> impl IntoView {
    let c = use_console();
    let html_of = move || match c.modem.status.get().map(unstamped) {
        None => "<p class=\"muted\">No status message yet: send any request.</p>".to_string(),
        Some((at, b)) => format!(
            "<p>3F {b:02X}, received at {}</p>{}",
            seconds(at),
            table_html("", status::LAYOUT, &[b])
        ),
    };
    view! {
        <article class="card" id="status">
            <h3>"Status message"</h3>
            <p class="muted">
                "The bits of the last status message (UM0932 Table 8); the modem sends one each time the host asks to send."
            </p>
            {html(Box::new(html_of))}
        </article>
    }
}

/// The host's ACK latency (UM0932 3.2.8: within T_ACK of a frame's end).
#[component]
fn AckLatencyCard() -> impl IntoView {
    let c = use_console();
    // Written again when traffic comes: every ACK goes to the traffic log.
    let html_of = move || {
        c.traffic.log.track();
        c.conn.port.track();
        let l = c.ack_latency();
        if l.count == 0 {
            return "<p class=\"muted\" id=\"ack-latency-value\">No frame from the modem yet.</p>"
                .to_string();
        }
        let t_ack = c.conn.timeouts.get().t_ack;
        let p = l.page;
        let frames = if l.count as usize > ACK_SAMPLES {
            format!(
                "Over the last {ACK_SAMPLES} of {} frames ACKed since connecting.",
                l.count
            )
        } else {
            format!("{} frame(s) ACKed since connecting.", l.count)
        };
        let link = if c.conn.kind.get() == "Simulated" {
            format!(
                "The simulated modem's virtual time waits for the page, so it saw p99 {} (max {}).",
                millis(l.link.p99),
                millis(l.link.max)
            )
        } else {
            String::new()
        };
        format!(
            "<p id=\"ack-latency-value\"{}>ACK latency p50 {}, p99 {}, max {} (T_ACK {} ms)</p><p class=\"muted\">{frames} {link}</p>",
            if p.max > t_ack { " class=\"problem\"" } else { "" },
            millis(p.p50),
            millis(p.p99),
            millis(p.max),
            t_ack / MS
        )
    };
    view! {
        <article class="card" id="ack-latency">
            <h3>"ACK latency"</h3>
            <p class="muted">
                "From the last byte of each modem frame to the host's ACK (UM0932 3.2.8), on the page's clock: it includes how late the page woke and any stall of the page."
            </p>
            {html(Box::new(html_of))}
        </article>
    }
}

#[component]
fn FirmwareCard() -> impl IntoView {
    let c = use_console();
    let message = signal(None::<String>);
    let value = move || {
        c.modem
            .mib
            .with(|m| m.get(&(index::FIRMWARE_VERSION as u16)).cloned())
    };
    view! {
        <article class="card" id="firmware">
            <h3>"Firmware version"</h3>
            <p class="muted">"MIB 0Ah (UM0932 4.2.10)."</p>
            {button("firmware-read", "Read", "", move || {
                message.set(Some("reading…".into()));
                c.read_mib(index::FIRMWARE_VERSION as u16, move |r| message.set(r.err()));
            })}
            <p id="firmware-value" class="big">
                {text(Box::new(move || value().map_or(String::new(), |v| format!("{}h", plm_core::hex::encode(&v).to_ascii_uppercase()))))}
            </p>
            {note("", "problem", message)}
        </article>
    }
}

#[component]
fn ResetCard() -> impl IntoView {
    let c = use_console();
    let message = signal(None::<String>);
    let reset = move || {
        message.set(Some("BIO_ResetRequest sent…".into()));
        c.request(Command::BioResetRequest, move |o| {
            message.set(Some(match o {
                Outcome::Answer {
                    command: Command::BioResetConfirm { .. },
                    ..
                } => {
                    "BIO_ResetConfirm: the modem restarts; its BIO_ResetIndication follows.".into()
                }
                Outcome::Answer { command, .. } => {
                    refusal(&command).unwrap_or_else(|| "unexpected answer".into())
                }
                Outcome::Failed(why) => why,
            }))
        });
    };
    view! {
        <article class="card" id="reset">
            <h3>"Reset"</h3>
            <p class="muted">
                "BIO_ResetRequest (3Ch) restarts the modem; MIB 00h-02h survive if written since power-on (UM0932 3.3.1)."
            </p>
            {button("reset-send", "Reset modem", "", reset)}
            <label
                title="DTR drives the modem's RESETN on this port (kept per port): DTR is kept released"
            >
                {checkbox("resetn-on-dtr", Box::new(move || c.conn.resetn_on_dtr.get()), Box::new(move |on| c.set_resetn_on_dtr(on)))}
                " RESETN wired to DTR"
            </label>
            <button
                id="reset-resetn"
                hidden=move || !c.conn.resetn_on_dtr.get()
                title="DTR asserted 20 ms: a hardware reset"
                on:click=on_click(move |_| {
                    c.pulse_resetn();
                    message.set(Some("RESETN pulsed: BIO_ResetIndication follows.".into()));
                })
            >
                "Reset modem (RESETN)"
            </button>
            {note("reset-result", "", message)}
            <h4>"Last BIO_ResetIndication"</h4>
            {html(Box::new(move || match c.modem.last_reset.get().map(unstamped) {
                None => "<p class=\"muted\">None since connecting.</p>".to_string(),
                Some((at, byte)) => format!(
                    "<p>ResetData {byte:02X}h at {}</p>{}",
                    seconds(at),
                    table_html("reset-cause", reset_data::LAYOUT, &[byte])
                ),
            }))}
        </article>
    }
}

#[component]
fn CountersCard() -> impl IntoView {
    view! {
        <article class="card wide" id="counters">
            <h3>"Counters"</h3>
            <p class="muted">"MIB 06h-08h (UM0932 Tables 58-60): 16-bit, wrapping; erase sets them to 0."</p>
            <div class="counter-grid">
                {[index::PHY_DATA, index::DL_DATA, index::SS_DATA]
                    .into_iter()
                    .map(|i| view! { <Counters index=i/> })
                    .map(IntoAny::into_any).collect_view()}
            </div>
        </article>
    }
}

#[component]
fn Counters(index: u8) -> impl IntoView {
    let c = use_console();
    let o = object(index).expect("06h-08h are in Table 52");
    let message = signal(None::<String>);
    let value = move || c.modem.mib.with(|m| m.get(&(index as u16)).cloned());
    let read = move || {
        c.read_mib(index as u16, move |r| message.set(r.err()));
    };
    let erase = move || {
        c.erase_mib(index as u16, move |r| match r {
            Ok(_) => {
                message.set(None);
                read();
            }
            Err(why) => message.set(Some(why)),
        });
    };
    view! {
        <div class="counters" id=format!("counters-{index:02x}")>
            <h4>{format!("{index:02X}h {}", o.name)}</h4>
            {action_button("read", "Read", read)}
            {action_button("erase", "Erase", erase)}
            {html(Box::new(move || match value() {
                None => "<p class=\"muted\">Not read yet.</p>".to_string(),
                Some(v) => table_html("", o.fields, &v),
            }))}
            {note("", "problem", message)}
        </div>
    }
}
