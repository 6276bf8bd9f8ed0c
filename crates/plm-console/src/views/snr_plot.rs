//! SNR of the received frames over time, as an SVG drawing. The geometry
//! (axes, ticks, coordinates) is plain functions; [`draw`] only turns a
//! [`Plot`] into elements.

use super::seconds;
use plm_core::time::Instant;

/// Indications plotted at most (the newest).
pub const MAX_POINTS: usize = 500;

/// Size of the drawing (SVG user units; CSS scales it down on narrow pages).
pub const WIDTH: f64 = 960.0;
/// See [`WIDTH`].
pub const HEIGHT: f64 = 230.0;
/// Plot area edges: room left of it for the dB labels and title, above it
/// for the legend, below it for the time labels and title.
const LEFT: f64 = 58.0;
const RIGHT: f64 = WIDTH - 14.0;
const TOP: f64 = 30.0;
const BOTTOM: f64 = HEIGHT - 46.0;
/// Space between the plot area's edges and the ends of the axis ranges, so
/// markers on a tick at an end do not sit on the frame.
const INSET: f64 = 8.0;
/// Marker radius.
pub const RADIUS: f64 = 4.0;
/// About how many tick intervals an axis gets.
const INTERVALS: f64 = 5.0;

/// Which indication a point comes from; one marker class each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// PHY_DataIndication.
    Phy,
    /// DL_DataIndication.
    Dl,
    /// SS_DataIndication.
    Ss,
    /// DL_SnifferIndication or SS_SnifferIndication.
    Sniffer,
}

impl Kind {
    /// In legend order.
    pub const ALL: [Kind; 4] = [Kind::Phy, Kind::Dl, Kind::Ss, Kind::Sniffer];

    /// The kind of an indication by its manual name; `None` for others.
    pub fn of(indication: &str) -> Option<Kind> {
        Some(match indication {
            "PHY_DataIndication" => Kind::Phy,
            "DL_DataIndication" => Kind::Dl,
            "SS_DataIndication" => Kind::Ss,
            "DL_SnifferIndication" | "SS_SnifferIndication" => Kind::Sniffer,
            _ => return None,
        })
    }

    /// Legend text.
    pub fn label(self) -> &'static str {
        match self {
            Kind::Phy => "PHY",
            Kind::Dl => "DL",
            Kind::Ss => "SS",
            Kind::Sniffer => "sniffer",
        }
    }

    /// CSS class of its markers.
    pub fn class(self) -> &'static str {
        match self {
            Kind::Phy => "kind-phy",
            Kind::Dl => "kind-dl",
            Kind::Ss => "kind-ss",
            Kind::Sniffer => "kind-sniffer",
        }
    }
}

/// One received frame's SNR.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// When it was received, µs on the transport's clock.
    pub at: Instant,
    /// SNR in dB (UM0932 Table 39: byte 1 of IndicationData, signed).
    pub snr_db: i8,
    /// The indication's manual name.
    pub indication: String,
    /// Its kind.
    pub kind: Kind,
}

impl Point {
    /// A point, `None` if `indication` is no data or sniffer indication.
    pub fn new(at: Instant, snr_db: i8, indication: &str) -> Option<Point> {
        Some(Point {
            at,
            snr_db,
            indication: indication.to_string(),
            kind: Kind::of(indication)?,
        })
    }
}

/// An axis: its range (from the first to the last tick) and ticks.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The first tick.
    pub lo: f64,
    /// The last tick.
    pub hi: f64,
    /// Between ticks.
    pub step: f64,
    /// Tick values, `lo` to `hi`.
    pub ticks: Vec<f64>,
}

/// The smallest 1, 2 or 5 × 10ⁿ that is at least `raw` (`raw` > 0).
pub fn nice_step(raw: f64) -> f64 {
    // The power of ten at or below `raw`, by steps (no libm log and pow in
    // the console's wasm for this).
    let mut magnitude = 1.0;
    while magnitude * 10.0 <= raw {
        magnitude *= 10.0;
    }
    while magnitude > raw {
        magnitude /= 10.0;
    }
    let n = raw / magnitude;
    // The epsilon keeps 0.2 / 0.1 from becoming 5 by a rounding error.
    let nice = [1.0, 2.0, 5.0]
        .into_iter()
        .find(|&m| n <= m * (1.0 + 1e-9))
        .unwrap_or(10.0);
    nice * magnitude
}

/// What an axis needs beyond its data range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    /// A narrower range (one point, or all at one value) is widened to
    /// this around its middle.
    pub min_span: f64,
    /// No step is smaller.
    pub min_step: f64,
    /// Widening never goes below this (unless the data does).
    pub floor: f64,
}

/// The time axis in seconds: one point still gets a second of axis, and
/// the transport's clock starts at 0.
pub const TIME: Spec = Spec {
    min_span: 1.0,
    min_step: 1e-6,
    floor: 0.0,
};

/// The SNR axis in dB: whole dB (a signed byte, UM0932 Table 39).
pub const SNR: Spec = Spec {
    min_span: 2.0,
    min_step: 1.0,
    floor: f64::NEG_INFINITY,
};

/// An axis with "nice" ticks whose range includes `lo..=hi`.
pub fn nice_axis(lo: f64, hi: f64, spec: &Spec) -> Axis {
    let (mut lo, mut hi) = (lo.min(hi), lo.max(hi));
    if hi - lo < spec.min_span {
        let floor = spec.floor.min(lo);
        lo = ((lo + hi) / 2.0 - spec.min_span / 2.0).max(floor);
        hi = lo + spec.min_span;
    }
    let step = nice_step(((hi - lo) / INTERVALS).max(spec.min_step));
    let first = (lo / step).floor() as i64;
    let last = (hi / step).ceil() as i64;
    Axis {
        lo: first as f64 * step,
        hi: last as f64 * step,
        step,
        ticks: (first..=last).map(|i| i as f64 * step).collect(),
    }
}

/// A tick value with as many decimals as its step needs (`2.6`, `20`).
pub fn tick_label(value: f64, step: f64) -> String {
    let (mut decimals, mut s) = (0, step);
    while s < 1.0 - 1e-9 && decimals < 6 {
        s *= 10.0;
        decimals += 1;
    }
    super::fixed(value, decimals as u32)
}

/// Maps `axis.lo..=axis.hi` onto `from..=to` (pixels; `to` < `from` flips).
fn scale(axis: &Axis, value: f64, from: f64, to: f64) -> f64 {
    from + (value - axis.lo) / (axis.hi - axis.lo) * (to - from)
}

/// A tick ready to draw: where (x for time, y for dB) and its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Pixel position along its axis.
    pub at: f64,
    /// Its value as text.
    pub label: String,
}

/// A marker ready to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Centre x.
    pub cx: f64,
    /// Centre y.
    pub cy: f64,
    /// Its kind (class).
    pub kind: Kind,
    /// Hover text: time, indication and SNR.
    pub title: String,
}

/// Everything the drawing shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    /// Time axis, seconds.
    pub x: Axis,
    /// SNR axis, dB.
    pub y: Axis,
    /// Time ticks (x pixels).
    pub x_ticks: Vec<Tick>,
    /// SNR ticks (y pixels).
    pub y_ticks: Vec<Tick>,
    /// One per plotted indication, oldest first.
    pub markers: Vec<Marker>,
    /// The kinds present, with the x of their legend entry.
    pub legend: Vec<(Kind, f64)>,
    /// How many are plotted, of how many.
    pub count: String,
}

/// Horizontal position of a time in seconds.
fn x_of(axis: &Axis, s: f64) -> f64 {
    scale(axis, s, LEFT + INSET, RIGHT - INSET)
}

/// Vertical position of an SNR in dB (up is more).
fn y_of(axis: &Axis, db: f64) -> f64 {
    scale(axis, db, BOTTOM - INSET, TOP + INSET)
}

/// The plot of the newest [`MAX_POINTS`] points; `None` when there are none.
pub fn layout(points: &[Point]) -> Option<Plot> {
    let shown = &points[points.len().saturating_sub(MAX_POINTS)..];
    let first = shown.first()?;
    let secs = |p: &Point| p.at as f64 / 1e6;
    let (t0, t1) = shown.iter().fold((secs(first), secs(first)), |(a, b), p| {
        (a.min(secs(p)), b.max(secs(p)))
    });
    let (s0, s1) = shown
        .iter()
        .fold((first.snr_db, first.snr_db), |(a, b), p| {
            (a.min(p.snr_db), b.max(p.snr_db))
        });
    let x = nice_axis(t0, t1, &TIME);
    let y = nice_axis(s0 as f64, s1 as f64, &SNR);
    let x_ticks = x
        .ticks
        .iter()
        .map(|&t| Tick {
            at: x_of(&x, t),
            label: tick_label(t, x.step),
        })
        .collect();
    let y_ticks = y
        .ticks
        .iter()
        .map(|&v| Tick {
            at: y_of(&y, v),
            label: tick_label(v, y.step),
        })
        .collect();
    let markers = shown
        .iter()
        .map(|p| Marker {
            cx: x_of(&x, secs(p)),
            cy: y_of(&y, p.snr_db as f64),
            kind: p.kind,
            title: format!("{}: {}, SNR {} dB", seconds(p.at), p.indication, p.snr_db),
        })
        .collect();
    let mut legend = Vec::new();
    let mut at = LEFT;
    for kind in Kind::ALL {
        if shown.iter().any(|p| p.kind == kind) {
            legend.push((kind, at));
            // A marker, a gap, the label at about 7 units a letter, a gap.
            at += 3.0 * RADIUS + 7.0 * kind.label().len() as f64 + 20.0;
        }
    }
    let count = match (shown.len(), points.len()) {
        (1, 1) => "1 indication".to_string(),
        (n, all) if n == all => format!("{n} indications"),
        (n, all) => format!("the last {n} of {all} indications"),
    };
    Some(Plot {
        x,
        y,
        x_ticks,
        y_ticks,
        markers,
        legend,
        count,
    })
}

/// A coordinate as attribute text.
fn n(v: f64) -> String {
    super::fixed(v, 1)
}

/// The drawing as HTML: `<svg id="snr-plot">` with one `circle.snr-point`
/// per marker. Written as text in one go (as the tables of text): a
/// drawing of elements cost the console's wasm a copy of each element's
/// code.
pub fn draw(plot: &Plot) -> String {
    use super::widgets::escape;
    use std::fmt::Write;
    let middle = (TOP + BOTTOM) / 2.0;
    let mut h = format!(
        "<svg id=\"snr-plot\" class=\"snr-plot\" viewBox=\"0 0 {} {}\" role=\"img\" aria-label=\"SNR of the received frames over time\">",
        n(WIDTH),
        n(HEIGHT)
    );
    let line = |h: &mut String, class: &str, x1: f64, x2: f64, y1: f64, y2: f64| {
        let _ = write!(
            h,
            "<line class=\"{class}\" x1=\"{}\" x2=\"{}\" y1=\"{}\" y2=\"{}\"></line>",
            n(x1),
            n(x2),
            n(y1),
            n(y2)
        );
    };
    let text = |h: &mut String, class: &str, x: f64, y: f64, extra: &str, body: &str| {
        let _ = write!(
            h,
            "<text class=\"{class}\" x=\"{}\" y=\"{}\"{extra}>{}</text>",
            n(x),
            n(y),
            escape(body)
        );
    };
    for t in &plot.y_ticks {
        line(&mut h, "snr-grid", LEFT, RIGHT, t.at, t.at);
        text(
            &mut h,
            "snr-tick snr-y-tick",
            LEFT - 6.0,
            t.at,
            "",
            &t.label,
        );
    }
    for t in &plot.x_ticks {
        line(&mut h, "snr-axis", t.at, t.at, BOTTOM, BOTTOM + 4.0);
        text(
            &mut h,
            "snr-tick snr-x-tick",
            t.at,
            BOTTOM + 17.0,
            "",
            &t.label,
        );
    }
    line(&mut h, "snr-axis", LEFT, LEFT, TOP, BOTTOM);
    line(&mut h, "snr-axis", LEFT, RIGHT, BOTTOM, BOTTOM);
    text(
        &mut h,
        "snr-title",
        (LEFT + RIGHT) / 2.0,
        HEIGHT - 6.0,
        "",
        "time (s)",
    );
    let rotate = format!(" transform=\"rotate(-90 16 {})\"", n(middle));
    text(&mut h, "snr-title", 16.0, middle, &rotate, "SNR (dB)");
    let circle = |h: &mut String, class: &str, kind: Kind, cx: f64, cy: f64, title: &str| {
        let _ = write!(
            h,
            "<circle class=\"{class} {}\" cx=\"{}\" cy=\"{}\" r=\"{}\">{title}</circle>",
            kind.class(),
            n(cx),
            n(cy),
            n(RADIUS)
        );
    };
    for &(kind, x) in &plot.legend {
        circle(&mut h, "snr-key", kind, x + RADIUS, TOP - 14.0, "");
        text(
            &mut h,
            "snr-legend",
            x + 2.0 * RADIUS + 5.0,
            TOP - 14.0,
            "",
            kind.label(),
        );
    }
    text(&mut h, "snr-count", RIGHT, TOP - 14.0, "", &plot.count);
    for m in &plot.markers {
        let title = format!("<title>{}</title>", escape(&m.title));
        circle(&mut h, "snr-point", m.kind, m.cx, m.cy, &title);
    }
    h.push_str("</svg>");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    fn ticks(a: &Axis) -> Vec<String> {
        a.ticks.iter().map(|&t| tick_label(t, a.step)).collect()
    }

    fn point(s: f64, db: i8, indication: &str) -> Point {
        Point::new((s * 1e6) as u64, db, indication).unwrap()
    }

    #[test]
    fn steps_are_one_two_or_five_times_a_power_of_ten() {
        assert!(close(nice_step(1.0), 1.0));
        assert!(close(nice_step(1.8), 2.0));
        assert!(close(nice_step(0.2), 0.2));
        assert!(close(nice_step(0.3), 0.5));
        assert!(close(nice_step(2.8), 5.0));
        assert!(close(nice_step(7.0), 10.0));
        assert!(close(nice_step(20.0), 20.0));
        assert!(close(nice_step(0.000_07), 0.000_1));
    }

    #[test]
    fn snr_ticks_cover_the_data_in_whole_db() {
        let a = nice_axis(20.0, 29.0, &SNR);
        assert_eq!(ticks(&a), ["20", "22", "24", "26", "28", "30"]);
        let a = nice_axis(4.0, 18.0, &SNR);
        assert_eq!(ticks(&a), ["0", "5", "10", "15", "20"]);
        // Negative SNR (a signed byte): the range still includes it.
        let a = nice_axis(-3.0, 27.0, &SNR);
        assert_eq!(ticks(&a), ["-10", "0", "10", "20", "30"]);
        // One value: widened to 2 dB, never a step under 1 dB.
        let a = nice_axis(12.0, 12.0, &SNR);
        assert_eq!(ticks(&a), ["11", "12", "13"]);
        assert_eq!((a.lo, a.hi), (11.0, 13.0));
    }

    #[test]
    fn time_ticks_take_the_decimals_their_step_needs() {
        let a = nice_axis(0.0, 100.0, &TIME);
        assert_eq!(ticks(&a), ["0", "20", "40", "60", "80", "100"]);
        // One instant: a second around it.
        let a = nice_axis(3.2, 3.2, &TIME);
        assert_eq!(ticks(&a), ["2.6", "2.8", "3.0", "3.2", "3.4", "3.6", "3.8"]);
        // Near the start of the clock, not before it.
        let a = nice_axis(0.36, 0.36, &TIME);
        assert_eq!(ticks(&a), ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let a = nice_axis(12.31, 14.07, &TIME);
        assert_eq!(ticks(&a), ["12.0", "12.5", "13.0", "13.5", "14.0", "14.5"]);
    }

    #[test]
    fn no_points_no_plot() {
        assert_eq!(layout(&[]), None);
    }

    #[test]
    fn the_ends_of_the_ranges_are_the_ends_of_the_plot_area() {
        let plot = layout(&[
            point(0.0, 10, "DL_DataIndication"),
            point(10.0, 20, "PHY_DataIndication"),
        ])
        .unwrap();
        assert_eq!((plot.x.lo, plot.x.hi), (0.0, 10.0));
        assert_eq!((plot.y.lo, plot.y.hi), (10.0, 20.0));
        let m = &plot.markers;
        assert_eq!((m[0].cx, m[0].cy), (66.0, 176.0));
        assert_eq!((m[1].cx, m[1].cy), (938.0, 38.0));
        assert_eq!(m[0].kind, Kind::Dl);
        assert_eq!(m[0].title, "0.000000 s: DL_DataIndication, SNR 10 dB");
        // Ticks sit where values of the same scale would.
        assert_eq!(plot.x_ticks[0].at, 66.0);
        assert_eq!(plot.x_ticks.last().map(|t| t.at), Some(938.0));
        assert_eq!(plot.y_ticks[0].at, 176.0);
        assert_eq!(plot.y_ticks[0].label, "10");
        // Legend in fixed order, whatever came first.
        let kinds: Vec<Kind> = plot.legend.iter().map(|(k, _)| *k).collect();
        assert_eq!(kinds, [Kind::Phy, Kind::Dl]);
        assert_eq!(plot.count, "2 indications");
    }

    #[test]
    fn one_point_sits_in_the_middle() {
        let plot = layout(&[point(3.2, -4, "SS_SnifferIndication")]).unwrap();
        assert_eq!(ticks(&plot.y), ["-5", "-4", "-3"]);
        let m = &plot.markers[0];
        assert!(close(m.cx, (LEFT + RIGHT) / 2.0), "{}", m.cx);
        assert!(close(m.cy, (TOP + BOTTOM) / 2.0), "{}", m.cy);
        assert_eq!(m.kind, Kind::Sniffer);
        assert_eq!(m.title, "3.200000 s: SS_SnifferIndication, SNR -4 dB");
        assert_eq!(plot.count, "1 indication");
    }

    #[test]
    fn only_the_newest_are_plotted() {
        let points: Vec<Point> = (0..600)
            .map(|i| point(i as f64, (i % 30) as i8, "DL_DataIndication"))
            .collect();
        let plot = layout(&points).unwrap();
        assert_eq!(plot.markers.len(), MAX_POINTS);
        assert_eq!(plot.x.lo, 100.0);
        assert_eq!(plot.x.hi, 600.0);
        assert_eq!(plot.count, "the last 500 of 600 indications");
    }

    #[test]
    fn kinds_by_indication_name() {
        assert_eq!(Kind::of("PHY_DataIndication"), Some(Kind::Phy));
        assert_eq!(Kind::of("DL_SnifferIndication"), Some(Kind::Sniffer));
        assert_eq!(Kind::of("SS_DataIndication"), Some(Kind::Ss));
        assert_eq!(Kind::of("DL_DataConfirm"), None);
        assert_eq!(Point::new(0, 1, "PingConfirm"), None);
    }
}
