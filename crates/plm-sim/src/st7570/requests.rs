//! What the simulated ST7570 answers to each request of Table 15, and the
//! confirm code it refuses one with when its state does not allow it
//! (Tables 43, 48, 63; 5.3.26 for CMD_SyntaxError).

use super::slots::{SlotUse, Transmission, FRAME_BITS};
use super::{mode, store, Power, St7570, TxJob, BOOT_TIME};
use plm_core::link::LocalFrame;
use plm_core::st7570::mac::MacFrame;
use plm_core::st7570::mib::index;
use plm_core::st7570::validate::{check_data_request, check_read, check_write};
use plm_core::st7570::{
    code, Address, Command, Credit, Layer, MacData, MacSync, RcHeard, SyncEstimate,
};
use plm_core::time::Instant;

/// CONFIRM_CODEs of Tables 43, 48 and 63 (the same byte in PHY and MAC
/// mode; the names differ).
pub mod confirm {
    /// LP_TU / LM_TU: busy.
    pub const BUSY: u8 = 0x00;
    /// LP_NI: not initialized for a repeater call.
    pub const NOT_INITIALIZED: u8 = 0x01;
    /// LP_NS / LM_NS: not synchronized.
    pub const NOT_SYNCHRONIZED: u8 = 0x04;
    /// LM_IS: intelligent synchronization search in progress.
    pub const IS_RUNNING: u8 = 0x05;
    /// LP_NOT_VALID: a repeater call refused to a NEVER_REPEAT node.
    pub const NOT_VALID: u8 = 0x06;
    /// LP_OK / LM_OK.
    pub const OK: u8 = 0xFF;
}

/// 5.3.26: ERROR is 01h.
pub(super) const SYNTAX_ERROR: Command = Command::SyntaxError { error: 0x01 };

impl St7570 {
    /// The answer to a request the link engine accepted, if any.
    pub(super) fn answer(&mut self, now: Instant, frame: &LocalFrame) -> Option<Command> {
        let layer = self.layer();
        // 5.3.23: a CMD_RC_Request in PHY mode "does not take any effect".
        if frame.code == code::CMD_RC_REQUEST && layer == Layer::Phy {
            return None;
        }
        // 5.3.26: a code Table 15 does not give the host in this access
        // layer, or a data field the command does not take.
        if !code::is_request(frame.code) || !code::in_layer(frame.code, layer) {
            return Some(SYNTAX_ERROR);
        }
        let Ok(cmd) = Command::from_frame(frame, layer) else {
            return Some(SYNTAX_ERROR);
        };
        let ctx = self.mib.context();
        Some(match cmd {
            Command::SynchroStatusRequest => Command::SynchroStatus {
                // Table 20: 1 LP_SYNC_FOUND, 2 LP_SYNC_LOSS.
                status: if self.synchronized() { 1 } else { 2 },
            },
            Command::DesynchroRequest { reset } => return self.desynchro(now, reset),
            Command::ResetRequest { reset } => {
                // Table 24: 0 restores the stored configuration (7.1),
                // anything else loads the factory defaults.
                let software = Power::Booting {
                    until: now + BOOT_TIME,
                    software: true,
                };
                self.restart(now, reset == 0, false);
                self.power = software;
                return None;
            }
            Command::WriteDbRequest { index, data } => match check_write(index, &data, &ctx) {
                Err(r) => Command::WriteDbError { error: r.error },
                Ok(o) => {
                    let before = self.mib.context();
                    let data = self.mib.write(o, &data);
                    if let Some(effect) = self.after_write(now, index, &data, before) {
                        self.submit(now, effect);
                    }
                    Command::WriteDbConfirm { index, data }
                }
            },
            Command::ReadDbRequest { index } => match check_read(index, &ctx) {
                Err(r) => Command::ReadDbError { error: r.error },
                Ok(_) => Command::ReadDbConfirm {
                    index,
                    data: self.mib.get(index).unwrap_or_default().to_vec(),
                },
            },
            Command::PhyDataRequest { .. } | Command::MacDataRequest(_) => {
                return self.data_request(now, cmd)
            }
            Command::AlarmRequest => return self.alarm_request(now),
            Command::RcRequest {
                tx_pos,
                rc_threshold,
            } => return self.rc_request(tx_pos, rc_threshold),
            // Every other code is refused above (not a request).
            _ => SYNTAX_ERROR,
        })
    }

    /// What a write changes besides the value (6.5.12, 6.5.29, 6.5.30,
    /// 6.5.10), and the indication it draws, if any.
    fn after_write(
        &mut self,
        now: Instant,
        index: u16,
        data: &[u8],
        before: plm_core::st7570::validate::Context,
    ) -> Option<Command> {
        match index {
            index::TIC_REPEATER => self.engine.set_tic(self.mib.tic_repeater().tic_selector()),
            // 5.3.3: in MAC mode writing 01h is CMD_DesynchroRequest.
            index::NEW_SYNCHRONIZATION if data[0] == 1 && before.layer == Layer::Mac => {
                return self.desynchro(now, 1)
            }
            index::PLC_CONFIGURATION => {
                let after = self.mib.context();
                if (after.mode, after.layer) != (before.mode, before.layer) {
                    self.mode_changed(now, before.mode);
                }
            }
            store::IS_TIMEOUT => self.start_is(now),
            _ => {}
        }
        None
    }

    /// 5.3.3: RESET = 1 rejects the synchronization; MAC mode says so with
    /// SYNC = LOST, CAUSE 5 (Table 21), PHY mode says nothing.
    fn desynchro(&mut self, now: Instant, reset: u8) -> Option<Command> {
        if reset != 1 {
            return None;
        }
        self.lose_sync(now);
        (self.layer() == Layer::Mac).then(|| {
            Command::MacSynchroIndication(MacSync::Lost {
                cause: super::sync::cause::HOST,
                add1: self.mib.local_address(),
                add2: self.mib.word(index::LOCAL_INIT_MAC_ADD, 2),
            })
        })
    }

    /// Whether this mode may put a frame on the line now: a Client always
    /// (it makes the time slots), a Server or Monitor once synchronized.
    fn may_transmit(&self) -> bool {
        !self.zc_fail
            && match self.mode() {
                mode::CLIENT => true,
                mode::SERVER | mode::MONITOR => self.synchronized(),
                _ => false,
            }
    }

    /// The refusal every line request checks first: LM_IS, then LP_NS,
    /// then LP_TU (Tables 43, 48).
    fn refusal(&self) -> Option<u8> {
        if self.is_running() {
            Some(confirm::IS_RUNNING)
        } else if !self.may_transmit() {
            Some(confirm::NOT_SYNCHRONIZED)
        } else if self.busy() {
            Some(confirm::BUSY)
        } else {
            None
        }
    }

    /// 5.3.12: a refused request is confirmed at once, an accepted one
    /// goes out in the next time slot and is confirmed at the end of its
    /// (first) frame.
    fn data_request(&mut self, now: Instant, cmd: Command) -> Option<Command> {
        let refuse = |confirm_code| Some(Command::DataConfirm { confirm_code });
        if let Err((code, _)) = check_data_request(&cmd) {
            return refuse(code);
        }
        if let Some(code) = self.refusal() {
            return refuse(code);
        }
        let clock = self.slots();
        // A burst heard is not over until its last copy (4.8): the slots
        // until then are its repetitions', so the frame waits (model).
        let start = clock.next_slot(now).max(self.burst_end());
        let (slots, frame_slots, count) = match cmd {
            Command::PhyDataRequest { p_sdu } => {
                let mut p = [0u8; plm_core::st7570::fields::P_SDU_LEN];
                p.copy_from_slice(&p_sdu);
                (vec![SlotUse::Subframe(p)], 1, None)
            }
            Command::MacDataRequest(d) => {
                let (slots, ns, copies) = self.mac_slots(d)?;
                (slots, ns, Some((store::TRANSMITTED_FRAMES, copies)))
            }
            _ => return None,
        };
        if self.mode() == mode::CLIENT && self.layer() == Layer::Mac && !self.client_found {
            // 10.3.1: a Client's first transmission synchronizes it, with
            // estimates all 0.
            self.client_found = true;
            self.submit(
                now,
                Command::MacSynchroIndication(MacSync::Found(SyncEstimate::default())),
            );
        }
        let confirm_at = start + clock.slot * (frame_slots - 1) + clock.bits(FRAME_BITS);
        self.queue_line(start, slots);
        let end = self.line_out.back().map_or(start, |t| t.end());
        self.jobs.push(TxJob {
            start,
            confirm_at,
            confirm: Some(Command::DataConfirm {
                confirm_code: confirm::OK,
            }),
            end,
            count,
        });
        None
    }

    /// The slots of a MAC frame (4.4, 4.8): SA is the local address
    /// (4.5.4), CC = IC in the first copy, and a Client or repeater sends
    /// IC+1 copies with CC counting down, a Server one. With the frame's
    /// NS and the number of copies.
    fn mac_slots(&self, d: MacData) -> Option<(Vec<SlotUse>, u64, u32)> {
        let ic = d.credit.ic;
        let repeats = self.mode() == mode::CLIENT || self.mib.tic_repeater().is_repeater();
        let copies = if repeats { ic + 1 } else { 1 };
        let fi = self.mib.word(0x0012, 0);
        let mut slots = Vec::new();
        let mut ns = 0;
        for k in 0..copies {
            let frame = MacFrame {
                credit: Credit {
                    ic,
                    cc: ic - k,
                    dc: d.credit.dc,
                },
                address: Address {
                    sa: self.mib.local_address(),
                    da: d.address.da,
                },
                m_sdu: d.m_sdu.clone(),
            };
            let subframes = frame.to_subframes(fi).ok()?;
            ns = subframes.len() as u64;
            slots.extend(subframes.into_iter().map(SlotUse::Subframe));
        }
        Some((slots, ns, copies as u32))
    }

    pub(super) fn queue_line(&mut self, start: Instant, slots: Vec<SlotUse>) {
        let plc = self.mib.plc();
        self.line_out.push_back(Transmission {
            start,
            slot: self.slots().slot,
            bit_rate_2400: plc.bit_rate_2400,
            f0: plc.f0,
            f1: plc.f1,
            gain: plc.target_output_gain,
            slots,
        });
    }

    /// 5.3.15, 7.2.1: a burst of N_TX alarms (0085h byte 0) from the next
    /// slot, confirmed after it; a request during the burst or the N_REJ
    /// slots after it is confirmed LP_OK at once and sends nothing.
    fn alarm_request(&mut self, now: Instant) -> Option<Command> {
        let ok = Some(Command::AlarmConfirm {
            confirm_code: confirm::OK,
        });
        let bursting = self
            .jobs
            .iter()
            .any(|j| j.count.is_some_and(|(i, _)| i == store::TRANSMITTED_ALARMS));
        if bursting || now < self.alarm_quiet_until {
            return ok;
        }
        if let Some(code) = self.refusal() {
            return Some(Command::AlarmConfirm { confirm_code: code });
        }
        let n_tx = self.mib.byte(store::ALARM_PARAMETERS, 0).max(1) as u64;
        let n_rej = self.mib.byte(store::ALARM_PARAMETERS, 2) as u64;
        let clock = self.slots();
        let start = clock.next_slot(now);
        self.queue_line(start, vec![SlotUse::Alarm; n_tx as usize]);
        let end = start + clock.slot * n_tx;
        self.alarm_quiet_until = end + clock.slot * n_rej;
        self.jobs.push(TxJob {
            start,
            confirm_at: end,
            confirm: ok,
            end,
            count: Some((store::TRANSMITTED_ALARMS, n_tx as u32)),
        });
        None
    }

    /// 5.3.23-5.3.24 (MAC mode): refused when not synchronized (LP_NS), to
    /// a Server still NEW with no TX_POS (LP_NI) or set NEVER_REPEAT
    /// (LP_NOT_VALID), and unless a transmission is in progress (LP_TU).
    /// Accepted, the call takes the slot after that transmission (7.3): a
    /// Client calls at sub-slot 0, a Server at TX_POS or its local
    /// address, and the confirm comes at the end of that slot. With nobody
    /// on the line a Server hears no pattern (S, N, RX_POS all 0).
    fn rc_request(&mut self, tx_pos: u16, rc_threshold: u16) -> Option<Command> {
        let repeater = self.mib.tic_repeater();
        let server = self.mode() != mode::CLIENT;
        let refuse = |result| {
            Some(Command::RcConfirm {
                result,
                repeater_state: repeater.repeater_settings,
                heard: None,
            })
        };
        if !self.synchronized() {
            return refuse(confirm::NOT_SYNCHRONIZED);
        }
        if server && tx_pos == 0 && self.mib.local_address() == super::NEW {
            return refuse(confirm::NOT_INITIALIZED);
        }
        if server && repeater.repeater_settings == 0 {
            return refuse(confirm::NOT_VALID);
        }
        // A transmission of this modem, or a frame being received.
        let clock = self.slots();
        let receiving = self.assembly.as_ref().map(|a| a.end_slot() * clock.slot);
        let Some(after) = self.jobs.iter().map(|j| j.end).max().or(receiving) else {
            return refuse(confirm::BUSY);
        };
        // 5.3.23: RC_THRESHOLD 0 takes 000Ch.
        self.rc_threshold = match rc_threshold {
            0 => self.mib.word(0x000C, 0) as u32,
            t => t as u32,
        };
        let position = match (server, tx_pos) {
            (false, _) => 0,
            (true, 0) => self.mib.local_address(),
            (true, p) => p,
        };
        self.queue_line(after, vec![SlotUse::RepeaterCall { position }]);
        let end = after + clock.slot;
        self.jobs.push(TxJob {
            start: after,
            confirm_at: end,
            confirm: Some(Command::RcConfirm {
                result: confirm::OK,
                repeater_state: repeater.repeater_settings,
                heard: server.then(RcHeard::default),
            }),
            end,
            count: None,
        });
        None
    }
}
