//! Two or more simulated modems exchange PHY, DL and SS frames over the
//! simulated power line (UM0932 2.2-2.4, Figure 5).

use plm_core::link::host::Event;
use plm_core::st7580::mib::{index, MibObject, ModemConfig, PhyConfig};
use plm_core::st7580::{
    Channel, Command, DataConfirm, DataIndication, DataRequest, IndicationInfo, Modulation,
    SsDataRequest, TxParams,
};
use plm_core::time::{Duration, MS};
use plm_sim::{HostDriver, LineConfig, LineEvent, Outcome, Sim, SimConfig};

const KEY: [u8; 16] = *b"0123456789abcdef";

fn mc(access_mode: u8, crc_length: u8, on_len: bool, sniffer: bool) -> ModemConfig {
    ModemConfig {
        access_mode,
        sniffer_mode: sniffer,
        crc_length,
        dl_crc_on_phy_length: on_len,
    }
}

fn default_phy() -> PhyConfig {
    match MibObject::factory_default(index::PHY_CONFIG) {
        Some(MibObject::PhyConfig(p)) => p,
        _ => unreachable!(),
    }
}

/// `nodes` modems, every one configured with `config` and `KEY`.
fn street(nodes: usize, config: ModemConfig, line: LineConfig) -> HostDriver {
    let mut sim = Sim::new(SimConfig {
        nodes,
        line,
        ..SimConfig::default()
    });
    for n in 0..nodes {
        sim.configure(n, index::MODEM_CONFIG, &config.encode())
            .unwrap();
        sim.configure(n, index::SS_KEY, &KEY).unwrap();
    }
    let mut d = HostDriver::new(sim);
    d.run_for(100 * MS);
    d
}

fn req(modulation: Modulation, payload: &[u8]) -> DataRequest {
    DataRequest {
        params: TxParams {
            modulation,
            ..TxParams::default()
        },
        payload: payload.to_vec(),
    }
}

fn confirmed(d: &mut HostDriver, cmd: Command) -> DataConfirm {
    match d.request(&cmd, 2_000 * MS) {
        Outcome::Answer(
            Command::PhyDataConfirm(c) | Command::DlDataConfirm(c) | Command::SsDataConfirm(c),
        ) => c,
        other => panic!("{cmd:?}: {other:?}"),
    }
}

/// The first indication from now on, within `limit`.
fn indication(d: &mut HostDriver, limit: Duration) -> Option<Command> {
    let seen = d.frames().len();
    d.run_until(
        limit,
        |e| matches!(e, Event::Frame(f) if matches!(f.code, 0x26 | 0x52 | 0x5A | 0x56 | 0x5E)),
    );
    d.frames().into_iter().skip(seen).find(|c| {
        matches!(
            c,
            Command::PhyDataIndication(_)
                | Command::DlDataIndication(_)
                | Command::DlSnifferIndication(_)
                | Command::SsDataIndication(_)
                | Command::SsSnifferIndication(_)
        )
    })
}

fn payload(c: &Command) -> (&IndicationInfo, &[u8]) {
    match c {
        Command::PhyDataIndication(DataIndication { info, payload })
        | Command::DlDataIndication(DataIndication { info, payload })
        | Command::DlSnifferIndication(DataIndication { info, payload })
        | Command::SsDataIndication(DataIndication { info, payload })
        | Command::SsSnifferIndication(DataIndication { info, payload }) => (info, payload),
        other => panic!("{other:?}"),
    }
}

#[test]
fn phy_dl_and_ss_frames_travel_to_a_peer_and_back() {
    for (mode, send, name) in [
        (
            0,
            Command::PhyDataRequest(req(Modulation::QPsk, b"phy frame")),
            "PHY",
        ),
        (
            1,
            Command::DlDataRequest(req(Modulation::BPsk, b"dl frame")),
            "DL",
        ),
        (
            2,
            Command::SsDataRequest(SsDataRequest {
                params: TxParams::default(),
                header_length: 4,
                header_and_payload: b"HEADsecret payload".to_vec(),
            }),
            "SS",
        ),
    ] {
        let mut d = street(2, mc(mode, 2, false, false), LineConfig::default());
        let sent = confirmed(&mut d, send.clone());
        let got = indication(&mut d, 2_000 * MS).unwrap_or_else(|| panic!("{name}: no echo"));
        let expected: &[u8] = match &send {
            Command::PhyDataRequest(r) | Command::DlDataRequest(r) => &r.payload,
            Command::SsDataRequest(r) => &r.header_and_payload,
            _ => unreachable!(),
        };
        let (info, data) = payload(&got);
        assert_eq!(data, expected, "{name}");
        assert_eq!(
            got.code(),
            send.code() + 2,
            "{name}: the layer's indication"
        );
        assert_eq!(info.rx_channel, Channel::High);
        assert!(info.snr_db().is_some_and(|s| s > 10), "{name}: {info:?}");
        // MIB 04h and 05h keep the last indication and confirm.
        let read = |d: &mut HostDriver, index| match d
            .request(&Command::MibReadRequest { index }, 1_000 * MS)
        {
            Outcome::Answer(Command::MibReadConfirm { data }) => data,
            other => panic!("{other:?}"),
        };
        assert_eq!(read(&mut d, 4), info.encode(), "{name}");
        assert_eq!(read(&mut d, 5), sent.encode(), "{name}");
        // The counters of the layer (Tables 58-60).
        let counters = read(&mut d, [6, 7, 8][mode as usize]);
        let rx_valid = match mode {
            0 => &counters[2..4],
            _ => &counters[0..2],
        };
        assert_eq!(rx_valid, &[0, 1], "{name}: {counters:?}");
    }
}

#[test]
fn every_crc_option_with_and_without_the_phy_length() {
    for crc in 0..4 {
        for on_len in [false, true] {
            let mut d = street(2, mc(1, crc, on_len, false), LineConfig::default());
            let data = format!("crc {crc} on length {on_len}").into_bytes();
            confirmed(&mut d, Command::DlDataRequest(req(Modulation::BPsk, &data)));
            let got = indication(&mut d, 2_000 * MS).expect("echo");
            assert_eq!(
                got,
                Command::DlDataIndication(DataIndication {
                    info: *payload(&got).0,
                    payload: data,
                })
            );
            // One DL frame transmitted (Table 59).
            let sent = d.sim.modem(0).mib(index::DL_DATA).map(|c| c[4..6].to_vec());
            assert_eq!(sent, Some(vec![0, 1]));
        }
    }
}

/// UM0932 Tables 45 and 48: 226 bytes of SS header and payload, whatever
/// the CRC of MIB 00h (the SS frame's length byte does not count it).
#[test]
fn ss_frames_of_226_bytes_travel_with_every_crc() {
    for crc in 0..4 {
        let mut d = street(2, mc(2, crc, crc == 3, false), LineConfig::default());
        let data: Vec<u8> = (0..226u32).map(|i| (i * 7) as u8).collect();
        confirmed(
            &mut d,
            Command::SsDataRequest(SsDataRequest {
                params: TxParams::default(),
                header_length: 16,
                header_and_payload: data.clone(),
            }),
        );
        let got = indication(&mut d, 2_000 * MS).expect("echo");
        assert!(
            matches!(got, Command::SsDataIndication(_)),
            "CRC {crc}: {got:?}"
        );
        assert_eq!(payload(&got).1, &data[..], "CRC {crc}");
    }
}

/// A frame that cannot be read: a DL frame whose CRC is wrong for the
/// receiver, an SS frame under another key. With the sniffer flag on, the
/// sniffer indication; with it off, nothing (Figure 5).
#[test]
fn wrong_crc_and_wrong_key_reach_the_host_only_as_sniffer_indications() {
    for sniffer in [true, false] {
        // DL: the peer uses CRC-16, node 0 CRC-8.
        let mut d = street(2, mc(1, 0, false, sniffer), LineConfig::default());
        d.sim
            .configure(1, index::MODEM_CONFIG, &mc(1, 1, false, false).encode())
            .unwrap();
        d.sim
            .peer_request(1, &Command::DlDataRequest(req(Modulation::BPsk, b"abc")));
        let got = indication(&mut d, 1_000 * MS);
        if sniffer {
            let got = got.expect("DL_SnifferIndication");
            assert!(matches!(got, Command::DlSnifferIndication(_)), "{got:?}");
            let (_, data) = payload(&got);
            assert_eq!(&data[..3], b"abc");
            assert_eq!(data.len(), 5, "payload and the (wrong) 2-byte CRC");
        } else {
            assert_eq!(got, None);
        }
        // SS: the peer has another key.
        let mut d = street(2, mc(2, 2, false, sniffer), LineConfig::default());
        d.sim
            .configure(1, index::SS_KEY, b"another key 1234")
            .unwrap();
        let ss = SsDataRequest {
            params: TxParams::default(),
            header_length: 4,
            header_and_payload: b"HEADpayload".to_vec(),
        };
        d.sim.peer_request(1, &Command::SsDataRequest(ss));
        let got = indication(&mut d, 1_000 * MS);
        if sniffer {
            let got = got.expect("SS_SnifferIndication");
            assert!(matches!(got, Command::SsSnifferIndication(_)), "{got:?}");
            let (_, sdu) = payload(&got);
            assert_eq!(sdu.len(), 11 + 29, "the whole SS_SDU");
            assert_eq!(&sdu[..4], b"HEAD", "header in clear");
            assert_ne!(&sdu[4..11], b"payload", "payload encrypted");
        } else {
            assert_eq!(got, None);
        }
        let not_authentic = d.sim.modem(0).mib(index::SS_DATA).unwrap()[2..4].to_vec();
        assert_eq!(not_authentic, vec![0, 1]);
    }
}

#[test]
fn fsk_frames_reach_only_fsk_channels_with_the_same_shape() {
    let fsk = PhyConfig {
        rx_high_psk: false,
        fsk_bit_rate: 2,
        ..default_phy()
    };
    let mut d = street(3, mc(0, 2, false, false), LineConfig::default());
    d.sim
        .configure(0, index::PHY_CONFIG, &fsk.encode())
        .unwrap();
    d.sim
        .configure(1, index::PHY_CONFIG, &fsk.encode())
        .unwrap();
    // Node 2 keeps PSK on its high channel: it does not hear B-FSK.
    confirmed(
        &mut d,
        Command::PhyDataRequest(req(Modulation::BFsk, b"fsk")),
    );
    let got = indication(&mut d, 2_000 * MS).expect("echo from node 1");
    let (info, data) = payload(&got);
    assert_eq!(
        (info.modulation, info.snr, data),
        (Modulation::BFsk, 255, &b"fsk"[..])
    );
    assert_eq!(d.sim.echoed(1), 1);
    assert_eq!(d.sim.echoed(2), 0);
}

#[test]
fn zero_crossing_synchronised_transmission_keeps_its_delay() {
    let mut d = street(1, mc(0, 2, false, false), LineConfig::default());
    let phy = PhyConfig {
        zc_delay: 200,
        ..default_phy()
    };
    d.sim
        .configure(0, index::PHY_CONFIG, &phy.encode())
        .unwrap();
    let mut r = req(Modulation::BPsk, b"zc");
    r.params.zero_crossing_sync = true;
    let c1 = confirmed(&mut d, Command::PhyDataRequest(r.clone()));
    d.run_for(7 * MS);
    let c2 = confirmed(&mut d, Command::PhyDataRequest(r));
    // The frame starts 200 steps after the crossing; the UW ends the sync
    // time later (32 + 32 bits at 9600 bps = 6666 µs = 512 steps).
    assert_eq!(c1.zc_delay, 200 + 512);
    assert_eq!(c1.zc_delay, c2.zc_delay, "whenever the request comes");
}

#[test]
fn far_modems_miss_fast_modulations_and_simultaneous_echoes_collide() {
    let mut d = street(10, mc(0, 2, false, false), LineConfig::default());
    confirmed(
        &mut d,
        Command::PhyDataRequest(req(Modulation::EightPsk, b"8psk")),
    );
    d.run_for(500 * MS);
    let mut weak = vec![];
    let mut collisions = 0;
    while let Some(e) = d.sim.poll_line_event() {
        match e {
            LineEvent::Missed {
                from: 0,
                to,
                why: "signal too weak",
                ..
            } => weak.push(to),
            LineEvent::Missed {
                to: 0,
                why: "collision",
                ..
            } => collisions += 1,
            _ => {}
        }
    }
    assert!(!weak.is_empty() && !weak.contains(&1), "{weak:?}");
    assert!(collisions > 0, "the near peers echo at the same time");
}

#[test]
fn a_lossy_line_loses_frames() {
    let lossy = LineConfig {
        loss: 1.0,
        ..LineConfig::default()
    };
    let mut d = street(2, mc(1, 2, false, false), lossy);
    confirmed(
        &mut d,
        Command::DlDataRequest(req(Modulation::BPsk, b"gone")),
    );
    assert_eq!(indication(&mut d, 1_000 * MS), None);
    assert_eq!(d.sim.echoed(1), 0);
}
