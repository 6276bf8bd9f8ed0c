//! A simulated board that breaks one rule of the board protocol
//! (docs/board-protocol.md), so that `plm board conformance` can be
//! shown to catch each: `plm sim --board --break RULE` (a hidden flag)
//! makes every lamp of the street break it. The names are the
//! conformance rules'.

use plm_core::app::rfu::Status;
use plm_core::app::{ErrorCode, FrameType, Message, Service};

/// The rule a board breaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Breach {
    /// Never answers SERVICE_FW_REL_GET (06h).
    Release,
    /// Stays silent on a service request that does not parse, or whose
    /// command it does not know, where the protocol wants the error
    /// frame.
    ErrorFrame,
    /// Never answers a discovery request (0Bh).
    Discovery,
    /// Ignores the ACK of its discovery answer: answers the same session
    /// again.
    DiscoveryAck,
    /// Answers RFU_STATUS_GET (11h) with a bitmap one byte short.
    Status,
    /// Refuses every image header (0Ch) with an error frame.
    Header,
    /// Numbers the status bitmap's bits from bit 7 down, not bit 0 up.
    Bitmap,
    /// Acknowledges a swap (0Eh) it refuses (segments missing).
    Swap,
    /// Answers RFU_ABORT (12h) with an error frame.
    Abort,
}

/// Every breach and its name, as `--break` takes it.
pub const BREACHES: &[(&str, Breach)] = &[
    ("release", Breach::Release),
    ("error-frame", Breach::ErrorFrame),
    ("discovery", Breach::Discovery),
    ("discovery-ack", Breach::DiscoveryAck),
    ("status", Breach::Status),
    ("header", Breach::Header),
    ("bitmap", Breach::Bitmap),
    ("swap", Breach::Swap),
    ("abort", Breach::Abort),
];

impl Breach {
    /// The breach of a name.
    pub fn named(name: &str) -> Option<Breach> {
        BREACHES.iter().find(|(n, _)| *n == name).map(|(_, b)| *b)
    }

    /// Whether a board breaking this rule acts as if it never heard `m`.
    pub fn ignores(self, m: &Message) -> bool {
        matches!(
            (self, m),
            (Breach::Release, Message::Service(Service::FwRelGet))
                | (
                    Breach::Discovery,
                    Message::Service(
                        Service::Discover { .. } | Service::DiscoverAny | Service::DiscoverFrame(_)
                    )
                )
                | (
                    Breach::DiscoveryAck,
                    Message::Ack {
                        frame_type: FrameType::Service,
                        echo: 0x0b,
                    },
                )
        )
    }

    /// What a board breaking this rule answers to `request` (`None`: a
    /// request that did not parse) instead of `answer`.
    pub fn answer(self, request: Option<&Message>, answer: Option<Message>) -> Option<Message> {
        let refused = Message::Error(ErrorCode::SERVICE_CMD_ERROR);
        // The error code compared, not the whole message: the page would
        // carry a comparison of every message for these two.
        let is_refused =
            |a: &Message| matches!(a, Message::Error(c) if *c == ErrorCode::SERVICE_CMD_ERROR);
        let service = match request {
            Some(Message::Service(s)) => Some(s),
            _ => None,
        };
        match (self, service, answer) {
            (Breach::ErrorFrame, None | Some(Service::Raw { .. }), Some(a)) if is_refused(&a) => {
                None
            }
            (Breach::Status, _, Some(Message::Service(Service::RfuStatus(mut s)))) => {
                s.bitmap.pop();
                Some(Message::Service(Service::RfuStatus(s)))
            }
            (Breach::Bitmap, _, Some(Message::Service(Service::RfuStatus(s)))) => {
                Some(Message::Service(Service::RfuStatus(Status {
                    bitmap: s.bitmap.iter().map(|b| b.reverse_bits()).collect(),
                    ..s
                })))
            }
            (Breach::Header, Some(Service::RfuHeader(_)), Some(Message::Ack { .. })) => {
                Some(refused)
            }
            (Breach::Swap, Some(s @ Service::RfuSwap { .. }), Some(a)) if is_refused(&a) => {
                Some(Message::ack_of(s))
            }
            (Breach::Abort, Some(Service::RfuAbort { .. }), Some(Message::Ack { .. })) => {
                Some(refused)
            }
            (_, _, a) => a,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_reads_back() {
        for (name, b) in BREACHES {
            assert_eq!(Breach::named(name), Some(*b));
        }
        assert_eq!(Breach::named("nothing"), None);
    }
}
