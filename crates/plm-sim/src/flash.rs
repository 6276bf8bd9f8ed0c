//! The controller board's flash as remote firmware update needs it
//! (STEVAL-IHP007V1 UM 4.2): a 4 KiB bootloader, two image slots of 60 KiB
//! and the boot record the bootloader reads at every start, and what a
//! power cut does to each of them. Decisions: docs/protocol-notes.md,
//! "Remote firmware update", "The board's flash".
//!
//! - **Boot record, two copies.** Each copy is one page: a sequence
//!   number, the slot to run, the image's size, CRC-32 and release, and
//!   whether the image is on trial, protected by its own CRC-32. A new
//!   record goes to the copy that does not hold the newest one, so a power
//!   cut while it is written tears that copy only and the bootloader falls
//!   back on the other.
//! - **Trial.** A new image boots on trial. The bootloader marks a trial
//!   record *tried* before jumping to it (a halfword programmed from FFFFh
//!   to 0000h, no erase, outside the record's CRC); an image that comes up
//!   confirms itself by writing a new record without the trial flag. A
//!   start that finds a tried trial record (the image reset or lost power
//!   before confirming) boots the older copy's image: the old firmware.
//!   If the tried trial is the only good record left (the power went while
//!   its confirmation was written over the older copy), it is tried again:
//!   starting it beats starting nothing.
//! - **Every start checks** the chosen slot's CRC-32 against its record;
//!   an image that fails is never run (the other copy's is).
//! - **Vector table.** Images are linked for slot 0; a segment that falls
//!   in the first [`VECTORS`] bytes has every vector but the initial stack
//!   pointer moved by the slot's offset as it is written (§4.2), and the
//!   CRC is taken with them moved back, over the image as it was sent.
//! - **Power cuts** ([`Flash::cut_after`]): after a given number of page
//!   operations the power goes; the operation under way is torn (a page
//!   half written reads as garbage) and nothing more is written.

use crate::rng::Rng;
use plm_core::app::rfu::{image_crc, IMAGE_MAX};
use plm_core::app::Release;
use std::ops::Range;
use std::sync::Arc;

/// A flash page (STM32F10x medium density: 1 KiB), the unit of erasing.
pub const PAGE: usize = 1024;
/// The bootloader (§4.2: "4 Kb of additional memory for a bootloader").
pub const BOOTLOADER: usize = 4 * 1024;
/// An image slot (§4.2: 60 KB).
pub const SLOT: usize = IMAGE_MAX;
/// Flash address of the start of the flash (STM32F10x).
pub const FLASH_BASE: u32 = 0x0800_0000;
pub use plm_core::app::rfu::image::VECTORS;

/// Flash address of slot `slot`'s first byte.
pub fn slot_base(slot: usize) -> u32 {
    FLASH_BASE + (BOOTLOADER + slot * SLOT) as u32
}

/// One copy of the boot record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record {
    /// Newest wins.
    pub seq: u32,
    /// Slot to run (0 or 1).
    pub slot: u8,
    /// Image bytes.
    pub size: u32,
    /// CRC-32 of the image as sent.
    pub crc: u32,
    /// Its release (what service 06h reports while it runs).
    pub version: Release,
    /// The image has not confirmed itself yet.
    pub trial: bool,
}

/// What a copy of the boot record page holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Copy {
    /// Erased (FFh): no record.
    Erased,
    /// A record, its CRC good, and whether the bootloader marked it tried.
    Good { record: Record, tried: bool },
    /// Torn by a power cut: its CRC fails.
    Torn,
}

/// A good copy of the boot record: which copy, the record, and whether
/// it was tried.
type Found = (usize, Record, bool);

/// Where a start leads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Boot {
    /// The slot that runs.
    pub slot: usize,
    /// Its record.
    pub record: Record,
    /// It runs on trial (it must confirm itself).
    pub trial: bool,
    /// The start went back to the older image (the newer one was on trial
    /// and did not confirm itself, or its CRC failed).
    pub reverted: bool,
}

/// The supply, as the flash sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Power {
    On,
    /// On for this many more page operations; the next one is torn.
    CutAfter(u32),
    /// Gone: nothing is written.
    Off,
}

/// What becomes of one page operation.
enum Op {
    Done,
    /// The power went during it.
    Torn,
    /// The power had gone.
    Lost,
}

/// An image slot's bytes: only what was written is kept (a street of 500
/// boards would otherwise carry 60 MB of erased flash), and a factory
/// image is shared by every board that still runs it.
#[derive(Debug, Clone)]
enum Slot {
    /// Every byte FFh.
    Erased,
    /// The factory image (FFh after it).
    Shared(Arc<[u8]>),
    /// Bytes written since the last erase (FFh after them).
    Own(Vec<u8>),
}

impl Slot {
    fn bytes(&self) -> &[u8] {
        match self {
            Slot::Erased => &[],
            Slot::Shared(b) => b,
            Slot::Own(b) => b,
        }
    }

    /// The bytes of `range`, FFh where nothing was written.
    fn read(&self, range: Range<usize>) -> Vec<u8> {
        let b = self.bytes();
        range.map(|i| b.get(i).copied().unwrap_or(0xFF)).collect()
    }

    /// Room to write `range`: the slot's own copy, at least that long.
    fn own(&mut self, range: &Range<usize>) -> &mut [u8] {
        if !matches!(self, Slot::Own(_)) {
            *self = Slot::Own(self.bytes().to_vec());
        }
        let Slot::Own(b) = self else {
            unreachable!("made Own above")
        };
        if b.len() < range.end {
            b.resize(range.end, 0xFF);
        }
        &mut b[range.clone()]
    }

    /// Erases `range`.
    fn erase(&mut self, range: Range<usize>) {
        if self.bytes().len() > range.start {
            self.own(&range).fill(0xFF);
            if let Slot::Own(b) = self {
                while b.last() == Some(&0xFF) {
                    b.pop();
                }
                if b.is_empty() {
                    *self = Slot::Erased;
                }
            }
        }
    }
}

/// The flash.
#[derive(Debug, Clone)]
pub struct Flash {
    slots: [Slot; 2],
    copies: [Copy; 2],
    power: Power,
    /// What the last start chose (the firmware in RAM knows it).
    booted: Option<Boot>,
}

impl Flash {
    /// A board as it leaves the factory: `image` in slot 0, confirmed, as
    /// release `version`.
    pub fn factory(image: Arc<[u8]>, version: Release) -> Flash {
        let record = Record {
            seq: 1,
            slot: 0,
            size: image.len() as u32,
            crc: image_crc(&image),
            version,
            trial: false,
        };
        Flash {
            slots: [Slot::Shared(image), Slot::Erased],
            copies: [Copy::Erased, Copy::Erased],
            power: Power::On,
            booted: None,
        }
        .with_record(record)
    }

    fn with_record(mut self, record: Record) -> Flash {
        self.copies[0] = Copy::Good {
            record,
            tried: false,
        };
        self
    }

    /// The power goes after `ops` more page operations (erase, program,
    /// record write); the one after is torn.
    pub fn cut_after(&mut self, ops: u32) {
        self.power = Power::CutAfter(ops);
    }

    /// Whether the power went.
    pub fn is_dead(&self) -> bool {
        self.power == Power::Off
    }

    /// The power is back.
    pub fn power_on(&mut self) {
        self.power = Power::On;
    }

    /// Counts one page operation.
    fn op(&mut self) -> Op {
        match self.power {
            Power::On => Op::Done,
            Power::CutAfter(0) => {
                self.power = Power::Off;
                Op::Torn
            }
            Power::CutAfter(n) => {
                self.power = Power::CutAfter(n - 1);
                Op::Done
            }
            Power::Off => Op::Lost,
        }
    }

    /// The newest good record and its copy, then the other good one.
    fn records(&self) -> (Option<Found>, Option<Found>) {
        let mut good = self.copies.iter().enumerate().filter_map(|(i, c)| match c {
            Copy::Good { record, tried } => Some((i, *record, *tried)),
            _ => None,
        });
        // Two copies: no sort needed (and none linked into the console).
        match (good.next(), good.next()) {
            (Some(a), Some(b)) if b.1.seq > a.1.seq => (Some(b), Some(a)),
            pair => pair,
        }
    }

    /// What runs now: the last start's choice.
    pub fn running(&self) -> Option<Boot> {
        self.booted
    }

    /// The free slot (the one an update writes to): not the one running.
    pub fn free_slot(&self) -> usize {
        self.booted.map_or(1, |b| 1 - b.slot)
    }

    /// The bootloader at a start: picks the image to run, marks a trial
    /// tried, reverts one that was tried and never confirmed. `None` only
    /// if no slot holds an image whose CRC passes (never, for a board that
    /// left the factory: see the tests).
    pub fn boot(&mut self) -> Option<Boot> {
        let (newest, older) = self.records();
        let mut candidates: Vec<(Found, bool)> = Vec::new();
        if let Some(n) = newest {
            let given_up = n.1.trial && n.2;
            if !given_up {
                candidates.push((n, false));
            }
        }
        if let Some(o) = older {
            candidates.push((o, true));
        }
        // A tried trial that is the only record left (the power went while
        // it wrote its confirmation over the older one): better to try it
        // again than to start nothing.
        if let Some(n) = newest.filter(|n| n.1.trial && n.2) {
            candidates.push((n, false));
        }
        for ((copy, record, _), older) in candidates {
            if !self.verifies(&record) {
                continue;
            }
            let reverted = older && newest.is_some_and(|n| n.1.seq != record.seq);
            let trial = record.trial && !reverted;
            if trial {
                // Programmed without erasing: a cut here leaves it untried,
                // and the next start tries again.
                if let Op::Done = self.op() {
                    if let Copy::Good { tried, .. } = &mut self.copies[copy] {
                        *tried = true;
                    }
                }
            }
            self.booted = Some(Boot {
                slot: record.slot as usize,
                record,
                trial,
                reverted,
            });
            return self.booted;
        }
        self.booted = None;
        None
    }

    /// Whether `record`'s slot holds the image it describes.
    pub fn verifies(&self, record: &Record) -> bool {
        let slot = record.slot as usize;
        slot < 2
            && (record.size as usize) <= SLOT
            && self.image_crc(slot, record.size as usize) == record.crc
    }

    /// The CRC-32 of the first `size` bytes of `slot`, with the vector
    /// table moved back to slot 0: the image as it was sent.
    pub fn image_crc(&self, slot: usize, size: usize) -> u32 {
        image_crc(&self.image(slot, size))
    }

    /// The first `size` bytes of `slot` as sent (vectors moved back).
    pub fn image(&self, slot: usize, size: usize) -> Vec<u8> {
        let mut image = self.slots[slot].read(0..size.min(SLOT));
        relocate(&mut image, 0, slot_base(slot), slot_base(0));
        image
    }

    /// Erases `slot` (every page): before an update writes to it.
    pub fn erase_slot(&mut self, slot: usize, rng: &mut Rng) {
        for page in 0..SLOT / PAGE {
            let range = page * PAGE..(page + 1) * PAGE;
            match self.op() {
                Op::Done => self.slots[slot].erase(range),
                Op::Torn => return tear(self.slots[slot].own(&range), rng),
                Op::Lost => return,
            }
        }
    }

    /// Writes `data` at `offset` of `slot`, moving the vectors it holds to
    /// the slot's addresses; a cut tears it.
    pub fn program(&mut self, slot: usize, offset: usize, data: &[u8], rng: &mut Rng) {
        let end = (offset + data.len()).min(SLOT);
        if offset >= end {
            return;
        }
        let mut bytes = data[..end - offset].to_vec();
        relocate(&mut bytes, offset, slot_base(0), slot_base(slot));
        match self.op() {
            Op::Done => self.slots[slot].own(&(offset..end)).copy_from_slice(&bytes),
            Op::Torn => tear(self.slots[slot].own(&(offset..end)), rng),
            Op::Lost => {}
        }
    }

    /// Writes `record` to the copy that does not hold the newest record
    /// (erase, then program); a cut tears that copy.
    pub fn write_record(&mut self, record: Record) {
        let (newest, _) = self.records();
        let target = match newest {
            Some((copy, ..)) => 1 - copy,
            None => 0,
        };
        // Erase, then program: a cut at either tears the copy.
        for _ in 0..2 {
            match self.op() {
                Op::Done => {}
                Op::Torn => return self.copies[target] = Copy::Torn,
                Op::Lost => return,
            }
        }
        self.copies[target] = Copy::Good {
            record,
            tried: false,
        };
    }

    /// The next record's sequence number.
    pub fn next_seq(&self) -> u32 {
        let (newest, older) = self.records();
        newest
            .map(|n| n.1.seq)
            .max(older.map(|o| o.1.seq))
            .unwrap_or(0)
            + 1
    }
}

/// Moves the vectors (every word of the vector table but the initial
/// stack pointer, word 0) that `bytes`, written at image `offset`, holds
/// and that point into the slot at `from` to the same place in the slot at
/// `to`. Words pointing elsewhere (unused vectors, 0) stay, so moving back
/// restores the image exactly.
fn relocate(bytes: &mut [u8], offset: usize, from: u32, to: u32) {
    let mut at = offset.div_ceil(4).max(1) * 4;
    while at + 4 <= (offset + bytes.len()).min(VECTORS) {
        let i = at - offset;
        let v = u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
        if (from..from + SLOT as u32).contains(&v) {
            bytes[i..i + 4].copy_from_slice(&(v - from + to).to_le_bytes());
        }
        at += 4;
    }
}

/// What a write cut short leaves: some bytes written, some not, some
/// neither.
fn tear(bytes: &mut [u8], rng: &mut Rng) {
    for b in bytes.iter_mut() {
        *b = rng.below(256) as u8;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::app::rfu::SEGMENT;

    const OLD: Release = Release { major: 1, minor: 4 };
    const NEW: Release = Release { major: 1, minor: 5 };

    /// An image linked for slot 0: a stack pointer, vectors into the
    /// image (one unused, 0), then code.
    fn image(len: usize, seed: u8) -> Vec<u8> {
        let mut b: Vec<u8> = (0..len)
            .map(|i| (i as u8).wrapping_mul(31) ^ seed)
            .collect();
        b[..4].copy_from_slice(&0x2000_5000u32.to_le_bytes());
        for (n, at) in (4..VECTORS).step_by(4).enumerate() {
            let v = if n == 3 {
                0
            } else {
                slot_base(0) + 0x200 + 8 * n as u32 + 1
            };
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        b
    }

    /// What a board does for an update, page operation by page operation:
    /// erase the free slot, write every segment, write the trial record.
    fn install(f: &mut Flash, image: &[u8], version: Release, rng: &mut Rng) {
        let slot = f.free_slot();
        f.erase_slot(slot, rng);
        for (n, segment) in image.chunks(SEGMENT).enumerate() {
            f.program(slot, n * SEGMENT, segment, rng);
        }
        if f.image_crc(slot, image.len()) == image_crc(image) {
            f.write_record(Record {
                seq: f.next_seq(),
                slot: slot as u8,
                size: image.len() as u32,
                crc: image_crc(image),
                version,
                trial: true,
            });
        }
    }

    /// The new image came up: it confirms itself.
    fn confirm(f: &mut Flash) {
        if let Some(b) = f.running().filter(|b| b.trial) {
            f.write_record(Record {
                seq: f.next_seq(),
                trial: false,
                ..b.record
            });
        }
    }

    #[test]
    fn images_are_linked_for_slot_0() {
        assert_eq!(slot_base(0), plm_core::app::rfu::image::LINK_BASE);
    }

    #[test]
    fn an_update_boots_on_trial_then_stays_once_confirmed() {
        let mut rng = Rng::new(1);
        let (old, new) = (image(3000, 1), image(2000, 2));
        let mut f = Flash::factory(old.clone().into(), OLD);
        let b = f.boot().unwrap();
        assert_eq!((b.slot, b.record.version, b.trial), (0, OLD, false));
        install(&mut f, &new, NEW, &mut rng);
        // The slot holds the vectors moved to slot 1; sent back, the image.
        assert_ne!(f.slots[1].read(4..8), new[4..8]);
        assert_eq!(f.slots[1].read(0..4), new[..4], "the stack pointer stays");
        assert_eq!(f.slots[1].read(16..20), [0; 4], "an unused vector stays 0");
        assert_eq!(f.image(1, new.len()), new);
        let b = f.boot().unwrap();
        assert_eq!((b.slot, b.record.version, b.trial), (1, NEW, true));
        confirm(&mut f);
        for _ in 0..3 {
            let b = f.boot().unwrap();
            assert_eq!((b.slot, b.record.version, b.trial), (1, NEW, false));
        }
        // And the next update goes to slot 0.
        assert_eq!(f.free_slot(), 0);
    }

    #[test]
    fn an_image_that_never_confirms_gives_way_to_the_old_one() {
        let mut rng = Rng::new(2);
        let mut f = Flash::factory(image(3000, 1).into(), OLD);
        install(&mut f, &image(2000, 2), NEW, &mut rng);
        assert!(f.boot().unwrap().trial);
        // It resets (or loses power) before confirming.
        let b = f.boot().unwrap();
        assert_eq!((b.slot, b.record.version, b.reverted), (0, OLD, true));
        assert_eq!(f.running().unwrap().record.version, OLD);
        assert_eq!(f.boot().unwrap().record.version, OLD);
    }

    /// A power cut at every page operation of an update, its swap, its
    /// first start and its confirmation: every time, the board then
    /// starts an image whose CRC passes, old or new, and a second update
    /// afterwards succeeds.
    #[test]
    fn a_power_cut_anywhere_leaves_a_board_that_starts() {
        let (old, new) = (image(3000, 1), image(1000, 2));
        let steps = |f: &mut Flash, rng: &mut Rng| {
            install(f, &new, NEW, rng);
            if f.boot().is_some_and(|b| b.trial) {
                confirm(f);
            }
        };
        let mut total = Flash::factory(old.clone().into(), OLD);
        total.cut_after(u32::MAX);
        steps(&mut total, &mut Rng::new(3));
        let Power::CutAfter(left) = total.power else {
            panic!("no cut")
        };
        let ops = u32::MAX - left;
        assert!(ops > 60, "{ops} page operations");
        for cut in 0..=ops {
            let mut rng = Rng::new(u64::from(cut));
            let mut f = Flash::factory(old.clone().into(), OLD);
            f.cut_after(cut);
            steps(&mut f, &mut rng);
            f.power_on();
            let b = f
                .boot()
                .unwrap_or_else(|| panic!("cut after {cut}: no image starts"));
            assert!(f.verifies(&b.record), "cut after {cut}");
            assert!(
                [OLD, NEW].contains(&b.record.version),
                "cut after {cut}: {b:?}"
            );
            if b.trial {
                confirm(&mut f);
            }
            let again = image(1500, 9);
            install(&mut f, &again, Release { major: 2, minor: 0 }, &mut rng);
            let b = f.boot().unwrap();
            assert_eq!(
                b.record.version.major, 2,
                "cut after {cut}: the next update"
            );
            assert_eq!(f.image(b.slot, again.len()), again);
        }
    }
}
