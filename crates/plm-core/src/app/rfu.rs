//! Remote firmware update (RFU) of the street-light boards over the power
//! line (STEVAL-IHP007V1 UM 4.2): the layouts of SERVICE_RFU_SET_IMG_HEADER
//! (0Ch), SERVICE_RFU_SET_IMG_DATA (0Dh) and SERVICE_RFU_SWAP_IMG (0Eh),
//! which the seed names without giving, and the two commands recovery
//! needs, in the user-defined service range the seed reserves: RFU_STATUS_GET
//! (11h: which segments a board holds, so an update resumes instead of
//! restarting) and RFU_ABORT (12h). Every decision is in
//! docs/protocol-notes.md, "Remote firmware update".
//!
//! - An update is a *campaign* (1-255): a board keeps the segments of one
//!   campaign and ignores the data of any other.
//! - The image is cut into [`SEGMENT`]-byte segments, numbered from 0; a
//!   segment's address in the image is its number × the segment size.
//! - Integrity: CRC-32 (ISO-HDLC, the one of zip and Ethernet) over the
//!   image as sent, announced in the header and checked again at the
//!   swap. The seed's "checksum" would be a sum: a 16-bit additive sum
//!   misses two segments swapped and any pair of errors that cancel, which
//!   a CRC-32 catches.
//! - Multi-byte numbers are big-endian, as the error frames' codes and the
//!   frames' CRC.

pub mod image;

use super::release::Release;
use crate::CrcImpl;
use alloc::format;
use alloc::string::String;
use crc::{Crc, CRC_32_ISO_HDLC};

/// Largest image: an image slot (4.2: "the maximum size of the firmware
/// application (in this application is set to 60 kbytes)").
pub const IMAGE_MAX: usize = 60 * 1024;
/// Bytes of one segment: the most a SERVICE_RFU_SET_IMG_DATA request
/// carries after its campaign and segment number (99 data bytes in a
/// 110-byte frame: 10 bytes of frame, the command, 3 of header).
pub const SEGMENT: usize = 96;
/// Segments of the largest image.
pub const SEGMENTS_MAX: usize = IMAGE_MAX / SEGMENT;
/// Bytes of the segment bitmap RFU_STATUS_GET answers with.
pub const BITMAP_LEN: usize = SEGMENTS_MAX / 8;
/// User-defined service command: which segments a board holds.
pub const RFU_STATUS_GET: u8 = 0x11;
/// User-defined service command: forget a campaign.
pub const RFU_ABORT: u8 = 0x12;

const CRC32: Crc<u32, CrcImpl> = Crc::<u32, CrcImpl>::new(&CRC_32_ISO_HDLC);

/// The CRC-32 of an image, as the header announces it and the swap checks.
pub fn image_crc(image: &[u8]) -> u32 {
    CRC32.checksum(image)
}

/// Segment `n` of `image` (the last one short).
pub fn segment_of(image: &[u8], n: usize) -> &[u8] {
    let start = (n * SEGMENT).min(image.len());
    &image[start..((n + 1) * SEGMENT).min(image.len())]
}

/// Segments an image of `size` bytes is cut into.
pub fn segments(size: usize) -> usize {
    size.div_ceil(SEGMENT)
}

/// The release a header announces for an image that states none (a plain
/// `.bin` and no release given): 0.0 (decided here; docs/
/// protocol-notes.md, "The image file").
pub const RELEASE_NOT_STATED: Release = Release { major: 0, minor: 0 };

/// A campaign's release in words: "release 1.5", or that it states none.
pub fn release_words(release: Option<Release>) -> String {
    match release {
        Some(r) => format!("release {r}"),
        None => "release not stated (a plain .bin names none)".into(),
    }
}

/// SERVICE_RFU_SET_IMG_HEADER: a new image is coming.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Header {
    /// The campaign (1-255).
    pub campaign: u8,
    /// Image bytes (1 to [`IMAGE_MAX`]).
    pub size: u32,
    /// The release the image reports once it runs (service 06h).
    pub version: Release,
    /// [`image_crc`] of the image.
    pub crc: u32,
    /// Bytes per segment: [`SEGMENT`] (carried so that a later protocol
    /// may change it; a board of this one refuses any other).
    pub segment: u8,
}

impl Header {
    /// The header of `image` for `campaign`, as release `version`.
    pub fn of(campaign: u8, version: Release, image: &[u8]) -> Header {
        Header {
            campaign,
            size: image.len() as u32,
            version,
            crc: image_crc(image),
            segment: SEGMENT as u8,
        }
    }

    /// The release announced, or `None` when the image states none
    /// ([`RELEASE_NOT_STATED`]).
    pub fn release(&self) -> Option<Release> {
        (self.version != RELEASE_NOT_STATED).then_some(self.version)
    }

    /// Segments of the image.
    pub fn segments(&self) -> usize {
        segments(self.size as usize)
    }
}

/// Where a board is in an update (RFU_STATUS_GET `state`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RfuState {
    /// No campaign.
    Idle,
    /// A header was accepted; segments are arriving.
    Receiving,
    /// Every segment is in and the image's CRC-32 is the header's.
    Complete,
    /// The new image runs on trial: a reset before it confirms itself
    /// boots the old one again.
    Trial,
    /// The new image runs and confirmed itself.
    Done,
}

/// The states by value, as [`fields::STATE`] names them.
pub const STATES: &[&str] = &["IDLE", "RECEIVING", "COMPLETE", "TRIAL", "DONE"];

impl RfuState {
    /// Its byte.
    pub fn byte(self) -> u8 {
        self as u8
    }

    /// From its byte.
    pub fn from_byte(b: u8) -> Option<RfuState> {
        use RfuState::*;
        [Idle, Receiving, Complete, Trial, Done]
            .get(b as usize)
            .copied()
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        STATES[self as usize]
    }
}

/// Why a board refused or undid an update (RFU_STATUS_GET `reason`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RfuReason {
    /// Nothing went wrong.
    None,
    /// The image is larger than a slot.
    TooLarge,
    /// A segment size other than [`SEGMENT`].
    SegmentSize,
    /// Segments are missing (swap asked too early).
    Missing,
    /// The image's CRC-32 is not the header's (or the swap's).
    Crc,
    /// A request named another campaign than the one under way.
    OtherCampaign,
    /// Writing the flash failed.
    Flash,
    /// The campaign was aborted.
    Aborted,
    /// The new image did not confirm itself: the board went back to the
    /// old one.
    Reverted,
}

/// The reasons by value, as [`fields::REASON`] names them.
pub const REASONS: &[&str] = &[
    "NONE",
    "IMAGE_TOO_LARGE",
    "SEGMENT_SIZE",
    "SEGMENTS_MISSING",
    "CRC_MISMATCH",
    "OTHER_CAMPAIGN",
    "FLASH_ERROR",
    "ABORTED",
    "REVERTED",
];

impl RfuReason {
    /// Its byte.
    pub fn byte(self) -> u8 {
        self as u8
    }

    /// From its byte.
    pub fn from_byte(b: u8) -> Option<RfuReason> {
        use RfuReason::*;
        [
            None,
            TooLarge,
            SegmentSize,
            Missing,
            Crc,
            OtherCampaign,
            Flash,
            Aborted,
            Reverted,
        ]
        .get(b as usize)
        .copied()
    }

    /// In words, for the person at the console.
    pub fn words(self) -> &'static str {
        use RfuReason::*;
        match self {
            None => "no problem",
            TooLarge => "the image is larger than the board's image slot (60 KiB)",
            SegmentSize => "the board takes 96-byte segments only",
            Missing => "segments are missing",
            Crc => "the image's CRC-32 does not match the header's",
            OtherCampaign => "the board is busy with another update",
            Flash => "the board could not write its flash",
            Aborted => "the update was aborted",
            Reverted => "the new image did not start: the board went back to the old one",
        }
    }
}

/// RFU_STATUS_GET's reply.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Status {
    /// The campaign it is about (0: none).
    pub campaign: u8,
    /// Where the board is ([`RfuState`] byte; a sniffer shows any).
    pub state: u8,
    /// What went wrong last ([`RfuReason`] byte).
    pub reason: u8,
    /// Segments held.
    pub received: u16,
    /// [`BITMAP_LEN`] bytes: bit `i % 8` of byte `i / 8` set = segment `i`
    /// held.
    pub bitmap: alloc::vec::Vec<u8>,
}

impl Status {
    /// The state, if its byte is one of [`STATES`].
    pub fn state(&self) -> Option<RfuState> {
        RfuState::from_byte(self.state)
    }

    /// The reason, if its byte is one of [`REASONS`].
    pub fn reason(&self) -> Option<RfuReason> {
        RfuReason::from_byte(self.reason)
    }

    /// Whether segment `i` is held.
    pub fn has(&self, i: usize) -> bool {
        self.bitmap
            .get(i / 8)
            .is_some_and(|b| b & (1 << (i % 8)) != 0)
    }

    /// The segments of `0..count` not held.
    pub fn missing(&self, count: usize) -> impl Iterator<Item = usize> + '_ {
        (0..count).filter(|&i| !self.has(i))
    }
}

/// Field layouts of the RFU commands' data.
pub mod fields {
    use super::*;
    use crate::field::Field;

    /// Campaign, first byte of every RFU request.
    pub const CAMPAIGN: Field = Field::uint("campaign", "Update campaign", 0, 1).range(1, 255);
    /// Header: image size.
    pub const IMAGE_SIZE: Field = Field::uint("image_size", "Image size", 1, 4)
        .range(1, IMAGE_MAX as i64)
        .unit("B");
    /// Header: release x.
    pub const VERSION_MAJOR: Field = Field::uint("version_major", "Image release x", 5, 1);
    /// Header: release y.
    pub const VERSION_MINOR: Field = Field::uint("version_minor", "Image release y", 6, 1);
    /// Header: CRC-32 of the image.
    pub const IMAGE_CRC: Field = Field::uint("image_crc32", "Image CRC-32", 7, 4);
    /// Header: segment size.
    pub const SEGMENT_SIZE: Field = Field::uint("segment_size", "Segment size", 11, 1)
        .range(SEGMENT as i64, SEGMENT as i64)
        .unit("B");
    /// Data: segment number.
    pub const SEGMENT_NUMBER: Field =
        Field::uint("segment", "Segment", 1, 2).range(0, SEGMENTS_MAX as i64 - 1);
    /// Data: the segment's bytes (1 to 96).
    pub const SEGMENT_DATA: Field = Field::bytes("data", "Segment data", 3, 0);
    /// Swap: the CRC-32 the image must have.
    pub const SWAP_CRC: Field = Field::uint("image_crc32", "Image CRC-32", 1, 4);
    /// Status: campaign (0: none).
    pub const STATUS_CAMPAIGN: Field = Field::uint("campaign", "Update campaign", 0, 1);
    /// Status: state.
    pub const STATE: Field = Field::enumeration("state", "State", 1, 0, 8, STATES);
    /// Status: reason.
    pub const REASON: Field = Field::enumeration("reason", "Reason", 2, 0, 8, REASONS);
    /// Status: segments held.
    pub const RECEIVED: Field = Field::uint("received", "Segments held", 3, 2);
    /// Status: segment bitmap.
    pub const BITMAP: Field = Field::bytes("bitmap", "Segments held (bitmap)", 5, BITMAP_LEN);

    /// SERVICE_RFU_SET_IMG_HEADER request.
    pub const HEADER: &[Field] = &[
        CAMPAIGN,
        IMAGE_SIZE,
        VERSION_MAJOR,
        VERSION_MINOR,
        IMAGE_CRC,
        SEGMENT_SIZE,
    ];
    /// SERVICE_RFU_SET_IMG_DATA request.
    pub const DATA: &[Field] = &[CAMPAIGN, SEGMENT_NUMBER, SEGMENT_DATA];
    /// SERVICE_RFU_SWAP_IMG request.
    pub const SWAP: &[Field] = &[CAMPAIGN, SWAP_CRC];
    /// RFU_STATUS_GET and RFU_ABORT requests.
    pub const CAMPAIGN_ONLY: &[Field] = &[CAMPAIGN];
    /// RFU_STATUS_GET reply.
    pub const STATUS: &[Field] = &[STATUS_CAMPAIGN, STATE, REASON, RECEIVED, BITMAP];
}

/// Data bytes of each request and reply.
pub mod len {
    use super::*;
    /// SERVICE_RFU_SET_IMG_HEADER request.
    pub const HEADER: usize = 12;
    /// SERVICE_RFU_SET_IMG_DATA request: 3 + 1..=96.
    pub const DATA_MAX: usize = 3 + SEGMENT;
    /// SERVICE_RFU_SWAP_IMG request.
    pub const SWAP: usize = 5;
    /// RFU_STATUS_GET reply.
    pub const STATUS: usize = 5 + BITMAP_LEN;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_fit_the_frame() {
        // A service frame is 10 bytes of frame + the command + data, at
        // most 110 (4.5).
        const { assert!(10 + 1 + len::DATA_MAX == 110) };
        const { assert!(10 + 1 + len::STATUS <= 110) };
        assert_eq!(SEGMENTS_MAX, 640);
        assert_eq!(BITMAP_LEN, 80);
        assert_eq!(segments(1), 1);
        assert_eq!(segments(96), 1);
        assert_eq!(segments(97), 2);
        assert_eq!(segments(IMAGE_MAX), 640);
    }

    #[test]
    fn the_crc_is_crc32_iso_hdlc() {
        assert_eq!(image_crc(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn states_and_reasons_round_trip() {
        for b in 0..=255u8 {
            if let Some(s) = RfuState::from_byte(b) {
                assert_eq!(s.byte(), b);
                assert_eq!(s.name(), STATES[b as usize]);
            }
            if let Some(r) = RfuReason::from_byte(b) {
                assert_eq!(r.byte(), b);
            }
        }
        assert_eq!(RfuState::from_byte(5), None);
        assert_eq!(RfuReason::from_byte(9), None);
    }
}
