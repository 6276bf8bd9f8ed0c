use plm_core::app::{AppEvent, Discovery, Happening, RequesterConfig};
use plm_sim::{Attach, Sim, SimConfig, StreetDriver};
fn main() {
    let args: Vec<usize> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let verbose = std::env::var("V").is_ok();
    for &lamps in &args {
        for seed in [5u64, 6, 7] {
            let sim = Sim::new(SimConfig { seed, ..SimConfig::street(lamps, Attach::Board) });
            let mut dr = StreetDriver::new(sim, RequesterConfig::default());
            dr.run_for(2_000_000);
            let t0 = dr.now();
            let (mut d, first) = Discovery::start(dr.now(), 1, Discovery::window_for(12), 40);
            dr.submit(first);
            let mut log = Vec::new();
            let mut last = 0;
            while !d.is_done() {
                let until = d.poll_timeout().unwrap_or(dr.now());
                for h in dr.step(until) {
                    if let Happening::App(AppEvent::Unsolicited { address, message, .. }) = h {
                        if let Some(ack) = d.on_message(address, &message) {
                            dr.send(ack);
                        }
                    }
                }
                let round = d.round();
                if let Some(next) = d.handle_timeout(dr.now()) {
                    dr.submit(next);
                }
                if d.round() != round || d.is_done() {
                    log.push(format!("r{round}:+{}", d.found().len() - last));
                    last = d.found().len();
                }
            }
            println!("{lamps} lamps seed {seed}: found {} in {:.1} s", d.found().len(), (dr.now() - t0) as f64 / 1e6);
            if verbose { println!("   {}", log.join(" ")); }
        }
    }
}
