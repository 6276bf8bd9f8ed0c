//! `cargo xtask bench`, ST7570 network part (issue 12): simulated seconds
//! per wall second of a 50-node S-FSK network with repeaters. Node 0 is a
//! MAC Client driven through plm-core's host engine; nodes 1..49 are
//! Servers with their own hosts (`Responder`), every 5th an
//! ALWAYS_REPEAT repeater; a frame crosses about 6 nodes.
//! The Client asks each Server in turn (IC one per repeater on the way,
//! at most 7), waits up to 10 s for its echo, and the run reports the
//! exchanges answered, the frames relayed and the speed.

use plm_core::link::host::Event;
use plm_core::st7570::mib::{object, PlcConfiguration};
use plm_core::st7570::{Address, Command, Credit, Layer, MacData};
use plm_core::time::{Duration, MS};
use plm_sim::st7570::line::SfskLine;
use plm_sim::st7570::mode;
use plm_sim::st7570::net::{NetConfig, Network};
use std::time::Instant;

const S: Duration = 1_000 * MS;
const NODES: usize = 50;

fn main() {
    let line = SfskLine {
        attenuation_per_hop_db: 2.0,
        ..SfskLine::default()
    };
    let responders = (1..NODES).map(|n| (n, n % 5 == 0)).collect();
    let mut net = Network::new(NetConfig {
        line,
        responders,
        ..NetConfig::new(NODES)
    });
    let mut p = PlcConfiguration::decode(object(0x00A1).unwrap().default);
    p.operating_mode = mode::CLIENT;
    p.access_layer_mode = Layer::Mac.access_layer_mode();
    net.submit(
        0,
        &Command::WriteDbRequest {
            index: 0x00A1,
            data: p.encode(),
        },
    );
    net.run_for(2 * S);
    let wall = Instant::now();
    let start = net.now();
    let (mut asked, mut answered) = (0, 0);
    for round in 0..3 {
        for server in 1..NODES as u16 {
            asked += 1;
            // One more repetition per repeater on the way (5 nodes apart).
            let ic = (server.div_ceil(5) as u8).min(7);
            net.submit(
                0,
                &Command::MacDataRequest(MacData {
                    credit: Credit { ic, cc: ic, dc: 0 },
                    address: Address { sa: 0, da: server },
                    pad: 0,
                    m_sdu: format!("round {round} to {server}").into_bytes(),
                }),
            );
            let got = net.run_until(10 * S, |n, e| {
                n == 0
                    && matches!(e, Event::Frame(f) if f.code == 0x50
                        && f.data.get(1..4).is_some_and(|a| Address::from_bytes([a[0], a[1], a[2]]).sa == server))
            });
            answered += got as u32;
        }
    }
    let simulated = (net.now() - start) as f64 / S as f64;
    let secs = wall.elapsed().as_secs_f64();
    let relayed: u32 = (1..NODES).map(|n| net.modem(n).mib().counter(0x0010)).sum();
    println!(
        "ST7570 network of {NODES} nodes ({} repeaters): {answered}/{asked} echoes, \
         {relayed} frames relayed, {} collisions",
        (NODES - 1) / 5,
        net.collisions
    );
    println!(
        "  {simulated:.0} simulated s in {secs:.2} wall s: {:.0} simulated s per wall s",
        simulated / secs
    );
}
