//! The simulated transport: plm-sim's modem (and its power line, with any
//! echoing peers) running in the page. Its clock is the simulation's
//! virtual time, which the session moves on in step with the page's clock.

use super::{LampAction, LinkState, Simulator, Transport};
use plm_core::app::Address;
use plm_core::time::Instant;
use plm_sim::board::street_address;
use plm_sim::{
    Attach, ByteFaults, Dir, Fault, LineConfig, LineEvent, Sim, SimConfig, StreetProfile,
};

/// A simulated modem on node 0 of a simulated power line.
#[derive(Debug, Clone)]
pub struct SimTransport {
    sim: Sim,
}

impl SimTransport {
    /// `nodes` modems (1 = this modem alone, more = echoing peers), every
    /// UART at `baud`, one seed for the whole run.
    pub fn new(nodes: usize, baud: u32, seed: u64) -> Self {
        SimTransport {
            sim: Sim::new(SimConfig {
                seed,
                nodes: nodes.max(1),
                baud,
                ..SimConfig::default()
            }),
        }
    }

    /// A street of `lamps` street-light boards behind a concentrator
    /// board's USART, or behind a bare modem (`via`), its lamps alike or
    /// differing as a real street's (`profile`).
    pub fn street(lamps: usize, via: Attach, baud: u32, seed: u64, profile: StreetProfile) -> Self {
        SimTransport {
            sim: Sim::new(SimConfig {
                seed,
                baud,
                profile,
                ..SimConfig::street(lamps, via)
            }),
        }
    }
}

impl Transport for SimTransport {
    fn kind(&self) -> &'static str {
        "Simulated"
    }

    fn port(&self) -> String {
        if self.sim.board(1).is_some() {
            let lamps = self.sim.nodes() - 1;
            return match self.sim.attach() {
                Attach::Board => format!("concentrator board (simulated, {lamps} lamps)"),
                Attach::Modem => format!("ST7580 concentrator (simulated, {lamps} lamps)"),
            };
        }
        match self.sim.nodes() {
            1 => "ST7580 (simulated, alone)".to_string(),
            2 => "ST7580 (simulated, 1 echoing peer)".to_string(),
            n => format!("ST7580 (simulated, {} echoing peers)", n - 1),
        }
    }

    fn state(&self) -> LinkState {
        if self.sim.plugged() {
            LinkState::Connected
        } else {
            LinkState::Disconnected(
                "the simulated cable is unplugged: plug it back in (Simulator view)".to_string(),
            )
        }
    }

    fn now(&self) -> Instant {
        self.sim.now()
    }

    fn baud(&self) -> u32 {
        self.sim.baud()
    }

    fn set_baud(&mut self, baud: u32) {
        self.sim.set_baud(baud);
    }

    fn write(&mut self, bytes: &[u8]) {
        self.sim.write(bytes);
    }

    fn set_treq(&mut self, asserted: bool) {
        self.sim.set_treq(asserted);
    }

    /// The simulated adapter has DTR wired to RESETN (as `plm sim`).
    fn set_dtr(&mut self, asserted: bool) {
        self.sim.inject(Fault::Resetn(asserted));
    }

    fn uart_due(&self) -> Option<Instant> {
        self.sim.uart_due_of(0)
    }

    fn next_event(&self) -> Option<Instant> {
        self.sim.next_deadline()
    }

    fn poll(&mut self, until: Instant) -> Vec<(Instant, u8)> {
        self.sim.advance_to(until);
        self.sim.host_read()
    }

    fn simulator(&mut self) -> Option<&mut dyn Simulator> {
        Some(self)
    }
}

impl Simulator for SimTransport {
    fn nodes(&self) -> usize {
        self.sim.nodes()
    }

    fn echoed(&self) -> u64 {
        (1..self.sim.nodes()).map(|n| self.sim.echoed(n)).sum()
    }

    fn line(&self) -> LineConfig {
        self.sim.line().clone()
    }

    fn set_line(&mut self, line: LineConfig) {
        self.sim.set_line(line);
    }

    fn set_byte_faults(&mut self, dir: Dir, faults: ByteFaults) {
        self.sim.set_byte_faults(dir, faults);
    }

    fn inject(&mut self, fault: Fault) {
        self.sim.inject(fault);
    }

    fn plugged(&self) -> bool {
        self.sim.plugged()
    }

    fn line_events(&mut self) -> Vec<LineEvent> {
        std::iter::from_fn(|| self.sim.poll_line_event()).collect()
    }

    fn set_failure_rate(&mut self, per_lit_hour: f64) {
        for node in 1..self.sim.nodes() {
            self.sim.with_board(node, |b, now| {
                if let Some(ballast) = b.ballast_mut() {
                    ballast.set_failure_rate(now, per_lit_hour);
                }
            });
        }
    }

    fn lamp(&mut self, address: Address, action: LampAction) {
        let Some(node) = (1..self.sim.nodes()).find(|&n| street_address(n) == address) else {
            return;
        };
        let cut = match action {
            LampAction::Cut => Some(true),
            LampAction::Join => Some(false),
            _ => None,
        };
        if let Some(cut) = cut {
            self.sim.set_cut(node, cut);
            return;
        }
        self.sim.with_board(node, |b, now| {
            if let Some(ballast) = b.ballast_mut() {
                match action {
                    LampAction::Fail => ballast.fail(now),
                    _ => ballast.repair(now),
                }
            }
        });
    }
}
