//! What an application frame says, typed: the Repr of [`AppFrame`]
//! (after smoltcp's `wire`), and which answer a request waits for.

use super::error::ErrorCode;
use super::frame::{Address, AppFrame, FrameType};
use super::hid::Hid;
use super::service::{self, Answer, Service, ServiceError};
use alloc::vec::Vec;
use core::fmt;

/// A frame's payload, typed by its frame type.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Message {
    /// APP_DATA_FRAME with a HID ballast command or reply (Appendix A).
    Hid(Hid),
    /// APP_DATA_FRAME with other user data (at least 1 byte, 4.6.1).
    Data(Vec<u8>),
    /// APP_SERVICE_FRAME.
    Service(Service),
    /// APP_PING_FRAME.
    Ping,
    /// APP_ACK_FRAME: `[frame type, command_echo]` (4.6.2, 4.6.4).
    Ack {
        /// Type of the frame acknowledged.
        frame_type: FrameType,
        /// Its service command, `'s'` for HID sets, 0 for a ping.
        echo: u8,
    },
    /// APP_ERROR_FRAME.
    Error(ErrorCode),
    /// APP_PROGRAMMING_FRAME: `[group, data...]` (protocol notes).
    Programming {
        /// Programming group (`APP_PROG_GROUP_t`).
        group: u8,
        /// The group's bytes.
        data: Vec<u8>,
    },
    /// APP_MIB_FRAME: `[index]` reads, `[index, value...]` writes the
    /// board modem's MIB object; the reply is `[index, value...]`
    /// (protocol notes).
    Mib {
        /// ST7580 MIB index.
        index: u8,
        /// The value (empty for a read).
        data: Vec<u8>,
    },
    /// A frame type the seed does not define.
    Unknown {
        /// The type value.
        frame_type: u8,
        /// Its payload.
        payload: Vec<u8>,
    },
}

/// Why a frame's payload does not fit its type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MessageError {
    /// Service data does not fit the command.
    Service(ServiceError),
    /// The payload is the wrong size for the frame type.
    Length {
        /// Frame type name.
        frame: &'static str,
        /// Bytes it needs.
        expected: &'static str,
        /// Bytes it has.
        got: usize,
    },
}

impl fmt::Display for MessageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MessageError::Service(e) => write!(f, "{e}"),
            MessageError::Length {
                frame,
                expected,
                got,
            } => {
                write!(
                    f,
                    "an {frame} carries {expected} after the address, not {got}"
                )
            }
        }
    }
}

impl Message {
    /// Reads a frame's payload.
    pub fn parse(frame_type: FrameType, payload: &[u8]) -> Result<Message, MessageError> {
        let len = |expected: &'static str, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(MessageError::Length {
                    frame: frame_type.name().unwrap_or("unknown frame"),
                    expected,
                    got: payload.len(),
                })
            }
        };
        Ok(match frame_type {
            FrameType::Data => {
                len("at least 1 byte", !payload.is_empty())?;
                Hid::parse(payload).map_or_else(|| Message::Data(payload.to_vec()), Message::Hid)
            }
            FrameType::Service => {
                Message::Service(Service::parse(payload).map_err(MessageError::Service)?)
            }
            FrameType::Ping => {
                len("nothing", payload.is_empty())?;
                Message::Ping
            }
            FrameType::Ack => {
                len("2 bytes", payload.len() == 2)?;
                Message::Ack {
                    frame_type: FrameType::from_byte(payload[0]),
                    echo: payload[1],
                }
            }
            FrameType::Error => {
                len("2 bytes", payload.len() == 2)?;
                Message::Error(ErrorCode(u16::from_be_bytes([payload[0], payload[1]])))
            }
            FrameType::Programming => {
                len("a group byte and data", !payload.is_empty())?;
                Message::Programming {
                    group: payload[0],
                    data: payload[1..].to_vec(),
                }
            }
            FrameType::Mib => {
                len("an index byte", !payload.is_empty())?;
                Message::Mib {
                    index: payload[0],
                    data: payload[1..].to_vec(),
                }
            }
            FrameType::Unknown(t) => Message::Unknown {
                frame_type: t,
                payload: payload.to_vec(),
            },
        })
    }

    /// Reads a frame.
    pub fn of(frame: &AppFrame) -> Result<Message, MessageError> {
        Message::parse(frame.frame_type, &frame.payload)
    }

    /// Its frame type.
    pub fn frame_type(&self) -> FrameType {
        match self {
            Message::Hid(_) | Message::Data(_) => FrameType::Data,
            Message::Service(_) => FrameType::Service,
            Message::Ping => FrameType::Ping,
            Message::Ack { .. } => FrameType::Ack,
            Message::Error(_) => FrameType::Error,
            Message::Programming { .. } => FrameType::Programming,
            Message::Mib { .. } => FrameType::Mib,
            Message::Unknown { frame_type, .. } => FrameType::Unknown(*frame_type),
        }
    }

    /// The payload after the address.
    pub fn payload(&self) -> Vec<u8> {
        match self {
            Message::Hid(h) => h.payload(),
            Message::Data(d) => d.clone(),
            Message::Service(s) => s.payload(),
            Message::Ping => Vec::new(),
            Message::Ack { frame_type, echo } => alloc::vec![frame_type.byte(), *echo],
            Message::Error(e) => e.0.to_be_bytes().to_vec(),
            Message::Programming { group: i, data } | Message::Mib { index: i, data } => {
                let mut v = alloc::vec![*i];
                v.extend_from_slice(data);
                v
            }
            Message::Unknown { payload, .. } => payload.clone(),
        }
    }

    /// A unicast frame to (or from) `address`.
    pub fn to(&self, address: Address) -> AppFrame {
        AppFrame::new(self.frame_type(), address, self.payload())
    }

    /// A broadcast frame (the address field as given, usually the
    /// concentrator's own or all ones).
    pub fn broadcast(&self, address: Address) -> AppFrame {
        AppFrame {
            broadcast: true,
            ..self.to(address)
        }
    }

    /// The ACK a board sends for this request: `[frame type, echo]`,
    /// echo being the first payload byte (the service command, `'s'`)
    /// or 0 for a ping (4.6.2, 4.6.4, Appendix A).
    pub fn ack(&self) -> Message {
        if let Message::Service(s) = self {
            return Message::ack_of(s);
        }
        Message::Ack {
            frame_type: self.frame_type(),
            echo: self.payload().first().copied().unwrap_or(0),
        }
    }

    /// [`Message::ack`] of the service request `s`, without the message:
    /// its echo is the command byte, the payload's first.
    pub fn ack_of(s: &Service) -> Message {
        Message::Ack {
            frame_type: FrameType::Service,
            echo: s.command(),
        }
    }

    /// What a board answers to this request with, when unicast.
    pub fn expects(&self) -> Expect {
        match self {
            Message::Service(s) if s.is_request() => match s.answer() {
                Answer::None | Answer::Undefined => Expect::Nothing,
                Answer::Ack => Expect::Ack(self.ack()),
                Answer::Reply(..) => Expect::Service(s.command()),
            },
            Message::Hid(Hid::Reset(_) | Hid::Dimming(_)) | Message::Ping => {
                Expect::Ack(self.ack())
            }
            Message::Hid(Hid::Get(p)) => Expect::Hid(*p),
            Message::Programming { .. } => Expect::Ack(self.ack()),
            Message::Mib { index, data } if data.is_empty() => Expect::Mib(*index),
            Message::Mib { .. } => Expect::Ack(self.ack()),
            _ => Expect::Nothing,
        }
    }

    /// The seed's name of what this is (`SERVICE_PLM_CLOCK_GET`,
    /// `Lamp dimming`, `APP_PING_FRAME`).
    pub fn name(&self) -> &'static str {
        match self {
            Message::Hid(h) => h.name(),
            Message::Service(s) => {
                service::describe(s.command()).map_or("SERVICE_USER_CMD", |d| d.name)
            }
            m => m.frame_type().name().unwrap_or("unknown frame type"),
        }
    }

    /// The checks a board applies, for the console to refuse a request
    /// before anything is sent.
    pub fn validate(&self) -> Result<(), alloc::string::String> {
        use alloc::string::ToString;
        match self {
            Message::Service(s) => s.validate().map_err(|e| e.to_string()),
            Message::Hid(h) => h.validate().map_err(|e| e.to_string()),
            Message::Data(d) if d.is_empty() => Err("user data needs at least 1 byte".into()),
            _ => Ok(()),
        }
    }
}

/// The answer a request waits for.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Expect {
    /// None: the request is done once sent.
    Nothing,
    /// This ACK.
    Ack(Message),
    /// A service reply of this command.
    Service(u8),
    /// A HID `'g'` reply of this parameter.
    Hid(u8),
    /// A MIB frame of this index.
    Mib(u8),
}

impl Expect {
    /// Whether `m` is the answer (an error frame answers every request).
    pub fn answered_by(&self, m: &Message) -> bool {
        match (self, m) {
            (Expect::Nothing, _) => false,
            (_, Message::Error(_)) => true,
            (Expect::Ack(a), m) => a == m,
            (Expect::Service(c), Message::Service(s)) => !s.is_request() && s.command() == *c,
            (Expect::Hid(p), Message::Hid(Hid::Reply { param, .. })) => param == p,
            (Expect::Mib(i), Message::Mib { index, data }) => index == i && !data.is_empty(),
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::hid;

    #[test]
    fn dimming_waits_for_the_ack_echoing_s() {
        let m = Message::Hid(Hid::Dimming(50));
        assert_eq!(
            m.expects(),
            Expect::Ack(Message::Ack {
                frame_type: FrameType::Data,
                echo: hid::SET
            })
        );
        let ack = Message::parse(FrameType::Ack, &[0x00, 0x73]).unwrap();
        assert!(m.expects().answered_by(&ack));
        assert!(m.expects().answered_by(&Message::Error(ErrorCode(0x12))));
        assert!(!m.expects().answered_by(&Message::Ping));
    }

    #[test]
    fn every_frame_type_round_trips() {
        let ms = [
            Message::Hid(Hid::Get(hid::ALL)),
            Message::Data(alloc::vec![1, 2, 3]),
            Message::Service(Service::ClockGet),
            Message::Ping,
            Message::Ack {
                frame_type: FrameType::Ping,
                echo: 0,
            },
            Message::Error(ErrorCode(0x0b)),
            Message::Programming {
                group: 2,
                data: alloc::vec![9; 32],
            },
            Message::Mib {
                index: 1,
                data: Vec::new(),
            },
            Message::Unknown {
                frame_type: 0x33,
                payload: alloc::vec![1],
            },
        ];
        for m in ms {
            let f = m.to(Address([1, 2, 3, 4, 5, 6]));
            let back = AppFrame::parse(&f.emit().unwrap()).unwrap();
            assert_eq!(Message::of(&back), Ok(m));
        }
    }
}
