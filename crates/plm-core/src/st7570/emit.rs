//! Emitting ST7570 commands: the data field of every [`Command`], the
//! mirror of its parse (ST7570 UM Tables 16-67).

use super::fields::{self as f, spy_alarm};
use super::types::{set, Demodulation, SignalNoise, SyncEstimate};
use super::{Command, MacSync};
use crate::link::LocalFrame;
use alloc::vec::Vec;

fn put24(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes()[..3]);
}

impl Command {
    /// The data field.
    pub fn data(&self) -> Vec<u8> {
        use Command::*;
        let mut out = Vec::new();
        match self {
            PhySynchroIndication(e) => put_estimate(&mut out, e),
            MacSynchroIndication(m) => match m {
                MacSync::Found(e) => {
                    out.push(1);
                    put_estimate(&mut out, e);
                }
                MacSync::Confirmed { pad, sa, da } => {
                    out.extend_from_slice(&[2, *pad]);
                    out.extend_from_slice(&sa.to_le_bytes());
                    out.extend_from_slice(&da.to_le_bytes());
                }
                MacSync::Lost { cause, add1, add2 } => {
                    out.extend_from_slice(&[4, *cause]);
                    out.extend_from_slice(&add1.to_le_bytes());
                    out.extend_from_slice(&add2.to_le_bytes());
                }
                MacSync::Intelligent { cause, add, s } => {
                    out.extend_from_slice(&[5, *cause]);
                    out.extend_from_slice(&add.to_le_bytes());
                    out.extend_from_slice(&s.to_le_bytes());
                }
                MacSync::Other { sync, data } => {
                    out.push(*sync);
                    out.extend_from_slice(data);
                }
            },
            DesynchroRequest { reset: b }
            | SynchroStatus { status: b }
            | ResetRequest { reset: b }
            | WriteDbError { error: b }
            | ReadDbError { error: b }
            | DataConfirm { confirm_code: b }
            | AlarmConfirm { confirm_code: b }
            | SyntaxError { error: b } => out.push(*b),
            SynchroStatusRequest | AlarmRequest | SpySearchSynchroIndication => {}
            WriteDbRequest { index, data }
            | WriteDbConfirm { index, data }
            | ReadDbConfirm { index, data } => {
                out.extend_from_slice(&index.to_le_bytes());
                out.extend_from_slice(data);
            }
            ReadDbRequest { index } => out.extend_from_slice(&index.to_le_bytes()),
            PhyDataIndication(i) => {
                out.extend_from_slice(&i.p_sdu);
                put_demodulation(&mut out, &i.demodulation);
                put24(&mut out, i.snr0);
                put24(&mut out, i.snr1);
            }
            MacDataIndication(d) | MacDataRequest(d) => d.write(&mut out),
            PhyDataRequest { p_sdu } => out.extend_from_slice(p_sdu),
            AlarmIndication { cnt, long } => {
                out.extend_from_slice(&cnt.to_le_bytes());
                if let Some((sn, pad)) = long {
                    put_sn(&mut out, sn);
                    out.push(*pad);
                }
            }
            SpyNoSubframeIndication { sn, pad } => {
                put_sn(&mut out, sn);
                out.extend_from_slice(pad);
            }
            SpySubframeIndication(s) => {
                put_sn(&mut out, &s.sn);
                put_demodulation(&mut out, &s.demodulation);
                out.push(s.pga);
                out.extend_from_slice(&s.p_sdu);
                put24(&mut out, s.snr0);
                put24(&mut out, s.snr1);
            }
            SpySynchroFoundIndication {
                sn,
                demodulation,
                pga,
            } => {
                put_sn(&mut out, sn);
                put_demodulation(&mut out, demodulation);
                out.push(*pga);
            }
            SpyNoAlarmIndication(a) | SpyAlarmIndication(a) => {
                put_sn(&mut out, &a.sn);
                out.extend_from_slice(&a.pad);
                let mut alarm = [0u8; spy_alarm::LEN];
                set(&spy_alarm::LAYOUT[5], &mut alarm, a.alarm);
                out.extend_from_slice(&alarm[19..]);
            }
            RcRequest {
                tx_pos,
                rc_threshold,
            } => {
                out.extend_from_slice(&tx_pos.to_le_bytes());
                out.extend_from_slice(&rc_threshold.to_le_bytes());
            }
            RcConfirm {
                result,
                repeater_state,
                heard,
            } => {
                out.extend_from_slice(&[*result, *repeater_state]);
                if let Some(h) = heard {
                    put24(&mut out, h.s);
                    put24(&mut out, h.n);
                    out.extend_from_slice(&h.rx_pos.to_le_bytes());
                }
            }
            IsIndication { is_status, locked } => {
                out.push(*is_status);
                if let Some(l) = locked {
                    out.extend_from_slice(&l.add.to_le_bytes());
                    out.extend_from_slice(&l.s.to_le_bytes());
                }
            }
            Unknown { data, .. } => out.extend_from_slice(data),
        }
        out
    }

    /// The command as a local frame (STX 02h).
    pub fn to_frame(&self) -> LocalFrame {
        LocalFrame::new(self.code(), self.data())
    }
}

fn put_sn(out: &mut Vec<u8>, sn: &SignalNoise) {
    let at = out.len();
    out.resize(at + f::signal_noise::LEN, 0);
    sn.write(out, at);
}

fn put_estimate(out: &mut Vec<u8>, e: &SyncEstimate) {
    put_sn(out, &e.sn);
    out.extend_from_slice(&[e.pga, e.phase]);
}

fn put_demodulation(out: &mut Vec<u8>, d: &Demodulation) {
    let at = out.len();
    out.resize(at + 6, 0);
    d.write(out, at);
}
