//! The connection bar, always visible: what the console is connected to
//! (the profile), state, transport (with the WebSerial port chooser) and
//! port, baud, T_REQ level, the link's repeats and its timeouts.
//!
//! Its status items are written as HTML, a few at a time ([`html`]): a
//! bar of a dozen items each with its own reactive bindings costs the
//! console's wasm a render effect per binding (docs/console.md "Size").
//! The T_REQ level, which changes at every exchange, and the controls
//! keep elements of their own.

use super::widgets::{escape, html, live_button, option_html, select, text};
use crate::profile::Profile;
use crate::stores::use_console;
use crate::transport::LinkState;
use leptos::prelude::*;
use plm_core::link::BAUD_RATES;

/// The bar.
#[component]
pub fn ConnectionBar() -> impl IntoView {
    let c = use_console();
    let conn = c.conn;
    let profile = c.profile;
    let modem = move || !profile.get().is_street();
    let state = move || {
        let (ok, title) = match conn.state.get() {
            LinkState::Connected => (true, "Bytes flow".to_string()),
            LinkState::Disconnected(why) => (false, why),
        };
        let kind = conn.kind.get();
        let transport = match (kind.as_str(), profile.get()) {
            ("", _) => "none",
            ("Simulated", Profile::St7570) => "simulated S-FSK network",
            ("Simulated", p) if !p.is_street() => "simulated modem",
            ("Simulated", _) => "simulated street",
            (other, _) => other,
        };
        format!(
            "<span id=\"conn-state\" class=\"state{}\" title=\"{}\">{}</span>\
             <span class=\"item\" id=\"conn-transport\" title=\"Where the bytes go: the simulated world in this page, or a real modem or board over WebSerial (the button beside it)\">Transport <b>{}</b></span>",
            if ok { " ok" } else { "" },
            escape(&title),
            if ok { "● Connected" } else { "○ Disconnected" },
            escape(transport)
        )
    };
    let chip = move || {
        let (what, name) = match profile.get() {
            Profile::StreetBoard => ("Board", "STEVAL-IHP007V1 USART"),
            Profile::St7570 => ("Chip", "ST7570"),
            _ => ("Chip", "ST7580"),
        };
        format!("<span class=\"item\">{what} <b id=\"conn-chip\">{name}</b></span>")
    };
    let link = move || {
        let mut h = String::new();
        let retries = conn.retries.get();
        if retries != 0 {
            h.push_str(&format!(
                "<span class=\"item warn\" id=\"conn-retries\" title=\"Frames the link had to repeat since connecting (UM0932 3.2.7: NAK, no ACK, no status message). Last: {}\">Repeats <b>{retries}</b></span>",
                escape(&conn.last_problem.get().unwrap_or_default()),
            ));
        }
        let t = conn.timeouts.get();
        // T_IC of 5 characters is under a millisecond (ST7570).
        h.push_str(&format!(
            "<span class=\"item muted\" title=\"Host-interface timeouts (ST7580 MIB 09h; ST7570: T_IC from 000Bh)\"{}>T_SR {} · T_ACK {} · T_IC {}.{} ms</span>",
            if modem() { "" } else { " hidden" },
            t.t_sr / 1000,
            t.t_ack / 1000,
            t.t_ic / 1000,
            t.t_ic % 1000 / 100,
        ));
        h
    };
    let profiles = move || {
        let chosen = profile.get();
        let mut h = String::new();
        for p in Profile::ALL {
            option_html(&mut h, p.key(), p.label(), p == chosen);
        }
        h
    };
    let bauds = move || {
        let chosen = conn.baud.get();
        let mut h = String::new();
        for b in BAUD_RATES {
            option_html(&mut h, &b.to_string(), &b.to_string(), b == chosen);
        }
        h
    };
    view! {
        <div class="conn" id="connection" aria-label="Connection">
            <label title="What is at the other end of the serial port. Changing it restarts the simulated world (or reconnects the port with the new profile).">
                {select("profile", Box::new(profiles), Box::new(move |v| {
                    if let Some(p) = Profile::from_key(&v) {
                        c.set_profile(p);
                    }
                }))}
            </label>
            {html(Box::new(state))}
            <crate::views::serial_port::SerialPort/>
            <span class="item" id="conn-port" title="Port">{text(Box::new(move || conn.port.get()))}</span>
            <label>
                "Baud "
                {select("baud", Box::new(bauds), Box::new(move |v| {
                    if let Ok(b) = v.parse::<u32>() {
                        c.set_baud(b);
                    }
                }))}
            </label>
            {html(Box::new(chip))}
            <span class="item" id="conn-treq" title="T_REQ: low = the host asks to send" hidden=move || !modem()>
                "T_REQ "
                {html(Box::new(move || String::from(if conn.treq.get() { "<b class=\"low\">low</b>" } else { "<b>high</b>" })))}
            </span>
            {html(Box::new(link))}
            {live_button(
                "connect",
                Box::new(move || String::from(if conn.kind.get().is_empty() { "Connect" } else { "Disconnect" })),
                Box::new(|| false),
                Box::new(move || {
                    if c.conn.kind.get_untracked().is_empty() {
                        c.connect_simulated();
                    } else {
                        c.disconnect();
                    }
                }),
            )}
        </div>
    }
}
