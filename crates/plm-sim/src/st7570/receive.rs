//! What the simulated ST7570 does with what the line delivers: a PHY
//! subframe with its estimations (3.6, 5.3.1, 5.3.11, 5.3.18, 5.3.20;
//! 000Dh, 000Eh) and alarms (7.2.2, 5.3.14); and what a PHY Monitor says
//! at each slot while it searches for the slots (5.3.19).

use super::slots::Heard;
use super::{mode, store, St7570};
use plm_core::st7570::mib::object;
use plm_core::st7570::{Command, Layer, SignalNoise};
use plm_core::time::Instant;

/// 0086h b0: alarm indication disabled; b2: S/N indication disabled
/// (Table 133, 0 = enabled).
const INDICATION_DISABLED: u8 = 1 << 0;
const SN_INDICATION_DISABLED: u8 = 1 << 2;
/// 0086h.
const ALARM_FLAGS: u16 = 0x0086;
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
    /// (4.5.3, the synchronization machine of 4.6) belongs to the MAC
    /// network, a later part of issue 12: a MAC modem does not take
    /// subframes yet, and says so by returning `false`. A modem sending
    /// hears nothing (`false` too).
    pub fn hear(&mut self, now: Instant, heard: &Heard) -> bool {
        if !self.is_on() || self.zc_fail || self.on_air(now) || self.layer() != Layer::Phy {
            return false;
        }
        let mode = self.mode();
        if !(mode::CLIENT..=mode::MONITOR).contains(&mode) {
            return false;
        }
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
    /// Repeating alarms (7.2.3) is the MAC network's. Returns whether the
    /// alarm was taken.
    pub fn hear_alarm(&mut self, now: Instant, sn: SignalNoise) -> bool {
        if !self.is_on() || !self.synchronized() || self.on_air(now) || now < self.alarm_quiet_until
        {
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
        }
        self.refresh_status();
        self.pump(now);
        true
    }

    /// 6.5.14-6.5.15: 000Dh and 000Eh hold the estimations of the last
    /// CMD_DataIndication, written through their layouts.
    fn store_estimations(&mut self, heard: &Heard) {
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

    /// The next SPY_SearchSynchroIndication, if one is due.
    pub(super) fn spy_due(&self) -> Option<Instant> {
        self.searching_spy()
            .then(|| self.slots().next_slot(self.spy_from))
    }

    /// Sends the SPY_SearchSynchroIndication of a slot start that passed.
    pub(super) fn spy_tick(&mut self, now: Instant) {
        if self.spy_due().is_some_and(|t| t <= now) {
            let slot = self.slots().slot;
            self.spy_from = now / slot * slot;
            self.submit(now, Command::SpySearchSynchroIndication);
        }
    }
}
