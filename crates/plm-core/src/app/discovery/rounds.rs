//! Discovery rule 1, the older rule: rounds and ACKs. Kept so that a
//! board still on it is found (docs/protocol-notes.md, "Discovery"):
//!
//! 1. the concentrator broadcasts `[session, window]`;
//! 2. every board not yet acknowledged in that session answers once, at a
//!    random moment within the window (so that answers rarely collide);
//! 3. the concentrator acknowledges each answer with an APP_ACK_FRAME
//!    `[01h, 0Bh]`: that board stays quiet for the rest of the session;
//! 4. after the window, a round that heard any answer is followed by
//!    another (the answers that collided, and the boards whose ACK was
//!    lost, come again); [`Rounds::next_window`] sizes it and says
//!    when silence means the street has answered.
//!
//! Sans-IO: the caller sends the requests and frames it is given.

use super::super::frame::{Address, AppFrame};
use super::super::message::Message;
use super::super::requester::Request;
use super::super::service::{Discovered, Service};
use crate::time::{Duration, Instant, MS};
use alloc::vec::Vec;

/// Answers a second of window holds with few collisions: an answer and
/// its ACK take about 0.1 s on the line at B-PSK.
pub const BOARDS_PER_SECOND: usize = 10;

/// Time after a round's window for the last answers to arrive (an
/// answer and its ACK take about 0.1 s on the line at B-PSK).
pub const ROUND_MARGIN: Duration = 1_000 * MS;

/// A rule-1 discovery in progress.
#[derive(Debug, Clone)]
pub struct Rounds {
    session: u8,
    window: u8,
    max_rounds: u8,
    round: u8,
    round_ends: Instant,
    heard_in_round: usize,
    /// This round checks a silence with a wider window.
    confirming: bool,
    /// Boards found before this round.
    found_before: usize,
    /// New boards the previous round heard, if its window was this one.
    previous: Option<usize>,
    /// The last round heard a quarter of what its window holds.
    crowded: bool,
    /// Boards found, in the order they were heard (a list: a street is
    /// at most a few hundred boards, and the console carries no map code
    /// for it).
    found: Vec<(Address, Discovered)>,
    done: bool,
}

impl Rounds {
    /// Starts a discovery now; returns it and the broadcast to send.
    /// `window` is in seconds (1-60): about 0.1 s per board expected
    /// keeps collisions rare.
    pub fn start(now: Instant, session: u8, window: u8, max_rounds: u8) -> (Rounds, Request) {
        let mut d = Rounds {
            session,
            window: window.clamp(1, 60),
            max_rounds: max_rounds.max(1),
            round: 0,
            round_ends: 0,
            heard_in_round: 0,
            confirming: false,
            found_before: 0,
            previous: None,
            crowded: false,
            found: Vec::new(),
            done: false,
        };
        let r = d.next_round(now);
        (d, r)
    }

    /// A window long enough for `boards` answers (1-60 s): 0.1 s each,
    /// so that an answer and its ACK rarely meet another.
    pub fn window_for(boards: usize) -> u8 {
        (boards / BOARDS_PER_SECOND + 1).min(60) as u8
    }

    /// What follows a round of `window` seconds that heard `heard` new
    /// boards (`previous`: what the round before heard, if its window was
    /// the same): the next round's window, or `None` to stop. In a crowd
    /// most answers collide unheard, so a crowded window can hear little
    /// or nothing even when many boards are left:
    /// - a round that heard a quarter of what its window holds was
    ///   crowded: the window doubles;
    /// - a round that heard no fewer than the one before in the same
    ///   window was crowded too: with few boards left each round hears
    ///   fewer than the last (those heard are acknowledged and stay
    ///   quiet), while in a crowd collisions keep the count low and flat;
    /// - a silent round after a crowded one, or before anybody was heard,
    ///   doubles the window (up to 60 s, after which silence is taken as
    ///   nobody there);
    /// - any other silent round is believed only once a round with twice
    ///   its window (`confirming`) is silent too: a crowd that collided
    ///   whole is silent as well, and a wider window breaks it up;
    /// - otherwise the window stays (shrinking it on a count collisions
    ///   may have cut would hide the boards still silent).
    pub fn next_window(
        window: u8,
        heard: usize,
        previous: Option<usize>,
        was_crowded: bool,
        ever_heard: bool,
        confirming: bool,
    ) -> Option<u8> {
        let holds = window as usize * BOARDS_PER_SECOND;
        let double = (window < 60).then(|| window.saturating_mul(2).min(60));
        match heard {
            0 if was_crowded || !ever_heard || !confirming => double,
            0 => None,
            h if 4 * h >= holds => double.or(Some(60)),
            h if previous.is_some_and(|p| h >= p) => double.or(Some(60)),
            _ => Some(window),
        }
    }

    fn next_round(&mut self, now: Instant) -> Request {
        self.round += 1;
        self.heard_in_round = 0;
        self.found_before = self.found.len();
        self.round_ends = now + self.window as u64 * 1_000 * MS + ROUND_MARGIN;
        Request::all(Message::Service(Service::Discover {
            session: self.session,
            window: self.window,
        }))
    }

    /// A frame that came unasked: if it is a discovery answer, records
    /// the board and returns the acknowledgement to send it.
    pub fn on_message(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        let Message::Service(Service::DiscoverReply(d)) = message else {
            return None;
        };
        match self.found.iter_mut().find(|(a, _)| *a == address) {
            Some(known) => known.1 = *d,
            None => self.found.push((address, *d)),
        }
        self.heard_in_round += 1;
        Some(message.ack().to(address))
    }

    /// When [`Rounds::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        (!self.done).then_some(self.round_ends)
    }

    /// The round is over: the next round's broadcast, or `None` when the
    /// discovery is done.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<Request> {
        if self.done || now < self.round_ends {
            return None;
        }
        let holds = self.window as usize * BOARDS_PER_SECOND;
        let heard = self.found.len() - self.found_before;
        let next = Rounds::next_window(
            self.window,
            heard,
            self.previous,
            self.crowded,
            !self.found.is_empty(),
            self.confirming,
        );
        // The next round, twice as wide, checks this silence.
        self.confirming = heard == 0 && !self.found.is_empty();
        self.crowded = 4 * heard >= holds || self.previous.is_some_and(|p| heard > 0 && heard >= p);
        if let (Some(w), true) = (next, self.round < self.max_rounds) {
            self.previous = (w == self.window).then_some(heard);
            self.window = w;
            return Some(self.next_round(now));
        }
        self.done = true;
        None
    }

    /// Whether it is over.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Rounds so far.
    pub fn round(&self) -> u8 {
        self.round
    }

    /// The boards found, in the order they were first heard.
    pub fn found(&self) -> &[(Address, Discovered)] {
        &self.found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crowded_rounds_widen_and_silence_ends_only_after_a_quiet_round() {
        // 2 s hold 20 answers: 5 heard is a crowd, 4 is not.
        assert_eq!(Rounds::next_window(2, 5, None, false, true, false), Some(4));
        assert_eq!(Rounds::next_window(2, 4, None, false, true, false), Some(2));
        // Fewer than the round before in the same window: the crowd thins.
        assert_eq!(
            Rounds::next_window(4, 3, Some(6), false, true, false),
            Some(4)
        );
        // As many or more: a crowd keeps the count flat.
        assert_eq!(
            Rounds::next_window(4, 6, Some(6), false, true, false),
            Some(8)
        );
        // Silence after a quiet round: done; after a crowd, or before
        // anybody was heard: look again with a wider window.
        assert_eq!(Rounds::next_window(8, 0, Some(3), false, true, true), None);
        assert_eq!(
            Rounds::next_window(8, 0, Some(3), false, true, false),
            Some(16)
        );
        assert_eq!(Rounds::next_window(8, 0, None, true, true, false), Some(16));
        assert_eq!(
            Rounds::next_window(8, 0, None, false, false, false),
            Some(16)
        );
        assert_eq!(Rounds::next_window(60, 0, None, true, false, false), None);
        assert_eq!(
            Rounds::next_window(60, 400, None, true, true, false),
            Some(60)
        );
    }
}
