//! Several served nodes of one line ([`SimConfig::served`]) and echoing
//! peers that follow node 0's MIB ([`Peers::EchoFollowing`]).

use plm_core::st7580::mib::index;
use plm_core::st7580::Command;
use plm_core::time::MS;
use plm_sim::{HostDriver, Outcome, Peers, Sim, SimConfig};

fn write_phy_config(d: &mut HostDriver, data: Vec<u8>) {
    let cmd = Command::MibWriteRequest {
        index: index::PHY_CONFIG,
        data,
    };
    assert_eq!(
        d.request(&cmd, 1_000 * MS),
        Outcome::Answer(Command::MibWriteConfirm)
    );
}

fn phy_117khz(sim: &Sim) -> Vec<u8> {
    let mut phy = sim.modem(0).phy_config();
    phy.high_frequency = 117_000;
    phy.encode()
}

#[test]
fn echoing_peers_follow_node_0s_mib_00h_01h_or_keep_the_factory_one() {
    for (peers, follows) in [(Peers::EchoFollowing, true), (Peers::Echo, false)] {
        let sim = Sim::new(SimConfig {
            nodes: 3,
            peers,
            ..SimConfig::default()
        });
        let factory = sim.modem(1).mib(index::PHY_CONFIG).unwrap().to_vec();
        let phy = phy_117khz(&sim);
        let mut d = HostDriver::new(sim);
        d.run_for(100 * MS);
        write_phy_config(&mut d, phy.clone());
        for n in 1..3 {
            let got = d.sim.modem(n).mib(index::PHY_CONFIG).unwrap().to_vec();
            assert_eq!(
                got,
                if follows {
                    phy.clone()
                } else {
                    factory.clone()
                },
                "{peers:?} node {n}"
            );
        }
    }
}

#[test]
fn a_second_served_node_has_its_own_uart_and_t_req() {
    let mut sim = Sim::new(SimConfig {
        nodes: 3,
        served: 2,
        peers: Peers::EchoFollowing,
        ..SimConfig::default()
    });
    assert_eq!(sim.served(), 2);
    sim.advance_to(100 * MS);
    // Both served modems said BIO_ResetIndication to their own hosts.
    let reset0 = sim.host_read_of(0);
    let reset1 = sim.host_read_of(1);
    assert!(
        reset0.len() > 4 && reset1.len() > 4,
        "{reset0:?} {reset1:?}"
    );
    // Node 1's T_REQ is answered with a status on node 1's UART only.
    sim.write_to(1, &[0x06]);
    sim.write_to(0, &[0x06]);
    sim.advance_to(150 * MS);
    sim.set_treq_of(1, true);
    sim.advance_to(160 * MS);
    let got1: Vec<u8> = sim.host_read_of(1).into_iter().map(|(_, b)| b).collect();
    assert_eq!(got1.first(), Some(&0x3F), "{got1:02X?}");
    assert!(sim.host_read_of(0).is_empty());
    // Node 1 is not an echo: it has its own host (ours).
    assert_eq!(sim.echoed(1), 0);
}
