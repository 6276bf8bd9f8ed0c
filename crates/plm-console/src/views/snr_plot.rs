//! SNR of the received frames over time (the Data view), drawn with the
//! console's plots ([`super::plot`]): time on the transport's clock, as
//! the table of indications and the Traffic log show it. The geometry is
//! plain functions; [`draw`] only turns a [`Plot`] into SVG.

use super::plot::{self, nice_axis, Axis, Frame};
use super::seconds;
use plm_core::time::Instant;

/// Indications plotted at most (the newest).
pub const MAX_POINTS: usize = 500;

/// The drawing (SVG user units; CSS scales it down on narrow pages): room
/// left of the plot area for the dB labels and title, above it for the
/// legend, below it for the time labels and title.
pub const FRAME: Frame = Frame {
    width: 960.0,
    height: 230.0,
    left: 58.0,
    right: 946.0,
    top: 30.0,
    bottom: 184.0,
    inset: 8.0,
};
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
    /// Time axis, seconds on the transport's clock.
    pub x: Axis,
    /// SNR axis, dB.
    pub y: Axis,
    /// One per plotted indication, oldest first.
    pub markers: Vec<Marker>,
    /// The kinds present, with the x of their legend entry.
    pub legend: Vec<(Kind, f64)>,
    /// How many are plotted, of how many, and their least and greatest
    /// SNR.
    pub count: String,
}

/// The plot of the newest [`MAX_POINTS`] points; `None` when there are none.
pub fn layout(points: &[Point]) -> Option<Plot> {
    let shown = &points[points.len().saturating_sub(MAX_POINTS)..];
    let secs = |p: &Point| p.at as f64 / 1e6;
    let (t0, t1) = plot::min_max(shown.iter().map(secs))?;
    let (s0, s1) = plot::min_max(shown.iter().map(|p| f64::from(p.snr_db)))?;
    let x = nice_axis(t0, t1, &plot::SECONDS, INTERVALS);
    let y = nice_axis(s0, s1, &plot::WHOLE, INTERVALS);
    let markers = shown
        .iter()
        .map(|p| Marker {
            cx: FRAME.x(&x, secs(p)),
            cy: FRAME.y(&y, f64::from(p.snr_db)),
            kind: p.kind,
            title: format!("{}: {}, SNR {} dB", seconds(p.at), p.indication, p.snr_db),
        })
        .collect();
    let mut legend = Vec::new();
    let mut at = FRAME.left;
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
    // Whole dB, written out (std's float printing costs the page's wasm).
    let count = format!(
        "{count}, SNR min {} dB, max {} dB",
        super::fixed(s0, 0),
        super::fixed(s1, 0)
    );
    Some(Plot {
        x,
        y,
        markers,
        legend,
        count,
    })
}

/// The reading under a pointer `share` of the way across the drawing:
/// the marker nearest in time, as a [`plot::cursor`].
pub fn readout(plot: &Plot, share: f64) -> Option<String> {
    let xs: Vec<f64> = plot.markers.iter().map(|m| m.cx).collect();
    let m = &plot.markers[plot::nearest(&xs, share * FRAME.width)?];
    Some(plot::cursor(&FRAME, m.cx, m.cy, &m.title))
}

/// The drawing as HTML: `<svg id="snr-plot">` with one `circle.snr-point`
/// per marker.
pub fn draw(p: &Plot) -> String {
    use plot::{n, text};
    use std::fmt::Write;
    let f = &FRAME;
    let mut h = plot::open(
        "snr-plot",
        "snr-plot",
        "SNR of the received frames over time",
        f,
        &p.x,
        plot::tick_label,
        &p.y,
    );
    let middle = (f.top + f.bottom) / 2.0;
    text(
        &mut h,
        "plot-title",
        (f.left + f.right) / 2.0,
        f.height - 6.0,
        "",
        "time on the transport's clock (s), as in the table",
    );
    let rotate = format!(" transform=\"rotate(-90 16 {})\"", n(middle));
    text(&mut h, "plot-title", 16.0, middle, &rotate, "SNR (dB)");
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
    for &(kind, x) in &p.legend {
        circle(&mut h, "snr-key", kind, x + RADIUS, f.top - 14.0, "");
        text(
            &mut h,
            "snr-legend",
            x + 2.0 * RADIUS + 5.0,
            f.top - 14.0,
            "",
            kind.label(),
        );
    }
    text(&mut h, "snr-count", f.right, f.top - 14.0, "", &p.count);
    for m in &p.markers {
        let title = format!("<title>{}</title>", super::widgets::escape(&m.title));
        circle(&mut h, "snr-point", m.kind, m.cx, m.cy, &title);
    }
    plot::close(&mut h);
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    fn ticks(a: &Axis) -> Vec<String> {
        a.ticks
            .iter()
            .map(|&t| plot::tick_label(t, a.step))
            .collect()
    }

    fn point(s: f64, db: i8, indication: &str) -> Point {
        Point::new((s * 1e6) as u64, db, indication).unwrap()
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
        // Legend in fixed order, whatever came first.
        let kinds: Vec<Kind> = plot.legend.iter().map(|(k, _)| *k).collect();
        assert_eq!(kinds, [Kind::Phy, Kind::Dl]);
        assert_eq!(plot.count, "2 indications, SNR min 10 dB, max 20 dB");
        let svg = draw(&plot);
        // Ticks at the ends of the plot area, labelled, and the axis titles.
        assert!(
            svg.contains("<text class=\"plot-tick plot-x\" x=\"938.0\" y=\"198.0\">10</text>"),
            "{svg}"
        );
        assert!(
            svg.contains("<text class=\"plot-tick plot-y\" x=\"53.0\" y=\"176.0\">10</text>"),
            "{svg}"
        );
        assert!(svg.contains(">SNR (dB)</text>"));
        assert!(svg.ends_with("<g class=\"plot-cursor\"></g></svg>"));
    }

    #[test]
    fn the_readout_is_the_marker_nearest_the_pointer() {
        let plot = layout(&[
            point(0.0, 10, "DL_DataIndication"),
            point(10.0, 20, "PHY_DataIndication"),
        ])
        .unwrap();
        let near_end = readout(&plot, 0.8).unwrap();
        assert!(
            near_end.contains("10.000000 s: PHY_DataIndication, SNR 20 dB"),
            "{near_end}"
        );
        assert!(near_end.contains("cx=\"938.0\" cy=\"38.0\""), "{near_end}");
        let near_start = readout(&plot, 0.1).unwrap();
        assert!(
            near_start.contains("0.000000 s: DL_DataIndication, SNR 10 dB"),
            "{near_start}"
        );
    }

    #[test]
    fn one_point_sits_in_the_middle() {
        let plot = layout(&[point(3.2, -4, "SS_SnifferIndication")]).unwrap();
        assert_eq!(ticks(&plot.y), ["-5", "-4", "-3"]);
        let m = &plot.markers[0];
        assert!(close(m.cx, (FRAME.left + FRAME.right) / 2.0), "{}", m.cx);
        assert!(close(m.cy, (FRAME.top + FRAME.bottom) / 2.0), "{}", m.cy);
        assert_eq!(m.kind, Kind::Sniffer);
        assert_eq!(m.title, "3.200000 s: SS_SnifferIndication, SNR -4 dB");
        assert_eq!(plot.count, "1 indication, SNR min -4 dB, max -4 dB");
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
        assert_eq!(
            plot.count,
            "the last 500 of 600 indications, SNR min 0 dB, max 29 dB"
        );
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
