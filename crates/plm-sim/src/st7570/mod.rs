//! The simulated ST7570 (ST7570 UM, seed `003_2edea85fed0bdf2a`): its
//! host interface through plm-core's device link engine in the ST7570
//! dialect, its commands through plm-core's `st7570::Command`, its MIB
//! checks through `st7570::validate`, its status message through
//! `st7570::Status`. What is simulated here is the chip's state: operating
//! mode and access layer (00A1h), the MIB values and counters, reset and
//! auto-reconfiguration (7.1), synchronization as far as one modem alone
//! knows it, and the requests it refuses (Tables 43, 48, 63).
//!
//! The S-FSK line is not here: the model queues [`Transmission`]s for it
//! ([`St7570::poll_line`]) and takes subframes it hears
//! ([`St7570::hear`]); see [`slots`]. With nobody on the line a Client's
//! data request is confirmed LP_OK at the end of its frame, and a Server
//! never synchronizes (docs/protocol-notes.md, "ST7570: simulated modem").
//!
//! - [`store`]: the MIB values, write effects, Tables 149-150.
//! - [`requests`]: what the chip answers to each request of Table 15.
//! - `receive`: what it does with subframes and alarms the line delivers.
//! - [`slots`]: time slots and the seam to the line.
//! - [`drive`]: plm-core's host engine driving one model in virtual time.

pub mod drive;
pub mod line;
mod mac_rx;
pub mod net;
mod receive;
mod requests;
pub mod responder;
pub mod slots;
pub mod store;
mod sync;

use plm_core::link::device::{DeviceEngine, DeviceEvent};
use plm_core::link::host::Transmit;
use plm_core::link::{Dialect, Element};
use plm_core::st7570::mib::index;
use plm_core::st7570::{Command, IsLocked, Layer, SignalNoise, Status};
use plm_core::time::{earliest, Duration, Instant, MS};
pub use slots::{Heard, SlotClock, SlotUse, TestTone, Transmission};
use std::collections::VecDeque;
pub use store::Store;

/// Time from a reset to the modem answering again (model; the manual
/// gives none).
pub const BOOT_TIME: Duration = 20 * MS;
/// FW_RELEASE of the status message: 1 in this manual (Table 11).
pub const FW_RELEASE: u8 = 1;
/// 0001h's local address of a node that has none (Table 6: NEW).
pub const NEW: u16 = 0x0FFE;

/// Operating modes of 00A1h byte 0 (Table 137).
pub mod mode {
    /// IDLE.
    pub const IDLE: u8 = 0;
    /// Client.
    pub const CLIENT: u8 = 1;
    /// Server.
    pub const SERVER: u8 = 2;
    /// Monitor.
    pub const MONITOR: u8 = 3;
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Power {
    On,
    /// Restarting until `until`: deaf and mute. `software`: through
    /// CMD_ResetRequest, confirmed with 21h once up again (5.3.4).
    Booting {
        until: Instant,
        software: bool,
    },
    /// RESETn held low (a host that wires DTR to it): deaf, mute, no
    /// timers, until released.
    Held,
}

/// A request being served on the line: its confirm, when it is due, and
/// when the modem stops being BUSY.
#[derive(Debug, Clone, PartialEq, Eq)]
struct TxJob {
    /// When its first slot starts on the line.
    start: Instant,
    confirm_at: Instant,
    confirm: Option<Command>,
    end: Instant,
    /// MIB counter to add to at `end`, and by how much.
    count: Option<(u16, u32)>,
}

/// A simulated ST7570.
#[derive(Debug, Clone)]
pub struct St7570 {
    engine: DeviceEngine,
    mib: Store,
    power: Power,
    /// Status RESET: the last reset was a software reset (Table 11).
    software_reset: bool,
    treq: bool,
    /// Status ZC_FAIL: the mains PLL is not locked (no slot clock).
    zc_fail: bool,
    /// A Server or Monitor found the time slots on a received PRE+SSD.
    heard_sync: bool,
    /// A MAC Client synchronizes on its own first transmission (10.3.1).
    client_found: bool,
    /// An intelligent synchronization search runs until then (0009h).
    is_until: Option<Instant>,
    /// Alarm requests before then are confirmed and not sent (7.2.1).
    alarm_quiet_until: Instant,
    /// The slot of the last alarm heard and how many came in a row (7.2.2).
    alarm_run: Option<(u64, u8)>,
    /// Status ALARM: an alarm was heard since the last status message.
    alarm_flag: bool,
    /// A PHY Monitor searching for the slots sends SPY_SearchSynchro-
    /// Indication at every slot start after this moment (5.3.19).
    spy_from: Instant,
    jobs: Vec<TxJob>,
    line_out: VecDeque<Transmission>,
    /// The line's noise here: what a PHY Monitor measures in a slot with
    /// nothing in it (A0h, E0h).
    line_noise: SignalNoise,
    /// MAC timeouts (0002h-0004h, 0009h) run this many times faster.
    timeout_scale: u64,
    /// MAC: the subframes of a long frame being received (4.4).
    assembly: Option<mac_rx::Assembly>,
    /// MAC: the last burst taken, to tell its repetitions (4.8).
    burst: Option<mac_rx::Burst>,
    /// MAC Server: the synchronization state (4.6, 4.7).
    mac_state: sync::MacState,
    /// Intelligent synchronization: the initiator heard loudest.
    is_best: Option<IsLocked>,
    /// PHY Monitor: the slots the last subframe and alarm were heard in.
    spy_subframe_slot: Option<u64>,
    spy_alarm: Option<(u64, SignalNoise)>,
    /// Repeater call: the threshold of the call requested (7.3).
    rc_threshold: u32,
}

impl St7570 {
    /// A chip with nothing stored (factory defaults: PHY, IDLE) powering
    /// on at `now`, its UART strapped to `baud`.
    pub fn new(baud: u32, now: Instant) -> Self {
        let mut m = St7570 {
            engine: DeviceEngine::new(Dialect::St7570, baud),
            mib: Store::default(),
            power: Power::On,
            software_reset: false,
            treq: false,
            zc_fail: false,
            heard_sync: false,
            client_found: false,
            is_until: None,
            alarm_quiet_until: 0,
            alarm_run: None,
            alarm_flag: false,
            spy_from: 0,
            jobs: Vec::new(),
            line_out: VecDeque::new(),
            line_noise: SignalNoise::default(),
            timeout_scale: 1,
            assembly: None,
            burst: None,
            mac_state: sync::MacState::Off,
            is_best: None,
            spy_subframe_slot: None,
            spy_alarm: None,
            rc_threshold: 0,
        };
        m.restart(now, false, true);
        m
    }

    /// Changes the UART baud rate (the host's rate, strapped on the
    /// board; T_IC of 5 characters follows it, 5.2.2).
    pub fn set_baud(&mut self, baud: u32) {
        self.engine.set_baud(baud);
    }

    /// The MIB values.
    pub fn mib(&self) -> &Store {
        &self.mib
    }

    /// Whether the modem is up (not restarting).
    pub fn is_on(&self) -> bool {
        self.power == Power::On
    }

    /// The access layer (00A1h byte 12).
    pub fn layer(&self) -> Layer {
        self.mib.context().layer
    }

    /// The operating mode (00A1h byte 0 b0..b2).
    pub fn mode(&self) -> u8 {
        self.mib.context().mode
    }

    /// The tone a Test mode sends, and its gain (0..31), while the modem
    /// is up: the line reads it rather than a queue, the tone having no
    /// slots and no end.
    pub fn test_tone(&self) -> Option<(TestTone, u8)> {
        let plc = self.mib.plc();
        TestTone::of(&plc)
            .filter(|_| self.is_on())
            .map(|t| (t, plc.target_output_gain))
    }

    /// The slot clock 00A1h sets.
    pub fn slots(&self) -> SlotClock {
        SlotClock::of(&self.mib.plc())
    }

    /// Whether the modem is synchronized: a Client in PHY mode follows the
    /// mains alone, a MAC Client from its first transmission (10.3.1), a
    /// Server or Monitor once it heard a PRE+SSD; IDLE and Test modes run
    /// no time slots, and nothing does without the zero crossing.
    pub fn synchronized(&self) -> bool {
        !self.zc_fail
            && match self.mode() {
                mode::CLIENT => self.layer() == Layer::Phy || self.client_found,
                mode::SERVER | mode::MONITOR => self.heard_sync,
                _ => false,
            }
    }

    /// Whether an intelligent synchronization search runs (LM_IS).
    pub fn is_running(&self) -> bool {
        self.is_until.is_some()
    }

    /// Whether a transmission is requested or in progress (status BUSY).
    pub fn busy(&self) -> bool {
        !self.jobs.is_empty()
    }

    /// The status message bits now (Table 11).
    pub fn status(&self) -> Status {
        let ctx = self.mib.context();
        let mac = ctx.layer == Layer::Mac;
        let repeater = self.mib.tic_repeater();
        Status {
            mode: if ctx.mode <= mode::MONITOR {
                ctx.mode
            } else {
                0
            },
            mac,
            new: mac && ctx.mode == mode::SERVER && self.mib.local_address() == NEW,
            // SYNC is inverted: 1 = not synchronized.
            sync: !self.synchronized(),
            busy: self.busy(),
            reset: self.software_reset,
            fw_release: FW_RELEASE,
            zc_fail: self.zc_fail,
            alarm: self.alarm_flag,
            // INVALID_FRAME is the LSByte of 0006h.
            invalid_frame: self.mib.counter(store::INVALID_FRAMES) as u8,
            min_credit: self.mib.byte(store::MIN_DELTA_CREDIT, 0),
            repeater: repeater.is_repeater(),
            ..Status::default()
        }
    }

    /// The mains zero crossing is lost (`true`) or back: ZC_FAIL, and no
    /// time slots while it is lost.
    pub fn set_zc_fail(&mut self, now: Instant, fail: bool) {
        self.zc_fail = fail;
        self.spy_from = now;
        if fail {
            self.heard_sync = false;
            self.forget_mac();
        }
        self.refresh_status();
    }

    /// Whether the mains zero crossing is lost (status ZC_FAIL).
    pub fn zc_fail(&self) -> bool {
        self.zc_fail
    }

    /// The line's noise at this modem (the line sets it).
    pub fn set_line_noise(&mut self, sn: SignalNoise) {
        self.line_noise = sn;
    }

    /// Makes the MAC timeouts (0002h-0004h, 0009h) run `scale` times
    /// faster, so that a demo shows a 360-minute timeout in 6 minutes at
    /// 60 (a simulation knob; the chip has none).
    pub fn set_timeout_scale(&mut self, scale: u64) {
        self.timeout_scale = scale.max(1);
    }

    /// A hardware reset (power cycle or RESETn) at `now`: the stored
    /// settings come back through auto-reconfiguration (7.1: "if a reset
    /// occurs"), the status says RESET = hardware, and no frame follows.
    pub fn hardware_reset(&mut self, now: Instant) {
        self.restart(now, true, false);
    }

    /// RESETn held low (`true`: the chip stops, deaf and mute, its UART
    /// silent) or released (`false`: it boots as after any hardware
    /// reset, [`St7570::hardware_reset`]: auto-reconfiguration, status
    /// RESET = 0). A host wiring DTR to RESETn pulses it to reset the
    /// modem (`plm sim`, docs/protocol-notes.md "ST7570: simulated
    /// modem").
    pub fn set_resetn(&mut self, now: Instant, low: bool) {
        match (low, self.power) {
            (true, _) => {
                self.power = Power::Held;
                self.jobs.clear();
                self.line_out.clear();
            }
            (false, Power::Held) => self.hardware_reset(now),
            (false, _) => {}
        }
    }

    fn restart(&mut self, now: Instant, keep: bool, power_on: bool) {
        self.mib = self.mib.after_reset(keep);
        self.software_reset = false;
        self.heard_sync = false;
        self.client_found = false;
        self.is_until = None;
        self.alarm_quiet_until = 0;
        self.alarm_run = None;
        self.alarm_flag = false;
        self.jobs.clear();
        self.line_out.clear();
        self.forget_mac();
        self.power = if power_on {
            Power::On
        } else {
            Power::Booting {
                until: now + BOOT_TIME,
                software: false,
            }
        };
        if power_on {
            self.boot_done(now, false);
        }
    }

    fn boot_done(&mut self, now: Instant, software: bool) {
        self.power = Power::On;
        self.spy_from = now;
        self.software_reset = software;
        self.engine.reset();
        self.engine.set_tic(self.mib.tic_repeater().tic_selector());
        self.start_is(now);
        self.refresh_status();
        if software {
            // Table 25: RESET = 0, "the reset request has been taken into
            // account".
            self.submit(now, Command::ResetRequest { reset: 0 });
        }
        if self.treq {
            self.engine.set_treq(now, true);
        }
        self.pump(now);
    }

    /// The host's T_REQ level changed (`asserted`: low).
    pub fn set_treq(&mut self, now: Instant, asserted: bool) {
        self.treq = asserted;
        if self.is_on() {
            self.refresh_status();
            self.engine.set_treq(now, asserted);
            self.pump(now);
        }
    }

    /// Bytes from the host's UART.
    pub fn handle_rx(&mut self, now: Instant, bytes: &[u8]) {
        if self.is_on() {
            self.refresh_status();
            self.engine.handle_rx(now, bytes);
            self.pump(now);
        }
    }

    /// The next moment [`St7570::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        match self.power {
            Power::Booting { until, .. } => Some(until),
            Power::Held => None,
            Power::On => {
                let jobs = self.jobs.iter().map(|j| {
                    if j.confirm.is_some() {
                        j.confirm_at
                    } else {
                        j.end
                    }
                });
                let mut t = earliest(self.engine.poll_timeout(), self.is_until);
                t = earliest(t, self.spy_due());
                t = earliest(t, self.mac_due());
                for j in jobs {
                    t = earliest(t, Some(j));
                }
                t
            }
        }
    }

    /// Runs whatever is due at `now`.
    pub fn handle_timeout(&mut self, now: Instant) {
        match self.power {
            Power::Booting { until, software } => {
                if now >= until {
                    self.boot_done(now, software);
                }
                return;
            }
            Power::Held => return,
            Power::On => {}
        }
        self.run_jobs(now);
        self.spy_tick(now);
        self.mac_tick(now);
        if self.is_until.is_some_and(|t| now >= t) {
            self.is_end(now);
        }
        self.refresh_status();
        self.engine.handle_timeout(now);
        self.pump(now);
    }

    fn run_jobs(&mut self, now: Instant) {
        let mut i = 0;
        while i < self.jobs.len() {
            if self.jobs[i].confirm_at <= now {
                if let Some(c) = self.jobs[i].confirm.take() {
                    self.submit(now, c);
                }
            }
            if self.jobs[i].end <= now && self.jobs[i].confirm.is_none() {
                let job = self.jobs.remove(i);
                if let Some((index, n)) = job.count {
                    self.mib.count(index, n);
                }
            } else {
                i += 1;
            }
        }
    }

    /// The next UART output for the host.
    pub fn poll_transmit(&mut self) -> Option<Vec<u8>> {
        // Held in reset, the chip's TXD is silent.
        if self.power == Power::Held {
            return None;
        }
        // The device side only writes bytes; T_REQ is the host's line.
        loop {
            if let Transmit::Bytes(b) = self.engine.poll_transmit()? {
                return Some(b);
            }
        }
    }

    /// The next transmission this modem puts on the line.
    pub fn poll_line(&mut self) -> Option<Transmission> {
        self.line_out.pop_front()
    }

    /// Whether one of its own transmissions is on the line at `now` (the
    /// modem is half duplex: it hears nothing meanwhile).
    fn on_air(&self, now: Instant) -> bool {
        self.jobs.iter().any(|j| j.start <= now && now < j.end)
    }

    /// Starts the intelligent synchronization search of a MAC Server whose
    /// 0009h is not 0 (minutes), or stops it (5.3.25, 6.5.10).
    fn start_is(&mut self, now: Instant) {
        let minutes = self.mib.word(store::IS_TIMEOUT, 0) as u64;
        let ctx = self.mib.context();
        self.is_until = (minutes > 0
            && ctx.layer == Layer::Mac
            && ctx.mode == mode::SERVER
            && !self.synchronized())
        .then(|| now + minutes * 60_000 * MS / self.timeout_scale);
    }

    fn submit(&mut self, now: Instant, cmd: Command) {
        self.engine.submit(now, cmd.to_frame());
    }

    /// Acts on what the link engine reports.
    fn pump(&mut self, now: Instant) {
        while let Some(ev) = self.engine.poll_event() {
            match ev {
                DeviceEvent::Request(frame) => {
                    if let Some(answer) = self.answer(now, &frame) {
                        self.submit(now, answer);
                    }
                    if !self.is_on() {
                        return;
                    }
                }
                // 5.3.26: "the value declared in the length field has not
                // been respected": a frame cut short by T_IC.
                DeviceEvent::FrameCut => self.submit(now, requests::SYNTAX_ERROR),
                // Table 11: ALARM is set in one status message only.
                DeviceEvent::Sent(Element::Status(_)) => self.alarm_flag = false,
                _ => {}
            }
        }
        self.refresh_status();
    }

    fn refresh_status(&mut self) {
        self.engine.set_status(self.status().to_message());
    }

    /// Drops a Server's synchronization (CMD_DesynchroRequest, 00A0h, a
    /// mode change).
    fn lose_sync(&mut self, now: Instant) {
        self.heard_sync = false;
        self.forget_mac();
        self.spy_from = now;
        self.client_found = false;
        self.start_is(now);
    }

    /// 00A1h's local address after a mode change (4.5.4): a Client takes
    /// FIMA, a node leaving Client mode is NEW again.
    fn mode_changed(&mut self, now: Instant, before: u8) {
        let after = self.mode();
        let init = self.mib.word(index::LOCAL_INIT_MAC_ADD, 2);
        let local = if after == mode::CLIENT {
            Some(self.mib.fima())
        } else if before == mode::CLIENT {
            Some(NEW)
        } else {
            None
        };
        if let Some(local) = local {
            let mut v = local.to_le_bytes().to_vec();
            v.extend_from_slice(&init.to_le_bytes());
            self.mib.set(index::LOCAL_INIT_MAC_ADD, &v);
        }
        self.lose_sync(now);
    }
}
