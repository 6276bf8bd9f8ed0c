//! The street picture: every lamp in the street's order (a pole list's,
//! [`plm_core::file::poles`], or the addresses' without one), its state
//! by shape and colour ([`Look`]), the dimming last set from this console
//! and its signal quality, written as one piece of HTML and SVG that the
//! Street view sets at once (no element tree per lamp).
//!
//! The layout is a row of marks along a cable, wrapping: with a few lamps
//! each has its name, dimming and SNR written under it; with many (more
//! than [`NAMED_MAX`]) the marks are small, 58 to a row, so 500 fit in 9
//! rows, and a lamp's words are in its tooltip. A lamp in trouble has a
//! larger mark in a ring. The picture's order is never a lamp's signal
//! quality: without a pole list it says so.

use super::Look;
use crate::street::Lamp;
use crate::views::widgets::escape as esc;
use plm_core::app::Address;
use plm_core::file::poles::Pole;
use std::collections::BTreeMap;

/// The most lamps drawn with their words under them.
pub const NAMED_MAX: usize = 36;
/// The picture's width, in CSS pixels at its natural size.
const WIDTH: i32 = 1320;
/// SNR drawn as a full bar, dB.
const SNR_FULL: i32 = 30;

/// One place of the street: a lamp, its pole, or both.
struct Place<'a> {
    address: Address,
    pole: Option<&'a Pole>,
    lamp: Option<&'a Lamp>,
}

impl Place<'_> {
    fn look(&self) -> Look {
        self.lamp.map_or(Look::NotRead, Look::of)
    }

    /// How it is named: its pole, or its address.
    fn name(&self) -> String {
        self.pole
            .map_or_else(|| self.address.to_string(), |p| p.name.clone())
    }
}

/// The street's places: the poles of `poles` in their order, then the
/// lamps found that no pole names, by address.
fn places<'a>(fleet: &'a BTreeMap<Address, Lamp>, poles: &'a [Pole]) -> Vec<Place<'a>> {
    let listed = poles.iter().map(|p| Place {
        address: p.address,
        pole: Some(p),
        lamp: fleet.get(&p.address),
    });
    let rest = fleet
        .values()
        .filter(|l| poles.iter().all(|p| p.address != l.address))
        .map(|l| Place {
            address: l.address,
            pole: None,
            lamp: Some(l),
        });
    listed.chain(rest).collect()
}

/// The picture of `fleet` in the order of `poles` (none: address order).
pub fn html(fleet: &BTreeMap<Address, Lamp>, poles: Option<&[Pole]>) -> String {
    let places = places(fleet, poles.unwrap_or_default());
    let mut counts = [0usize; Look::ALL.len()];
    for p in &places {
        counts[Look::ALL.iter().position(|l| *l == p.look()).unwrap_or(0)] += 1;
    }
    let order = match poles {
        None => {
            "Address order (no pole list): import one to see the lamps in their places".to_string()
        }
        Some(list) => {
            let unlisted = places.len() - list.len();
            let unheard = list
                .iter()
                .filter(|p| !fleet.contains_key(&p.address))
                .count();
            let mut s = format!("Pole order: the pole list's {} pole(s)", list.len());
            if unlisted > 0 {
                s.push_str(&format!(", then {unlisted} lamp(s) not in it, by address"));
            }
            if unheard > 0 {
                s.push_str(&format!("; {unheard} listed lamp(s) not heard on the line"));
            }
            s
        }
    };
    let mut out = format!(
        "<div class=\"pk-head\"><span id=\"street-order\">{}</span>",
        esc(&order)
    );
    let trouble: Vec<String> = places
        .iter()
        .filter(|p| p.look().in_trouble())
        .map(|p| format!("{} {}", p.name(), p.look().name()))
        .collect();
    if !trouble.is_empty() {
        let mut t = trouble[..trouble.len().min(6)].join(", ");
        if trouble.len() > 6 {
            t.push_str(&format!(" and {} more", trouble.len() - 6));
        }
        out.push_str(&format!(
            "<b id=\"street-trouble\" class=\"problem\">In trouble: {}</b>",
            esc(&t)
        ));
    }
    out.push_str("</div><div class=\"pk-legend\">");
    for (look, n) in Look::ALL.iter().zip(counts) {
        out.push_str(&format!(
            "<span><svg viewBox=\"-10 -10 20 20\" width=\"14\" height=\"14\">{}</svg> {} {n}</span>",
            mark(*look, 0, 0, 8),
            look.name()
        ));
    }
    out.push_str(
        "<span>bar: SNR, 0 to 30 dB</span><span>dim set: as last set from this console (the board has no dimming read)</span></div>",
    );
    if places.is_empty() {
        return out;
    }
    let named = places.len() <= NAMED_MAX;
    // Cell size, left margin (row numbers when small), marks to a row.
    let (w, h, left) = if named { (110, 80, 0) } else { (22, 26, 34) };
    let per_row = ((WIDTH - left) / w) as usize;
    let rows = places.len().div_ceil(per_row);
    let height = rows as i32 * h;
    out.push_str(&format!(
        "<svg class=\"pk\" viewBox=\"0 0 {WIDTH} {height}\" role=\"img\" aria-label=\"the street\">"
    ));
    for (r, row) in places.chunks(per_row).enumerate() {
        let y = r as i32 * h;
        let cy = y + if named { 24 } else { 9 };
        let last = left + (row.len() as i32 - 1) * w + w / 2;
        out.push_str(&format!(
            "<line class=\"pk-cable\" x1=\"{}\" y1=\"{cy}\" x2=\"{last}\" y2=\"{cy}\"/>",
            left + w / 2
        ));
        if !named {
            out.push_str(&format!(
                "<text class=\"pk-small\" x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>",
                left - 4,
                cy + 4,
                r * per_row + 1
            ));
        }
        for (i, place) in row.iter().enumerate() {
            let x = left + i as i32 * w;
            out.push_str(&lamp(place, x, y, cy, w, named));
        }
    }
    out.push_str("</svg>");
    out
}

/// One place's mark, words and SNR bar, in its cell at `x`, `y`.
fn lamp(p: &Place, x: i32, y: i32, cy: i32, w: i32, named: bool) -> String {
    let look = p.look();
    let cx = x + w / 2;
    let name = p.name();
    let dimming = p.lamp.and_then(|l| l.dimming);
    let snr = p.lamp.and_then(|l| l.snr);
    let mut title = name.clone();
    if p.pole.is_some() {
        title.push_str(&format!(" ({})", p.address));
    }
    if let Some(m) = p.pole.and_then(|p| p.position) {
        title.push_str(&format!(", {m} m"));
    }
    title.push_str(&format!(": {}", look.name()));
    if p.lamp.is_none() {
        title.push_str(" (not heard on the line)");
    }
    if let Some(d) = dimming {
        title.push_str(&format!(
            "; dim set {d} % from this console (the board has no dimming read)"
        ));
    }
    if let Some(s) = snr {
        title.push_str(&format!("; SNR {s} dB"));
    }
    // A lamp not heard has no page to open.
    let address = match p.lamp {
        Some(_) => format!(" data-address=\"{}\"", p.address),
        None => String::new(),
    };
    let mut g = format!(
        "<g class=\"pk-lamp\"{address} data-look=\"{}\"><title>{}</title><rect class=\"pk-hit\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{}\"/>",
        look_key(look),
        esc(&title),
        if named { 80 } else { 26 }
    );
    let r = match (named, look.in_trouble()) {
        (true, true) => 11,
        (true, false) => 9,
        (false, true) => 8,
        (false, false) => 6,
    };
    if look.in_trouble() {
        g.push_str(&format!(
            "<circle class=\"pk-halo\" cx=\"{cx}\" cy=\"{cy}\" r=\"{}\"/>",
            r + r / 2 + 2
        ));
    }
    g.push_str(&mark(look, cx, cy, r));
    let bar = |at: i32, full: i32| {
        let len = snr.map_or(0, |s| (i32::from(s).clamp(0, SNR_FULL) * full) / SNR_FULL);
        // Named, the bar leaves room for its figure on its right.
        let x = if named { cx - 40 } else { cx - full / 2 };
        format!(
            "<rect class=\"pk-track\" x=\"{x}\" y=\"{at}\" width=\"{full}\" height=\"3\"/><rect class=\"pk-snr\" x=\"{x}\" y=\"{at}\" width=\"{len}\" height=\"3\"/>"
        )
    };
    if named {
        if let Some(m) = p.pole.and_then(|p| p.position) {
            g.push_str(&format!(
                "<text class=\"pk-small\" x=\"{cx}\" y=\"{}\">{m} m</text>",
                y + 9
            ));
        }
        let short: String = if name.chars().count() > 15 {
            name.chars().take(14).chain(['…']).collect()
        } else {
            name
        };
        g.push_str(&format!(
            "<text class=\"pk-name\" x=\"{cx}\" y=\"{}\">{}</text>",
            y + 48,
            esc(&short)
        ));
        if let Some(d) = dimming {
            g.push_str(&format!(
                "<text class=\"pk-small\" x=\"{cx}\" y=\"{}\">dim set {d} %</text>",
                y + 61
            ));
        }
        g.push_str(&bar(y + 69, 50));
        if let Some(s) = snr {
            g.push_str(&format!(
                "<text class=\"pk-small pk-db\" x=\"{}\" y=\"{}\">{s} dB</text>",
                cx + 14,
                y + 73
            ));
        }
    } else {
        g.push_str(&bar(y + 19, 16));
    }
    g.push_str("</g>");
    g
}

/// A look's mark centred on `cx`, `cy`, of radius `r`: a disc running, a
/// half disc dimmed, a diamond starting, a ring off, a triangle failed, a
/// dashed ring not answering, a small dot not read.
fn mark(look: Look, cx: i32, cy: i32, r: i32) -> String {
    let key = look_key(look);
    match look {
        Look::Running => format!("<circle class=\"pk-{key}\" cx=\"{cx}\" cy=\"{cy}\" r=\"{r}\"/>"),
        Look::Dimmed => format!(
            "<circle class=\"pk-ring pk-run\" cx=\"{cx}\" cy=\"{cy}\" r=\"{}\"/><path class=\"pk-run\" d=\"M{cx} {}A{r} {r} 0 0 0 {cx} {}Z\"/>",
            r - 1,
            cy - r,
            cy + r
        ),
        Look::Between => format!(
            "<path class=\"pk-{key}\" d=\"M{cx} {}L{} {cy}L{cx} {}L{} {cy}Z\"/>",
            cy - r,
            cx + r,
            cy + r,
            cx - r
        ),
        Look::Off => format!(
            "<circle class=\"pk-ring pk-{key}\" cx=\"{cx}\" cy=\"{cy}\" r=\"{}\"/>",
            r - 1
        ),
        Look::Failed => format!(
            "<path class=\"pk-{key}\" d=\"M{cx} {}L{} {}L{} {}Z\"/>",
            cy - r - 1,
            cx + r + 1,
            cy + r - 1,
            cx - r - 1,
            cy + r - 1
        ),
        Look::Unreachable => format!(
            "<circle class=\"pk-ring pk-{key}\" cx=\"{cx}\" cy=\"{cy}\" r=\"{}\"/>",
            r - 1
        ),
        Look::NotRead => format!(
            "<circle class=\"pk-{key}\" cx=\"{cx}\" cy=\"{cy}\" r=\"{}\"/>",
            r / 2
        ),
    }
}

/// A look as a word for classes and `data-look`.
fn look_key(look: Look) -> &'static str {
    match look {
        Look::Running => "run",
        Look::Dimmed => "dim",
        Look::Between => "between",
        Look::Off => "off",
        Look::Failed => "failed",
        Look::Unreachable => "silent",
        Look::NotRead => "unread",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::app::Ballast;

    fn a(n: u64) -> Address {
        Address::from_u64(0x0080_e100_0000 + n)
    }

    /// A street of `n` lamps, read and running, SNR 20 dB.
    fn street(n: u64) -> BTreeMap<Address, Lamp> {
        (1..=n)
            .map(|i| {
                let lamp = Lamp {
                    address: a(i),
                    ballast: Some(Ballast {
                        status: 6,
                        ..Ballast::default()
                    }),
                    snr: Some(20),
                    ..Lamp::default()
                };
                (a(i), lamp)
            })
            .collect()
    }

    /// The addresses of the clickable lamps, in the picture's order.
    fn order(html: &str) -> Vec<String> {
        html.split("data-address=\"")
            .skip(1)
            .map(|s| s[..12].to_string())
            .collect()
    }

    #[test]
    fn without_a_pole_list_the_order_is_the_addresses_and_it_says_so() {
        let html = html(&street(12), None);
        assert!(html.contains("Address order (no pole list)"));
        assert_eq!(
            order(&html),
            (1..=12).map(|i| a(i).to_string()).collect::<Vec<_>>()
        );
        // Twelve named lamps in one row, each with its SNR bar (20 of 30 dB).
        assert!(html.contains("viewBox=\"0 0 1320 80\""), "{html}");
        assert_eq!(html.matches("class=\"pk-snr\"").count(), 12);
        assert!(html.contains("width=\"33\" height=\"3\""));
        assert_eq!(html.matches(">20 dB</text>").count(), 12);
        assert!(html.contains("running 12"));
    }

    #[test]
    fn a_pole_list_orders_names_and_places_the_lamps() {
        let fleet = street(4);
        let poles = vec![
            Pole {
                address: a(3),
                name: "P1 <north>".into(),
                position: Some(0),
            },
            Pole {
                address: a(9),
                name: "P2".into(),
                position: Some(30),
            },
            Pole {
                address: a(1),
                name: "P3".into(),
                position: None,
            },
        ];
        let html = html(&fleet, Some(&poles));
        // Listed first in the list's order, then the others by address;
        // the listed lamp not heard is drawn, not clickable.
        assert_eq!(
            order(&html),
            [a(3), a(1), a(2), a(4)].map(|a| a.to_string())
        );
        assert!(html.contains(
            "Pole order: the pole list's 3 pole(s), then 2 lamp(s) not in it, by address; 1 listed lamp(s) not heard on the line"
        ));
        assert!(html.contains("P1 &lt;north&gt;"));
        assert!(html.contains(">30 m</text>"));
        assert!(html.contains(
            "<title>P2 (0080e1000009), 30 m: not read yet (not heard on the line)</title>"
        ));
    }

    #[test]
    fn each_state_has_its_shape_and_trouble_stands_out() {
        let mut fleet = street(6);
        let lamp = |f: &mut BTreeMap<Address, Lamp>, n| f.get_mut(&a(n)).unwrap().clone();
        let mut l = lamp(&mut fleet, 2);
        l.dimming = Some(60);
        fleet.insert(a(2), l);
        let mut l = lamp(&mut fleet, 3);
        l.ballast = Some(Ballast {
            status: 8,
            ..Ballast::default()
        });
        fleet.insert(a(3), l);
        let mut l = lamp(&mut fleet, 4);
        l.unreachable = Some("silent".into());
        fleet.insert(a(4), l);
        let mut l = lamp(&mut fleet, 5);
        l.ballast = None;
        fleet.insert(a(5), l);
        let mut l = lamp(&mut fleet, 6);
        l.ballast = Some(Ballast::default());
        fleet.insert(a(6), l);
        let html = html(&fleet, None);
        let looks: Vec<&str> = html
            .split("data-look=\"")
            .skip(1)
            .map(|s| &s[..s.find('"').unwrap()])
            .collect();
        assert_eq!(looks, ["run", "dim", "failed", "silent", "unread", "off"]);
        assert!(html.contains(">dim set 60 %</text>"));
        assert!(html.contains("<path class=\"pk-failed\""));
        assert!(html.contains("pk-ring pk-silent"));
        // Failed and silent lamps: a larger mark in a ring, and named.
        assert_eq!(html.matches("class=\"pk-halo\"").count(), 2);
        assert!(html.contains("In trouble: 0080e1000003 failed, 0080e1000004 not answering"));
    }

    #[test]
    fn five_hundred_lamps_fit_in_nine_small_rows() {
        let mut fleet = street(500);
        fleet.get_mut(&a(433)).unwrap().unreachable = Some("silent".into());
        let html = html(&fleet, None);
        assert!(html.contains("viewBox=\"0 0 1320 234\""), "9 rows of 26");
        assert_eq!(order(&html).len(), 500);
        assert!(
            !html.contains("class=\"pk-name\""),
            "no words under small marks"
        );
        assert!(html.contains("<title>0080e10001b1: not answering; SNR 20 dB</title>"));
        assert!(html.contains(">465</text>"), "rows numbered");
        assert!(html.contains("In trouble: 0080e10001b1 not answering"));
    }
}
