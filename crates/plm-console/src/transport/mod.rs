//! Byte transports to a modem's host interface, behind one trait.
//!
//! A transport moves bytes and the T_REQ line, and says what time it is;
//! it knows nothing of frames. The [`crate::session`] drives plm-core's
//! host link engine over it. Two kinds: the simulated modem
//! in the page ([`sim::SimTransport`], the default) and a real modem over
//! WebSerial (`webserial::WebSerialTransport`, wasm32 only).

pub mod sfsk;
pub mod sim;
/// WebSerial exists only in the browser (web-sys unstable APIs, wasm32).
#[cfg(target_arch = "wasm32")]
pub mod webserial;

use plm_core::app::Address;
use plm_core::time::{Duration, Instant};
use plm_sim::{Fault, LineConfig, LineEvent};

/// Whether a transport can carry bytes now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LinkState {
    /// Bytes flow.
    Connected,
    /// Nothing crosses; the reason in words (what to do about it).
    Disconnected(String),
}

impl LinkState {
    /// Whether bytes flow.
    pub fn is_connected(&self) -> bool {
        matches!(self, LinkState::Connected)
    }
}

/// A byte transport with a T_REQ line, driven by the session.
///
/// Time is in microseconds on the transport's own clock: virtual time for
/// the simulator, the page's clock for a real port. Received bytes carry
/// the time they arrived, so that the link engine can apply T_IC (UM0932
/// 3.2.6) however late the page gets to them.
pub trait Transport {
    /// What kind of transport this is (`Simulated`, `WebSerial`).
    fn kind(&self) -> &'static str;
    /// Which port or device, in words.
    fn port(&self) -> String;
    /// Whether bytes can flow, and if not why.
    fn state(&self) -> LinkState;
    /// The transport's clock, µs.
    fn now(&self) -> Instant;
    /// UART baud rate.
    fn baud(&self) -> u32;
    /// Changes the UART baud rate.
    fn set_baud(&mut self, baud: u32);
    /// Writes bytes now.
    fn write(&mut self, bytes: &[u8]);
    /// Sets T_REQ now; `asserted` means pulled low (a request to send).
    fn set_treq(&mut self, asserted: bool);
    /// Sets DTR now (`true` = asserted). The console touches DTR only when
    /// the port's setting says it is wired to the modem's RESETN (as on
    /// many USB-UART boards): asserted holds the modem in reset, released
    /// lets it boot (UM0932 Table 19, cause 0).
    fn set_dtr(&mut self, asserted: bool);
    /// Lets time run up to `until` (no further than the clock allows) and
    /// returns the bytes received meanwhile, with their arrival times.
    fn poll(&mut self, until: Instant) -> Vec<(Instant, u8)>;
    /// The next instant anything happens behind the transport, when it
    /// knows (a simulated world does; a real port says so by waking the
    /// page when bytes come, [`crate::wake::soon`]).
    fn next_event(&self) -> Option<Instant> {
        None
    }
    /// When the bytes now on the UART have arrived, the earliest of the
    /// two ways, when the transport knows (a simulated world; a real port
    /// wakes the page when bytes come): a frame may end there, which the
    /// modem answers at once, or the host must (a frame to ACK). The page
    /// wakes for it to its clock's resolution, and for the other events
    /// ([`Transport::next_event`]) within a millisecond ([`crate::wake`]).
    fn uart_due(&self) -> Option<Instant> {
        None
    }
    /// How late the transport may hand over the modem's bytes, or carry
    /// out the host's, beyond their wire time (0 for a simulated modem):
    /// the host's waits for the modem are lengthened by it.
    fn latency(&self) -> Duration {
        0
    }
    /// The modem's T_IC: the longest gap it allows between two bytes of
    /// a frame (UM0932 3.2.6, ST7570 UM 5.2.2). A transport that cannot
    /// time a T_REQ change between two writes that closely keeps a
    /// frame's bytes together ([`webserial`]).
    fn set_byte_gap_limit(&mut self, t_ic: Duration) {
        let _ = t_ic;
    }
    /// The simulated world behind this transport, if it is one.
    fn simulator(&mut self) -> Option<&mut dyn Simulator> {
        None
    }
    /// The simulated S-FSK network behind this transport, if it is one.
    fn sfsk(&mut self) -> Option<&mut sfsk::SfskTransport> {
        None
    }
}

/// What the Simulator view can do to a simulated transport.
pub trait Simulator {
    /// Modems on the line (1 = alone).
    fn nodes(&self) -> usize;
    /// Frames the echoing peers have sent back so far.
    fn echoed(&self) -> u64;
    /// Line conditions.
    fn line(&self) -> LineConfig;
    /// Changes the line conditions.
    fn set_line(&mut self, line: LineConfig);
    /// Random byte faults on one direction of the UART.
    fn set_byte_faults(&mut self, dir: plm_sim::Dir, faults: plm_sim::ByteFaults);
    /// Injects a fault now.
    fn inject(&mut self, fault: Fault);
    /// Whether the cable is plugged in.
    fn plugged(&self) -> bool;
    /// Line events since the last call, oldest first.
    fn line_events(&mut self) -> Vec<LineEvent>;
    /// Does something to the simulated lamp at `address` (nothing when
    /// no lamp of the street has it): faults on demand for demos and
    /// tests.
    fn lamp(&mut self, address: Address, action: LampAction);
    /// Random lamp failures from now on, per lamp per lit hour (0: none),
    /// on every lamp of a simulated street.
    fn set_failure_rate(&mut self, per_lit_hour: f64);
}

/// What the Simulator view can do to one lamp of a simulated street.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LampAction {
    /// The lamp breaks (FAILURE until repaired).
    Fail,
    /// A technician fits a new lamp.
    Repair,
    /// The board's supply is cut: it neither hears nor answers.
    Cut,
    /// Its supply is back.
    Join,
}

impl LampAction {
    /// What it does, in words.
    pub fn label(self) -> &'static str {
        match self {
            LampAction::Fail => "lamp broken",
            LampAction::Repair => "lamp replaced",
            LampAction::Cut => "supply cut",
            LampAction::Join => "supply restored",
        }
    }
}
