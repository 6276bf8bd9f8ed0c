//! The WebSerial port chooser, in the connection bar: a real modem on a
//! USB-UART adapter instead of the simulated one.
//!
//! A button opens a small panel: the ports this site was granted before
//! (`navigator.serial.getPorts()`, refreshed when one is plugged in or
//! out), "Choose a port…" (the browser's own chooser), the baud rate
//! (UM0932 3.1: 9600, 19200, 38400, 57600), which RTS level asserts T_REQ
//! (default: RTS asserted = T_REQ low), Connect, and the way back to the
//! simulated modem. The choices are remembered in `localStorage`.
//! Browsers without WebSerial get a plain explanation; the simulated modem
//! stays available.

use leptos::prelude::*;

/// Why WebSerial is not offered here, in words.
pub const NO_WEB_SERIAL: &str = "This browser has no WebSerial (navigator.serial), so it cannot reach a modem on a serial port. WebSerial needs Chrome, Edge or Opera on a desktop, and the page served over HTTPS or from localhost. The simulated modem works here.";

/// The button and its panel.
#[component]
pub fn SerialPort() -> impl IntoView {
    #[cfg(target_arch = "wasm32")]
    {
        wasm::panel().into_any()
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        view! { <span class="item muted" id="serial-unavailable" title=NO_WEB_SERIAL>"WebSerial: not here"</span> }
            .into_any()
    }
}

#[cfg(target_arch = "wasm32")]
mod wasm {
    use super::NO_WEB_SERIAL;
    use crate::stores::{use_console, Console};
    use crate::transport::webserial::{self, OnLost, Settings, TReqPolarity, WebSerialTransport};
    use crate::transport::LinkState;
    use crate::views::widgets::{
        checkbox, escape, html, live_button, on_click, option_html, select, text,
    };
    use leptos::prelude::*;
    use plm_core::link::BAUD_RATES;
    use std::rc::Rc;
    use wasm_bindgen::closure::Closure;
    use wasm_bindgen::{JsCast, JsValue};
    use wasm_bindgen_futures::spawn_local;
    use web_sys::SerialPort as Port;

    const KEY_BAUD: &str = "plm-console.serial.baud";
    const KEY_POLARITY: &str = "plm-console.serial.polarity";
    const KEY_PORT: &str = "plm-console.serial.port";
    const KEY_RTS_TWICE: &str = "plm-console.serial.rts-twice";

    use crate::storage::load;
    use crate::views::widgets::button;

    fn save(key: &str, value: &str) {
        crate::storage::store(key, Some(value));
    }

    thread_local! {
        /// Granted ports, in the order `getPorts` gave them (one chooser
        /// in the page, which lives as long as it).
        static PORTS: std::cell::RefCell<Vec<Port>> = const { std::cell::RefCell::new(Vec::new()) };
    }

    /// The panel's state; `Copy`, shared by the handlers.
    #[derive(Clone, Copy)]
    struct Chooser {
        console: Console,
        /// Their names, for the list.
        labels: RwSignal<Vec<String>>,
        /// The index of the chosen port (a signal type the page has anyway).
        selected: RwSignal<Option<u64>>,
        baud: RwSignal<u32>,
        /// The key of the [`TReqPolarity`] chosen.
        polarity: RwSignal<String>,
        /// Each RTS change sent twice (Windows' usbser driver).
        rts_twice: RwSignal<bool>,
        /// A port is being opened.
        busy: RwSignal<bool>,
        message: RwSignal<Option<String>>,
        open: RwSignal<bool>,
    }

    impl Chooser {
        /// The chosen port.
        fn port(&self) -> Option<Port> {
            let i = self.selected.get_untracked()? as usize;
            PORTS.with(|p| p.borrow().get(i).cloned())
        }

        /// Shows `ports`, keeping the selection on the same port, else on
        /// the one used last time, else the first.
        fn show(&self, ports: Vec<Port>, prefer: Option<Port>) {
            let current = self.port();
            let labels: Vec<String> = ports.iter().map(webserial::describe).collect();
            let last = load(KEY_PORT);
            let same = |want: &Port| {
                ports
                    .iter()
                    .position(|p| JsValue::from(p) == JsValue::from(want))
            };
            let selected = prefer
                .as_ref()
                .and_then(same)
                .or_else(|| current.as_ref().and_then(same))
                .or_else(|| last.and_then(|l| labels.iter().position(|x| *x == l)))
                .or(if ports.is_empty() { None } else { Some(0) });
            PORTS.with(|p| *p.borrow_mut() = ports);
            self.labels.set(labels);
            self.selected.set(selected.map(|i| i as u64));
        }

        /// Asks the browser for the ports granted to this site.
        fn refresh(self, prefer: Option<Port>) {
            let Some(serial) = webserial::serial() else {
                return;
            };
            let promise = serial.get_ports();
            spawn_local(async move {
                match promise.await {
                    Ok(list) => {
                        let ports = list.iter().map(|p| p.unchecked_into::<Port>()).collect();
                        self.show(ports, prefer);
                    }
                    Err(e) => self.message.set(Some(format!(
                        "the granted ports could not be listed: {}",
                        webserial::js_error(&e)
                    ))),
                }
            });
        }

        /// The browser's port chooser (needs the click that calls it).
        fn choose(self) {
            let Some(serial) = webserial::serial() else {
                return;
            };
            let promise = serial.request_port();
            spawn_local(async move {
                match promise.await {
                    Ok(port) => {
                        let port: Port = port.unchecked_into();
                        self.message.set(Some(format!(
                            "{} granted: Connect to open it",
                            webserial::describe(&port)
                        )));
                        self.refresh(Some(port));
                    }
                    Err(e) => self.message.set(Some(
                        if webserial::js_error(&e).starts_with("NotFoundError") {
                            "no port was chosen".to_string()
                        } else {
                            format!("no port: {}", webserial::js_error(&e))
                        },
                    )),
                }
            });
        }

        /// Opens the selected port and makes it the session's transport.
        fn connect(self) {
            let Some(port) = self.port() else {
                self.message.set(Some(
                    "no port: choose one first (Choose a port…)".to_string(),
                ));
                return;
            };
            let label = webserial::describe(&port);
            let settings = Settings {
                baud: self.baud.get_untracked(),
                polarity: TReqPolarity::from_key(&self.polarity.get_untracked())
                    .unwrap_or_default(),
                rts_twice: self.rts_twice.get_untracked(),
            };
            save(KEY_BAUD, &settings.baud.to_string());
            save(KEY_POLARITY, settings.polarity.key());
            crate::storage::store(KEY_RTS_TWICE, settings.rts_twice.then_some("1"));
            save(KEY_PORT, &label);
            let console = self.console;
            // A port open over WebSerial now (maybe this one) is closed
            // first; the simulated modem keeps running until the port is
            // open, so a port that will not open leaves it in place.
            if console.conn.kind.get_untracked() == "WebSerial" {
                console.disconnect();
            }
            self.busy.set(true);
            self.message
                .set(Some(format!("opening {label} at {} baud…", settings.baud)));
            let chooser = self;
            let on_lost: OnLost = Rc::new(move |why: String| chooser.lost(why));
            spawn_local(async move {
                let opened = WebSerialTransport::open(port, label.clone(), settings, on_lost).await;
                self.busy.set(false);
                match opened {
                    Ok(t) => {
                        console.connect_transport(Box::new(t));
                        console.set_baud(settings.baud);
                        self.message.set(Some(format!(
                            "connected to {label} at {} baud; T_REQ on RTS ({})",
                            settings.baud,
                            settings.polarity.label()
                        )));
                        self.open.set(false);
                    }
                    Err(why) => self.message.set(Some(why)),
                }
            });
        }

        /// The port was lost: the session lets go of it at once (requests
        /// in flight fail now rather than at the link's timeouts), and the
        /// connection bar says why.
        fn lost(self, why: String) {
            let conn = self.console.conn;
            if conn.kind.get_untracked() == "WebSerial" {
                self.console.disconnect();
            }
            conn.state.set(LinkState::Disconnected(why.clone()));
            conn.last_problem.set(Some(why.clone()));
            self.message.set(Some(why));
            self.refresh(None);
        }

        /// Back to the simulated modem (closing the port).
        fn use_simulator(self) {
            let c = self.console;
            c.connect_simulated();
            self.message.set(None);
            self.open.set(false);
        }
    }

    /// Refreshes the list whenever a granted port comes or goes. The
    /// listeners live as long as the page (the bar is never unmounted).
    fn watch_ports(chooser: Chooser) {
        let Some(serial) = webserial::serial() else {
            return;
        };
        for event in ["connect", "disconnect"] {
            let listener =
                Closure::<dyn FnMut(web_sys::Event)>::new(move |_| chooser.refresh(None));
            let _ =
                serial.add_event_listener_with_callback(event, listener.as_ref().unchecked_ref());
            listener.forget();
        }
    }

    pub fn panel() -> impl IntoView {
        let console = use_console();
        let supported = webserial::serial().is_some();
        let chooser = Chooser {
            console,
            labels: crate::views::widgets::signal(Vec::new()),
            selected: crate::views::widgets::signal(None),
            baud: crate::views::widgets::signal(
                load(KEY_BAUD)
                    .and_then(|b| b.parse().ok())
                    .filter(|b| BAUD_RATES.contains(b))
                    .unwrap_or_else(|| console.conn.baud.get_untracked()),
            ),
            polarity: crate::views::widgets::signal(
                load(KEY_POLARITY)
                    .filter(|p| TReqPolarity::from_key(p).is_some())
                    .unwrap_or_else(|| TReqPolarity::default().key().to_string()),
            ),
            rts_twice: crate::views::widgets::signal(load(KEY_RTS_TWICE).is_some()),
            busy: crate::views::widgets::signal(false),
            message: crate::views::widgets::signal(None),
            open: crate::views::widgets::signal(false),
        };
        if supported {
            chooser.refresh(None);
            watch_ports(chooser);
        }
        let Chooser {
            labels,
            selected,
            baud,
            polarity,
            rts_twice,
            busy,
            message,
            open,
            ..
        } = chooser;
        let active = move || console.conn.kind.get() == "WebSerial";
        let summary = move || {
            if !supported {
                "WebSerial: not in this browser"
            } else if active() {
                "WebSerial ▾ (in use)"
            } else {
                "WebSerial ▾"
            }
        };

        let ports = move || {
            let list = labels.get();
            let mut h = String::new();
            if list.is_empty() {
                option_html(&mut h, "", "no port granted yet", true);
            }
            let chosen = selected.get();
            for (i, l) in list.iter().enumerate() {
                option_html(&mut h, &i.to_string(), l, chosen == Some(i as u64));
            }
            h
        };
        let bauds = move || {
            let chosen = baud.get();
            let mut h = String::new();
            for b in BAUD_RATES {
                option_html(&mut h, &b.to_string(), &b.to_string(), b == chosen);
            }
            h
        };
        let polarities = move || {
            let chosen = polarity.get();
            let chosen = chosen.as_str();
            let mut h = String::new();
            for p in TReqPolarity::ALL {
                option_html(&mut h, p.key(), p.label(), p.key() == chosen);
            }
            h
        };
        let controls = if supported {
            view! {
                <p class="muted" style="margin-top: 0">
                    "A modem on a USB-UART adapter: TX, RX, GND, and RTS wired to T_REQ."
                </p>
                <div style="display: grid; grid-template-columns: max-content 1fr; gap: 6px 10px; align-items: center">
                    <label for="serial-port">"Port"</label>
                    <span style="display: flex; gap: 6px">
                        {select("serial-port", Box::new(ports), Box::new(move |v| selected.set(v.parse().ok())))}
                        {button("serial-choose", "Choose a port…", "The browser asks which port this site may use, and remembers the answer.", move || chooser.choose())}
                    </span>
                    <label
                        for="serial-baud"
                        title="The modem's baud rate, set by its BR0/BR1 pins (UM0932 3.1); 8N1, no flow control."
                    >
                        "Baud"
                    </label>
                    {select("serial-baud", Box::new(bauds), Box::new(move |v| {
                        if let Ok(b) = v.parse() {
                            baud.set(b);
                        }
                    }))}
                    <label
                        for="serial-polarity"
                        title="Which RTS level pulls T_REQ low (a request to send). Straight wiring: RTS asserted = T_REQ low; through an inverting level shifter: the other."
                    >
                        "T_REQ"
                    </label>
                    {select("serial-polarity", Box::new(polarities), Box::new(move |v| {
                        if TReqPolarity::from_key(&v).is_some() {
                            polarity.set(v);
                        }
                    }))}
                    <span></span>
                    <label
                        title="Windows' usbser driver sets RTS one call late"
                    >
                        {checkbox("serial-rts-twice", Box::new(move || rts_twice.get()), Box::new(move |on| rts_twice.set(on)))}
                        " Send each RTS change twice (Windows)"
                    </label>
                </div>
            }
                .into_any()
        } else {
            view! { <p id="serial-unavailable" style="margin-top: 0">{NO_WEB_SERIAL}</p> }
                .into_any()
        };

        view! {
            <span class="item" id="serial" style="position: relative">
                <button
                    id="serial-toggle"
                    aria-expanded=move || open.get().to_string()
                    aria-controls="serial-panel"
                    title=if supported { "Connect to a real modem over WebSerial" } else { NO_WEB_SERIAL }
                    on:click=on_click(move |_| open.update(|o| *o = !*o))
                >
                    {text(Box::new(move || summary().to_string()))}
                </button>
                <div
                    id="serial-panel"
                    role="dialog"
                    aria-label="WebSerial port"
                    hidden=move || !open.get()
                    style="position: absolute; top: calc(100% + 6px); left: 0; z-index: 30; width: 500px; \
                           background: var(--panel); border: 1px solid var(--line); border-radius: 6px; \
                           padding: 10px 12px; box-shadow: 0 4px 16px rgba(0, 0, 0, 0.18)"
                >
                    {controls}
                    <div class="buttons" style="margin-top: 10px">
                        {supported.then(|| live_button(
                            "serial-connect",
                            Box::new(move || String::from(if active() { "Reconnect" } else { "Connect over WebSerial" })),
                            Box::new(move || busy.get() || labels.with(Vec::is_empty)),
                            Box::new(move || chooser.connect()),
                        ))}
                        {live_button(
                            "serial-use-sim",
                            Box::new(|| String::from("Use the simulated modem")),
                            Box::new(move || console.conn.kind.get() == "Simulated"),
                            Box::new(move || chooser.use_simulator()),
                        )}
                        {button("serial-close", "Close", "", move || open.set(false))}
                    </div>
                    {html(Box::new(move || message.with(|m| m.as_deref().map_or(String::new(), |m| format!(
                        "<p class=\"message\" id=\"serial-message\" role=\"status\">{}</p>",
                        escape(m)
                    )))))}
                </div>
            </span>
        }
    }
}
