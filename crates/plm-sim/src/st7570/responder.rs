//! A simulated Server node's host: it configures its ST7570 as a MAC
//! Server (optionally a repeater) with a local address, then answers what
//! is sent to that address, so that a demo shows traffic. It drives the
//! modem through plm-core's host engine, as the console does.
//!
//! What it answers is ours (the manual has no application layer): an
//! M_SDU starting with `?` draws `!` and the node's address and the
//! delta-phase it measured (000Eh), anything else is echoed. Answers go to
//! the sender with the IC the request came with (the way back is as long).
//!
//! Its 00A1h is the factory one made a MAC Server, with the Client's bit
//! rate, f0 and f1 once the network tells it ([`Responder::follow`],
//! docs/protocol-notes.md "ST7570: simulated network").

use super::drive::ModemDriver;
use super::mode;
use plm_core::link::host::Event;
use plm_core::st7570::mib::{index, object, PlcConfiguration};
use plm_core::st7570::{code, Address, Command, Credit, Layer, MacData, MacSync};
use plm_core::time::Instant;
use std::collections::VecDeque;

/// Synchronization changes a [`Responder`] keeps, newest last.
pub const SYNC_HISTORY: usize = 16;

/// A Server's host.
#[derive(Debug, Clone)]
pub struct Responder {
    /// The local MAC address it gives its modem.
    pub address: u16,
    /// Requests to send, in order, one at a time.
    queue: VecDeque<Command>,
    /// The request waiting for its answer.
    waiting: Option<u8>,
    /// Frames indicated to it, and answers confirmed LM_OK.
    pub indicated: u64,
    /// Answers the modem confirmed LM_OK.
    pub answered: u64,
    /// The modem's last [`SYNC_HISTORY`] CMD_SynchroIndications (Table
    /// 18), when they came: what a demo shows of a Server's
    /// synchronization.
    /// (A list: it runs in the console's page too, where a `VecDeque` of
    /// its own item type would bring its own code.)
    pub syncs: Vec<(Instant, MacSync)>,
    /// The 00A1h it gives its modem.
    plc: PlcConfiguration,
}

/// The PHY settings of 00A1h (Table 137) a Server takes on from the
/// Client: bit rate, f0 and f1. The mains frequency is the line's, the
/// gain and current limiting each modem's own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PhySettings {
    /// 2400 bit/s rather than 1200.
    pub bit_rate_2400: bool,
    /// f0 in Hz.
    pub f0: u32,
    /// f1 in Hz.
    pub f1: u32,
}

impl PhySettings {
    /// Those of `plc`.
    pub fn of(plc: &PlcConfiguration) -> Self {
        PhySettings {
            bit_rate_2400: plc.bit_rate_2400,
            f0: plc.f0,
            f1: plc.f1,
        }
    }

    /// `plc` with these.
    fn apply(self, plc: &mut PlcConfiguration) {
        plc.bit_rate_2400 = self.bit_rate_2400;
        plc.f0 = self.f0;
        plc.f1 = self.f1;
    }
}

fn write(index: u16, data: Vec<u8>) -> Command {
    Command::WriteDbRequest { index, data }
}

impl Responder {
    /// A host that makes its modem a MAC Server at `address` (a repeater,
    /// ALWAYS_REPEAT, if `repeater`).
    pub fn new(address: u16, repeater: bool) -> Self {
        let mut plc = PlcConfiguration::decode(object(index::PLC_CONFIGURATION).unwrap().default);
        plc.operating_mode = mode::SERVER;
        plc.access_layer_mode = Layer::Mac.access_layer_mode();
        let mut queue = VecDeque::new();
        queue.push_back(write(index::PLC_CONFIGURATION, plc.encode()));
        let mut local = address.to_le_bytes().to_vec();
        local.extend_from_slice(&[0, 0]);
        queue.push_back(write(index::LOCAL_INIT_MAC_ADD, local));
        if repeater {
            queue.push_back(write(index::TIC_REPEATER, vec![0x01]));
        }
        Responder {
            address,
            queue,
            waiting: None,
            indicated: 0,
            answered: 0,
            syncs: Vec::new(),
            plc,
        }
    }

    /// Takes on the Client's bit rate, f0 and f1: if they differ from
    /// those it gave its modem, its 00A1h with them is written before
    /// anything else it has to send (replacing one not sent yet).
    pub fn follow(&mut self, phy: PhySettings) {
        if PhySettings::of(&self.plc) == phy {
            return;
        }
        phy.apply(&mut self.plc);
        self.queue.retain(|c| {
            !matches!(c, Command::WriteDbRequest { index: i, .. } if *i == index::PLC_CONFIGURATION)
        });
        self.queue
            .push_front(write(index::PLC_CONFIGURATION, self.plc.encode()));
    }

    /// Has its modem send an alarm (CMD_AlarmRequest, 5.3.15) once the
    /// requests before it are done: what a demo shows of alarms.
    pub fn raise_alarm(&mut self) {
        self.queue.push_back(Command::AlarmRequest);
    }

    /// Acts on the host events since the last call and sends the next
    /// request if none is waiting.
    pub fn step(&mut self, d: &mut ModemDriver) {
        if d.events.is_empty() && (self.waiting.is_some() || self.queue.is_empty()) {
            return;
        }
        let layer = d.port.modem.layer();
        for (at, e) in std::mem::take(&mut d.events) {
            match e {
                Event::Frame(f) => {
                    if self
                        .waiting
                        .is_some_and(|r| code::answers(r, f.code, layer))
                    {
                        self.waiting = None;
                    }
                    match Command::from_frame(&f, layer) {
                        Ok(Command::MacDataIndication(m)) if m.address.da == self.address => {
                            self.indicated += 1;
                            let answer = self.answer(d, &m);
                            self.queue.push_back(answer);
                        }
                        Ok(Command::DataConfirm { confirm_code: 0xFF }) => self.answered += 1,
                        Ok(Command::MacSynchroIndication(sync)) => {
                            if self.syncs.len() == SYNC_HISTORY {
                                self.syncs.remove(0);
                            }
                            self.syncs.push((at, sync));
                        }
                        _ => {}
                    }
                }
                Event::Failed(..) => self.waiting = None,
                _ => {}
            }
        }
        if self.waiting.is_none() {
            if let Some(cmd) = self.queue.pop_front() {
                self.waiting = Some(cmd.code());
                d.submit(&cmd);
            }
        }
    }

    fn answer(&self, d: &ModemDriver, m: &MacData) -> Command {
        let m_sdu = if m.m_sdu.first() == Some(&b'?') {
            let phase = d.port.modem.mib().byte(0x000E, 8);
            format!("!{:03X} phase {phase}", self.address).into_bytes()
        } else {
            m.m_sdu.clone()
        };
        Command::MacDataRequest(MacData {
            credit: Credit {
                ic: m.credit.ic,
                cc: m.credit.ic,
                dc: m.credit.ic.saturating_sub(m.credit.cc).min(3),
            },
            address: Address {
                sa: self.address,
                da: m.address.sa,
            },
            pad: 0,
            m_sdu,
        })
    }
}
