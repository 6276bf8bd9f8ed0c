//! What a simulation offers the hosts outside it: the UART of each served
//! node (bytes, T_REQ, RESETN, baud rate) and its clock. `plm sim` serves
//! any of them over RFC 2217 through this one trait: the ST7580 line
//! ([`crate::Sim`]) and the ST7570 S-FSK network
//! ([`crate::st7570::net::Network`]).

use plm_core::time::{Duration, Instant};

/// A simulation whose nodes 0..[`Ports::served`] have their host outside.
pub trait Ports {
    /// Nodes whose host is outside (0 up to this).
    fn served(&self) -> usize;
    /// The host of served node `node` writes `bytes` to its UART now.
    fn write_to(&mut self, node: usize, bytes: &[u8]);
    /// The host of served node `node` sets its T_REQ (`asserted`: low),
    /// after the bytes it wrote before have left the UART.
    fn set_treq_of(&mut self, node: usize, asserted: bool);
    /// The host holds node `node`'s RESETN low (`true`) or releases it
    /// (a host that wires DTR to RESETN).
    fn set_resetn_of(&mut self, node: usize, low: bool);
    /// The UART baud rate of served node `node`.
    fn baud_of(&self, node: usize) -> u32;
    /// Sets served node `node`'s UART baud rate both ways and at the
    /// modem (its BR pins strapped to match).
    fn set_baud_of(&mut self, node: usize, baud: u32);
    /// How long until the bytes served node `node`'s host wrote so far
    /// have all reached the modem (0 when none are on the way).
    fn backlog_to_modem(&self, node: usize) -> Duration;
    /// Purges the transmit side of served node `node`'s host, as its
    /// serial driver does on a purge (RFC 2217 PURGE-DATA, or the host
    /// gone): the bytes it wrote that the modem has not yet received are
    /// lost, and a T_REQ change waiting behind them takes effect now.
    /// The modem runs on (nothing is reset).
    fn purge_to_modem(&mut self, node: usize);
    /// Purges the receive side of served node `node`'s host: the bytes
    /// that reached it and are not yet read, and those on their way to it
    /// (they are not heard; the modem's UART still takes their time).
    fn purge_to_host(&mut self, node: usize);
    /// Bytes that reached served node `node`'s host by now, with their
    /// arrival times.
    fn host_read_of(&mut self, node: usize) -> Vec<(Instant, u8)>;
    /// When the bytes now on served node `node`'s UART have arrived, the
    /// earliest of the two ways still to come (`None`: none are on the
    /// way): a frame may end there, which the modem or the host answers at
    /// once. The bytes before those ends wait for them.
    fn uart_due_of(&self, node: usize) -> Option<Instant>;
    /// The next moment anything happens, byte arrivals at the hosts
    /// included.
    fn next_deadline(&self) -> Option<Instant>;
    /// Runs everything due up to `t`.
    fn advance_to(&mut self, t: Instant);
}

impl Ports for crate::Sim {
    fn served(&self) -> usize {
        crate::Sim::served(self)
    }
    fn write_to(&mut self, node: usize, bytes: &[u8]) {
        crate::Sim::write_to(self, node, bytes)
    }
    fn set_treq_of(&mut self, node: usize, asserted: bool) {
        crate::Sim::set_treq_of(self, node, asserted)
    }
    fn set_resetn_of(&mut self, node: usize, low: bool) {
        self.inject_on(node, crate::Fault::Resetn(low))
    }
    fn baud_of(&self, node: usize) -> u32 {
        crate::Sim::baud_of(self, node)
    }
    fn set_baud_of(&mut self, node: usize, baud: u32) {
        crate::Sim::set_baud_of(self, node, baud)
    }
    fn backlog_to_modem(&self, node: usize) -> Duration {
        crate::Sim::backlog_to_modem(self, node)
    }
    fn purge_to_modem(&mut self, node: usize) {
        crate::Sim::purge_to_modem(self, node)
    }
    fn purge_to_host(&mut self, node: usize) {
        crate::Sim::purge_to_host(self, node)
    }
    fn host_read_of(&mut self, node: usize) -> Vec<(Instant, u8)> {
        crate::Sim::host_read_of(self, node)
    }
    fn uart_due_of(&self, node: usize) -> Option<Instant> {
        crate::Sim::uart_due_of(self, node)
    }
    fn next_deadline(&self) -> Option<Instant> {
        crate::Sim::next_deadline(self)
    }
    fn advance_to(&mut self, t: Instant) {
        crate::Sim::advance_to(self, t)
    }
}
