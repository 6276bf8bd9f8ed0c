//! The PHY frame on the line (ST7570 UM 3.2): 45 bytes, one time slot,
//! sent MSByte first.
//!
//! ```text
//! PRE AAAAh (2) | SSD 54C7h (2) | P_sdu (38) | pause or alarm (3)
//! ```
//!
//! And [`decode`], which tells a line capture's long MAC frame,
//! subframes or PHY frames apart for `plm decode --line`.

use super::mac::{self, LongFrame, MacError, MacFrame, SUBFRAME_LEN};
use crate::field::Field;
use alloc::vec::Vec;

/// Bytes of a PHY frame (3.2: "45 bytes (360 bits)").
pub const PHY_FRAME_LEN: usize = 45;
/// PRE (3.2).
pub const PREAMBLE: u16 = 0xAAAA;
/// SSD (3.2).
pub const START_SUBFRAME_DELIMITER: u16 = 0x54C7;
/// The alarm pattern sent in the pause window (7.2; SPY_AlarmIndication
/// ALARM, Table 59).
pub const ALARM: u32 = 0x56_9E89;

/// The field layout of a PHY frame.
pub mod fields {
    use super::*;
    /// Preamble.
    pub const PRE: Field = Field::uint("pre", "PRE", 0, 2);
    /// Start subframe delimiter.
    pub const SSD: Field = Field::uint("ssd", "SSD", 2, 2);
    /// The MAC subframe carried.
    pub const P_SDU: Field = Field::bytes("p_sdu", "P_sdu", 4, SUBFRAME_LEN);
    /// The pause or alarm window.
    pub const PAUSE_ALARM: Field = Field::uint("pause_alarm", "Pause or alarm", 42, 3);
    /// The whole frame.
    pub const LAYOUT: &[Field] = &[PRE, SSD, P_SDU, PAUSE_ALARM];
}

/// What the last 3 bytes of a time slot hold (3.2, 7.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Window {
    /// Silence, written 000000h in a byte capture.
    #[default]
    Pause,
    /// The alarm pattern 569E89h.
    Alarm,
    /// Anything else, kept as received (noise, a damaged alarm).
    Other(u32),
}

impl Window {
    /// The window of 3 bytes read as one number.
    pub fn from_value(v: u32) -> Window {
        match v {
            0 => Window::Pause,
            ALARM => Window::Alarm,
            v => Window::Other(v & 0xFF_FFFF),
        }
    }

    /// Its 24-bit value.
    pub fn value(self) -> u32 {
        match self {
            Window::Pause => 0,
            Window::Alarm => ALARM,
            Window::Other(v) => v & 0xFF_FFFF,
        }
    }
}

/// One PHY frame: a subframe and the window after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PhyFrame {
    /// The P_sdu: one MAC subframe.
    pub p_sdu: [u8; SUBFRAME_LEN],
    /// The pause or alarm window.
    pub window: Window,
}

impl PhyFrame {
    /// Parses 45 bytes, refusing a wrong length, preamble or delimiter.
    pub fn parse(bytes: &[u8]) -> Result<PhyFrame, MacError> {
        if bytes.len() != PHY_FRAME_LEN {
            return Err(MacError::PhyLength(bytes.len()));
        }
        let get = |f: &Field| f.get(bytes).unwrap_or(0);
        let pre = get(&fields::PRE) as u16;
        if pre != PREAMBLE {
            return Err(MacError::Preamble(pre));
        }
        let ssd = get(&fields::SSD) as u16;
        if ssd != START_SUBFRAME_DELIMITER {
            return Err(MacError::Delimiter(ssd));
        }
        let mut p_sdu = [0u8; SUBFRAME_LEN];
        p_sdu.copy_from_slice(&bytes[fields::P_SDU.offset..fields::P_SDU.end()]);
        Ok(PhyFrame {
            p_sdu,
            window: Window::from_value(get(&fields::PAUSE_ALARM) as u32),
        })
    }

    /// The 45 bytes.
    pub fn emit(&self) -> [u8; PHY_FRAME_LEN] {
        let mut out = [0u8; PHY_FRAME_LEN];
        fields::PRE.set(&mut out, PREAMBLE as i64);
        fields::SSD.set(&mut out, START_SUBFRAME_DELIMITER as i64);
        out[fields::P_SDU.offset..fields::P_SDU.end()].copy_from_slice(&self.p_sdu);
        fields::PAUSE_ALARM.set(&mut out, self.window.value() as i64);
        out
    }
}

/// Parses consecutive PHY frames (any number, each 45 bytes).
pub fn parse_frames(bytes: &[u8]) -> Result<Vec<PhyFrame>, MacError> {
    if bytes.is_empty() || !bytes.len().is_multiple_of(PHY_FRAME_LEN) {
        return Err(MacError::PhyLength(bytes.len()));
    }
    bytes
        .chunks_exact(PHY_FRAME_LEN)
        .map(PhyFrame::parse)
        .collect()
}

/// The PHY frames of a MAC frame in consecutive time slots, each with a
/// pause window.
pub fn to_phy_frames(frame: &MacFrame, fi: u16) -> Result<Vec<PhyFrame>, MacError> {
    Ok(frame
        .to_subframes(fi)?
        .into_iter()
        .map(|p_sdu| PhyFrame {
            p_sdu,
            window: Window::Pause,
        })
        .collect())
}

/// The MAC frame and FI of 1..7 PHY frames.
pub fn from_phy_frames(frames: &[PhyFrame]) -> Result<(u16, MacFrame), MacError> {
    let subframes: Vec<_> = frames.iter().map(|f| f.p_sdu).collect();
    MacFrame::from_subframes(&subframes)
}

/// What a line capture held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineKind {
    /// A long MAC frame alone (36·NS bytes, starting with NS).
    MacFrame,
    /// MAC subframes (38 bytes each, starting with FI).
    Subframes,
    /// PHY frames (45 bytes each, starting with AAAA54C7h).
    PhyFrames,
}

impl LineKind {
    /// Its name in `plm decode` output.
    pub fn name(self) -> &'static str {
        match self {
            LineKind::MacFrame => "mac_frame",
            LineKind::Subframes => "mac_subframes",
            LineKind::PhyFrames => "phy_frames",
        }
    }
}

/// A long MAC frame found in a line capture, FCS not yet judged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Line {
    /// How it was carried.
    pub kind: LineKind,
    /// The subframes' FI (subframes and PHY frames).
    pub fi: Option<u16>,
    /// The PHY frames' windows, one per frame.
    pub windows: Vec<Window>,
    /// The long frame's bytes.
    pub long: Vec<u8>,
}

impl Line {
    /// The checked view of the long frame (always `Ok` for a [`Line`]
    /// that [`decode`] returned).
    pub fn frame(&self) -> Result<LongFrame<'_>, MacError> {
        LongFrame::new_checked(&self.long)
    }
}

/// Reads a line capture: PHY frames if it starts with PRE and SSD, a
/// long MAC frame if it starts with an NS code, else subframes. The long
/// frame's length, NS and PAD are checked; its FCS is left to the caller
/// ([`LongFrame::fcs_ok`], [`MacFrame::parse`]).
pub fn decode(bytes: &[u8]) -> Result<Line, MacError> {
    let (kind, fi, windows, long) = if bytes.starts_with(&[0xAA, 0xAA]) {
        let frames = parse_frames(bytes)?;
        let subframes: Vec<_> = frames.iter().map(|f| f.p_sdu).collect();
        let (fi, long) = mac::join(&subframes)?;
        let windows = frames.iter().map(|f| f.window).collect();
        (LineKind::PhyFrames, Some(fi), windows, long)
    } else if bytes.len() >= 2 && mac::ns_count([bytes[0], bytes[1]]).is_some() {
        (LineKind::MacFrame, None, Vec::new(), bytes.to_vec())
    } else {
        let (fi, long) = mac::join(&mac::subframes_of(bytes)?)?;
        (LineKind::Subframes, Some(fi), Vec::new(), long)
    };
    LongFrame::new_checked(&long)?;
    Ok(Line {
        kind,
        fi,
        windows,
        long,
    })
}
