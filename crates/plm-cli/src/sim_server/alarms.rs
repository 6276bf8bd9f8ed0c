//! `plm sim --chip st7570 --alarms S`: the line's MAC Servers raise an
//! alarm in turn every S seconds of simulated time (ST7570 UM 5.3.15: a
//! Server's host sends CMD_AlarmRequest), so that a host program on the
//! served node sees CMD_AlarmIndication come in. A Server that is not
//! synchronized has its request refused, and nothing is heard.

use plm_core::time::{Duration, Instant};
use plm_sim::st7570::net::Network;
use plm_sim::Ports;

/// A network whose Servers raise alarms on a schedule.
pub struct Alarming {
    net: Network,
    /// µs between two alarms.
    every: Instant,
    /// When the next one is raised.
    next: Instant,
    /// Alarms raised so far: which Server is next.
    raised: usize,
}

impl Alarming {
    /// `net`, with an alarm every `every` µs, the first after `every`.
    pub fn new(net: Network, every: Instant) -> Alarming {
        let every = every.max(1);
        Alarming {
            net,
            every,
            next: every,
            raised: 0,
        }
    }

    /// The next Server in turn raises its alarm.
    fn raise(&mut self) {
        let servers: Vec<usize> = (0..self.net.nodes.len())
            .filter(|&i| self.net.nodes[i].responder.is_some())
            .collect();
        if let Some(&node) = servers.get(self.raised % servers.len().max(1)) {
            if let Some(r) = self.net.nodes[node].responder.as_mut() {
                r.raise_alarm();
            }
        }
        self.raised += 1;
    }
}

impl Ports for Alarming {
    fn served(&self) -> usize {
        self.net.served()
    }

    fn write_to(&mut self, node: usize, bytes: &[u8]) {
        self.net.write_to(node, bytes);
    }

    fn set_treq_of(&mut self, node: usize, asserted: bool) {
        self.net.set_treq_of(node, asserted);
    }

    fn set_resetn_of(&mut self, node: usize, low: bool) {
        self.net.set_resetn_of(node, low);
    }

    fn baud_of(&self, node: usize) -> u32 {
        self.net.baud_of(node)
    }

    fn set_baud_of(&mut self, node: usize, baud: u32) {
        self.net.set_baud_of(node, baud);
    }

    fn backlog_to_modem(&self, node: usize) -> Duration {
        self.net.backlog_to_modem(node)
    }

    fn purge_to_modem(&mut self, node: usize) {
        self.net.purge_to_modem(node);
    }

    fn purge_to_host(&mut self, node: usize) {
        self.net.purge_to_host(node);
    }

    fn host_read_of(&mut self, node: usize) -> Vec<(Instant, u8)> {
        self.net.host_read_of(node)
    }

    fn uart_due_of(&self, node: usize) -> Option<Instant> {
        self.net.uart_due_of(node)
    }

    fn next_deadline(&self) -> Option<Instant> {
        Some(
            self.net
                .next_deadline()
                .map_or(self.next, |t| t.min(self.next)),
        )
    }

    fn advance_to(&mut self, t: Instant) {
        while self.next <= t {
            self.net.advance_to(self.next);
            self.raise();
            self.next += self.every;
        }
        self.net.advance_to(t);
    }
}
