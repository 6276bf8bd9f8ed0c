//! What the simulated ST7570 does with what the line delivers: a PHY
//! subframe with its estimations (3.6, 5.3.1, 5.3.11, 5.3.18, 5.3.20;
//! 000Dh, 000Eh) and alarms (7.2.2, 5.3.14); and what a PHY Monitor says
//! at each slot while it searches for the slots (5.3.19).

use super::slots::Heard;
use super::{mode, store, St7570};
use plm_core::st7570::mib::object;
use plm_core::st7570::{Command, Layer, RcHeard, SignalNoise, SpyAlarm};
use plm_core::time::Instant;

/// 0086h b0: alarm indication disabled; b2: S/N indication disabled
/// (Table 133, 0 = enabled).
const INDICATION_DISABLED: u8 = 1 << 0;
const SN_INDICATION_DISABLED: u8 = 1 << 2;
/// 0086h.
const ALARM_FLAGS: u16 = 0x0086;
/// 0086h b1: alarm repetition disabled.
const REPETITION_DISABLED: u8 = 1 << 1;
/// The alarm pattern (7.2, Table 59).
const ALARM_PATTERN: u32 = 0x569E89;
/// 0083h Received alarm counter.
const RECEIVED_ALARMS: u16 = 0x0083;
/// 000Dh S0, N0, PGA and 000Eh S1, N1, phase.
const S0_N0_PGA: u16 = 0x000D;
const S1_N1_PHASE: u16 = 0x000E;

impl St7570 {
    /// A subframe the line delivered at `now` (3.6: with its estimations).
    /// In PHY mode a Client, Server or Monitor takes it (a Server or
    /// Monitor synchronizes on it): the Client and Server indicate the
    /// PRE+SSD (Table 17) and the P_SDU (Table 37), the Monitor the spy
    /// indications of a valid subframe (5.3.18, 5.3.20). MAC reception
    /// (4.5.3, 4.6) is `mac_rx`'s. A modem sending hears nothing
    /// (`false`).
    pub fn hear(&mut self, now: Instant, heard: &Heard) -> bool {
        if !self.is_on() || self.zc_fail || self.on_air(now) {
            return false;
        }
        let mode = self.mode();
        if !(mode::CLIENT..=mode::MONITOR).contains(&mode) {
            return false;
        }
        if self.layer() == Layer::Mac {
            return self.hear_mac(now, heard);
        }
        self.spy_subframe_slot = Some(self.slots().slot_number(now));
        let found = !self.synchronized();
        self.heard_sync = true;
        let estimate = plm_core::st7570::SyncEstimate {
            sn: heard.sn,
            pga: heard.pga,
            phase: heard.phase,
        };
        if mode == mode::MONITOR {
            if found {
                self.submit(
                    now,
                    Command::SpySynchroFoundIndication {
                        sn: heard.sn,
                        demodulation: heard.demodulation,
                        pga: heard.pga,
                    },
                );
            }
            self.submit(
                now,
                Command::SpySubframeIndication(plm_core::st7570::SpySubframe {
                    sn: heard.sn,
                    demodulation: heard.demodulation,
                    pga: heard.pga,
                    p_sdu: heard.p_sdu,
                    snr0: heard.snr.0,
                    snr1: heard.snr.1,
                }),
            );
        } else {
            self.store_estimations(heard);
            self.submit(now, Command::PhySynchroIndication(estimate));
            self.submit(
                now,
                Command::PhyDataIndication(plm_core::st7570::PhyDataIndication {
                    p_sdu: heard.p_sdu,
                    demodulation: heard.demodulation,
                    snr0: heard.snr.0,
                    snr1: heard.snr.1,
                }),
            );
        }
        self.refresh_status();
        self.pump(now);
        true
    }

    /// An alarm heard in the window of the slot `now` falls in, with the
    /// estimations made on it (7.2.2). A synchronized modem not sending and
    /// outside its reject window counts it (0083h), sets the status ALARM
    /// bit for one status message (Table 11), and after N_RX alarms in
    /// consecutive slots (0085h byte 1) sends CMD_AlarmIndication (short,
    /// or long when 0086h b2 is 0) unless 0086h b0 disables it (a PHY
    /// Monitor always sends it, 6.5.28); N_REJ slots of deafness follow.
    /// A repeater repeats the burst (7.2.3, `repeat_alarms`). Returns
    /// whether the alarm was taken.
    pub fn hear_alarm(&mut self, now: Instant, sn: SignalNoise) -> bool {
        if !self.is_on() || !self.synchronized() || self.on_air(now) {
            return false;
        }
        // F0h reports every alarm window heard (5.3.22).
        self.spy_alarm = Some((self.slots().slot_number(now), sn));
        if now < self.alarm_quiet_until {
            return false;
        }
        self.mib.count(RECEIVED_ALARMS, 1);
        self.alarm_flag = true;
        let clock = self.slots();
        let slot = clock.slot_number(now);
        let run = match self.alarm_run {
            Some((last, run)) if last + 1 == slot => run.saturating_add(1),
            Some((last, run)) if last == slot => run,
            _ => 1,
        };
        self.alarm_run = Some((slot, run));
        let n_rx = self.mib.byte(store::ALARM_PARAMETERS, 1).max(1);
        if run >= n_rx {
            self.alarm_run = None;
            let n_rej = self.mib.byte(store::ALARM_PARAMETERS, 2) as u64;
            self.alarm_quiet_until = (slot + 1 + n_rej) * clock.slot;
            let flags = self.mib.byte(ALARM_FLAGS, 0);
            let monitor = self.mode() == mode::MONITOR && self.layer() == Layer::Phy;
            if flags & INDICATION_DISABLED == 0 || monitor {
                let long = (flags & SN_INDICATION_DISABLED == 0).then_some((sn, 0));
                let cnt = self.mib.counter(RECEIVED_ALARMS);
                self.submit(now, Command::AlarmIndication { cnt, long });
            }
            self.repeat_alarms(slot);
        }
        self.refresh_status();
        self.pump(now);
        true
    }

    /// 6.5.14-6.5.15: 000Dh and 000Eh hold the estimations of the last
    /// CMD_DataIndication, written through their layouts.
    pub(super) fn store_estimations(&mut self, heard: &Heard) {
        let sn = heard.sn;
        for (index, values) in [
            (
                S0_N0_PGA,
                [("s0", sn.s0), ("n0", sn.n0), ("pga", heard.pga as u32)],
            ),
            (
                S1_N1_PHASE,
                [("s1", sn.s1), ("n1", sn.n1), ("phase", heard.phase as u32)],
            ),
        ] {
            let Some(o) = object(index) else { continue };
            let mut v = o.default.to_vec();
            for (name, value) in values {
                if let Some(f) = o.field(name) {
                    f.set(&mut v, value as i64);
                }
            }
            self.mib.set(index, &v);
        }
    }

    /// Whether this is a PHY Monitor searching for the slots: it says so
    /// at the start of each slot (5.3.19), the mains being there.
    fn searching_spy(&self) -> bool {
        self.is_on()
            && !self.zc_fail
            && self.layer() == Layer::Phy
            && self.mode() == mode::MONITOR
            && !self.synchronized()
    }

    /// Whether this is a synchronized PHY Monitor: at each slot's end it
    /// says what the slot held (5.3.17, 5.3.21, 5.3.22).
    fn synchronized_spy(&self) -> bool {
        self.is_on()
            && !self.zc_fail
            && self.layer() == Layer::Phy
            && self.mode() == mode::MONITOR
            && self.synchronized()
    }

    /// The next per-slot spy indication, if one is due.
    pub(super) fn spy_due(&self) -> Option<Instant> {
        (self.searching_spy() || self.synchronized_spy())
            .then(|| self.slots().next_slot(self.spy_from))
    }

    /// Sends the spy indications of a slot boundary that passed: C0h while
    /// searching; once synchronized, for the slot that ended, A0h if no
    /// subframe came in it (B0h went when one did) and F0h or E0h for its
    /// window, with the line's noise where nothing was heard.
    pub(super) fn spy_tick(&mut self, now: Instant) {
        if self.spy_due().is_none_or(|t| t > now) {
            return;
        }
        let slot = self.slots().slot;
        self.spy_from = now / slot * slot;
        if self.searching_spy() {
            self.submit(now, Command::SpySearchSynchroIndication);
            return;
        }
        let ended = (now / slot).saturating_sub(1);
        if self.spy_subframe_slot != Some(ended) {
            self.submit(
                now,
                Command::SpyNoSubframeIndication {
                    sn: self.line_noise,
                    pad: vec![0; 58],
                },
            );
        }
        let alarm = self.spy_alarm.filter(|(s, _)| *s == ended);
        let spy = |sn, alarm| SpyAlarm {
            sn,
            pad: [0; 7],
            alarm,
        };
        self.submit(
            now,
            match alarm {
                Some((_, sn)) => Command::SpyAlarmIndication(spy(sn, ALARM_PATTERN)),
                // Table 57 prints the pattern here too; what the window
                // held, silence, is sent (docs/protocol-notes.md).
                None => Command::SpyNoAlarmIndication(spy(self.line_noise, 0)),
            },
        );
    }

    /// 7.2.3: a Server set as a repeater (000Bh ALWAYS_REPEAT or REPEAT)
    /// with alarm repetition enabled (0086h b1 = 0) repeats a burst it
    /// took with N_TX alarms from the next slot, then rejects alarms for
    /// N_REJ slots.
    fn repeat_alarms(&mut self, slot: u64) {
        let flags = self.mib.byte(ALARM_FLAGS, 0);
        if self.mode() != mode::SERVER
            || !self.mib.tic_repeater().is_repeater()
            || flags & REPETITION_DISABLED != 0
            || self.busy()
        {
            return;
        }
        let n_tx = self.mib.byte(store::ALARM_PARAMETERS, 0).max(1) as u64;
        let n_rej = self.mib.byte(store::ALARM_PARAMETERS, 2) as u64;
        let clock = self.slots();
        let start = (slot + 1) * clock.slot;
        self.queue_line(start, vec![super::SlotUse::Alarm; n_tx as usize]);
        let end = start + clock.slot * n_tx;
        self.alarm_quiet_until = end + clock.slot * n_rej;
        self.jobs.push(super::TxJob {
            start,
            confirm_at: end,
            confirm: None,
            end,
            count: Some((store::TRANSMITTED_ALARMS, n_tx as u32)),
        });
    }

    /// Repeater call patterns heard in the slot `now` falls in (7.3), per
    /// sub-slot: a Server whose call takes this slot keeps the loudest
    /// valid one (S_RC > N_RC and above the threshold) for its confirm.
    pub fn hear_rc(&mut self, now: Instant, heard: &[(u16, SignalNoise)]) {
        let threshold = self.rc_threshold;
        let best = heard
            .iter()
            .map(|(pos, sn)| {
                let s = (sn.s0 + sn.s1) / 2;
                let n = (sn.n0 + sn.n1) / 2;
                (*pos, s, n)
            })
            .filter(|&(_, s, n)| s > n && s > threshold)
            .max_by_key(|&(_, s, _)| s);
        for job in self.jobs.iter_mut() {
            if job.start <= now && now < job.end {
                if let Some(Command::RcConfirm { heard: Some(h), .. }) = job.confirm.as_mut() {
                    if let Some((rx_pos, s, n)) = best {
                        *h = RcHeard { s, n, rx_pos };
                    }
                }
            }
        }
    }
}
