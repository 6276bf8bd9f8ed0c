//! Reading many boards at the speed of the line (docs/protocol-notes.md,
//! "Reads in slots"): broadcasts of SERVICE_READ_IN_SLOTS (13h, a
//! user-defined command, UM 4.5) each naming up to [`SlotRead::MAX`]
//! boards, one after another; each named board answers its HID reply in
//! its own slot, so no board waits for another's round trip. The boards
//! not heard are handed back as stragglers, for the caller to ask one by
//! one with ordinary unicast requests (the requester retries those).
//! Sans-IO: the caller sends the requests it is given and hands over
//! what boards say.

use super::discovery::Timing;
use super::frame::Address;
use super::hid::{self, Hid};
use super::message::Message;
use super::requester::Request;
use super::service::{names, Service, SlotRead};
use crate::time::{Instant, MS};
use alloc::vec::Vec;

/// From a board hearing the request to its first slot, ms: room for its
/// ballast to answer on its USART (Appendix A gives no figure; the
/// simulated ballast takes 5 ms, and the board's own HID timeout is
/// 100 ms).
pub const FIRST_MS: u8 = 20;

/// Room in each slot besides the reply and discovery's guard, ms: every
/// board hears the previous slot's reply, and its modem hands it over on
/// their UART before it takes the board's own (measured on the simulated
/// street through a concentrator board: with 50 ms slots a reply went
/// 11 ms late and half the street collided; with 62 ms, none of 100).
pub const HAND_OVER_MS: u8 = 12;

/// How a read runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadConfig {
    /// The HID `param_to_get` read from every board.
    pub param: u8,
    /// The line's timing (the slot length comes from it).
    pub timing: Timing,
    /// From a board hearing the request to its first slot, ms.
    pub first_ms: u8,
}

impl ReadConfig {
    /// Every lamp parameter (GET ALL, 0Ah) at B-PSK.
    pub const ALL: ReadConfig = ReadConfig {
        param: hid::ALL,
        timing: Timing::BPSK,
        first_ms: FIRST_MS,
    };

    /// One slot, ms (discovery's arithmetic, and [`HAND_OVER_MS`]): a HID reply of `param` on the line and the guard.
    pub fn slot_ms(&self) -> u8 {
        // A parameter not described gets the longest reply's slot.
        let value = hid::param(self.param)
            .or(hid::param(hid::ALL))
            .map_or(0, |d| d.len);
        // The data frame's payload: 'g', param, value.
        self.timing.slot_ms_for(2 + value) + HAND_OVER_MS
    }

    /// How long one request naming `boards` boards lasts at most (their
    /// addresses in full), from handing it over to the last slot's reply
    /// arriving.
    pub fn window(&self, boards: usize) -> crate::time::Duration {
        self.window_of(boards, 1 + 6 * boards)
    }

    /// [`ReadConfig::window`] of a request naming `boards`.
    pub fn window_naming(&self, boards: &[Address]) -> crate::time::Duration {
        self.window_of(boards.len(), names::len(boards))
    }

    fn window_of(&self, boards: usize, names: usize) -> crate::time::Duration {
        let request = 1 + SlotRead::FIXED + names;
        let slots = (self.first_ms as u64 + boards as u64 * self.slot_ms() as u64) * MS;
        self.timing.slotted(request, slots)
    }
}

/// A read of many boards in progress.
#[derive(Debug, Clone)]
pub struct ReadAll {
    config: ReadConfig,
    /// Boards not yet named in a request.
    queue: Vec<Address>,
    /// Boards named in the request under way, and when its window ends.
    named: Vec<Address>,
    window_ends: Option<Instant>,
    /// Every board asked, in order.
    asked: Vec<Address>,
    /// The values heard, by board.
    heard: Vec<(Address, Vec<u8>)>,
    /// Requests sent.
    requests: usize,
}

impl ReadAll {
    /// Starts reading `boards` now; returns the read and its first
    /// request (`None` when there is nobody to read).
    pub fn start(
        now: Instant,
        boards: &[Address],
        config: ReadConfig,
    ) -> (ReadAll, Option<Request>) {
        let mut r = ReadAll {
            config,
            queue: boards.to_vec(),
            named: Vec::new(),
            window_ends: None,
            asked: boards.to_vec(),
            heard: Vec::new(),
            requests: 0,
        };
        let first = r.next(now);
        (r, first)
    }

    fn next(&mut self, now: Instant) -> Option<Request> {
        let n = SlotRead::fitting(&self.queue);
        if n == 0 {
            self.named.clear();
            self.window_ends = None;
            return None;
        }
        self.named = self.queue.drain(..n).collect();
        self.window_ends = Some(now + self.config.window_naming(&self.named));
        self.requests += 1;
        let read = SlotRead {
            slot_ms: self.config.slot_ms(),
            param: self.config.param,
            first_ms: self.config.first_ms,
            addresses: self.named.clone(),
        };
        Some(Request::all(Message::Service(Service::ReadInSlots(read))))
    }

    /// A frame that came unasked: a HID reply of the parameter read from
    /// a board asked is recorded. Whether it was one.
    pub fn on_message(&mut self, address: Address, message: &Message) -> bool {
        let Message::Hid(Hid::Reply { param, value }) = message else {
            return false;
        };
        if *param != self.config.param || !self.asked.contains(&address) {
            return false;
        }
        match self.heard.iter_mut().find(|(a, _)| *a == address) {
            Some(h) => h.1 = value.clone(),
            None => self.heard.push((address, value.clone())),
        }
        true
    }

    /// When [`ReadAll::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.window_ends
    }

    /// The window is over: the next request, or `None` when every board
    /// was named.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<Request> {
        if self.window_ends.is_some_and(|t| t <= now) {
            return self.next(now);
        }
        None
    }

    /// Whether every request's window is over.
    pub fn is_done(&self) -> bool {
        self.window_ends.is_none()
    }

    /// Requests sent so far.
    pub fn requests(&self) -> usize {
        self.requests
    }

    /// The values heard, by board, in the order they came.
    pub fn heard(&self) -> &[(Address, Vec<u8>)] {
        &self.heard
    }

    /// The boards asked and not heard, in the order they were asked: to
    /// be asked one by one.
    pub fn stragglers(&self) -> Vec<Address> {
        self.asked
            .iter()
            .filter(|a| !self.heard.iter().any(|(h, _)| h == *a))
            .copied()
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn board(i: u8) -> Address {
        Address([0, 0x80, 0xE1, 0, 1, i])
    }

    fn reply(value: u8) -> Message {
        Message::Hid(Hid::Reply {
            param: hid::ALL,
            value: alloc::vec![value; 24],
        })
    }

    fn named(r: &Request) -> Vec<Address> {
        match &r.message {
            Message::Service(Service::ReadInSlots(s)) => s.addresses.clone(),
            m => panic!("not a read in slots: {m:?}"),
        }
    }

    #[test]
    fn a_slot_holds_a_hid_reply_of_all_parameters_at_b_psk() {
        // 2 + 24 payload bytes, 17 more on the line, 7.5 ms of sync and
        // 6 ms of guard at 833 µs a byte, and the hand-over.
        assert_eq!(ReadConfig::ALL.slot_ms(), 50 + HAND_OVER_MS);
        // Discovery's slot is the same arithmetic for 6 bytes.
        assert_eq!(Timing::BPSK.slot_ms(), Timing::BPSK.slot_ms_for(6));
    }

    #[test]
    fn a_hundred_and_twenty_boards_take_three_requests_and_the_silent_are_stragglers() {
        let boards: Vec<Address> = (0..120).map(board).collect();
        let (mut r, first) = ReadAll::start(0, &boards, ReadConfig::ALL);
        let mut now;
        let mut requests = alloc::vec![first.expect("a request")];
        loop {
            let last = requests.last().expect("one");
            assert!(last.broadcast);
            for a in named(last) {
                // Board 7 and board 83 stay silent; board 199 was not asked.
                if a != board(7) && a != board(83) {
                    assert!(r.on_message(a, &reply(a.0[5])));
                }
            }
            assert!(!r.on_message(board(199), &reply(1)));
            now = r.poll_timeout().expect("a window");
            match r.handle_timeout(now) {
                Some(q) => requests.push(q),
                None => break,
            }
        }
        assert!(r.is_done());
        let sizes: Vec<usize> = requests.iter().map(|q| named(q).len()).collect();
        assert_eq!(sizes, [SlotRead::MOST, SlotRead::MOST, 20]);
        assert_eq!(r.stragglers(), [board(7), board(83)]);
        assert_eq!(r.heard().len(), 118);
        assert_eq!(r.heard()[0], (board(0), alloc::vec![0; 24]));
        let c = ReadConfig::ALL;
        let windows: crate::time::Duration = boards
            .chunks(SlotRead::MOST)
            .map(|b| c.window_naming(b))
            .sum();
        assert_eq!(now, windows);
        // 120 boards in about 7.8 s (stop-and-wait: about 13 s).
        assert!((7_700 * MS..7_900 * MS).contains(&now), "{now}");
    }

    #[test]
    fn the_window_is_not_over_before_its_time() {
        let (mut r, _) = ReadAll::start(0, &[board(1)], ReadConfig::ALL);
        let end = r.poll_timeout().expect("a window");
        assert_eq!(r.handle_timeout(end - 1), None);
        assert!(!r.is_done());
        assert_eq!(r.handle_timeout(end), None);
        assert!(r.is_done());
        assert_eq!(r.stragglers(), [board(1)]);
    }

    #[test]
    fn nobody_to_read_is_done_at_once() {
        let (r, first) = ReadAll::start(0, &[], ReadConfig::ALL);
        assert!(first.is_none());
        assert!(r.is_done());
        assert_eq!(r.requests(), 0);
    }

    #[test]
    fn the_request_round_trips_and_too_many_boards_are_refused_in_words() {
        let boards: Vec<Address> = (0..15).map(board).collect();
        let (_, q) = ReadAll::start(0, &boards, ReadConfig::ALL);
        let Message::Service(s) = q.expect("a request").message else {
            panic!("a service request")
        };
        let p = s.payload();
        // The five bytes every board shares once, then one byte each.
        assert_eq!(p.len(), 1 + 3 + 1 + 5 + 15);
        assert_eq!(
            &p[..10],
            [0x13, 62, hid::ALL, FIRST_MS, 5, 0, 0x80, 0xE1, 0, 1]
        );
        assert_eq!(Service::parse(&p), Ok(s.clone()));
        assert_eq!(s.validate(), Ok(()));
        assert!(Service::parse(&p[..9]).is_err());
        let Service::ReadInSlots(mut over) = s else {
            unreachable!()
        };
        over.addresses = (0..=SlotRead::MOST as u8).map(board).collect();
        let e = Service::ReadInSlots(over.clone()).validate().unwrap_err();
        assert_eq!(
            alloc::string::ToString::to_string(&e),
            "addresses: a request names at most 50 of these boards, not 51"
        );
        // Addresses that share nothing take six bytes each: 15 fit.
        over.addresses = (0..16u8).map(|i| Address([i, 1, 2, 3, 4, 5])).collect();
        let e = Service::ReadInSlots(over).validate().unwrap_err();
        assert_eq!(
            alloc::string::ToString::to_string(&e),
            "addresses: a request names at most 15 of these boards, not 16"
        );
    }
}
