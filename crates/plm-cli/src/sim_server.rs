//! `plm sim`: the simulated ST7580 served as a serial port over RFC 2217,
//! so that any host software that speaks it (pyserial's `rfc2217://`,
//! ser2net clients, the console's own TCP transport) can drive it; or,
//! with `--board`, a street-light concentrator board's USART with a
//! street of lamps behind it (application frames, RTS ignored: a board's
//! USART has no T_REQ).
//!
//! One thread. The simulator runs in virtual microseconds; this loop maps
//! wall-clock time since the first client connected onto it, advancing it
//! at least every millisecond while anything is scheduled, and passes
//! bytes both ways:
//!
//! | client (RFC 2217)                    | simulated modem 0          |
//! |--------------------------------------|----------------------------|
//! | data                                 | host UART TX -> modem RX   |
//! | SET-BAUDRATE 9600/19200/38400/57600  | BR pins (`Sim::set_baud`)  |
//! | SET-CONTROL RTS ON / OFF             | T_REQ asserted / released  |
//! | SET-CONTROL DTR ON / OFF             | RESETN held low / released |
//! | data to the client                   | modem UART TX -> host RX   |
//!
//! The modems are powered on (simulated time 0) when the first client
//! connects, so that it sees the BIO_ResetIndication; later clients find
//! them running. One client at a time: another one is told so and closed.
//! With `--serve N`, nodes 0..N-1 of the one line are each served on a
//! port of their own (the `--listen` port + i, or N free ports with port
//! 0), each with its own client, T_REQ, DTR, baud rate and faults; the
//! nodes not served echo, by default with node 0's MIB 00h/01h
//! (`Peers::EchoFollowing`), with `--peers factory` at the factory MIB.
//!
//! When the client goes, T_REQ and DTR are released and the simulation
//! goes on. DTR is wired to RESETN, as on many USB-UART boards: a client
//! that asserts it holds the modem off (a DTR pulse resets it, factory
//! MIB and BIO_ResetIndication); a client that never touches DTR finds the
//! modem running (the line starts released).

use crate::rfc2217::{self, Action};
use plm_sim::{Attach, Fault, Peers, Sim, SimConfig};
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Baud rates the BR0/BR1 pins select (UM0932 3.1).
pub const RATES: &[u32] = &plm_sim::BAUD_RATES;

/// The longest the loop sleeps while the simulator has something scheduled.
const TICK: Duration = Duration::from_millis(1);
/// The longest it sleeps when nothing is scheduled (only accepting, Ctrl-C).
const IDLE: Duration = Duration::from_millis(20);

/// Lamps on a street unless told otherwise (`--board` alone).
pub const DEFAULT_STREET: usize = 12;

/// What is simulated behind the served port.
pub enum World {
    /// Modems: `serve` served ones and the others echoing.
    Modems {
        /// Modems on the line.
        nodes: usize,
        /// Nodes 0..serve served, each on its own port.
        serve: usize,
        /// Who the echoing peers are ([`Peers::Echo`]: factory MIB;
        /// [`Peers::EchoFollowing`]: node 0's MIB 00h/01h).
        peers: Peers,
    },
    /// A street of lamps behind the served modem or concentrator board.
    Street {
        /// Street-light boards on the line.
        lamps: usize,
        /// What the client's bytes reach.
        attach: Attach,
        /// The lamps start cold: they ignite and warm up at power-on
        /// (otherwise they burn in RUN from the start,
        /// `BallastConfig::warm_start`).
        cold: bool,
        /// Random lamp failures per lamp per lit hour (0: none;
        /// `BallastConfig::failure_rate_per_lit_hour`).
        failures: f64,
    },
}

/// What `plm sim` was asked for.
pub struct Options {
    pub listen: String,
    pub allow_remote: bool,
    pub world: World,
    pub seed: u64,
}

/// Serves until Ctrl-C (or SIGTERM).
pub fn run(opts: Options) -> Result<(), String> {
    let serve = match opts.world {
        World::Modems { serve, .. } => serve.max(1),
        World::Street { .. } => 1,
    };
    let listeners = bind_all(&opts.listen, opts.allow_remote, serve)?;
    let addrs: Vec<SocketAddr> = listeners
        .iter()
        .map(|l| l.local_addr().map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let addr = addrs[0];
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst))
        .map_err(|e| format!("cannot catch Ctrl-C: {e}"))?;

    let (config, what) = match opts.world {
        World::Modems {
            nodes,
            serve,
            peers,
        } => (
            SimConfig {
                nodes: nodes.max(serve),
                served: serve,
                peers,
                ..SimConfig::default()
            },
            if serve > 1 {
                format!(
                    "simulated ST7580 line (nodes 0-{} of {nodes} served",
                    serve - 1
                )
            } else {
                format!("simulated ST7580 (node 0 of {nodes}")
            },
        ),
        World::Street {
            lamps,
            attach,
            cold,
            failures,
        } => (
            {
                let street = SimConfig::street(lamps, attach);
                SimConfig {
                    ballast: plm_sim::ballast::BallastConfig {
                        warm_start: !cold,
                        failure_rate_per_lit_hour: failures,
                        ..street.ballast.clone()
                    },
                    ..street
                }
            },
            match attach {
                Attach::Modem => {
                    format!("simulated ST7580 with a street of {lamps} lamps (nodes 1-{lamps}")
                }
                Attach::Board => format!(
                    "simulated concentrator board's USART with a street of {lamps} lamps \
                     (nodes 1-{lamps}"
                ),
            },
        ),
    };
    let greeting = match config.attach {
        Attach::Modem => "plm sim: simulated ST7580, node 0",
        Attach::Board => "plm sim: simulated street-light concentrator board (USART)",
    };
    let mut sim = Sim::new(SimConfig {
        seed: opts.seed,
        ..config
    });
    println!(
        "plm sim: {what}, seed {}) as RFC 2217 on {addr} \
         — connect with e.g. pyserial rfc2217://{addr}",
        opts.seed
    );
    if serve > 1 {
        for (i, a) in addrs.iter().enumerate() {
            println!("plm sim: node {i} on rfc2217://{a}");
        }
    }
    if sim.nodes() > serve {
        println!(
            "plm sim: nodes {}-{} echo what they hear, {}",
            serve,
            sim.nodes() - 1,
            match sim_peers(&opts.world) {
                Peers::EchoFollowing => "with node 0's MIB 00h/01h (as its host writes them)",
                _ => "with the factory MIB (--peers factory)",
            }
        );
    }
    println!("plm sim: the simulation powers on when the first client connects; Ctrl-C stops");

    // Wall-clock time of simulated time 0.
    let mut origin: Option<Instant> = None;
    let mut clients: Vec<Option<Client>> = (0..serve).map(|_| None).collect();
    while !stop.load(Ordering::SeqCst) {
        for (node, listener) in listeners.iter().enumerate() {
            match listener.accept() {
                Ok((stream, peer)) if clients[node].is_some() => refuse(stream, peer),
                Ok((stream, peer)) => {
                    let start = *origin.get_or_insert_with(Instant::now);
                    advance(&mut sim, start);
                    match Client::open(stream, peer, sim.baud_of(node), greeting) {
                        Ok(c) => {
                            if serve > 1 {
                                println!("plm sim: client {peer} connected to node {node}");
                            } else {
                                println!("plm sim: client {peer} connected");
                            }
                            clients[node] = Some(c);
                        }
                        Err(e) => println!("plm sim: client {peer} lost at once: {e}"),
                    }
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                Err(e) => eprintln!("plm sim: accept failed: {e}"),
            }
        }
        let Some(start) = origin else {
            std::thread::sleep(IDLE);
            continue;
        };

        advance(&mut sim, start);
        let wait = match sim.next_deadline() {
            Some(t) => Duration::from_micros(t.saturating_sub(sim_now(start))).min(TICK),
            None => IDLE,
        }
        .max(Duration::from_micros(50));
        let connected = clients.iter().filter(|c| c.is_some()).count();
        if connected == 0 {
            // Nobody on the host side of the UARTs: the bytes are lost.
            for node in 0..serve {
                sim.host_read_of(node);
            }
            std::thread::sleep(wait);
            continue;
        }
        // One client waits the whole of it; several take turns of a share
        // of TICK, so that one client's bytes never wait out another's
        // idle read (a T_REQ edge must meet its status within 20 ms).
        let share = if connected > 1 {
            (wait.min(TICK) / connected as u32).max(Duration::from_micros(50))
        } else {
            wait
        };
        for (node, slot) in clients.iter_mut().enumerate() {
            advance(&mut sim, start);
            let out: Vec<u8> = sim.host_read_of(node).into_iter().map(|(_, b)| b).collect();
            let Some(c) = slot.as_mut() else {
                continue;
            };
            let result = c
                .send(&out)
                .and_then(|()| c.serve(&mut sim, node, start, share));
            if let Err(why) = result {
                println!("plm sim: client {} disconnected ({why})", c.peer);
                *slot = None;
                advance(&mut sim, start);
                // The host is gone: T_REQ and DTR are released (pulled up).
                sim.set_treq_of(node, false);
                sim.inject_on(node, Fault::Resetn(false));
            }
        }
    }
    for c in clients.into_iter().flatten() {
        let _ = c.stream.shutdown(std::net::Shutdown::Both);
        println!("plm sim: client {} disconnected (stopping)", c.peer);
    }
    println!("plm sim: stopped");
    Ok(())
}

/// Who the echoing peers of `world` are.
fn sim_peers(world: &World) -> Peers {
    match world {
        World::Modems { peers, .. } => *peers,
        World::Street { .. } => Peers::Street,
    }
}

/// Binds `n` ports: `listen`, then its port + 1, ... (port 0: `n` free
/// ports).
fn bind_all(listen: &str, allow_remote: bool, n: usize) -> Result<Vec<TcpListener>, String> {
    let first = bind(listen, allow_remote)?;
    let base = first.local_addr().map_err(|e| e.to_string())?;
    let fixed = !listen.ends_with(":0");
    let mut all = vec![first];
    for i in 1..n {
        let mut a = base;
        if fixed {
            let port = u16::try_from(usize::from(base.port()) + i)
                .map_err(|_| format!("--listen {listen}: no port {i} above it for node {i}"))?;
            a.set_port(port);
        } else {
            a.set_port(0);
        }
        all.push(bind(&a.to_string(), allow_remote)?);
    }
    Ok(all)
}

/// Binds `listen`, refusing anything but loopback unless `allow_remote`:
/// the simulator has no authentication.
fn bind(listen: &str, allow_remote: bool) -> Result<TcpListener, String> {
    let addrs: Vec<SocketAddr> = listen
        .to_socket_addrs()
        .map_err(|e| format!("--listen {listen}: {e}"))?
        .collect();
    if let Some(remote) = addrs.iter().find(|a| !a.ip().is_loopback()) {
        if !allow_remote {
            return Err(format!(
                "--listen {listen}: {} is not a loopback address; anyone who can reach it \
                 could drive the simulator. Use 127.0.0.1 or [::1], or add --allow-remote",
                remote.ip()
            ));
        }
    }
    let listener =
        TcpListener::bind(&addrs[..]).map_err(|e| format!("cannot listen on {listen}: {e}"))?;
    listener
        .set_nonblocking(true)
        .map_err(|e| format!("cannot listen on {listen}: {e}"))?;
    Ok(listener)
}

/// Simulated time now: microseconds of wall-clock time since `start`.
fn sim_now(start: Instant) -> plm_core::time::Instant {
    start.elapsed().as_micros() as u64
}

fn advance(sim: &mut Sim, start: Instant) {
    sim.advance_to(sim_now(start));
}

/// A second client while one is connected: told and closed.
fn refuse(mut stream: TcpStream, peer: SocketAddr) {
    println!("plm sim: refused {peer}: a client is already connected");
    let _ = stream.write_all(b"plm sim: busy: the simulated modem has a client already\r\n");
    let _ = stream.shutdown(std::net::Shutdown::Both);
}

/// The connected client.
struct Client {
    stream: TcpStream,
    peer: SocketAddr,
    telnet: rfc2217::Server,
    /// Modem bytes held while the client has suspended the flow
    /// (RFC 2217 FLOWCONTROL-SUSPEND).
    held: Vec<u8>,
}

impl Client {
    fn open(
        stream: TcpStream,
        peer: SocketAddr,
        baud: u32,
        greeting: &'static str,
    ) -> std::io::Result<Client> {
        stream.set_nonblocking(false)?;
        // Bytes go out as they come: Nagle's delay would eat T_ACK (40 ms).
        stream.set_nodelay(true)?;
        stream.set_write_timeout(Some(Duration::from_secs(5)))?;
        let mut c = Client {
            stream,
            peer,
            telnet: rfc2217::Server::new(greeting, baud, RATES),
            held: Vec::new(),
        };
        let greeting = c.telnet.greeting();
        c.stream.write_all(&greeting)?;
        Ok(c)
    }

    /// Sends modem bytes to the client, IAC doubled (RFC 2217 "Data
    /// transfer": the data stream is Telnet, RFC 854).
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.held.extend_from_slice(bytes);
        if self.telnet.suspended() || self.held.is_empty() {
            return Ok(());
        }
        let data = rfc2217::escape(&self.held);
        self.held.clear();
        self.stream.write_all(&data)
    }

    /// Waits up to `wait` for bytes from the client and carries them out.
    fn serve(
        &mut self,
        sim: &mut Sim,
        node: usize,
        start: Instant,
        wait: Duration,
    ) -> std::io::Result<()> {
        self.stream.set_read_timeout(Some(wait))?;
        let mut buf = [0u8; 4096];
        let n = match self.stream.read(&mut buf) {
            Ok(0) => {
                return Err(std::io::Error::new(
                    ErrorKind::UnexpectedEof,
                    "closed by the client",
                ))
            }
            Ok(n) => n,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Ok(())
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => return Ok(()),
            Err(e) => return Err(e),
        };
        // The bytes arrived now: bring the modem up to now first.
        advance(sim, start);
        let mut reply = Vec::new();
        for action in self.telnet.receive(&buf[..n], &mut reply) {
            match action {
                Action::Write(data) => sim.write_to(node, &data),
                Action::SetBaud(baud) => sim.set_baud_of(node, baud),
                Action::SetRts(on) => sim.set_treq_of(node, on),
                // DTR wired to RESETN, as on many USB-UART boards: asserted
                // holds the modem in reset, released boots it.
                Action::SetDtr(on) => sim.inject_on(node, Fault::Resetn(on)),
                Action::PurgeReceive => {
                    self.held.clear();
                    sim.host_read_of(node);
                }
                // Client data goes to the UART at once: nothing is held.
                Action::PurgeTransmit => {}
                Action::Suspend(_) => {}
            }
        }
        self.stream.write_all(&reply)?;
        // Resuming sends what was held.
        self.send(&[])
    }
}
