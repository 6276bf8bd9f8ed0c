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
pub const WIDTH: i32 = 1320;
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

/// The picture in two parts, each written again only when it changed:
/// its heading and legend, and the street (SVG, empty without lamps).
#[derive(Default, PartialEq)]
pub struct Picture {
    pub head: String,
    pub street: String,
    pub grid: Grid,
}

/// Where the small marks' cells are (more than [`NAMED_MAX`] lamps, drawn
/// with the rows, no element per lamp), and each cell's lamp and words.
#[derive(Default, PartialEq)]
pub struct Grid {
    pub left: i32,
    pub w: i32,
    pub h: i32,
    pub per_row: usize,
    pub cells: Vec<Cell>,
}

/// A small mark's lamp (none when not heard on the line) and tooltip.
#[derive(PartialEq)]
pub struct Cell {
    pub address: Option<Address>,
    pub title: String,
}

impl Grid {
    /// The cell at `x`, `y` of the picture's coordinates (its `viewBox`).
    pub fn at(&self, x: f64, y: f64) -> Option<&Cell> {
        let col = (x - f64::from(self.left)) / f64::from(self.w);
        let row = y / f64::from(self.h);
        if self.w == 0 || col < 0.0 || row < 0.0 || col >= self.per_row as f64 {
            return None;
        }
        self.cells.get(row as usize * self.per_row + col as usize)
    }
}

/// The picture of `fleet` in the order of `poles` (none: address order),
/// the lamp whose page is open (`focus`) marked.
pub fn picture(
    fleet: &BTreeMap<Address, Lamp>,
    poles: Option<&[Pole]>,
    focus: Option<Address>,
) -> Picture {
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
    let mut picture = Picture {
        head: out,
        ..Picture::default()
    };
    if places.is_empty() {
        return picture;
    }
    let named = places.len() <= NAMED_MAX;
    // Cell size, left margin (row numbers when small), marks to a row.
    let (w, h, left) = if named { (110, 80, 0) } else { (22, 26, 34) };
    let per_row = ((WIDTH - left) / w) as usize;
    let rows = places.len().div_ceil(per_row);
    let cy = if named { 24 } else { 9 };
    let mut out = format!(
        "<svg class=\"pk\" viewBox=\"0 0 {WIDTH} {}\" role=\"img\" aria-label=\"the street\">",
        rows as i32 * h
    );
    for (r, row) in places.chunks(per_row).enumerate() {
        let y = r as i32 * h;
        let last = left + (row.len() as i32 - 1) * w + w / 2;
        out.push_str(&format!(
            "<line class=\"pk-cable\" x1=\"{}\" y1=\"{}\" x2=\"{last}\" y2=\"{}\"/>",
            left + w / 2,
            y + cy,
            y + cy
        ));
        if !named {
            out.push_str(&format!(
                "<text class=\"pk-small\" x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>",
                left - 4,
                y + cy + 4,
                r * per_row + 1
            ));
        }
    }
    if named {
        for (i, place) in places.iter().enumerate() {
            let focused = focus == Some(place.address) && place.lamp.is_some();
            let (x, y) = (left + (i % per_row) as i32 * w, (i / per_row) as i32 * h);
            out.push_str(&format!(
                "<g transform=\"translate({x} {y})\"{}",
                lamp(place, cy, w, focused)
            ));
        }
    } else {
        let grid = Grid {
            left,
            w,
            h,
            per_row,
            cells: Vec::new(),
        };
        out.push_str(&small_marks(&places, &grid, cy, focus));
        picture.grid = Grid {
            cells: places
                .iter()
                .map(|p| Cell {
                    address: p.lamp.map(|_| p.address),
                    title: title(p),
                })
                .collect(),
            ..grid
        };
    }
    out.push_str("</svg>");
    picture.street = out;
    picture
}

/// Small marks (more than [`NAMED_MAX`] lamps), drawn as one path per
/// kind of shape for the whole street rather than elements per lamp: 500
/// lamps are a dozen elements to lay out and paint, not 2 500. The lamp
/// under the pointer is found by its cell ([`Grid::at`]).
fn small_marks(places: &[Place], grid: &Grid, cy: i32, focus: Option<Address>) -> String {
    // Path data by class, bottom first: the bars, the rings of the lamps
    // in trouble, then the marks.
    let mut paths: Vec<(&str, String)> = ["pk-track", "pk-snr", "pk-halo"]
        .into_iter()
        .chain(SHAPE_CLASSES)
        .map(|c| (c, String::new()))
        .collect();
    let mut add = |class: &str, d: &str| {
        if let Some((_, all)) = paths.iter_mut().find(|(c, _)| *c == class) {
            all.push_str(d);
        }
    };
    let mut svg = String::new();
    for (i, p) in places.iter().enumerate() {
        let (x, y) = (
            grid.left + (i % grid.per_row) as i32 * grid.w,
            (i / grid.per_row) as i32 * grid.h,
        );
        let (cx, cy) = (x + grid.w / 2, y + cy);
        if focus == Some(p.address) && p.lamp.is_some() {
            svg.push_str(&format!(
                "<rect class=\"pk-hit pk-focus\" x=\"{x}\" y=\"{y}\" width=\"{}\" height=\"{}\"/>",
                grid.w, grid.h
            ));
        }
        let look = p.look();
        let r = if look.in_trouble() { 8 } else { 6 };
        let (track, bar) = snr_bar(p.lamp.and_then(|l| l.snr), cx - 8, y + 19, 16);
        add("pk-track", &track);
        add("pk-snr", &bar);
        if look.in_trouble() {
            add("pk-halo", &circle(cx, cy, halo(r)));
        }
        for (class, d) in shapes(look, cx, cy, r) {
            add(class, &d);
        }
    }
    for (class, d) in paths.iter().filter(|(_, d)| !d.is_empty()) {
        svg.push_str(&format!("<path class=\"{class}\" d=\"{d}\"/>"));
    }
    svg
}

/// One place's mark, words and SNR bar in a cell `w` wide, its cable at
/// `cy` (the cell's coordinates: a group's attributes after its
/// `transform`, and its content); the lamp whose page is open `focused`.
fn lamp(p: &Place, cy: i32, w: i32, focused: bool) -> String {
    let look = p.look();
    let cx = w / 2;
    let name = p.name();
    let dimming = p.lamp.and_then(|l| l.dimming);
    let snr = p.lamp.and_then(|l| l.snr);
    // A lamp not heard has no page to open.
    let address = match p.lamp {
        Some(_) => format!(" data-address=\"{}\"", p.address),
        None => String::new(),
    };
    let mut g = format!(
        " class=\"pk-lamp{}\"{address} data-look=\"{}\"><title>{}</title><rect class=\"pk-hit\" width=\"{w}\" height=\"80\"/>",
        if focused { " pk-focus" } else { "" },
        look_key(look),
        esc(&title(p)),
    );
    let r = if look.in_trouble() { 11 } else { 9 };
    if look.in_trouble() {
        g.push_str(&format!(
            "<path class=\"pk-halo\" d=\"{}\"/>",
            circle(cx, cy, halo(r))
        ));
    }
    g.push_str(&mark(look, cx, cy, r));
    if let Some(m) = p.pole.and_then(|p| p.position) {
        g.push_str(&format!(
            "<text class=\"pk-small\" x=\"{cx}\" y=\"9\">{m} m</text>"
        ));
    }
    let short: String = if name.chars().count() > 15 {
        name.chars().take(14).chain(['…']).collect()
    } else {
        name
    };
    g.push_str(&format!(
        "<text class=\"pk-name\" x=\"{cx}\" y=\"48\">{}</text>",
        esc(&short)
    ));
    if let Some(d) = dimming {
        g.push_str(&format!(
            "<text class=\"pk-small\" x=\"{cx}\" y=\"61\">dim set {d} %</text>"
        ));
    }
    // The bar leaves room for its figure on its right.
    let (track, bar) = snr_bar(snr, cx - 40, 69, 50);
    g.push_str(&format!(
        "<path class=\"pk-track\" d=\"{track}\"/><path class=\"pk-snr\" d=\"{bar}\"/>"
    ));
    if let Some(s) = snr {
        g.push_str(&format!(
            "<text class=\"pk-small pk-db\" x=\"{}\" y=\"73\">{s} dB</text>",
            cx + 14
        ));
    }
    g.push_str("</g>");
    g
}

/// The radius of the ring around the mark of radius `r` of a lamp in
/// trouble.
fn halo(r: i32) -> i32 {
    r + r / 2 + 2
}

/// An SNR bar at `x`, `y`, `full` long at [`SNR_FULL`]: its track and its
/// bar as path data (3 high).
fn snr_bar(snr: Option<i8>, x: i32, y: i32, full: i32) -> (String, String) {
    let len = snr.map_or(0, |s| (i32::from(s).clamp(0, SNR_FULL) * full) / SNR_FULL);
    let bar = |len: i32| format!("M{x} {y}h{len}v3h{}Z", -len);
    (bar(full), bar(len))
}

/// What a place's tooltip says: its name, address and position, its look,
/// the dimming last set and its signal quality.
fn title(p: &Place) -> String {
    let look = p.look();
    let name = p.name();
    let dimming = p.lamp.and_then(|l| l.dimming);
    let snr = p.lamp.and_then(|l| l.snr);
    let mut title = name;
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
    title
}

/// A look's mark centred on `cx`, `cy`, of radius `r`: a disc running, a
/// half disc dimmed, a diamond starting, a ring off, a triangle failed, a
/// dashed ring not answering, a small dot not read.
fn mark(look: Look, cx: i32, cy: i32, r: i32) -> String {
    let mut svg = String::new();
    for (class, d) in shapes(look, cx, cy, r) {
        svg.push_str(&format!("<path class=\"{class}\" d=\"{d}\"/>"));
    }
    svg
}

/// The classes of [`shapes`] in the order they are drawn, bottom first
/// (style.css gives each its colour).
pub const SHAPE_CLASSES: [&str; 7] = [
    "pk-run",
    "pk-ring pk-run",
    "pk-between",
    "pk-ring pk-off",
    "pk-failed",
    "pk-ring pk-silent",
    "pk-unread",
];

/// A look's mark as SVG path data, each with its class (one of
/// [`SHAPE_CLASSES`]).
fn shapes(look: Look, cx: i32, cy: i32, r: i32) -> Vec<(&'static str, String)> {
    let c = SHAPE_CLASSES;
    match look {
        Look::Running => vec![(c[0], circle(cx, cy, r))],
        Look::Dimmed => vec![
            (c[1], circle(cx, cy, r - 1)),
            (
                c[0],
                format!("M{cx} {}A{r} {r} 0 0 0 {cx} {}Z", cy - r, cy + r),
            ),
        ],
        Look::Between => vec![(
            c[2],
            format!(
                "M{cx} {}L{} {cy}L{cx} {}L{} {cy}Z",
                cy - r,
                cx + r,
                cy + r,
                cx - r
            ),
        )],
        Look::Off => vec![(c[3], circle(cx, cy, r - 1))],
        Look::Failed => vec![(
            c[4],
            format!(
                "M{cx} {}L{} {}L{} {}Z",
                cy - r - 1,
                cx + r + 1,
                cy + r - 1,
                cx - r - 1,
                cy + r - 1
            ),
        )],
        Look::Unreachable => vec![(c[5], circle(cx, cy, r - 1))],
        Look::NotRead => vec![(c[6], circle(cx, cy, r / 2))],
    }
}

/// A circle as path data (two arcs), so that many join in one path.
fn circle(cx: i32, cy: i32, r: i32) -> String {
    format!(
        "M{} {cy}a{r} {r} 0 1 0 {} 0a{r} {r} 0 1 0 {} 0",
        cx - r,
        2 * r,
        -2 * r
    )
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

    /// The whole picture as one piece of HTML.
    fn html(fleet: &BTreeMap<Address, Lamp>, poles: Option<&[Pole]>) -> String {
        let p = picture(fleet, poles, None);
        format!("{}{}", p.head, p.street)
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
        assert!(html.contains("d=\"M15 69h33v3h-33Z\""));
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
    fn five_hundred_lamps_fit_in_nine_small_rows_of_a_few_paths() {
        let mut fleet = street(500);
        fleet.get_mut(&a(433)).unwrap().unreachable = Some("silent".into());
        let p = picture(&fleet, None, Some(a(2)));
        let html = format!("{}{}", p.head, p.street);
        assert!(html.contains("viewBox=\"0 0 1320 234\""), "9 rows of 26");
        assert!(order(&html).is_empty(), "no element per lamp");
        // Tracks, bars, the ring in trouble, two kinds of mark: 5 paths
        // besides the legend's 8.
        assert_eq!(p.street.matches("<path").count(), 5);
        assert_eq!(
            html.matches("pk-ring pk-silent").count(),
            2,
            "one in the legend"
        );
        assert!(
            !html.contains("class=\"pk-name\""),
            "no words under small marks"
        );
        assert!(html.contains(">465</text>"), "rows numbered");
        assert!(html.contains("In trouble: 0080e10001b1 not answering"));
        // Lamp 433 is the 433rd cell: row 7, column 26 (58 to a row).
        let cell = p
            .grid
            .at(34.0 + 26.0 * 22.0 + 11.0, 7.0 * 26.0 + 5.0)
            .unwrap();
        assert_eq!(cell.address, Some(a(433)));
        assert_eq!(cell.title, "0080e10001b1: not answering; SNR 20 dB");
        assert!(p.grid.at(20.0, 5.0).is_none(), "the row numbers' margin");
        assert!(p.grid.at(1319.0, 5.0).is_none(), "past the last column");
        assert!(
            p.grid.at(40.0, 9.0 * 26.0 + 1.0).is_none(),
            "below the street"
        );
        assert_eq!(html.matches("pk-focus").count(), 1, "the open lamp's cell");
    }

    #[test]
    fn the_lamp_whose_page_is_open_is_marked() {
        let fleet = street(30);
        let p = picture(&fleet, None, Some(a(7)));
        assert_eq!(p.street.matches("pk-focus").count(), 1);
        assert!(p.street.contains(
            "<g transform=\"translate(660 0)\" class=\"pk-lamp pk-focus\" data-address=\"0080e1000007\""
        ));
        // A lamp not heard has no page to open.
        assert!(!picture(&fleet, None, Some(a(31)))
            .street
            .contains("pk-focus"));
    }
}
