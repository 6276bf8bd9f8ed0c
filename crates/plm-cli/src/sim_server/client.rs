//! One client of `plm sim`: its RFC 2217 connection, the threads that
//! read and write its socket, and the bounds on what it can make the
//! server hold (a client that floods, or reads nothing, costs a few
//! kilobytes and never holds up another).
//!
//! - What it sends reaches the simulated UART through a transmit buffer
//!   of [`TX_BUFFER`] bytes (as a host's serial driver has one): bytes
//!   written while it is full are dropped and said so.
//! - Its reading thread stops reading while [`IN_FLIGHT`] bytes wait for
//!   the loop, so that TCP holds the rest back.
//! - What goes to it waits in an [`Outbox`] for its writing thread; past
//!   [`OUTBOX`] bytes the client is dropped (it reads nothing).
//! - When it goes, its port is purged ([`purge`]): what it sent and the
//!   modem has not read is lost, as on a real port.

use crate::rfc2217::{self, Action, Refusal};
use plm_sim::Ports;
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Duration;

/// What wakes the loop ([`super::event_loop`]): a client's threads send
/// `Data` and `Closed`, the listeners `Accepted`, a stopper `Stop`.
pub(super) enum Wake {
    /// A client connected to node `node`'s port.
    Accepted {
        node: usize,
        stream: TcpStream,
        peer: SocketAddr,
    },
    /// Bytes from connection `conn`.
    Data { conn: u64, chunk: Chunk },
    /// Connection `conn` closed or failed.
    Closed { conn: u64, why: String },
    /// Ctrl-C, SIGTERM or [`super::event_loop::Stopper::stop`].
    Stop,
}

/// The simulated UART's transmit buffer: bytes a client may have written
/// and the modem not yet received (4 KiB, the transmit buffer of Linux's
/// serial driver; at 57600 baud 0.7 s of line, at 9600 4.3 s).
pub const TX_BUFFER: usize = 4096;

/// Modem bytes held for a client that suspended the flow
/// (FLOWCONTROL-SUSPEND), as a port's receive buffer would; more are
/// lost.
pub const HELD: usize = 4096;

/// Bytes read from a client and not yet handled by the loop (two reads):
/// what another client sends never waits behind more than this of one
/// client's.
pub const IN_FLIGHT: usize = 8 * 1024;

/// Bytes waiting to be written to a client: past this it reads nothing,
/// and it is dropped.
pub const OUTBOX: usize = 64 * 1024;

/// Which buffers of a port a purge empties (RFC 2217 PURGE-DATA).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Purge {
    /// What the modem sent that the client has not yet had.
    pub receive: bool,
    /// What the client sent that the modem has not yet read.
    pub transmit: bool,
}

impl Purge {
    pub const BOTH: Purge = Purge {
        receive: true,
        transmit: true,
    };
}

/// Purges node `node`'s port as a real port's driver purges its buffers
/// (RFC 2217 PURGE-DATA; both ways when the client goes): `transmit`,
/// what the client sent and the modem has not yet read (in the simulated
/// UART, [`Ports::purge_to_modem`], a T_REQ change waiting behind it
/// coming now); `receive`, what the modem sent and the client has not
/// yet had (`held` while the flow is suspended, what reached the host
/// side of the UART and what is on its way there,
/// [`Ports::purge_to_host`]). The modem runs on: nothing is reset.
pub fn purge(sim: &mut dyn Ports, node: usize, held: &mut Vec<u8>, which: Purge) {
    if which.transmit {
        sim.purge_to_modem(node);
    }
    if which.receive {
        held.clear();
        sim.purge_to_host(node);
    }
}

/// A connected client.
pub struct Client {
    pub stream: TcpStream,
    pub peer: SocketAddr,
    pub conn: u64,
    telnet: rfc2217::Server,
    /// Modem bytes held while the client has suspended the flow
    /// (RFC 2217 FLOWCONTROL-SUSPEND), at most [`HELD`].
    pub held: Vec<u8>,
    outbox: Arc<Outbox>,
}

impl Client {
    /// Greets the client and starts its reading and writing threads,
    /// which pass what happens to the loop through `wakes`.
    pub(super) fn open(
        stream: TcpStream,
        peer: SocketAddr,
        conn: u64,
        baud: u32,
        signature: &str,
        wakes: &Sender<Wake>,
    ) -> std::io::Result<Client> {
        stream.set_nonblocking(false)?;
        // Bytes go out as they come: Nagle's delay would eat T_ACK (40 ms).
        stream.set_nodelay(true)?;
        stream.set_write_timeout(Some(Duration::from_secs(5)))?;
        let reader = stream.try_clone()?;
        let writer = stream.try_clone()?;
        let outbox = Arc::new(Outbox::default());
        let mut c = Client {
            stream,
            peer,
            conn,
            telnet: rfc2217::Server::new(signature, baud, super::RATES),
            held: Vec::new(),
            outbox: outbox.clone(),
        };
        let greeting = c.telnet.greeting();
        c.outbox.push(&greeting).map_err(std::io::Error::other)?;
        let tx = wakes.clone();
        std::thread::spawn(move || read(conn, reader, tx));
        let tx = wakes.clone();
        std::thread::spawn(move || write(conn, writer, outbox, tx));
        Ok(c)
    }

    /// Sends modem bytes to the client, IAC doubled (RFC 2217 "Data
    /// transfer": the data stream is Telnet, RFC 854), or holds them
    /// while the flow is suspended. An error says why the client must go.
    pub fn send(&mut self, bytes: &[u8]) -> Result<(), String> {
        let room = HELD.saturating_sub(self.held.len()).min(bytes.len());
        self.held.extend_from_slice(&bytes[..room]);
        if room < bytes.len() {
            self.telnet.refuse(Refusal::Overrun {
                bytes: bytes.len() - room,
                buffer: HELD,
            });
        }
        if self.telnet.suspended() || self.held.is_empty() {
            return Ok(());
        }
        let data = rfc2217::escape(&self.held);
        self.held.clear();
        self.outbox.push(&data)
    }

    /// Carries out what the client sent; an error says why it must go.
    ///
    /// | client (RFC 2217)                    | simulated modem `node`     |
    /// |--------------------------------------|----------------------------|
    /// | data                                 | host UART TX -> modem RX   |
    /// | SET-BAUDRATE 9600/19200/38400/57600  | BR pins (`Ports::set_baud_of`) |
    /// | SET-CONTROL RTS ON / OFF             | T_REQ asserted / released  |
    /// | SET-CONTROL DTR ON / OFF             | RESETN held low / released |
    /// | PURGE-DATA 1 / 2 / 3                 | [`purge`] of that buffer   |
    pub fn receive(
        &mut self,
        sim: &mut dyn Ports,
        node: usize,
        bytes: &[u8],
    ) -> Result<(), String> {
        let mut reply = Vec::new();
        for action in self.telnet.receive(bytes, &mut reply) {
            match action {
                Action::Write(data) => self.write_to_uart(sim, node, &data),
                Action::SetBaud(baud) => sim.set_baud_of(node, baud),
                Action::SetRts(on) => sim.set_treq_of(node, on),
                // DTR wired to RESETN, as on many USB-UART boards: asserted
                // holds the modem in reset, released boots it.
                Action::SetDtr(on) => sim.set_resetn_of(node, on),
                Action::PurgeReceive => purge(
                    sim,
                    node,
                    &mut self.held,
                    Purge {
                        receive: true,
                        transmit: false,
                    },
                ),
                Action::PurgeTransmit => purge(
                    sim,
                    node,
                    &mut self.held,
                    Purge {
                        receive: false,
                        transmit: true,
                    },
                ),
                Action::Suspend(_) => {}
            }
        }
        self.outbox.push(&reply)?;
        // Resuming sends what was held.
        self.send(&[])
    }

    /// Data to the modem, as much as the transmit buffer takes: the rest
    /// is dropped and counted.
    fn write_to_uart(&mut self, sim: &mut dyn Ports, node: usize, data: &[u8]) {
        let baud = sim.baud_of(node);
        let backlog = sim.backlog_to_modem(node);
        let queued = (backlog * u64::from(baud)).div_ceil(10 * 1_000_000);
        let room = TX_BUFFER.saturating_sub(queued as usize).min(data.len());
        if room > 0 {
            sim.write_to(node, &data[..room]);
        }
        if room < data.len() {
            self.telnet.refuse(Refusal::Flood {
                bytes: data.len() - room,
                buffer: TX_BUFFER,
                baud,
            });
        }
    }

    /// The first refusal of each kind not yet said.
    pub fn refusal_news(&mut self) -> Vec<Refusal> {
        self.telnet.take_refusal_news()
    }

    /// Everything refused over the connection, in words.
    pub fn refusal_summary(&self) -> Option<String> {
        self.telnet.refusals().summary()
    }

    /// Stops its writing thread (what waits is dropped).
    pub fn close(&self) {
        self.outbox.close();
    }
}

/// Locks, taking over a lock whose holder panicked (the data is plain
/// bytes and counts, never half-changed).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// What waits for a client's writing thread.
#[derive(Default)]
struct Outbox {
    /// The bytes, and whether the client is gone.
    state: Mutex<(Vec<u8>, bool)>,
    ready: Condvar,
}

impl Outbox {
    /// Queues `bytes`; an error when [`OUTBOX`] bytes would wait.
    fn push(&self, bytes: &[u8]) -> Result<(), String> {
        if bytes.is_empty() {
            return Ok(());
        }
        let mut s = lock(&self.state);
        if s.0.len() + bytes.len() > OUTBOX {
            return Err(format!(
                "it reads nothing: {} bytes wait to be sent to it",
                s.0.len() + bytes.len()
            ));
        }
        s.0.extend_from_slice(bytes);
        self.ready.notify_one();
        Ok(())
    }

    fn close(&self) {
        lock(&self.state).1 = true;
        self.ready.notify_one();
    }

    /// The next bytes to write; `None` once closed.
    fn next(&self) -> Option<Vec<u8>> {
        let mut s = lock(&self.state);
        loop {
            if s.1 {
                return None;
            }
            if !s.0.is_empty() {
                return Some(std::mem::take(&mut s.0));
            }
            s = self.ready.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }
}

/// A client's writing thread.
fn write(conn: u64, mut stream: TcpStream, outbox: Arc<Outbox>, tx: Sender<Wake>) {
    while let Some(bytes) = outbox.next() {
        if let Err(e) = stream.write_all(&bytes) {
            let _ = tx.send(Wake::Closed {
                conn,
                why: e.to_string(),
            });
            return;
        }
    }
}

/// Bytes a reading thread has passed on and the loop not yet handled.
#[derive(Default)]
pub struct Credit {
    used: Mutex<usize>,
    freed: Condvar,
}

impl Credit {
    /// Waits until fewer than [`IN_FLIGHT`] bytes are in flight.
    fn wait_for_room(&self) {
        let mut used = lock(&self.used);
        while *used >= IN_FLIGHT {
            used = self.freed.wait(used).unwrap_or_else(|e| e.into_inner());
        }
    }
}

/// Bytes read from a client, counted in flight until dropped (handled, or
/// ignored because the client went).
pub struct Chunk {
    pub bytes: Vec<u8>,
    credit: Arc<Credit>,
}

impl Chunk {
    fn new(bytes: Vec<u8>, credit: Arc<Credit>) -> Chunk {
        *lock(&credit.used) += bytes.len();
        Chunk { bytes, credit }
    }
}

impl Drop for Chunk {
    fn drop(&mut self) {
        let mut used = lock(&self.credit.used);
        *used = used.saturating_sub(self.bytes.len());
        self.credit.freed.notify_one();
    }
}

/// A client's reading thread: its bytes to the loop as they come, at most
/// [`IN_FLIGHT`] of them waiting there.
fn read(conn: u64, mut stream: TcpStream, tx: Sender<Wake>) {
    let credit = Arc::new(Credit::default());
    let mut buf = [0u8; 4096];
    let why = loop {
        credit.wait_for_room();
        match stream.read(&mut buf) {
            Ok(0) => break "closed by the client".to_string(),
            Ok(n) => {
                let chunk = Chunk::new(buf[..n].to_vec(), credit.clone());
                if tx.send(Wake::Data { conn, chunk }).is_err() {
                    return;
                }
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => break e.to_string(),
        }
    };
    let _ = tx.send(Wake::Closed { conn, why });
}
