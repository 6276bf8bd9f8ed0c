//! A lamp's own page in the Street view: its history plotted (power,
//! temperature, SNR), read now, dimming, clock, GPIO, parameter groups,
//! ballast reset, and on a simulated street the faults a demo needs.

use super::fixed;
use super::plot::{self, Axis, Frame, Spec};
use super::widgets::{button, escape, html, on_event, signal, text_input};
use crate::clock::computer_clock;
use crate::fleet::{dimming_value, key_address};
use crate::stores::use_console;
use crate::street::{Lamp, Lamps, Sample};
use crate::transport::LampAction;
use leptos::prelude::*;
use plm_core::app::service::{self, Service};
use plm_core::app::{hid, Message, Request};
use plm_core::field::Field;

/// Eight checkboxes, IO7 first, bound to the bits of `mask`.
fn pin_boxes(mask: RwSignal<u32>, id: &'static str) -> impl IntoView {
    (0..8u8)
        .rev()
        .map(|bit| {
            view! {
                <input
                    type="checkbox"
                    id=format!("{id}-{bit}")
                    title=format!("IO{bit}")
                    prop:checked=move || mask.get() & (1 << bit) != 0
                    on:change=on_event(move |ev| {
                        let on = event_target_checked(&ev);
                        mask.update(|m| if on { *m |= 1 << bit } else { *m &= !(1 << bit) });
                    })
                />
            }
        })
        .map(IntoAny::into_any)
        .collect_view()
}

/// The output levels to send: a level on a pin configured as an input
/// is refused (STEVAL UM 4.6.4: bit x = 1 -> IOx output), with the pin.
fn output_levels(config: u8, levels: u8) -> Result<u8, String> {
    match (0..8).find(|b| levels & !config & (1 << b) != 0) {
        Some(b) => Err(format!(
            "nothing sent: IO{b} is an input; configure it as an output (and Set) before driving it"
        )),
        None => Ok(levels),
    }
}

/// A lamp page's plot: room left of the plot area for the values, above
/// it for the unit, below it for the clock times.
const FRAME: Frame = Frame {
    width: 316.0,
    height: 86.0,
    left: 34.0,
    right: 308.0,
    top: 14.0,
    bottom: 68.0,
    inset: 6.0,
};

/// Readings further apart than this are not joined: the page was closed
/// or the lamp silent in between.
const GAP_S: f64 = 300.0;

/// A reading of a lamp's history.
type Reading = fn(&Sample) -> Option<f64>;

/// What a lamp's page plots: the plot's id, the field read (its label and
/// unit, as plm-core describes it: HID parameters 04h and 07h, STEVAL UM
/// Appendix A; the SNR of SN GET), its axis and its value.
const READINGS: [(&str, Field, Spec, Reading); 3] = [
    (
        "plot-power",
        hid::fields::LAMP_POWER,
        plot::WHOLE_POSITIVE,
        |s| Some(f64::from(s.power)),
    ),
    (
        "plot-temperature",
        hid::fields::TEMPERATURE,
        plot::WHOLE,
        |s| Some(f64::from(s.temperature)),
    ),
    ("plot-snr", service::fields::SNR, plot::WHOLE, |s| {
        s.snr.map(f64::from)
    }),
];

/// One reading of a lamp over time: its axes and its points (seconds of
/// the local clock, value).
struct Chart {
    x: Axis,
    y: Axis,
    points: Vec<(f64, f64)>,
}

/// The chart of `reading` over `lamp`'s history; `None` before a reading.
fn chart(lamp: &Lamp, reading: Reading, spec: &Spec) -> Option<Chart> {
    // Seconds of the local clock.
    let offset = plot::zone_offset();
    let points: Vec<(f64, f64)> = crate::history_store::of(lamp)
        .iter()
        .filter_map(|s| Some((s.at as f64 / 1e6 + offset, reading(s)?)))
        .collect();
    let (t0, t1) = plot::min_max(points.iter().map(|p| p.0))?;
    let (v0, v1) = plot::min_max(points.iter().map(|p| p.1))?;
    Some(Chart {
        x: plot::clock_axis(t0, t1, 4.0),
        y: plot::nice_axis(v0, v1, spec, 3.0),
        points,
    })
}

impl Chart {
    /// Where each point is drawn.
    fn at(&self) -> Vec<(f64, f64)> {
        self.points
            .iter()
            .map(|&(t, v)| (FRAME.x(&self.x, t), FRAME.y(&self.y, v)))
            .collect()
    }

    /// The plot as `<figure>`: a caption with the name, unit, min, max and
    /// last value, and the drawing.
    fn figure(&self, id: &str, name: &str, unit: &str) -> String {
        let (lo, hi) = plot::min_max(self.points.iter().map(|p| p.1)).unwrap_or_default();
        let last = self.points.last().map_or(0.0, |p| p.1);
        let mut h = format!(
            "<figure class=\"lamp-plot\"><figcaption><b>{name}</b> ({unit}) min {} · max {} · last {}</figcaption>",
            fixed(lo, 0),
            fixed(hi, 0),
            fixed(last, 0)
        );
        h.push_str(&plot::open(
            id,
            "",
            &format!("{name} over time, {unit}"),
            &FRAME,
            &self.x,
            plot::clock_label,
            &self.y,
        ));
        plot::text(
            &mut h,
            "plot-unit",
            FRAME.left - 5.0,
            FRAME.top - 3.0,
            "",
            unit,
        );
        let mut d = String::new();
        let mut was = f64::NEG_INFINITY;
        for (&(t, _), (x, y)) in self.points.iter().zip(self.at()) {
            let jump = if t - was > GAP_S { 'M' } else { 'L' };
            d.push_str(&format!("{jump}{} {}", plot::n(x), plot::n(y)));
            was = t;
        }
        h.push_str(&format!("<path class=\"plot-line\" d=\"{d}\"></path>"));
        if let Some((x, y)) = self.at().last() {
            h.push_str(&format!(
                "<circle class=\"plot-last\" cx=\"{}\" cy=\"{}\" r=\"2.5\"></circle>",
                plot::n(*x),
                plot::n(*y)
            ));
        }
        plot::close(&mut h);
        h.push_str("</figure>");
        h
    }

    /// The reading nearest a pointer `share` of the way across, as a
    /// cursor (`12:03:05 · 150 W`).
    fn readout(&self, share: f64, unit: &str) -> Option<String> {
        let at = self.at();
        let xs: Vec<f64> = at.iter().map(|p| p.0).collect();
        let i = plot::nearest(&xs, share * FRAME.width)?;
        let (t, v) = self.points[i];
        let label = format!("{} · {} {unit}", plot::clock_label(t, 1.0), fixed(v, 0));
        Some(plot::cursor(&FRAME, at[i].0, at[i].1, &label))
    }
}

/// Under the plots: which clock their times are on.
fn clock_note(simulated: bool) -> &'static str {
    if simulated {
        "Times are the simulated street's clock, which started at this computer's time when the street did. Point at a plot to read it."
    } else {
        "Times are this computer's clock. Point at a plot to read it."
    }
}

/// What the street knows of a lamp, as HTML: its state, and its history
/// plotted (power, temperature, SNR). Redrawn as the lamp is read, apart
/// from the page's forms, so that typing in them goes on undisturbed.
fn state_html(lamp: Option<&Lamp>, simulated: bool) -> String {
    let Some(l) = lamp else {
        return "<p class=\"muted\">This lamp is not on the street any more.</p>".into();
    };
    let state = match (&l.unreachable, l.state()) {
        (Some(u), Some(s)) => format!("Unreachable: {u}. Last read: {s}."),
        (Some(u), None) => format!("Unreachable: {u}."),
        (None, Some(s)) => format!("Lamp {s}"),
        (None, None) => "Not read yet.".to_string(),
    };
    let mut html = format!(
        "<p{}>{}</p>",
        if crate::fleet::Look::of(l).in_trouble() {
            " class=\"problem\""
        } else {
            ""
        },
        escape(&state)
    );
    for (id, field, spec, reading) in &READINGS {
        match chart(l, *reading, spec) {
            Some(c) => html.push_str(&c.figure(id, field.label, field.unit)),
            None => html.push_str(&format!(
                "<p class=\"muted\">{} ({}): no reading yet.</p>",
                field.label, field.unit
            )),
        }
    }
    html.push_str(&format!(
        "<p class=\"muted plot-note\">{}</p>",
        clock_note(simulated)
    ));
    html
}

/// The page of the lamp `focus` names (by its row key).
#[component]
pub fn LampPanel(focus: RwSignal<Option<u64>>) -> impl IntoView {
    let street = use_console().street;
    let note = signal(None::<String>);
    let level = signal(String::from("50"));
    // u32 signals (a type the page has) holding bytes.
    let io_config = signal(0u32);
    let outputs = signal(0u32);
    let group = signal(2u32);
    let params = signal(String::new());
    let ask = move |m: Message, what: &'static str| {
        let Some(a) = focus.get_untracked().map(key_address) else {
            return;
        };
        note.set(Some(format!("{what}…")));
        let r = street.act(|s| {
            s.request(
                Request::to(a, m),
                Box::new(move |r| {
                    note.set(Some(match r {
                        Ok(Message::Service(Service::ClockNow(c))) => format!("clock: {c}"),
                        Ok(Message::Service(Service::Inputs(v))) => {
                            format!("GPIO levels: {v:08b} (IO7…IO0)")
                        }
                        Ok(Message::Service(Service::IoConfig(v))) => {
                            io_config.set(v.into());
                            format!("GPIO outputs: {v:08b} (IO7…IO0, 1 = output)")
                        }
                        Ok(Message::Service(Service::Params { group, data })) => {
                            params.set(plm_core::hex::encode(&data));
                            format!("parameter group {group}: {} bytes read", data.len())
                        }
                        Ok(Message::Error(e)) => format!("{what}: the board answered {e}"),
                        Ok(_) => format!("{what}: done"),
                        Err(e) => format!("{what}: {e}"),
                    }))
                }),
            )
        });
        if let Err(e) = r {
            note.set(Some(format!("nothing sent: {e}")));
        }
    };
    let sim = move |action: LampAction| {
        let Some(a) = focus.get_untracked().map(key_address) else {
            return;
        };
        street.act(|s| {
            if let Some(sim) = s.transport_mut().and_then(|t| t.simulator()) {
                sim.lamp(a, action);
            }
        });
        note.set(Some(format!("simulator: {} on this lamp", action.label())));
    };
    view! {
        <aside class="details lamp" id="lamp-panel">
            // Rebuilt when another lamp is chosen; its state as it is read.
            {move || focus.get().map(key_address).map(|address| view! {
                        <div class="lamp-head">
                            <h3>{format!("Lamp {address}")}</h3>
                            {button("lamp-close", "✕", "close this lamp's page", move || focus.set(None))}
                        </div>
                        // Read in place at each change of the fleet, not
                        // through a memo of the lamp (a memo type of its own:
                        // 1.8 KiB of the page); the HTML is written only when
                        // it differs.
                        // The reading under the pointer, in the plot it is over.
                        <div on:mousemove=plot::follow(Box::new(move |id, share| {
                            let (_, field, spec, reading) = READINGS.iter().find(|r| r.0 == id)?;
                            street.with_fleet(|f| chart(f.get(&address)?, *reading, spec)?.readout(share, field.unit))
                        }))>
                            {html(Box::new(move || {
                                street.version.track();
                                let simulated = street.port.with(|p| crate::fleet::has_text(p, "simulated"));
                                street.with_fleet(|f| state_html(f.get(&address), simulated))
                            }))}
                        </div>
                        <div class="form-row">
                            {button("lamp-read", "Read now", "", move || ask(Message::Hid(plm_core::app::Hid::Get(plm_core::app::hid::ALL)), "read"))}
                            <label>
                                "Dimming % "
                                {text_input("lamp-dim-level", "", "", Some(4), level)}
                            </label>
                            {button("lamp-dim", "Dim", "", move || {
                                match dimming_value(&level.get_untracked()) {
                                    Ok(v) => {
                                        let Some(a) = focus.get_untracked().map(key_address) else { return };
                                        let r = street.act(|s| s.dim(Lamps::These(&[a]), v));
                                        note.set(Some(match r { Ok(()) => format!("dimming {v} % sent"), Err(e) => format!("nothing sent: {e}") }));
                                    }
                                    Err(e) => note.set(Some(e)),
                                }
                            })}
                        </div>
                        <div class="form-row">
                            {button("", "Read clock", "", move || ask(Message::Service(Service::ClockGet), "clock"))}
                            {button("", "Set clock from this computer", "", move || ask(Message::Service(Service::ClockSet(computer_clock())), "set clock"))}
                            {button("", "Read GPIO levels", "", move || ask(Message::Service(Service::InputsGet), "GPIO"))}
                            {button("", "Reset ballast", "", move || ask(Message::Hid(plm_core::app::Hid::Reset(plm_core::app::hid::RESET_SOFTWARE)), "ballast reset"))}
                        </div>
                        <h4>"GPIO (IO7 … IO0)"</h4>
                        <div class="form-row pins">
                            <span class="muted">"output"</span>
                            {pin_boxes(io_config, "io-config")}
                            {button("", "Read", "", move || ask(Message::Service(Service::IoConfigGet), "read GPIO configuration"))}
                            {button("lamp-io-config", "Set", "", move || ask(Message::Service(Service::IoConfigSet(io_config.get_untracked() as u8)), "set GPIO configuration"))}
                        </div>
                        <div class="form-row pins">
                            <span class="muted">"level"</span>
                            {pin_boxes(outputs, "io-out")}
                            {button("lamp-io-out", "Set outputs", "", move || {
                                match output_levels(io_config.get_untracked() as u8, outputs.get_untracked() as u8) {
                                    Ok(v) => ask(Message::Service(Service::OutputsSet(v)), "set GPIO outputs"),
                                    Err(e) => note.set(Some(e)),
                                }
                            })}
                        </div>
                        <h4>"Parameters"</h4>
                        <div class="form-row">
                            <select on:change=on_event(move |ev| group.set(event_target_value(&ev).parse().unwrap_or(2)))>
                                {plm_core::app::service::PROG_GROUPS.iter().enumerate().map(|(i, n)| view! {
                                    <option value=i.to_string() selected=move || i == 2>{*n}</option>
                                }).map(IntoAny::into_any).collect_view()}
                            </select>
                            {button("", "Read", "", move || ask(Message::Service(Service::ParamGet { group: group.get_untracked() as u8 }), "read parameters"))}
                            {button("lamp-params-write", "Write", "", move || {
                                let data = match plm_core::hex::parse(&params.get_untracked()) {
                                    Ok(d) => d,
                                    Err(e) => return note.set(Some(format!("nothing sent: {e}"))),
                                };
                                ask(Message::Service(Service::ParamSet { group: group.get_untracked() as u8, data }), "write parameters")
                            })}
                        </div>
                        {text_input("lamp-params", "payload hex", "32 bytes, hex", None, params)}
                        {move || street.port.with(|p| crate::fleet::has_text(p, "simulated")).then(|| view! {
                            <div class="form-row sim-actions">
                                <span class="muted">"Simulator:"</span>
                                {button("lamp-sim-fail", "Break lamp", "", move || sim(LampAction::Fail))}
                                {button("", "Replace lamp", "", move || sim(LampAction::Repair))}
                                {button("lamp-sim-cut", "Cut supply", "", move || sim(LampAction::Cut))}
                                {button("", "Restore supply", "", move || sim(LampAction::Join))}
                            </div>
                        }).map(IntoAny::into_any)}
                        {super::widgets::note("lamp-note", "muted", note)}
            }.into_any())}
        </aside>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lamp read every 5 s from 12:03:05 (UTC, the tests' clock):
    /// power falling 5 W a reading from 150 W, temperature flat at 55 °C,
    /// no SNR.
    fn lamp_read(readings: u64) -> Lamp {
        let start = 20_000 * 86_400_000_000 + (12 * 3600 + 185) * 1_000_000;
        let mut l = Lamp::default();
        for i in 0..readings {
            l.history.push_back(Sample {
                at: start + i * 5_000_000,
                power: 150 - 5 * i as u16,
                temperature: 55,
                snr: None,
            });
        }
        l
    }

    #[test]
    fn a_flat_reading_sits_on_its_tick_under_clock_times() {
        let l = lamp_read(13);
        let (id, field, spec, reading) = &READINGS[1];
        let svg = chart(&l, *reading, spec)
            .unwrap()
            .figure(id, field.label, field.unit);
        assert!(
            svg.contains("<b>Board temperature</b> (°C) min 55 · max 55 · last 55"),
            "{svg}"
        );
        for tick in [">54</text>", ">55</text>", ">56</text>", ">°C</text>"] {
            assert!(svg.contains(tick), "{tick} in {svg}");
        }
        // A minute of readings: every 15 s, with seconds.
        for tick in [">12:03:15</text>", ">12:03:30</text>", ">12:04:00</text>"] {
            assert!(svg.contains(tick), "{tick} in {svg}");
        }
        // Every point on the middle tick's height.
        let y = FRAME.y(&plot::nice_axis(55.0, 55.0, spec, 3.0), 55.0);
        assert_eq!(y, (FRAME.top + FRAME.bottom) / 2.0);
        assert_eq!(
            svg.matches(&format!(" {}", plot::n(y))).count(),
            13,
            "{svg}"
        );
        // No SNR known: no plot.
        let (_, _, spec, reading) = &READINGS[2];
        assert!(chart(&l, *reading, spec).is_none());
    }

    #[test]
    fn the_readout_is_the_reading_nearest_the_pointer_with_its_time_and_unit() {
        let l = lamp_read(13);
        let (_, field, spec, reading) = &READINGS[0];
        let unit = field.unit;
        let c = chart(&l, *reading, spec).unwrap();
        let r = c.readout(0.99, unit).unwrap();
        assert!(r.contains(">12:04:05 · 90 W</text>"), "{r}");
        let r = c.readout(0.0, unit).unwrap();
        assert!(r.contains(">12:03:05 · 150 W</text>"), "{r}");
    }

    #[test]
    fn readings_far_apart_are_not_joined() {
        let mut l = lamp_read(3);
        let mut late = *l.history.back().unwrap();
        late.at += 10 * 60 * 1_000_000;
        l.history.push_back(late);
        let (id, field, spec, reading) = &READINGS[0];
        let svg = chart(&l, *reading, spec)
            .unwrap()
            .figure(id, field.label, field.unit);
        let d = svg.split(" d=\"").nth(1).unwrap();
        let d = &d[..d.find('"').unwrap()];
        assert_eq!(d.matches('M').count(), 2, "{d}");
        assert_eq!(d.matches('L').count(), 2, "{d}");
    }

    #[test]
    fn outputs_only_on_output_pins() {
        assert_eq!(output_levels(0b1111_0000, 0b0101_0000), Ok(0b0101_0000));
        assert!(output_levels(0b1111_0000, 0b0000_1000)
            .unwrap_err()
            .contains("IO3 is an input"));
    }
}
