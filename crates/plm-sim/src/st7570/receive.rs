//! What the simulated ST7570 does with what the line delivers: a PHY
//! subframe with its estimations (3.6, 5.3.1, 5.3.11, 5.3.18, 5.3.20) and
//! alarms (7.2.2, 5.3.14).

use super::slots::Heard;
use super::{mode, store, St7570};
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
}
