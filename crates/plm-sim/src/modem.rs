//! The simulated ST7580: its host interface (through plm-core's device
//! link engine), its MIB (Table 52) and its power line transmit and
//! receive paths (UM0932 2.2-2.4, Figure 5).
//!
//! The modem does not know the world around it: the simulation hands it
//! UART bytes, T_REQ levels and frames heard on the line, and takes from
//! it UART bytes and frames to put on the line.

use crate::line::{self, FskShape, Transmission};
use crate::rng::Rng;
use plm_core::link::device::{DeviceEngine, DeviceEvent};
use plm_core::link::host::Transmit;
use plm_core::link::{Dialect, LocalFrame};
use plm_core::st7580::mib::{self as mib, index, MibObject, ModemConfig, PhyConfig};
use plm_core::st7580::plc::{self, DlOptions, DlReceived, SsError};
use plm_core::st7580::validate::check_request;
use plm_core::st7580::{
    code, ActiveLayer, Channel, Command, DataConfirm, DataIndication, ErrorCause, FrequencySet,
    IndicationInfo, Modulation, ResetCause, ResetData, Status, Temperature, TxParams,
};
use plm_core::time::{earliest, Duration, Instant, MS};
use std::collections::VecDeque;

/// Time from a reset to the BIO_ResetIndication (model; the manual gives
/// none).
pub const BOOT_TIME: Duration = 20 * MS;
/// Time from an accepted data request to the start of the preamble.
pub const TX_SETUP: Duration = MS;
/// TX gain above which the line driver hits its current limit (model).
pub const OVERCURRENT_GAIN: u8 = 28;

/// The three frame structures (UM0932 2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layer {
    /// PHY frames.
    Phy,
    /// DL frames.
    Dl,
    /// SS frames.
    Ss,
}

impl Layer {
    /// The MIB counters object of the layer (Tables 58-60).
    fn counters(self) -> u8 {
        match self {
            Layer::Phy => index::PHY_DATA,
            Layer::Dl => index::DL_DATA,
            Layer::Ss => index::SS_DATA,
        }
    }

    /// Byte offsets of the transmitted and refused counters in it.
    fn tx_counters(self) -> (usize, usize) {
        match self {
            Layer::Phy => (4, 6),
            Layer::Dl => (4, 6),
            Layer::Ss => (6, 8),
        }
    }

    fn confirm(self, c: DataConfirm) -> Command {
        match self {
            Layer::Phy => Command::PhyDataConfirm(c),
            Layer::Dl => Command::DlDataConfirm(c),
            Layer::Ss => Command::SsDataConfirm(c),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Power {
    /// Restarting: deaf and mute until `until`, then BIO_ResetIndication.
    Booting {
        until: Instant,
        cause: ResetCause,
    },
    On,
    /// RESETN held low: off until it is released.
    Held,
}

#[derive(Debug, Clone)]
struct TxJob {
    layer: Layer,
    end: Instant,
    confirm: DataConfirm,
}

/// A simulated ST7580.
#[derive(Debug, Clone)]
pub struct St7580 {
    node: usize,
    baud: u32,
    engine: DeviceEngine,
    mib: Vec<Vec<u8>>,
    /// MIB 00h and 01h decoded, kept in step with `mib` by
    /// [`St7580::store`] and [`St7580::reset`]: every frame on the line
    /// asks for them.
    config: (ModemConfig, PhyConfig),
    /// The status last handed to the link engine.
    status_sent: Option<Status>,
    /// MIB 00h, 01h, 02h written since power-on (Table 19 bits 3-5).
    written: [bool; 3],
    power: Power,
    treq: bool,
    tx: Option<TxJob>,
    receiving: usize,
    overcurrent: bool,
    /// Simulated die temperature class (Table 8).
    pub temperature: Temperature,
    /// A BIO_ResetConfirm is out: reset once it is delivered.
    reset_pending: bool,
    /// For SS initialisation vectors: seeded from the simulation's seed.
    rng: Rng,
    line_out: VecDeque<Transmission>,
}

impl St7580 {
    /// Modem of node `node`, powering on at `now` (UART at `baud`); `seed`
    /// fixes the IVs it picks.
    pub fn new(node: usize, baud: u32, now: Instant, seed: u64) -> Self {
        let mib = factory_mib();
        let mut m = St7580 {
            node,
            baud,
            engine: DeviceEngine::new(Dialect::St7580, baud),
            config: decode_config(&mib),
            mib,
            status_sent: None,
            written: [false; 3],
            power: Power::On,
            treq: false,
            tx: None,
            receiving: 0,
            overcurrent: false,
            temperature: Temperature::Below70,
            reset_pending: false,
            rng: Rng::new(seed ^ (node as u64).rotate_left(32)),
            line_out: VecDeque::new(),
        };
        m.reset(now, ResetCause::PowerOn);
        m
    }

    /// The node this modem sits at.
    pub fn node(&self) -> usize {
        self.node
    }

    /// Current value of MIB object `index` (Table 52), as the host would
    /// read it.
    pub fn mib(&self, index: u8) -> Option<&[u8]> {
        self.mib.get(index as usize).map(|v| v.as_slice())
    }

    /// Sets a MIB object directly, as if its host had written it (used to
    /// bring up simulated peers already configured). Checked like a write.
    pub fn configure(&mut self, index: u8, data: &[u8]) -> Result<(), plm_core::mib::MibError> {
        mib::check_write(index, data)?;
        self.store(index, data);
        if let Some(w) = self.written.get_mut(index as usize) {
            *w = true;
        }
        Ok(())
    }

    /// MIB 00h.
    pub fn modem_config(&self) -> ModemConfig {
        self.config.0
    }

    /// MIB 01h.
    pub fn phy_config(&self) -> PhyConfig {
        self.config.1
    }

    /// Whether a power line frame is being transmitted.
    pub fn transmitting(&self) -> bool {
        self.tx.is_some()
    }

    /// Whether the modem is up (not restarting).
    pub fn is_on(&self) -> bool {
        self.power == Power::On
    }

    /// The status message bits now (UM0932 Table 8).
    pub fn status(&self) -> Status {
        let mc = self.modem_config();
        Status {
            configuration_status: self.written.contains(&false),
            transmitting: self.tx.is_some(),
            receiving: self.receiving > 0,
            active_layer: ActiveLayer::from_bits(mc.access_mode),
            overcurrent: self.overcurrent,
            temperature: self.temperature,
        }
    }

    /// Changes the UART baud rate (BR0/BR1 strapped to the host's rate).
    pub fn set_baud(&mut self, baud: u32) {
        self.baud = baud;
        self.engine.set_baud(baud);
    }

    /// Restarts the modem at `now`: a power-on or RESETN reset forgets the
    /// MIB; a BIO_ResetRequest or watchdog reset keeps the objects 00h-02h
    /// the host wrote (autoreconfiguration, Table 19). Everything in flight
    /// is lost; the BIO_ResetIndication follows after [`BOOT_TIME`].
    pub fn reset(&mut self, now: Instant, cause: ResetCause) {
        let keep = cause != ResetCause::PowerOn;
        let old = std::mem::replace(&mut self.mib, factory_mib());
        if keep {
            for (i, value) in old.into_iter().take(3).enumerate() {
                if self.written[i] {
                    self.mib[i] = value;
                }
            }
        } else {
            self.written = [false; 3];
        }
        self.config = decode_config(&self.mib);
        self.engine = DeviceEngine::new(Dialect::St7580, self.baud);
        self.status_sent = None;
        self.tx = None;
        self.reset_pending = false;
        self.overcurrent = false;
        self.line_out.clear();
        self.power = Power::Booting {
            until: now + BOOT_TIME,
            cause,
        };
    }

    /// RESETN pulled low (`low`) or released at `now` (a host that wires
    /// DTR to RESETN): held low, the modem is off, deaf and mute, its
    /// MIB lost; released, it boots as at power-on (factory MIB,
    /// BIO_ResetIndication with cause 0 after [`BOOT_TIME`], Table 19).
    pub fn set_resetn(&mut self, now: Instant, low: bool) {
        if low && self.power != Power::Held {
            self.reset(now, ResetCause::PowerOn);
            self.power = Power::Held;
        } else if !low && self.power == Power::Held {
            self.power = Power::Booting {
                until: now + BOOT_TIME,
                cause: ResetCause::PowerOn,
            };
        }
    }

    /// Whether RESETN is held low.
    pub fn resetn_low(&self) -> bool {
        self.power == Power::Held
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

    /// The next moment [`St7580::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        match &self.power {
            Power::Booting { until, .. } => Some(*until),
            Power::Held => None,
            Power::On => earliest(self.engine.poll_timeout(), self.tx.as_ref().map(|t| t.end)),
        }
    }

    /// Runs whatever is due at `now`.
    pub fn handle_timeout(&mut self, now: Instant) {
        match self.power {
            Power::Booting { until, cause } => {
                if now >= until {
                    self.power = Power::On;
                    self.boot_done(now, cause);
                }
                return;
            }
            Power::Held => return,
            Power::On => {}
        }
        if let Some(job) = self.tx.take_if(|t| now >= t.end) {
            self.tx_done(now, job);
        }
        self.refresh_status();
        self.engine.handle_timeout(now);
        self.pump(now);
    }

    /// The next UART output for the host.
    pub fn poll_transmit(&mut self) -> Option<Vec<u8>> {
        // The device side only writes bytes; T_REQ is the host's line.
        loop {
            if let Transmit::Bytes(b) = self.engine.poll_transmit()? {
                return Some(b);
            }
        }
    }

    /// The next frame this modem puts on the line.
    pub fn poll_line(&mut self) -> Option<Transmission> {
        self.line_out.pop_front()
    }

    /// A reception starts (`true`) or ends (`false`): the status bit.
    pub fn set_receiving(&mut self, receiving: bool) {
        if receiving {
            self.receiving += 1;
        } else {
            self.receiving = self.receiving.saturating_sub(1);
        }
        self.refresh_status();
    }

    /// A frame heard on the line, its bytes as received (maybe
    /// corrupted), on `channel` with the given level and SNR: the
    /// reception flow of UM0932 Figure 5.
    pub fn receive(&mut self, now: Instant, rx: Reception) {
        if !self.is_on() || self.transmitting() {
            return;
        }
        // Table 58: every preamble + UW, and every frame with a right one.
        self.bump(index::PHY_DATA, 0);
        self.bump(index::PHY_DATA, 2);
        self.set_counter(index::PHY_DATA, 8, line::network_period());
        let info = IndicationInfo {
            modulation: rx.modulation,
            rx_channel: rx.channel,
            pga: rx.pga,
            snr: rx.snr,
            zc_delay: line::zc_delay(rx.uw_end, line::phase_of(self.node)),
        };
        let mc = self.modem_config();
        let psdu = &rx.psdu;
        // The length byte, then as many bytes as it announces; an SS
        // frame's CRC follows them, uncounted (`plc::ss_frame`).
        let dl = DlOptions::from_modem_config(&mc);
        let uncounted = if mc.access_mode == 2 { dl.crc.len() } else { 0 };
        let declared = psdu.first().copied().unwrap_or(0) as usize + uncounted;
        let frame = &psdu[..(1 + declared).min(psdu.len())];
        let body = frame.get(1..).unwrap_or_default();
        let ind = |payload: Vec<u8>| DataIndication { info, payload };
        let out = match mc.access_mode {
            0 => Some(Command::PhyDataIndication(ind(body.to_vec()))),
            mode => {
                let opened = if mode == 1 {
                    plc::dl_open(&dl, frame)
                } else {
                    plc::ss_frame_open(&dl, frame)
                };
                match opened {
                    Ok(DlReceived::Good { payload }) => {
                        self.bump(index::DL_DATA, 0);
                        if mode == 1 {
                            Some(Command::DlDataIndication(ind(payload)))
                        } else {
                            self.open_ss(mc, payload, ind)
                        }
                    }
                    Ok(DlReceived::WrongCrc { mut payload, crc }) => {
                        self.bump(index::DL_DATA, 2);
                        payload.extend_from_slice(&crc);
                        mc.sniffer_mode
                            .then(|| Command::DlSnifferIndication(ind(payload)))
                    }
                    // Cut short or too short for its CRC: malformed.
                    Err(_) => {
                        self.bump(index::DL_DATA, 2);
                        None
                    }
                }
            }
        };
        if let Some(cmd) = out {
            self.store(index::LAST_DATA_INDICATION, &info.encode());
            self.engine.submit(now, cmd.to_frame());
        }
    }

    /// SS frames: authenticate, then decrypt (Figure 5).
    fn open_ss(
        &mut self,
        mc: ModemConfig,
        sdu: Vec<u8>,
        ind: impl Fn(Vec<u8>) -> DataIndication,
    ) -> Option<Command> {
        let key: [u8; 16] = self.mib[index::SS_KEY as usize]
            .as_slice()
            .try_into()
            .unwrap_or([0; 16]);
        match plc::ss_open(&key, &sdu) {
            Ok(clear) => {
                self.bump(index::SS_DATA, 0);
                Some(Command::SsDataIndication(ind(clear)))
            }
            Err(e) => {
                let at = if e == SsError::Authentication { 2 } else { 4 };
                self.bump(index::SS_DATA, at);
                mc.sniffer_mode
                    .then(|| Command::SsSnifferIndication(ind(sdu)))
            }
        }
    }

    fn boot_done(&mut self, now: Instant, cause: ResetCause) {
        let default = |i: usize| !self.written[i];
        let data = ResetData {
            reset_cause: cause,
            autoreconfiguration_error: self.written.contains(&false),
            modem_config_error: default(0),
            phy_config_error: default(1),
            ss_key_error: default(2),
        };
        self.refresh_status();
        self.engine
            .submit(now, Command::BioResetIndication(data).to_frame());
        if self.treq {
            self.engine.set_treq(now, true);
        }
        self.pump(now);
    }

    fn tx_done(&mut self, now: Instant, job: TxJob) {
        let (sent, _) = job.layer.tx_counters();
        self.bump(job.layer.counters(), sent);
        self.set_counter(index::PHY_DATA, 8, line::network_period());
        self.store(index::LAST_TX_CONFIRM, &job.confirm.encode());
        self.engine
            .submit(now, job.layer.confirm(job.confirm).to_frame());
    }

    /// Acts on what the link engine reports.
    fn pump(&mut self, now: Instant) {
        while let Some(ev) = self.engine.poll_event() {
            match ev {
                DeviceEvent::Request(frame) => self.execute(now, frame),
                DeviceEvent::Delivered { frame, .. }
                    if frame.code == code::BIO_RESET_CONFIRM && self.reset_pending =>
                {
                    self.reset(now, ResetCause::ResetRequest);
                    return;
                }
                _ => {}
            }
        }
        self.refresh_status();
    }

    fn refresh_status(&mut self) {
        let s = self.status();
        if self.status_sent != Some(s) {
            self.status_sent = Some(s);
            self.engine.set_status(s.to_message());
        }
    }

    /// Executes a request the link engine accepted (UM0932 3.3, Table 10).
    fn execute(&mut self, now: Instant, frame: LocalFrame) {
        let answer = match self.answer(now, &frame) {
            Ok(Some(cmd)) => cmd.to_frame(),
            Ok(None) => return,
            Err(cause) => match code::error_for(frame.code) {
                Some(err) => LocalFrame::new(err, vec![cause.byte()]),
                None => return,
            },
        };
        self.engine.submit(now, answer);
    }

    fn answer(&mut self, now: Instant, frame: &LocalFrame) -> Result<Option<Command>, ErrorCause> {
        if !code::is_request(frame.code) {
            return Ok(Some(Command::CmdSyntaxError { error: frame.code }));
        }
        let layer = match frame.code {
            code::PHY_DATA_REQUEST => Some(Layer::Phy),
            code::DL_DATA_REQUEST => Some(Layer::Dl),
            code::SS_DATA_REQUEST => Some(Layer::Ss),
            _ => None,
        };
        let refused = |m: &mut Self, cause| {
            if let Some(l) = layer {
                m.bump(l.counters(), l.tx_counters().1);
            }
            Err(cause)
        };
        let cmd = match Command::from_frame(frame) {
            Ok(cmd) => cmd,
            Err(_) => return refused(self, ErrorCause::WrongParameterLength),
        };
        let mc = self.modem_config();
        let crc_len = DlOptions::from_modem_config(&mc).crc.len();
        if let Err(r) = check_request(&cmd, crc_len) {
            return refused(self, r.cause);
        }
        if layer.is_some() {
            if self.tx.is_some() {
                return refused(self, ErrorCause::Busy);
            }
            if self.temperature == Temperature::Above125 {
                return refused(self, ErrorCause::ThermalError);
            }
        }
        Ok(match cmd {
            Command::BioResetRequest => {
                self.reset_pending = true;
                Some(Command::BioResetConfirm { confirm_data: 0 })
            }
            Command::MibWriteRequest { index, data } => {
                self.configure(index, &data)
                    .map_err(|e| mib::error_cause(&e))?;
                Some(Command::MibWriteConfirm)
            }
            Command::MibReadRequest { index } => Some(Command::MibReadConfirm {
                data: self.mib[index as usize].clone(),
            }),
            Command::MibEraseRequest { index } => {
                let len = self.mib[index as usize].len();
                self.store(index, &vec![0; len]);
                Some(Command::MibEraseConfirm)
            }
            Command::PingRequest { data } => Some(Command::PingConfirm { data }),
            Command::PhyDataRequest(r) => {
                let psdu =
                    plc::phy_frame(&r.payload).map_err(|_| ErrorCause::WrongParameterLength)?;
                self.start_tx(now, Layer::Phy, r.params, psdu);
                None
            }
            Command::DlDataRequest(r) => {
                let psdu = plc::dl_frame(&DlOptions::from_modem_config(&mc), &r.payload)
                    .map_err(|_| ErrorCause::WrongParameterLength)?;
                self.start_tx(now, Layer::Dl, r.params, psdu);
                None
            }
            Command::SsDataRequest(r) => {
                let key: [u8; 16] = self.mib[index::SS_KEY as usize]
                    .as_slice()
                    .try_into()
                    .unwrap_or([0; 16]);
                // UM0932 2.3: "deciding an arbitrary initialization vector".
                let mut iv = [0u8; plc::IV_LEN];
                self.rng.fill(&mut iv);
                let sdu = plc::ss_seal(&key, &iv, r.header_length as usize, &r.header_and_payload)
                    .map_err(|_| ErrorCause::WrongParameterLength)?;
                let psdu = plc::ss_frame(&DlOptions::from_modem_config(&mc), &sdu)
                    .map_err(|_| ErrorCause::WrongParameterLength)?;
                self.start_tx(now, Layer::Ss, r.params, psdu);
                None
            }
            // Not requests: answered above.
            _ => Some(Command::CmdSyntaxError { error: frame.code }),
        })
    }

    /// Puts a frame on the line (UM0932 3.3.12, Table 35): frequency and
    /// gain from the request or PHY_Config, ZC synchronisation, current
    /// control; the confirm comes at the end of the transmission.
    fn start_tx(&mut self, now: Instant, layer: Layer, p: TxParams, psdu: Vec<u8>) {
        let mut phy = self.phy_config();
        let frequency = match (p.tx_frequency, p.frequency_set) {
            (Some(hz), set) => {
                if p.frequency_overwrite {
                    match set {
                        FrequencySet::High => phy.high_frequency = hz,
                        FrequencySet::Low => phy.low_frequency = hz,
                    }
                    self.store(index::PHY_CONFIG, &phy.encode());
                }
                hz
            }
            (None, FrequencySet::High) => phy.high_frequency,
            (None, FrequencySet::Low) => phy.low_frequency,
        };
        let gain = p.tx_gain.unwrap_or(phy.tx_gain);
        let phase = line::phase_of(self.node);
        let start = if p.zero_crossing_sync {
            line::next_zc_slot(now + TX_SETUP, phase, phy.zc_delay)
        } else {
            now + TX_SETUP
        };
        let (sync, _) = line::timing(p.modulation, &phy);
        let end = start + line::airtime(p.modulation, &phy, psdu.len());
        let uw_end = start + sync;
        self.overcurrent = gain > OVERCURRENT_GAIN;
        let limited = if phy.current_control && self.overcurrent {
            OVERCURRENT_GAIN
        } else {
            gain
        };
        let confirm = DataConfirm {
            max_temp: self.temperature,
            max_gain: gain,
            min_temp: self.temperature,
            min_gain: limited,
            overcurrent_events: if phy.current_control {
                gain - limited
            } else {
                0
            },
            overcurrent: self.overcurrent,
            zc_delay: line::zc_delay(uw_end, phase),
        };
        self.line_out.push_back(Transmission {
            from: self.node,
            start,
            uw_end,
            end,
            modulation: p.modulation,
            frequency,
            gain: limited,
            fsk: (p.modulation == Modulation::BFsk).then(|| FskShape::of(&phy)),
            psdu,
        });
        self.tx = Some(TxJob {
            layer,
            end,
            confirm,
        });
        self.refresh_status();
    }

    fn store(&mut self, index: u8, data: &[u8]) {
        if index == index::HOST_INTERFACE_TIMEOUT {
            if let Ok(t) = MibObject::decode(index, data) {
                if let Some(t) = t.timeouts() {
                    self.engine.set_timeouts(t);
                }
            }
        }
        if let Some(v) = self.mib.get_mut(index as usize) {
            v.clear();
            v.extend_from_slice(data);
        }
        if index == index::MODEM_CONFIG || index == index::PHY_CONFIG {
            self.config = decode_config(&self.mib);
        }
    }

    fn counter(&self, index: u8, at: usize) -> u16 {
        let v = &self.mib[index as usize];
        u16::from_be_bytes([v[at], v[at + 1]])
    }

    fn set_counter(&mut self, index: u8, at: usize, value: u16) {
        self.mib[index as usize][at..at + 2].copy_from_slice(&value.to_be_bytes());
    }

    /// Counts one more (16-bit counters wrap, like the chip's).
    fn bump(&mut self, index: u8, at: usize) {
        let v = self.counter(index, at).wrapping_add(1);
        self.set_counter(index, at, v);
    }
}

/// Every MIB object at its factory value (Table 52).
fn factory_mib() -> Vec<Vec<u8>> {
    mib::OBJECTS.iter().map(|o| o.default.to_vec()).collect()
}

/// MIB 00h and 01h of `mib`, decoded.
fn decode_config(mib: &[Vec<u8>]) -> (ModemConfig, PhyConfig) {
    (
        ModemConfig::decode(&mib[index::MODEM_CONFIG as usize]),
        PhyConfig::decode(&mib[index::PHY_CONFIG as usize]),
    )
}

/// A frame as one modem received it.
#[derive(Debug, Clone, PartialEq)]
pub struct Reception {
    /// Frame modulation.
    pub modulation: Modulation,
    /// Channel it came in on.
    pub channel: Channel,
    /// PGA value.
    pub pga: u8,
    /// Raw SNR byte (255 for FSK, Table 39).
    pub snr: u8,
    /// End of its unique word.
    pub uw_end: Instant,
    /// The bytes after the unique word, as received.
    pub psdu: Vec<u8>,
}
