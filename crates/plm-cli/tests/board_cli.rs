//! `plm board` end to end: the real binary, as a child process, against
//! the real `plm sim` serving a street of 3 lamps behind a concentrator
//! board's USART (or a bare ST7580) over RFC 2217. Simulated time runs at
//! wall-clock speed, so images are small (3-4 KB: 32-42 segments at the
//! engine's default 250 ms) and each test file's servers run side by
//! side.
//!
//! Every check is on what the tool prints and its exit code, and on what
//! the simulated boards then answer (a status after an update shows the
//! new release).

mod common;

use common::Server;
use plm_core::app::update::{Update, UpdateConfig};
use plm_core::app::Release;
use plm_sim::board::street_address;
use serde_json::Value;
use std::fs::File;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The longest any one `plm board` run may take here (an update of two
/// boards takes about 20 s).
const LIMIT: Duration = Duration::from_secs(90);

/// A scratch directory of its own for each test.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("plm-board-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    fn text(&self, name: &str) -> String {
        self.path(name).to_str().unwrap().to_string()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A `plm` run whose stdout and stderr go to files (they can be read
/// after the run was killed).
struct Run {
    child: Child,
    out: PathBuf,
    err: PathBuf,
    args: Vec<String>,
}

/// What a finished run left.
#[derive(Debug)]
struct Done {
    code: Option<i32>,
    out: String,
    err: String,
}

impl Run {
    fn start<S: AsRef<str>>(dir: &Scratch, tag: &str, args: &[S]) -> Run {
        let args: Vec<String> = args.iter().map(|s| s.as_ref().to_string()).collect();
        let out = dir.path(&format!("{tag}.out"));
        let err = dir.path(&format!("{tag}.err"));
        let child = Command::new(env!("CARGO_BIN_EXE_plm"))
            .args(&args)
            .stdin(Stdio::null())
            .stdout(File::create(&out).unwrap())
            .stderr(File::create(&err).unwrap())
            .spawn()
            .expect("plm runs");
        Run {
            child,
            out,
            err,
            args,
        }
    }

    fn output(&self, code: Option<i32>) -> Done {
        Done {
            code,
            out: std::fs::read_to_string(&self.out).unwrap(),
            err: std::fs::read_to_string(&self.err).unwrap(),
        }
    }

    /// Waits for the end (at most [`LIMIT`]).
    fn wait(mut self) -> Done {
        let deadline = Instant::now() + LIMIT;
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return self.output(status.code());
            }
            if Instant::now() > deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                panic!(
                    "plm {:?} still running after {LIMIT:?}: {:?}",
                    self.args,
                    self.output(None)
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Ctrl-C, then waits for the end.
    fn interrupt(self) -> Done {
        let sent = Command::new("kill")
            .args(["-INT", &self.child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success(), "kill -INT");
        self.wait()
    }

    /// SIGKILL: no chance to save or say anything.
    fn kill(mut self) -> Done {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
        self.output(None)
    }
}

/// `plm <args>` to its end.
fn plm<S: AsRef<str>>(dir: &Scratch, tag: &str, args: &[S]) -> Done {
    Run::start(dir, tag, args).wait()
}

/// `plm board --port rfc2217://ADDR <args>` to its end; then waits for
/// the server to see it go (it serves one client at a time).
fn board(server: &mut Server, dir: &Scratch, tag: &str, args: &[&str]) -> Done {
    let done = plm(dir, tag, &board_args(server, args));
    server.line_containing("disconnected");
    done
}

fn board_args(server: &Server, args: &[&str]) -> Vec<String> {
    let mut v = vec![
        "board".to_string(),
        "--port".into(),
        format!("rfc2217://{}", server.addr),
    ];
    v.extend(args.iter().map(|s| s.to_string()));
    v
}

fn street(lamps: &str) -> Server {
    Server::start(&["--board", "--street", lamps, "--listen", "127.0.0.1:0"])
}

fn json_lines(text: &str) -> Vec<Value> {
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON ({e}): {l}")))
        .collect()
}

fn lamp(i: usize) -> String {
    street_address(i).to_string()
}

/// A lamp's power as `status --json` reads it.
fn power(server: &mut Server, dir: &Scratch, tag: &str, node: &str) -> u64 {
    let s = board(server, dir, tag, &["--json", "status", node]);
    assert_eq!(s.code, Some(0), "{s:?}");
    let v = &json_lines(&s.out)[0];
    v["lamp"]["power_w"]
        .as_u64()
        .unwrap_or_else(|| panic!("no power in {v}"))
}

/// Discovery finds the three lamps and what they say; a status reads a
/// lamp in words and in JSON; dimming one lamp and then all of them
/// moves the lamps' power; a board that is not there is reported with
/// exit code 1.
#[test]
fn discover_status_and_dim_a_street() {
    let mut server = street("3");
    let dir = Scratch::new("street");

    let found = board(&mut server, &dir, "discover", &["discover", "--json"]);
    assert_eq!(found.code, Some(0), "{found:?}");
    let mut lamps: Vec<(String, String)> = json_lines(&found.out)
        .iter()
        .map(|v| {
            assert_eq!(v["stack"], "2.0", "{v}");
            assert!(v["snr_db"].as_u64().is_some(), "{v}");
            (
                v["address"].as_str().unwrap().to_string(),
                v["firmware"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    lamps.sort();
    let want: Vec<(String, String)> = (1..=3).map(|i| (lamp(i), "1.4".into())).collect();
    assert_eq!(lamps, want, "{found:?}");
    assert!(found.err.contains("3 boards found"), "{}", found.err);

    // With a round of the older rule after it: every board, each once.
    let older = board(
        &mut server,
        &dir,
        "older",
        &["discover", "--older-rule", "--json"],
    );
    assert_eq!(older.code, Some(0), "{older:?}");
    assert_eq!(json_lines(&older.out).len(), 3, "{older:?}");

    // `status all`: the street found again and every lamp read, one
    // JSON object each.
    let all = board(
        &mut server,
        &dir,
        "status-all",
        &["status", "all", "--json", "--guess", "3"],
    );
    assert_eq!(all.code, Some(0), "{all:?}");
    let mut read: Vec<String> = json_lines(&all.out)
        .iter()
        .map(|v| {
            assert_eq!(v["state"], "RUN", "{v}");
            assert!(v["lamp_power_w"].as_u64().is_some_and(|w| w > 0), "{v}");
            v["address"].as_str().unwrap().to_string()
        })
        .collect();
    read.sort();
    assert_eq!(read, (1..=3).map(lamp).collect::<Vec<_>>(), "{all:?}");
    assert!(all.err.contains("3 lamp(s) read, 0 silent"), "{}", all.err);
    // Read in slots (docs/protocol-notes.md, "Reads in slots"), not one
    // by one.
    assert!(all.err.contains("reading them in slots"), "{}", all.err);
    assert!(all.err.contains("3 heard in their slot"), "{}", all.err);

    let s = board(&mut server, &dir, "status", &["status", &lamp(2)]);
    assert_eq!(s.code, Some(0), "{s:?}");
    assert!(
        s.out.starts_with(&format!("board {}", lamp(2))),
        "{}",
        s.out
    );
    for words in [
        "firmware     1.4 (stack 2.0)",
        "lamp         RUN",
        "clock",
        "SNR",
    ] {
        assert!(s.out.contains(words), "no {words:?} in\n{}", s.out);
    }

    let full = power(&mut server, &dir, "full", &lamp(2));
    let dim = board(&mut server, &dir, "dim40", &["dim", &lamp(2), "40"]);
    assert_eq!(dim.code, Some(0), "{dim:?}");
    assert!(dim.out.contains("dimmed to 40 %"), "{}", dim.out);
    let at40 = power(&mut server, &dir, "at40", &lamp(2));
    assert!(
        0 < at40 && at40 < full,
        "{at40} W at 40 %, {full} W at 100 %"
    );

    let all = board(&mut server, &dir, "dimall", &["dim", "all", "70"]);
    assert_eq!(all.code, Some(0), "{all:?}");
    assert!(all.out.contains("every board"), "{}", all.out);
    let at70 = power(&mut server, &dir, "at70", &lamp(2));
    assert!(at40 < at70 && at70 < full, "{at70} W at 70 %");
    let other = power(&mut server, &dir, "other", &lamp(3));
    assert!(other < full, "lamp 3 follows the broadcast: {other} W");

    // Nobody at node 9: the requester's three attempts, then exit 1.
    let gone = board(&mut server, &dir, "gone", &["status", &lamp(9)]);
    assert_eq!(gone.code, Some(1), "{gone:?}");
    assert!(gone.err.contains("did not answer"), "{}", gone.err);
    server.interrupt();
}

/// `plm board image` makes a 1.5 image; `rfu` refuses a truncated copy
/// and a state file of another image before connecting (exit 4), then
/// updates lamp 1 with the good one (exit 0), removes its state file,
/// and lamp 1 reports release 1.5. A port nobody serves is exit 3;
/// usage errors are exit 2.
#[test]
fn rfu_updates_one_board_and_refuses_bad_input() {
    let mut server = street("3");
    let dir = Scratch::new("rfu");
    let image = dir.text("fw15.bin");

    let made = plm(
        &dir,
        "image",
        &[
            "board",
            "image",
            "--version",
            "1.5",
            "--size",
            "3000",
            "-o",
            &image,
        ],
    );
    assert_eq!(made.code, Some(0), "{made:?}");
    assert!(made.out.contains("release 1.5, 3000 bytes"), "{}", made.out);
    let bytes = std::fs::read(&image).unwrap();
    assert_eq!(bytes.len(), 3000);

    // A truncated image: refused in words, nothing sent (no connection).
    let cut = dir.text("cut.bin");
    std::fs::write(&cut, &bytes[..2000]).unwrap();
    let refused = plm(&dir, "cut", &board_args(&server, &["rfu", &cut, &lamp(1)]));
    assert_eq!(refused.code, Some(4), "{refused:?}");
    assert!(refused.err.contains("truncated"), "{}", refused.err);
    assert!(refused.err.contains("Nothing was sent"), "{}", refused.err);
    assert!(!dir.path("cut.bin.plm-update").exists());

    // A state file left by an update of another image: refused.
    let state = dir.path("fw15.bin.plm-update");
    let other = plm_sim::rfu::firmware_image(Release { major: 1, minor: 6 }, 3000);
    let saved = Update::new(
        7,
        Release { major: 1, minor: 6 },
        other,
        &[street_address(1)],
        UpdateConfig::default(),
    )
    .unwrap()
    .save();
    std::fs::write(&state, &saved).unwrap();
    let stale = plm(
        &dir,
        "stale",
        &board_args(&server, &["rfu", &image, &lamp(1)]),
    );
    assert_eq!(stale.code, Some(4), "{stale:?}");
    assert!(stale.err.contains("not the one"), "{}", stale.err);
    assert!(stale.err.contains("--restart"), "{}", stale.err);
    std::thread::sleep(Duration::from_millis(200));
    let lines = server.lines_so_far();
    assert!(
        !lines.iter().any(|l| l.contains("connected")),
        "the port was opened: {lines:?}"
    );
    assert_eq!(std::fs::read(&state).unwrap(), saved, "left as it was");
    std::fs::remove_file(&state).unwrap();

    // The update.
    let rfu = board(&mut server, &dir, "rfu", &["rfu", &image, &lamp(1)]);
    assert_eq!(rfu.code, Some(0), "{rfu:?}");
    assert!(
        rfu.out.contains(&format!("{}  updated to 1.5", lamp(1))),
        "{}",
        rfu.out
    );
    assert!(rfu.err.contains("campaign "), "{}", rfu.err);
    assert!(
        !state.exists(),
        "the state file is removed once the update is over"
    );
    let s = board(&mut server, &dir, "status", &["status", &lamp(1)]);
    assert_eq!(s.code, Some(0), "{s:?}");
    assert!(s.out.contains("firmware     1.5"), "{}", s.out);

    // A port nobody serves.
    let closed = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let url = format!("rfc2217://{}", closed.local_addr().unwrap());
    drop(closed);
    let nobody = plm(
        &dir,
        "nobody",
        &["board", "--port", &url, "status", &lamp(1)],
    );
    assert_eq!(nobody.code, Some(3), "{nobody:?}");
    assert!(nobody.err.contains("cannot open"), "{}", nobody.err);

    // Usage errors.
    let no_port = plm(&dir, "noport", &["board", "status", &lamp(1)]);
    assert_eq!(no_port.code, Some(2), "{no_port:?}");
    assert!(no_port.err.contains("--port"), "{}", no_port.err);
    let bad = plm(&dir, "bad", &board_args(&server, &["dim", &lamp(1), "101"]));
    assert_eq!(bad.code, Some(2), "{bad:?}");
    server.interrupt();
}

/// A plain `.bin` as ST's toolchain writes it (UM 4.3: a vector table
/// and code, no descriptor, no release): `plm board image` without
/// `--version` writes one; `rfu` refuses, in words and before connecting,
/// one linked at 0800_0000h and one that is no STM32 application; then
/// updates lamp 1 with the plain image and `--release 2.0` (lamp 1
/// reports 2.0) and lamp 2 with none (judged by its restart and answer,
/// the release it reports shown).
#[test]
fn rfu_takes_a_plain_bin() {
    let mut server = street("2");
    let dir = Scratch::new("plain");
    let image = dir.text("PLM_HID_STANDALONE.bin");
    let made = plm(
        &dir,
        "image",
        &["board", "image", "--size", "3000", "-o", &image],
    );
    assert_eq!(made.code, Some(0), "{made:?}");
    assert!(made.out.contains("release not stated"), "{}", made.out);
    let bytes = std::fs::read(&image).unwrap();
    assert_eq!(plm_core::app::rfu::image::release_of(&bytes), None);

    // Built without the bootloader: every vector 4 KiB lower.
    let mut at_base = bytes.clone();
    for at in (4..plm_core::app::rfu::image::VECTORS).step_by(4) {
        let v = u32::from_le_bytes(at_base[at..at + 4].try_into().unwrap());
        if v != 0 {
            at_base[at..at + 4].copy_from_slice(&(v - 0x1000).to_le_bytes());
        }
    }
    let low = dir.text("low.bin");
    std::fs::write(&low, &at_base).unwrap();
    let refused = plm(&dir, "low", &board_args(&server, &["rfu", &low, &lamp(1)]));
    assert_eq!(refused.code, Some(4), "{refused:?}");
    assert!(
        refused.err.contains("built without the bootloader"),
        "{}",
        refused.err
    );
    assert!(refused.err.contains("Nothing was sent"), "{}", refused.err);
    // Not an application at all (text).
    let text = dir.text("notes.bin");
    std::fs::write(&text, "release notes for 2.0\n".repeat(40)).unwrap();
    let refused = plm(
        &dir,
        "text",
        &board_args(&server, &["rfu", &text, &lamp(1)]),
    );
    assert_eq!(refused.code, Some(4), "{refused:?}");
    assert!(
        refused.err.contains("not an STM32F103 application image"),
        "{}",
        refused.err
    );
    std::thread::sleep(Duration::from_millis(200));
    let lines = server.lines_so_far();
    assert!(
        !lines.iter().any(|l| l.contains("connected")),
        "the port was opened: {lines:?}"
    );

    let stated = board(
        &mut server,
        &dir,
        "stated",
        &[
            "rfu",
            &image,
            &lamp(1),
            "--release",
            "2.0",
            "--gap-ms",
            "40",
        ],
    );
    assert_eq!(stated.code, Some(0), "{stated:?}");
    assert!(
        stated.out.contains(&format!("{}  updated to 2.0", lamp(1))),
        "{}",
        stated.out
    );
    let s = board(&mut server, &dir, "status1", &["status", &lamp(1)]);
    assert!(s.out.contains("firmware     2.0"), "{}", s.out);

    let unstated = board(
        &mut server,
        &dir,
        "unstated",
        &["rfu", &image, &lamp(2), "--gap-ms", "40"],
    );
    assert_eq!(unstated.code, Some(0), "{unstated:?}");
    assert!(
        unstated.err.contains("states no release"),
        "{}",
        unstated.err
    );
    assert!(
        unstated.out.contains(&format!(
            "{}  updated: it restarted and answers, reporting release 0.0",
            lamp(2)
        )),
        "{}",
        unstated.out
    );
    server.interrupt();
}

/// An update of two lamps stopped by Ctrl-C (exit 130, state kept, how
/// to resume said), resumed and killed outright, then resumed again:
/// it finishes (exit 0) with both lamps on 1.5.
#[test]
fn an_interrupted_update_resumes() {
    let mut server = street("3");
    let dir = Scratch::new("resume");
    let image = dir.text("fw.bin");
    let made = plm(
        &dir,
        "image",
        &[
            "board",
            "image",
            "--version",
            "1.5",
            "--size",
            "4000",
            "-o",
            &image,
        ],
    );
    assert_eq!(made.code, Some(0), "{made:?}");
    let state = dir.path("fw.bin.plm-update");
    let (l2, l3) = (lamp(2), lamp(3));
    let args = ["rfu", image.as_str(), &l2, &l3];
    let wait_for_state = || {
        let deadline = Instant::now() + Duration::from_secs(20);
        while !state.exists() {
            assert!(Instant::now() < deadline, "no state file {state:?}");
            std::thread::sleep(Duration::from_millis(50));
        }
    };

    let first = Run::start(&dir, "first", &board_args(&server, &args));
    wait_for_state();
    std::thread::sleep(Duration::from_secs(3));
    let first = first.interrupt();
    server.line_containing("disconnected");
    assert_eq!(first.code, Some(130), "{first:?}");
    assert!(
        first.err.contains("run the same command again"),
        "{}",
        first.err
    );
    assert!(state.exists(), "kept on Ctrl-C");

    let second = Run::start(&dir, "second", &board_args(&server, &args));
    std::thread::sleep(Duration::from_secs(3));
    let second = second.kill();
    server.line_containing("disconnected");
    assert!(
        second.err.contains("resuming the update saved in"),
        "{second:?}"
    );
    // Whatever moment the kill came at, the file is a whole save.
    let saved = std::fs::read(&state).expect("kept after a kill");
    let bytes = std::fs::read(&image).unwrap();
    Update::resume(bytes, &saved, 0).expect("a whole save");

    let third = board(&mut server, &dir, "third", &args);
    assert_eq!(third.code, Some(0), "{third:?}");
    assert!(
        third.err.contains("resuming the update saved in"),
        "{}",
        third.err
    );
    for i in [2, 3] {
        assert!(
            third.out.contains(&format!("{}  updated to 1.5", lamp(i))),
            "{}",
            third.out
        );
    }
    assert!(!state.exists(), "removed once over");
    let s = board(&mut server, &dir, "status", &["status", &lamp(3)]);
    assert!(s.out.contains("firmware     1.5"), "{s:?}");
    server.interrupt();
}

/// `--via modem`: the port is a bare ST7580 and `plm board` is the
/// concentrator (T_REQ on RTS): a lamp's status and a dimming cross the
/// line.
#[test]
fn a_bare_modem_as_the_concentrator() {
    let mut server = Server::start(&[
        "--chip",
        "st7580",
        "--street",
        "2",
        "--listen",
        "127.0.0.1:0",
    ]);
    let dir = Scratch::new("modem");
    let s = board(
        &mut server,
        &dir,
        "status",
        &["--via", "modem", "status", &lamp(1)],
    );
    assert_eq!(s.code, Some(0), "{s:?}");
    assert!(s.out.contains("firmware     1.4"), "{}", s.out);
    let d = board(
        &mut server,
        &dir,
        "dim",
        &["--via", "modem", "dim", &lamp(2), "30"],
    );
    assert_eq!(d.code, Some(0), "{d:?}");
    server.interrupt();
}

/// A serial device: a pseudo-terminal whose other end the test bridges to
/// `plm sim`'s concentrator board (its RFC 2217 data, IAC undone both
/// ways). `plm board` opens `/dev/pts/N` with the `serialport` crate,
/// 8N1, and reads a lamp and dims one; a pseudo-terminal has no RTS, so
/// `--via modem` is refused with exit 3.
#[cfg(unix)]
#[test]
fn a_serial_device() {
    use plm_cli::rfc2217::client::Client;
    use serialport::SerialPort;
    use std::io::{Read, Write};
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    let mut server = street("2");
    let dir = Scratch::new("serial");
    let (mut master, slave) = serialport::TTYPort::pair().expect("a pseudo-terminal");
    let device = slave.name().expect("the pseudo-terminal's name");
    // `plm board` opens it by its name; the test keeps only the master.
    drop(slave);
    master.set_timeout(Duration::from_millis(5)).unwrap();
    let mut link = Client::connect(&server.addr).unwrap();
    server.line_containing("connected");
    let stop = Arc::new(AtomicBool::new(false));
    let bridge = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 512];
            while !stop.load(Ordering::SeqCst) {
                match master.read(&mut buf) {
                    Ok(n) if n > 0 => link.send_data(&buf[..n]).unwrap(),
                    // No reader on the other side yet (EIO), or nothing.
                    Ok(_) | Err(_) => {}
                }
                link.pump(Duration::from_millis(2)).unwrap();
                link.telnet.clear();
                let data = link.take_data();
                if !data.is_empty() {
                    // Lost if nobody has the device open: as on a wire.
                    let _ = master.write_all(&data);
                }
            }
        })
    };

    let s = plm(
        &dir,
        "status",
        &["board", "--port", &device, "status", &lamp(1)],
    );
    assert_eq!(s.code, Some(0), "{s:?}");
    assert!(s.out.contains("firmware     1.4"), "{}", s.out);
    let d = plm(
        &dir,
        "dim",
        &["board", "--port", &device, "dim", &lamp(2), "30"],
    );
    assert_eq!(d.code, Some(0), "{d:?}");
    assert!(d.out.contains("dimmed to 30 %"), "{}", d.out);
    let m = plm(
        &dir,
        "modem",
        &[
            "board",
            "--port",
            &device,
            "--via",
            "modem",
            "status",
            &lamp(1),
        ],
    );
    assert_eq!(m.code, Some(3), "{m:?}");
    assert!(m.err.contains("RTS"), "{}", m.err);

    stop.store(true, Ordering::SeqCst);
    bridge.join().unwrap();
    server.line_containing("disconnected");
    server.interrupt();
}
