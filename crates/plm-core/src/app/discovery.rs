//! Network discovery (SERVICE_NET_DISCOVER_REQ, 0Bh), in rounds. The
//! seed names the command only; the procedure is decided here
//! (docs/protocol-notes.md, "Discovery"):
//!
//! 1. the concentrator broadcasts `[session, window]`;
//! 2. every board not yet acknowledged in that session answers once, at a
//!    random moment within the window (so that answers rarely collide);
//! 3. the concentrator acknowledges each answer with an APP_ACK_FRAME
//!    `[01h, 0Bh]`: that board stays quiet for the rest of the session;
//! 4. after the window, a round that found someone new is followed by
//!    another (the answers that collided come again), with a window sized
//!    for twice as many boards as that round found (fewer are left each
//!    time, and a window too short would hide them all in collisions);
//!    a round that found nobody ends the discovery.
//!
//! Sans-IO: the caller sends the requests and frames it is given.

use super::frame::{Address, AppFrame};
use super::message::Message;
use super::requester::Request;
use super::service::{Discovered, Service};
use crate::time::{Duration, Instant, MS};
use alloc::collections::BTreeMap;

/// Time after a round's window for the last answers to arrive (an
/// answer and its ACK take about 0.1 s on the line at B-PSK).
pub const ROUND_MARGIN: Duration = 1_000 * MS;

/// A discovery in progress.
#[derive(Debug, Clone)]
pub struct Discovery {
    session: u8,
    window: u8,
    max_rounds: u8,
    round: u8,
    round_ends: Instant,
    new_in_round: usize,
    found: BTreeMap<Address, Discovered>,
    done: bool,
}

impl Discovery {
    /// Starts a discovery now; returns it and the broadcast to send.
    /// `window` is in seconds (1-60): about 0.1 s per board expected
    /// keeps collisions rare.
    pub fn start(now: Instant, session: u8, window: u8, max_rounds: u8) -> (Discovery, Request) {
        let mut d = Discovery {
            session,
            window: window.clamp(1, 60),
            max_rounds: max_rounds.max(1),
            round: 0,
            round_ends: 0,
            new_in_round: 0,
            found: BTreeMap::new(),
            done: false,
        };
        let r = d.next_round(now);
        (d, r)
    }

    /// A window long enough for `boards` answers (1-60 s): 0.1 s each,
    /// so that an answer and its ACK rarely meet another.
    pub fn window_for(boards: usize) -> u8 {
        (boards / 10 + 1).min(60) as u8
    }

    fn next_round(&mut self, now: Instant) -> Request {
        self.round += 1;
        self.new_in_round = 0;
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
        if self.found.insert(address, *d).is_none() {
            self.new_in_round += 1;
        }
        Some(message.ack().to(address))
    }

    /// When [`Discovery::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        (!self.done).then_some(self.round_ends)
    }

    /// The round is over: the next round's broadcast, or `None` when the
    /// discovery is done.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<Request> {
        if self.done || now < self.round_ends {
            return None;
        }
        if self.new_in_round > 0 && self.round < self.max_rounds {
            self.window = self
                .window
                .min(Discovery::window_for(2 * self.new_in_round));
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

    /// The boards found, by address.
    pub fn found(&self) -> &BTreeMap<Address, Discovered> {
        &self.found
    }
}
