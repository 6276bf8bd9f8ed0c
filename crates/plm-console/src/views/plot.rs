//! Every plot of the console (a lamp's power, temperature and SNR, the
//! Data view's SNR of received frames): readings over time with axes at
//! round steps, a grid, clock times on the time axis, min and max, and the
//! reading under the pointer. The geometry is plain functions, tested
//! natively; the drawing is SVG written as one string (a drawing of
//! elements costs the console's wasm a copy of each element's code), and
//! one `mousemove` listener per container shows the reading under the
//! pointer ([`follow`]).

use super::fixed;
use super::widgets::escape;
use std::fmt::Write;

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

/// What a value axis needs beyond its data range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    /// A narrower range (one point, or all at one value) is widened to
    /// this around its middle: a flat series reads as a line on its
    /// value's tick between the ticks either side.
    pub min_span: f64,
    /// No step is smaller.
    pub min_step: f64,
    /// Widening never goes below this (unless the data does).
    pub floor: f64,
}

/// Seconds on the transport's clock, which starts at 0: one point still
/// gets a second of axis.
pub const SECONDS: Spec = Spec {
    min_span: 1.0,
    min_step: 1e-6,
    floor: 0.0,
};

/// A reading in whole units that may be negative (dB, °C).
pub const WHOLE: Spec = Spec {
    min_span: 2.0,
    min_step: 1.0,
    floor: f64::NEG_INFINITY,
};

/// A reading in whole units, never negative (W).
pub const WHOLE_POSITIVE: Spec = Spec {
    floor: 0.0,
    ..WHOLE
};

/// An axis of about `intervals` steps at round values whose range
/// includes `lo..=hi`.
pub fn nice_axis(lo: f64, hi: f64, spec: &Spec, intervals: f64) -> Axis {
    let (mut lo, mut hi) = (lo.min(hi), lo.max(hi));
    if hi - lo < spec.min_span {
        let floor = spec.floor.min(lo);
        lo = ((lo + hi) / 2.0 - spec.min_span / 2.0).max(floor);
        hi = lo + spec.min_span;
    }
    let step = nice_step(((hi - lo) / intervals).max(spec.min_step));
    ticked(lo, hi, step)
}

/// The axis from the last multiple of `step` at or below `lo` to the
/// first at or above `hi`.
fn ticked(lo: f64, hi: f64, step: f64) -> Axis {
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
    fixed(value, decimals as u32)
}

/// Steps of a clock axis, seconds: round to a person reading a clock.
const CLOCK_STEPS: [f64; 17] = [
    1.0, 2.0, 5.0, 10.0, 15.0, 30.0, 60.0, 120.0, 300.0, 600.0, 900.0, 1800.0, 3600.0, 7200.0,
    10800.0, 21600.0, 43200.0,
];
use crate::numbers::DAY;
pub use crate::numbers::{clock_label, zone_offset};

/// A time axis in seconds of a local clock (seconds since the Unix epoch
/// plus the time zone's offset) from `t0` to `t1` (one reading gets a
/// minute around it), with at most about `intervals` steps at round clock
/// times (5 s, 15 min, 1 h…) and ticks only inside: the line spans the
/// plot's width. No tick in the last 6 % of it, where its label would
/// not fit.
pub fn clock_axis(t0: f64, t1: f64, intervals: f64) -> Axis {
    let (mut t0, mut t1) = (t0.min(t1), t0.max(t1));
    if t1 - t0 < 60.0 {
        let middle = (t0 + t1) / 2.0;
        (t0, t1) = (middle - 30.0, middle + 30.0);
    }
    let span = t1 - t0;
    let step = CLOCK_STEPS
        .into_iter()
        .find(|s| span / s <= intervals)
        .unwrap_or_else(|| DAY * nice_step(span / DAY / intervals));
    let first = (t0 / step).ceil() as i64;
    let last = ((t1 - span * 0.06) / step).floor() as i64;
    Axis {
        lo: t0,
        hi: t1,
        step,
        ticks: (first..=last).map(|i| i as f64 * step).collect(),
    }
}

/// Where a plot sits in its drawing (SVG user units): the drawing's size
/// and the plot area's edges, with room outside for labels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Drawing width.
    pub width: f64,
    /// Drawing height.
    pub height: f64,
    /// Plot area's left edge.
    pub left: f64,
    /// Plot area's right edge.
    pub right: f64,
    /// Plot area's top edge.
    pub top: f64,
    /// Plot area's bottom edge.
    pub bottom: f64,
    /// Between the plot area's edges and the ends of the axes' ranges,
    /// so marks on a tick at an end do not sit on the frame.
    pub inset: f64,
}

impl Frame {
    /// Horizontal position of `v` on `x`.
    pub fn x(&self, x: &Axis, v: f64) -> f64 {
        scale(x, v, self.left + self.inset, self.right - self.inset)
    }

    /// Vertical position of `v` on `y` (up is more).
    pub fn y(&self, y: &Axis, v: f64) -> f64 {
        scale(y, v, self.bottom - self.inset, self.top + self.inset)
    }
}

/// Maps `axis.lo..=axis.hi` onto `from..=to` (`to` < `from` flips).
fn scale(axis: &Axis, value: f64, from: f64, to: f64) -> f64 {
    from + (value - axis.lo) / (axis.hi - axis.lo) * (to - from)
}

/// The smallest and largest of `values`; `None` when there are none.
pub fn min_max(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |m, v| {
        Some(m.map_or((v, v), |(lo, hi): (f64, f64)| (lo.min(v), hi.max(v))))
    })
}

/// The index of the x in `xs` nearest `x` (the first of equals).
pub fn nearest(xs: &[f64], x: f64) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, &v) in xs.iter().enumerate() {
        let d = (v - x).abs();
        if best.is_none_or(|(_, b)| d < b) {
            best = Some((i, d));
        }
    }
    best.map(|(i, _)| i)
}

/// A coordinate as attribute text.
pub fn n(v: f64) -> String {
    fixed(v, 1)
}

/// Appends `<line>` from (x1, y1) to (x2, y2).
pub fn line(h: &mut String, class: &str, x1: f64, y1: f64, x2: f64, y2: f64) {
    let _ = write!(
        h,
        "<line class=\"{class}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"></line>",
        n(x1),
        n(y1),
        n(x2),
        n(y2)
    );
}

/// Appends `<text>` at (x, y); `extra` is more attributes.
pub fn text(h: &mut String, class: &str, x: f64, y: f64, extra: &str, body: &str) {
    let _ = write!(
        h,
        "<text class=\"{class}\" x=\"{}\" y=\"{}\"{extra}>{}</text>",
        n(x),
        n(y),
        escape(body)
    );
}

/// Opens the drawing: `<svg id class="plot …">` with its grid, ticks and
/// axes, x ticks labelled by `x_label(value, step)`, y ticks by value.
/// `label` is what it shows, for a screen reader.
pub fn open(
    id: &str,
    class: &str,
    label: &str,
    f: &Frame,
    x: &Axis,
    x_label: fn(f64, f64) -> String,
    y: &Axis,
) -> String {
    let mut h = format!(
        "<svg id=\"{id}\" class=\"plot {class}\" viewBox=\"0 0 {} {}\" role=\"img\" aria-label=\"{}\">",
        n(f.width),
        n(f.height),
        escape(label)
    );
    for &v in &y.ticks {
        let at = f.y(y, v);
        line(&mut h, "plot-grid", f.left, at, f.right, at);
        text(
            &mut h,
            "plot-tick plot-y",
            f.left - 5.0,
            at,
            "",
            &tick_label(v, y.step),
        );
    }
    for &v in &x.ticks {
        let at = f.x(x, v);
        line(&mut h, "plot-grid", at, f.top, at, f.bottom);
        text(
            &mut h,
            "plot-tick plot-x",
            at,
            f.bottom + 14.0,
            "",
            &x_label(v, x.step),
        );
    }
    line(&mut h, "plot-axis", f.left, f.top, f.left, f.bottom);
    line(&mut h, "plot-axis", f.left, f.bottom, f.right, f.bottom);
    h
}

/// Closes a drawing [`open`] began, with the place [`follow`] writes the
/// reading under the pointer in.
pub fn close(h: &mut String) {
    h.push_str("<g class=\"plot-cursor\"></g></svg>");
}

/// The reading under the pointer, drawn: a vertical rule at `x`, a dot
/// at (`x`, `y`) and `label` beside the rule, on the side with room.
pub fn cursor(f: &Frame, x: f64, y: f64, label: &str) -> String {
    let mut h = String::new();
    line(&mut h, "plot-rule", x, f.top, x, f.bottom);
    let _ = write!(
        h,
        "<circle class=\"plot-dot\" cx=\"{}\" cy=\"{}\" r=\"3\"></circle>",
        n(x),
        n(y)
    );
    let right = x > (f.left + f.right) / 2.0;
    let (at, anchor) = if right {
        (x - 5.0, " text-anchor=\"end\"")
    } else {
        (x + 5.0, "")
    };
    text(&mut h, "plot-readout", at, f.top + 10.0, anchor, label);
    h
}

/// What [`follow`] asks of a container's plots: given a plot's id and how
/// far across it the pointer is, the cursor to draw there.
pub type Pick = Box<dyn Fn(&str, f64) -> Option<String>>;

/// A `mousemove` listener for a container of plots. `pick(id, share)`
/// gets the plot's id and how far across its drawing the pointer is (0 at
/// the left edge, 1 at the right) and returns the [`cursor`] to draw, or
/// `None` to leave the plot as it is.
pub fn follow(pick: Pick) -> Box<dyn FnMut(web_sys::MouseEvent)> {
    Box::new(move |ev| {
        let Some(svg) = super::widgets::closest(&ev, "svg.plot") else {
            return;
        };
        let r = svg.get_bounding_client_rect();
        if r.width() <= 0.0 {
            return;
        }
        // web-sys has clientX as an f64 for wasm32, an i32 natively.
        #[allow(clippy::useless_conversion)]
        let x = f64::from(ev.client_x());
        let share = (x - r.left()) / r.width();
        if let (Some(h), Some(g)) = (pick(&svg.id(), share), svg.last_element_child()) {
            g.set_inner_html(&h);
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close_to(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    fn ticks(a: &Axis) -> Vec<String> {
        a.ticks.iter().map(|&t| tick_label(t, a.step)).collect()
    }

    fn clock(a: &Axis) -> Vec<String> {
        a.ticks.iter().map(|&t| clock_label(t, a.step)).collect()
    }

    /// 12:03:05 on some day, as seconds of a local clock.
    const NOON: f64 = 20_000.0 * DAY + 12.0 * 3600.0;

    #[test]
    fn steps_are_one_two_or_five_times_a_power_of_ten() {
        assert!(close_to(nice_step(1.0), 1.0));
        assert!(close_to(nice_step(1.8), 2.0));
        assert!(close_to(nice_step(0.2), 0.2));
        assert!(close_to(nice_step(0.3), 0.5));
        assert!(close_to(nice_step(2.8), 5.0));
        assert!(close_to(nice_step(7.0), 10.0));
        assert!(close_to(nice_step(20.0), 20.0));
        assert!(close_to(nice_step(0.000_07), 0.000_1));
    }

    #[test]
    fn value_ticks_cover_the_data_at_round_steps() {
        let a = nice_axis(20.0, 29.0, &WHOLE, 5.0);
        assert_eq!(ticks(&a), ["20", "22", "24", "26", "28", "30"]);
        let a = nice_axis(4.0, 18.0, &WHOLE, 5.0);
        assert_eq!(ticks(&a), ["0", "5", "10", "15", "20"]);
        let a = nice_axis(-3.0, 27.0, &WHOLE, 5.0);
        assert_eq!(ticks(&a), ["-10", "0", "10", "20", "30"]);
        // Fewer intervals for a small plot.
        let a = nice_axis(90.0, 150.0, &WHOLE_POSITIVE, 3.0);
        assert_eq!(ticks(&a), ["80", "100", "120", "140", "160"]);
    }

    #[test]
    fn a_flat_series_sits_on_its_tick_between_two_others() {
        // "Temperature 55…55" reads 54, 55, 56 with the line on 55.
        let a = nice_axis(55.0, 55.0, &WHOLE, 3.0);
        assert_eq!(ticks(&a), ["54", "55", "56"]);
        let a = nice_axis(150.0, 150.0, &WHOLE_POSITIVE, 3.0);
        assert_eq!(ticks(&a), ["149", "150", "151"]);
        // A lamp off: no negative watts.
        let a = nice_axis(0.0, 0.0, &WHOLE_POSITIVE, 3.0);
        assert_eq!(ticks(&a), ["0", "1", "2"]);
        let a = nice_axis(-4.0, -4.0, &WHOLE, 3.0);
        assert_eq!(ticks(&a), ["-5", "-4", "-3"]);
    }

    #[test]
    fn seconds_ticks_take_the_decimals_their_step_needs() {
        let a = nice_axis(0.0, 100.0, &SECONDS, 5.0);
        assert_eq!(ticks(&a), ["0", "20", "40", "60", "80", "100"]);
        let a = nice_axis(3.2, 3.2, &SECONDS, 5.0);
        assert_eq!(ticks(&a), ["2.6", "2.8", "3.0", "3.2", "3.4", "3.6", "3.8"]);
        // Near the start of the clock, not before it.
        let a = nice_axis(0.36, 0.36, &SECONDS, 5.0);
        assert_eq!(ticks(&a), ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
    }

    #[test]
    fn clock_ticks_are_round_clock_times_inside_the_readings() {
        // Twenty minutes of readings: every 5 minutes, HH:MM.
        let a = clock_axis(NOON + 185.0, NOON + 1385.0, 4.0);
        assert_eq!(clock(&a), ["12:05", "12:10", "12:15", "12:20"]);
        assert_eq!((a.lo, a.hi), (NOON + 185.0, NOON + 1385.0));
        // Two minutes: every 30 s, with seconds.
        let a = clock_axis(NOON + 65.0, NOON + 185.0, 4.0);
        assert_eq!(clock(&a), ["12:01:30", "12:02:00", "12:02:30"]);
        // Less than a minute: a minute around it.
        let a = clock_axis(NOON + 185.0, NOON + 200.0, 4.0);
        assert_eq!(clock(&a), ["12:02:45", "12:03:00", "12:03:15", "12:03:30"]);
        assert_eq!(a.hi - a.lo, 60.0);
        // Over midnight, the clock turns.
        let a = clock_axis(NOON + 11.5 * 3600.0, NOON + 12.5 * 3600.0, 4.0);
        assert_eq!(clock(&a), ["23:30", "23:45", "00:00", "00:15"]);
        // Days: whole days.
        let a = clock_axis(NOON, NOON + 9.0 * DAY, 4.0);
        assert_eq!(a.step, 5.0 * DAY);
    }

    #[test]
    fn a_clock_label_has_seconds_unless_the_step_is_whole_minutes() {
        assert_eq!(clock_label(NOON + 185.4, 1.0), "12:03:05");
        assert_eq!(clock_label(NOON + 185.4, 90.0), "12:03:05");
        assert_eq!(clock_label(NOON + 180.0, 60.0), "12:03");
        // Before 1970 (a local clock west of Greenwich): still a time of day.
        assert_eq!(clock_label(-1.0, 1.0), "23:59:59");
    }

    /// A plot area of 80 × 40 in a 100 × 50 frame, its ends 5 inside.
    const FRAME: Frame = Frame {
        width: 100.0,
        height: 50.0,
        left: 10.0,
        right: 90.0,
        top: 5.0,
        bottom: 45.0,
        inset: 5.0,
    };

    #[test]
    fn the_ends_of_an_axis_are_the_plot_area_less_its_inset() {
        let f = FRAME;
        let a = nice_axis(0.0, 10.0, &WHOLE, 5.0);
        assert_eq!(
            (f.x(&a, 0.0), f.x(&a, 10.0), f.x(&a, 5.0)),
            (15.0, 85.0, 50.0)
        );
        assert_eq!((f.y(&a, 0.0), f.y(&a, 10.0)), (40.0, 10.0));
    }

    #[test]
    fn min_max_and_nearest() {
        assert_eq!(min_max([3.0, -1.0, 7.0].into_iter()), Some((-1.0, 7.0)));
        assert_eq!(min_max(std::iter::empty()), None);
        let xs = [10.0, 20.0, 30.0];
        assert_eq!(nearest(&xs, 0.0), Some(0));
        assert_eq!(nearest(&xs, 24.0), Some(1));
        assert_eq!(nearest(&xs, 26.0), Some(2));
        assert_eq!(nearest(&xs, 99.0), Some(2));
        assert_eq!(nearest(&[], 5.0), None);
    }

    #[test]
    fn the_cursor_is_a_rule_a_dot_and_the_reading_on_the_side_with_room() {
        let f = FRAME;
        let left = cursor(&f, 20.0, 30.0, "12:03:05 · 150 W");
        assert!(
            left.contains("x1=\"20.0\" y1=\"5.0\" x2=\"20.0\" y2=\"45.0\""),
            "{left}"
        );
        assert!(left.contains("cx=\"20.0\" cy=\"30.0\""), "{left}");
        assert!(
            left.contains("x=\"25.0\" y=\"15.0\">12:03:05 · 150 W</text>"),
            "{left}"
        );
        let right = cursor(&f, 80.0, 30.0, "a < b");
        assert!(
            right.contains("x=\"75.0\" y=\"15.0\" text-anchor=\"end\">a &lt; b</text>"),
            "{right}"
        );
    }
}
