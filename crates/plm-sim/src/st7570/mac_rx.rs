//! MAC reception in the simulated ST7570 (ST7570 UM 4.4, 4.5.3, 4.8):
//! subframes in consecutive slots joined into a long frame by plm-core's
//! `mac` codec, FI/NS/FCS checks and their counters (0006h, 000Ah, 0011h,
//! 0007h), the reception rules of 4.5.3 and Table 6, repetitions told
//! from first copies, and a repeater joining a burst with CC-1..0.

use super::slots::{Heard, SlotUse, Transmission};
use super::{mode, store, St7570, TxJob, NEW};
use plm_core::st7570::mac::{self, LongFrame, MacFrame, LONG_MAC_FRAME, SUBFRAME_LEN};
use plm_core::st7570::{Command, Credit, Group, MacData, SyncEstimate};
use plm_core::time::Instant;

/// 0008h (Monitor): b0 disables the frame type check, b1 the CRC check.
const DISABLE_CHECKS: u16 = 0x0008;
/// 000Ah valid frames, 0010h repeated frames, 0011h bad FI.
const VALID_FRAMES: u16 = 0x000A;
const REPEATED_FRAMES: u16 = 0x0010;
const BAD_FI: u16 = 0x0011;
/// 0005h: five group addresses.
const GROUPS: u16 = 0x0005;
/// 0015h: a Monitor rejects the synchronization after each frame.
const AUTO_REJECT: u16 = 0x0015;

/// A long frame being received.
#[derive(Debug, Clone)]
pub(super) struct Assembly {
    subframes: Vec<[u8; SUBFRAME_LEN]>,
    ns: usize,
    /// The slot the next subframe must come in.
    next_slot: u64,
    first: Heard,
}

impl Assembly {
    /// The slot after the frame's last one.
    pub(super) fn end_slot(&self) -> u64 {
        self.next_slot + (self.ns - self.subframes.len()) as u64
    }
}

/// The last burst taken: a copy of the same frame before `until` (the
/// slot after its last copy) is a repetition.
#[derive(Debug, Clone)]
pub(super) struct Burst {
    frame: MacData,
    until: u64,
}

impl St7570 {
    /// When the last burst heard ends: the start of the slot after its
    /// last copy.
    pub(super) fn burst_end(&self) -> Instant {
        self.burst
            .as_ref()
            .map_or(0, |b| b.until * self.slots().slot)
    }

    /// A subframe heard in MAC mode (Client, Server or Monitor).
    pub(super) fn hear_mac(&mut self, now: Instant, heard: &Heard) -> bool {
        let slot = self.slots().slot_number(now);
        let estimate = SyncEstimate {
            sn: heard.sn,
            pga: heard.pga,
            phase: heard.phase,
        };
        let follows = self.assembly.as_ref().is_some_and(|a| a.next_slot == slot);
        if follows {
            let a = self.assembly.as_mut().expect("checked");
            a.subframes.push(heard.p_sdu);
            a.next_slot += 1;
        } else {
            if self.assembly.take().is_some() {
                // A frame whose next subframe never came.
                self.mib.count(store::INVALID_FRAMES, 1);
            }
            // The PRE+SSD of a frame's first subframe (4.6.1).
            match self.mode() {
                mode::SERVER if !self.heard_sync && !self.is_running() => {
                    self.heard_sync = true;
                    self.mac_found(now, estimate);
                }
                mode::MONITOR => {
                    // 4.2.1: every received frame draws a SynchroIndication.
                    self.heard_sync = true;
                    self.submit(
                        now,
                        Command::MacSynchroIndication(plm_core::st7570::MacSync::Found(estimate)),
                    );
                }
                _ => {}
            }
            self.store_estimations(heard);
            let code = [heard.p_sdu[2], heard.p_sdu[3]];
            let Some(ns) = mac::ns_count(code) else {
                self.mib.count(store::INVALID_FRAMES, 1);
                self.refresh_status();
                self.pump(now);
                return true;
            };
            self.assembly = Some(Assembly {
                subframes: vec![heard.p_sdu],
                ns,
                next_slot: slot + 1,
                first: *heard,
            });
        }
        if self
            .assembly
            .as_ref()
            .is_some_and(|a| a.subframes.len() == a.ns)
        {
            let a = self.assembly.take().expect("checked");
            self.mac_frame(now, slot, a);
        }
        self.refresh_status();
        self.pump(now);
        true
    }

    /// A whole long frame: checks, counters, synchronization, indication,
    /// repetition.
    fn mac_frame(&mut self, now: Instant, slot: u64, a: Assembly) {
        let checks_off = if self.mode() == mode::MONITOR {
            self.mib.byte(DISABLE_CHECKS, 0)
        } else {
            0
        };
        let Ok((fi, long)) = mac::join(&a.subframes) else {
            self.mib.count(store::INVALID_FRAMES, 1);
            return;
        };
        // 6.5.7, 6.5.18: FI other than LONG_MAC_FRAME counts as invalid
        // and as a bad FI, even when the check is disabled.
        if fi != LONG_MAC_FRAME {
            self.mib.count(BAD_FI, 1);
            self.mib.count(store::INVALID_FRAMES, 1);
            if checks_off & 1 == 0 {
                return;
            }
        }
        let Ok(lf) = LongFrame::new_checked(&long) else {
            self.mib.count(store::INVALID_FRAMES, 1);
            return;
        };
        let fcs_ok = lf.fcs_ok();
        if !fcs_ok {
            self.mib.count(store::INVALID_FRAMES, 1);
            if checks_off & 2 == 0 {
                return;
            }
        }
        let frame = MacData {
            credit: lf.credit(),
            address: lf.address(),
            pad: lf.pad_len() as u8,
            m_sdu: lf.m_sdu().to_vec(),
        };
        if fcs_ok && fi == LONG_MAC_FRAME {
            self.mib.count(VALID_FRAMES, 1);
            // 6.5.8: the smallest DC received.
            if frame.credit.dc < self.mib.byte(store::MIN_DELTA_CREDIT, 0) {
                self.mib.set(store::MIN_DELTA_CREDIT, &[frame.credit.dc]);
            }
        }
        let estimate = SyncEstimate {
            sn: a.first.sn,
            pga: a.first.pga,
            phase: a.first.phase,
        };
        match self.mode() {
            mode::SERVER if self.is_running() => {
                self.is_frame(now, &frame, estimate);
                return;
            }
            mode::SERVER if !self.mac_valid_frame(now, &frame) => return,
            mode::MONITOR if self.mib.byte(AUTO_REJECT, 0) == 1 => self.heard_sync = false,
            _ => {}
        }
        let ns = a.ns as u64;
        let repetition = self
            .burst
            .as_ref()
            .is_some_and(|b| slot < b.until && same_frame(&b.frame, &frame));
        let repeater = self.mib.tic_repeater().is_repeater();
        if !repetition {
            self.burst = Some(Burst {
                frame: frame.clone(),
                until: slot + 1 + frame.credit.cc as u64 * ns,
            });
        }
        let indicate = if repetition {
            // 4.2.1: a Monitor set as a repeater indicates each copy.
            self.mode() == mode::MONITOR && repeater
        } else {
            self.accepts(frame.address.da)
        };
        let cc = frame.credit.cc;
        if indicate {
            self.submit(now, Command::MacDataIndication(frame.clone()));
        }
        if !repetition && repeater && self.mode() == mode::SERVER && cc > 0 {
            self.relay(now, fi, frame);
        }
    }

    /// 4.5.3 and Table 6: whether a valid frame to `da` is indicated. A
    /// Client and a Monitor take every frame.
    fn accepts(&self, da: u16) -> bool {
        if self.mode() != mode::SERVER {
            return true;
        }
        let local = self.mib.local_address();
        let in_groups = (0..5).any(|k| self.mib.word(GROUPS, 2 * k) == da);
        da == local
            || in_groups
            || match Group::of(da) {
                Some(Group::Broadcast) => true,
                Some(Group::New) => local == NEW,
                Some(Group::NotNew) => local != NEW,
                // NO-BODY only through a group address of 000h (above).
                _ => false,
            }
    }

    /// 4.8.2: a repeater joins the burst from the next slot with CC-1..0,
    /// copies identical to the originator's (same SA, DA, IC, DC, FI), so
    /// that they add up on the line. A repeater with a transmission of its
    /// own under way does not join (model).
    fn relay(&mut self, now: Instant, fi: u16, frame: MacData) {
        if self.busy() {
            return;
        }
        let mut slots = Vec::new();
        for cc in (0..frame.credit.cc).rev() {
            let copy = MacFrame {
                credit: Credit { cc, ..frame.credit },
                address: frame.address,
                m_sdu: frame.m_sdu.clone(),
            };
            let Ok(subframes) = copy.to_subframes(fi) else {
                return;
            };
            slots.extend(subframes.into_iter().map(SlotUse::Subframe));
        }
        let clock = self.slots();
        let start = clock.next_slot(now);
        let end = start + clock.slot * slots.len() as u64;
        let plc = self.mib.plc();
        self.line_out.push_back(Transmission {
            start,
            slot: clock.slot,
            bit_rate_2400: plc.bit_rate_2400,
            f0: plc.f0,
            f1: plc.f1,
            gain: plc.target_output_gain,
            slots,
        });
        self.jobs.push(TxJob {
            start,
            confirm_at: end,
            confirm: None,
            end,
            count: Some((REPEATED_FRAMES, frame.credit.cc as u32)),
        });
    }
}

/// Copies of one frame: all but CC alike.
fn same_frame(a: &MacData, b: &MacData) -> bool {
    a.address == b.address
        && a.credit.ic == b.credit.ic
        && a.credit.dc == b.credit.dc
        && a.m_sdu == b.m_sdu
}
