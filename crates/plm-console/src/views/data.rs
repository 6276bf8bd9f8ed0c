//! The Data view: PHY, DL and SS data requests with the options of UM0932
//! Tables 35 and 45, checked by plm-core before sending, their confirms
//! decoded; and the power line frames received (data and sniffer
//! indications) as plm-core decoded them in the traffic log.

use super::snr_plot::{self, Point};
use super::widgets::{set_checked, set_value, signal, text_input, text_table};
use super::{millis, seconds, spaced};
use crate::session::Outcome;
use crate::stores::{refusal, use_console};
use crate::tab::Tab;
use crate::traffic::Entry;
use leptos::prelude::*;
use plm_core::json::Json;
use plm_core::st7580::fields::{confirm_data, tx_options, MODULATIONS};
use plm_core::st7580::mib::{index, ModemConfig};
use plm_core::st7580::{
    validate, Command, DataRequest, FrequencySet, Modulation, SsDataRequest, TxParams,
};
use std::sync::Arc;

/// Received frames shown, the most recent (the traffic log keeps them all).
const INDICATION_ROWS: usize = 200;

/// The indications that carry a received frame (UM0932 Table 39).
const INDICATIONS: &[&str] = &[
    "PHY_DataIndication",
    "DL_DataIndication",
    "DL_SnifferIndication",
    "SS_DataIndication",
    "SS_SnifferIndication",
];

fn field(e: &Entry, name: &str) -> String {
    e.decoded
        .fields
        .as_ref()
        .and_then(|f| f.get(name))
        .map(|v| match v {
            Json::String(s) => s.clone(),
            Json::Null => "–".into(),
            v => v.to_string(),
        })
        .unwrap_or_default()
}

fn payload(e: &Entry) -> String {
    [
        "phy_payload",
        "dl_payload",
        "dl_payload_and_wrong_crc",
        "ss_header_and_payload",
        "ss_sdu",
    ]
    .iter()
    .map(|k| field(e, k))
    .find(|p| !p.is_empty())
    .unwrap_or_default()
}

/// The SNR of each indication, in log order. Left out: B-FSK frames (SNR
/// byte 255, "no meaning", decoded as null: UM0932 Table 39) and entries
/// imported without a time.
fn snr_points(rows: &[Arc<Entry>]) -> Vec<Point> {
    rows.iter()
        .filter_map(|e| Point::new(e.at?, field(e, "snr").parse().ok()?, &e.title()))
        .collect()
}

/// The view, on the page's `tab`.
#[component]
pub fn DataView(tab: RwSignal<String>) -> impl IntoView {
    view! {
        <div class="cards">
            <DataRequestCard/>
            <Indications tab=tab/>
        </div>
    }
}

/// What the form says, before it is a command.
#[derive(Clone)]
struct Form {
    layer: String,
    modulation: String,
    frequency: String,
    custom_hz: String,
    overwrite: bool,
    gain: String,
    zc: bool,
    header_length: String,
    text: bool,
    payload: String,
}

/// The request a form makes, or the reason it cannot be sent.
fn build(f: &Form, dl_crc_len: usize) -> Result<Command, String> {
    let number = |what: &str, t: &str| -> Result<i64, String> {
        t.trim()
            .parse::<i64>()
            .map_err(|_| format!("{what}: \"{}\" is not a whole number", t.trim()))
    };
    let modulation = Modulation::from_bits(number("modulation", &f.modulation)? as u8);
    let tx_frequency = if f.frequency == "custom" {
        let hz = number("TX frequency", &f.custom_hz)?;
        tx_options::TX_FREQUENCY
            .check(hz)
            .map_err(|e| format!("TX frequency: {}", e.reason))?;
        Some(hz as u32)
    } else {
        None
    };
    let tx_gain = if f.gain.trim().is_empty() {
        None
    } else {
        let g = number("TX gain", &f.gain)?;
        tx_options::TX_GAIN
            .check(g)
            .map_err(|e| format!("TX gain: {}", e.reason))?;
        Some(g as u8)
    };
    let params = TxParams {
        modulation,
        frequency_set: if f.frequency == "low" {
            FrequencySet::Low
        } else {
            FrequencySet::High
        },
        frequency_overwrite: tx_frequency.is_some() && f.overwrite,
        zero_crossing_sync: f.zc,
        tx_frequency,
        tx_gain,
    };
    let payload = if f.text {
        f.payload.as_bytes().to_vec()
    } else {
        plm_core::hex::parse(&f.payload).map_err(|e| format!("payload: {e}"))?
    };
    let cmd = match f.layer.as_str() {
        "phy" => Command::PhyDataRequest(DataRequest { params, payload }),
        "ss" => Command::SsDataRequest(SsDataRequest {
            params,
            header_length: u8::try_from(number("header length", &f.header_length)?)
                .map_err(|_| "header length: 0 to 255".to_string())?,
            header_and_payload: payload,
        }),
        _ => Command::DlDataRequest(DataRequest { params, payload }),
    };
    if cmd.data().len() > 255 {
        return Err(format!(
            "the request carries {} bytes; a local frame carries at most 255",
            cmd.data().len()
        ));
    }
    validate::check_request(&cmd, dl_crc_len).map_err(|r| r.reason)?;
    Ok(cmd)
}

#[component]
fn DataRequestCard() -> impl IntoView {
    let c = use_console();
    // The form's inputs, each a signal of a type the page has anyway,
    // made a [`Form`] when sent.
    let text = |t: &str| signal(t.to_string());
    let layer = text("dl");
    let modulation = text("0");
    let frequency = text("high");
    let custom_hz = text("86000");
    let overwrite = signal(false);
    let gain = text("");
    let zc = signal(false);
    let header_length = text("4");
    let kind = text("text");
    let payload = text("hello street");
    let form = move || Form {
        layer: layer.get_untracked(),
        modulation: modulation.get_untracked(),
        frequency: frequency.get_untracked(),
        custom_hz: custom_hz.get_untracked(),
        overwrite: overwrite.get_untracked(),
        gain: gain.get_untracked(),
        zc: zc.get_untracked(),
        header_length: header_length.get_untracked(),
        text: kind.get_untracked() == "text",
        payload: payload.get_untracked(),
    };
    // What came of it, and whether that is a problem: two signals of types
    // the page has anyway rather than one `Option<Result<String, String>>`
    // (each signal type brings its own code, docs/console.md "Size").
    let result = signal(None::<String>);
    let problem = signal(false);
    let show = move |r: Result<String, String>| {
        problem.set(r.is_err());
        result.set(Some(r.unwrap_or_else(|e| e)));
    };
    // The DL CRC length of MIB 00h (as last read, else its default) sets
    // how long a DL or SS payload may be (UM0932 Tables 3, 4, 53).
    let dl_crc_len = move || {
        let mc = c
            .modem
            .mib
            .with_untracked(|m| m.get(&(index::MODEM_CONFIG as u16)).cloned());
        let o = plm_core::st7580::mib::object(index::MODEM_CONFIG);
        let data = mc
            .or_else(|| o.map(|o| o.default.to_vec()))
            .unwrap_or_default();
        [1, 2, 4, 4][ModemConfig::decode(&data).crc_length as usize & 3]
    };
    let send = move || {
        let cmd = match build(&form(), dl_crc_len()) {
            Ok(cmd) => cmd,
            Err(why) => {
                show(Err(format!("nothing sent: {why}")));
                return;
            }
        };
        show(Ok(format!("{} sent…", cmd.name().unwrap_or("request"))));
        c.request(cmd, move |o| {
            show(match o {
                Outcome::Answer {
                    command:
                        command @ (Command::PhyDataConfirm(_)
                        | Command::DlDataConfirm(_)
                        | Command::SsDataConfirm(_)),
                    rtt,
                } => {
                    let data = command.data();
                    let fields: Vec<String> = plm_core::mib::describe(confirm_data::LAYOUT, &data)
                        .into_iter()
                        .map(|(f, v)| format!("{}: {v}", f.label))
                        .collect();
                    Ok(format!(
                        "{} after {}: {}",
                        command.name().unwrap_or("confirm"),
                        millis(rtt),
                        fields.join(", ")
                    ))
                }
                Outcome::Answer { command, .. } => {
                    Err(refusal(&command).unwrap_or_else(|| crate::stores::unexpected(&command)))
                }
                Outcome::Failed(why) => Err(why),
            })
        });
    };
    let not_custom = move || frequency.get() != "custom";
    // The modulations but the reserved codes, as the select's options.
    let modulations: String = MODULATIONS
        .iter()
        .enumerate()
        .filter(|(_, n)| **n != "Reserved")
        .map(|(i, n)| format!("<option value=\"{i}\">{n}</option>"))
        .collect();
    view! {
        <article class="card wide" id="data-request">
            <h3>"Send a frame"</h3>
            <p class="muted">
                "PHY_DataRequest, DL_DataRequest or SS_DataRequest (UM0932 Tables 35 and 45), checked as the modem checks it before it is sent."
            </p>
            <div class="form-row">
                <label>
                    "Layer "
                    <select id="data-layer" on:change=set_value(layer)>
                        <option value="phy">"PHY"</option>
                        <option value="dl" selected>"DL"</option>
                        <option value="ss">"SS"</option>
                    </select>
                </label>
                <label>
                    "Modulation "
                    <select
                        id="data-modulation"
                        inner_html=modulations
                        on:change=set_value(modulation)
                    ></select>
                </label>
                <label>
                    "Frequency "
                    <select id="data-frequency" on:change=set_value(frequency)>
                        <option value="high" selected>"MIB high frequency"</option>
                        <option value="low">"MIB low frequency"</option>
                        <option value="custom">"custom"</option>
                    </select>
                </label>
                <label hidden=not_custom>
                    "Hz "
                    {text_input("data-custom-hz", "", "", Some(7), custom_hz)}
                </label>
                <label hidden=not_custom>
                    <input type="checkbox" id="data-overwrite" on:change=set_checked(overwrite)/>
                    " overwrite MIB frequency"
                </label>
                <label title="Empty: the MIB's TX gain">
                    "TX gain "
                    {text_input("data-gain", "", "MIB", Some(3), gain)}
                </label>
                <label>
                    <input type="checkbox" id="data-zc" on:change=set_checked(zc)/>
                    " zero-crossing synchronisation"
                </label>
                <label hidden=move || layer.get() != "ss">
                    "SS header length "
                    {text_input("data-header-length", "", "", Some(3), header_length)}
                </label>
            </div>
            <div class="form-row">
                <label>
                    "Payload as "
                    <select id="data-payload-kind" on:change=set_value(kind)>
                        <option value="text" selected>"text"</option>
                        <option value="hex">"hex"</option>
                    </select>
                </label>
                {text_input("data-payload", "payload", "", Some(60), payload)}
                {super::widgets::button("data-send", "Send", "", send)}
            </div>
            <p id="data-result" class:problem=move || problem.get()>
                {move || result.get().unwrap_or_default()}
            </p>
        </article>
    }
}

/// The indications table's columns and their cells' classes.
const INDICATION_COLUMNS: &[(&str, &str)] = &[
    ("Time", "time"),
    ("Indication", ""),
    ("Modulation", ""),
    ("Channel", ""),
    ("PGA", ""),
    ("SNR (dB)", ""),
    ("ZC delay (13 µs)", ""),
    ("Payload", "hex"),
];

#[component]
fn Indications(tab: RwSignal<String>) -> impl IntoView {
    let c = use_console();
    // Hidden, the plot keeps its points and does not look at the log (as
    // the Traffic table).
    let shown = move || tab.get() == Tab::Data.slug();
    // The indications (how many, the newest INDICATION_ROWS), compared
    // by what they are (as the Traffic table's rows, and of their type: one
    // memo type for both).
    let rows = Memo::new_with_compare(
        move |prev: Option<&(usize, Vec<Arc<Entry>>)>| {
            if let Some(p) = prev.filter(|_| !shown()) {
                return p.clone();
            }
            let mut rows = c.traffic.log.with(|l| {
                l.iter()
                    .filter(|e| {
                        e.decoded
                            .command
                            .as_ref()
                            .and_then(|c| c.as_str())
                            .is_some_and(|c| INDICATIONS.contains(&c))
                    })
                    .cloned()
                    .collect::<Vec<_>>()
            });
            let total = rows.len();
            rows.drain(..total.saturating_sub(INDICATION_ROWS));
            (total, rows)
        },
        crate::traffic::rows_changed,
    );
    view! {
        <article class="card wide" id="data-indications">
            <h3>"Received frames"</h3>
            <p class="muted">
                "Data and sniffer indications from the modem (UM0932 Table 39). With echoing peers (Simulator view) every frame sent comes back."
            </p>
            // The plot, or why there is none, written as HTML in one go;
            // the reading under the pointer.
            <div on:mousemove=super::plot::follow(Box::new(move |_, share| {
                rows.with_untracked(|(_, r)| snr_plot::readout(&snr_plot::layout(&snr_points(r))?, share))
            })) inner_html=move || {
                rows.with(|(_, r)| match snr_plot::layout(&snr_points(r)) {
                    Some(plot) => snr_plot::draw(&plot),
                    None if r.is_empty() => {
                        "<p class=\"muted\" id=\"snr-plot-empty\">No indications yet: send a frame with echoing peers (Simulator view).</p>".to_string()
                    }
                    None => {
                        "<p class=\"muted\" id=\"snr-plot-empty\">No SNR to plot: B-FSK frames carry none, and imported entries may have no time.</p>".to_string()
                    }
                })
            }></div>
            // At most INDICATION_ROWS rows, rewritten when one arrives.
            {text_table("indications-table", INDICATION_COLUMNS, Box::new(move || {
                rows.get()
                    .1
                    .iter()
                    .map(|e| {
                        vec![
                            e.at.map(seconds).unwrap_or_default(),
                            e.title(),
                            field(e, "frame_modulation"),
                            field(e, "rx_channel"),
                            field(e, "pga_value"),
                            field(e, "snr"),
                            field(e, "zc_delay"),
                            spaced(&payload(e)),
                        ]
                    })
                    .collect()
            }))}
        </article>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn form() -> Form {
        Form {
            layer: "dl".into(),
            modulation: "1".into(),
            frequency: "high".into(),
            custom_hz: "86000".into(),
            overwrite: false,
            gain: String::new(),
            zc: false,
            header_length: "4".into(),
            text: true,
            payload: "hi".into(),
        }
    }

    #[test]
    fn a_dl_request_carries_the_options_and_payload() {
        let mut f = form();
        f.frequency = "custom".into();
        f.custom_hz = "110000".into();
        f.gain = "20".into();
        let Ok(Command::DlDataRequest(r)) = build(&f, 4) else {
            panic!("a DL request");
        };
        assert_eq!(r.params.modulation, Modulation::QPsk);
        assert_eq!(r.params.tx_frequency, Some(110_000));
        assert_eq!(r.params.tx_gain, Some(20));
        assert_eq!(r.payload, b"hi");
    }

    #[test]
    fn snr_points_are_the_signed_snr_of_timed_indications() {
        use crate::traffic::TrafficLog;
        use plm_core::decode::decode_all;
        use plm_core::link::{Dialect, Source};
        use plm_core::st7580::{DataIndication, IndicationInfo};
        let indication = |modulation, snr: u8| {
            let info = IndicationInfo {
                modulation,
                snr,
                ..IndicationInfo::default()
            };
            let c = Command::DlDataIndication(DataIndication {
                info,
                payload: b"hi".to_vec(),
            });
            let bytes = c.to_frame().emit(Dialect::St7580).unwrap();
            decode_all(Dialect::St7580, Source::Modem, &bytes)
        };
        let mut log = TrafficLog::default();
        for d in indication(Modulation::QPsk, (-3i8) as u8) {
            log.push(Some(2_500_000), d);
        }
        // B-FSK: SNR byte 255, no meaning (UM0932 Table 39).
        for d in indication(Modulation::BFsk, 0xFF) {
            log.push(Some(3_000_000), d);
        }
        // No time (imported).
        for d in indication(Modulation::BPsk, 7) {
            log.push(None, d);
        }
        let rows: Vec<_> = log.iter().cloned().collect();
        let points = snr_points(&rows);
        assert_eq!(points.len(), 1, "{points:?}");
        assert_eq!(points[0].at, 2_500_000);
        assert_eq!(points[0].snr_db, -3);
        assert_eq!(points[0].kind, snr_plot::Kind::Dl);
    }

    #[test]
    fn what_the_modem_would_refuse_is_not_built() {
        let mut f = form();
        f.frequency = "custom".into();
        f.custom_hz = "200000".into();
        assert_eq!(
            build(&f, 4),
            Err("TX frequency: 200000 is out of range: 3000 to 148500 Hz".into())
        );
        let mut f = form();
        f.gain = "40".into();
        assert!(build(&f, 4)
            .unwrap_err()
            .starts_with("TX gain: 40 is out of range"));
        let mut f = form();
        f.layer = "ss".into();
        f.header_length = "9".into();
        assert!(build(&f, 4).is_err(), "header longer than the buffer");
        let mut f = form();
        f.text = false;
        f.payload = "zz".into();
        assert!(build(&f, 4).unwrap_err().starts_with("payload: "));
    }
}
