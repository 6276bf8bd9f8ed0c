//! The loop of `plm sim`: one thread owns the simulation (any
//! [`Ports`]: the ST7580 line, the ST7570 network) and wakes only when
//! something happens, either a message from the sockets' threads (a
//! connection accepted, bytes read, a connection closed, Ctrl-C) or the
//! simulation's next deadline ([`Ports::next_deadline`]: a byte
//! reaching a host, a modem timer, a line event), so that a modem's
//! bytes reach its client when the simulated chip sends them (issue 13,
//! point 8), and nothing runs while nothing happens.
//!
//! Each listener has a thread blocked in `accept`, each client a thread
//! blocked in `read` and one in `write` ([`super::client`]); they pass
//! what they get through one channel, whose
//! timed wait (unlike a socket's read timeout, rounded to the kernel's
//! scheduler tick) ends within some tens of microseconds of the deadline.

use super::client::{self, Client, Purge, Wake};
use plm_sim::Ports;
use std::collections::VecDeque;
use std::io::Write;
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

/// Baud rates the BR0/BR1 pins select: UM0932 3.1 for the ST7580, the
/// same four in the ST7570 UM's Table 9.
pub const RATES: &[u32] = &plm_core::link::BAUD_RATES;

/// Stops a running [`Served`] loop from another thread.
#[derive(Clone)]
pub struct Stopper(Sender<Wake>);

impl Stopper {
    pub fn stop(&self) {
        let _ = self.0.send(Wake::Stop);
    }
}

/// How long a new client of a node with a client waits for that client
/// to be seen gone before it is refused as busy.
const REOPEN_GRACE: Duration = Duration::from_millis(200);

/// The simulation and its ports, served until stopped.
pub struct Served {
    sim: Box<dyn Ports + Send>,
    /// Each node's answer to RFC 2217 SIGNATURE.
    signatures: Vec<String>,
    wakes: Receiver<Wake>,
    /// Wakes put aside while a new client waited for the one before it.
    later: VecDeque<Wake>,
    sender: Sender<Wake>,
    clients: Vec<Option<Client>>,
    /// Wall-clock time of simulated time 0: when the first client came.
    origin: Option<Instant>,
    /// Connections so far (each client's id).
    conns: u64,
}

impl Served {
    /// Starts a thread accepting on each of `listeners` (node i on the
    /// i-th, whose RFC 2217 SIGNATURE is `signatures[i]`); nothing is
    /// served until [`Served::run`].
    pub fn new(
        sim: Box<dyn Ports + Send>,
        listeners: Vec<TcpListener>,
        signatures: Vec<String>,
    ) -> Served {
        let (sender, wakes) = channel();
        let clients = (0..listeners.len()).map(|_| None).collect();
        for (node, listener) in listeners.into_iter().enumerate() {
            let tx = sender.clone();
            std::thread::spawn(move || accept(node, listener, tx));
        }
        Served {
            sim,
            signatures,
            wakes,
            later: VecDeque::new(),
            sender,
            clients,
            origin: None,
            conns: 0,
        }
    }

    /// What stops [`Served::run`].
    pub fn stopper(&self) -> Stopper {
        Stopper(self.sender.clone())
    }

    /// Serves until stopped; then closes every client.
    pub fn run(mut self) {
        loop {
            let wake = match self.deadline() {
                _ if !self.later.is_empty() => self.later.pop_front(),
                Some(at) => {
                    match self
                        .wakes
                        .recv_timeout(at.saturating_duration_since(Instant::now()))
                    {
                        Ok(w) => Some(w),
                        Err(RecvTimeoutError::Timeout) => None,
                        Err(RecvTimeoutError::Disconnected) => break,
                    }
                }
                None => match self.wakes.recv() {
                    Ok(w) => Some(w),
                    Err(_) => break,
                },
            };
            match wake {
                Some(Wake::Stop) => break,
                Some(w) => self.handle(w),
                None => {}
            }
            self.advance();
            self.forward();
        }
        for c in self.clients.into_iter().flatten() {
            c.close();
            let _ = c.stream.shutdown(Shutdown::Both);
            println!("plm sim: client {} disconnected (stopping)", c.peer);
        }
    }

    /// When the simulation next needs running, on the wall clock.
    fn deadline(&self) -> Option<Instant> {
        let origin = self.origin?;
        let at = self.sim.next_deadline()?;
        Some(origin + Duration::from_micros(at))
    }

    /// Runs the simulation up to now.
    fn advance(&mut self) {
        if let Some(origin) = self.origin {
            self.sim.advance_to(origin.elapsed().as_micros() as u64);
        }
    }

    fn handle(&mut self, wake: Wake) {
        match wake {
            Wake::Accepted { node, stream, peer } => self.accepted(node, stream, peer),
            Wake::Data { conn, chunk } => {
                let Some(node) = self.node_of(conn) else {
                    return; // a client already gone: its bytes with it
                };
                // The bytes arrived now: bring the modems up to now first.
                self.advance();
                let Some(c) = self.clients[node].as_mut() else {
                    return;
                };
                let done = c.receive(self.sim.as_mut(), node, &chunk.bytes);
                say_refusals(c);
                if let Err(why) = done {
                    self.drop_client(node, &why);
                }
            }
            Wake::Closed { conn, why } => {
                if let Some(node) = self.node_of(conn) {
                    self.drop_client(node, &why);
                }
            }
            Wake::Stop => {}
        }
    }

    fn node_of(&self, conn: u64) -> Option<usize> {
        self.clients
            .iter()
            .position(|c| c.as_ref().is_some_and(|c| c.conn == conn))
    }

    fn accepted(&mut self, node: usize, stream: TcpStream, peer: SocketAddr) {
        // A host that closes its port and opens it again at once: its
        // close and its new connection reach the loop from two threads,
        // in either order. The new one waits a moment for the old one to
        // be seen gone (serving every client meanwhile) before it is
        // refused as busy.
        let until = Instant::now() + REOPEN_GRACE;
        while self.clients[node].is_some() {
            let wait = self.deadline().map_or(until, |at| at.min(until));
            match self
                .wakes
                .recv_timeout(wait.saturating_duration_since(Instant::now()))
            {
                Ok(w @ (Wake::Data { .. } | Wake::Closed { .. })) => self.handle(w),
                Ok(w) => self.later.push_back(w),
                Err(RecvTimeoutError::Timeout) if Instant::now() < until => {}
                Err(_) => return refuse(stream, peer),
            }
            self.advance();
            self.forward();
        }
        // The modems power on with the first client (simulated time 0).
        self.origin.get_or_insert_with(Instant::now);
        self.advance();
        self.conns += 1;
        let conn = self.conns;
        let signature = &self.signatures[node];
        let baud = self.sim.baud_of(node);
        match Client::open(stream, peer, conn, baud, signature, &self.sender) {
            Ok(c) => {
                if self.clients.len() > 1 {
                    println!("plm sim: client {peer} connected to node {node}");
                } else {
                    println!("plm sim: client {peer} connected");
                }
                self.clients[node] = Some(c);
            }
            Err(e) => println!("plm sim: client {peer} lost at once: {e}"),
        }
    }

    /// Passes what reached each served host to its client (lost when
    /// nobody is connected: nobody is on the host side of that UART).
    fn forward(&mut self) {
        for node in 0..self.clients.len() {
            let out: Vec<u8> = self
                .sim
                .host_read_of(node)
                .into_iter()
                .map(|(_, b)| b)
                .collect();
            let Some(c) = self.clients[node].as_mut() else {
                continue;
            };
            let sent = c.send(&out);
            say_refusals(c);
            if let Err(why) = sent {
                self.drop_client(node, &why);
            }
        }
    }

    /// The client of `node` goes: its port is purged both ways (what it
    /// sent and the modem has not read is lost, as on a real port), T_REQ
    /// and DTR are released (pulled up); the modem runs on.
    fn drop_client(&mut self, node: usize, why: &str) {
        let Some(mut c) = self.clients[node].take() else {
            return;
        };
        c.close();
        let _ = c.stream.shutdown(Shutdown::Both);
        println!("plm sim: client {} disconnected ({why})", c.peer);
        say_refusals(&mut c);
        if let Some(all) = c.refusal_summary() {
            eprintln!("plm sim: client {} refused, in all: {all}", c.peer);
        }
        self.advance();
        // T_REQ released before the purge, which applies the last level
        // at once: the departed client's last RTS ON never reaches the
        // modem as a pulse (whose status message nobody would read).
        self.sim.set_treq_of(node, false);
        client::purge(self.sim.as_mut(), node, &mut c.held, Purge::BOTH);
        self.sim.set_resetn_of(node, false);
    }
}

/// Says the first refusal of each kind a client earned since last time,
/// one line each (the rest are counted, and summed up when it goes).
fn say_refusals(c: &mut Client) {
    for r in c.refusal_news() {
        eprintln!(
            "plm sim: client {}: refused {r} (more of the kind are counted and summed up when \
             it goes)",
            c.peer
        );
    }
}

/// A listener's thread: every connection to the loop.
fn accept(node: usize, listener: TcpListener, tx: Sender<Wake>) {
    for conn in listener.incoming() {
        let sent = match conn.and_then(|s| Ok((s.peer_addr()?, s))) {
            Ok((peer, stream)) => tx.send(Wake::Accepted { node, stream, peer }),
            Err(e) => {
                eprintln!("plm sim: accept failed: {e}");
                // Out of descriptors, say: a moment before the next try.
                std::thread::sleep(Duration::from_millis(10));
                Ok(())
            }
        };
        if sent.is_err() {
            return; // the loop has ended
        }
    }
}

/// A second client while one is connected: told and closed.
fn refuse(mut stream: TcpStream, peer: SocketAddr) {
    println!("plm sim: refused {peer}: a client is already connected");
    let _ = stream.write_all(b"plm sim: busy: the simulated modem has a client already\r\n");
    let _ = stream.shutdown(Shutdown::Both);
}
