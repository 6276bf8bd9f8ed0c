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
//! A board that does not answer (after the requester's retries) or
//! refuses is left with its reason in words; the others go on. Every
//! request goes through the caller's requester one at a time: the engine
//! hands out the next one only when the last is over.

use super::frame::Address;
use super::message::Message;
use super::requester::Request;
use super::rfu::{self, Header, RfuState, Status};
use super::service::{Release, Service};
use crate::time::{Duration, Instant, MS};
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

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
}

impl Default for UpdateConfig {
    fn default() -> Self {
        UpdateConfig {
            gap: 250 * MS,
            repair_rounds: 5,
            restart: 8_000 * MS,
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
    boards: Vec<(Address, BoardState)>,
    phase: Phase,
    waiting: Waiting,
}

impl Update {
    /// A campaign that puts `image`, release `version`, on `targets`.
    pub fn new(
        campaign: u8,
        version: Release,
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
        Ok(Update {
            header: Header::of(campaign, version, &image),
            image,
            config,
            boards: targets
                .iter()
                .map(|a| (*a, BoardState::Announcing))
                .collect(),
            phase: Phase::Announce,
            waiting: Waiting::Nothing,
        })
    }

    /// The header every board gets.
    pub fn header(&self) -> Header {
        self.header
    }

    /// Every board and where it is.
    pub fn boards(&self) -> &[(Address, BoardState)] {
        &self.boards
    }

    /// Whether it is over (every board done or given up).
    pub fn is_done(&self) -> bool {
        self.phase == Phase::Over
    }

    /// When [`Update::poll`] may have something again, if it waits for
    /// time rather than an answer.
    pub fn poll_timeout(&self) -> Option<Instant> {
        match self.waiting {
            Waiting::Until(t) => Some(t),
            _ => None,
        }
    }

    fn segment(&self, n: usize) -> Service {
        Service::RfuData {
            campaign: self.header.campaign,
            segment: n as u16,
            data: rfu::segment_of(&self.image, n).to_vec(),
        }
    }

    fn first(&self, f: impl Fn(&BoardState) -> bool) -> Option<usize> {
        self.boards.iter().position(|(_, s)| f(s))
    }

    fn ask(&mut self, board: usize, s: Service) -> Option<Request> {
        self.waiting = Waiting::Answer(board);
        Some(Request::to(self.boards[board].0, Message::Service(s)))
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
        loop {
            match self.phase {
                Phase::Announce => {
                    if let Some(b) = self.first(|s| *s == BoardState::Announcing) {
                        return self.ask(b, Service::RfuHeader(self.header));
                    }
                    self.phase = Phase::Broadcast(0);
                }
                Phase::Broadcast(n) => {
                    let receiving = self
                        .first(|s| matches!(s, BoardState::Receiving { .. }))
                        .is_some();
                    if n >= self.header.segments() || !receiving {
                        self.phase = Phase::Repair;
                        continue;
                    }
                    self.phase = Phase::Broadcast(n + 1);
                    self.pace(now);
                    return Some(Request::all(Message::Service(self.segment(n))));
                }
                Phase::Repair => {
                    // A board with segments to send again gets them, one by one.
                    let next = self
                        .boards
                        .iter_mut()
                        .enumerate()
                        .find_map(|(i, (_, s))| match s {
                            BoardState::Receiving { missing, .. } if !missing.is_empty() => {
                                Some((i, missing.remove(0)))
                            }
                            _ => None,
                        });
                    if let Some((b, n)) = next {
                        let to = self.boards[b].0;
                        self.pace(now);
                        return Some(Request::to(to, Message::Service(self.segment(n))));
                    }
                    // Then each board still receiving is asked what it holds.
                    let asking = self
                        .boards
                        .iter()
                        .enumerate()
                        .find_map(|(i, (_, s))| match s {
                            BoardState::Receiving { missing, asked } if missing.is_empty() => {
                                Some((i, *asked))
                            }
                            _ => None,
                        });
                    if let Some((b, asked)) = asking {
                        if asked > self.config.repair_rounds {
                            self.boards[b].1 = BoardState::Failed(format!(
                                "segments still missing after {} repair rounds: the line to this board loses too much",
                                self.config.repair_rounds
                            ));
                            continue;
                        }
                        self.boards[b].1 = BoardState::Receiving {
                            missing: Vec::new(),
                            asked: asked + 1,
                        };
                        let campaign = self.header.campaign;
                        return self.ask(b, Service::RfuStatusGet { campaign });
                    }
                    self.phase = Phase::Swap;
                }
                Phase::Swap => {
                    if let Some(b) = self.first(|s| *s == BoardState::Complete) {
                        let campaign = self.header.campaign;
                        let crc = self.header.crc;
                        return self.ask(b, Service::RfuSwap { campaign, crc });
                    }
                    let restarting =
                        self.boards
                            .iter()
                            .enumerate()
                            .find_map(|(i, (_, s))| match s {
                                BoardState::Restarting(at) => Some((i, *at)),
                                _ => None,
                            });
                    match restarting {
                        Some((b, at)) if now >= at + self.config.restart => {
                            return self.ask(b, Service::FwRelGet);
                        }
                        Some((_, at)) => {
                            self.waiting = Waiting::Until(at + self.config.restart);
                            return None;
                        }
                        None => self.phase = Phase::Over,
                    }
                }
                Phase::Abort => {
                    let pending = self.first(|s| {
                        matches!(
                            s,
                            BoardState::Announcing
                                | BoardState::Receiving { .. }
                                | BoardState::Complete
                        )
                    });
                    if let Some(b) = pending {
                        let campaign = self.header.campaign;
                        return self.ask(b, Service::RfuAbort { campaign });
                    }
                    // Boards swapped already finish as they would.
                    self.phase = if self
                        .first(|s| matches!(s, BoardState::Restarting(_)))
                        .is_some()
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
        }
    }

    /// What became of the last request: the board's answer, or why there
    /// was none (the requester gave up).
    pub fn on_answer(&mut self, now: Instant, answer: Result<Message, String>) {
        let Waiting::Answer(b) = self.waiting else {
            return;
        };
        self.waiting = Waiting::Nothing;
        let state = core::mem::replace(&mut self.boards[b].1, BoardState::Announcing);
        if self.phase == Phase::Abort
            && !matches!(state, BoardState::Restarting(_) | BoardState::Done)
        {
            self.boards[b].1 = match answer {
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
        self.boards[b].1 = match (state, answer) {
            (_, Err(why)) => BoardState::Failed(format!("did not answer: {why}")),
            (BoardState::Announcing, Ok(Message::Ack { .. })) => BoardState::Receiving {
                missing: Vec::new(),
                asked: 0,
            },
            (BoardState::Announcing, Ok(Message::Error(_))) => {
                BoardState::Failed("refused the image (ask its RFU status for the reason)".into())
            }
            (BoardState::Receiving { asked, .. }, Ok(Message::Service(Service::RfuStatus(s)))) => {
                self.after_status(&s, asked)
            }
            (BoardState::Complete, Ok(Message::Ack { .. })) => BoardState::Restarting(now),
            (BoardState::Complete, Ok(Message::Error(_))) => {
                BoardState::Failed("refused the swap: the image it holds does not check".into())
            }
            (BoardState::Restarting(_), Ok(Message::Service(Service::FwRel { firmware, .. }))) => {
                if firmware == self.header.version {
                    BoardState::Done
                } else {
                    BoardState::Failed(format!(
                        "came back on release {firmware}: the new image did not start and the board went back to the old one"
                    ))
                }
            }
            (state, Ok(other)) => BoardState::Failed(format!(
                "answered {other:?} while {}",
                match state {
                    BoardState::Announcing => "announcing",
                    BoardState::Receiving { .. } => "receiving",
                    BoardState::Complete => "swapping",
                    BoardState::Restarting(_) => "restarting",
                    _ => "over",
                }
            )),
        };
    }

    fn after_status(&self, s: &Status, asked: u8) -> BoardState {
        let count = self.header.segments();
        if s.campaign != self.header.campaign
            || !matches!(s.state(), Some(RfuState::Receiving | RfuState::Complete))
        {
            return BoardState::Failed(format!(
                "lost the campaign (it restarted?): status {} for campaign {}",
                s.state().map_or("unknown", |st| st.name()),
                s.campaign
            ));
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
        self.boards
            .iter()
            .map(|(a, s)| {
                let words = match s {
                    BoardState::Done => format!("updated to {}", self.header.version),
                    BoardState::Aborted => "not updated: the update was aborted".into(),
                    BoardState::Failed(why) => format!("not updated: {why}"),
                    other => format!("in progress ({other:?})"),
                };
                (*a, words)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::frame::FrameType;
    use alloc::vec;

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
        u.on_answer(0, ack(0x0c));
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
        u.on_answer(t, Ok(Message::Service(Service::RfuStatus(status))));
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
        u.on_answer(t, Ok(Message::Service(Service::RfuStatus(status))));
        let r = u.poll(t).unwrap();
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuSwap { campaign: 9, .. })
        ));
        u.on_answer(t, ack(0x0e));
        assert_eq!(u.poll(t), None);
        assert_eq!(u.poll_timeout(), Some(t + c.restart));
        t += c.restart;
        let r = u.poll(t).unwrap();
        assert_eq!(r.message, Message::Service(Service::FwRelGet));
        u.on_answer(
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
        u.on_answer(0, ack(0x0c));
        u.poll(0).unwrap();
        u.on_answer(0, ack(0x0c));
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
            u.on_answer(1_000_000, ack(0x12));
        }
        assert_eq!(u.poll(1_000_000), None);
        assert!(u.is_done());
        assert!(u.boards().iter().all(|(_, s)| *s == BoardState::Aborted));
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
        u.poll(0).unwrap();
        u.on_answer(0, Err("did not answer 3 times".into()));
        assert_eq!(u.poll(0), None);
        assert!(u.is_done());
        assert!(u.report()[0].1.starts_with("not updated: did not answer"));
    }
}
