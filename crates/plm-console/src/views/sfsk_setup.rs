//! The ST7570's common set-ups in one card: role and access layer, mains
//! frequency, bit rate, tones and gain, written to 00A1h (Table 137) with
//! the checks of the declarative MIB ([`crate::mibform::build`]), and for
//! a MAC Server its local address (0001h, Table 74).

use super::widgets::{button, note, on_event, signal, text_input};
use crate::mibform::{build, input_text, Texts};
use crate::stores::use_console;
use leptos::prelude::*;
use plm_core::st7570::mib::{index, object, plc};

/// The roles the card offers: operating mode (00A1h byte 0) and access
/// layer mode (byte 12), as [`plc::OPERATING_MODE`] and
/// [`plc::ACCESS_LAYER_MODE`] number them.
const ROLES: [(&str, u8, u8); 6] = [
    ("MAC Client (initiator)", 1, 2),
    ("MAC Server", 2, 2),
    ("MAC Monitor", 3, 2),
    ("PHY Client", 1, 1),
    ("PHY Server", 2, 1),
    ("PHY Monitor", 3, 1),
];

/// A select over `options` (value, label) bound to `value`.
fn choice(
    id: &'static str,
    options: &'static [(&'static str, &'static str)],
    value: RwSignal<String>,
) -> AnyView {
    view! {
        <select id=id on:change=on_event(move |ev| value.set(event_target_value(&ev)))>
            {options.iter().map(|&(v, label)| view! {
                <option value=v selected=move || value.get() == v>{label}</option>
            }).collect_view()}
        </select>
    }
    .into_any()
}

/// The card, on the Modem view of the ST7570 profile.
#[component]
pub fn SetupCard() -> impl IntoView {
    let c = use_console();
    let plc_object = object(index::PLC_CONFIGURATION).expect("00A1h is in Table 71");
    let base = move || {
        c.modem
            .mib
            .with(|m| m.get(&index::PLC_CONFIGURATION).cloned())
            .unwrap_or_else(|| plc_object.default.to_vec())
    };
    let text = |f: &'static plm_core::field::Field| {
        let b = base();
        signal(input_text(f, &b))
    };
    let role = signal("0".to_string());
    let mains = text(&plc::MAINS_FREQUENCY);
    let bit_rate = text(&plc::BIT_RATE);
    let f0 = text(&plc::F0);
    let f1 = text(&plc::F1);
    let gain = text(&plc::TARGET_OUTPUT_GAIN);
    let address = signal("001".to_string());
    let problem = signal(None::<String>);
    let result = signal(None::<String>);
    let server_mac = move || {
        role.get()
            .parse::<usize>()
            .ok()
            .and_then(|i| ROLES.get(i))
            .is_some_and(|r| r.1 == 2 && r.2 == 2)
    };
    let write = move || {
        let Some(&(name, mode, layer)) = role
            .get_untracked()
            .parse::<usize>()
            .ok()
            .and_then(|i| ROLES.get(i))
        else {
            return;
        };
        let mut texts = Texts::default();
        texts.insert(plc::OPERATING_MODE.name, mode.to_string());
        texts.insert(plc::ACCESS_LAYER_MODE.name, layer.to_string());
        for (f, v) in [
            (&plc::MAINS_FREQUENCY, mains),
            (&plc::BIT_RATE, bit_rate),
            (&plc::F0, f0),
            (&plc::F1, f1),
            (&plc::TARGET_OUTPUT_GAIN, gain),
        ] {
            texts.insert(f.name, v.get_untracked());
        }
        let data = match build(plc_object, &base(), &texts) {
            Ok(d) => d,
            Err(p) => {
                let mut why: Vec<String> =
                    p.fields.iter().map(|(f, r)| format!("{f}: {r}")).collect();
                why.extend(p.object);
                return problem.set(Some(why.join("; ")));
            }
        };
        let local = if mode == 2 && layer == 2 {
            match super::sfsk_data::parse_da(&address.get_untracked()) {
                Ok(a) if (1..0xFFC).contains(&a) => Some(a),
                _ => return problem.set(Some("a Server's local address is 001-FFB (hex)".into())),
            }
        } else {
            None
        };
        problem.set(None);
        result.set(Some("writing…".into()));
        // Written, then read back (which also brings a status message of
        // the new mode): what the modem has is what the card says.
        let wanted = data.clone();
        let check = move |done: String| {
            c.read_mib(index::PLC_CONFIGURATION, move |r| {
                result.set(Some(match r {
                    Ok(v) if v == wanted => format!("{done}, read back: the modem has it"),
                    Ok(_) => format!("{done}, but 00A1h reads back otherwise"),
                    Err(why) => format!("{done}; reading it back failed: {why}"),
                }))
            })
        };
        c.write_mib(index::PLC_CONFIGURATION, data, move |r| match (r, local) {
            (Err(why), _) => result.set(Some(format!("00A1h not written: {why}"))),
            (Ok(_), None) => check(format!("{name}: 00A1h written")),
            (Ok(_), Some(a)) => {
                let mut d = a.to_le_bytes().to_vec();
                d.extend([0, 0]);
                c.write_mib(index::LOCAL_INIT_MAC_ADD, d, move |r| match r {
                    Ok(_) => check(format!("{name} at {a:03X}h: 00A1h and 0001h written")),
                    Err(why) => result.set(Some(format!("00A1h written, 0001h not: {why}"))),
                })
            }
        });
    };
    const MAINS: &[(&str, &str)] = &[("0", "50 Hz"), ("1", "60 Hz")];
    const RATES: &[(&str, &str)] = &[("0", "1200 bit/s"), ("1", "2400 bit/s")];
    const ROLE_OPTIONS: &[(&str, &str)] = &[
        ("0", ROLES[0].0),
        ("1", ROLES[1].0),
        ("2", ROLES[2].0),
        ("3", ROLES[3].0),
        ("4", ROLES[4].0),
        ("5", ROLES[5].0),
    ];
    view! {
        <article class="card wide" id="sfsk-setup">
            <h3>"Set up"</h3>
            <p class="muted">"The common set-ups, written to 00A1h (PLC configuration, Table 137) as one MIB write; a MAC Server also gets its local address (0001h). The modem restarts in the new mode. Every other object is below."</p>
            <div class="form-row">
                <label>"Role "{choice("setup-role", ROLE_OPTIONS, role)}</label>
                <label hidden=move || !server_mac()>"Local address "{text_input("setup-address", "", "001", Some(5), address)}</label>
                <label>"Mains "{choice("setup-mains", MAINS, mains)}</label>
                <label>"Bit rate "{choice("setup-rate", RATES, bit_rate)}</label>
            </div>
            <div class="form-row">
                <label>"f0, Hz "{text_input("setup-f0", "", "", Some(7), f0)}</label>
                <label>"f1, Hz "{text_input("setup-f1", "", "", Some(7), f1)}</label>
                <label>"Gain 0..31 "{text_input("setup-gain", "", "", Some(3), gain)}</label>
                {button("setup-write", "Write set-up", "", write)}
            </div>
            {note("setup-problem", "problem", problem)}
            {note("setup-result", "", result)}
        </article>
    }
}
