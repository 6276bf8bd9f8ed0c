//! The ST7570 capture of the decoder bench: what a host interface carries
//! in both directions (`Source::Any`), built with plm-core's own emitters.
//! A MAC Server serves its network for 64 KiB, then the host writes MIB
//! 00A1h to make it a PHY Monitor, which spies for 16 KiB, and back.

use super::Rng;
use plm_core::link::Dialect;
use plm_core::st7570::mib::{self, index, PlcConfiguration};
use plm_core::st7570::{
    Address, Command, Credit, Demodulation, Layer, MacData, MacSync, SignalNoise, SpySubframe,
    Status, SyncEstimate,
};

fn estimate(rng: &mut Rng) -> SignalNoise {
    let mut level = || 4000 + rng.below(8000) as u32;
    SignalNoise {
        s0: level(),
        n0: level(),
        s1: level(),
        n1: level(),
    }
}

fn mac_data(rng: &mut Rng) -> MacData {
    MacData {
        credit: Credit {
            ic: rng.below(8) as u8,
            cc: rng.below(8) as u8,
            dc: rng.below(4) as u8,
        },
        address: Address {
            sa: 0xC00,
            da: 1 + rng.below(0x3FF) as u16,
        },
        pad: 0,
        m_sdu: {
            let n = 1 + rng.below(242) as usize;
            rng.bytes(n)
        },
    }
}

/// A frame of a MAC Server's traffic: mostly data, some of the rest.
fn server(rng: &mut Rng) -> Command {
    match rng.below(16) {
        0..=5 => Command::MacDataIndication(mac_data(rng)),
        6..=8 => Command::MacDataRequest(mac_data(rng)),
        9..=10 => Command::DataConfirm { confirm_code: 0xFF },
        11 => Command::MacSynchroIndication(MacSync::Confirmed {
            pad: 0,
            sa: 0xC00,
            da: 1 + rng.below(0x3FF) as u16,
        }),
        12 => Command::AlarmIndication {
            cnt: rng.below(1000) as u32,
            long: Some((estimate(rng), 0)),
        },
        13 => Command::ReadDbRequest {
            index: mib::OBJECTS[rng.below(mib::OBJECTS.len() as u64) as usize].index,
        },
        14 => {
            let o = &mib::OBJECTS[rng.below(mib::OBJECTS.len() as u64) as usize];
            Command::ReadDbConfirm {
                index: o.index,
                data: o.default.to_vec(),
            }
        }
        _ => Command::RcConfirm {
            result: 0xFF,
            repeater_state: 3,
            heard: None,
        },
    }
}

/// A frame of a PHY Monitor: spy indications and P_Data indications.
fn monitor(rng: &mut Rng) -> Command {
    let p_sdu: [u8; 38] = rng.bytes(38).try_into().unwrap();
    let demodulation = Demodulation {
        ask0: rng.below(304) as u16,
        ask1: rng.below(304) as u16,
        fsk: rng.below(304) as u16,
    };
    match rng.below(4) {
        0 => Command::PhySynchroIndication(SyncEstimate {
            sn: estimate(rng),
            pga: rng.below(9) as u8,
            phase: rng.below(7) as u8,
        }),
        1 => Command::PhyDataIndication(plm_core::st7570::PhyDataIndication {
            p_sdu,
            demodulation,
            snr0: rng.below(1 << 20) as u32,
            snr1: rng.below(1 << 20) as u32,
        }),
        _ => Command::SpySubframeIndication(SpySubframe {
            sn: estimate(rng),
            demodulation,
            pga: rng.below(9) as u8,
            p_sdu,
            snr0: rng.below(1 << 20) as u32,
            snr1: rng.below(1 << 20) as u32,
        }),
    }
}

/// The status message of a Server MAC or a Monitor (Table 11).
fn status(rng: &mut Rng, layer: Layer) -> Vec<u8> {
    let s = Status {
        mode: if layer == Layer::Mac { 2 } else { 3 },
        mac: layer == Layer::Mac,
        ts_counter: rng.below(8) as u8,
        fw_release: 1,
        delta_phase: rng.below(7) as u8,
        min_credit: rng.below(8) as u8,
        ..Status::default()
    };
    let mut m = vec![0x3F];
    m.extend(s.emit());
    m
}

/// The host's write of 00A1h making the modem a Server MAC or a Monitor
/// PHY, and the modem's confirm.
fn reconfigure(layer: Layer) -> [Command; 2] {
    let mut p = PlcConfiguration::decode(mib::object(index::PLC_CONFIGURATION).unwrap().default);
    p.access_layer_mode = layer.access_layer_mode();
    p.operating_mode = if layer == Layer::Mac { 2 } else { 3 };
    let data = p.encode();
    [
        Command::WriteDbRequest {
            index: index::PLC_CONFIGURATION,
            data: data.clone(),
        },
        Command::WriteDbConfirm {
            index: index::PLC_CONFIGURATION,
            data,
        },
    ]
}

/// About `size` bytes of traffic and the number of frames in it.
pub fn capture(size: usize, rng: &mut Rng) -> (Vec<u8>, usize) {
    let mut out = Vec::with_capacity(size + 300);
    let mut frames = 0;
    let mut put = |out: &mut Vec<u8>, cmd: &Command| {
        out.extend(cmd.to_frame().emit(Dialect::St7570).unwrap());
        out.push(0x06);
        frames += 1;
    };
    let mut layer = Layer::Mac;
    let mut block_end = 64 << 10;
    while out.len() < size {
        if out.len() >= block_end {
            layer = match layer {
                Layer::Mac => Layer::Phy,
                Layer::Phy => Layer::Mac,
            };
            block_end = out.len()
                + if layer == Layer::Mac {
                    64 << 10
                } else {
                    16 << 10
                };
            out.extend(status(rng, layer));
            for cmd in reconfigure(layer) {
                put(&mut out, &cmd);
            }
        }
        match rng.below(10) {
            0..=1 => out.extend(status(rng, layer)),
            2 => out.push((rng.below(256) as u8) | 0x80),
            _ => {
                let cmd = match layer {
                    Layer::Mac => server(rng),
                    Layer::Phy => monitor(rng),
                };
                put(&mut out, &cmd);
            }
        }
    }
    (out, frames)
}
