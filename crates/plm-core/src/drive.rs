//! The loop that drives a sans-IO engine over a serial port, written once
//! (docs/architecture.md, "One drive loop"). An [`Engine`] (the host link
//! engine, the street's concentrator) takes bytes and time and gives
//! bytes, T_REQ levels and events; an [`Io`] (a real serial port on the
//! wall clock, a simulated one in virtual time, the page's transport)
//! moves them and keeps the time. [`turn`] is one turn of the loop:
//! `plm board`, plm-sim's drivers and the console's sessions all run it.

use crate::time::Instant;
use alloc::vec::Vec;

/// Something the driver must do on the wire.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Transmit {
    /// Write these bytes.
    Bytes(Vec<u8>),
    /// Set T_REQ: `asserted` means pulled low (a request to send).
    TReq {
        /// Whether T_REQ is asserted (low).
        asserted: bool,
    },
}

/// A sans-IO engine on a serial line: time is always an argument.
pub trait Engine {
    /// What it reports.
    type Event;
    /// Bytes received at `at`.
    fn handle_rx(&mut self, at: Instant, bytes: &[u8]);
    /// Time passed: a deadline given by [`Engine::poll_timeout`] is due.
    fn handle_timeout(&mut self, now: Instant);
    /// When [`Engine::handle_timeout`] is due next.
    fn poll_timeout(&self) -> Option<Instant>;
    /// The next thing to do on the wire.
    fn poll_transmit(&mut self) -> Option<Transmit>;
    /// The next event.
    fn poll_event(&mut self) -> Option<Self::Event>;
}

/// [`Engine`] over an engine's own methods of the same names (its event
/// poll named `$event`).
macro_rules! engine {
    ($engine:ty, $out:ty, $event:ident) => {
        impl $crate::drive::Engine for $engine {
            type Event = $out;
            fn handle_rx(&mut self, at: Instant, bytes: &[u8]) {
                <$engine>::handle_rx(self, at, bytes)
            }
            fn handle_timeout(&mut self, now: Instant) {
                <$engine>::handle_timeout(self, now)
            }
            fn poll_timeout(&self) -> Option<Instant> {
                <$engine>::poll_timeout(self)
            }
            fn poll_transmit(&mut self) -> Option<$crate::drive::Transmit> {
                <$engine>::poll_transmit(self)
            }
            fn poll_event(&mut self) -> Option<$out> {
                <$engine>::$event(self)
            }
        }
    };
}
pub(crate) use engine;

/// The engine's side of a serial port: bytes, T_REQ and a clock.
pub trait Io {
    /// Why the port cannot go on (a real port lost, the user's Ctrl-C).
    type Error;
    /// The port's clock.
    fn now(&self) -> Instant;
    /// Lets time run to `until` at most, returning sooner when bytes
    /// come, and appends what arrived to `rx`, each byte with its arrival
    /// time. A simulated port runs its world to `until` or to its next
    /// event, whichever comes first.
    fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), Self::Error>;
    /// Writes bytes now.
    fn write(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;
    /// Sets T_REQ now (on a USB adapter, RTS).
    fn set_treq(&mut self, asserted: bool) -> Result<(), Self::Error>;
}

/// Does on `io` what `engine` has for the wire.
pub fn flush<E: Engine + ?Sized, I: Io + ?Sized>(
    engine: &mut E,
    io: &mut I,
) -> Result<(), I::Error> {
    while let Some(t) = engine.poll_transmit() {
        match t {
            Transmit::Bytes(b) => io.write(&b)?,
            Transmit::TReq { asserted } => io.set_treq(asserted)?,
        }
    }
    Ok(())
}

/// One turn of the loop: lets time run to `until` or the engine's next
/// deadline, whichever comes first; feeds each byte that arrived to the
/// engine at its arrival time (`each` is called after each, to see what
/// it caused at that instant); runs the engine's timer when it is due;
/// writes what the engine has for the wire. Returns the time reached.
pub fn turn<E: Engine + ?Sized, I: Io + ?Sized>(
    engine: &mut E,
    io: &mut I,
    until: Instant,
    mut each: impl FnMut(&mut E, Instant),
) -> Result<Instant, I::Error> {
    flush(engine, io)?;
    let until = engine.poll_timeout().map_or(until, |t| t.min(until));
    let mut rx = Vec::new();
    io.wait(until.max(io.now()), &mut rx)?;
    for (at, byte) in rx {
        engine.handle_rx(at, &[byte]);
        each(engine, at);
    }
    let now = io.now();
    if engine.poll_timeout().is_some_and(|t| t <= now) {
        engine.handle_timeout(now);
    }
    flush(engine, io)?;
    Ok(now)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::host::{Event, HostConfig, HostEngine};
    use crate::link::{Dialect, LocalFrame};
    use crate::time::MS;
    use alloc::vec;

    /// A port whose other end answers nothing and whose bytes come from a
    /// script: what `turn` owes any port.
    struct Scripted {
        now: Instant,
        script: Vec<(Instant, u8)>,
        written: Vec<(Instant, Vec<u8>)>,
        treq: Vec<(Instant, bool)>,
    }

    impl Io for Scripted {
        type Error = ();
        fn now(&self) -> Instant {
            self.now
        }
        fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), ()> {
            let next = self.script.first().map_or(until, |(t, _)| (*t).min(until));
            self.now = next.max(self.now);
            while self.script.first().is_some_and(|(t, _)| *t <= self.now) {
                rx.push(self.script.remove(0));
            }
            Ok(())
        }
        fn write(&mut self, bytes: &[u8]) -> Result<(), ()> {
            self.written.push((self.now, bytes.to_vec()));
            Ok(())
        }
        fn set_treq(&mut self, asserted: bool) -> Result<(), ()> {
            self.treq.push((self.now, asserted));
            Ok(())
        }
    }

    #[test]
    fn a_frame_is_acked_at_the_instant_its_last_byte_arrives_and_time_stops_at_deadlines() {
        let frame = LocalFrame::new(0x3F, vec![1, 2]);
        let bytes = frame.emit(Dialect::St7580).unwrap();
        let mut io = Scripted {
            now: 0,
            script: bytes
                .iter()
                .enumerate()
                .map(|(i, b)| (10 * MS + i as Instant * 100, *b))
                .collect(),
            written: Vec::new(),
            treq: Vec::new(),
        };
        let mut host = HostEngine::new(Dialect::St7580, HostConfig::default());
        let last = 10 * MS + (bytes.len() as Instant - 1) * 100;
        let mut at_frame = None;
        let mut t = 0;
        while t < 20 * MS {
            t = turn(&mut host, &mut io, 20 * MS, |h, at| {
                while let Some(e) = h.poll_event() {
                    if matches!(e, Event::Frame(_)) {
                        at_frame = Some(at);
                    }
                }
            })
            .unwrap();
        }
        assert_eq!(
            at_frame,
            Some(last),
            "the frame is reported at its last byte"
        );
        // The ACK was written in the turn that took the last byte: the
        // port's clock stood at the last byte's arrival.
        assert_eq!(io.written.first().map(|(t, _)| *t), Some(last));
        assert_eq!(io.now, 20 * MS);
    }

    #[test]
    fn a_turn_stops_at_the_engine_deadline_not_after_it() {
        let mut io = Scripted {
            now: 0,
            script: Vec::new(),
            written: Vec::new(),
            treq: Vec::new(),
        };
        let mut host = HostEngine::new(Dialect::St7580, HostConfig::default());
        host.submit(0, LocalFrame::new(0x08, vec![]));
        let t = turn(&mut host, &mut io, 10_000 * MS, |_, _| {}).unwrap();
        let deadline = host.poll_timeout();
        // T_REQ asserted at once, then the wait for the status message
        // (T_SR) ends the turn at its deadline, which the engine handled.
        assert_eq!(io.treq.first(), Some(&(0, true)));
        assert!(
            t < 10_000 * MS,
            "the turn ended at the engine's deadline ({t} µs)"
        );
        assert!(deadline.is_none_or(|d| d > t));
    }
}
