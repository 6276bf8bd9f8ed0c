//! `plm sim` serving a street of lamps, end to end: plm-core's
//! [`Concentrator`] (the one the console and `plm board` drive) talks to
//! the real binary over RFC 2217 in real time, through both ways in
//! (docs/architecture.md, "Connection profiles"):
//!
//! - `--board`: a concentrator board's USART (application frames, no
//!   T_REQ); its firmware carries them over the simulated power line;
//! - `--chip st7580 --street N`: a bare ST7580 whose host is the
//!   concentrator itself, T_REQ driven by RTS through RFC 2217
//!   SET-CONTROL.
//!
//! Time is the wall clock since the connection, in microseconds, as the
//! concentrator expects; every wait ends on a condition, bounded by
//! generous limits. Lost frames are the requester's business (timeouts
//! and retries), not the test's.

mod common;

use common::{com_port, escape, Link, Server, Telnet, RTS_OFF, RTS_ON, SET_CONTROL};
use plm_core::app::discovery::{reply_slot, DiscoveryConfig};
use plm_core::app::hid::{self, Hid, LampState};
use plm_core::app::service::{Discovered, Service, SlotFrame};
use plm_core::app::{
    Address, AppEvent, Ballast, Concentrator, Discovery, ErrorCode, FrameType, Happening, Message,
    Request, RequesterConfig,
};
use plm_core::link::host::{Event, Transmit};
use plm_core::st7580::TxParams;
use plm_sim::board::{street_address, FIRMWARE};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// The concentrator's own address: node 0 of a simulated street.
const CONCENTRATOR: u64 = 0x0080_E100_0000;
/// The longest the loop waits for bytes before it looks at the clock
/// again: well under the 40 ms the modem gives the host to ACK a frame
/// (UM0932 T_ACK).
const TICK: Duration = Duration::from_millis(5);

/// The concentrator driven over an RFC 2217 link in real time.
struct Driver {
    link: Link,
    conc: Concentrator,
    /// Wall-clock time of the concentrator's time 0.
    start: Instant,
    /// Values of the server's SET-CONTROL answers (RTS on/off), in order.
    rts_answers: Vec<u8>,
    /// Every happening so far, for failure messages.
    log: Vec<Happening>,
}

impl Driver {
    fn new(mut link: Link, conc: Concentrator) -> Driver {
        link.agree();
        Driver {
            link,
            conc,
            start: Instant::now(),
            rts_answers: Vec::new(),
            log: Vec::new(),
        }
    }

    /// Concentrator time: microseconds since the driver started.
    fn now(&self) -> u64 {
        self.start.elapsed().as_micros() as u64
    }

    /// Writes everything the concentrator has for the port as one TCP
    /// write: data with IAC doubled, T_REQ as SET-CONTROL RTS.
    fn flush(&mut self) {
        let mut out = Vec::new();
        while let Some(t) = self.conc.poll_transmit() {
            match t {
                Transmit::Bytes(b) => out.extend(escape(&b)),
                Transmit::TReq { asserted } => {
                    let value = if asserted { RTS_ON } else { RTS_OFF };
                    out.extend(com_port(SET_CONTROL, &[value]));
                }
            }
        }
        if !out.is_empty() {
            self.link.send(&out);
        }
    }

    /// One turn: waits for bytes until the concentrator's next deadline
    /// (at most [`TICK`]), feeds them at the time they were read, runs
    /// what is due and sends what that produced.
    fn step(&mut self) -> Vec<Happening> {
        let now = self.now();
        let wait = self
            .conc
            .poll_timeout()
            .map_or(TICK, |t| Duration::from_micros(t.saturating_sub(now)))
            .min(TICK);
        self.link.pump(wait);
        while let Some(t) = self.link.telnet.pop_front() {
            if let Telnet::ComPort(c, value) = t {
                if c == SET_CONTROL + 100 {
                    self.rts_answers.extend(value);
                }
            }
        }
        let data = self.link.take_data();
        let now = self.now();
        if !data.is_empty() {
            self.conc.handle_rx(now, &data);
        }
        if self.conc.poll_timeout().is_some_and(|t| t <= now) {
            self.conc.handle_timeout(now);
        }
        self.flush();
        let mut out = Vec::new();
        while let Some(h) = self.conc.poll_happening() {
            self.log.push(h.clone());
            out.push(h);
        }
        out
    }

    /// Runs until `done` holds for a happening or `limit` passed.
    fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Happening) -> bool) -> bool {
        let until = Instant::now() + limit;
        while Instant::now() < until {
            if self.step().iter().any(&mut done) {
                return true;
            }
        }
        false
    }

    /// Every happening of the next `time`.
    fn listen(&mut self, time: Duration) -> Vec<Happening> {
        let until = Instant::now() + time;
        let mut heard = Vec::new();
        while Instant::now() < until {
            heard.extend(self.step());
        }
        heard
    }

    /// Sends a request and waits for its fate (answer, failure, or sent).
    fn request(&mut self, request: Request) -> AppEvent {
        let id = self.conc.submit(self.now(), request.clone());
        self.flush();
        let mut fate = None;
        // The requester gives up by itself after its attempts (1.5 s, then
        // 3 s, then 4.5 s by default): this limit only guards the test.
        self.run_until(Duration::from_secs(20), |h| match h {
            Happening::App(e) if e.fate_of() == Some(id) => {
                fate = Some(e.clone());
                true
            }
            _ => false,
        });
        fate.unwrap_or_else(|| panic!("no fate for {request:?}; happenings: {:?}", self.log))
    }

    /// The answer of one board, or a panic saying why there is none.
    fn ask(&mut self, to: Address, message: Message) -> Message {
        match self.request(Request::to(to, message.clone())) {
            AppEvent::Answered { answer, .. } => answer,
            other => panic!("{to} did not answer {message:?}: {other:?}"),
        }
    }

    /// A lamp's all-parameters reply (HID `'g'` 0Ah), decoded.
    fn all_parameters(&mut self, to: Address) -> Ballast {
        match self.ask(to, Message::Hid(Hid::Get(hid::ALL))) {
            Message::Hid(Hid::Reply { param, value }) => {
                assert_eq!(param, hid::ALL, "{to}: reply to another parameter");
                Ballast::decode(&value)
                    .unwrap_or_else(|| panic!("{to}: short all-parameters reply {value:02X?}"))
            }
            other => panic!("{to}: not a HID reply: {other:?}"),
        }
    }

    /// Discovery in rounds, each reply acknowledged as it comes.
    fn discover(&mut self, config: DiscoveryConfig) -> (Discovery, usize) {
        let (mut d, first) = Discovery::start(self.now(), config);
        self.conc.submit(self.now(), first);
        self.flush();
        let mut replies = 0;
        let give_up = Instant::now() + Duration::from_secs(40);
        while !d.is_done() {
            assert!(Instant::now() < give_up, "discovery did not end");
            for h in self.step() {
                if let Happening::App(AppEvent::Unsolicited {
                    address, message, ..
                }) = h
                {
                    replies += 1;
                    if let Some(ack) = d.on_message(address, &message) {
                        self.conc.send(self.now(), ack);
                        self.flush();
                    }
                }
            }
            if let Some(next) = d.handle_timeout(self.now()) {
                self.conc.submit(self.now(), next);
                self.flush();
            }
        }
        (d, replies)
    }
}

/// `plm sim --board --street 5`: the concentrator board's USART reaches
/// five lamps: discovered, read, dimmed one by one and all at once; the
/// board answers for itself over its USART.
#[test]
fn concentrator_board_over_rfc2217_discovers_reads_and_dims_a_street() {
    let mut server = Server::start(&[
        "--board",
        "--listen",
        "127.0.0.1:0",
        "--street",
        "5",
        "--seed",
        "3",
    ]);
    assert!(
        server.banner.contains("concentrator board") && server.banner.contains("5 lamps"),
        "{}",
        server.banner
    );
    let link = Link::connect(&server.addr);
    server.line_containing("connected");
    let mut d = Driver::new(link, Concentrator::usart(RequesterConfig::default()));

    // 1. Discovery: every lamp answers, is named in the next frame's
    // request, and nothing but the street's lamps answers.
    let (discovery, replies) = d.discover(DiscoveryConfig::new(1, 5));
    let found: BTreeMap<Address, Discovered> = discovery.found().iter().copied().collect();
    let lamps: Vec<Address> = (1..=5).map(street_address).collect();
    assert_eq!(
        found.keys().copied().collect::<Vec<_>>(),
        lamps,
        "found after {} frame(s)",
        discovery.frames()
    );
    for (a, info) in found {
        assert_eq!(info.firmware, FIRMWARE, "{a}: firmware release");
    }
    // Named lamps keep quiet for the rest of the session: only a lamp
    // that missed the request naming it answers again.
    assert!(
        replies <= 5 + discovery.frames() as usize,
        "{replies} replies in {} frame(s)",
        discovery.frames()
    );

    // 2. All parameters of lamp 2: burning, drawing power.
    let lamp = street_address(2);
    let full = d.all_parameters(lamp);
    assert_eq!(full.state(), LampState::Run, "{full:?}");
    assert!(full.lamp_power > 0, "{full:?}");

    // 3. Dimmed to 40 % by a unicast command, acknowledged; the power
    // drops.
    let dim = Message::Hid(Hid::Dimming(40));
    let ack = d.ask(lamp, dim.clone());
    assert_eq!(ack, dim.ack(), "ACK of the dimming");
    assert!(matches!(
        ack,
        Message::Ack {
            frame_type: FrameType::Data,
            echo: hid::SET
        }
    ));
    let dimmed = d.all_parameters(lamp);
    assert_eq!(dimmed.state(), LampState::Run, "{dimmed:?}");
    assert!(
        0 < dimmed.lamp_power && dimmed.lamp_power < full.lamp_power,
        "{} W at 40 % vs {} W at 100 %",
        dimmed.lamp_power,
        full.lamp_power
    );

    // 4. A broadcast dimming to 70 %: sent without an answer; every lamp
    // follows it (lamp 2 rises from 40 %, lamp 4 falls from 100 %).
    let before4 = d.all_parameters(street_address(4));
    let sent = d.request(Request::all(Message::Hid(Hid::Dimming(70))));
    assert!(matches!(sent, AppEvent::Sent { .. }), "{sent:?}");
    let after2 = d.all_parameters(lamp);
    let after4 = d.all_parameters(street_address(4));
    assert!(
        after2.lamp_power > dimmed.lamp_power && after2.lamp_power < full.lamp_power,
        "lamp 2: {} W at 70 %, {} W at 40 %, {} W at 100 %",
        after2.lamp_power,
        dimmed.lamp_power,
        full.lamp_power
    );
    assert!(
        after4.lamp_power < before4.lamp_power,
        "lamp 4: {} W at 70 % vs {} W at 100 %",
        after4.lamp_power,
        before4.lamp_power
    );

    // 5. The concentrator board's own clock, answered over its USART: it
    // powered on with the connection (RTC at midnight, virtual time 0).
    let elapsed = d.start.elapsed().as_secs();
    match d.ask(
        Address::from_u64(CONCENTRATOR),
        Message::Service(Service::ClockGet),
    ) {
        Message::Service(Service::ClockNow(c)) => {
            let s = u64::from(c.seconds_of_day());
            assert!(
                s <= d.start.elapsed().as_secs() + 2 && s + 2 >= elapsed,
                "concentrator clock {c} after {elapsed} s"
            );
        }
        other => panic!("clock of the concentrator: {other:?}"),
    }
    assert!(
        !d.log.iter().any(|h| matches!(
            h,
            Happening::App(AppEvent::Malformed { .. } | AppEvent::Failed { .. })
        )),
        "{:?}",
        d.log
    );

    drop(d);
    server.line_containing("disconnected");
    server.interrupt();
}

/// SERVICE_NET_DISCOVER_REQ as seed 004 lists it (0Bh, no data), and
/// malformed (0Bh with 3 data bytes, a rule-2 request cut short: neither
/// rule's request nor a reply), through `plm sim --board` and its
/// default street of 12 lamps (docs/protocol-notes.md, "Discovery"):
///
/// - broadcast malformed: no board answers (500 error frames at once
///   would jam the line);
/// - broadcast bare, twice: the lamps answer each time (no session, no
///   silencing), each in the slot of `SlotFrame::BARE` its address
///   draws with the count of bare requests it heard as the frame number
///   (so that lamps sharing a slot once do not share it the next time):
///   every lamp alone in its slot is heard, in the order of the slots,
///   and of lamps that share a slot at most one (the line may capture
///   the strongest);
/// - unicast malformed: APP_ERROR_SERVICE_CMD_ERROR.
#[test]
fn a_bare_discover_is_answered_in_slots_and_a_malformed_one_only_when_unicast() {
    let lamps = 12;
    let slots_of = |nth: u8| {
        let slot = |a: &Address| {
            let frame = SlotFrame {
                frame: nth,
                ..SlotFrame::BARE
            };
            reply_slot(a, &frame)
                .unwrap_or_else(|| panic!("{a} sits a bare 0Bh out: its share is all"))
        };
        let mut by_slot: BTreeMap<u8, Vec<Address>> = BTreeMap::new();
        for a in (1..=lamps).map(street_address) {
            by_slot.entry(slot(&a)).or_default().push(a);
        }
        by_slot
    };
    let street = lamps.to_string();
    let mut server = Server::start(&["--board", "--listen", "127.0.0.1:0", "--street", &street]);
    let link = Link::connect(&server.addr);
    server.line_containing("connected");
    let mut d = Driver::new(link, Concentrator::usart(RequesterConfig::default()));
    // The last bare slot ends 16 × 40 ms after the request; the relays
    // and a late firmware add well under a second.
    let listen = Duration::from_millis(2_500);
    let malformed = Message::Service(Service::Raw {
        command: 0x0b,
        data: vec![2, 1, 0],
    });

    let sent = d.request(Request::all(malformed.clone()));
    assert!(matches!(sent, AppEvent::Sent { .. }), "{sent:?}");
    let heard: Vec<Happening> = d
        .listen(listen)
        .into_iter()
        .filter(|h| matches!(h, Happening::App(_)))
        .collect();
    assert!(
        heard.is_empty(),
        "a malformed broadcast 0Bh was answered: {heard:?}"
    );

    let mut ever = Vec::new();
    for (nth, time) in ["first", "second"].into_iter().enumerate() {
        let by_slot = slots_of(nth as u8);
        let alone: Vec<Address> = by_slot
            .values()
            .filter(|group| group.len() == 1)
            .map(|group| group[0])
            .collect();
        assert!(
            alone.len() >= 3,
            "too few lamps alone in a slot: {by_slot:?}"
        );
        let sent = d.request(Request::all(Message::Service(Service::DiscoverAny)));
        assert!(matches!(sent, AppEvent::Sent { .. }), "{sent:?}");
        let mut heard = Vec::new();
        for h in d.listen(listen) {
            match h {
                Happening::App(AppEvent::Unsolicited {
                    address,
                    message: Message::Service(Service::DiscoverReply(info)),
                    ..
                }) => {
                    assert_eq!(info.firmware, FIRMWARE, "{address}: firmware release");
                    heard.push(address);
                }
                Happening::App(other) => panic!("{time} bare 0Bh: {other:?}"),
                _ => {}
            }
        }
        let words = |v: &[Address]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
        println!(
            "{time} bare 0Bh: {} of {lamps} lamps heard: {:?}; slots shared: {:?}",
            heard.len(),
            words(&heard),
            by_slot
                .iter()
                .filter(|(_, group)| group.len() > 1)
                .map(|(s, group)| (s, words(group)))
                .collect::<Vec<_>>()
        );
        let in_order: Vec<Address> = by_slot
            .values()
            .filter_map(|group| group.iter().find(|a| heard.contains(a)).copied())
            .collect();
        assert_eq!(
            heard, in_order,
            "{time} bare 0Bh: heard, against one lamp of each slot in the order of the slots \
             ({by_slot:?})"
        );
        for a in &alone {
            assert!(
                heard.contains(a),
                "{time} bare 0Bh: {a}, alone in its slot, not heard: {heard:?} ({by_slot:?})"
            );
        }
        ever.extend(heard);
    }
    ever.sort();
    ever.dedup();
    println!("{} of {lamps} lamps heard in two bare requests", ever.len());

    let lamp = street_address(2);
    assert_eq!(
        d.ask(lamp, malformed),
        Message::Error(ErrorCode::SERVICE_CMD_ERROR),
        "a malformed unicast 0Bh"
    );

    drop(d);
    server.line_containing("disconnected");
    server.interrupt();
}

/// `plm sim --chip st7580 --street 3`: the concentrator is the modem's
/// host (T_REQ on RTS) and speaks the board protocol over the line
/// itself: lamp 1 answers a ping.
#[test]
fn bare_st7580_over_rfc2217_pings_a_lamp_of_the_street() {
    let mut server = Server::start(&[
        "--chip",
        "st7580",
        "--street",
        "3",
        "--listen",
        "127.0.0.1:0",
    ]);
    assert!(
        server.banner.contains("ST7580") && server.banner.contains("3 lamps"),
        "{}",
        server.banner
    );
    let link = Link::connect(&server.addr);
    server.line_containing("connected");
    let conc = Concentrator::modem(
        RequesterConfig::default(),
        57_600,
        Address::from_u64(CONCENTRATOR),
        TxParams::default(),
    );
    let mut d = Driver::new(link, conc);

    // The modem powered on with the connection: BIO_ResetIndication.
    assert!(
        d.run_until(Duration::from_secs(10), |h| matches!(
            h,
            Happening::Link(Event::Frame(f)) if f.code == 0x3E
        )),
        "no BIO_ResetIndication: {:?}",
        d.log
    );

    let lamp = street_address(1);
    let answer = d.ask(lamp, Message::Ping);
    assert_eq!(
        answer,
        Message::Ack {
            frame_type: FrameType::Ping,
            echo: 0
        }
    );
    // The answer crossed the line from lamp 1, and T_REQ went through
    // RTS: every request asserted it and released it again.
    assert!(
        d.log
            .iter()
            .any(|h| matches!(h, Happening::Heard { address, .. } if *address == lamp)),
        "{:?}",
        d.log
    );
    assert!(
        d.rts_answers.contains(&RTS_ON) && d.rts_answers.contains(&RTS_OFF),
        "SET-CONTROL answers {:?}",
        d.rts_answers
    );
    assert!(
        d.log
            .iter()
            .any(|h| matches!(h, Happening::Link(Event::Delivered(_)))),
        "the modem ACKed the DL_DataRequest: {:?}",
        d.log
    );

    drop(d);
    server.line_containing("disconnected");
    server.interrupt();
}

/// `--cold-lamps` starts a street's lamps cold: without a street it has
/// no lamps, and says so.
#[test]
fn cold_lamps_need_a_street() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["sim", "--cold-lamps", "--listen", "127.0.0.1:0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--street"), "{err}");
}

/// The lamps of a street differ as a real street's by default: the
/// start-up lines name the worn lamp and the weak far one. With
/// `--uniform-lamps` they are alike and nothing is said of them; without
/// a street the flag is refused.
#[test]
fn the_default_street_names_its_worn_and_weak_lamps() {
    let args = ["--board", "--street", "5", "--listen", "127.0.0.1:0"];
    let mut server = Server::start(&args);
    let lines = server.lines_up_to("powers on");
    let said = |what: &str| lines.iter().any(|l| l.contains(what));
    assert!(said("fails about 2 minutes in"), "{lines:?}");
    assert!(said("(node 5), the far one, is heard weakly"), "{lines:?}");
    server.interrupt();
    let mut server = Server::start(&[&args[..], &["--uniform-lamps"]].concat());
    let lines = server.lines_up_to("powers on");
    assert!(
        !lines
            .iter()
            .any(|l| l.contains("worn") || l.contains("weakly")),
        "{lines:?}"
    );
    server.interrupt();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["sim", "--uniform-lamps", "--listen", "127.0.0.1:0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--street"));
}

/// `--lamp-failures` needs a street too, and a rate in range.
#[test]
fn lamp_failures_need_a_street_and_a_rate() {
    let plm = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_plm"))
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = plm(&["sim", "--lamp-failures", "2", "--listen", "127.0.0.1:0"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--street"), "{err}");
    let (code, err) = plm(&[
        "sim",
        "--board",
        "--lamp-failures",
        "99",
        "--listen",
        "127.0.0.1:0",
    ]);
    assert_eq!(code, Some(2));
    assert!(err.contains("0 to 60"), "{err}");
}

/// The start-up lines of a street name its boards, and say nothing of
/// echoing peers (a street has none; `--peers` is refused with it).
#[test]
fn a_street_is_announced_as_boards_not_echoing_peers() {
    for (args, what) in [
        (
            &["--street", "3"][..],
            "simulated ST7580 with a street of 3 lamps (nodes 1-3",
        ),
        (
            &["--board"],
            "concentrator board's USART with a street of 12 lamps (nodes 1-12",
        ),
    ] {
        let mut server = Server::start(&[args, &["--listen", "127.0.0.1:0"]].concat());
        assert!(server.banner.contains(what), "{}", server.banner);
        let lines = server.lines_up_to("powers on");
        assert!(!lines.iter().any(|l| l.contains("echo")), "{lines:?}");
        server.interrupt();
    }
}
