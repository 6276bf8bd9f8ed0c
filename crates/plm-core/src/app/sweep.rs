//! One round of reading a street (docs/board-protocol.md, "A round of
//! reads"): what the console's background sweep and `plm board status
//! all` both do. Every lamp's HID parameter is read in slots
//! ([`ReadAll`], SERVICE_READ_IN_SLOTS 13h) when there are enough lamps
//! to pay for the request, the lamps not heard are asked one by one (a
//! unicast `'g' param`, UM Appendix A), then SERVICE_SN_GET (10h, UM 4.5) goes
//! to the lamps whose SNR figure is oldest, and last, if asked, one
//! discovery frame of the session the lamps were heard in asks whether
//! anyone is new.
//! Sans-IO: the caller sends each request [`Round::poll`] gives it, hands
//! back the fate of each unicast one ([`Round::on_answer`]) and what
//! boards send unasked ([`Round::hear`]), and takes what was read
//! ([`Round::take_readings`]).

use super::discovery::{Discovery, DiscoveryConfig};
use super::frame::{Address, AppFrame};
use super::hid::Hid;
use super::message::Message;
use super::read_all::{ReadAll, ReadConfig};
use super::requester::Request;
use super::service::{Discovered, Service};
use crate::time::{Duration, Instant, MS};
use alloc::collections::VecDeque;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

/// Lamps from which a read in slots pays, at B-PSK for GET ALL: its
/// window for 3 boards is about 306 ms against 330 ms for three unicast
/// round trips (about 110 ms each on the simulated street); for 2,
/// 239 ms against 220.
pub const SLOTS_FROM: usize = 3;

/// A lamp as the round sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Known {
    /// Its board's address.
    pub address: Address,
    /// What discovery heard of it (heard in the probe's session, it stays
    /// quiet; heard again, it restarted and is not new).
    pub discovered: Option<Discovered>,
    /// When its SNR figure was got (`None`: never).
    pub snr_at: Option<Instant>,
}

/// How a round runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundConfig {
    /// The parameter read and the line's timing.
    pub read: ReadConfig,
    /// Fewer lamps than this are asked one by one.
    pub slots_from: usize,
    /// SN GET for the lamps whose figure is older than this; `None`:
    /// never (through a bare modem every frame heard carries its SNR).
    pub snr_after: Option<Duration>,
    /// At most one lamp in this many is asked its SNR in a round.
    pub snr_one_in: usize,
    /// After the reads, one discovery frame of this session.
    pub probe: Option<u8>,
}

impl RoundConfig {
    /// The reads alone: GET ALL, no SNR, no probe.
    pub const READS: RoundConfig = RoundConfig {
        read: ReadConfig::ALL,
        slots_from: SLOTS_FROM,
        snr_after: None,
        snr_one_in: 1,
        probe: None,
    };

    /// A background sweep's: a figure older than a minute asked again,
    /// one lamp in ten a round, and the probe in `session`.
    pub fn sweep(session: u8, snr: bool) -> RoundConfig {
        RoundConfig {
            snr_after: snr.then_some(60_000 * MS),
            snr_one_in: 10,
            probe: Some(session),
            ..RoundConfig::READS
        }
    }
}

/// What a round learned.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reading {
    /// A lamp's value of the parameter, heard in its slot or asked alone.
    Value(Address, Vec<u8>),
    /// A lamp not read: why, in words.
    Failed(Address, String),
    /// A lamp's SNR as its board reports it, dB.
    Snr(Address, u8),
    /// The probe heard a board (a new one, or one that restarted).
    Heard(Address, Discovered),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ask {
    Read,
    Snr,
}

#[derive(Debug, Clone)]
enum Step {
    Start,
    Slots(ReadAll),
    /// Unicast requests of one kind, one at a time.
    Alone(Ask),
    Probe(Discovery),
    Done,
}

/// A round in progress.
#[derive(Debug, Clone)]
pub struct Round {
    config: RoundConfig,
    lamps: Vec<Known>,
    step: Step,
    /// Lamps to ask alone, and the request under way.
    queue: VecDeque<Address>,
    asked: Option<(Address, Ask)>,
    readings: Vec<Reading>,
    /// Lamps whose read ended (a value or a failure), heard in slots.
    settled: usize,
    in_slots: usize,
    failed: Vec<Address>,
    new_heard: bool,
}

impl Round {
    /// A round over `lamps`; the first [`Round::poll`] starts it.
    pub fn new(lamps: Vec<Known>, config: RoundConfig) -> Round {
        Round {
            config,
            lamps,
            step: Step::Start,
            queue: VecDeque::new(),
            asked: None,
            readings: Vec::new(),
            settled: 0,
            in_slots: 0,
            failed: Vec::new(),
            new_heard: false,
        }
    }

    /// The next request to send now, if any: call it after every answer
    /// and when [`Round::poll_timeout`] is due. Unicast requests come one
    /// at a time, each after the fate of the one before.
    pub fn poll(&mut self, now: Instant) -> Option<Request> {
        if self.asked.is_some() {
            return None;
        }
        loop {
            match &mut self.step {
                Step::Start => {
                    let boards: Vec<Address> = self.lamps.iter().map(|l| l.address).collect();
                    if boards.len() < self.config.slots_from {
                        self.queue = boards.into();
                        self.step = Step::Alone(Ask::Read);
                        continue;
                    }
                    let (r, first) = ReadAll::start(now, &boards, self.config.read);
                    self.step = Step::Slots(r);
                    if first.is_some() {
                        return first;
                    }
                }
                Step::Slots(r) => {
                    if let Some(next) = r.handle_timeout(now) {
                        return Some(next);
                    }
                    if !r.is_done() {
                        return None;
                    }
                    self.queue = r.stragglers().into();
                    self.step = Step::Alone(Ask::Read);
                }
                Step::Alone(ask) => {
                    let ask = *ask;
                    if let Some(a) = self.queue.pop_front() {
                        self.asked = Some((a, ask));
                        let m = match ask {
                            Ask::Read => Message::Hid(Hid::Get(self.config.read.param)),
                            Ask::Snr => Message::Service(Service::SnGet),
                        };
                        return Some(Request::to(a, m));
                    }
                    if ask == Ask::Read {
                        // The reads are over: the SNR where it is needed.
                        self.queue = self.snr_wanted(now).into();
                        self.step = Step::Alone(Ask::Snr);
                        continue;
                    }
                    self.step = Step::Done;
                    if let Some(session) = self.config.probe {
                        let known = self
                            .lamps
                            .iter()
                            .filter_map(|l| Some((l.address, l.discovered?)))
                            .collect();
                        let config = DiscoveryConfig {
                            timing: self.config.read.timing,
                            max_frames: 1,
                            ..DiscoveryConfig::new(session, 1)
                        };
                        let (d, first) = Discovery::resume(now, config, known);
                        self.step = Step::Probe(d);
                        return Some(first);
                    }
                }
                Step::Probe(d) => {
                    let next = d.handle_timeout(now);
                    if d.is_done() {
                        self.step = Step::Done;
                    }
                    return next;
                }
                Step::Done => return None,
            }
        }
    }

    /// The lamps to ask their SNR: figures older than the config says
    /// (none first, then the oldest), at most one lamp in `snr_one_in`,
    /// and not a lamp whose read failed in this round.
    fn snr_wanted(&self, now: Instant) -> Vec<Address> {
        let Some(after) = self.config.snr_after else {
            return Vec::new();
        };
        let mut stale: Vec<&Known> = self
            .lamps
            .iter()
            .filter(|l| l.snr_at.is_none_or(|t| now.saturating_sub(t) > after))
            .filter(|l| !self.failed.contains(&l.address))
            .collect();
        let most = self.lamps.len().div_ceil(self.config.snr_one_in.max(1));
        // The oldest, one after another (a missing figure is older than
        // any): no sort, which would cost the console its code.
        let mut wanted = Vec::new();
        while wanted.len() < most {
            let Some(i) = (0..stale.len()).min_by_key(|&i| stale[i].snr_at) else {
                break;
            };
            wanted.push(stale.swap_remove(i).address);
        }
        wanted
    }

    /// A frame that came unasked: a lamp's reply in its slot, or a
    /// discovery reply to the probe. Returns the frame to send back, if
    /// any (only discovery's older rule has one).
    pub fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        match &mut self.step {
            Step::Slots(r) => {
                let before = r.heard().len();
                if r.on_message(address, message) && r.heard().len() > before {
                    if let Message::Hid(Hid::Reply { value, .. }) = message {
                        self.settled += 1;
                        self.in_slots += 1;
                        self.readings.push(Reading::Value(address, value.clone()));
                    }
                }
                None
            }
            Step::Probe(d) => {
                let ack = d.on_message(address, message);
                if let Message::Service(Service::DiscoverReply(r)) = message {
                    self.new_heard |= !self.lamps.iter().any(|l| l.address == address);
                    self.readings.push(Reading::Heard(address, *r));
                }
                ack
            }
            _ => None,
        }
    }

    /// The fate of the unicast request under way: its answer, or why
    /// there is none.
    pub fn on_answer(&mut self, answer: Result<&Message, &str>) {
        let Some((a, ask)) = self.asked.take() else {
            return;
        };
        let reading = match (ask, answer) {
            (Ask::Read, Ok(Message::Hid(Hid::Reply { param, value })))
                if *param == self.config.read.param =>
            {
                Reading::Value(a, value.clone())
            }
            (Ask::Read, Ok(Message::Error(code))) => {
                Reading::Failed(a, format!("the board answered with an error: {code}"))
            }
            (Ask::Read, Ok(other)) => {
                Reading::Failed(a, format!("an unexpected answer: {}", other.name()))
            }
            (Ask::Read, Err(why)) => Reading::Failed(a, why.into()),
            (Ask::Snr, Ok(Message::Service(Service::Sn(v)))) => Reading::Snr(a, *v),
            (Ask::Snr, _) => return,
        };
        if let Reading::Failed(..) = reading {
            self.failed.push(a);
        }
        self.settled += usize::from(ask == Ask::Read);
        self.readings.push(reading);
    }

    /// What was learned since the last call, in the order it came.
    pub fn take_readings(&mut self) -> Vec<Reading> {
        core::mem::take(&mut self.readings)
    }

    /// When [`Round::poll`] is due for time (a window or a probe frame
    /// ending).
    pub fn poll_timeout(&self) -> Option<Instant> {
        match &self.step {
            Step::Slots(r) => r.poll_timeout(),
            Step::Probe(d) => d.poll_timeout(),
            _ => None,
        }
    }

    /// Whether it is over.
    pub fn is_done(&self) -> bool {
        matches!(self.step, Step::Done)
    }

    /// The lamps of the round.
    pub fn lamps(&self) -> usize {
        self.lamps.len()
    }

    /// Lamps whose read is over (a value or a failure).
    pub fn settled(&self) -> usize {
        self.settled
    }

    /// Lamps heard in their slot.
    pub fn in_slots(&self) -> usize {
        self.in_slots
    }

    /// Whether the probe heard a board that was not among the lamps.
    pub fn found_new(&self) -> bool {
        self.new_heard
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::error::ErrorCode;
    use crate::app::hid;
    use crate::app::service::Release;

    const S: Duration = 1_000 * MS;

    fn board(i: u8) -> Address {
        Address([0, 0x80, 0xE1, 0, 1, i])
    }

    fn lamp(i: u8, snr_at: Option<Instant>) -> Known {
        Known {
            address: board(i),
            discovered: Some(found(i)),
            snr_at,
        }
    }

    fn found(snr: u8) -> Discovered {
        let r = Release { major: 1, minor: 4 };
        Discovered {
            firmware: r,
            stack: r,
            snr,
        }
    }

    fn reply(value: u8) -> Message {
        Message::Hid(Hid::Reply {
            param: hid::ALL,
            value: alloc::vec![value; 24],
        })
    }

    fn readings(r: &mut Round) -> Vec<Reading> {
        r.take_readings()
    }

    /// 40 lamps: three requests in slots, where 7 and 33 stay silent;
    /// they are asked alone (33 answers, 7 does not); then the SNR of the
    /// four lamps whose figure is oldest (one in ten; not 7, whose read
    /// failed); then one probe frame, where a new board answers.
    #[test]
    fn a_round_reads_in_slots_then_stragglers_then_snr_then_probes() {
        let now = 100 * S;
        let lamps: Vec<Known> = (0..40)
            .map(|i| match i {
                // No figure, or one older than a minute: 7 has none.
                7 | 20 => lamp(i, None),
                21 => lamp(i, Some(now - 90 * S)),
                22 => lamp(i, Some(now - 70 * S)),
                23 => lamp(i, Some(now - 61 * S)),
                24 => lamp(i, Some(now - 65 * S)),
                _ => lamp(i, Some(now - 10 * S)),
            })
            .collect();
        let mut r = Round::new(lamps, RoundConfig::sweep(9, true));
        let mut t = now;
        let mut slot_requests = 0;
        let mut q = r.poll(t).expect("the first request");
        while let Message::Service(Service::ReadInSlots(s)) = &q.message {
            assert!(q.broadcast);
            slot_requests += 1;
            for a in &s.addresses {
                if *a != board(7) && *a != board(33) {
                    let v = reply(a.0[5]);
                    assert_eq!(r.hear(*a, &v), None);
                    // Heard twice, counted once.
                    r.hear(*a, &v);
                }
            }
            assert_eq!(r.poll(t), None, "nothing before the window ends");
            t = r.poll_timeout().expect("a window");
            q = r.poll(t).expect("the next request");
        }
        // Forty boards sharing five address bytes: one request names them.
        assert_eq!(slot_requests, 1);
        assert_eq!((r.settled(), r.in_slots()), (38, 38));
        let heard = readings(&mut r);
        assert_eq!(heard.len(), 38);
        assert_eq!(heard[0], Reading::Value(board(0), alloc::vec![0; 24]));

        // The stragglers, alone, one after the other.
        assert_eq!(q, Request::to(board(7), Message::Hid(Hid::Get(hid::ALL))));
        assert_eq!(r.poll(t), None, "one at a time");
        r.on_answer(Err("did not answer"));
        let q = r.poll(t).expect("the next straggler");
        assert_eq!(q, Request::to(board(33), Message::Hid(Hid::Get(hid::ALL))));
        r.on_answer(Ok(&reply(33)));
        assert_eq!(
            readings(&mut r),
            [
                Reading::Failed(board(7), "did not answer".into()),
                Reading::Value(board(33), alloc::vec![33; 24]),
            ]
        );
        assert_eq!(r.settled(), 40);

        // The SNR: no figure first, then the oldest, four (one lamp in
        // ten); 23's is old enough but the share is spent.
        let mut snr = Vec::new();
        let mut q = r.poll(t).expect("an SNR request");
        while let Message::Service(Service::SnGet) = q.message {
            snr.push(q.address);
            let sn = Message::Service(Service::Sn(q.address.0[5]));
            r.on_answer(match q.address == board(22) {
                // A board that does not answer its SNR: nothing learned.
                true => Err("did not answer"),
                false => Ok(&sn),
            });
            q = r.poll(t).expect("a request");
        }
        assert_eq!(snr, [board(20), board(21), board(22), board(24)]);
        assert_eq!(
            readings(&mut r),
            [
                Reading::Snr(board(20), 20),
                Reading::Snr(board(21), 21),
                Reading::Snr(board(24), 24),
            ]
        );
        assert_eq!(r.settled(), 40, "SNR is not a read");

        // The probe: one discovery frame in the session given (the lamps
        // heard in it stay quiet); a new board answers.
        let Message::Service(Service::DiscoverFrame(f)) = &q.message else {
            panic!("a probe: {q:?}")
        };
        assert!(q.broadcast);
        assert_eq!(f.session, 9);
        assert!(!r.found_new());
        let hello = Message::Service(Service::DiscoverReply(found(3)));
        assert_eq!(r.hear(board(99), &hello), None);
        assert_eq!(readings(&mut r), [Reading::Heard(board(99), found(3))]);
        assert!(r.found_new());
        assert!(!r.is_done());
        let end = r.poll_timeout().expect("the frame's end");
        assert_eq!(r.poll(end), None, "one frame only");
        assert!(r.is_done());
        assert_eq!(r.poll_timeout(), None);
    }

    /// Fewer lamps than pay for a request in slots are asked alone; an
    /// error frame is a failure in words. No SNR and no probe: done.
    #[test]
    fn two_lamps_are_asked_alone() {
        let lamps = alloc::vec![lamp(1, None), lamp(2, None)];
        let mut r = Round::new(lamps, RoundConfig::READS);
        let q = r.poll(0).expect("a request");
        assert_eq!(q, Request::to(board(1), Message::Hid(Hid::Get(hid::ALL))));
        r.on_answer(Ok(&Message::Error(ErrorCode(0x12))));
        let q = r.poll(0).expect("a request");
        assert_eq!(q.address, board(2));
        r.on_answer(Ok(&Message::Ping));
        assert_eq!(r.poll(0), None);
        assert!(r.is_done());
        let got = readings(&mut r);
        let Reading::Failed(a, why) = &got[0] else {
            panic!("{got:?}")
        };
        assert_eq!(*a, board(1));
        assert!(
            why.starts_with("the board answered with an error: "),
            "{why}"
        );
        assert!(matches!(&got[1], Reading::Failed(a, why)
            if *a == board(2) && why.starts_with("an unexpected answer")));
        assert_eq!((r.settled(), r.in_slots()), (2, 0));
    }

    /// Reading in slots pays from [`SLOTS_FROM`] lamps at B-PSK: a
    /// request's window against about 110 ms a lamp stop-and-wait.
    #[test]
    fn slots_pay_from_three_lamps() {
        let alone = |n: usize| n as u64 * 110 * MS;
        let c = ReadConfig::ALL;
        assert!(c.window(SLOTS_FROM) < alone(SLOTS_FROM));
        assert!(c.window(SLOTS_FROM - 1) > alone(SLOTS_FROM - 1));
    }

    /// A street of no lamp: the probe alone, or nothing at all.
    #[test]
    fn no_lamp_is_the_probe_alone() {
        let mut r = Round::new(Vec::new(), RoundConfig::sweep(3, true));
        let q = r.poll(0).expect("the probe");
        assert!(matches!(
            q.message,
            Message::Service(Service::DiscoverFrame(_))
        ));
        let mut r = Round::new(Vec::new(), RoundConfig::READS);
        assert_eq!(r.poll(0), None);
        assert!(r.is_done());
    }
}
