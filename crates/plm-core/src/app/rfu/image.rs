//! What a firmware image for the boards' RFU bootloader looks like, and
//! the check the console and `plm board rfu` make before a campaign
//! starts (docs/protocol-notes.md, "The image file").
//!
//! An image is linked for slot 0 ([`LINK_BASE`]) and starts with the
//! STM32F10x vector table ([`VECTORS`] bytes, UM 4.2: "the interrupt
//! vector table relocated by slot"). Right after it comes a 16-byte
//! *descriptor* (decided here: the seed gives none) that lets a tool tell
//! a whole image from a truncated or damaged file before sending a byte:
//!
//! | offset | bytes | what |
//! |---|---|---|
//! | 0 | 6 | `PLM-FW` |
//! | 6 | 2 | release x, y (what service 06h reports once it runs) |
//! | 8 | 4 | image size, little-endian (the MCU's order) |
//! | 12 | 4 | CRC-32 of the image with these 4 bytes left out, little-endian |

use super::{image_crc, IMAGE_MAX};
use crate::app::service::Release;
use crate::CrcImpl;
use alloc::format;
use alloc::string::String;
use crc::{Crc, CRC_32_ISO_HDLC};

/// Bytes of the interrupt vector table at the start of an image
/// (STM32F10x: the initial stack pointer and 75 vectors).
pub const VECTORS: usize = 0x130;
/// Where images are linked: slot 0, after the 4 KiB bootloader (UM 4.2).
pub const LINK_BASE: u32 = 0x0800_1000;
/// Where the descriptor starts.
pub const DESCRIPTOR: usize = VECTORS;
/// The descriptor's mark.
pub const MAGIC: &[u8; 6] = b"PLM-FW";
/// Bytes of the descriptor.
pub const DESCRIPTOR_LEN: usize = 16;
/// The smallest image: a vector table and a descriptor.
pub const IMAGE_MIN: usize = DESCRIPTOR + DESCRIPTOR_LEN;
/// SRAM of the STM32F10x (the initial stack pointer points into it).
const SRAM: core::ops::RangeInclusive<u32> = 0x2000_0000..=0x2001_0000;

const SIZE_AT: usize = DESCRIPTOR + 8;
const CRC_AT: usize = DESCRIPTOR + 12;

/// What a good image says of itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Image {
    /// The release it reports once it runs.
    pub version: Release,
    /// Its bytes.
    pub size: usize,
    /// CRC-32 of the whole image: what the campaign's header announces.
    pub crc: u32,
}

impl Image {
    /// The campaign number to send it under: from its CRC-32, so that the
    /// same image gets the same number from the console and from
    /// `plm board rfu` (a board holding its segments resumes).
    pub fn campaign(&self) -> u8 {
        (self.crc % 255) as u8 + 1
    }
}

fn word(image: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([image[at], image[at + 1], image[at + 2], image[at + 3]])
}

/// The CRC-32 the descriptor holds: of the image without its 4 bytes.
fn descriptor_crc(image: &[u8]) -> u32 {
    let crc = Crc::<u32, CrcImpl>::new(&CRC_32_ISO_HDLC);
    let mut d = crc.digest();
    d.update(&image[..CRC_AT]);
    d.update(&image[CRC_AT + 4..]);
    d.finalize()
}

/// Writes the descriptor of `image` (release `version`) into it.
pub fn seal(image: &mut [u8], version: Release) {
    let size = image.len() as u32;
    image[DESCRIPTOR..DESCRIPTOR + 6].copy_from_slice(MAGIC);
    image[DESCRIPTOR + 6] = version.major;
    image[DESCRIPTOR + 7] = version.minor;
    image[SIZE_AT..SIZE_AT + 4].copy_from_slice(&size.to_le_bytes());
    let crc = descriptor_crc(image);
    image[CRC_AT..CRC_AT + 4].copy_from_slice(&crc.to_le_bytes());
}

/// The release an image's descriptor names, if it has one.
pub fn release_of(image: &[u8]) -> Option<Release> {
    (image.len() >= IMAGE_MIN && image[DESCRIPTOR..DESCRIPTOR + 6] == MAGIC[..]).then(|| Release {
        major: image[DESCRIPTOR + 6],
        minor: image[DESCRIPTOR + 7],
    })
}

/// Whether `image` can be a whole firmware image; the reason in words if
/// not.
pub fn check(image: &[u8]) -> Result<Image, String> {
    let len = image.len();
    if len > IMAGE_MAX {
        return Err(format!(
            "{len} bytes: larger than a board's image slot ({IMAGE_MAX} bytes)"
        ));
    }
    if len < IMAGE_MIN {
        return Err(format!(
            "{len} bytes: too short to hold a vector table and an image descriptor ({IMAGE_MIN} bytes)"
        ));
    }
    let Some(version) = release_of(image) else {
        return Err(format!(
            "no image descriptor ({}) at offset {DESCRIPTOR:#x}: not a firmware image for the boards' bootloader",
            "PLM-FW"
        ));
    };
    let size = word(image, SIZE_AT) as usize;
    if size > len {
        return Err(format!(
            "truncated: the image says {size} bytes and the file has {len}"
        ));
    }
    if size < len {
        return Err(format!(
            "{} bytes more than the image says ({size}): not the file the build wrote",
            len - size
        ));
    }
    let (said, is) = (word(image, CRC_AT), descriptor_crc(image));
    if said != is {
        return Err(format!(
            "damaged: its CRC-32 is {is:08X}, its descriptor says {said:08X}"
        ));
    }
    let sp = word(image, 0);
    if !SRAM.contains(&sp) {
        return Err(format!(
            "its initial stack pointer {sp:08X} is not in SRAM: not an STM32 image"
        ));
    }
    let reset = word(image, 4);
    let end = LINK_BASE + size as u32;
    if reset & 1 == 0 || !(LINK_BASE..end).contains(&(reset & !1)) {
        return Err(format!(
            "its reset vector {reset:08X} is not in the image ({LINK_BASE:08X}-{:08X}): linked for another address?",
            end - 1
        ));
    }
    Ok(Image {
        version,
        size,
        crc: image_crc(image),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;
    use alloc::vec::Vec;

    const V: Release = Release { major: 1, minor: 7 };

    fn good(size: usize) -> Vec<u8> {
        let mut image = vec![0x5a; size];
        image[..4].copy_from_slice(&0x2000_5000u32.to_le_bytes());
        image[4..8].copy_from_slice(&(LINK_BASE + 0x201).to_le_bytes());
        seal(&mut image, V);
        image
    }

    #[test]
    fn a_sealed_image_checks() {
        let image = good(4_000);
        let info = check(&image).unwrap();
        assert_eq!(info.version, V);
        assert_eq!(info.size, 4_000);
        assert_eq!(info.crc, image_crc(&image));
    }

    #[test]
    fn campaigns_are_1_to_255() {
        let with = |crc| {
            Image {
                crc,
                ..check(&good(4_000)).unwrap()
            }
            .campaign()
        };
        assert_eq!(with(0), 1);
        assert_eq!(with(254), 255);
        assert_eq!(with(255), 1);
        assert_eq!(with(u32::MAX), (u32::MAX % 255) as u8 + 1);
    }

    #[test]
    fn every_fault_is_refused_in_words() {
        let image = good(4_000);
        let why = |b: &[u8]| check(b).unwrap_err();
        assert!(why(&image[..3_000]).starts_with("truncated: the image says 4000 bytes"));
        assert!(why(&image[..100]).contains("too short"));
        assert!(why(&[image.clone(), vec![0; 4]].concat()).contains("4 bytes more"));
        assert!(why(&vec![0; IMAGE_MAX + 1]).contains("larger than"));
        assert!(why(&vec![0; 1_000]).contains("no image descriptor"));
        let mut bad = image.clone();
        bad[2_000] ^= 1;
        assert!(why(&bad).starts_with("damaged"));
        let mut bad = image.clone();
        bad[..4].copy_from_slice(&0x1000u32.to_le_bytes());
        seal(&mut bad, V);
        assert!(why(&bad).contains("stack pointer"));
        let mut bad = image;
        bad[4..8].copy_from_slice(&(LINK_BASE + 10_000).to_le_bytes());
        seal(&mut bad, V);
        assert!(why(&bad).contains("reset vector"));
    }
}
