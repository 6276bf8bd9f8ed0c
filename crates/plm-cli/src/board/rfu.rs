//! `plm board rfu` and `plm board image`: a remote firmware update
//! campaign run by plm-core's engine ([`Update`]), saved after every
//! answer so that it survives Ctrl-C, a lost port or a crash; and the
//! simulated images to try it on `plm sim`.

use super::driver::Driver;
use super::{connect, exit, session, BoardArgs, Failure, ImageArgs, RfuArgs};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use plm_core::app::discovery::DiscoveryConfig;
use plm_core::app::rfu::{self, image};
use plm_core::app::update::{BoardState, Update, UpdateConfig};
use plm_core::app::{Address, Happening, Run};
use plm_core::time::MS;
use serde_json::json;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The state file beside `image` unless `--state` names one.
fn state_path(args: &RfuArgs) -> PathBuf {
    args.state.clone().unwrap_or_else(|| {
        let mut s = args.image.as_os_str().to_owned();
        s.push(".plm-update");
        PathBuf::from(s)
    })
}

/// Writes `bytes` to `path` so that a crash leaves the old file or the
/// new one, never half of one: a temporary file beside it, synced, then
/// renamed over it.
fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
    }
    std::fs::rename(&tmp, path)
}

/// `plm board image`.
pub fn write_image(args: &ImageArgs) -> Result<u8, Failure> {
    let size = args.size as usize;
    let bytes = match args.release {
        Some(release) => plm_sim::rfu::firmware_image(release, size),
        None => plm_sim::rfu::plain_image(0, size),
    };
    let info = image::check(&bytes)
        .map_err(|why| Failure::input(format!("the image made is not good: {why} (a bug)")))?;
    std::fs::write(&args.output, &bytes)
        .map_err(|e| Failure::input(format!("cannot write {}: {e}", args.output.display())))?;
    say!(
        "{}: simulated firmware image, {}, {} bytes, CRC-32 {:08X} (campaign {})",
        args.output.display(),
        info.release_words(),
        info.size,
        info.crc,
        info.campaign()
    );
    Ok(exit::OK)
}

/// Where the campaign is kept between runs.
struct State {
    path: PathBuf,
}

impl State {
    fn save(&self, u: &Update) -> Result<(), Failure> {
        write_atomically(&self.path, &u.save()).map_err(|e| {
            Failure::input(format!(
                "cannot save the update's state to {}: {e} (choose another place with --state)",
                self.path.display()
            ))
        })
    }
}

/// The bytes of a file, refused (as an `InvalidData` error, in words)
/// past [`plm_core::file::FILE_MAX`] without reading more than one byte
/// beyond it: a device or a huge file named by mistake costs nothing.
fn read_capped(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let cap = plm_core::file::FILE_MAX as u64;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(cap + 1)
        .read_to_end(&mut bytes)?;
    plm_core::file::check_size(bytes.len() as u64)
        .map_err(|why| std::io::Error::new(std::io::ErrorKind::InvalidData, why))?;
    Ok(bytes)
}

/// `plm board rfu`.
pub fn run(args: &BoardArgs, r: &RfuArgs) -> Result<u8, Failure> {
    let name = r.image.display().to_string();
    let bytes = read_capped(&r.image)
        .map_err(|e| Failure::input(format!("cannot read the image {name}: {e}")))?;
    let info = image::check(&bytes)
        .and_then(|i| i.stating(r.release))
        .map_err(|why| {
            Failure::input(format!(
                "{name} is not an image the boards take: {why}. Nothing was sent."
            ))
        })?;
    if info.release.is_none() {
        tell!(
            "plm board: {name} states no release (a plain .bin names none; give one with \
             --release X.Y): each board is judged by its swap, its restart and its answer, \
             and the release it reports is shown"
        );
    }
    let state = State {
        path: state_path(r),
    };
    let shown = state.path.display().to_string();

    // A saved campaign is checked before the port is opened.
    let saved = match (r.restart, read_capped(&state.path)) {
        (true, _) => None,
        (false, Ok(saved)) => Some(saved),
        (false, Err(e)) if e.kind() == std::io::ErrorKind::NotFound => None,
        (false, Err(e)) => {
            return Err(Failure::input(format!(
                "cannot read the state file {shown}: {e}"
            )))
        }
    };
    if let Some(saved) = &saved {
        let u = Update::resume(bytes.clone(), saved, 0).map_err(|why| {
            Failure::input(format!(
                "the saved update in {shown} cannot go on with {name}: {why}. \
                 Remove {shown}, or pass --restart to start a new update. Nothing was sent."
            ))
        })?;
        let mut was: Vec<Address> = u.boards().map(|(a, _)| a).collect();
        let mut now: Vec<Address> = r.nodes.clone();
        was.sort();
        now.sort();
        now.dedup();
        if !r.all && was != now {
            let list = |v: &[Address]| {
                v.iter()
                    .map(|a| a.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            return Err(Failure::input(format!(
                "the saved update in {shown} is for the boards {}, not {}: name the same boards \
                 to resume it, or pass --restart to start a new update for these. Nothing was sent.",
                list(&was),
                list(&now)
            )));
        }
    }

    let mut d = connect(args)?;
    let mut u = match saved {
        Some(saved) => {
            tell!("plm board: resuming the update saved in {shown}");
            Update::resume(bytes, &saved, d.now()).map_err(Failure::input)?
        }
        None => {
            let targets = if r.all {
                find_boards(&mut d)?
            } else {
                let mut t: Vec<Address> = Vec::new();
                for a in &r.nodes {
                    if !t.contains(a) {
                        t.push(*a);
                    }
                }
                t
            };
            if targets.is_empty() {
                tell!("plm board: no board answered the discovery: nothing to update");
                return Ok(exit::FAILED);
            }
            let config = UpdateConfig {
                gap: r.gap_ms * MS,
                ..UpdateConfig::default()
            };
            Update::new(info.campaign(), info.release, bytes, &targets, config)
                .map_err(|why| Failure::input(format!("cannot update: {why}")))?
        }
    };
    let h = u.header();
    tell!(
        "plm board: campaign {}: {name}, {}, {} bytes ({} segments), CRC-32 {:08X}, \
         to {} board{}; progress saved in {shown}",
        h.campaign,
        rfu::release_words(h.release()),
        h.size,
        h.segments(),
        h.crc,
        u.boards().count(),
        if u.boards().count() == 1 { "" } else { "s" }
    );
    state.save(&u)?;

    let mut progress = Progress::new(&u);
    let outcome = drive(&mut d, &mut u, &state, &mut progress);
    progress.finish();
    match outcome {
        Ok(()) => {}
        Err(f) => {
            // The state as it is now: a request under way is asked again
            // on resume (every RFU request may be repeated).
            let kept = state.save(&u).is_ok();
            let how = if kept {
                format!(
                    "the update is saved in {shown}: run the same command again to resume it \
                     (or pass --restart to start over)"
                )
            } else {
                format!("the state could not be saved to {shown}")
            };
            let what = if f.code == exit::INTERRUPTED {
                "interrupted".to_string()
            } else {
                f.message
            };
            return Err(Failure {
                code: f.code,
                message: format!("{what}; {how}"),
            });
        }
    }

    let report = u.report();
    let updated = u
        .boards()
        .filter(|(_, s)| matches!(s, BoardState::Done))
        .count();
    for ((address, words), (_, s)) in report.iter().zip(u.boards()) {
        if args.json {
            say!(
                "{}",
                json!({
                    "address": address.to_string(),
                    "updated": matches!(s, BoardState::Done),
                    "result": words,
                })
            );
        } else {
            say!("{address}  {words}");
        }
    }
    if let Err(e) = std::fs::remove_file(&state.path) {
        tell!("plm board: the update is over but its state file {shown} could not be removed: {e}");
    }
    tell!(
        "plm board: {updated} of {} board{} updated ({})",
        report.len(),
        if report.len() == 1 { "" } else { "s" },
        rfu::release_words(h.release())
    );
    Ok(if updated == report.len() {
        exit::OK
    } else {
        exit::FAILED
    })
}

/// `--all`: the boards a discovery finds.
fn find_boards(d: &mut Driver) -> Result<Vec<Address>, Failure> {
    tell!("plm board: discovering the boards to update");
    let found = d.discover(DiscoveryConfig::new(session(), 12), false, |a, info| {
        tell!("plm board: found {a} (firmware {})", info.firmware);
    })?;
    Ok(found.found().iter().map(|(a, _)| *a).collect())
}

/// Runs the campaign to its end: each request the engine hands out goes
/// through the concentrator, its answer (or failure) back to the engine,
/// and the campaign is saved after each.
fn drive(
    d: &mut Driver,
    u: &mut Update,
    state: &State,
    progress: &mut Progress,
) -> Result<(), Failure> {
    d.run(&mut Run::new(u), |run, now, happenings| {
        // Every request is the campaign's: saved after each fate.
        let fate = happenings
            .iter()
            .any(|h| matches!(h, Happening::App(e) if e.fate_of().is_some()));
        if fate {
            state.save(run.job())?;
        }
        progress.show(run.job(), now);
        Ok(())
    })
}

/// Progress on stderr: one line refreshed in place on a terminal, a
/// plain line every few seconds otherwise.
struct Progress {
    bar: Option<ProgressBar>,
    started: Instant,
    /// Bytes the engine had sent when this run started (a resumed
    /// campaign counts its earlier runs).
    sent_before: u64,
    last_line: Instant,
}

/// Between two plain progress lines.
const PLAIN_EVERY: Duration = Duration::from_secs(5);

impl Progress {
    fn new(u: &Update) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template("[{bar:30}] {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> ");
            bar.set_style(style);
            bar
        });
        Progress {
            bar,
            started: Instant::now(),
            sent_before: u.bytes_sent(),
            last_line: Instant::now(),
        }
    }

    fn show(&mut self, u: &Update, now: plm_core::time::Instant) {
        let (line, permille) = self.line(u, now);
        match &self.bar {
            Some(bar) => {
                bar.set_position(permille);
                bar.set_message(line);
            }
            None if self.last_line.elapsed() >= PLAIN_EVERY => {
                self.last_line = Instant::now();
                tell!("plm board: {line}");
            }
            None => {}
        }
    }

    /// The words, and the average of the boards' progress in permille.
    fn line(&self, u: &Update, now: plm_core::time::Instant) -> (String, u64) {
        let total = u.boards().count();
        let (mut done, mut failed) = (0, 0);
        for (_, s) in u.boards() {
            match s {
                BoardState::Done => done += 1,
                BoardState::Failed(_) | BoardState::Aborted => failed += 1,
                _ => {}
            }
        }
        let permille = (0..total).map(|i| u.permille(i) as u64).sum::<u64>() / total.max(1) as u64;
        let secs = self.started.elapsed().as_secs_f64().max(0.001);
        let rate = (u.bytes_sent() - self.sent_before.min(u.bytes_sent())) as f64 / secs;
        let left = u.time_left(now) / 1_000_000;
        (
            format!(
                "{}.{} % · {done}/{total} boards updated, {failed} failed · {rate:.0} B/s · about {} left",
                permille / 10,
                permille % 10,
                duration_words(left)
            ),
            permille,
        )
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// `1 min 05 s`, `42 s`.
fn duration_words(secs: u64) -> String {
    match secs {
        s if s >= 3600 => format!("{} h {:02} min", s / 3600, s / 60 % 60),
        s if s >= 60 => format!("{} min {:02} s", s / 60, s % 60),
        s => format!("{s} s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_in_words() {
        assert_eq!(duration_words(42), "42 s");
        assert_eq!(duration_words(65), "1 min 05 s");
        assert_eq!(duration_words(3_725), "1 h 02 min");
    }

    #[test]
    fn a_file_past_the_cap_is_refused_unread() {
        let dir = std::env::temp_dir().join(format!("plm-cap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("big.bin");
        let f = std::fs::File::create(&path).unwrap();
        f.set_len(plm_core::file::FILE_MAX as u64 * 4).unwrap();
        let e = read_capped(&path).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
        assert!(
            e.to_string()
                .contains("larger than 16777216 bytes (16 MiB)"),
            "{e}"
        );
        std::fs::write(&path, b"small").unwrap();
        assert_eq!(read_capped(&path).unwrap(), b"small");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_state_file_is_replaced_whole() {
        let dir = std::env::temp_dir().join(format!("plm-rfu-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.plm-update");
        write_atomically(&path, b"first").unwrap();
        write_atomically(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 1, "no temporary file left");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
