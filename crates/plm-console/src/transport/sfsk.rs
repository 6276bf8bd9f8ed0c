//! The simulated ST7570 transport: plm-sim's S-FSK network running in the
//! page, the console's modem as node 0 and Servers along the line that
//! answer what is sent to them, every third a repeater
//! ([`NetConfig::served_line`], the network `plm sim --chip st7570`
//! serves, whose Servers take on the bit rate, f0 and f1 the console
//! writes to its modem). Its clock is the network's virtual time.

use super::{LinkState, Transport};
use plm_core::st7570::MacSync;
use plm_core::time::Instant;
use plm_sim::st7570::net::{NetConfig, Network};
use plm_sim::Ports;

/// Noise added at a node cut off by the Network view, dBµV: far above
/// what its neighbours' frames arrive with on the default line (about
/// 100 dBµV), so that it hears nothing.
pub const CUT_OFF_NOISE_DBUV: f64 = 110.0;

/// A simulated Server as the Network view shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct SimServer {
    /// Its node number along the line (1..).
    pub node: usize,
    /// Its local MAC address.
    pub address: u16,
    /// Whether it relays (000Bh).
    pub repeater: bool,
    /// Its modem is synchronized (status message SYNC bit).
    pub synchronized: bool,
    /// Cut off by noise at its end of the line.
    pub cut_off: bool,
    /// Frames addressed to it, and its answers confirmed.
    pub indicated: u64,
    /// Its answers confirmed LM_OK.
    pub answered: u64,
    /// Its last synchronization changes, newest last.
    pub syncs: Vec<(Instant, MacSync)>,
}

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

    /// The simulated Servers (every node but the console's).
    pub fn servers(&self) -> Vec<SimServer> {
        self.net.nodes[1..]
            .iter()
            .enumerate()
            .filter_map(|(i, n)| {
                let r = n.responder.as_ref()?;
                Some(SimServer {
                    node: i + 1,
                    address: r.address,
                    repeater: matches!(n.driver.port.modem.mib().byte(0x000B, 0) & 0x03, 1 | 3),
                    synchronized: n.driver.port.modem.synchronized(),
                    cut_off: n.extra_noise_dbuv.is_some(),
                    indicated: r.indicated,
                    answered: r.answered,
                    syncs: r.syncs.clone(),
                })
            })
            .collect()
    }

    /// Cuts node `node` off (noise at its end of the line) or restores it.
    pub fn cut_off(&mut self, node: usize, cut: bool) {
        if let Some(n) = self.net.nodes.get_mut(node) {
            n.extra_noise_dbuv = cut.then_some(CUT_OFF_NOISE_DBUV);
        }
    }

    /// Node `node`'s host has its modem send an alarm.
    pub fn raise_alarm(&mut self, node: usize) {
        if let Some(r) = self
            .net
            .nodes
            .get_mut(node)
            .and_then(|n| n.responder.as_mut())
        {
            r.raise_alarm();
        }
    }

    /// Every modem's MAC timeouts run `scale` times faster from now on.
    pub fn set_timeout_scale(&mut self, scale: u64) {
        self.net.set_timeout_scale(scale);
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

    fn uart_due(&self) -> Option<Instant> {
        self.net.uart_due_of(0)
    }

    fn next_event(&self) -> Option<Instant> {
        self.net.next_deadline()
    }

    fn poll(&mut self, until: Instant) -> Vec<(Instant, u8)> {
        self.net.advance_to(until);
        self.net.host_read_of(0)
    }

    fn sfsk(&mut self) -> Option<&mut SfskTransport> {
        Some(self)
    }
}
