//! Service commands (STEVAL-IHP007V1 UM 4.5 `APP_SER_CMD_t`, 4.6.4): the
//! one description of each command's request and answer, and the typed
//! [`Service`] the simulator and the console use. A service frame's
//! payload is `[command, data...]`; the offsets below count from the
//! first data byte.
//!
//! Requests and replies of one command always differ in length, so a
//! frame is read without knowing which way it went.

use super::error::ErrorCode;
use super::frame::Address;
pub use super::release::Release;
use super::rfu::{self, fields as rf};
use crate::field::{self, Field, FieldError};
use alloc::vec::Vec;
use core::fmt;

/// Programming groups (`APP_PROG_GROUP_t`), index = value.
pub const PROG_GROUPS: &[&str] = &[
    "PROG_GRP_DEVICE_DATA",
    "PROG_GRP_LL_STACK_PARAM",
    "PROG_GRP_USER_DATA",
];
/// Bytes of one parameter group (4.6.4 "Set module parameters":
/// buffer[10 -> 41], 32 bytes; the same size for every group, see
/// protocol notes).
pub const PARAM_LEN: usize = 32;
/// Highest SNR value of SERVICE_SN_SET/GET ("SNR Ratio from 0 to 31").
pub const SNR_MAX: u8 = 31;
/// First code of the user-defined service range ("0x0b to 0x7f";
/// 0Bh-10h are taken by the native commands that follow in the enum).
pub const USER_FIRST: u8 = 0x11;
/// SERVICE_READ_IN_SLOTS, a user-defined command (4.5: 0Bh-7Fh; 11h-12h
/// are the remote update's): the boards named read one HID parameter and
/// answer it each in its slot (docs/protocol-notes.md, "Reads in slots").
pub const READ_IN_SLOTS: u8 = 0x13;

/// What answers a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// Nothing (the resets: "Any response from PLM module" read as none).
    None,
    /// An APP_ACK_FRAME echoing the service frame type and the command.
    Ack,
    /// A service frame of the same command with this data.
    Reply(&'static [Field], usize),
    /// Not described (user-defined commands this project does not
    /// know).
    Undefined,
}

/// One service command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServiceDesc {
    /// Command code.
    pub code: u8,
    /// The seed's name (`SERVICE_PLM_CLOCK_SET`).
    pub name: &'static str,
    /// What it does, in words.
    pub what: &'static str,
    /// Request data layout.
    pub request: &'static [Field],
    /// Request data length; `None` for any length.
    pub request_len: Option<usize>,
    /// What answers it.
    pub answer: Answer,
}

/// Field layouts of the service data.
pub mod fields {
    use super::*;
    /// Programming group.
    pub const GROUP: Field =
        Field::enumeration("group", "Programming group", 0, 0, 8, PROG_GROUPS).range(0, 2);
    /// Parameter block after the group.
    pub const PARAMETERS: Field = Field::bytes("parameters", "Parameters", 1, PARAM_LEN);
    /// GPIO input pins, bit x = IOx.
    pub const INPUTS: Field = Field::uint("inputs", "Inputs", 0, 1);
    /// GPIO output pins, bit x = IOx.
    pub const OUTPUTS: Field = Field::uint("outputs", "Outputs", 0, 1);
    /// GPIO direction: bit x = 1 -> IOx output, 0 -> input.
    pub const IO_CONFIG: Field = Field::uint("io_configuration", "I/O configuration", 0, 1);
    /// Module firmware release x.y.
    pub const FIRMWARE_MAJOR: Field = Field::uint("firmware_major", "Firmware release x", 0, 1);
    /// Module firmware release x.y.
    pub const FIRMWARE_MINOR: Field = Field::uint("firmware_minor", "Firmware release y", 1, 1);
    /// Stack firmware release x.y.
    pub const STACK_MAJOR: Field = Field::uint("stack_major", "Stack release x", 2, 1);
    /// Stack firmware release x.y.
    pub const STACK_MINOR: Field = Field::uint("stack_minor", "Stack release y", 3, 1);
    /// Clock hours.
    pub const HOURS: Field = Field::uint("hours", "Hours", 0, 1).range(0, 23).unit("h");
    /// Clock minutes.
    pub const MINUTES: Field = Field::uint("minutes", "Minutes", 1, 1)
        .range(0, 59)
        .unit("min");
    /// Clock seconds.
    pub const SECONDS: Field = Field::uint("seconds", "Seconds", 2, 1)
        .range(0, 59)
        .unit("s");
    /// SNR ratio 0-31.
    pub const SNR: Field = Field::uint("snr", "SNR ratio", 0, 1)
        .range(0, SNR_MAX as i64)
        .unit("dB");
    /// Discovery session: a board answers once per session (protocol notes).
    pub const SESSION: Field = Field::uint("session", "Discovery session", 0, 1);
    /// Discovery reply window: boards answer at a random moment in it.
    pub const WINDOW: Field = Field::uint("window", "Reply window", 1, 1)
        .range(1, 60)
        .unit("s");
    /// Discovery rule of a slotted frame (docs/protocol-notes.md,
    /// "Discovery"); rule 1 requests carry no rule byte.
    pub const RULE: Field = Field::uint("rule", "Discovery rule", 0, 1).range(2, 2);
    /// Slotted frame: the session.
    pub const FRAME_SESSION: Field = Field::uint("session", "Discovery session", 1, 1);
    /// Slotted frame: its number in the session.
    pub const FRAME: Field = Field::uint("frame", "Frame number", 2, 1);
    /// Slotted frame: reply slots.
    pub const SLOTS: Field = Field::uint("slots", "Reply slots", 3, 1).range(1, 255);
    /// Slotted frame: length of one slot.
    pub const SLOT_MS: Field = Field::uint("slot_ms", "Slot length", 4, 1)
        .range(1, 255)
        .unit("ms");
    /// Slotted frame: a board answers when its draw (0-255) is at most
    /// this (255: every board).
    pub const SHARE: Field = Field::uint("share", "Share that answers", 5, 1);
    /// Slotted frame: the bytes every address heard starts with
    /// (`service::names`).
    pub const HEARD_SHARED: Field = Field::uint("shared", "Bytes shared", 6, 1).range(0, 5);
    /// Slotted frame: the addresses heard in the previous frame (the
    /// shared bytes once, then the rest of each), which stay quiet for
    /// the rest of the session.
    pub const HEARD: Field = Field::bytes("heard", "Addresses heard", 7, 0);
    /// Discovery reply: SNR at which the board heard the request.
    pub const DISCOVERY_SNR: Field = Field::uint("snr", "SNR of the request", 4, 1)
        .range(0, SNR_MAX as i64)
        .unit("dB");
    /// Reads in slots: length of one reply slot.
    pub const READ_SLOT_MS: Field = Field::uint("slot_ms", "Slot length", 0, 1)
        .range(1, 255)
        .unit("ms");
    /// Reads in slots: the HID `param_to_get` each board reads.
    pub const READ_PARAM: Field = Field::uint("param", "HID parameter", 1, 1);
    /// Reads in slots: from the request heard to the first slot.
    pub const READ_FIRST_MS: Field = Field::uint("first_ms", "First slot after", 2, 1).unit("ms");
    /// Reads in slots: the bytes every address named starts with
    /// (`service::names`).
    pub const READ_SHARED: Field = Field::uint("shared", "Bytes shared", 3, 1).range(0, 5);
    /// Reads in slots: the boards named (the shared bytes once, then the
    /// rest of each); the board at index i answers in slot i.
    pub const READ_ADDRESSES: Field = Field::bytes("addresses", "Boards, in slot order", 4, 0);
    /// Bytes not yet described (RFU, user commands).
    pub const DATA: Field = Field::bytes("data", "Data", 0, 0);

    /// PARAM_SET request.
    pub const PARAM_SET: &[Field] = &[GROUP, PARAMETERS];
    /// PARAM_GET request.
    pub const PARAM_GET: &[Field] = &[GROUP];
    /// FW_REL_GET reply.
    pub const RELEASES: &[Field] = &[FIRMWARE_MAJOR, FIRMWARE_MINOR, STACK_MAJOR, STACK_MINOR];
    /// CLOCK_SET request, CLOCK_GET reply.
    pub const CLOCK: &[Field] = &[HOURS, MINUTES, SECONDS];
    /// NET_DISCOVER_REQ request, rule 1 (rounds).
    pub const DISCOVER: &[Field] = &[SESSION, WINDOW];
    /// NET_DISCOVER_REQ request, rule 2 (slotted frames).
    pub const DISCOVER_FRAME: &[Field] = &[
        RULE,
        FRAME_SESSION,
        FRAME,
        SLOTS,
        SLOT_MS,
        SHARE,
        HEARD_SHARED,
        HEARD,
    ];
    /// READ_IN_SLOTS request.
    pub const READ_IN_SLOTS: &[Field] = &[
        READ_SLOT_MS,
        READ_PARAM,
        READ_FIRST_MS,
        READ_SHARED,
        READ_ADDRESSES,
    ];
    /// NET_DISCOVER_REQ reply.
    pub const DISCOVERED: &[Field] = &[
        FIRMWARE_MAJOR,
        FIRMWARE_MINOR,
        STACK_MAJOR,
        STACK_MINOR,
        DISCOVERY_SNR,
    ];
}

use fields as f;

/// Every native service command (4.5, 4.6.4), by code, and the
/// user-defined ones this project adds: the remote firmware update
/// (11h-12h, [`rfu`]) and reads in slots (13h).
pub const COMMANDS: &[ServiceDesc] = &[
    ServiceDesc {
        code: 0x00,
        name: "SERVICE_SOFTWARE_RESET",
        what: "Reset the board's state machines",
        request: &[],
        request_len: Some(0),
        answer: Answer::None,
    },
    ServiceDesc {
        code: 0x01,
        name: "SERVICE_HARDWARE_RESET",
        what: "Reset the board",
        request: &[],
        request_len: Some(0),
        answer: Answer::None,
    },
    ServiceDesc {
        code: 0x02,
        name: "SERVICE_PARAM_SET",
        what: "Write a parameter group",
        request: f::PARAM_SET,
        request_len: Some(1 + PARAM_LEN),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x03,
        name: "SERVICE_PARAM_GET",
        what: "Read a parameter group",
        request: f::PARAM_GET,
        request_len: Some(1),
        answer: Answer::Reply(f::PARAM_SET, 1 + PARAM_LEN),
    },
    ServiceDesc {
        code: 0x04,
        name: "SERVICE_INPUTS_GET",
        what: "Read the GPIO inputs",
        request: &[],
        request_len: Some(0),
        answer: Answer::Reply(&[f::INPUTS], 1),
    },
    ServiceDesc {
        code: 0x05,
        name: "SERVICE_OUTPUTS_SET",
        what: "Set the GPIO outputs",
        request: &[f::OUTPUTS],
        request_len: Some(1),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x06,
        name: "SERVICE_FW_REL_GET",
        what: "Read the firmware and stack releases",
        request: &[],
        request_len: Some(0),
        answer: Answer::Reply(f::RELEASES, 4),
    },
    ServiceDesc {
        code: 0x07,
        name: "SERVICE_PLM_CLOCK_SET",
        what: "Set the board's clock",
        request: f::CLOCK,
        request_len: Some(3),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x08,
        name: "SERVICE_PLM_CLOCK_GET",
        what: "Read the board's clock",
        request: &[],
        request_len: Some(0),
        answer: Answer::Reply(f::CLOCK, 3),
    },
    ServiceDesc {
        code: 0x09,
        name: "SERVICE_IO_CONFIG_SET",
        what: "Set which GPIO pins are outputs",
        request: &[f::IO_CONFIG],
        request_len: Some(1),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x0a,
        name: "SERVICE_IO_CONFIG_GET",
        what: "Read which GPIO pins are outputs",
        request: &[],
        request_len: Some(0),
        answer: Answer::Reply(&[f::IO_CONFIG], 1),
    },
    ServiceDesc {
        code: 0x0b,
        name: "SERVICE_NET_DISCOVER_REQ",
        what: "Discover the boards on the line",
        request: f::DISCOVER,
        request_len: Some(2),
        answer: Answer::Reply(f::DISCOVERED, 5),
    },
    ServiceDesc {
        code: 0x0c,
        name: "SERVICE_RFU_SET_IMG_HEADER",
        what: "Remote firmware update: a new image is coming (its header)",
        request: rf::HEADER,
        request_len: Some(rfu::len::HEADER),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x0d,
        name: "SERVICE_RFU_SET_IMG_DATA",
        what: "Remote firmware update: one segment of the image",
        request: rf::DATA,
        // 3 + 1..=96: any length is a request (there is no reply).
        request_len: None,
        answer: Answer::None,
    },
    ServiceDesc {
        code: 0x0e,
        name: "SERVICE_RFU_SWAP_IMG",
        what: "Remote firmware update: check the image and boot it",
        request: rf::SWAP,
        request_len: Some(rfu::len::SWAP),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x0f,
        name: "SERVICE_SN_SET",
        what: "Set the SNR threshold",
        request: &[f::SNR],
        request_len: Some(1),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: 0x10,
        name: "SERVICE_SN_GET",
        what: "Read the SNR of the last frame the board heard",
        request: &[],
        request_len: Some(0),
        answer: Answer::Reply(&[f::SNR], 1),
    },
    ServiceDesc {
        code: rfu::RFU_STATUS_GET,
        name: "RFU_STATUS_GET",
        what: "Remote firmware update: which segments the board holds",
        request: rf::CAMPAIGN_ONLY,
        request_len: Some(1),
        answer: Answer::Reply(rf::STATUS, rfu::len::STATUS),
    },
    ServiceDesc {
        code: rfu::RFU_ABORT,
        name: "RFU_ABORT",
        what: "Remote firmware update: forget the campaign",
        request: rf::CAMPAIGN_ONLY,
        request_len: Some(1),
        answer: Answer::Ack,
    },
    ServiceDesc {
        code: READ_IN_SLOTS,
        name: "SERVICE_READ_IN_SLOTS",
        what: "Boards named read a HID parameter and answer it each in its slot",
        request: f::READ_IN_SLOTS,
        // 3 + the names (`names`): any length is a request (the answers
        // are HID replies, data frames).
        request_len: None,
        answer: Answer::None,
    },
];

/// The description of a command code.
pub fn describe(code: u8) -> Option<&'static ServiceDesc> {
    COMMANDS.iter().find(|d| d.code == code)
}

/// A time of day as the board's RTC keeps it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Clock {
    /// 0-23.
    pub hours: u8,
    /// 0-59.
    pub minutes: u8,
    /// 0-59.
    pub seconds: u8,
}

impl Clock {
    /// Seconds since midnight.
    pub fn seconds_of_day(self) -> u32 {
        self.hours as u32 * 3600 + self.minutes as u32 * 60 + self.seconds as u32
    }

    /// The time `s` seconds after midnight (wrapping at 24 h).
    pub fn from_seconds(s: u64) -> Clock {
        let s = s % 86_400;
        Clock {
            hours: (s / 3600) as u8,
            minutes: (s / 60 % 60) as u8,
            seconds: (s % 60) as u8,
        }
    }
}

impl fmt::Display for Clock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:02}:{:02}:{:02}",
            self.hours, self.minutes, self.seconds
        )
    }
}

/// What a board found by discovery says of itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Discovered {
    /// Module firmware release.
    pub firmware: Release,
    /// Stack release.
    pub stack: Release,
    /// SNR at which it heard the request, dB (0-31).
    pub snr: u8,
}

/// A discovery request of rule 2: one frame of reply slots
/// (docs/protocol-notes.md, "Discovery").
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct SlotFrame {
    /// Session: a board heard in it stays quiet until the next.
    pub session: u8,
    /// Frame number in the session (a board's slot changes with it).
    pub frame: u8,
    /// Reply slots (1-255).
    pub slots: u8,
    /// Length of one slot, ms.
    pub slot_ms: u8,
    /// A board answers when its draw is at most this (255: all).
    pub share: u8,
    /// Addresses heard in the previous frame (as many as fit:
    /// [`SlotFrame::fitting`]).
    pub heard: Vec<Address>,
}

impl SlotFrame {
    /// The rule byte a slotted frame starts with.
    pub const RULE: u8 = 2;
    /// Data bytes before the heard addresses.
    pub const FIXED: usize = 6;
    /// How many of `heard`, from its start, one request can name.
    pub fn fitting(heard: &[Address]) -> usize {
        names::fitting(heard, Self::FIXED, usize::MAX)
    }
    /// What a bare 0Bh (no data, as seed 004 lists it) stands for.
    pub const BARE: SlotFrame = SlotFrame {
        session: 0,
        frame: 0,
        slots: 16,
        slot_ms: 40,
        share: 255,
        heard: Vec::new(),
    };

    fn parse(d: &[u8]) -> Option<SlotFrame> {
        let (fixed, heard) = fixed_then_addresses(d, Self::FIXED)?;
        (fixed[0] == Self::RULE).then(|| SlotFrame {
            session: fixed[1],
            frame: fixed[2],
            slots: fixed[3],
            slot_ms: fixed[4],
            share: fixed[5],
            heard,
        })
    }
}

/// `fixed` bytes, then a list of addresses ([`names`]): the layout of
/// the slotted requests (0Bh rule 2, 13h).
fn fixed_then_addresses(d: &[u8], fixed: usize) -> Option<(&[u8], Vec<Address>)> {
    let (head, rest) = d.split_at_checked(fixed)?;
    Some((head, names::parse(rest)?))
}

/// The addresses a slotted request names (0Bh rule 2, 13h), in few
/// bytes: `[p, prefix, suffixes...]`, where the `p` bytes (0-5) every
/// address starts with are sent once, then each address's other `6 - p`
/// bytes (docs/protocol-notes.md, "Discovery"). Boards of one street
/// share their maker's first bytes at least, so a request names about
/// twice as many boards as in full.
pub mod names {
    use super::super::frame::{Address, MAX_PAYLOAD};
    use alloc::vec::Vec;

    /// Bytes shared by every address in `list` at its start (at most 5).
    pub fn shared(list: &[Address]) -> usize {
        let Some(first) = list.first() else {
            return 0;
        };
        list.iter().fold(5, |p, a| {
            p.min(
                first
                    .0
                    .iter()
                    .zip(a.0)
                    .take_while(|(x, y)| **x == *y)
                    .count(),
            )
        })
    }

    /// The bytes `list` takes.
    pub fn len(list: &[Address]) -> usize {
        let p = shared(list);
        1 + p + list.len() * (6 - p)
    }

    /// How many of `list`, from its start, fit in a request whose other
    /// data takes `fixed` bytes (the frame's 100-byte payload, its
    /// command byte included), and no more than `most`.
    /// One pass: each address taken can only shorten the shared prefix,
    /// and adds at least a byte (every board of a street checks each
    /// slotted request it hears).
    pub fn fitting(list: &[Address], fixed: usize, most: usize) -> usize {
        let room = MAX_PAYLOAD - 1 - fixed;
        let mut p = 5;
        let mut fit = 0;
        for (k, a) in list.iter().take(most).enumerate() {
            p = shared(&[list[0], *a]).min(p);
            if 1 + p + (k + 1) * (6 - p) > room {
                break;
            }
            fit = k + 1;
        }
        fit
    }

    /// Appends `list` to `out`.
    pub fn emit(list: &[Address], out: &mut Vec<u8>) {
        let p = shared(list);
        out.push(p as u8);
        if let Some(first) = list.first() {
            out.extend_from_slice(&first.0[..p]);
        }
        for a in list {
            out.extend_from_slice(&a.0[p..]);
        }
    }

    /// The addresses of `d`, or `None` when it is not such a list.
    pub fn parse(d: &[u8]) -> Option<Vec<Address>> {
        let (&p, rest) = d.split_first()?;
        let p = p as usize;
        if p > 5 {
            return None;
        }
        let (prefix, tails) = rest.split_at_checked(p)?;
        if !tails.len().is_multiple_of(6 - p) {
            return None;
        }
        Some(
            tails
                .chunks_exact(6 - p)
                .map(|tail| {
                    let mut a = [0; 6];
                    a[..p].copy_from_slice(prefix);
                    a[p..].copy_from_slice(tail);
                    Address(a)
                })
                .collect(),
        )
    }
}

/// A SERVICE_READ_IN_SLOTS request (docs/protocol-notes.md, "Reads in
/// slots"): the board at index i of `addresses` asks its ballast for
/// `param` and sends the HID reply `first_ms + i × slot_ms` after hearing
/// the request, or nothing if the ballast has not answered by then.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct SlotRead {
    /// Length of one slot, ms (1-255).
    pub slot_ms: u8,
    /// HID `param_to_get`.
    pub param: u8,
    /// From the request heard to slot 0, ms.
    pub first_ms: u8,
    /// The boards named, in slot order (at most [`SlotRead::MOST`]).
    pub addresses: Vec<Address>,
}

impl SlotRead {
    /// Data bytes before the addresses.
    pub const FIXED: usize = 3;
    /// Boards one request names at most: 50 slots of GET ALL are 3.1 s
    /// at B-PSK, as long as a view's own request waits behind them.
    pub const MOST: usize = 50;

    /// How many of `boards`, from its start, one request can name.
    pub fn fitting(boards: &[Address]) -> usize {
        names::fitting(boards, Self::FIXED, Self::MOST)
    }

    fn parse(d: &[u8]) -> Option<SlotRead> {
        let (fixed, addresses) = fixed_then_addresses(d, Self::FIXED)?;
        Some(SlotRead {
            slot_ms: fixed[0],
            param: fixed[1],
            first_ms: fixed[2],
            addresses,
        })
    }

    /// The slot of `board`, if it is named.
    pub fn slot_of(&self, board: &Address) -> Option<usize> {
        self.addresses.iter().position(|a| a == board)
    }

    /// When `board` answers, µs after hearing the request; `None` when
    /// it is not named.
    pub fn reply_after(&self, board: &Address) -> Option<crate::time::Duration> {
        let i = self.slot_of(board)? as u64;
        Some((self.first_ms as u64 + i * self.slot_ms as u64) * crate::time::MS)
    }
}

/// A service frame's payload, typed: requests and their replies.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Service {
    /// 00h.
    SoftwareReset,
    /// 01h.
    HardwareReset,
    /// 02h.
    ParamSet {
        /// Programming group (0-2).
        group: u8,
        /// 32 bytes.
        data: Vec<u8>,
    },
    /// 03h request.
    ParamGet {
        /// Programming group.
        group: u8,
    },
    /// 03h reply.
    Params {
        /// Programming group.
        group: u8,
        /// 32 bytes.
        data: Vec<u8>,
    },
    /// 04h request.
    InputsGet,
    /// 04h reply: bit x = IOx.
    Inputs(u8),
    /// 05h: bit x = IOx.
    OutputsSet(u8),
    /// 06h request.
    FwRelGet,
    /// 06h reply.
    FwRel {
        /// Module firmware.
        firmware: Release,
        /// Stack.
        stack: Release,
    },
    /// 07h.
    ClockSet(Clock),
    /// 08h request.
    ClockGet,
    /// 08h reply.
    ClockNow(Clock),
    /// 09h: bit x = 1 -> IOx output.
    IoConfigSet(u8),
    /// 0Ah request.
    IoConfigGet,
    /// 0Ah reply.
    IoConfig(u8),
    /// 0Bh request with no data, as seed 004 lists it: answered as a
    /// slotted frame with the defaults ([`SlotFrame::BARE`]).
    DiscoverAny,
    /// 0Bh request, rule 1 (the older rule: rounds and ACKs).
    Discover {
        /// Session number: a board acknowledged in a session answers no
        /// more requests of it.
        session: u8,
        /// Reply window, s.
        window: u8,
    },
    /// 0Bh request, rule 2: a frame of reply slots.
    DiscoverFrame(SlotFrame),
    /// 0Bh reply.
    DiscoverReply(Discovered),
    /// 0Fh.
    SnSet(u8),
    /// 10h request.
    SnGet,
    /// 10h reply.
    Sn(u8),
    /// 0Ch.
    RfuHeader(rfu::Header),
    /// 0Dh.
    RfuData {
        /// Campaign.
        campaign: u8,
        /// Segment number.
        segment: u16,
        /// Its bytes (1 to 96).
        data: Vec<u8>,
    },
    /// 0Eh.
    RfuSwap {
        /// Campaign.
        campaign: u8,
        /// The CRC-32 the image must have.
        crc: u32,
    },
    /// 11h request.
    RfuStatusGet {
        /// Campaign asked about.
        campaign: u8,
    },
    /// 11h reply.
    RfuStatus(rfu::Status),
    /// 12h.
    RfuAbort {
        /// Campaign to forget.
        campaign: u8,
    },
    /// 13h: reads in slots.
    ReadInSlots(SlotRead),
    /// A command whose layout is not described (user-defined commands
    /// this project does not know), kept as bytes.
    Raw {
        /// Command code.
        command: u8,
        /// Its data.
        data: Vec<u8>,
    },
}

/// Why a service payload does not fit its command.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ServiceError {
    /// No command byte.
    Empty,
    /// The data length fits neither request nor reply.
    Length {
        /// Command name.
        name: &'static str,
        /// Request length.
        request: usize,
        /// Reply length, if there is a reply.
        reply: Option<usize>,
        /// What came.
        got: usize,
    },
    /// A field is out of range.
    Field(FieldError),
}

impl fmt::Display for ServiceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ServiceError::Empty => f.write_str("a service frame needs a command byte"),
            ServiceError::Length {
                name,
                request,
                reply,
                got,
            } => {
                write!(f, "{name} carries {request} data bytes")?;
                if let Some(r) = reply {
                    write!(f, " (its reply {r})")?;
                }
                write!(f, ", not {got}")
            }
            ServiceError::Field(e) => write!(f, "{e}"),
        }
    }
}

impl ServiceError {
    /// The error code a board answers with (4.5).
    pub fn code(&self) -> ErrorCode {
        ErrorCode::SERVICE_CMD_ERROR
    }
}

fn get(f: &Field, d: &[u8]) -> u8 {
    f.get(d).unwrap_or(0) as u8
}

fn get_u32(f: &Field, d: &[u8]) -> u32 {
    f.get(d).unwrap_or(0) as u32
}

fn release(d: &[u8], major: &Field, minor: &Field) -> Release {
    Release {
        major: get(major, d),
        minor: get(minor, d),
    }
}

fn clock(d: &[u8]) -> Clock {
    Clock {
        hours: get(&f::HOURS, d),
        minutes: get(&f::MINUTES, d),
        seconds: get(&f::SECONDS, d),
    }
}

impl Service {
    /// Reads a service payload `[command, data...]`. Field ranges are
    /// not checked here (see [`Service::validate`]): a sniffer shows what
    /// was sent.
    pub fn parse(payload: &[u8]) -> Result<Service, ServiceError> {
        let (&command, d) = payload.split_first().ok_or(ServiceError::Empty)?;
        let Some(desc) = describe(command) else {
            return Ok(Service::Raw {
                command,
                data: d.to_vec(),
            });
        };
        let reply_len = match desc.answer {
            Answer::Reply(_, n) => Some(n),
            _ => None,
        };
        if command == 0x0b && reply_len != Some(d.len()) {
            return match d.len() {
                0 => Ok(Service::DiscoverAny),
                2 => Ok(Service::Discover {
                    session: get(&f::SESSION, d),
                    window: get(&f::WINDOW, d),
                }),
                _ => SlotFrame::parse(d)
                    .map(Service::DiscoverFrame)
                    .ok_or(ServiceError::Length {
                        name: desc.name,
                        request: SlotFrame::FIXED,
                        reply: reply_len,
                        got: d.len(),
                    }),
            };
        }
        if command == READ_IN_SLOTS {
            return SlotRead::parse(d)
                .map(Service::ReadInSlots)
                .ok_or(ServiceError::Length {
                    name: desc.name,
                    request: SlotRead::FIXED,
                    reply: None,
                    got: d.len(),
                });
        }
        let is_request = desc.request_len.is_none_or(|n| n == d.len());
        let is_reply = reply_len == Some(d.len());
        if !is_request && !is_reply {
            return Err(ServiceError::Length {
                name: desc.name,
                request: desc.request_len.unwrap_or(0),
                reply: reply_len,
                got: d.len(),
            });
        }
        let group = || get(&f::GROUP, d);
        let params = || d[1..].to_vec();
        Ok(match (command, is_request) {
            (0x00, _) => Service::SoftwareReset,
            (0x01, _) => Service::HardwareReset,
            (0x02, _) => Service::ParamSet {
                group: group(),
                data: params(),
            },
            (0x03, true) => Service::ParamGet { group: group() },
            (0x03, false) => Service::Params {
                group: group(),
                data: params(),
            },
            (0x04, true) => Service::InputsGet,
            (0x04, false) => Service::Inputs(get(&f::INPUTS, d)),
            (0x05, _) => Service::OutputsSet(get(&f::OUTPUTS, d)),
            (0x06, true) => Service::FwRelGet,
            (0x06, false) => Service::FwRel {
                firmware: release(d, &f::FIRMWARE_MAJOR, &f::FIRMWARE_MINOR),
                stack: release(d, &f::STACK_MAJOR, &f::STACK_MINOR),
            },
            (0x07, _) => Service::ClockSet(clock(d)),
            (0x08, true) => Service::ClockGet,
            (0x08, false) => Service::ClockNow(clock(d)),
            (0x09, _) => Service::IoConfigSet(get(&f::IO_CONFIG, d)),
            (0x0a, true) => Service::IoConfigGet,
            (0x0a, false) => Service::IoConfig(get(&f::IO_CONFIG, d)),
            (0x0b, true) => Service::Discover {
                session: get(&f::SESSION, d),
                window: get(&f::WINDOW, d),
            },
            (0x0b, false) => Service::DiscoverReply(Discovered {
                firmware: release(d, &f::FIRMWARE_MAJOR, &f::FIRMWARE_MINOR),
                stack: release(d, &f::STACK_MAJOR, &f::STACK_MINOR),
                snr: get(&f::DISCOVERY_SNR, d),
            }),
            (0x0f, _) => Service::SnSet(get(&f::SNR, d)),
            (0x10, true) => Service::SnGet,
            (0x10, false) => Service::Sn(get(&f::SNR, d)),
            (0x0c, _) => Service::RfuHeader(rfu::Header {
                campaign: get(&rf::CAMPAIGN, d),
                size: get_u32(&rf::IMAGE_SIZE, d),
                version: release(d, &rf::VERSION_MAJOR, &rf::VERSION_MINOR),
                crc: get_u32(&rf::IMAGE_CRC, d),
                segment: get(&rf::SEGMENT_SIZE, d),
            }),
            (0x0d, _) => Service::RfuData {
                campaign: get(&rf::CAMPAIGN, d),
                segment: get_u32(&rf::SEGMENT_NUMBER, d) as u16,
                data: d.get(3..).unwrap_or(&[]).to_vec(),
            },
            (0x0e, _) => Service::RfuSwap {
                campaign: get(&rf::CAMPAIGN, d),
                crc: get_u32(&rf::SWAP_CRC, d),
            },
            (rfu::RFU_STATUS_GET, true) => Service::RfuStatusGet {
                campaign: get(&rf::CAMPAIGN, d),
            },
            (rfu::RFU_STATUS_GET, false) => Service::RfuStatus(rfu::Status {
                campaign: get(&rf::STATUS_CAMPAIGN, d),
                state: get(&rf::STATE, d),
                reason: get(&rf::REASON, d),
                received: get_u32(&rf::RECEIVED, d) as u16,
                bitmap: d[5..].to_vec(),
            }),
            (rfu::RFU_ABORT, _) => Service::RfuAbort {
                campaign: get(&rf::CAMPAIGN, d),
            },
            _ => Service::Raw {
                command,
                data: d.to_vec(),
            },
        })
    }

    /// The command code.
    pub fn command(&self) -> u8 {
        use Service::*;
        match self {
            SoftwareReset => 0x00,
            HardwareReset => 0x01,
            ParamSet { .. } => 0x02,
            ParamGet { .. } | Params { .. } => 0x03,
            InputsGet | Inputs(_) => 0x04,
            OutputsSet(_) => 0x05,
            FwRelGet | FwRel { .. } => 0x06,
            ClockSet(_) => 0x07,
            ClockGet | ClockNow(_) => 0x08,
            IoConfigSet(_) => 0x09,
            IoConfigGet | IoConfig(_) => 0x0a,
            DiscoverAny | Discover { .. } | DiscoverFrame(_) | DiscoverReply(_) => 0x0b,
            SnSet(_) => 0x0f,
            SnGet | Sn(_) => 0x10,
            RfuHeader(_) => 0x0c,
            RfuData { .. } => 0x0d,
            RfuSwap { .. } => 0x0e,
            RfuStatusGet { .. } | RfuStatus(_) => rfu::RFU_STATUS_GET,
            RfuAbort { .. } => rfu::RFU_ABORT,
            ReadInSlots(_) => READ_IN_SLOTS,
            Raw { command, .. } => *command,
        }
    }

    /// The description of its command, if the seed describes it.
    pub fn desc(&self) -> Option<&'static ServiceDesc> {
        describe(self.command())
    }

    /// Whether this is a request (and not a reply).
    pub fn is_request(&self) -> bool {
        use Service::*;
        !matches!(
            self,
            Params { .. }
                | Inputs(_)
                | FwRel { .. }
                | ClockNow(_)
                | IoConfig(_)
                | DiscoverReply(_)
                | Sn(_)
                | RfuStatus(_)
        )
    }

    /// The payload `[command, data...]`.
    pub fn payload(&self) -> Vec<u8> {
        use Service::*;
        let mut out = alloc::vec![self.command()];
        match self {
            SoftwareReset | HardwareReset | InputsGet | FwRelGet | ClockGet | IoConfigGet
            | SnGet | DiscoverAny => {}
            ParamSet { group, data } | Params { group, data } => {
                out.push(*group);
                out.extend_from_slice(data);
            }
            ParamGet { group } => out.push(*group),
            Inputs(v) | OutputsSet(v) | IoConfigSet(v) | IoConfig(v) | SnSet(v) | Sn(v) => {
                out.push(*v)
            }
            FwRel { firmware, stack } => {
                out.extend_from_slice(&[firmware.major, firmware.minor, stack.major, stack.minor])
            }
            ClockSet(c) | ClockNow(c) => out.extend_from_slice(&[c.hours, c.minutes, c.seconds]),
            Discover { session, window } => out.extend_from_slice(&[*session, *window]),
            DiscoverFrame(fr) => {
                out.extend_from_slice(&[
                    SlotFrame::RULE,
                    fr.session,
                    fr.frame,
                    fr.slots,
                    fr.slot_ms,
                    fr.share,
                ]);
                names::emit(&fr.heard, &mut out);
            }
            DiscoverReply(r) => out.extend_from_slice(&[
                r.firmware.major,
                r.firmware.minor,
                r.stack.major,
                r.stack.minor,
                r.snr,
            ]),
            RfuHeader(h) => {
                out.push(h.campaign);
                out.extend_from_slice(&h.size.to_be_bytes());
                out.extend_from_slice(&[h.version.major, h.version.minor]);
                out.extend_from_slice(&h.crc.to_be_bytes());
                out.push(h.segment);
            }
            RfuData {
                campaign,
                segment,
                data,
            } => {
                out.push(*campaign);
                out.extend_from_slice(&segment.to_be_bytes());
                out.extend_from_slice(data);
            }
            RfuSwap { campaign, crc } => {
                out.push(*campaign);
                out.extend_from_slice(&crc.to_be_bytes());
            }
            RfuStatusGet { campaign } | RfuAbort { campaign } => out.push(*campaign),
            ReadInSlots(r) => {
                out.extend_from_slice(&[r.slot_ms, r.param, r.first_ms]);
                names::emit(&r.addresses, &mut out);
            }
            RfuStatus(s) => {
                out.extend_from_slice(&[s.campaign, s.state, s.reason]);
                out.extend_from_slice(&s.received.to_be_bytes());
                out.extend_from_slice(&s.bitmap);
            }
            Raw { data, .. } => out.extend_from_slice(data),
        }
        out
    }

    /// The data layout of this request or reply.
    pub fn layout(&self) -> &'static [Field] {
        match self {
            Service::DiscoverAny => return &[],
            Service::DiscoverFrame(_) => return f::DISCOVER_FRAME,
            _ => {}
        }
        match (self.desc(), self.is_request()) {
            (Some(d), true) => d.request,
            (
                Some(ServiceDesc {
                    answer: Answer::Reply(l, _),
                    ..
                }),
                false,
            ) => l,
            _ => &[f::DATA],
        }
    }

    /// The checks a board applies (ranges, lengths), with the reason in
    /// words; the console refuses a request that fails them before
    /// anything is sent.
    pub fn validate(&self) -> Result<(), ServiceError> {
        let payload = self.payload();
        let data = &payload[1..];
        if let Some(desc) = self.desc() {
            let want = if let Service::DiscoverFrame(fr) = self {
                Some(SlotFrame::FIXED + names::len(&fr.heard))
            } else if matches!(self, Service::DiscoverAny) {
                Some(0)
            } else if self.is_request() {
                desc.request_len
            } else if let Answer::Reply(_, n) = desc.answer {
                Some(n)
            } else {
                None
            };
            if want.is_some_and(|n| n != data.len()) {
                return Err(ServiceError::Length {
                    name: desc.name,
                    request: desc.request_len.unwrap_or(0),
                    reply: None,
                    got: data.len(),
                });
            }
        }
        let named = match self {
            Service::ReadInSlots(r) => Some((&r.addresses, SlotRead::fitting(&r.addresses))),
            Service::DiscoverFrame(fr) => Some((&fr.heard, SlotFrame::fitting(&fr.heard))),
            _ => None,
        };
        if let Some((list, fit)) = named.filter(|(list, fit)| *fit < list.len()) {
            return Err(ServiceError::Field(FieldError {
                field: "addresses",
                reason: alloc::format!(
                    "a request names at most {fit} of these boards, not {}",
                    list.len()
                ),
            }));
        }
        if let Service::RfuData { data: segment, .. } = self {
            if !(1..=rfu::SEGMENT).contains(&segment.len()) {
                return Err(ServiceError::Field(FieldError {
                    field: "data",
                    reason: alloc::format!(
                        "a segment carries 1 to {} bytes, not {}",
                        rfu::SEGMENT,
                        segment.len()
                    ),
                }));
            }
        }
        field::validate(self.layout(), data).map_err(ServiceError::Field)
    }

    /// What answers this request.
    pub fn answer(&self) -> Answer {
        self.desc().map_or(Answer::Undefined, |d| d.answer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use alloc::string::ToString;

    #[test]
    fn the_addresses_fitting_a_request_are_the_most_whose_list_fits() {
        // Streets sharing 0 to 5 bytes, one address breaking the prefix
        // at different places, and every limit.
        let mut x = 0x2545_f491_u64;
        for shared_bytes in 0..=5usize {
            for breaker in [None, Some(0), Some(3), Some(17)] {
                let list: Vec<Address> = (0..40u64)
                    .map(|i| {
                        x = x
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        let mut a = [0x00, 0x80, 0xe1, 0x12, 0x34, 0x56];
                        let tail = (x >> 16).to_be_bytes();
                        a[shared_bytes..].copy_from_slice(&tail[2 + shared_bytes..]);
                        if breaker == Some(i as usize) {
                            a[0] ^= 0xff;
                        }
                        Address(a)
                    })
                    .collect();
                for (fixed, most) in [(0, usize::MAX), (4, 16), (13, 10), (90, usize::MAX)] {
                    let room = crate::app::frame::MAX_PAYLOAD - 1 - fixed;
                    let brute = (0..=list.len().min(most))
                        .filter(|k| names::len(&list[..*k]) <= room)
                        .max()
                        .unwrap_or(0);
                    assert_eq!(
                        names::fitting(&list, fixed, most),
                        brute,
                        "{shared_bytes} {breaker:?} {fixed} {most}"
                    );
                }
            }
        }
    }

    #[test]
    fn requests_and_replies_of_one_command_are_told_apart_by_length() {
        assert_eq!(Service::parse(&[0x08]), Ok(Service::ClockGet));
        assert_eq!(
            Service::parse(&[0x08, 12, 30, 5]),
            Ok(Service::ClockNow(Clock {
                hours: 12,
                minutes: 30,
                seconds: 5
            }))
        );
        assert!(matches!(
            Service::parse(&[0x08, 1]),
            Err(ServiceError::Length { .. })
        ));
    }

    #[test]
    fn clock_ranges_are_refused_in_words() {
        let e = Service::ClockSet(Clock {
            hours: 24,
            minutes: 0,
            seconds: 0,
        })
        .validate()
        .unwrap_err();
        assert_eq!(e.to_string(), "hours: 24 is out of range: 0 to 23 h");
        assert!(Service::SnSet(32).validate().is_err());
        assert!(Service::ParamSet {
            group: 2,
            data: alloc::vec![0; 31]
        }
        .validate()
        .is_err());
        assert!(Service::ParamSet {
            group: 3,
            data: alloc::vec![0; 32]
        }
        .validate()
        .is_err());
        assert!(Service::ParamSet {
            group: 2,
            data: alloc::vec![0; 32]
        }
        .validate()
        .is_ok());
    }

    #[test]
    fn every_described_command_round_trips() {
        for d in COMMANDS {
            // Of a variable length: three bytes and an empty list of names.
            let data = alloc::vec![0; d.request_len.unwrap_or(4)];
            let mut p = alloc::vec![d.code];
            p.extend_from_slice(&data);
            let s = Service::parse(&p).unwrap();
            assert_eq!(s.payload(), p, "{}", d.name);
            assert!(s.is_request(), "{}", d.name);
        }
    }
}
