//! The host side of the application protocol, sans-IO like the link
//! engines: requests go out as [`AppFrame`]s, answers come back as
//! frames, time comes in as an argument. The carrier (the board's USART,
//! or a bare ST7580 on the power line, [`super::carrier`]) only moves
//! frames.
//!
//! - A unicast request waits for the answer its message names
//!   ([`Message::expects`]): an ACK, a reply, or an error frame from the
//!   same board. Requests that expect nothing (broadcasts, resets) are
//!   done once handed to the carrier.
//! - No answer within the timeout: the request is sent again, waiting a
//!   little longer each time (the timeout times the attempt), at most
//!   `max_attempts` times; then it fails, in words.
//! - At most one request per board is in flight (the seed has no
//!   sequence numbers: an answer is matched by board and kind), and at
//!   most `max_in_flight` in all. The default is 1: the power line is
//!   one half-duplex channel without carrier sense (the ST7580's PHY and
//!   DL layers have none), so a second request sent while the first
//!   board answers only collides with its answer.

use super::frame::{Address, AppFrame};
use super::message::{Expect, Message, MessageError};
use crate::time::{Duration, Instant, MS};
use alloc::collections::VecDeque;
use alloc::string::String;
use alloc::vec::Vec;

/// Settings of the requester.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RequesterConfig {
    /// How long the first attempt waits for its answer.
    pub timeout: Duration,
    /// Attempts before a request fails.
    pub max_attempts: u8,
    /// Requests in flight at once (to different boards).
    pub max_in_flight: usize,
}

impl Default for RequesterConfig {
    /// 1.5 s covers a request and its reply over the power line at B-PSK
    /// with the ST7580 host interfaces at both ends, a few times over.
    fn default() -> Self {
        RequesterConfig {
            timeout: 1_500 * MS,
            max_attempts: 3,
            max_in_flight: 1,
        }
    }
}

/// Identifies a request in later events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RequestId(pub u32);

/// A request for one board or, broadcast, for all.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// The board (ignored by the line for a broadcast).
    pub address: Address,
    /// Sent to every board.
    pub broadcast: bool,
    /// What to say.
    pub message: Message,
}

impl Request {
    /// To one board.
    pub fn to(address: Address, message: Message) -> Request {
        Request {
            address,
            broadcast: false,
            message,
        }
    }

    /// To every board.
    pub fn all(message: Message) -> Request {
        Request {
            address: Address::BROADCAST,
            broadcast: true,
            message,
        }
    }

    fn frame(&self) -> AppFrame {
        if self.broadcast {
            self.message.broadcast(self.address)
        } else {
            self.message.to(self.address)
        }
    }

    fn expects(&self) -> Expect {
        if self.broadcast {
            Expect::Nothing
        } else {
            self.message.expects()
        }
    }
}

/// What became of a request, and what else came.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AppEvent {
    /// The board answered (an error frame is an answer too).
    Answered {
        /// The request.
        id: RequestId,
        /// The board.
        address: Address,
        /// Its answer.
        answer: Message,
        /// From the last attempt handed to the carrier to the answer.
        rtt: Duration,
    },
    /// A request that expects no answer was handed to the carrier.
    Sent {
        /// The request.
        id: RequestId,
    },
    /// No answer after every attempt.
    Failed {
        /// The request.
        id: RequestId,
        /// The board.
        address: Address,
        /// Why, in words.
        reason: String,
    },
    /// An attempt went unanswered; the request is sent again.
    Retry {
        /// The request.
        id: RequestId,
        /// The board.
        address: Address,
        /// Attempts made so far.
        attempt: u8,
    },
    /// A frame that answers no request in flight (discovery replies,
    /// late answers, a board talking first).
    Unsolicited {
        /// The board it came from.
        address: Address,
        /// Sent to all.
        broadcast: bool,
        /// What it says.
        message: Message,
    },
    /// A frame whose payload does not fit its type.
    Malformed {
        /// The board it came from.
        address: Address,
        /// Why.
        error: MessageError,
    },
}

impl AppEvent {
    /// The request this event ends (answered, failed, or sent when no
    /// answer is expected); `None` for the others.
    pub fn fate_of(&self) -> Option<RequestId> {
        match self {
            AppEvent::Answered { id, .. } | AppEvent::Failed { id, .. } | AppEvent::Sent { id } => {
                Some(*id)
            }
            _ => None,
        }
    }
}

#[derive(Debug, Clone)]
struct InFlight {
    id: RequestId,
    request: Request,
    expect: Expect,
    attempts: u8,
    sent_at: Instant,
    deadline: Instant,
}

/// The requester.
#[derive(Debug, Clone)]
pub struct Requester {
    config: RequesterConfig,
    next_id: u32,
    queue: VecDeque<(RequestId, Request)>,
    in_flight: Vec<InFlight>,
    outbox: VecDeque<AppFrame>,
    events: VecDeque<AppEvent>,
}

impl Requester {
    /// A requester with `config`.
    pub fn new(config: RequesterConfig) -> Self {
        Requester {
            config,
            next_id: 0,
            queue: VecDeque::new(),
            in_flight: Vec::new(),
            outbox: VecDeque::new(),
            events: VecDeque::new(),
        }
    }

    /// The settings in use.
    pub fn config(&self) -> RequesterConfig {
        self.config
    }

    /// Changes the settings (for requests sent from now on).
    pub fn set_config(&mut self, config: RequesterConfig) {
        self.config = config;
    }

    /// Requests queued or in flight.
    pub fn pending(&self) -> usize {
        self.queue.len() + self.in_flight.len()
    }

    /// Queues a request; its fate comes as an event with the returned id.
    pub fn submit(&mut self, now: Instant, request: Request) -> RequestId {
        let id = RequestId(self.next_id);
        self.next_id = self.next_id.wrapping_add(1);
        self.queue.push_back((id, request));
        self.dispatch(now);
        id
    }

    /// Fails every request queued or in flight (the carrier is gone).
    pub fn abort_all(&mut self, reason: &str) {
        let gone = self
            .queue
            .drain(..)
            .map(|(id, r)| (id, r.address))
            .chain(self.in_flight.drain(..).map(|f| (f.id, f.request.address)))
            .collect::<Vec<_>>();
        for (id, address) in gone {
            self.events.push_back(AppEvent::Failed {
                id,
                address,
                reason: reason.into(),
            });
        }
        self.outbox.clear();
    }

    /// A frame from the boards' side: the address is the board's.
    pub fn handle_frame(&mut self, now: Instant, frame: &AppFrame) {
        let message = match Message::of(frame) {
            Ok(m) => m,
            Err(error) => {
                self.events.push_back(AppEvent::Malformed {
                    address: frame.address,
                    error,
                });
                return;
            }
        };
        let hit = self
            .in_flight
            .iter()
            .position(|f| f.request.address == frame.address && f.expect.answered_by(&message));
        match hit {
            Some(i) => {
                let f = self.in_flight.swap_remove(i);
                self.events.push_back(AppEvent::Answered {
                    id: f.id,
                    address: frame.address,
                    answer: message,
                    rtt: now.saturating_sub(f.sent_at),
                });
                self.dispatch(now);
            }
            None => self.events.push_back(AppEvent::Unsolicited {
                address: frame.address,
                broadcast: frame.broadcast,
                message,
            }),
        }
    }

    /// Runs what is due at `now`.
    pub fn handle_timeout(&mut self, now: Instant) {
        let mut i = 0;
        while i < self.in_flight.len() {
            if self.in_flight[i].deadline > now {
                i += 1;
                continue;
            }
            let f = &mut self.in_flight[i];
            if f.attempts < self.config.max_attempts {
                f.attempts += 1;
                f.sent_at = now;
                f.deadline = now + self.config.timeout * f.attempts as u64;
                self.events.push_back(AppEvent::Retry {
                    id: f.id,
                    address: f.request.address,
                    attempt: f.attempts - 1,
                });
                self.outbox.push_back(f.request.frame());
                i += 1;
            } else {
                let f = self.in_flight.swap_remove(i);
                self.events.push_back(AppEvent::Failed {
                    id: f.id,
                    address: f.request.address,
                    reason: alloc::format!(
                        "board {} did not answer {} after {} attempts: it may be unpowered or out of reach on the line",
                        f.request.address,
                        f.request.message.name(),
                        f.attempts
                    ),
                });
            }
        }
        self.dispatch(now);
    }

    /// The next frame for the carrier.
    pub fn poll_send(&mut self) -> Option<AppFrame> {
        self.outbox.pop_front()
    }

    /// The next event.
    pub fn poll_event(&mut self) -> Option<AppEvent> {
        self.events.pop_front()
    }

    /// When [`Requester::handle_timeout`] is next due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.in_flight.iter().map(|f| f.deadline).min()
    }

    /// Moves queued requests in flight while there is room, keeping the
    /// order of requests to one board.
    fn dispatch(&mut self, now: Instant) {
        let mut i = 0;
        while i < self.queue.len() && self.in_flight.len() < self.config.max_in_flight {
            let (id, ref req) = self.queue[i];
            let busy = |a: Address| self.in_flight.iter().any(|f| f.request.address == a);
            let earlier_same = self
                .queue
                .iter()
                .take(i)
                .any(|(_, r)| !r.broadcast && r.address == req.address);
            if !req.broadcast && (busy(req.address) || earlier_same) {
                i += 1;
                continue;
            }
            let (_, request) = self.queue.remove(i).expect("index in range");
            self.outbox.push_back(request.frame());
            let expect = request.expects();
            if expect == Expect::Nothing {
                self.events.push_back(AppEvent::Sent { id });
                continue;
            }
            self.in_flight.push(InFlight {
                id,
                request,
                expect,
                attempts: 1,
                sent_at: now,
                deadline: now + self.config.timeout,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::hid::Hid;
    use crate::app::service::Service;

    const A: Address = Address([0, 0x80, 0xE1, 0, 0, 1]);

    #[test]
    fn answers_are_matched_by_board_and_kind_and_silence_is_retried_then_failed() {
        let mut r = Requester::new(RequesterConfig {
            timeout: 100,
            max_attempts: 2,
            max_in_flight: 4,
        });
        let id = r.submit(0, Request::to(A, Message::Service(Service::ClockGet)));
        assert_eq!(r.poll_send().unwrap().address, A);
        // A ping ACK from the same board does not answer a clock read.
        r.handle_frame(
            10,
            &Message::Ack {
                frame_type: crate::app::FrameType::Ping,
                echo: 0,
            }
            .to(A),
        );
        assert!(matches!(r.poll_event(), Some(AppEvent::Unsolicited { .. })));
        r.handle_timeout(100);
        assert!(matches!(
            r.poll_event(),
            Some(AppEvent::Retry { attempt: 1, .. })
        ));
        assert!(r.poll_send().is_some());
        assert_eq!(
            r.poll_timeout(),
            Some(300),
            "the second attempt waits twice as long"
        );
        r.handle_timeout(300);
        match r.poll_event() {
            Some(AppEvent::Failed { id: i, reason, .. }) => {
                assert_eq!(i, id);
                assert!(reason.contains("after 2 attempts"), "{reason}");
            }
            e => panic!("{e:?}"),
        }
    }

    #[test]
    fn one_request_per_board_in_flight_and_broadcasts_need_no_answer() {
        let mut r = Requester::new(RequesterConfig {
            max_in_flight: 4,
            ..RequesterConfig::default()
        });
        let a = r.submit(0, Request::to(A, Message::Hid(Hid::Dimming(10))));
        let _b = r.submit(0, Request::to(A, Message::Hid(Hid::Dimming(20))));
        let c = r.submit(0, Request::all(Message::Hid(Hid::Dimming(30))));
        assert_eq!(r.poll_send().unwrap().payload, [b's', 1, 10]);
        assert_eq!(r.poll_send().unwrap().payload, [b's', 1, 30]);
        assert!(r.poll_send().is_none(), "the second dimming of A waits");
        assert_eq!(r.poll_event(), Some(AppEvent::Sent { id: c }));
        r.handle_frame(50, &Message::Hid(Hid::Dimming(10)).ack().to(A));
        assert!(matches!(r.poll_event(), Some(AppEvent::Answered { id, rtt: 50, .. }) if id == a));
        assert_eq!(r.poll_send().unwrap().payload, [b's', 1, 20]);
    }
}
