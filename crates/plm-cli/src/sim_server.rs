//! `plm sim`: the simulated ST7580 served as a serial port over RFC 2217,
//! so that any host software that speaks it (pyserial's `rfc2217://`,
//! ser2net clients, the console's own TCP transport) can drive it; or,
//! with `--board`, a street-light concentrator board's USART with a
//! street of lamps behind it (application frames, RTS ignored: a board's
//! USART has no T_REQ); or, with `--chip st7570`, an S-FSK line of
//! ST7570s ([`plm_sim::st7570::net::Network`]) whose node 0 is the
//! client's modem and whose other nodes are answering MAC Servers, every
//! [`REPEATER_EVERY`]-th a repeater. One loop serves both chips: it
//! reaches the simulation through [`plm_sim::Ports`].
//!
//! The loop ([`event_loop`]) maps wall-clock time since the first client
//! connected onto the simulator's virtual microseconds, and wakes when a
//! socket has something or the simulation's next deadline comes; it
//! passes bytes both ways:
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
//! When the client goes, what it sent and the modem has not yet read is
//! discarded, as a purge of a real port's buffers would ([`client::purge`]),
//! T_REQ and DTR are released and the simulation goes on. What a client
//! can make the server hold is bounded ([`client`]), and what it refuses
//! it says on stderr in words ([`crate::rfc2217::Refusal`]), the first of
//! each kind at once, all of them summed up when the client goes. DTR is wired to RESETN, as on many USB-UART boards: a client
//! that asserts it holds the modem off (a DTR pulse resets it, factory
//! MIB and BIO_ResetIndication); a client that never touches DTR finds the
//! modem running (the line starts released).

pub mod alarms;
pub mod client;
pub mod event_loop;

pub use event_loop::{Served, Stopper, RATES};
use plm_sim::board::street_address;
use plm_sim::{Attach, LineConfig, Peers, Sim, SimConfig, StreetProfile};
use std::net::{SocketAddr, TcpListener, ToSocketAddrs};

/// Lamps on a street unless told otherwise (`--board` alone).
pub const DEFAULT_STREET: usize = 12;

/// ST7570 nodes on the line unless told otherwise: the host's modem and
/// three Servers, the third a repeater.
pub const DEFAULT_ST7570_NODES: usize = plm_sim::st7570::net::SERVED_LINE_NODES;

/// Every this many nodes along an ST7570 line, a Server is a repeater
/// (nodes 3, 6, 9, ...): a frame then crosses at most two Servers to the
/// next repeater, well inside a hop's reach on the default line.
pub use plm_sim::st7570::net::REPEATER_EVERY;

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
    /// ST7570 modems on one S-FSK line (`--chip st7570`): nodes
    /// 0..serve served (their host is the client), the others
    /// [`plm_sim::st7570::responder::Responder`] MAC Servers, every
    /// [`REPEATER_EVERY`]-th a repeater.
    St7570 {
        /// Modems on the line.
        nodes: usize,
        /// Nodes 0..serve served, each on its own port.
        serve: usize,
        /// Every this many µs the next Server raises an alarm
        /// ([`alarms::Alarming`]); `None`: only when asked.
        alarms: Option<u64>,
        /// The Servers take on node 0's bit rate, f0 and f1
        /// ([`plm_sim::st7570::net::NetConfig::servers_follow`]); `false`:
        /// they keep the factory ones (`--factory-servers`).
        servers_follow: bool,
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
        /// Every lamp alike (`StreetProfile::Uniform`); otherwise they
        /// differ as a real street's (`StreetProfile::Realistic`).
        uniform: bool,
        /// Random lamp failures per lamp per lit hour (0: none;
        /// `BallastConfig::failure_rate_per_lit_hour`).
        failures: f64,
        /// A rule of the board protocol every lamp breaks (`--break`).
        breach: Option<plm_sim::breach::Breach>,
    },
}

/// What `plm sim` was asked for.
pub struct Options {
    pub listen: String,
    pub allow_remote: bool,
    pub world: World,
    pub seed: u64,
    /// Probability that a frame is lost at each receiver that could hear
    /// it (`--loss`; [`plm_sim::LineConfig::loss`]).
    pub loss: f64,
    /// Capture on the ST7580 line (`--no-capture` turns it off;
    /// [`plm_sim::LineConfig::capture_db`]).
    pub capture: bool,
}

/// `plm sim`, bound and ready: its ports, what it says at start, and the
/// loop that serves them.
pub struct Bound {
    /// Node i's address (node 0's first).
    pub addrs: Vec<SocketAddr>,
    /// The lines that say what is served where.
    pub banner: Vec<String>,
    pub served: Served,
}

/// Serves until Ctrl-C (or SIGTERM).
pub fn run(opts: Options) -> Result<(), String> {
    let bound = bind(opts)?;
    let stopper = bound.served.stopper();
    ctrlc::set_handler(move || stopper.stop()).map_err(|e| format!("cannot catch Ctrl-C: {e}"))?;
    for line in &bound.banner {
        println!("{line}");
    }
    bound.served.run();
    println!("plm sim: stopped");
    Ok(())
}

/// Binds the ports and builds the simulation that `opts` asks for;
/// nothing runs until [`Served::run`].
pub fn bind(opts: Options) -> Result<Bound, String> {
    let serve = match opts.world {
        World::Modems { serve, .. } | World::St7570 { serve, .. } => serve.max(1),
        World::Street { .. } => 1,
    };
    let listeners = bind_all(&opts.listen, opts.allow_remote, serve)?;
    let addrs: Vec<SocketAddr> = listeners
        .iter()
        .map(|l| l.local_addr().map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let addr = addrs[0];
    if let World::St7570 {
        nodes,
        serve,
        alarms,
        servers_follow,
    } = opts.world
    {
        use plm_sim::st7570::net::NetConfig;
        let config = NetConfig::served_line(nodes.max(serve), serve, opts.seed);
        let config = NetConfig {
            servers_follow,
            line: plm_sim::st7570::line::SfskLine {
                loss: opts.loss,
                ..config.line.clone()
            },
            ..config
        };
        return Ok(bind_st7570(addrs, listeners, config, alarms));
    }
    let (config, what) = match opts.world {
        World::St7570 { .. } => unreachable!("served above"),
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
            uniform,
            failures,
            breach,
        } => (
            {
                let street = SimConfig::street(lamps, attach);
                SimConfig {
                    profile: match uniform {
                        true => StreetProfile::Uniform,
                        false => StreetProfile::Realistic,
                    },
                    ballast: plm_sim::ballast::BallastConfig {
                        warm_start: !cold,
                        failure_rate_per_lit_hour: failures,
                        ..street.ballast.clone()
                    },
                    breach,
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
    // What each port answers to RFC 2217 SIGNATURE.
    let signatures = (0..serve)
        .map(|node| match config.attach {
            Attach::Modem => format!("plm sim: simulated ST7580, node {node}"),
            Attach::Board => "plm sim: simulated street-light concentrator board (USART)".into(),
        })
        .collect();
    let line = LineConfig {
        loss: opts.loss,
        capture_db: opts.capture.then_some(plm_sim::line::CAPTURE_DB),
        ..config.line.clone()
    };
    let sim = Sim::new(SimConfig {
        seed: opts.seed,
        line,
        ..config
    });
    let mut banner = vec![format!(
        "plm sim: {what}, seed {}) as RFC 2217 on {addr} \
         — connect with e.g. pyserial rfc2217://{addr}",
        opts.seed
    )];
    if serve > 1 {
        for (i, a) in addrs.iter().enumerate() {
            banner.push(format!("plm sim: node {i} on rfc2217://{a}"));
        }
    }
    // A street's other nodes are street-light boards (named above), not
    // echoing modems.
    if let (World::Modems { peers, .. }, true) = (&opts.world, sim.nodes() > serve) {
        banner.push(format!(
            "plm sim: nodes {}-{} echo what they hear, {}",
            serve,
            sim.nodes() - 1,
            match peers {
                Peers::EchoFollowing => "with node 0's MIB 00h/01h (as its host writes them)",
                _ => "with the factory MIB (--peers factory)",
            }
        ));
    }
    if let World::Street {
        lamps,
        uniform: false,
        ..
    } = opts.world
    {
        banner.extend(street_banner(opts.seed, lamps));
    }
    if let World::Street {
        breach: Some(b), ..
    } = opts.world
    {
        let name = plm_sim::breach::BREACHES.iter().find(|x| x.1 == b);
        banner.push(format!(
            "plm sim: every lamp breaks the board protocol's rule `{}` (--break)",
            name.map_or("?", |x| x.0)
        ));
    }
    banner.extend(line_banner(opts.loss, opts.capture));
    banner.push(
        "plm sim: the simulation powers on when the first client connects; Ctrl-C stops".into(),
    );
    Ok(Bound {
        addrs,
        banner,
        served: Served::new(Box::new(sim), listeners, signatures),
    })
}

/// What the banner says of a realistic street's lamps that stand out.
fn street_banner(seed: u64, lamps: usize) -> Vec<String> {
    let profile = StreetProfile::Realistic;
    let mut said = vec![String::from(
        "plm sim: the lamps differ as a real street's: powers, ages, the mains drifting, \
         the night's temperature (--uniform-lamps: all alike)",
    )];
    if let Some(n) = profile.worn_lamp(seed, lamps) {
        said.push(format!(
            "plm sim: lamp {} (node {n}) is worn out and fails about 2 minutes in",
            street_address(n)
        ));
    }
    let line = LineConfig::street(lamps);
    if let Some((n, _)) = profile.weak_lamp(lamps, &line) {
        said.push(format!(
            "plm sim: lamp {} (node {n}), the far one, is heard weakly (SNR about {} dB)",
            street_address(n),
            plm_sim::profile::WEAK_SNR_DB
        ));
    }
    said
}

/// What the banner says of a line that is not ideal (nothing for the
/// defaults: no loss, capture on).
fn line_banner(loss: f64, capture: bool) -> Vec<String> {
    let mut said = Vec::new();
    if loss > 0.0 {
        said.push(format!(
            "plm sim: each frame is lost at each receiver with probability {loss} (--loss)"
        ));
    }
    if !capture {
        said.push("plm sim: overlapping frames are all lost, none captured (--no-capture)".into());
    }
    said
}

/// `plm sim --chip st7570`: the S-FSK line of `config`
/// ([`plm_sim::st7570::net::NetConfig::served_line`]), nodes 0..served served at `addrs`, the
/// others MAC Servers that configure themselves (taking on node 0's bit
/// rate, f0 and f1 if `servers_follow`) and answer what is sent to them.
fn bind_st7570(
    addrs: Vec<SocketAddr>,
    listeners: Vec<TcpListener>,
    config: plm_sim::st7570::net::NetConfig,
    alarms: Option<u64>,
) -> Bound {
    use plm_sim::st7570::net::Network;
    let (nodes, serve, seed) = (config.nodes, config.served, config.seed);
    let (servers_follow, loss) = (config.servers_follow, config.line.loss);
    let repeaters = config.repeaters();
    let net = Network::new(config);
    let addr = addrs[0];
    let what = if serve > 1 {
        format!(
            "simulated ST7570 S-FSK line (nodes 0-{} of {nodes} served",
            serve - 1
        )
    } else {
        format!("simulated ST7570 S-FSK line (node 0 of {nodes}")
    };
    let mut banner = vec![format!(
        "plm sim: {what}, seed {seed}) as RFC 2217 on {addr} \
         — connect with e.g. pyserial rfc2217://{addr}"
    )];
    if serve > 1 {
        for (i, a) in addrs.iter().enumerate() {
            banner.push(format!("plm sim: node {i} on rfc2217://{a}"));
        }
    }
    banner.push(format!(
        "plm sim: {} with the factory MIB (IDLE, PHY): write 00A1h to make {} a MAC Client",
        if serve > 1 {
            "the served modems power on"
        } else {
            "node 0 powers on"
        },
        if serve > 1 { "one" } else { "it" }
    ));
    if nodes > serve {
        let list = |v: &[usize]| {
            v.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        banner.push(format!(
            "plm sim: nodes {serve}-{} are MAC Servers at their node number (001h, 002h, ...), \
             answering frames sent to them: an M_SDU starting with '?' with '!ADDR phase N', \
             anything else echoed",
            nodes - 1
        ));
        banner.push(if servers_follow {
            "plm sim: the Servers take on node 0's bit rate, f0 and f1 (00A1h) as its host \
             writes them"
                .into()
        } else {
            "plm sim: the Servers keep the factory bit rate, f0 and f1 (1200 bit/s, 74 kHz, \
             63.3 kHz; --factory-servers): a node 0 set otherwise reaches none"
                .into()
        });
        banner.push(if repeaters.is_empty() {
            "plm sim: no repeater (repeaters are nodes 3, 6, 9, ...: add --nodes 4 or more)".into()
        } else {
            format!(
                "plm sim: repeaters (000Bh ALWAYS_REPEAT): node{} {}",
                if repeaters.len() > 1 { "s" } else { "" },
                list(&repeaters)
            )
        });
    }
    if let Some(every) = alarms {
        banner.push(format!(
            "plm sim: every {} s a Server raises an alarm (nodes {serve}-{} in turn)",
            every / 1_000_000,
            nodes - 1
        ));
    }
    banner.extend(line_banner(loss, true));
    banner.push(
        "plm sim: the simulation powers on when the first client connects; Ctrl-C stops".into(),
    );
    let signatures = (0..serve)
        .map(|node| format!("plm sim: simulated ST7570, node {node}"))
        .collect();
    let world: Box<dyn plm_sim::Ports + Send> = match alarms {
        Some(every) => Box::new(alarms::Alarming::new(net, every)),
        None => Box::new(net),
    };
    Bound {
        addrs,
        banner,
        served: Served::new(world, listeners, signatures),
    }
}

/// Binds `n` ports: `listen`, then its port + 1, ... (port 0: `n` free
/// ports).
fn bind_all(listen: &str, allow_remote: bool, n: usize) -> Result<Vec<TcpListener>, String> {
    let first = bind_one(listen, allow_remote)?;
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
        all.push(bind_one(&a.to_string(), allow_remote)?);
    }
    Ok(all)
}

/// Binds `listen`, refusing anything but loopback unless `allow_remote`:
/// the simulator has no authentication.
fn bind_one(listen: &str, allow_remote: bool) -> Result<TcpListener, String> {
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
    Ok(listener)
}
