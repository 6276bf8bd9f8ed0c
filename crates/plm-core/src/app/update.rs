//! The remote firmware update engine (sans-IO): one image to one board or
//! a street of them, over the RFU commands of [`super::rfu`]. Decisions:
//! docs/protocol-notes.md, "Remote firmware update", "The update engine".
//!
//! 1. **Announce**: the header to each board, one after another (ACK).
//! 2. **Broadcast**: every segment once, to all boards at once, one every
//!    [`UpdateConfig::gap`] (segments have no answer; the gap is what the
//!    line takes for one).
//! 3. **Repair**, in rounds: each board is asked for its status; the
//!    segments it misses go to it alone. A board complete after a round
//!    waits for the others.
//! 4. **Swap**, one board at a time (ACK); then, once it had the time to
//!    restart and confirm its image, its release is read back (06h).
//!
//! A board that does not answer (after the requester's retries) is tried
//! again later, [`UpdateConfig::backoff`] doubling each time, while the
//! others go on; one that lost the campaign (it restarted) or refused its
//! swap is announced again and repaired; past the limits it is left with
//! its reason in words. Every request goes through the caller's requester
//! one at a time: the engine hands out the next one only when the last is
//! over. [`Update::save`] and [`Update::resume`] carry a campaign over a
//! closed console or a pulled cable (`update/save.rs`).

use super::frame::Address;
use super::message::Message;
use super::requester::Request;
use super::rfu::{self, Header, RfuState, Status};
use super::service::{Release, Service};
use crate::time::{Duration, Instant, MS};
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

mod save;

/// How the engine paces itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UpdateConfig {
    /// Between two segments sent without an answer: the airtime of a
    /// full segment frame and a margin (about 40 ms of B-PSK and the
    /// concentrator's queue; 250 ms leaves room for a board's answer to
    /// a neighbour).
    pub gap: Duration,
    /// Repair rounds before a board still missing segments is given up.
    pub repair_rounds: u8,
    /// From a swap's ACK to reading the release back: the board resets
    /// (300 ms) and its image confirms itself (5 s).
    pub restart: Duration,
    /// After a board did not answer (the requester's own retries spent):
    /// the wait before it is tried again, doubled each time.
    pub backoff: Duration,
    /// Times a board may stay silent, or refuse a header, before it is
    /// given up.
    pub silences: u8,
    /// Times a board that lost the campaign or refused its swap is
    /// announced again.
    pub restarts: u8,
}

impl UpdateConfig {
    /// Between two segments: what is left to the line after one (the
    /// simulated concentrator loses segments with none; 10 ms keeps 5 ms
    /// in hand there; docs/protocol-notes.md, "The update engine").
    pub const MARGIN: Duration = 10 * MS;

    /// The default pacing with the gap that a line whose full segment
    /// frame takes `segment_airtime` to send can carry: the airtime and
    /// [`UpdateConfig::MARGIN`] (the next frame crossing the USART and
    /// the modem's turnaround).
    pub fn paced(segment_airtime: Duration) -> UpdateConfig {
        UpdateConfig {
            gap: segment_airtime + Self::MARGIN,
            ..UpdateConfig::default()
        }
    }

    /// Longest gap, restart or back-off a campaign takes (ten minutes:
    /// sixty times the defaults' longest).
    pub const LONGEST: Duration = 600_000 * MS;
    /// Most silences a board may be allowed (the back-off doubles after
    /// each: sixteen from ten minutes is a year and a quarter).
    pub const MOST_SILENCES: u8 = 16;

    /// Refuses, in words, a pacing whose waits could not be counted in
    /// microseconds (a saved campaign's, a caller's).
    pub fn check(&self) -> Result<(), String> {
        for (what, d) in [
            ("gap", self.gap),
            ("restart", self.restart),
            ("back-off", self.backoff),
        ] {
            if d > Self::LONGEST {
                return Err(format!(
                    "a {what} of {} ms is over the {} ms a campaign waits at most",
                    d / MS,
                    Self::LONGEST / MS
                ));
            }
        }
        if self.silences > Self::MOST_SILENCES {
            return Err(format!(
                "{} silences allowed a board, over the {} whose doubling back-off can be waited",
                self.silences,
                Self::MOST_SILENCES
            ));
        }
        Ok(())
    }
}

impl Default for UpdateConfig {
    fn default() -> Self {
        UpdateConfig {
            gap: 250 * MS,
            repair_rounds: 5,
            restart: 8_000 * MS,
            backoff: 15_000 * MS,
            silences: 3,
            restarts: 2,
        }
    }
}

/// Where one board is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BoardState {
    /// The header is still to be acknowledged.
    Announcing,
    /// Receiving segments; the ones it is known to miss.
    Receiving {
        /// Segments to send it again.
        missing: Vec<usize>,
        /// Times it was asked for its status.
        asked: u8,
    },
    /// Every segment held; waiting for its swap.
    Complete,
    /// Swapped at this time: restarting into the new image.
    Restarting(Instant),
    /// It runs the new release.
    Done,
    /// The campaign was aborted before its swap: it keeps its release and
    /// forgot the segments (RFU_ABORT acknowledged).
    Aborted,
    /// Given up, and why, in words.
    Failed(String),
}

impl BoardState {
    /// Where it is, in a few words.
    pub fn words(&self) -> &'static str {
        match self {
            BoardState::Announcing => "announcing",
            BoardState::Receiving { .. } => "receiving",
            BoardState::Complete => "verified, waiting for its swap",
            BoardState::Restarting(_) => "swapped, restarting",
            BoardState::Done => "updated",
            BoardState::Aborted => "not updated: cancelled",
            BoardState::Failed(_) => "failed",
        }
    }

    /// Still to get segments (or its header).
    fn receiving(&self) -> bool {
        matches!(self, BoardState::Announcing | BoardState::Receiving { .. })
    }
}

/// One board of a campaign.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Target {
    address: Address,
    state: BoardState,
    /// Times it did not answer (or refused a header).
    silences: u8,
    /// Times it was announced again.
    restarts: u8,
    /// Not to be asked before this time (back-off).
    not_before: Instant,
    /// Done before a resume: its release is being read back.
    rechecked: bool,
    /// The release it reported after its restart.
    firmware: Option<Release>,
}

/// Where the campaign is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Announce,
    Broadcast(usize),
    Repair,
    Swap,
    /// Telling the boards not swapped yet to forget the campaign.
    Abort,
    Over,
}

/// What the engine waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Waiting {
    Nothing,
    /// The answer to a request to this board.
    Answer(usize),
    /// Nothing to send before this time.
    Until(Instant),
}

/// One campaign.
#[derive(Debug, Clone)]
pub struct Update {
    header: Header,
    image: Vec<u8>,
    config: UpdateConfig,
    targets: Vec<Target>,
    phase: Phase,
    waiting: Waiting,
    /// Segment bytes handed out so far.
    sent: u64,
}

impl Update {
    /// A campaign that puts `image`, release `version` (`None`: the image
    /// states none), on `targets`.
    pub fn new(
        campaign: u8,
        version: impl Into<Option<Release>>,
        image: Vec<u8>,
        targets: &[Address],
        config: UpdateConfig,
    ) -> Result<Update, String> {
        if image.is_empty() || image.len() > rfu::IMAGE_MAX {
            return Err(format!(
                "the image is {} bytes: a board's slot takes 1 to {} bytes",
                image.len(),
                rfu::IMAGE_MAX
            ));
        }
        if campaign == 0 {
            return Err("campaign 0 is reserved: use 1 to 255".into());
        }
        if targets.is_empty() {
            return Err("no board to update".into());
        }
        config.check()?;
        Ok(Update {
            header: Header::of(
                campaign,
                version.into().unwrap_or(rfu::RELEASE_NOT_STATED),
                &image,
            ),
            image,
            config,
            targets: targets
                .iter()
                .map(|a| Target {
                    address: *a,
                    state: BoardState::Announcing,
                    silences: 0,
                    restarts: 0,
                    not_before: 0,
                    rechecked: false,
                    firmware: None,
                })
                .collect(),
            phase: Phase::Announce,
            waiting: Waiting::Nothing,
            sent: 0,
        })
    }

    /// The release board `i` (in [`Update::boards`]'s order) reported
    /// after its restart, once it did.
    pub fn firmware(&self, i: usize) -> Option<Release> {
        self.targets.get(i)?.firmware
    }

    /// The header every board gets.
    pub fn header(&self) -> Header {
        self.header
    }

    /// The image it sends.
    pub fn image(&self) -> &[u8] {
        &self.image
    }

    /// Every board and where it is.
    pub fn boards(&self) -> impl Iterator<Item = (Address, &BoardState)> + '_ {
        self.targets.iter().map(|t| (t.address, &t.state))
    }

    /// Whether it is over (every board done or given up).
    pub fn is_done(&self) -> bool {
        self.phase == Phase::Over
    }

    /// Whether it is being aborted (or was).
    pub fn is_aborting(&self) -> bool {
        self.phase == Phase::Abort
    }

    /// Segment bytes handed out so far (since it started or resumed).
    pub fn bytes_sent(&self) -> u64 {
        self.sent
    }

    /// Of board `i`'s segments, how many it is known to hold, in
    /// thousandths (segments broadcast so far while the broadcast runs).
    pub fn permille(&self, i: usize) -> u16 {
        let count = self.header.segments();
        let held = match &self.targets[i].state {
            BoardState::Announcing | BoardState::Aborted | BoardState::Failed(_) => 0,
            BoardState::Receiving { missing, asked } => match self.phase {
                Phase::Broadcast(n) => n,
                _ if *asked == 0 && missing.is_empty() => count,
                _ => count - missing.len().min(count),
            },
            _ => count,
        };
        (held * 1000 / count.max(1)) as u16
    }

    /// What is left at `now`, at the engine's own pace: the segments
    /// still to broadcast or repair, a status per board still receiving,
    /// a swap per board not swapped yet, and the restart of the last one.
    pub fn time_left(&self, now: Instant) -> Duration {
        if self.is_done() {
            return 0;
        }
        let broadcast = match self.phase {
            Phase::Announce => self.header.segments(),
            Phase::Broadcast(n) => self.header.segments() - n.min(self.header.segments()),
            _ => 0,
        };
        let mut segments = broadcast as u64;
        let (mut asks, mut swaps) = (0, 0);
        let mut restart_ends = 0;
        for t in &self.targets {
            match &t.state {
                BoardState::Announcing => (asks, swaps) = (asks + 2, swaps + 1),
                BoardState::Receiving { missing, .. } => {
                    segments += missing.len() as u64;
                    (asks, swaps) = (asks + 1, swaps + 1);
                }
                BoardState::Complete => swaps += 1,
                BoardState::Restarting(at) => {
                    restart_ends = restart_ends.max(at + self.config.restart)
                }
                _ => {}
            }
        }
        let sending = segments * self.config.gap + (asks + swaps) * 1_000 * MS;
        let restart = if swaps > 0 {
            self.config.restart
        } else {
            restart_ends.saturating_sub(now)
        };
        sending + restart
    }

    /// When [`Update::poll`] may have something again, if it waits for
    /// time rather than an answer.
    pub fn poll_timeout(&self) -> Option<Instant> {
        match self.waiting {
            Waiting::Until(t) => Some(t),
            _ => None,
        }
    }

    fn segment(&mut self, n: usize) -> Service {
        let data = rfu::segment_of(&self.image, n).to_vec();
        self.sent += data.len() as u64;
        Service::RfuData {
            campaign: self.header.campaign,
            segment: n as u16,
            data,
        }
    }

    /// The first board, ready at `now`, whose state `f` picks.
    fn first<T>(&self, now: Instant, f: impl Fn(&BoardState) -> Option<T>) -> Option<(usize, T)> {
        self.targets
            .iter()
            .enumerate()
            .filter(|(_, t)| t.not_before <= now)
            .find_map(|(i, t)| f(&t.state).map(|x| (i, x)))
    }

    /// The earliest time a board that `f` picks but that is not ready yet
    /// will be.
    fn next_ready(&self, f: impl Fn(&BoardState) -> Option<Instant>) -> Option<Instant> {
        self.targets
            .iter()
            .filter_map(|t| f(&t.state).map(|at| at.max(t.not_before)))
            .min()
    }

    fn ask(&mut self, board: usize, s: Service) -> Option<Request> {
        self.waiting = Waiting::Answer(board);
        Some(Request::to(
            self.targets[board].address,
            Message::Service(s),
        ))
    }

    fn pace(&mut self, now: Instant) {
        self.waiting = Waiting::Until(now + self.config.gap);
    }

    /// The next request to hand to the requester now, if any. A request
    /// that expects an answer must be followed by [`Update::on_answer`].
    pub fn poll(&mut self, now: Instant) -> Option<Request> {
        match self.waiting {
            Waiting::Answer(_) => return None,
            Waiting::Until(t) if now < t => return None,
            _ => self.waiting = Waiting::Nothing,
        }
        let campaign = self.header.campaign;
        loop {
            match self.phase {
                Phase::Announce => {
                    if let Some((b, ())) =
                        self.first(now, |s| (*s == BoardState::Announcing).then_some(()))
                    {
                        return self.ask(b, Service::RfuHeader(self.header));
                    }
                    self.phase = Phase::Broadcast(0);
                }
                Phase::Broadcast(n) => {
                    let receiving = self
                        .targets
                        .iter()
                        .any(|t| matches!(t.state, BoardState::Receiving { .. }));
                    if n >= self.header.segments() || !receiving {
                        self.phase = Phase::Repair;
                        continue;
                    }
                    self.phase = Phase::Broadcast(n + 1);
                    self.pace(now);
                    let s = self.segment(n);
                    return Some(Request::all(Message::Service(s)));
                }
                Phase::Repair => {
                    // A board announced again gets its header first.
                    if let Some((b, ())) =
                        self.first(now, |s| (*s == BoardState::Announcing).then_some(()))
                    {
                        return self.ask(b, Service::RfuHeader(self.header));
                    }
                    // A board with segments to send again gets them, one by one.
                    let next = self.first(now, |s| match s {
                        BoardState::Receiving { missing, .. } => missing.first().copied(),
                        _ => None,
                    });
                    if let Some((b, n)) = next {
                        if let BoardState::Receiving { missing, .. } = &mut self.targets[b].state {
                            missing.remove(0);
                        }
                        let to = self.targets[b].address;
                        self.pace(now);
                        let s = self.segment(n);
                        return Some(Request::to(to, Message::Service(s)));
                    }
                    // Then each board still receiving is asked what it holds.
                    let asking = self.first(now, |s| match s {
                        BoardState::Receiving { missing, asked } if missing.is_empty() => {
                            Some(*asked)
                        }
                        _ => None,
                    });
                    if let Some((b, asked)) = asking {
                        // At most `repair_rounds` rounds (and a saved
                        // campaign's count may be anything up to 255).
                        let next = asked
                            .checked_add(1)
                            .filter(|_| asked <= self.config.repair_rounds);
                        let Some(next) = next else {
                            self.targets[b].state = BoardState::Failed(format!(
                                "segments still missing after {} repair rounds: the line to this board loses too much",
                                self.config.repair_rounds
                            ));
                            continue;
                        };
                        self.targets[b].state = BoardState::Receiving {
                            missing: Vec::new(),
                            asked: next,
                        };
                        return self.ask(b, Service::RfuStatusGet { campaign });
                    }
                    // The boards backing off wait; the others go on.
                    self.phase = Phase::Swap;
                }
                Phase::Swap => {
                    if self.first(now, |s| s.receiving().then_some(())).is_some() {
                        self.phase = Phase::Repair;
                        continue;
                    }
                    if let Some((b, ())) =
                        self.first(now, |s| (*s == BoardState::Complete).then_some(()))
                    {
                        let crc = self.header.crc;
                        return self.ask(b, Service::RfuSwap { campaign, crc });
                    }
                    let restart = self.config.restart;
                    // Restarted, or done before a resume: its release is read.
                    let back = self.targets.iter().position(|t| {
                        t.not_before <= now
                            && matches!(t.state, BoardState::Restarting(at)
                                if t.rechecked || now >= at + restart)
                    });
                    if let Some(b) = back {
                        return self.ask(b, Service::FwRelGet);
                    }
                    match self.next_ready(|s| match s {
                        BoardState::Announcing
                        | BoardState::Receiving { .. }
                        | BoardState::Complete => Some(0),
                        BoardState::Restarting(at) => Some(at + restart),
                        _ => None,
                    }) {
                        Some(t) => {
                            self.waiting = Waiting::Until(t.max(now + 1));
                            return None;
                        }
                        None => self.phase = Phase::Over,
                    }
                }
                Phase::Abort => {
                    let pending = self
                        .targets
                        .iter()
                        .position(|t| t.state.receiving() || t.state == BoardState::Complete);
                    if let Some(b) = pending {
                        return self.ask(b, Service::RfuAbort { campaign });
                    }
                    // Boards swapped already finish as they would.
                    self.phase = if self
                        .targets
                        .iter()
                        .any(|t| matches!(t.state, BoardState::Restarting(_)))
                    {
                        Phase::Swap
                    } else {
                        Phase::Over
                    };
                }
                Phase::Over => return None,
            }
        }
    }

    /// Stops the campaign: every board not swapped yet is told to forget
    /// it (RFU_ABORT) and keeps its release; a board already swapped
    /// finishes (its image runs). The answer to a request under way still
    /// comes to [`Update::on_answer`].
    pub fn abort(&mut self) {
        if self.phase != Phase::Over {
            self.phase = Phase::Abort;
            if matches!(self.waiting, Waiting::Until(_)) {
                self.waiting = Waiting::Nothing;
            }
        }
    }

    /// What became of the last request: the board's answer, or why there
    /// was none (the requester gave up).
    pub fn on_answer(&mut self, now: Instant, answer: Result<&Message, &str>) {
        let Waiting::Answer(b) = self.waiting else {
            return;
        };
        self.waiting = Waiting::Nothing;
        let state = core::mem::replace(&mut self.targets[b].state, BoardState::Announcing);
        if self.phase == Phase::Abort
            && !matches!(state, BoardState::Restarting(_) | BoardState::Done)
        {
            self.targets[b].state = match answer {
                Ok(Message::Ack { .. }) => BoardState::Aborted,
                // Not told: it forgets the campaign at its next restart,
                // and never swaps without being asked.
                Ok(_) | Err(_) => BoardState::Failed(
                    "aborted; it did not confirm (it forgets the segments at its next restart)"
                        .into(),
                ),
            };
            return;
        }
        self.targets[b].state = match (state, answer) {
            (state, Err(why)) => self.silent(b, now, state, why.into()),
            (BoardState::Announcing, Ok(Message::Ack { .. })) => BoardState::Receiving {
                missing: Vec::new(),
                asked: 0,
            },
            (BoardState::Announcing, Ok(Message::Error(_))) => self.silent(
                b,
                now,
                BoardState::Announcing,
                "refused the image (ask its RFU status for the reason)".into(),
            ),
            (BoardState::Receiving { asked, .. }, Ok(Message::Service(Service::RfuStatus(s)))) => {
                self.after_status(b, s, asked)
            }
            (BoardState::Complete, Ok(Message::Ack { .. })) => BoardState::Restarting(now),
            (BoardState::Complete, Ok(Message::Error(_))) => self.again(
                b,
                "refused the swap: the image it holds does not check".into(),
            ),
            (BoardState::Restarting(_), Ok(Message::Service(Service::FwRel { firmware, .. }))) => {
                let firmware = *firmware;
                self.targets[b].firmware = Some(firmware);
                // An image that states no release is judged by its swap's
                // ACK, the restart and the board answering.
                if self.header.release().is_none_or(|v| firmware == v) {
                    BoardState::Done
                } else if self.targets[b].rechecked {
                    // Done before a resume, not any more: announced again.
                    self.targets[b].rechecked = false;
                    self.again(b, format!("runs release {firmware} again"))
                } else {
                    BoardState::Failed(format!(
                        "came back on release {firmware}: the new image did not start and the board went back to the old one"
                    ))
                }
            }
            (state, Ok(other)) => {
                BoardState::Failed(format!("answered {} while {}", other.name(), state.words()))
            }
        };
    }

    /// Board `b` did not answer, or refused a header: tried again after
    /// the back-off, in the state it was in, or given up with `why`.
    fn silent(&mut self, b: usize, now: Instant, state: BoardState, why: String) -> BoardState {
        let t = &mut self.targets[b];
        if t.silences >= self.config.silences {
            return BoardState::Failed(why);
        }
        t.not_before = now + (self.config.backoff << t.silences);
        t.silences += 1;
        state
    }

    /// Board `b` lost the campaign or refused its swap: announced again
    /// (a board keeps the segments of a header it already holds), or
    /// given up with `why`.
    fn again(&mut self, b: usize, why: String) -> BoardState {
        let t = &mut self.targets[b];
        if t.restarts >= self.config.restarts {
            return BoardState::Failed(why);
        }
        t.restarts += 1;
        BoardState::Announcing
    }

    fn after_status(&mut self, b: usize, s: &Status, asked: u8) -> BoardState {
        let count = self.header.segments();
        if s.campaign != self.header.campaign
            || !matches!(s.state(), Some(RfuState::Receiving | RfuState::Complete))
        {
            return self.again(
                b,
                format!(
                    "lost the campaign (it restarted?): status {} for campaign {}",
                    s.state().map_or("unknown", |st| st.name()),
                    s.campaign
                ),
            );
        }
        let missing: Vec<usize> = s.missing(count).collect();
        if missing.is_empty() {
            BoardState::Complete
        } else {
            BoardState::Receiving { missing, asked }
        }
    }

    /// Every board's result in words.
    pub fn report(&self) -> Vec<(Address, String)> {
        self.targets
            .iter()
            .map(|t| {
                let words = match &t.state {
                    BoardState::Done => match (self.header.release(), t.firmware) {
                        (None, Some(f)) => format!(
                            "updated: it restarted and answers, reporting release {f} (the image states none)"
                        ),
                        _ => format!("updated to {}", self.header.version),
                    },
                    BoardState::Aborted => "not updated: the update was aborted".into(),
                    BoardState::Failed(why) => format!("not updated: {why}"),
                    _ => "in progress".into(),
                };
                (t.address, words)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::frame::FrameType;
    use alloc::vec;

    /// Hands `u` an answer, owned as tests build them.
    fn answer(u: &mut Update, now: Instant, a: Result<Message, String>) {
        u.on_answer(now, a.as_ref().map_err(String::as_str));
    }

    const NEW: Release = Release { major: 2, minor: 1 };

    fn board() -> Address {
        Address::from_u64(0x0080_E100_0007)
    }

    /// Campaign 9's status with the first segments held as `bits` says.
    fn held(state: RfuState, bits: u8) -> Status {
        let mut bitmap = vec![0u8; rfu::BITMAP_LEN];
        bitmap[0] = bits;
        Status {
            campaign: 9,
            state: state.byte(),
            reason: 0,
            received: bits.count_ones() as u16,
            bitmap,
        }
    }

    fn ack(code: u8) -> Result<Message, String> {
        Ok(Message::Ack {
            frame_type: FrameType::Service,
            echo: code,
        })
    }

    #[test]
    fn bad_campaigns_are_refused_in_words() {
        let c = UpdateConfig::default();
        assert!(Update::new(1, NEW, vec![], &[board()], c)
            .unwrap_err()
            .contains("1 to 61440"));
        assert!(Update::new(1, NEW, vec![0; 61_441], &[board()], c).is_err());
        assert!(Update::new(0, NEW, vec![0; 10], &[board()], c)
            .unwrap_err()
            .contains("reserved"));
        assert!(Update::new(1, NEW, vec![0; 10], &[], c).is_err());
    }

    /// One board, its conversation step by step: header, the segments
    /// broadcast one per gap, the status naming a lost one, that one
    /// again, the swap, the release read back after the restart.
    #[test]
    fn one_board_step_by_step() {
        let image: Vec<u8> = (0..200u32).map(|i| i as u8).collect();
        let c = UpdateConfig::default();
        let mut u = Update::new(9, NEW, image, &[board()], c).unwrap();
        let r = u.poll(0).unwrap();
        assert!(matches!(r.message, Message::Service(Service::RfuHeader(_))));
        assert_eq!(u.poll(0), None, "waits for the answer");
        answer(&mut u, 0, ack(0x0c));
        let mut t = 0;
        for n in 0..3 {
            let r = u.poll(t).unwrap();
            assert!(r.broadcast);
            assert!(
                matches!(r.message, Message::Service(Service::RfuData { segment, .. }) if segment == n)
            );
            assert_eq!(u.poll(t + c.gap - 1), None, "paced");
            t += c.gap;
        }
        let r = u.poll(t).unwrap();
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuStatusGet { campaign: 9 })
        ));
        let status = held(RfuState::Receiving, 0b101);
        answer(&mut u, t, Ok(Message::Service(Service::RfuStatus(status))));
        let r = u.poll(t).unwrap();
        assert!(!r.broadcast);
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuData { segment: 1, .. })
        ));
        t += c.gap;
        let r = u.poll(t).unwrap();
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuStatusGet { .. })
        ));
        let status = held(RfuState::Complete, 0b111);
        answer(&mut u, t, Ok(Message::Service(Service::RfuStatus(status))));
        let r = u.poll(t).unwrap();
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuSwap { campaign: 9, .. })
        ));
        answer(&mut u, t, ack(0x0e));
        assert_eq!(u.poll(t), None);
        assert_eq!(u.poll_timeout(), Some(t + c.restart));
        t += c.restart;
        let r = u.poll(t).unwrap();
        assert_eq!(r.message, Message::Service(Service::FwRelGet));
        answer(
            &mut u,
            t,
            Ok(Message::Service(Service::FwRel {
                firmware: NEW,
                stack: Release { major: 2, minor: 0 },
            })),
        );
        assert_eq!(u.poll(t), None);
        assert!(u.is_done());
        assert_eq!(u.report()[0].1, "updated to 2.1");
    }

    #[test]
    fn an_abort_tells_the_boards_not_swapped_to_forget_the_campaign() {
        let a2 = Address::from_u64(0x0080_E100_0008);
        let mut u = Update::new(
            1,
            NEW,
            vec![1; 100],
            &[board(), a2],
            UpdateConfig::default(),
        )
        .unwrap();
        u.poll(0).unwrap();
        answer(&mut u, 0, ack(0x0c));
        u.poll(0).unwrap();
        answer(&mut u, 0, ack(0x0c));
        let r = u.poll(0).unwrap();
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuData { .. })
        ));
        u.abort();
        for _ in 0..2 {
            let r = u.poll(1_000_000).unwrap();
            assert_eq!(
                r.message,
                Message::Service(Service::RfuAbort { campaign: 1 })
            );
            answer(&mut u, 1_000_000, ack(0x12));
        }
        assert_eq!(u.poll(1_000_000), None);
        assert!(u.is_done());
        assert!(u.boards().all(|(_, s)| *s == BoardState::Aborted));
        assert_eq!(u.report()[1].1, "not updated: the update was aborted");
    }

    #[test]
    fn a_board_that_does_not_answer_is_left_with_the_reason() {
        let mut u = Update::new(
            1,
            NEW,
            alloc::vec![1; 100],
            &[board()],
            UpdateConfig::default(),
        )
        .unwrap();
        let c = UpdateConfig::default();
        let mut t = 0;
        for n in 0..=c.silences {
            let r = u.poll(t).expect("the header again");
            assert!(matches!(r.message, Message::Service(Service::RfuHeader(_))));
            answer(&mut u, t, Err("did not answer 3 times".into()));
            if n < c.silences {
                assert_eq!(u.poll(t), None, "backs off");
                let wait = c.backoff << n;
                assert_eq!(u.poll_timeout(), Some(t + wait), "doubling");
                t += wait;
            }
        }
        assert_eq!(u.poll(t), None);
        assert!(u.is_done());
        assert!(u.report()[0].1.starts_with("not updated: did not answer"));
    }
}
