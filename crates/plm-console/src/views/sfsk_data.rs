//! The ST7570's data services: a MAC frame to an address or a group with
//! its credit (CMD_DataRequest in MAC mode, Table 41), a PHY P_SDU
//! (Table 40), and the frames indicated (Tables 37-38), read from
//! [`crate::network::NetworkLog`].

use super::network::send;
use super::seconds;
use super::widgets::{button, note, set_checked, set_value, signal, text_input, text_table};
use crate::network::{address_text, confirm_text};
use crate::stores::use_console;
use leptos::prelude::*;
use plm_core::st7570::fields::{self as f, P_SDU_LEN};
use plm_core::st7570::mac::MAX_M_SDU;
use plm_core::st7570::{Address, Command, Credit, Group, Layer, MacData};

/// The view.
#[component]
pub fn SfskDataView() -> impl IntoView {
    view! {
        <div class="cards">
            <SendCard/>
            <ReceivedCard/>
        </div>
    }
}

/// A destination typed as 3 hex digits or a group's name (Table 6).
pub fn parse_da(text: &str) -> Result<u16, String> {
    let t = text.trim();
    if let Some(g) = Group::ALL
        .into_iter()
        .find(|g| g.name().eq_ignore_ascii_case(t))
    {
        return Ok(g.address());
    }
    let digits = t.trim_end_matches(['h', 'H']);
    match u16::from_str_radix(digits, 16) {
        Ok(a) if a <= 0xFFF && !digits.is_empty() => Ok(a),
        _ => Err(format!(
            "DA is a 12-bit address in hex (000-FFF) or a group: {}",
            Group::ALL.map(|g| g.name()).join(", ")
        )),
    }
}

/// A payload typed as text, or as hex bytes when it starts with `0x` or
/// is given in the hex field.
fn payload(text: &str, hex: bool) -> Result<Vec<u8>, String> {
    if hex {
        plm_core::hex::parse(text).map_err(|e| format!("payload: {e}"))
    } else {
        Ok(text.as_bytes().to_vec())
    }
}

#[component]
fn SendCard() -> impl IntoView {
    let c = use_console();
    let da = signal("001".to_string());
    let ic = signal("0".to_string());
    let text = signal("?".to_string());
    let hex = signal(false);
    let problem = signal(None::<String>);
    let result = signal(None::<String>);
    let layer = move || c.modem.network.with(|n| n.layer());
    let send_frame = move || {
        let layer = c.modem.network.with_untracked(|n| n.layer());
        let data = match payload(&text.get_untracked(), hex.get_untracked()) {
            Ok(d) => d,
            Err(why) => return problem.set(Some(why)),
        };
        let command = match layer {
            Layer::Mac => {
                let da = match parse_da(&da.get_untracked()) {
                    Ok(a) => a,
                    Err(why) => return problem.set(Some(why)),
                };
                if data.is_empty() || data.len() > MAX_M_SDU {
                    return problem.set(Some(format!(
                        "M_SDU is 1..{MAX_M_SDU} bytes, not {}",
                        data.len()
                    )));
                }
                let ic = ic.get_untracked().parse().unwrap_or(0);
                Command::MacDataRequest(MacData {
                    credit: Credit { ic, cc: ic, dc: 0 },
                    // SA is the modem's own (Table 41 sends it as 0).
                    address: Address { sa: 0, da },
                    pad: 0,
                    m_sdu: data,
                })
            }
            Layer::Phy => {
                if data.len() > P_SDU_LEN {
                    return problem.set(Some(format!(
                        "a P_SDU is {P_SDU_LEN} bytes; this is {}",
                        data.len()
                    )));
                }
                let mut p_sdu = data;
                p_sdu.resize(P_SDU_LEN, 0);
                Command::PhyDataRequest { p_sdu }
            }
        };
        problem.set(None);
        result.set(Some("sending…".into()));
        let table = if layer == Layer::Mac {
            &f::MAC_CONFIRM_CODES
        } else {
            &f::PHY_CONFIRM_CODES
        };
        send(c, command, move |r| {
            result.set(Some(match r {
                Ok(Command::DataConfirm { confirm_code }) => {
                    format!("CMD_DataConfirm: {}", confirm_text(table, confirm_code))
                }
                Ok(other) => format!(
                    "answered {}",
                    other.name().unwrap_or("with an unknown code")
                ),
                Err(why) => why,
            }))
        });
    };
    let phy = move || layer() == Layer::Phy;
    // IC 0 to 7 (repetitions), 0 first; only the select changes `ic`.
    const IC_OPTIONS: &str = "<option value=\"0\">0</option><option value=\"1\">1</option><option value=\"2\">2</option><option value=\"3\">3</option><option value=\"4\">4</option><option value=\"5\">5</option><option value=\"6\">6</option><option value=\"7\">7</option>";
    view! {
        <article class="card wide" id="sfsk-send">
            <h3>"Send a frame"</h3>
            <p class="muted">{move || String::from(match layer() {
                Layer::Mac => "MAC mode: CMD_DataRequest (Table 41) to an address or a group of Table 6, with IC repetitions; a Server of the simulated network answers \"?\" with its address and phase, and echoes anything else.",
                Layer::Phy => "PHY mode: CMD_DataRequest (Table 40), one 38-byte P_SDU (padded with 00h).",
            })}</p>
            <div class="form-row">
                <label hidden=phy>"DA "{text_input("sfsk-da", "", "001 or BROADCAST", Some(12), da)}</label>
                <label hidden=phy>"IC "
                    <select id="sfsk-ic" inner_html=IC_OPTIONS on:change=set_value(ic)></select>
                </label>
                <label>"Payload "{text_input("sfsk-payload", "payload", "", None, text)}</label>
                <label><input type="checkbox" id="sfsk-hex" on:change=set_checked(hex)/>" hex"</label>
                {button("sfsk-send-btn", "Send", "", send_frame)}
            </div>
            {note("sfsk-problem", "problem", problem)}
            {note("sfsk-result", "", result)}
        </article>
    }
}

/// A payload as text when it is printable ASCII, else hex.
fn shown(payload: &[u8]) -> String {
    if !payload.is_empty() && payload.iter().all(|b| (0x20..0x7F).contains(b)) {
        // Printable ASCII: each byte is its character (no UTF-8 decoder).
        let text: String = payload.iter().map(|&b| char::from(b)).collect();
        format!("\"{text}\"")
    } else {
        super::spaced(&plm_core::hex::encode(payload))
    }
}

#[component]
fn ReceivedCard() -> impl IntoView {
    let c = use_console();
    let rows = move || {
        c.modem.network.with(|n| {
            n.received
                .iter()
                .rev()
                .map(|r| {
                    let addr = r.address.map_or("–".into(), |(sa, da)| {
                        let to = Group::of(da).map_or(address_text(da), |g| g.name().to_string());
                        format!("{} → {to}", address_text(sa))
                    });
                    let credit = r
                        .credit
                        .map_or("–".into(), |c| format!("{}/{}/{}", c.ic, c.cc, c.dc));
                    vec![seconds(r.at), addr, credit, shown(&r.payload)]
                })
                .collect()
        })
    };
    const COLUMNS: &[(&str, &str)] = &[
        ("When", "time"),
        ("SA → DA", "num"),
        ("IC/CC/DC", "num"),
        ("Payload", "hex"),
    ];
    view! {
        <article class="card wide" id="sfsk-received">
            <h3>"Received frames"</h3>
            {text_table("sfsk-received-table", COLUMNS, Box::new(rows))}
        </article>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_destination_is_hex_or_a_group_name() {
        assert_eq!(parse_da("001"), Ok(1));
        assert_eq!(parse_da(" c00h "), Ok(0xC00));
        assert_eq!(parse_da("broadcast"), Ok(0xFFF));
        assert_eq!(parse_da("NOT-NEW"), Ok(0xFFC));
        for bad in ["", "1000", "xyz", "h"] {
            assert!(parse_da(bad).unwrap_err().contains("12-bit"), "{bad}");
        }
    }
}
