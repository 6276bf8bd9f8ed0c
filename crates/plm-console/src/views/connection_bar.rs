//! The connection bar, always visible: what the console is connected to
//! (the profile), state, transport (with the WebSerial port chooser) and
//! port, baud, T_REQ level, the link's repeats and its timeouts.

use super::widgets::{on_click, on_event};
use crate::profile::Profile;
use crate::stores::use_console;
use crate::transport::LinkState;
use leptos::prelude::*;
use plm_sim::BAUD_RATES;

/// The bar.
#[component]
pub fn ConnectionBar() -> impl IntoView {
    let c = use_console();
    let conn = c.conn;
    let connected = move || conn.state.with(LinkState::is_connected);
    let profile = c.profile;
    let modem = move || !profile.get().is_street();
    view! {
        <div class="conn" id="connection" aria-label="Connection">
            <label title="What is at the other end of the serial port. Changing it restarts the simulated world (or reconnects the port with the new profile).">
                <select
                    id="profile"
                    on:change=on_event(move |ev| {
                        if let Some(p) = Profile::from_key(&event_target_value(&ev)) {
                            c.set_profile(p);
                        }
                    })
                >
                    {Profile::ALL
                        .into_iter()
                        .map(|p| {
                            view! {
                                <option value=p.key() selected=move || profile.get() == p>
                                    {p.label()}
                                </option>
                            }
                        })
                        .map(IntoAny::into_any).collect_view()}
                </select>
            </label>
            <span
                id="conn-state"
                class="state"
                class:ok=connected
                title=move || match conn.state.get() {
                    LinkState::Connected => "Bytes flow".to_string(),
                    LinkState::Disconnected(why) => why,
                }
            >
                {move || String::from(if connected() { "● Connected" } else { "○ Disconnected" })}
            </span>
            <span
                class="item"
                id="conn-transport"
                title="Where the bytes go: the simulated world in this page, or a real modem or board over WebSerial (the button beside it)"
            >
                "Transport "
                <b>
                    {move || match conn.kind.get().as_str() {
                        "" => "none".to_string(),
                        "Simulated" if modem() => "simulated modem".to_string(),
                        "Simulated" => "simulated street".to_string(),
                        other => other.to_string(),
                    }}
                </b>
            </span>
            <crate::views::serial_port::SerialPort/>
            <span class="item" id="conn-port" title="Port">{move || conn.port.get()}</span>
            <label>
                "Baud "
                <select
                    id="baud"
                    on:change=on_event(move |ev| {
                        if let Ok(b) = event_target_value(&ev).parse::<u32>() {
                            c.set_baud(b);
                        }
                    })
                >
                    {BAUD_RATES
                        .iter()
                        .map(|&b| {
                            view! {
                                <option value=b.to_string() selected=move || conn.baud.get() == b>
                                    {b.to_string()}
                                </option>
                            }
                        })
                        .map(IntoAny::into_any).collect_view()}
                </select>
            </label>
            <span class="item">
                {move || String::from(if profile.get() == Profile::StreetBoard { "Board " } else { "Chip " })}
                <b id="conn-chip">{move || String::from(match profile.get() {
                    Profile::StreetBoard => "STEVAL-IHP007V1 USART",
                    Profile::St7570 => "ST7570",
                    _ => "ST7580",
                })}</b>
            </span>
            <span class="item" id="conn-treq" title="T_REQ: low = the host asks to send" hidden=move || !modem()>
                "T_REQ "
                <b class:low=move || conn.treq.get()>
                    {move || String::from(if conn.treq.get() { "low" } else { "high" })}
                </b>
            </span>
            {move || (conn.retries.get() != 0).then(|| view! {
                <span
                    class="item warn"
                    id="conn-retries"
                    title=move || {
                        format!(
                            "Frames the link had to repeat since connecting (UM0932 3.2.7: NAK, no ACK, no status message). Last: {}",
                            conn.last_problem.get().unwrap_or_default(),
                        )
                    }
                >
                    "Repeats " <b>{move || conn.retries.get().to_string()}</b>
                </span>
            }).map(IntoAny::into_any)}
            <span class="item muted" title="Host-interface timeouts (ST7580 MIB 09h; ST7570: T_IC from 000Bh)" hidden=move || !modem()>
                {move || {
                    let t = conn.timeouts.get();
                    // T_IC of 5 characters is under a millisecond (ST7570).
                    format!(
                        "T_SR {} · T_ACK {} · T_IC {}.{} ms",
                        t.t_sr / 1000,
                        t.t_ack / 1000,
                        t.t_ic / 1000,
                        t.t_ic % 1000 / 100,
                    )
                }}
            </span>
            <button
                id="connect"
                on:click=on_click(move |_| {
                    if c.conn.kind.get_untracked().is_empty() {
                        c.connect_simulated();
                    } else {
                        c.disconnect();
                    }
                })
            >
                {move || String::from(if conn.kind.get().is_empty() { "Connect" } else { "Disconnect" })}
            </button>
        </div>
    }
}
