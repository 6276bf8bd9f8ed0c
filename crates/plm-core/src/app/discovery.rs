//! Network discovery (SERVICE_NET_DISCOVER_REQ, 0Bh). Seed 004 names the
//! command only; the rule is decided here (docs/protocol-notes.md,
//! "Discovery"). Rule 2 is framed slotted ALOHA:
//!
//! 1. the concentrator broadcasts a [`SlotFrame`]: session, frame number,
//!    slot count and length, the share of boards that answers, and the
//!    addresses it heard in the previous frame;
//! 2. a board named in it stays quiet for the rest of the session; any
//!    other answers once, in the slot [`reply_slot`] gives it (or sits
//!    the frame out when its draw is above the share) ([`Responder`]);
//! 3. the concentrator listens to the whole frame and sends nothing
//!    inside it, counts the boards heard for the first time, updates
//!    its belief of how many are left ([`Estimate`]) and sizes the next
//!    frame for the most boards found per second;
//! 4. it stops when its belief that anybody is left falls below
//!    [`STOP_RISK`].
//!
//! Rule 1 ([`rounds`]) is the older rule, kept so that a board still on
//! it is found (`plm board discover --older-rule` runs its [`Rounds`]
//! after a discovery). Sans-IO: the caller sends the requests it
//! is given and hands over what boards say.

pub mod estimate;
pub mod rounds;

pub use estimate::{Estimate, Plan, LOSS_ALLOWED, STOP_RISK};
pub use rounds::Rounds;

use super::frame::{Address, AppFrame};
use super::message::Message;
use super::requester::Request;
use super::service::{names, Discovered, Service, SlotFrame};
use crate::time::{Duration, Instant, MS};
use alloc::vec::Vec;
use core::ops::Range;

/// Most slots in one frame: what it hears fits the next request most of
/// the time (at the best share a frame of 32 hears about 12; a request
/// names 15 boards whose addresses share nothing, 29 that share their
/// maker's three bytes). Larger frames found no board sooner.
pub const MAX_SLOTS: u8 = 32;

/// Frames in one discovery at most (the frame number is one byte).
pub const MAX_FRAMES: u8 = 250;

/// The line's timing, for slot lengths and for how long a frame lasts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timing {
    /// One byte on the line, µs.
    pub line_byte: Duration,
    /// A frame's preamble and unique word, µs.
    pub sync: Duration,
    /// From a request handed to the carrier to its first bit on the
    /// line, and from the last reply's end to its arrival at the host
    /// (serial links and firmware, each way; measured on the simulated
    /// street through a concentrator board: a reply in the last slot
    /// arrives 15-30 ms before a frame of 2 × 30 ms ends).
    pub relay: Duration,
}

/// Line bytes of a frame besides its payload: the line frame's header
/// (13) and the DL layer's own (length, CRC).
const FRAME_LINE_BYTES: u64 = 17;
/// Payload of a discovery reply (command and 5 data bytes).
const REPLY_PAYLOAD: usize = 6;
/// Room in a slot for a board's firmware answering late (the simulated
/// boards' jitter is at most 4 ms) and the clocks' drift.
const SLOT_GUARD: Duration = 6 * MS;

impl Timing {
    /// A line at `bps` bits per second (UM0932 2.1: B-PSK 9 600).
    pub const fn for_bit_rate(bps: u64) -> Timing {
        Timing {
            line_byte: 8_000_000 / bps,
            sync: 72 * 1_000_000 / 9_600,
            relay: 30 * MS,
        }
    }

    /// The product's default modulation, B-PSK.
    pub const BPSK: Timing = Timing::for_bit_rate(9_600);

    /// A line frame of `payload` bytes on the line, sync included.
    pub fn on_line(&self, payload: usize) -> Duration {
        self.sync + (FRAME_LINE_BYTES + payload as u64) * self.line_byte
    }

    /// One slot for a reply of `payload` bytes, ms: the reply on the line
    /// and the guard.
    pub fn slot_ms_for(&self, payload: usize) -> u8 {
        (self.on_line(payload) + SLOT_GUARD).div_ceil(MS).min(255) as u8
    }

    /// One discovery reply slot, ms.
    pub fn slot_ms(&self) -> u8 {
        self.slot_ms_for(REPLY_PAYLOAD)
    }

    /// How long an exchange of slots lasts, from handing over a request
    /// of `request_payload` bytes to the last reply's arrival, when the
    /// slots take `slots` after the request is heard.
    pub fn slotted(&self, request_payload: usize, slots: Duration) -> Duration {
        2 * self.relay + self.on_line(request_payload) + slots
    }

    /// How long a frame of `slots` whose request names `heard` lasts,
    /// from handing the request over to the last reply's arrival.
    pub fn frame(&self, slots: u8, heard: &[Address]) -> Duration {
        let request = 1 + SlotFrame::FIXED + names::len(heard);
        self.slotted(request, slots as u64 * self.slot_ms() as u64 * MS)
    }
}

/// How a discovery runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscoveryConfig {
    /// Session: boards heard in it stay quiet until the next.
    pub session: u8,
    /// How many boards are expected (a guess: half or twice the truth
    /// costs a few frames, no board).
    pub guess: usize,
    /// The line's timing.
    pub timing: Timing,
    /// Frames at most.
    pub max_frames: u8,
}

impl DiscoveryConfig {
    /// Session `session`, `guess` boards expected, B-PSK, rule 2 only.
    pub fn new(session: u8, guess: usize) -> DiscoveryConfig {
        DiscoveryConfig {
            session,
            guess,
            timing: Timing::BPSK,
            max_frames: MAX_FRAMES,
        }
    }
}

/// A discovery in progress.
#[derive(Debug, Clone)]
pub struct Discovery {
    config: DiscoveryConfig,
    estimate: Estimate,
    /// Frames sent.
    frames: u8,
    /// The frame listened to now, and when it is over.
    plan: Plan,
    frame_ends: Instant,
    /// Boards heard for the first time in this frame.
    new_in_frame: usize,
    /// Boards heard and not yet named in a request.
    to_silence: Vec<Address>,
    /// Boards found, in the order they were first heard.
    found: Vec<(Address, Discovered)>,
    done: bool,
}

impl Discovery {
    /// Starts a discovery now; returns it and the first frame's request.
    pub fn start(now: Instant, config: DiscoveryConfig) -> (Discovery, Request) {
        Discovery::resume(now, config, Vec::new())
    }

    /// Starts a discovery that already knows `known` (a street found
    /// earlier in this session): only new boards are looked for, with
    /// `config.guess` the number of new ones expected.
    pub fn resume(
        now: Instant,
        config: DiscoveryConfig,
        known: Vec<(Address, Discovered)>,
    ) -> (Discovery, Request) {
        let mut d = Discovery {
            config,
            estimate: Estimate::new(config.guess),
            frames: 0,
            plan: Plan::default(),
            frame_ends: now,
            new_in_frame: 0,
            to_silence: Vec::new(),
            found: known,
            done: false,
        };
        let r = d.next_frame(now);
        (d, r)
    }

    fn next_frame(&mut self, now: Instant) -> Request {
        let named = SlotFrame::fitting(&self.to_silence);
        let heard: Vec<Address> = self.to_silence.drain(..named).collect();
        self.plan = self
            .estimate
            .plan(&self.config.timing, &heard, self.to_silence.len());
        self.new_in_frame = 0;
        self.frame_ends = now + self.config.timing.frame(self.plan.slots, &heard);
        let frame = SlotFrame {
            session: self.config.session,
            frame: self.frames,
            slots: self.plan.slots,
            slot_ms: self.config.timing.slot_ms(),
            share: self.plan.share,
            heard,
        };
        self.frames += 1;
        Request::all(Message::Service(Service::DiscoverFrame(frame)))
    }

    /// A frame that came unasked: a discovery reply records its board.
    /// Returns the acknowledgement to send: none, rule 2 acknowledges
    /// nothing (rule 1, [`Rounds`], does).
    pub fn on_message(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        if let Message::Service(Service::DiscoverReply(d)) = message {
            if self.record(address, *d) {
                self.new_in_frame += 1;
            }
            // Heard again (its silencing was lost, or it restarted): it
            // is named again.
            if !self.to_silence.contains(&address) {
                self.to_silence.push(address);
            }
        }
        None
    }

    /// A board found otherwise (by the older rule, after this discovery):
    /// recorded among those found; whether it is new.
    pub fn record_found(&mut self, address: Address, d: Discovered) -> bool {
        self.record(address, d)
    }

    /// Records what a board said; whether it is new.
    fn record(&mut self, address: Address, d: Discovered) -> bool {
        match self.found.iter_mut().find(|(a, _)| *a == address) {
            Some(known) => {
                known.1 = d;
                false
            }
            None => {
                self.found.push((address, d));
                true
            }
        }
    }

    /// When [`Discovery::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        (!self.done).then_some(self.frame_ends)
    }

    /// The frame is over: the next request, or `None` when the
    /// discovery is done.
    pub fn handle_timeout(&mut self, now: Instant) -> Option<Request> {
        if self.done {
            return None;
        }
        if now < self.frame_ends {
            return None;
        }
        self.estimate.observe(&self.plan, self.new_in_frame);
        let sure = self.estimate.anybody() < STOP_RISK;
        if !sure && self.frames < self.config.max_frames {
            return Some(self.next_frame(now));
        }
        self.done = true;
        None
    }

    /// Whether it is over.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Frames sent so far.
    pub fn frames(&self) -> u8 {
        self.frames
    }

    /// The frame listened to now.
    pub fn plan(&self) -> Plan {
        self.plan
    }

    /// How many boards it believes are left to find (the median of its
    /// belief).
    pub fn left(&self) -> f64 {
        self.estimate.left()
    }

    /// The boards found, in the order they were first heard.
    pub fn found(&self) -> &[(Address, Discovered)] {
        &self.found
    }
}

/// A board's side of discovery: which requests it answers and when.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Responder {
    /// The session it was named (heard) in: quiet until another.
    quiet_in: Option<u8>,
    /// Bare requests heard: the frame number of the next one's draw, so
    /// that two boards that share a slot once do not share it each time.
    bare: u8,
}

impl Responder {
    /// A discovery request heard (rule 2, or bare): when to answer it and
    /// when to give the reply up, how long after hearing it (its slot's
    /// start and the frame's last slot's end), or `None` for silence. A
    /// reply late for its slot, having waited for the line to be quiet
    /// (the modem's "not now"), may still be heard in a free one; past
    /// the frame, a crowd's replies would spill onto the next request.
    pub fn on_request(&mut self, me: &Address, service: &Service) -> Option<Range<Duration>> {
        let bare;
        let frame = match service {
            Service::DiscoverAny => {
                bare = SlotFrame {
                    frame: self.bare,
                    ..SlotFrame::BARE
                };
                self.bare = self.bare.wrapping_add(1);
                &bare
            }
            Service::DiscoverFrame(f) => f,
            _ => return None,
        };
        if matches!(service, Service::DiscoverFrame(_)) {
            if self.quiet_in.is_some_and(|s| s != frame.session) {
                self.quiet_in = None;
            }
            if frame.heard.contains(me) {
                self.quiet_in = Some(frame.session);
            }
            if self.quiet_in.is_some() {
                return None;
            }
        }
        let slot_len = frame.slot_ms as u64 * MS;
        reply_slot(me, frame).map(|slot| slot as u64 * slot_len..frame.slots as u64 * slot_len)
    }
}

/// The slot (0-based) a board answers `frame` in, or `None` when its
/// draw is above the frame's share. The draw is FNV-1a (32 bits) of the
/// address, session and frame number, then MurmurHash3's finaliser: the
/// slot is the draw modulo the slots, the share test uses its top byte.
/// (A CRC would not do: it is linear, so two boards that collide once
/// would collide in every frame.)
pub fn reply_slot(address: &Address, frame: &SlotFrame) -> Option<u8> {
    let mut h: u32 = 0x811c_9dc5;
    for b in address.0.iter().chain(&[frame.session, frame.frame]) {
        h = (h ^ *b as u32).wrapping_mul(0x0100_0193);
    }
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^= h >> 16;
    ((h >> 24) as u8 <= frame.share).then(|| (h % frame.slots.max(1) as u32) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(session: u8, n: u8, slots: u8, share: u8) -> SlotFrame {
        SlotFrame {
            session,
            frame: n,
            slots,
            slot_ms: 33,
            share,
            heard: Vec::new(),
        }
    }

    fn board(i: u32) -> Address {
        let b = i.to_be_bytes();
        Address([0x00, 0x80, 0xE1, b[1], b[2], b[3]])
    }

    #[test]
    fn slots_spread_evenly_and_change_with_the_frame() {
        let mut count = [0usize; 8];
        for i in 0..8_000 {
            count[reply_slot(&board(i), &frame(1, 0, 8, 255)).unwrap() as usize] += 1;
        }
        assert!(count.iter().all(|c| (900..1_100).contains(c)), "{count:?}");
        // Two boards that collide in one frame rarely collide in the next.
        let (mut once, mut twice) = (0, 0);
        for i in 0..2_000 {
            let same = |n| {
                reply_slot(&board(i), &frame(1, n, 8, 255))
                    == reply_slot(&board(i + 1), &frame(1, n, 8, 255))
            };
            if same(0) {
                once += 1;
                twice += same(1) as usize;
            }
        }
        assert!(once > 150 && twice < once / 4, "{once} {twice}");
        // The share: about half answer at 127.
        let answering = (0..4_000)
            .filter(|i| reply_slot(&board(*i), &frame(1, 0, 8, 127)).is_some())
            .count();
        assert!((1_850..2_150).contains(&answering), "{answering}");
    }

    #[test]
    fn a_board_named_in_a_frame_stays_quiet_for_the_session() {
        let me = board(7);
        let mut r = Responder::default();
        assert!(r
            .on_request(&me, &Service::DiscoverFrame(frame(3, 0, 4, 255)))
            .is_some());
        let mut named = frame(3, 1, 4, 255);
        named.heard.push(me);
        assert_eq!(r.on_request(&me, &Service::DiscoverFrame(named)), None);
        assert_eq!(
            r.on_request(&me, &Service::DiscoverFrame(frame(3, 2, 4, 255))),
            None
        );
        // A bare request is answered all the same; a new session wakes it.
        assert!(r.on_request(&me, &Service::DiscoverAny).is_some());
        assert!(r
            .on_request(&me, &Service::DiscoverFrame(frame(4, 0, 4, 255)))
            .is_some());
    }

    #[test]
    fn the_slot_fits_a_reply_at_b_psk() {
        // 7.5 ms sync, 23 bytes at 833 µs, 6 ms of guard.
        assert_eq!(Timing::BPSK.slot_ms(), 33);
    }
}
