//! `cargo xtask bench`: how long `plm sim`'s simulated ST7580 takes to
//! answer T_REQ with its status message through RFC 2217 on loopback
//! (issue 13, point 8; the ST7570's T_POLL, 20 ms, is what a host
//! allows). The server runs in this process, on its own thread, exactly
//! as `plm sim --listen 127.0.0.1:0` would; the client is `plm board`'s.

#[path = "../tests/common/latency.rs"]
mod latency;

use plm_cli::sim_server::{self, Options, World};

const SAMPLES: usize = 1000;

fn main() {
    let bound = sim_server::bind(Options {
        listen: "127.0.0.1:0".into(),
        allow_remote: false,
        world: World::Modems {
            nodes: 1,
            serve: 1,
            peers: plm_sim::Peers::EchoFollowing,
        },
        seed: 1,
        loss: 0.0,
        capture: true,
    })
    .expect("binds a loopback port");
    let addr = bound.addrs[0].to_string();
    let stopper = bound.served.stopper();
    let server = std::thread::spawn(move || bound.served.run());
    let times = latency::treq_to_status(&addr, SAMPLES);
    stopper.stop();
    server.join().expect("the server thread ends");
    let [median, p99, max] = [0.5, 0.99, 1.0].map(|q| latency::quantile(&times, q));
    println!(
        "plm sim, T_REQ -> status message through RFC 2217 on loopback ({SAMPLES} edges, \
         {} baud; the 2-byte status takes 0.35 ms of wire): median {}, p99 {}, max {}",
        latency::BAUD,
        latency::ms(median),
        latency::ms(p99),
        latency::ms(max)
    );
}
