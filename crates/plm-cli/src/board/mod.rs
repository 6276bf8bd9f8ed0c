//! `plm board`: talk to street-light controller boards (STEVAL-IHP007V1)
//! through a concentrator board's USART or a bare ST7580, on a serial
//! device or an `rfc2217://` port: discover, status, dimming, remote
//! firmware update, simulated images to try it on `plm sim`, and a
//! board's conformance to the board protocol.
//!
//! Everything on the wire is plm-core's ([`plm_core::app`]): the
//! concentrator, discovery, the requester and the update engine. This
//! module only drives them on the wall clock ([`driver`]) and says what
//! happened in words (or JSON lines).

/// `println!` that does not panic when stdout is closed (`| head`).
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

/// `eprintln!` that does not panic when stderr is closed.
macro_rules! tell {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($t)*);
    }};
}

mod conformance;
pub mod driver;
mod info;
mod rfu;

use crate::port;
use clap::{Args, Subcommand, ValueEnum};
use driver::Driver;
use plm_core::app::discovery::DiscoveryConfig;
use plm_core::app::{Address, Concentrator, Release, RequesterConfig};
use plm_core::st7580::TxParams;
use std::path::PathBuf;

/// Exit codes a script can trust (also in `plm board --help` and
/// docs/cli.md).
pub mod exit {
    /// Every board targeted answered (or was updated).
    pub const OK: u8 = 0;
    /// Some board failed, refused, or did not answer (conformance: a
    /// rule failed or could not be checked).
    pub const FAILED: u8 = 1;
    /// The command line is wrong (clap's own code).
    pub const USAGE: u8 = 2;
    /// The port could not be opened, or was lost.
    pub const PORT: u8 = 3;
    /// The image or the state file is bad (nothing was sent).
    pub const INPUT: u8 = 4;
    /// Ctrl-C (an update's state file is kept).
    pub const INTERRUPTED: u8 = 130;
}

/// The exit codes, as `plm board --help` prints them.
pub const EXIT_CODES: &str = "\
Exit codes:
  0    success: every board targeted answered (rfu: every board updated)
  1    some boards failed, refused or did not answer (conformance: a rule failed or was not checked)
  2    usage error (wrong arguments)
  3    the port could not be opened, or was lost
  4    bad image or state file (nothing was sent)
  130  interrupted by Ctrl-C (rfu: the state file is kept, run the same command to resume)";

/// Why `plm board` stops early: the exit code and the words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    /// One of [`exit`].
    pub code: u8,
    /// What went wrong and what to do, in words.
    pub message: String,
}

impl Failure {
    /// The port could not be opened or was lost.
    pub fn port(message: String) -> Failure {
        Failure {
            code: exit::PORT,
            message,
        }
    }

    /// A bad image or state file.
    pub fn input(message: String) -> Failure {
        Failure {
            code: exit::INPUT,
            message,
        }
    }

    /// A wrong command line that clap could not tell.
    pub fn usage(message: String) -> Failure {
        Failure {
            code: exit::USAGE,
            message,
        }
    }

    /// Ctrl-C.
    pub fn interrupted() -> Failure {
        Failure {
            code: exit::INTERRUPTED,
            message: "interrupted".into(),
        }
    }
}

/// What the port is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Via {
    /// A concentrator board's USART (application frames with CRC-16).
    Board,
    /// A bare ST7580 modem: this computer is the concentrator (T_REQ on
    /// RTS).
    Modem,
}

/// `plm board`.
#[derive(Args)]
#[command(after_help = EXIT_CODES)]
pub struct BoardArgs {
    /// The port: rfc2217://HOST:PORT (ser2net, plm sim), or a serial
    /// device (/dev/ttyUSB0, COM3).
    #[arg(long, global = true, value_name = "URL")]
    pub port: Option<String>,
    /// What the port reaches: a concentrator board's USART, or a bare
    /// ST7580 modem whose host this computer is.
    #[arg(long, global = true, value_enum, default_value = "board")]
    pub via: Via,
    /// Baud rate of the port.
    #[arg(long, global = true, default_value_t = 57_600)]
    pub baud: u32,
    /// With --via modem: this concentrator's own 6-byte address on the
    /// line (12 hex digits).
    #[arg(long, global = true, default_value_t = Concentrator::ADDRESS, value_parser = parse_address)]
    pub address: Address,
    /// Print JSON lines on stdout instead of words (discover, status,
    /// dim, rfu's results).
    #[arg(long, global = true)]
    pub json: bool,
    #[command(subcommand)]
    pub command: BoardCommand,
}

/// What to do.
#[derive(Subcommand)]
pub enum BoardCommand {
    /// Find the boards on the line (SERVICE_NET_DISCOVER_REQ in slotted
    /// frames until it is sure nobody is left); one line per board found.
    Discover {
        /// How many boards you expect (half or twice the truth costs a
        /// few frames, never a board).
        #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u16).range(1..=4095))]
        guess: u16,
        /// Also look, after the slotted frames, for boards on the older
        /// discovery rule (rounds and ACKs): about 1.5 s more.
        #[arg(long)]
        older_rule: bool,
    },
    /// Read what a board offers: firmware release, lamp (HID ballast),
    /// clock, GPIO, SNR.
    Status {
        /// The board's address (12 hex digits, e.g. 0080e1000001), or
        /// `all`: discover the street, then read every lamp found.
        #[arg(value_parser = parse_target)]
        node: Target,
        /// With `all`: how many boards you expect.
        #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u16).range(1..=4095))]
        guess: u16,
    },
    /// Set the dimming level of one lamp, or of every lamp at once.
    Dim {
        /// The board's address, or `all` (a broadcast, which has no
        /// answer).
        #[arg(value_parser = parse_target)]
        target: Target,
        /// Dimming level, 0-100 %.
        #[arg(value_parser = clap::value_parser!(u8).range(0..=100))]
        level: u8,
    },
    /// Check one board against the board protocol this project defines
    /// (discovery, RFU; docs/board-protocol.md): each rule passed, failed
    /// or not checked, in words. It never changes what the board runs.
    Conformance {
        /// The board's address (12 hex digits, e.g. 0080e1000001).
        #[arg(value_parser = parse_address)]
        node: Address,
    },
    /// Remote firmware update of boards over the line, resumable.
    Rfu(RfuArgs),
    /// Write a simulated firmware image (what `plm sim`'s boards take),
    /// to try `rfu` without hardware.
    Image(ImageArgs),
}

/// One board, or all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// A broadcast.
    All,
    /// One board.
    One(Address),
}

/// `plm board rfu`.
#[derive(Args)]
pub struct RfuArgs {
    /// The firmware image file (checked before anything is sent).
    pub image: PathBuf,
    /// The boards to update (12 hex digits each), or --all.
    #[arg(value_name = "NODE", value_parser = parse_address, required_unless_present = "all")]
    pub nodes: Vec<Address>,
    /// Discover the boards first, then update every board found.
    #[arg(long, conflicts_with = "nodes")]
    pub all: bool,
    /// Where the campaign is saved after every answer, to resume it
    /// (default: IMAGE.plm-update beside the image).
    #[arg(long, value_name = "FILE")]
    pub state: Option<PathBuf>,
    /// Start a new campaign even if a saved one exists (it is replaced).
    #[arg(long)]
    pub restart: bool,
    /// The release the image reports once it runs, X.Y. A plain .bin (as
    /// ST's toolchain writes it) names none: without this, the update is
    /// judged by the swap, the restart and the board answering. An image
    /// with a descriptor must name the same.
    #[arg(long, value_name = "X.Y", value_parser = parse_release)]
    pub release: Option<Release>,
    /// Milliseconds between two segments broadcast (the line's time for
    /// one; shorter only on a quiet line, or on `plm sim`).
    #[arg(long, default_value_t = 250, value_parser = clap::value_parser!(u64).range(20..=10_000))]
    pub gap_ms: u64,
}

/// `plm board image`.
#[derive(Args)]
pub struct ImageArgs {
    /// The release the image reports once it runs, X.Y, written in a
    /// descriptor; without it, a plain image as ST's toolchain writes one
    /// (a vector table and code, no release).
    #[arg(long = "version", value_name = "X.Y", value_parser = parse_release)]
    pub release: Option<Release>,
    /// Image size in bytes.
    #[arg(long, default_value_t = 24_576, value_parser = clap::value_parser!(u32).range(
        plm_core::app::rfu::image::IMAGE_MIN as i64..=plm_core::app::rfu::IMAGE_MAX as i64))]
    pub size: u32,
    /// The file to write.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: PathBuf,
}

fn parse_address(s: &str) -> Result<Address, String> {
    Address::parse(s).map_err(|e| format!("'{s}': {e}"))
}

fn parse_target(s: &str) -> Result<Target, String> {
    if s.eq_ignore_ascii_case("all") {
        Ok(Target::All)
    } else {
        parse_address(s).map(Target::One)
    }
}

fn parse_release(s: &str) -> Result<Release, String> {
    Release::parse(s)
}

/// Runs `plm board`; returns the exit code (errors already printed).
pub fn run(args: BoardArgs) -> u8 {
    match dispatch(args) {
        Ok(code) => code,
        Err(f) => {
            tell!("plm board: {}", f.message);
            f.code
        }
    }
}

fn dispatch(args: BoardArgs) -> Result<u8, Failure> {
    match &args.command {
        BoardCommand::Discover { guess, older_rule } => {
            let mut d = connect(&args)?;
            let config = DiscoveryConfig::new(session(), *guess as usize);
            info::discover(&mut d, config, *older_rule, args.json)
        }
        BoardCommand::Status { node, guess } => {
            let mut d = connect(&args)?;
            match node {
                Target::One(node) => info::status(&mut d, *node, args.json),
                Target::All => {
                    let config = DiscoveryConfig::new(session(), *guess as usize);
                    info::status_all(&mut d, config, args.json)
                }
            }
        }
        BoardCommand::Dim { target, level } => {
            let mut d = connect(&args)?;
            info::dim(&mut d, *target, *level, args.json)
        }
        BoardCommand::Conformance { node } => {
            let mut d = connect(&args)?;
            conformance::run(&mut d, *node, args.json)
        }
        BoardCommand::Rfu(r) => rfu::run(&args, r),
        BoardCommand::Image(a) => rfu::write_image(a),
    }
}

/// Opens the port and puts a concentrator of the kind `--via` says on it.
fn connect(args: &BoardArgs) -> Result<Driver, Failure> {
    let Some(url) = args.port.as_deref() else {
        return Err(Failure::usage(
            "which port? add --port rfc2217://HOST:PORT or --port /dev/ttyUSB0 (COM3 on Windows)"
                .into(),
        ));
    };
    // Ctrl-C stops at the driver's next turn (an update saves its state
    // first).
    ctrlc::set_handler(|| driver::INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst))
        .map_err(|e| Failure {
            code: exit::FAILED,
            message: format!("cannot catch Ctrl-C: {e}"),
        })?;
    let mut port = port::open(url, args.baud).map_err(Failure::port)?;
    if args.via == Via::Modem {
        // T_REQ is RTS: a port without it cannot drive a bare modem.
        port.set_rts(false)
            .map_err(|e| Failure::port(format!("cannot use {url} with --via modem: {e}")))?;
    }
    let config = RequesterConfig::default();
    let conc = match args.via {
        Via::Board => Concentrator::usart(config),
        Via::Modem => Concentrator::modem(config, args.baud, args.address, TxParams::default()),
    };
    Ok(Driver::new(port, conc, url))
}

/// A discovery session number for this run: a board acknowledged in a
/// session stays quiet for the rest of it, so two runs must not share
/// one (the clock's nanoseconds and the process id, 1-255).
fn session() -> u8 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    ((nanos ^ std::process::id()) % 255) as u8 + 1
}
