//! A MAC Server's time-slot synchronization (ST7570 UM 4.6-4.7, 5.3.1
//! Table 18): FOUND on a PRE+SSD, CONFIRMED by a valid frame within the
//! synchronization-confirmation-timeout (0002h; in locked mode from or to
//! the initiator, 4.6.3), kept by a valid frame every timeout-frame-not-OK
//! (0003h) and one addressed to it every timeout-not-addressed (0004h),
//! LOST with CAUSE 1-5. And the intelligent synchronization (5.3.25,
//! 0009h, 0016h) as far as the manual describes it.

use super::{mode, St7570, NEW};
use plm_core::st7570::mib::index;
use plm_core::st7570::{Command, IsLocked, Layer, MacData, MacSync, SyncEstimate};
use plm_core::time::{earliest, Duration, Instant, MS};

/// LOST causes of Table 18.
pub mod cause {
    /// Timeout-not-addressed expired (the local address is NEW again).
    pub const NOT_ADDRESSED: u8 = 1;
    /// Timeout-frame-not-OK expired.
    pub const FRAME_NOT_OK: u8 = 2;
    /// Synchronization-confirmation-timeout expired.
    pub const CONFIRMATION: u8 = 3;
    /// Addressed by a wrong initiator (locked mode).
    pub const WRONG_INITIATOR: u8 = 4;
    /// The host rejected the synchronization.
    pub const HOST: u8 = 5;
}

/// SYNC = 5 causes of Table 18.
mod intelligent {
    pub const INIT: u8 = 0x06;
    pub const SYNC_FAST: u8 = 0x07;
    pub const NOT_INIT: u8 = 0x08;
}

/// 0016h, the intelligent synchronization threshold.
const IS_THRESHOLD: u16 = 0x0016;

/// A MAC Server's synchronization. `None` deadlines: the timeout is 0,
/// which the model takes as "disabled" (the manual gives no meaning).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) enum MacState {
    /// Searching (or not a MAC Server).
    #[default]
    Off,
    /// PRE+SSD found; a valid frame must confirm it by `by`.
    Found { by: Option<Instant> },
    /// Confirmed; a valid frame is due by `frame_ok_by`, one addressed to
    /// this node by `addressed_by`.
    Confirmed {
        frame_ok_by: Option<Instant>,
        addressed_by: Option<Instant>,
    },
}

impl St7570 {
    fn mac_server(&self) -> bool {
        self.layer() == Layer::Mac && self.mode() == mode::SERVER
    }

    /// A MAC timeout of `index` in units of `unit` µs, scaled; 0 disables.
    fn mac_timeout(&self, now: Instant, index: u16, unit: Duration) -> Option<Instant> {
        let v = self.mib.word(index, 0) as u64;
        (v > 0).then(|| now + v * unit / self.timeout_scale)
    }

    /// The initiator address of 0001h (0: unlocked mode, 4.6.3).
    fn initiator(&self) -> u16 {
        self.mib.word(index::LOCAL_INIT_MAC_ADD, 2)
    }

    /// A MAC Server found a PRE+SSD while searching: SYNC = FOUND.
    pub(super) fn mac_found(&mut self, now: Instant, estimate: SyncEstimate) {
        self.mac_state = MacState::Found {
            by: self.mac_timeout(now, 0x0002, 1_000 * MS),
        };
        self.submit(now, Command::MacSynchroIndication(MacSync::Found(estimate)));
    }

    /// A valid frame reached a MAC Server: confirms, refreshes or loses
    /// the synchronization. Returns whether the node stays synchronized.
    pub(super) fn mac_valid_frame(&mut self, now: Instant, frame: &MacData) -> bool {
        let init = self.initiator();
        let local = self.mib.local_address();
        let (sa, da) = (frame.address.sa, frame.address.da);
        let locked = init != 0;
        match self.mac_state {
            MacState::Off => false,
            MacState::Found { .. } => {
                if locked && sa != init && da != init {
                    self.mac_lost(now, cause::WRONG_INITIATOR, sa, da);
                    return false;
                }
                self.mac_state = MacState::Confirmed {
                    frame_ok_by: self.mac_timeout(now, 0x0003, 1_000 * MS),
                    addressed_by: self.mac_timeout(now, 0x0004, 60_000 * MS),
                };
                self.submit(
                    now,
                    Command::MacSynchroIndication(MacSync::Confirmed { pad: 0, sa, da }),
                );
                true
            }
            MacState::Confirmed { addressed_by, .. } => {
                // Model: in locked mode a frame addressed to this node by
                // another node than the initiator is CAUSE 4.
                if locked && da == local && sa != init {
                    self.mac_lost(now, cause::WRONG_INITIATOR, sa, da);
                    return false;
                }
                self.mac_state = MacState::Confirmed {
                    frame_ok_by: self.mac_timeout(now, 0x0003, 1_000 * MS),
                    addressed_by: if da == local {
                        self.mac_timeout(now, 0x0004, 60_000 * MS)
                    } else {
                        addressed_by
                    },
                };
                true
            }
        }
    }

    /// SYNC = LOST with `cause` (Table 18): the Server searches again; at
    /// CAUSE 1 its local address is NEW again (4.7.3).
    pub(super) fn mac_lost(&mut self, now: Instant, cause: u8, add1: u16, add2: u16) {
        self.submit(
            now,
            Command::MacSynchroIndication(MacSync::Lost { cause, add1, add2 }),
        );
        self.heard_sync = false;
        self.forget_mac();
        if cause == cause::NOT_ADDRESSED {
            let mut v = NEW.to_le_bytes().to_vec();
            v.extend_from_slice(&self.initiator().to_le_bytes());
            self.mib.set(index::LOCAL_INIT_MAC_ADD, &v);
        }
        self.refresh_status();
    }

    /// Forgets a frame being received, the last burst and the state.
    pub(super) fn forget_mac(&mut self) {
        self.mac_state = MacState::Off;
        self.assembly = None;
        self.burst = None;
    }

    /// The next MAC timeout.
    pub(super) fn mac_due(&self) -> Option<Instant> {
        match self.mac_state {
            MacState::Off => None,
            MacState::Found { by } => by,
            MacState::Confirmed {
                frame_ok_by,
                addressed_by,
            } => earliest(frame_ok_by, addressed_by),
        }
    }

    /// Runs a MAC timeout that passed (4.7): CAUSE 3, 2 or 1.
    pub(super) fn mac_tick(&mut self, now: Instant) {
        if !self.mac_server() {
            return;
        }
        let due = |t: Option<Instant>| t.is_some_and(|t| t <= now);
        let cause = match self.mac_state {
            MacState::Found { by } if due(by) => cause::CONFIRMATION,
            MacState::Confirmed { addressed_by, .. } if due(addressed_by) => cause::NOT_ADDRESSED,
            MacState::Confirmed { frame_ok_by, .. } if due(frame_ok_by) => cause::FRAME_NOT_OK,
            _ => return,
        };
        let (local, init) = (self.mib.local_address(), self.initiator());
        self.mac_lost(now, cause, local, init);
    }

    /// A valid frame during the intelligent synchronization's search
    /// (5.3.1 SYNC = 5, model of what the manual only names): from an
    /// initiator (SA in FIMA..LIMA) at least as loud as 0016h, the search
    /// ends with a fast synchronization (07h) and the frame confirms it;
    /// otherwise the synchronization is rejected at once (06h from an
    /// initiator, 08h from anyone else) and the loudest initiator kept.
    pub(super) fn is_frame(&mut self, now: Instant, frame: &MacData, estimate: SyncEstimate) {
        let s = estimate.sn.s0.max(estimate.sn.s1).min(0xFFFF) as u16;
        let sa = frame.address.sa;
        let (fima, lima) = (self.mib.word(0x0000, 0), self.mib.word(0x0000, 2));
        let initiator = (fima..=lima).contains(&sa);
        let threshold = u32::from_le_bytes([
            self.mib.byte(IS_THRESHOLD, 0),
            self.mib.byte(IS_THRESHOLD, 1),
            self.mib.byte(IS_THRESHOLD, 2),
            self.mib.byte(IS_THRESHOLD, 3),
        ]);
        let intelligent =
            |cause| Command::MacSynchroIndication(MacSync::Intelligent { cause, add: sa, s });
        if initiator && s as u32 >= threshold {
            self.is_until = None;
            self.submit(now, intelligent(intelligent::SYNC_FAST));
            self.heard_sync = true;
            self.mac_state = MacState::Found { by: None };
            self.mac_valid_frame(now, frame);
            return;
        }
        let cause = if initiator {
            intelligent::INIT
        } else {
            intelligent::NOT_INIT
        };
        self.submit(now, intelligent(cause));
        if initiator && self.is_best.is_none_or(|b| s > b.s) {
            self.is_best = Some(IsLocked { add: sa, s });
        }
    }

    /// The intelligent synchronization timeout passed (5.3.25): LM_LOCKED
    /// with the loudest initiator, which becomes 0001h's initiator address
    /// (locked mode, our reading of "locked"), or LM_NOT_LOCKED. The
    /// Server then searches as usual.
    pub(super) fn is_end(&mut self, now: Instant) {
        self.is_until = None;
        let best = self.is_best.take();
        if let Some(b) = best {
            let mut v = self.mib.local_address().to_le_bytes().to_vec();
            v.extend_from_slice(&b.add.to_le_bytes());
            self.mib.set(index::LOCAL_INIT_MAC_ADD, &v);
        }
        self.submit(
            now,
            Command::IsIndication {
                is_status: if best.is_some() { 0x01 } else { 0x02 },
                locked: best,
            },
        );
    }
}
