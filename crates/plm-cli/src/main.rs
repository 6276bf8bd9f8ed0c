//! `plm`: decode ST power line modem host-interface traffic, and serve the
//! simulated modem as a serial port over RFC 2217.

use clap::{Parser, Subcommand, ValueEnum};
use plm_cli::{board, sim_server};
use plm_core::decode::Decoder;
use plm_core::link::{Dialect, Source};
use plm_core::st7570::Layer;
use std::io::{self, BufWriter, Read, Write};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "plm",
    version,
    about = "Tools for ST power line modems (ST7580, ST7570)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Decode host-interface bytes into JSON Lines, one object per frame,
    /// ACK, NAK, status message or run of garbage; with --board, a
    /// controller board's USART, one object per application frame or run
    /// of garbage; with --chip st7570 --line, a frame from the power line.
    Decode(DecodeArgs),
    /// Serve a simulated modem as an RFC 2217 (Telnet COM-PORT-OPTION)
    /// serial port: RTS drives T_REQ, DTR RESETN, SET-BAUDRATE the BR
    /// pins.
    Sim(SimArgs),
    /// Talk to street-light controller boards through a concentrator
    /// board or a bare ST7580 on a serial device or an rfc2217:// port:
    /// discover, status, dimming, firmware update, conformance.
    Board(board::BoardArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum Chip {
    St7580,
    St7570,
}

/// An ST7570 access layer (MIB 00A1h Access layer mode).
#[derive(Clone, Copy, ValueEnum)]
enum LayerArg {
    /// Physical layer mode.
    Phy,
    /// MAC layer mode.
    Mac,
}

#[derive(Clone, Copy, ValueEnum)]
enum From {
    /// Bytes the host sent (no status messages).
    Host,
    /// Bytes the modem sent.
    Modem,
}

#[derive(clap::Args)]
struct DecodeArgs {
    /// Which chip's host interface.
    #[arg(long, value_enum, required_unless_present = "board")]
    chip: Option<Chip>,
    /// Decode a street-light controller board's USART instead: application
    /// frames with CRC-16 (STEVAL-IHP007V1 UM 4.6).
    #[arg(long, conflicts_with_all = ["chip", "from", "mib_index", "layer"])]
    board: bool,
    /// Who sent the bytes (default: either).
    #[arg(long, value_enum)]
    from: Option<From>,
    /// Name MIB_ReadConfirm frames as this object (hex or decimal index)
    /// when the MIB_ReadRequest is not part of the input (ST7580).
    #[arg(long, value_parser = parse_index)]
    mib_index: Option<u8>,
    /// Read every frame in this access layer (ST7570), whatever the
    /// input's status messages and MIB 00A1h frames say; without it, PHY
    /// until they say otherwise.
    #[arg(long, value_enum)]
    layer: Option<LayerArg>,
    /// The bytes are from the ST7570's power line, not its host interface:
    /// one long MAC frame, its 38-byte subframes or its 45-byte PHY frames
    /// (IEC 61334-5-1), printed as one JSON object.
    #[arg(long, conflicts_with_all = ["board", "from", "mib_index", "layer"])]
    line: bool,
    /// Hex bytes (spaces, dots, colons allowed); read from stdin if absent.
    hex: Vec<String>,
}

#[derive(clap::Args)]
struct SimArgs {
    /// Which chip to simulate: st7580 (PSK/FSK) or st7570 (S-FSK: node 0
    /// the host's modem, the other nodes MAC Servers that answer, every
    /// third a repeater; not with --street, --board or --peers).
    #[arg(long, value_enum, default_value = "st7580")]
    chip: Chip,
    /// Address to listen on; port 0 picks a free port (the one chosen is
    /// printed).
    #[arg(long, default_value = "127.0.0.1:7580")]
    listen: String,
    /// Allow a --listen address that is not loopback (the server has no
    /// authentication).
    #[arg(long)]
    allow_remote: bool,
    /// Modems on the simulated power line (1-64, default: as many as
    /// served; with --chip st7570 3 more): the served ones and the others,
    /// which echo what they hear (ST7570: answer what is sent to them).
    /// Not with --street or --board.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=64), conflicts_with_all = ["street", "board"])]
    nodes: Option<u16>,
    /// Serve nodes 0..N-1 of the line, each on its own RFC 2217 port
    /// (the --listen port + i; port 0: N free ports), each with its own
    /// client, T_REQ, DTR and baud rate (1-64). Not with --street or
    /// --board.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..=64), conflicts_with_all = ["street", "board"])]
    serve: u16,
    /// The MIB of the nodes that are not served (they echo what they
    /// hear): `follow` applies node 0's MIB 00h/01h values as its host
    /// writes them, so that they hear what node 0 sends (the default);
    /// `factory` keeps the factory MIB. Needs such nodes (--nodes above
    /// --serve); not with --street or --board.
    #[arg(long, value_enum, conflicts_with_all = ["street", "board"])]
    peers: Option<PeerMib>,
    /// Serve a street-light concentrator board's USART (application
    /// frames, no T_REQ) with a street of lamps behind it (12 unless
    /// --street says otherwise).
    #[arg(long)]
    board: bool,
    /// Put a street of N street-light boards (1-500) on the power line,
    /// nodes 1..N, behind the served modem (node 0; or the concentrator
    /// board with --board).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=500))]
    street: Option<u16>,
    /// The street's lamps start cold when the simulation powers on:
    /// they ignite and warm up for about half a minute (by default they
    /// are already burning, as a street at work is).
    #[arg(long, conflicts_with = "nodes")]
    cold_lamps: bool,
    /// Every lamp of the street alike (150 W, new, 25 °C around it,
    /// nothing failing unless asked). By default the lamps differ as a
    /// real street's, from the seed: powers, ages, the mains drifting,
    /// the night's temperature, a worn lamp that fails about 2 minutes
    /// in, a weak far lamp (plm-sim's street profile).
    #[arg(long, conflicts_with = "nodes")]
    uniform_lamps: bool,
    /// Random lamp failures: the rate per lamp per lit hour (0-60; 0, the
    /// default, fails none). A failed lamp stays in FAILURE until a reset
    /// or a power cycle relights it (plm-sim's ballast model).
    #[arg(long, default_value_t = 0.0, value_parser = failure_rate, conflicts_with = "nodes")]
    lamp_failures: f64,
    /// With --chip st7570: every SECONDS of simulated time the next MAC
    /// Server in turn raises an alarm (its host sends CMD_AlarmRequest,
    /// heard once it is synchronized), so that a host program sees
    /// CMD_AlarmIndication come in (1-3600).
    #[arg(long, value_name = "SECONDS", value_parser = clap::value_parser!(u16).range(1..=3600))]
    alarms: Option<u16>,
    /// With --chip st7570: the MAC Servers keep the factory bit rate, f0
    /// and f1 (1200 bit/s, 74 kHz, 63.3 kHz) rather than taking on node
    /// 0's as its host writes 00A1h (the default), so that a host that
    /// sets others reaches no Server.
    #[arg(long)]
    factory_servers: bool,
    /// Each frame on the power line is lost at each receiver that could
    /// hear it with probability P (from 0 to 1, 1 excluded; default 0):
    /// a line that is not ideal.
    #[arg(long, value_name = "P", default_value_t = 0.0, allow_negative_numbers = true, value_parser = loss_probability)]
    loss: f64,
    /// Two frames overlapping at a receiver are both lost whatever their
    /// levels (by default one heard 6 dB or more above the other is
    /// received, as on a real line: capture). ST7580 only.
    #[arg(long)]
    no_capture: bool,
    /// Seed of the simulation's random number generator.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Every lamp breaks this rule of the board protocol
    /// (docs/board-protocol.md), to show `plm board conformance`
    /// catching it. For tests: hidden from --help.
    #[arg(long = "break", value_name = "RULE", hide = true, value_parser = parse_breach)]
    breach: Option<plm_sim::breach::Breach>,
}

fn parse_breach(s: &str) -> Result<plm_sim::breach::Breach, String> {
    plm_sim::breach::Breach::named(s).ok_or_else(|| {
        let names: Vec<&str> = plm_sim::breach::BREACHES.iter().map(|b| b.0).collect();
        format!("'{s}' is not a rule to break: one of {}", names.join(", "))
    })
}

/// The MIB of `plm sim`'s echoing peers.
#[derive(Clone, Copy, ValueEnum)]
enum PeerMib {
    /// Node 0's MIB 00h/01h, as its host writes them.
    Follow,
    /// The factory MIB.
    Factory,
}

fn failure_rate(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(r) if (0.0..=60.0).contains(&r) => Ok(r),
        _ => Err(format!(
            "'{s}' is not a failure rate: a number of failures per lamp per lit hour, 0 to 60"
        )),
    }
}

fn loss_probability(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if (0.0..1.0).contains(&p) => Ok(p),
        _ => Err(format!(
            "'{s}' is not a loss probability: a number from 0 up to but not including 1 \
             (0.05: one frame in twenty lost at each receiver)"
        )),
    }
}

fn parse_index(s: &str) -> Result<u8, String> {
    let t = s.trim_end_matches(['h', 'H']);
    let t = t.strip_prefix("0x").unwrap_or(t);
    u8::from_str_radix(
        t,
        if t.len() != s.len() || s.starts_with("0x") {
            16
        } else {
            10
        },
    )
    .map_err(|_| format!("'{s}' is not a MIB index (0..255, or hex like 0Ah / 0x0a)"))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Decode(args) => match decode(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(msg) => {
                eprintln!("plm decode: {msg}");
                ExitCode::from(2)
            }
        },
        Command::Sim(args) => match sim(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(msg) => {
                eprintln!("plm sim: {msg}");
                ExitCode::from(2)
            }
        },
        Command::Board(args) => ExitCode::from(board::run(args)),
    }
}

fn sim(args: SimArgs) -> Result<(), String> {
    let world = match args.chip {
        Chip::St7580 => st7580_world(&args)?,
        Chip::St7570 => st7570_world(&args)?,
    };
    sim_server::run(sim_server::Options {
        listen: args.listen,
        allow_remote: args.allow_remote,
        world,
        seed: args.seed,
        loss: args.loss,
        capture: !args.no_capture,
    })
}

/// `plm sim --chip st7570`: a line of ST7570s; the options of streets and
/// echoing ST7580 peers are refused rather than ignored.
fn st7570_world(args: &SimArgs) -> Result<sim_server::World, String> {
    for (given, flag) in [
        (args.street.is_some(), "--street"),
        (args.board, "--board"),
        (args.peers.is_some(), "--peers"),
        (args.cold_lamps, "--cold-lamps"),
        (args.uniform_lamps, "--uniform-lamps"),
        (args.lamp_failures > 0.0, "--lamp-failures"),
        (args.breach.is_some(), "--break"),
    ] {
        if given {
            return Err(format!(
                "{flag} cannot be used with --chip st7570: the ST7570 line has no street-light \
                 boards and its other nodes are MAC Servers that answer, not echoing ST7580s"
            ));
        }
    }
    if args.no_capture {
        return Err(format!(
            "--no-capture cannot be used with --chip st7570: on its S-FSK line a frame {} dB \
             above the others in its slot is always received (the ST7580 line's capture is \
             the one that can be turned off)",
            plm_sim::st7570::line::CAPTURE_DB
        ));
    }
    let serve = usize::from(args.serve);
    let nodes = args
        .nodes
        .map_or(serve + sim_server::DEFAULT_ST7570_NODES - 1, usize::from);
    if nodes < serve {
        return Err(format!(
            "--nodes {nodes} --serve {serve}: the served nodes are nodes of the line; \
             give --nodes {serve} or more"
        ));
    }
    if args.alarms.is_some() && nodes == serve {
        return Err(format!(
            "--alarms: every node is served ({nodes}), no Server raises one; \
             add Servers with --nodes {} or more",
            serve + 1
        ));
    }
    if args.factory_servers && nodes == serve {
        return Err(format!(
            "--factory-servers: every node is served ({nodes}), there is no Server; \
             add Servers with --nodes {} or more",
            serve + 1
        ));
    }
    Ok(sim_server::World::St7570 {
        nodes,
        serve,
        alarms: args.alarms.map(|s| u64::from(s) * 1_000_000),
        servers_follow: !args.factory_servers,
    })
}

fn st7580_world(args: &SimArgs) -> Result<sim_server::World, String> {
    if args.alarms.is_some() {
        return Err("--alarms needs --chip st7570: MAC Servers raise the alarms".into());
    }
    if args.factory_servers {
        return Err(
            "--factory-servers needs --chip st7570: the ST7580's echoing peers \
             keep the factory MIB with --peers factory"
                .into(),
        );
    }
    let world = match (args.board, args.street) {
        (true, n) => sim_server::World::Street {
            lamps: n.map_or(sim_server::DEFAULT_STREET, usize::from),
            attach: plm_sim::Attach::Board,
            cold: args.cold_lamps,
            uniform: args.uniform_lamps,
            failures: args.lamp_failures,
            breach: args.breach,
        },
        (false, Some(n)) => sim_server::World::Street {
            lamps: n.into(),
            attach: plm_sim::Attach::Modem,
            cold: args.cold_lamps,
            uniform: args.uniform_lamps,
            failures: args.lamp_failures,
            breach: args.breach,
        },
        (false, None)
            if args.cold_lamps
                || args.uniform_lamps
                || args.lamp_failures > 0.0
                || args.breach.is_some() =>
        {
            return Err(
                "--cold-lamps, --uniform-lamps, --lamp-failures and --break need a street of lamps: \
                 add --street N or --board"
                    .into(),
            )
        }
        (false, None) => {
            let nodes = args.nodes.unwrap_or(args.serve);
            if nodes < args.serve {
                return Err(format!(
                    "--nodes {nodes} --serve {}: the served nodes are nodes of the line; \
                     give --nodes {} or more",
                    args.serve, args.serve
                ));
            }
            if nodes == args.serve && args.peers.is_some() {
                return Err(format!(
                    "--peers: every node is served ({nodes}), none echoes; \
                     add nodes that do with --nodes {} or more",
                    args.serve + 1
                ));
            }
            sim_server::World::Modems {
                nodes: nodes.into(),
                serve: args.serve.into(),
                peers: match args.peers.unwrap_or(PeerMib::Follow) {
                    PeerMib::Follow => plm_sim::Peers::EchoFollowing,
                    PeerMib::Factory => plm_sim::Peers::Echo,
                },
            }
        }
    };
    Ok(world)
}

fn decode(args: DecodeArgs) -> Result<(), String> {
    let text = if args.hex.is_empty() {
        let mut s = Vec::new();
        io::stdin()
            .take(plm_core::file::FILE_MAX as u64 + 1)
            .read_to_end(&mut s)
            .map_err(|e| format!("cannot read stdin: {e}"))?;
        plm_core::file::text(&s)
            .map_err(|e| format!("cannot read stdin: {e}"))?
            .to_string()
    } else {
        args.hex.join(" ")
    };
    let bytes = plm_core::hex::parse(&text).map_err(|e| format!("input is not hex: {e}"))?;
    let mut out = BufWriter::new(io::stdout().lock());
    let mut print = |line: Result<String, serde_json::Error>| {
        let line = line.map_err(|e| e.to_string())?;
        writeln!(out, "{line}").map_err(|e| format!("cannot write: {e}"))
    };
    let dialect = match args.chip {
        Some(Chip::St7580) if args.line => {
            return Err("--line is for the ST7570's power line frames: add --chip st7570".into())
        }
        Some(Chip::St7570) if args.line => {
            let frame = plm_core::decode::decode_line(&bytes);
            print(serde_json::to_string(&frame))?;
            return out.flush().map_err(|e| format!("cannot write: {e}"));
        }
        Some(Chip::St7580) => Dialect::St7580,
        Some(Chip::St7570) => Dialect::St7570,
        None => {
            for d in plm_core::decode::app::decode_usart(&bytes) {
                print(serde_json::to_string(&d))?;
            }
            return out.flush().map_err(|e| format!("cannot write: {e}"));
        }
    };
    let source = match args.from {
        Some(From::Host) => Source::Host,
        Some(From::Modem) => Source::Modem,
        None => Source::Any,
    };
    let mut decoder = Decoder::new(dialect, source);
    match (dialect, args.mib_index, args.layer) {
        (Dialect::St7570, Some(_), _) => {
            return Err(
                "--mib-index is for the ST7580: an ST7570 CMD_ReadDBConfirm carries its INDEX"
                    .into(),
            )
        }
        (Dialect::St7580, _, Some(_)) => {
            return Err("--layer is for the ST7570: the ST7580 has one frame layout".into())
        }
        (_, Some(i), _) => decoder.assume_mib_read(i),
        (_, _, Some(LayerArg::Phy)) => decoder.fix_layer(Layer::Phy),
        (_, _, Some(LayerArg::Mac)) => decoder.fix_layer(Layer::Mac),
        _ => {}
    }
    decoder.push(&bytes);
    decoder.finish();
    while let Some(d) = decoder.next() {
        print(serde_json::to_string(&d))?;
    }
    out.flush().map_err(|e| format!("cannot write: {e}"))
}
