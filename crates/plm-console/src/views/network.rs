//! The ST7570's S-FSK network (ST7570 UM 4-5): the modem's status message
//! decoded per mode (Table 11), its synchronization and history, the nodes
//! heard, alarms, repeater calls and, in Monitor mode, the slot-by-slot
//! SPY timeline; with the simulated network, its Servers as the line sees
//! them. What it shows is [`crate::network::NetworkLog`]'s.

use super::diagnostics::fields_html;
use super::widgets::{button, escape, on_click, on_event, signal, text_table};
use super::{fixed, seconds};
use crate::network::{address_text, confirm_text, named, sn_text, sync_text, Event, NetworkLog};
use crate::profile::Profile;
use crate::session::Outcome;
use crate::stores::{use_console, Console};
use leptos::prelude::*;
use plm_core::st7570::fields as f;
use plm_core::st7570::status::Row;
use plm_core::st7570::Command;

/// Sends an ST7570 `command`; `done` gets the answer read in the access
/// layer the modem is in, or why there is none.
pub fn send(c: Console, command: Command, done: impl FnOnce(Result<Command, String>) + 'static) {
    send_boxed(c, command, Box::new(done));
}

/// [`send`] for every caller: one copy of the reading of the answer.
fn send_boxed(c: Console, command: Command, done: Box<dyn FnOnce(Result<Command, String>)>) {
    let layer = c.modem.network.with_untracked(|n| n.layer());
    c.request_frame(command.to_frame(), move |o| {
        done(
            match o.read(|a| Command::from_frame(a, layer).map_err(|e| e.to_string())) {
                Outcome::Answer { command, .. } => Ok(command),
                Outcome::Failed(why) => Err(why),
            },
        )
    });
}

/// The view.
#[component]
pub fn NetworkView() -> impl IntoView {
    let c = use_console();
    let st7570 = move || c.profile.get() == Profile::St7570;
    view! {
        <article class="card" hidden=st7570>
            <p class="muted">"The Network view shows an ST7570's S-FSK network. Choose the ST7570 profile in the connection bar."</p>
        </article>
        <div class="cards" hidden=move || !st7570()>
            <StatusCard/>
            <SyncCard/>
            <SimulatedServers/>
            <NodesCard/>
            <AlarmCard/>
            <RepeaterCallCard/>
            <SpyCard/>
        </div>
    }
}

/// A history of the network log as a list, newest first, written as
/// HTML (as [`text_table`]); `list` picks it.
#[inline(never)]
fn history(id: &'static str, list: fn(&NetworkLog) -> &Vec<Event>) -> AnyView {
    let net = use_console().modem.network;
    let html = move || {
        net.with(|n| {
            list(n).iter().rev().fold(String::new(), |mut h, e| {
                h.push_str(&format!(
                    "<li><span class=\"muted\">{}</span> {}</li>",
                    seconds(e.at),
                    escape(&e.what)
                ));
                h
            })
        })
    };
    view! { <ul class="events" id=id inner_html=html></ul> }.into_any()
}

#[component]
fn StatusCard() -> impl IntoView {
    let c = use_console();
    let status = move || c.modem.network.with(|n| n.status);
    // The modem sends a status message only when asked to take a frame
    // (5.2.2): any request brings a fresh one.
    let ask = move || c.read_mib(plm_core::st7570::mib::index::PLC_CONFIGURATION, |_| {});
    view! {
        <article class="card" id="net-status">
            <h3>"Modem status"</h3>
            <div class="buttons">
                {button("net-status-ask", "Ask now", "The modem sends its status message when the host asks to send (T_REQ): this reads 00A1h", ask)}
            </div>
            <p class="muted">{move || match status() {
                None => "No status message yet (one comes with every request).".to_string(),
                Some((at, s)) => format!("{} (Table 11), {}", s.row().name(), seconds(at)),
            }}</p>
            <table class="kv" inner_html=move || status().map_or(String::new(), |(_, s)| {
                fields_html(Row::of(s.emit()[0]).layout(), &s.emit())
            })></table>
        </article>
    }
}

#[component]
fn SyncCard() -> impl IntoView {
    let c = use_console();
    let net = c.modem.network;
    let state = move || {
        net.with(|n| match n.status {
            None => "unknown".to_string(),
            Some((_, s)) => format!(
                "{}{}",
                if s.synchronized() {
                    "synchronized"
                } else {
                    "not synchronized"
                },
                if s.zc_fail {
                    " (ZC_FAIL: no zero crossing)"
                } else {
                    ""
                }
            ),
        })
    };
    let result = signal(None::<String>);
    let reject = move || {
        send(c, Command::DesynchroRequest { reset: 1 }, move |r| {
            result.set(Some(match r {
                Ok(_) => "synchronization rejected (CMD_DesynchroRequest, RESET = 1)".into(),
                Err(why) => why,
            }))
        })
    };
    view! {
        <article class="card" id="net-sync">
            <h3>"Synchronization"</h3>
            <p>"Now: "<b id="net-sync-state">{state}</b></p>
            <div class="buttons">
                {button("net-desync", "Reject synchronization", "CMD_DesynchroRequest with RESET = 1 (Table 22): a Server searches again", reject)}
            </div>
            {super::widgets::note("", "muted", result)}
            <h4>"History (CMD_SynchroIndication, Table 18)"</h4>
            {history("net-sync-history", |n| &n.syncs)}
        </article>
    }
}

#[component]
fn NodesCard() -> impl IntoView {
    let c = use_console();
    let net = c.modem.network;
    let rows = move || {
        net.with(|n| {
            n.heard
                .iter()
                .map(|(a, h)| {
                    vec![
                        address_text(*a),
                        h.frames.to_string(),
                        seconds(h.last),
                        h.credit
                            .map_or("–".into(), |c| format!("{}/{}/{}", c.ic, c.cc, c.dc)),
                        h.snr.map_or("–".into(), |(a, b)| {
                            format!("{} / {}", fixed(a, 1), fixed(b, 1))
                        }),
                        h.sn.as_ref().map_or("–".into(), sn_text),
                        h.delta_phase
                            .and_then(|d| f::DELTA_PHASES.get(d as usize))
                            .map_or("–", |p| *p)
                            .to_string(),
                    ]
                })
                .collect()
        })
    };
    const COLUMNS: &[(&str, &str)] = &[
        ("Address", "num"),
        ("Frames", "num"),
        ("Last heard", "time"),
        ("IC/CC/DC", "num"),
        ("SNR0 / SNR1 dB", "num"),
        ("S/N", ""),
        ("Δφ", "num"),
    ];
    view! {
        <article class="card wide" id="net-nodes">
            <h3>"Nodes heard"</h3>
            <p class="muted">"By source address, from the frames indicated (MAC) and the subframes heard (PHY, Monitor). Δφ is the status message's delta-phase at the time (Server and Monitor)."</p>
            {text_table("net-nodes-table", COLUMNS, Box::new(rows))}
        </article>
    }
}

#[component]
fn AlarmCard() -> impl IntoView {
    let c = use_console();
    let net = c.modem.network;
    let alarm = move || {
        send(c, Command::AlarmRequest, move |r| {
            let what = match r {
                Ok(Command::AlarmConfirm { confirm_code }) => {
                    format!(
                        "alarm sent: {}",
                        confirm_text(&f::ALARM_CONFIRM_CODES[..], confirm_code)
                    )
                }
                Ok(other) => format!(
                    "alarm not sent: {}",
                    other.name().unwrap_or("unexpected answer")
                ),
                Err(why) => format!("alarm not sent: {why}"),
            };
            let at = c.now();
            net.update(|n| n.note_alarm(at, what));
        })
    };
    view! {
        <article class="card" id="net-alarms">
            <h3>"Alarms"</h3>
            <div class="buttons">
                {button("net-alarm", "Send an alarm", "CMD_AlarmRequest (5.3.15): the 3-byte alarm in the next slot's window", alarm)}
            </div>
            {history("net-alarm-history", |n| &n.alarms)}
        </article>
    }
}

#[component]
fn RepeaterCallCard() -> impl IntoView {
    let c = use_console();
    let net = c.modem.network;
    let tx_pos = signal("0".to_string());
    let threshold = signal("40".to_string());
    let problem = signal(None::<String>);
    let call = move || {
        let pos = tx_pos
            .get_untracked()
            .trim()
            .parse::<u16>()
            .ok()
            .filter(|p| *p <= 20);
        let th =
            super::decimal(&threshold.get_untracked()).filter(|t| (0.0..=167_772.0).contains(t));
        let (Some(tx_pos), Some(th)) = (pos, th) else {
            problem.set(Some(
                "TX_POS is a sub-slot 0..20 and the threshold a level in dBµV".into(),
            ));
            return;
        };
        problem.set(None);
        let rc_threshold = (th * 100.0).round() as u16;
        send(
            c,
            Command::RcRequest {
                tx_pos,
                rc_threshold,
            },
            move |r| {
                let what = match r {
                    Ok(Command::RcConfirm {
                        result,
                        repeater_state,
                        heard,
                    }) => {
                        let state = named(f::REPEATER_STATES, repeater_state);
                        let heard = heard.map_or(String::new(), |h| {
                            format!(
                                ", heard S {} N {} dBµV in sub-slot {}",
                                fixed(h.s as f64 / 100.0, 1),
                                fixed(h.n as f64 / 100.0, 1),
                                h.rx_pos
                            )
                        });
                        format!(
                            "TX_POS {tx_pos}: {}, repeater {state}{heard}",
                            named(&f::RC_RESULTS[..], result)
                        )
                    }
                    Ok(other) => format!(
                        "TX_POS {tx_pos}: {}",
                        other.name().unwrap_or("unexpected answer")
                    ),
                    Err(why) => format!("TX_POS {tx_pos}: {why}"),
                };
                let at = c.now();
                net.update(|n| n.note_call(at, what));
            },
        )
    };
    view! {
        <article class="card" id="net-rc">
            <h3>"Repeater call"</h3>
            <p class="muted">"CMD_RC_Request (Table 61, MAC): the RC pattern in sub-slot TX_POS of 21; Servers that hear it above the threshold say so."</p>
            <div class="form-row">
                <label>"TX_POS "{super::widgets::text_input("net-rc-pos", "", "0..20", Some(4), tx_pos)}</label>
                <label>"Threshold, dBµV "{super::widgets::text_input("net-rc-threshold", "", "", Some(6), threshold)}</label>
                {button("net-rc-send", "Call", "", call)}
            </div>
            {super::widgets::note("", "problem", problem)}
            {history("net-rc-history", |n| &n.calls)}
        </article>
    }
}

#[component]
fn SpyCard() -> impl IntoView {
    let c = use_console();
    let net = c.modem.network;
    let slots = move || {
        net.with(|n| {
            n.spy.iter().fold(String::new(), |mut h, (at, kind, text)| {
                let (mark, class) = kind.mark();
                h.push_str(&format!(
                    "<span class=\"slot {class}\" title=\"{} {}\">{mark}</span>",
                    seconds(*at),
                    escape(text)
                ));
                h
            })
        })
    };
    view! {
        // Only a Monitor has SPY indications (Table 15).
        <article class="card wide" id="net-spy" hidden=move || net.with(|n| n.spy.is_empty() && n.status.is_none_or(|(_, s)| s.mode != 3))>
            <h3>"PHY Monitor: SPY timeline"</h3>
            <p class="muted">"One mark per SPY indication, oldest first (PHY Monitor, 5.3.17-5.3.22): S subframe, · no subframe, ? searching, F synchronization found, A alarm, - no alarm. Hover for S/N."</p>
            <div class="timeline" id="net-spy-timeline" inner_html=slots></div>
        </article>
    }
}

/// The simulated Servers along the line (simulated network only).
#[component]
fn SimulatedServers() -> impl IntoView {
    let c = use_console();
    let servers = c.sim.servers;
    let scale = signal(1u64);
    // The rows as HTML, their buttons handled by one listener on the
    // table (as [`text_table`]): `data-node` says which Server.
    let rows = move || {
        servers.with(|list| {
            list.iter().fold(String::new(), |mut h, s| {
                let last: Vec<String> = s
                    .syncs
                    .iter()
                    .rev()
                    .take(3)
                    .map(|(at, y)| format!("{} {}", seconds(*at), sync_text(y)))
                    .collect();
                h.push_str(&format!(
                    "<tr id=\"sim-server-{n}\"><td class=\"num\">{n}</td><td class=\"num\">{}</td><td>{}</td><td class=\"sync\">{}</td><td class=\"num\">{} / {}</td><td class=\"fields\">{}</td><td><button class=\"cut\" data-node=\"{n}\">{}</button> <button class=\"alarm\" data-node=\"{n}\" title=\"Its host sends CMD_AlarmRequest: every node hears the alarm in the window of a slot\">Alarm</button></td></tr>",
                    address_text(s.address),
                    if s.repeater { "Server, repeater" } else { "Server" },
                    if s.synchronized { "synchronized" } else { "not synchronized" },
                    s.indicated,
                    s.answered,
                    escape(&last.join("; ")),
                    if s.cut_off { "Reconnect" } else { "Cut off" },
                    n = s.node,
                ));
                h
            })
        })
    };
    let act = move |ev: leptos::ev::MouseEvent| {
        let Some(b) = super::widgets::closest(&ev, "button[data-node]") else {
            return;
        };
        let node: usize = b
            .get_attribute("data-node")
            .and_then(|n| n.parse().ok())
            .unwrap_or(0);
        let alarm = b.class_name() == "alarm";
        let cut = servers.with_untracked(|l| l.iter().any(|s| s.node == node && s.cut_off));
        c.with_sfsk(|t| {
            if alarm {
                t.raise_alarm(node)
            } else {
                t.cut_off(node, !cut)
            }
        });
    };
    view! {
        <article class="card wide" id="net-sim" hidden=move || servers.with(|s| s.is_empty())>
                <h3>"Simulated line"</h3>
                <p class="muted">"The Servers of the simulated network, as the line sees them (a real network shows only what your modem hears). They answer what is sent to them; \"Cut off\" drowns a node in noise, so that it loses synchronization once timeout-frame-not-OK (0003h) runs out."</p>
                <div class="form-row">
                    <label title="From the next timeout started: one already running keeps its deadline">"MAC timeouts run "
                        <select id="net-sim-scale" on:change=on_event(move |ev| {
                            let s = event_target_value(&ev).parse().unwrap_or(1);
                            scale.set(s);
                            c.with_sfsk(|t| t.set_timeout_scale(s));
                        })>
                            {[1u64, 10, 60, 600].into_iter().map(|s| view! {
                                <option value=s.to_string() selected=move || scale.get() == s>{format!("{s}× as fast")}</option>
                            }).collect_view()}
                        </select>
                    </label>
                </div>
                <table class="log" id="net-sim-table">
                    <thead><tr><th>"Node"</th><th>"Address"</th><th>"Role"</th><th>"Now"</th><th>"Frames to it / answered"</th><th>"Last synchronization changes"</th><th></th></tr></thead>
                    <tbody inner_html=rows on:click=on_click(act)></tbody>
                </table>
        </article>
    }
}
