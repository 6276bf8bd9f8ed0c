//! Simulated ST7570s on one S-FSK line (ST7570 UM 3, 4, 7.2, 7.3), each
//! driven through plm-core's host engine in virtual time: PHY frames with
//! their estimations, collisions, ZC_FAIL, the PHY Monitor's per-slot spy
//! indications, MAC frames of 1..7 subframes, repeaters, the Server
//! synchronization machine with LOST causes 1-5, alarms both ways.

mod st7570_host;

use plm_core::link::host::Event;
use plm_core::st7570::mib::PlcConfiguration;
use plm_core::st7570::{Address, Command, Credit, Layer, MacData, MacSync, Status};
use plm_core::time::MS;
use plm_sim::st7570::line::SfskLine;
use plm_sim::st7570::mode;
use plm_sim::st7570::net::{NetConfig, Network};
use st7570_host::{answer, configure, plc, read, write, MAC, PHY};

const CLIENT: u16 = 0x0C00;

fn status(net: &mut Network, node: usize) -> Status {
    read(net, node, 0x00A1);
    Status::from_message(&net.node(node).host.last_status().unwrap()).unwrap()
}

fn confirm(net: &mut Network, node: usize, cmd: Command) -> u8 {
    match answer(net, node, cmd) {
        Command::DataConfirm { confirm_code } | Command::AlarmConfirm { confirm_code } => {
            confirm_code
        }
        other => panic!("{other:?}"),
    }
}

fn p_sdu(fill: u8) -> Command {
    Command::PhyDataRequest {
        p_sdu: vec![fill; 38],
    }
}

fn mac(ic: u8, da: u16, m_sdu: &[u8]) -> Command {
    Command::MacDataRequest(MacData {
        credit: Credit { ic, cc: ic, dc: 0 },
        address: Address { sa: 0, da },
        pad: 0,
        m_sdu: m_sdu.to_vec(),
    })
}

/// Frames node `i` got since `from` (an index into its events).
fn since(net: &Network, i: usize, from: usize, layer: Layer) -> Vec<Command> {
    net.nodes[i].driver.events[from..]
        .iter()
        .filter_map(|(_, e)| match e {
            Event::Frame(f) => Command::from_frame(f, layer).ok(),
            _ => None,
        })
        .collect()
}

fn mark(net: &Network, i: usize) -> usize {
    net.nodes[i].driver.events.len()
}

fn phy_net(nodes: usize, line: SfskLine) -> Network {
    let mut net = Network::new(NetConfig {
        line,
        ..NetConfig::new(nodes)
    });
    net.run_for(10 * MS);
    net
}

#[test]
fn a_phy_frame_reaches_near_servers_with_estimations_and_not_the_far_one() {
    let line = SfskLine {
        attenuation_per_hop_db: 15.0,
        phase_coupling_db: 0.0,
        ..SfskLine::default()
    };
    let mut net = phy_net(4, line);
    configure(&mut net, 0, mode::CLIENT, PHY);
    for s in 1..4 {
        configure(&mut net, s, mode::SERVER, PHY);
    }
    let at = [mark(&net, 1), mark(&net, 2), mark(&net, 3)];
    assert_eq!(confirm(&mut net, 0, p_sdu(0x5A)), 0xFF);
    net.run_for(100 * MS);
    let got = since(&net, 1, at[0], Layer::Phy);
    let Some(Command::PhySynchroIndication(est)) = got.first() else {
        panic!("{got:?}")
    };
    let Some(Command::PhyDataIndication(d)) = got.get(1) else {
        panic!("{got:?}")
    };
    assert_eq!(d.p_sdu, [0x5A; 38]);
    // 120 dBµV at gain 31, 10h = 16: 105 dBµV, 20 dB to the neighbour.
    assert_eq!(est.sn.s1, 8_500);
    assert_eq!(est.sn.n1, 6_000);
    assert!(
        est.sn.s0 < est.sn.s1,
        "f0 is the higher tone, it fades more"
    );
    // Node 0 on L1 (0°), node 1 on L2 (+120°): Table 4 code 5 (-120°).
    assert_eq!(est.phase, 5);
    let dm = d.demodulation;
    assert_eq!(dm.ask0 + dm.ask1 + dm.fsk, 304);
    assert!(d.snr1 > d.snr0 && d.snr1 > 0);
    // Node 2 is 15 dB further: still heard, weaker, its own phase (L3,
    // +240°: code 3, +120°).
    let got2 = since(&net, 2, at[1], Layer::Phy);
    let Some(Command::PhySynchroIndication(est2)) = got2.first() else {
        panic!("{got2:?}")
    };
    assert_eq!(est2.sn.s1, 7_000);
    assert_eq!(est2.phase, 3);
    // Node 3: 105 - 50 = 55 dBµV under 60 of noise: nothing.
    assert!(since(&net, 3, at[2], Layer::Phy).is_empty());
    // The Server keeps the estimations in 000Dh/000Eh (6.5.14-15).
    let d = read(&mut net, 1, 0x000D);
    assert_eq!(u32::from_le_bytes(d[4..8].try_into().unwrap()), 6_000);
}

#[test]
fn different_frames_in_one_slot_collide_identical_ones_add_up() {
    let mut net = phy_net(3, SfskLine::default());
    // Nodes 0 and 2 send, node 1 between them listens.
    configure(&mut net, 0, mode::CLIENT, PHY);
    configure(&mut net, 2, mode::CLIENT, PHY);
    configure(&mut net, 1, mode::SERVER, PHY);
    let both = |net: &mut Network, a: u8, b: u8| {
        let at = mark(net, 1);
        // Two requests submitted together go out in the same next slot.
        net.submit(0, &p_sdu(a));
        net.submit(2, &p_sdu(b));
        net.run_for(1_000 * MS);
        since(net, 1, at, Layer::Phy)
    };
    let got = both(&mut net, 0x11, 0x22);
    let data: Vec<_> = got
        .iter()
        .filter_map(|c| match c {
            Command::PhyDataIndication(d) => Some(d.p_sdu),
            _ => None,
        })
        .collect();
    assert_eq!(data.len(), 1, "PRE+SSD found: {got:?}");
    assert!(data[0] != [0x11; 38] && data[0] != [0x22; 38]);
    assert_eq!(net.collisions, 1);
    let got = both(&mut net, 0x33, 0x33);
    let sync: Vec<_> = got
        .iter()
        .filter_map(|c| match c {
            Command::PhySynchroIndication(e) => Some(e.sn.s1),
            _ => None,
        })
        .collect();
    let data: Vec<_> = got
        .iter()
        .filter_map(|c| match c {
            Command::PhyDataIndication(d) => Some(d.p_sdu),
            _ => None,
        })
        .collect();
    assert_eq!(data, [[0x33; 38]]);
    // Two equal 79 dBµV signals: 82 dBµV.
    assert_eq!(sync, [8_201]);
    assert_eq!(net.collisions, 1, "identical copies are no collision");
}

#[test]
fn a_lost_zero_crossing_or_the_wrong_mains_gives_zc_fail() {
    let mut net = phy_net(2, SfskLine::default());
    configure(&mut net, 0, mode::CLIENT, PHY);
    assert!(!status(&mut net, 0).zc_fail);
    net.set_mains_lost(0, true);
    let s = status(&mut net, 0);
    assert!(s.zc_fail && s.sync, "ZC_FAIL and not synchronized");
    assert_eq!(confirm(&mut net, 0, p_sdu(1)), 0x04, "LP_NS");
    net.set_mains_lost(0, false);
    assert_eq!(confirm(&mut net, 0, p_sdu(1)), 0xFF);
    // 00A1h says 60 Hz on a 50 Hz line: the PLL cannot lock.
    let mut p = PlcConfiguration::decode(&plc(mode::CLIENT, PHY));
    p.mains_60_hz = true;
    write(&mut net, 0, 0x00A1, &p.encode());
    assert!(status(&mut net, 0).zc_fail);
}

#[test]
fn a_phy_monitor_says_what_every_slot_held() {
    let mut net = phy_net(3, SfskLine::default());
    configure(&mut net, 0, mode::CLIENT, PHY);
    configure(&mut net, 2, mode::MONITOR, PHY);
    net.run_for(700 * MS);
    let at = mark(&net, 2);
    assert_eq!(confirm(&mut net, 0, p_sdu(7)), 0xFF);
    net.run_for(1_000 * MS);
    let kinds: Vec<u8> = since(&net, 2, at, Layer::Phy)
        .iter()
        .map(|c| c.code())
        .collect();
    // Searching: C0h per slot; the frame: D0h, B0h; its window E0h; then
    // per empty slot A0h and E0h.
    let first_d0 = kinds.iter().position(|&k| k == 0xD0).expect("D0h");
    assert!(kinds[..first_d0].iter().all(|&k| k == 0xC0) && first_d0 >= 1);
    assert_eq!(
        kinds[first_d0..first_d0 + 7],
        [0xD0, 0xB0, 0xE0, 0xA0, 0xE0, 0xA0, 0xE0]
    );
    // An alarm from the Client: F0h in its slots, then the indication.
    let at = mark(&net, 2);
    assert_eq!(confirm(&mut net, 0, Command::AlarmRequest), 0xFF);
    net.run_for(300 * MS);
    let got = since(&net, 2, at, Layer::Phy);
    assert!(got
        .iter()
        .any(|c| matches!(c, Command::SpyAlarmIndication(a) if a.alarm == 0x569E89)));
    assert!(got
        .iter()
        .any(|c| matches!(c, Command::AlarmIndication { .. })));
}

// ---------------------------------------------------------------- MAC

/// Node 0 a MAC Client; the nodes of `responders` Servers answering for
/// themselves (address = node number).
fn mac_net(nodes: usize, line: SfskLine, responders: &[(usize, bool)]) -> Network {
    let mut net = Network::new(NetConfig {
        line,
        responders: responders.to_vec(),
        ..NetConfig::new(nodes)
    });
    net.run_for(10 * MS);
    configure(&mut net, 0, mode::CLIENT, MAC);
    net.run_for(200 * MS);
    net
}

fn indications(got: &[Command]) -> Vec<MacData> {
    got.iter()
        .filter_map(|c| match c {
            Command::MacDataIndication(d) => Some(d.clone()),
            _ => None,
        })
        .collect()
}

#[test]
fn client_and_servers_exchange_frames_of_1_to_7_subframes() {
    let mut net = mac_net(3, SfskLine::default(), &[(1, false), (2, false)]);
    for (ns, len) in [
        (1, 26),
        (2, 40),
        (3, 90),
        (4, 130),
        (5, 170),
        (6, 200),
        (7, 242),
    ] {
        assert_eq!(plm_core::st7570::mac::subframes_for(len), ns);
        let payload: Vec<u8> = (0..len).map(|i| (i * 7 + ns) as u8).collect();
        let at = mark(&net, 0);
        assert_eq!(confirm(&mut net, 0, mac(0, 2, &payload)), 0xFF, "NS {ns}");
        // The Server's echo: its frame and the Client's each take NS slots.
        net.run_for((2 * ns as u64 + 4) * 300 * MS);
        let got = indications(&since(&net, 0, at, Layer::Mac));
        assert_eq!(got.len(), 1, "NS {ns}: {got:?}");
        assert_eq!(got[0].address, Address { sa: 2, da: CLIENT });
        assert_eq!(got[0].m_sdu, payload);
        assert_eq!(got[0].credit.ic, 0, "answered with the request's IC");
    }
    let r1 = net.nodes[1].responder.as_ref().unwrap();
    let r2 = net.nodes[2].responder.as_ref().unwrap();
    assert_eq!(
        (r1.indicated, r2.indicated),
        (0, 7),
        "only DA = 2 indicated"
    );
    assert_eq!(r2.answered, 7);
    // 000Ah on the Server counted every frame, the echoes of the other
    // Server included; 0006h none.
    let valid = read(&mut net, 0, 0x000A);
    assert_eq!(u32::from_le_bytes(valid.try_into().unwrap()), 7);
}

#[test]
fn a_repeater_carries_a_frame_to_a_server_out_of_the_clients_reach() {
    // 40 dB per extra hop: node 2 cannot hear node 0 (105 - 60 = 45
    // dBµV under 60 of noise), node 1 hears both.
    let line = SfskLine {
        attenuation_per_hop_db: 40.0,
        ..SfskLine::default()
    };
    let mut net = mac_net(3, line, &[(1, true), (2, false)]);
    // IC 0: one copy, nobody repeats: no answer.
    let at = mark(&net, 0);
    assert_eq!(confirm(&mut net, 0, mac(0, 2, b"hello")), 0xFF);
    net.run_for(3_000 * MS);
    assert!(indications(&since(&net, 0, at, Layer::Mac)).is_empty());
    // IC 1: the repeater joins with CC 0, Server 2 hears that copy, and
    // its answer (IC 1) comes back the same way.
    let at = mark(&net, 0);
    assert_eq!(confirm(&mut net, 0, mac(1, 2, b"hello")), 0xFF);
    net.run_for(3_000 * MS);
    let got = indications(&since(&net, 0, at, Layer::Mac));
    assert_eq!(got.len(), 1, "{got:?}");
    assert_eq!(got[0].address, Address { sa: 2, da: CLIENT });
    assert_eq!(
        got[0].credit,
        Credit {
            ic: 1,
            cc: 0,
            dc: 1
        }
    );
    assert_eq!(got[0].m_sdu, b"hello");
    // 0010h of the repeater: one copy for each direction.
    assert_eq!(net.modem(1).mib().counter(0x0010), 2);
}

#[test]
fn indication_only_for_the_first_good_copy() {
    let mut net = mac_net(2, SfskLine::default(), &[]);
    configure(&mut net, 1, mode::SERVER, MAC);
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x00]);
    let at = mark(&net, 1);
    assert_eq!(confirm(&mut net, 0, mac(3, 0x0FFF, b"all")), 0xFF);
    net.run_for(2_000 * MS);
    let got = indications(&since(&net, 1, at, Layer::Mac));
    assert_eq!(got.len(), 1, "4 copies, one indication: {got:?}");
    assert_eq!(
        got[0].credit,
        Credit {
            ic: 3,
            cc: 3,
            dc: 0
        }
    );
    let valid = read(&mut net, 1, 0x000A);
    assert_eq!(u32::from_le_bytes(valid.try_into().unwrap()), 4);
    // A frame to another Server or group is not indicated; NOT-NEW is.
    let at = mark(&net, 1);
    for da in [0x0006, 0x0FFE, 0x0FFC] {
        assert_eq!(confirm(&mut net, 0, mac(0, da, b"x")), 0xFF);
        net.run_for(600 * MS);
    }
    let got = indications(&since(&net, 1, at, Layer::Mac));
    assert_eq!(
        got.iter().map(|d| d.address.da).collect::<Vec<_>>(),
        [0x0FFC]
    );
}

fn syncs(net: &Network, i: usize, from: usize) -> Vec<MacSync> {
    since(net, i, from, Layer::Mac)
        .into_iter()
        .filter_map(|c| match c {
            Command::MacSynchroIndication(s) => Some(s),
            _ => None,
        })
        .collect()
}

/// Node 1 (Server, address 5) finds and confirms the Client's frame.
fn find(net: &mut Network) {
    let at = mark(net, 1);
    assert_eq!(confirm(net, 0, mac(0, 5, b"sync")), 0xFF);
    net.run_for(600 * MS);
    let s = syncs(net, 1, at);
    assert!(
        matches!(
            s[..],
            [
                MacSync::Found(_),
                MacSync::Confirmed {
                    sa: CLIENT,
                    da: 5,
                    ..
                }
            ]
        ),
        "{s:?}"
    );
}

/// A frame from the Client to node 1 (address 5), synchronized already.
fn send(net: &mut Network) {
    assert_eq!(confirm(net, 0, mac(0, 5, b"to 5")), 0xFF);
    net.run_for(600 * MS);
}

fn lost(net: &Network, at: usize) -> (u8, u16, u16) {
    let s = syncs(net, 1, at);
    match s.iter().rev().find(|s| matches!(s, MacSync::Lost { .. })) {
        Some(MacSync::Lost { cause, add1, add2 }) => (*cause, *add1, *add2),
        _ => panic!("{s:?}"),
    }
}

#[test]
fn a_server_loses_synchronization_for_each_cause_and_finds_it_again() {
    let mut net = mac_net(3, SfskLine::default(), &[]);
    configure(&mut net, 1, mode::SERVER, MAC);
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x00]);
    find(&mut net);
    assert!(!status(&mut net, 1).sync);

    // 5: the host rejects it.
    let at = mark(&net, 1);
    answer(&mut net, 1, Command::DesynchroRequest { reset: 1 });
    assert_eq!(lost(&net, at), (5, 5, 0));
    assert!(status(&mut net, 1).sync);
    find(&mut net);

    // 2: no valid frame within timeout-frame-not-OK (0003h = 5 s).
    write(&mut net, 1, 0x0003, &[5, 0]);
    send(&mut net);
    let at = mark(&net, 1);
    net.run_for(4_000 * MS);
    assert!(syncs(&net, 1, at).is_empty());
    net.run_for(1_500 * MS);
    assert_eq!(lost(&net, at), (2, 5, 0));
    find(&mut net);

    // 1: frames keep coming, none addressed to it, for 0004h = 1 min.
    write(&mut net, 1, 0x0003, &[30, 0]);
    write(&mut net, 1, 0x0004, &[1, 0]);
    send(&mut net);
    let at = mark(&net, 1);
    for _ in 0..5 {
        assert_eq!(confirm(&mut net, 0, mac(0, 0x0FFF, b"all")), 0xFF);
        net.run_for(10_000 * MS);
    }
    net.run_for(6_000 * MS);
    assert!(syncs(&net, 1, at).is_empty(), "kept by the broadcasts");
    net.run_for(5_000 * MS);
    assert_eq!(lost(&net, at), (1, 5, 0));
    assert_eq!(read(&mut net, 1, 0x0001), [0xFE, 0x0F, 0, 0], "NEW again");
    assert!(status(&mut net, 1).new);
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x00]);
    find(&mut net);

    // 4: locked to initiator C01h, addressed by C00h.
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x01, 0x0C]);
    answer(&mut net, 1, Command::DesynchroRequest { reset: 1 });
    let at = mark(&net, 1);
    assert_eq!(confirm(&mut net, 0, mac(0, 5, b"x")), 0xFF);
    net.run_for(600 * MS);
    assert_eq!(lost(&net, at), (4, CLIENT, 5));
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x0C]);
    find(&mut net);

    // 3: a PRE+SSD that no valid frame confirms within 0002h = 3 s (node 2,
    // a PHY Client, sends a P_SDU that is no MAC frame).
    answer(&mut net, 1, Command::DesynchroRequest { reset: 1 });
    configure(&mut net, 2, mode::CLIENT, PHY);
    let at = mark(&net, 1);
    assert_eq!(confirm(&mut net, 2, p_sdu(0xEE)), 0xFF);
    net.run_for(2_500 * MS);
    assert!(matches!(syncs(&net, 1, at)[..], [MacSync::Found(_)]));
    net.run_for(1_000 * MS);
    assert_eq!(lost(&net, at), (3, 5, 0x0C00));
    let invalid = read(&mut net, 1, 0x0006);
    assert!(u32::from_le_bytes(invalid.try_into().unwrap()) >= 1);
    find(&mut net);
}

#[test]
fn alarms_go_both_ways() {
    let mut net = mac_net(2, SfskLine::default(), &[]);
    configure(&mut net, 1, mode::SERVER, MAC);
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x00]);
    find(&mut net);
    let alarm = |net: &mut Network, from: usize, to: usize| {
        let at = mark(net, to);
        assert_eq!(confirm(net, from, Command::AlarmRequest), 0xFF);
        net.run_for(3_000 * MS);
        since(net, to, at, Layer::Mac)
            .into_iter()
            .filter(|c| matches!(c, Command::AlarmIndication { .. }))
            .count()
    };
    assert_eq!(alarm(&mut net, 0, 1), 1, "Client to Server");
    net.run_for(3_000 * MS);
    assert_eq!(alarm(&mut net, 1, 0), 1, "Server to Client");
    // N_TX = 8 alarms sent (0084h); the indication after N_RX = 2 heard
    // (0083h), the other 6 in the N_REJ window ignored (7.2.2).
    let tx = read(&mut net, 1, 0x0084);
    assert_eq!(u32::from_le_bytes(tx.try_into().unwrap()), 8);
    let rx = read(&mut net, 0, 0x0083);
    assert_eq!(u32::from_le_bytes(rx.try_into().unwrap()), 2);
}

#[test]
fn a_360_minute_timeout_seen_in_6_minutes_at_scale_60() {
    let mut net = Network::new(NetConfig {
        timeout_scale: 60,
        ..NetConfig::new(2)
    });
    net.run_for(10 * MS);
    configure(&mut net, 0, mode::CLIENT, MAC);
    configure(&mut net, 1, mode::SERVER, MAC);
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x00]);
    // 0003h 3600 s: one minute at this scale; 0004h stays 360 min.
    write(&mut net, 1, 0x0003, &[0x10, 0x0E]);
    find(&mut net);
    let at = mark(&net, 1);
    let start = net.now();
    while syncs(&net, 1, at).is_empty() {
        assert_eq!(confirm(&mut net, 0, mac(0, 0x0FFF, b"tick")), 0xFF);
        net.run_for(30_000 * MS);
        assert!(net.now() - start < 7 * 60_000 * MS);
    }
    assert_eq!(lost(&net, at), (1, 5, 0));
    assert!(net.now() - start >= 6 * 60_000 * MS - 600 * MS);
}

#[test]
fn intelligent_synchronization_locks_on_the_loudest_initiator() {
    let mut net = mac_net(2, SfskLine::default(), &[]);
    configure(&mut net, 1, mode::SERVER, MAC);
    write(&mut net, 1, 0x0001, &[0x05, 0x00, 0x00, 0x00]);
    write(&mut net, 1, 0x0009, &[1, 0]);
    let at = mark(&net, 1);
    for _ in 0..3 {
        assert_eq!(confirm(&mut net, 0, mac(0, 5, b"is")), 0xFF);
        net.run_for(10_000 * MS);
    }
    assert_eq!(confirm(&mut net, 1, mac(0, CLIENT, b"no")), 0x05, "LM_IS");
    let s = syncs(&net, 1, at);
    // SYNC = 5, LM_IS_INIT, from C00h at 79 dBµV (under 0016h's 106).
    assert_eq!(s.len(), 3, "{s:?}");
    assert!(s.iter().all(|s| *s
        == MacSync::Intelligent {
            cause: 0x06,
            add: CLIENT,
            s: 7_900
        }));
    net.run_for(35_000 * MS);
    let is: Vec<_> = since(&net, 1, at, Layer::Mac)
        .into_iter()
        .filter(|c| matches!(c, Command::IsIndication { .. }))
        .collect();
    assert_eq!(
        is,
        [Command::IsIndication {
            is_status: 0x01,
            locked: Some(plm_core::st7570::IsLocked {
                add: CLIENT,
                s: 7_900
            })
        }]
    );
    assert_eq!(
        read(&mut net, 1, 0x0001),
        [0x05, 0x00, 0x00, 0x0C],
        "locked"
    );
    find(&mut net);
    // Fast synchronization: a louder initiator than 0016h.
    write(&mut net, 1, 0x0016, &[0x58, 0x1B, 0, 0]);
    write(&mut net, 1, 0x0009, &[1, 0]);
    answer(&mut net, 1, Command::DesynchroRequest { reset: 1 });
    let at = mark(&net, 1);
    assert_eq!(confirm(&mut net, 0, mac(0, 5, b"fast")), 0xFF);
    net.run_for(600 * MS);
    let s = syncs(&net, 1, at);
    assert!(
        matches!(
            s[..],
            [
                MacSync::Intelligent { cause: 0x07, .. },
                MacSync::Confirmed { sa: CLIENT, .. }
            ]
        ),
        "{s:?}"
    );
}

#[test]
fn a_repeater_call_hears_the_client_in_sub_slot_0() {
    let mut net = mac_net(2, SfskLine::default(), &[]);
    configure(&mut net, 1, mode::SERVER, MAC);
    write(&mut net, 1, 0x0001, &[0x01, 0x00, 0x00, 0x00]);
    write(&mut net, 1, 0x000B, &[0x03]);
    let call = |net: &mut Network, threshold: u16| {
        let at = mark(net, 1);
        // A frame of 3 subframes; both calls while it is on the line.
        net.submit(0, &mac(0, 1, &[0x42; 90]));
        net.run_until(2_000 * MS, |n, e| {
            n == 1 && matches!(e, Event::Frame(f) if f.code == 0x10)
        });
        let rc = Command::RcRequest {
            tx_pos: 0,
            rc_threshold: threshold,
        };
        net.submit(0, &rc);
        net.submit(1, &rc);
        net.run_for(2_000 * MS);
        let client = since(net, 0, 0, Layer::Mac)
            .into_iter()
            .rfind(|c| matches!(c, Command::RcConfirm { .. }));
        let server = since(net, 1, at, Layer::Mac)
            .into_iter()
            .find(|c| matches!(c, Command::RcConfirm { .. }));
        (client, server)
    };
    let (client, server) = call(&mut net, 7_000);
    assert!(
        matches!(
            client,
            Some(Command::RcConfirm {
                result: 0xFF,
                heard: None,
                ..
            })
        ),
        "{client:?}"
    );
    // Heard in sub-slot 0 at 79 dBµV ((S0 + S1) / 2), 60 of noise.
    let Some(Command::RcConfirm {
        result: 0xFF,
        repeater_state: 3,
        heard: Some(h),
    }) = server
    else {
        panic!("{server:?}")
    };
    assert_eq!((h.rx_pos, h.n), (0, 6_000));
    assert!((7_800..7_900).contains(&h.s), "{h:?}");
    // Above the threshold: nothing valid heard.
    net.run_for(3_000 * MS);
    answer(&mut net, 1, Command::DesynchroRequest { reset: 1 });
    let (_, server) = call(&mut net, 9_000);
    assert!(
        matches!(
            server,
            Some(Command::RcConfirm {
                result: 0xFF,
                heard: Some(plm_core::st7570::RcHeard {
                    s: 0,
                    n: 0,
                    rx_pos: 0
                }),
                ..
            })
        ),
        "{server:?}"
    );
}

#[test]
fn a_repeater_repeats_an_alarm_burst() {
    // Node 2 hears node 0's alarms only through repeater 1.
    let line = SfskLine {
        attenuation_per_hop_db: 40.0,
        ..SfskLine::default()
    };
    let mut net = mac_net(3, line, &[]);
    for (n, a) in [(1u8, 1u8), (2, 2)] {
        configure(&mut net, n as usize, mode::SERVER, MAC);
        write(&mut net, n as usize, 0x0001, &[a, 0, 0, 0]);
    }
    write(&mut net, 1, 0x000B, &[0x01]);
    // Both synchronize: a frame to 2, relayed by 1.
    assert_eq!(confirm(&mut net, 0, mac(1, 2, b"sync")), 0xFF);
    net.run_for(1_000 * MS);
    let at = mark(&net, 2);
    assert_eq!(confirm(&mut net, 0, Command::AlarmRequest), 0xFF);
    net.run_for(6_000 * MS);
    let got = since(&net, 2, at, Layer::Mac);
    assert_eq!(
        got.iter()
            .filter(|c| matches!(c, Command::AlarmIndication { .. }))
            .count(),
        1,
        "{got:?}"
    );
    let tx = read(&mut net, 1, 0x0084);
    assert_eq!(
        u32::from_le_bytes(tx.try_into().unwrap()),
        8,
        "N_TX repeated"
    );
}
