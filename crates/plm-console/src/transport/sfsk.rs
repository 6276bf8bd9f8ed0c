//! The simulated ST7570 transport: plm-sim's S-FSK network running in the
//! page, the console's modem as node 0 and Servers along the line that
//! answer what is sent to them, every third a repeater
//! ([`NetConfig::served_line`], the network `plm sim --chip st7570`
//! serves). Its clock is the network's virtual time.

use super::{LinkState, Transport};
use plm_core::time::Instant;
use plm_sim::st7570::net::{NetConfig, Network};
use plm_sim::Ports;

/// Node 0 of a simulated S-FSK network, as its host sees it.
#[derive(Debug, Clone)]
pub struct SfskTransport {
    net: Network,
    nodes: usize,
}

impl SfskTransport {
    /// `nodes` ST7570 modems (node 0 the console's), every UART at
    /// `baud`, one seed for the whole run.
    pub fn new(nodes: usize, baud: u32, seed: u64) -> Self {
        let nodes = nodes.max(1);
        let mut net = Network::new(NetConfig::served_line(nodes, 1, seed));
        net.set_baud_of(0, baud);
        SfskTransport { net, nodes }
    }
}

impl Transport for SfskTransport {
    fn kind(&self) -> &'static str {
        "Simulated"
    }

    fn port(&self) -> String {
        match self.nodes {
            1 => "ST7570 (simulated, alone)".to_string(),
            n => format!("ST7570 (simulated, {} Servers on the line)", n - 1),
        }
    }

    fn state(&self) -> LinkState {
        LinkState::Connected
    }

    fn now(&self) -> Instant {
        self.net.now()
    }

    fn baud(&self) -> u32 {
        self.net.baud_of(0)
    }

    fn set_baud(&mut self, baud: u32) {
        self.net.set_baud_of(0, baud);
    }

    fn write(&mut self, bytes: &[u8]) {
        self.net.write_to(0, bytes);
    }

    fn set_treq(&mut self, asserted: bool) {
        self.net.set_treq_of(0, asserted);
    }

    /// The simulated adapter has DTR wired to RESETN (as `plm sim`).
    fn set_dtr(&mut self, asserted: bool) {
        self.net.set_resetn_of(0, asserted);
    }

    fn next_event(&self) -> Option<Instant> {
        self.net.next_deadline()
    }

    fn poll(&mut self, until: Instant) -> Vec<(Instant, u8)> {
        self.net.advance_to(until);
        self.net.host_read_of(0)
    }
}
