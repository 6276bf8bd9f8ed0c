//! What the street knows of each lamp, and what it raises: what each
//! answer, reading and silence means for the fleet.

use super::{Purpose, Street, StreetJob};
use crate::app::concentrator::Concentrator;
use crate::app::energy::Meter;
use crate::app::frame::Address;
use crate::app::hid::{Ballast, Hid, LampState};
use crate::app::message::Message;
use crate::app::service::{Clock, Discovered};
use crate::app::sweep::Reading;
use crate::app::Run;
use crate::time::Instant;
use alloc::collections::VecDeque;
use alloc::format;
use alloc::string::{String, ToString};

/// Samples of a lamp's history kept for its plots.
pub const HISTORY: usize = 240;

/// One reading of a lamp, for its history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// When, on the driver's clock.
    pub at: Instant,
    /// Lamp power, W.
    pub power: u16,
    /// Board temperature, °C.
    pub temperature: i16,
    /// SNR, dB, when known.
    pub snr: Option<i8>,
}

/// What the street knows of one lamp.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Lamp {
    /// Its board's address.
    pub address: Address,
    /// What discovery said of it.
    pub discovered: Option<Discovered>,
    /// Its ballast as last read.
    pub ballast: Option<Ballast>,
    /// Dimming last set and acknowledged, %.
    pub dimming: Option<u8>,
    /// Signal quality, dB: the SNR of its last frame (bare modem), or
    /// what the board reports.
    pub snr: Option<i8>,
    /// When that figure was got (a sweep asks the oldest again).
    pub snr_at: Option<Instant>,
    /// Its clock as last read.
    pub clock: Option<Clock>,
    /// When it last answered.
    pub last_seen: Option<Instant>,
    /// Why it does not answer, if it stopped.
    pub unreachable: Option<String>,
    /// Recent readings, oldest first (at most [`HISTORY`]).
    pub history: VecDeque<Sample>,
    /// Its energy, estimated from every power reading taken.
    pub energy: Meter,
}

impl Lamp {
    /// Its lamp state, if read.
    pub fn state(&self) -> Option<LampState> {
        self.ballast.map(|b| b.state())
    }
}

/// Something a technician must see.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Alert {
    /// When.
    pub at: Instant,
    /// Which lamp.
    pub address: Address,
    /// What, in words.
    pub what: String,
}

impl<R> Street<R> {
    pub(super) fn lamp(&mut self, a: Address) -> &mut Lamp {
        self.fleet.entry(a).or_insert_with(|| Lamp {
            address: a,
            ..Lamp::default()
        })
    }

    /// Any answer shows the lamp is there.
    pub(super) fn answered(&mut self, now: Instant, address: Address) {
        let lamp = self.lamp(address);
        lamp.last_seen = Some(now);
        if lamp.unreachable.take().is_some() {
            self.out.alerts.push(Alert {
                at: now,
                address,
                what: "answers again".into(),
            });
        }
        self.out.changed = true;
    }

    pub(super) fn unreachable(&mut self, now: Instant, address: Address, reason: &str) {
        let lamp = self.lamp(address);
        if lamp.unreachable.is_none() {
            lamp.unreachable = Some(reason.to_string());
            self.out.alerts.push(Alert {
                at: now,
                address,
                what: format!("stopped answering: {reason}"),
            });
        }
        self.out.changed = true;
    }

    /// A lamp's ballast as read: its history, and an alert when it has
    /// just failed.
    fn ballast(&mut self, now: Instant, a: Address, value: &[u8]) {
        let Some(b) = Ballast::decode(value) else {
            return;
        };
        let lamp = self.lamp(a);
        let was = lamp.state();
        lamp.ballast = Some(b);
        lamp.energy.record(now, b.lamp_power);
        let snr = lamp.snr;
        lamp.history.push_back(Sample {
            at: now,
            power: b.lamp_power,
            temperature: b.temperature,
            snr,
        });
        if lamp.history.len() > HISTORY {
            lamp.history.pop_front();
        }
        if b.state() == LampState::Failure && was != Some(LampState::Failure) {
            self.out.alerts.push(Alert {
                at: now,
                address: a,
                what: format!(
                    "lamp failed (was {} before the failure, lamp voltage {} V)",
                    LampState::from_word(b.last_failure.status),
                    b.last_failure.lamp_voltage
                ),
            });
        }
    }

    /// A discovery reply: the lamp is in the fleet, with what it said.
    pub(super) fn discovered(&mut self, now: Instant, address: Address, r: Discovered) {
        let modem = self.modem;
        let lamp = self.lamp(address);
        lamp.discovered = Some(r);
        // Through a board it is the board's own figure, the latest; through
        // a bare modem the SNR of each frame heard is better.
        if !modem || lamp.snr.is_none() {
            lamp.snr = Some(r.snr as i8);
            lamp.snr_at = Some(now);
        }
        lamp.last_seen = Some(now);
        self.out.changed = true;
        self.out.found = true;
    }

    /// What the round learned, into the fleet.
    pub(super) fn take_readings(&mut self, now: Instant) {
        let modem = self.modem;
        let Some(StreetJob::Round(round)) = self.job.as_mut().map(Run::job_mut) else {
            return;
        };
        let readings = round.take_readings();
        self.sweep.done = round.settled();
        for r in readings {
            match r {
                Reading::Value(a, value) => {
                    self.answered(now, a);
                    self.ballast(now, a, &value);
                }
                Reading::Snr(a, v) if !modem => {
                    let lamp = self.lamp(a);
                    lamp.snr = Some(v as i8);
                    lamp.snr_at = Some(now);
                }
                Reading::Heard(a, d) => self.discovered(now, a, d),
                _ => {}
            }
        }
        self.out.changed = true;
    }

    /// What a request's outcome means: a lamp read, a dimming done (read
    /// again to see its power follow), a reply for the caller.
    pub(super) fn fulfil(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        p: Purpose<R>,
        r: Result<Message, String>,
    ) {
        match (p, r) {
            (Purpose::Read(a), Ok(Message::Hid(Hid::Reply { value, .. }))) => {
                self.ballast(now, a, &value);
            }
            (Purpose::Dim(a, level), Ok(Message::Ack { .. })) => {
                self.lamp(a).dimming = Some(level);
                self.read(conc, now, a);
            }
            (Purpose::View(reply), r) => self.out.replies.push((reply, r)),
            _ => {}
        }
        self.out.changed = true;
    }
}
