//! What a firmware image for the boards' RFU bootloader looks like, and
//! the check the console and `plm board rfu` make before a campaign
//! starts (docs/protocol-notes.md, "The image file").
//!
//! An image is the `.bin` ST's toolchain writes (UM 4.3: the workspace
//! "Firmware - Application standalone", `PLM_HID_STANDALONE.bin`): a raw
//! STM32F103xB image linked for slot 0 ([`LINK_BASE`], after the 4 KB
//! bootloader, UM 4.2), the vector table ([`VECTORS`] bytes) first, then
//! code. Nothing in it names its release. The check reads what a raw
//! image can show: its size, the initial stack pointer, every vector.
//!
//! An image may also carry a 16-byte *descriptor* (decided here, the seed
//! gives none) at [`DESCRIPTOR`], which adds checks: the release it
//! reports, its size and a CRC-32, so that a truncated or damaged file is
//! told from a whole one. `plm board image` and the simulator write it.
//!
//! | offset | bytes | what |
//! |---|---|---|
//! | 0 | 6 | `PLM-FW` |
//! | 6 | 2 | release x, y (what service 06h reports once it runs) |
//! | 8 | 4 | image size, little-endian (the MCU's order) |
//! | 12 | 4 | CRC-32 of the image with these 4 bytes left out, little-endian |

use super::{image_crc, IMAGE_MAX};
use crate::app::release::Release;
use crate::CrcImpl;
use alloc::format;
use alloc::string::String;
use crc::{Crc, CRC_32_ISO_HDLC};

/// Bytes of the interrupt vector table at the start of an image
/// (STM32F103xB, medium density: the initial stack pointer, 15 system
/// exception vectors and 43 interrupt vectors).
pub const VECTORS: usize = 0xEC;
/// Where the flash starts (STM32F10x): an image linked here was built
/// without the bootloader.
pub const FLASH_BASE: u32 = 0x0800_0000;
/// Where images are linked: slot 0, after the 4 KiB bootloader (UM 4.2).
pub const LINK_BASE: u32 = FLASH_BASE + 0x1000;
/// Where the descriptor starts, when there is one (the end of the largest
/// STM32F10x vector table, so that it never overlaps a vector).
pub const DESCRIPTOR: usize = 0x130;
/// The descriptor's mark.
pub const MAGIC: &[u8; 6] = b"PLM-FW";
/// Bytes of the descriptor.
pub const DESCRIPTOR_LEN: usize = 16;
/// The smallest image with a descriptor.
pub const IMAGE_MIN: usize = DESCRIPTOR + DESCRIPTOR_LEN;
/// SRAM of the STM32F103xB (20 KiB): the initial stack pointer is above
/// its start and at most its end.
const SRAM: (u32, u32) = (0x2000_0000, 0x2000_5000);
/// Vector table words that are reserved (0 in real images): 1Ch-28h, 34h.
pub const RESERVED: [usize; 5] = [0x1C, 0x20, 0x24, 0x28, 0x34];
/// The system exceptions' names, by vector number (1-15).
const EXCEPTIONS: [&str; 15] = [
    "Reset",
    "NMI",
    "HardFault",
    "MemManage",
    "BusFault",
    "UsageFault",
    "reserved",
    "reserved",
    "reserved",
    "reserved",
    "SVCall",
    "DebugMon",
    "reserved",
    "PendSV",
    "SysTick",
];

const SIZE_AT: usize = DESCRIPTOR + 8;
const CRC_AT: usize = DESCRIPTOR + 12;

/// What a good image says of itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Image {
    /// The release it reports once it runs: its descriptor's, or the one
    /// the user stated ([`Image::stating`]); `None` for a plain file.
    pub release: Option<Release>,
    /// Its bytes.
    pub size: usize,
    /// CRC-32 of the whole image: what the campaign's header announces.
    pub crc: u32,
    /// It carries a descriptor (release, size and CRC checked).
    pub described: bool,
}

impl Image {
    /// The campaign number to send it under: from its CRC-32, so that the
    /// same image gets the same number from the console and from
    /// `plm board rfu` (a board holding its segments resumes).
    pub fn campaign(&self) -> u8 {
        (self.crc % 255) as u8 + 1
    }

    /// The image with the release the user says it reports (`plm board
    /// rfu --release`, the Update view's field): kept for a plain file,
    /// refused when the descriptor names another.
    pub fn stating(self, stated: Option<Release>) -> Result<Image, String> {
        match (self.release, stated) {
            (Some(own), Some(s)) if own != s => Err(format!(
                "the image says it is release {own}, not {s}: leave the release out, or give the file of {s}"
            )),
            (own, s) => Ok(Image {
                release: own.or(s),
                ..self
            }),
        }
    }

    /// The release in words, as tools show it.
    pub fn release_words(&self) -> String {
        super::release_words(self.release)
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
    if image.starts_with(b"\x7fELF") {
        return Err(
            "an ELF file: give the raw binary (.bin) the toolchain writes beside it".into(),
        );
    }
    if image.first() == Some(&b':') {
        return Err("an Intel HEX file: give the raw binary (.bin) the toolchain writes".into());
    }
    if len <= VECTORS {
        return Err(format!(
            "{len} bytes: too short for an STM32F103 vector table ({VECTORS} bytes) and code"
        ));
    }
    let release = release_of(image);
    if release.is_some() {
        check_descriptor(image)?;
    }
    check_vectors(image)?;
    Ok(Image {
        release,
        size: len,
        crc: image_crc(image),
        described: release.is_some(),
    })
}

/// The descriptor's size and CRC-32 against the file.
fn check_descriptor(image: &[u8]) -> Result<(), String> {
    let len = image.len();
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
    Ok(())
}

/// The vector table of an STM32F103xB application linked for slot 0: the
/// initial stack pointer in SRAM, the reset vector and every other
/// non-zero vector a Thumb address (odd) inside the image, the reserved
/// words 0.
fn check_vectors(image: &[u8]) -> Result<(), String> {
    let not_stm32 = "not an STM32F103 application image";
    let sp = word(image, 0);
    let (sram, sram_end) = SRAM;
    if sp <= sram || sp > sram_end || !sp.is_multiple_of(4) {
        return Err(format!(
            "its first word {sp:08X} is not an initial stack pointer in SRAM \
             ({sram:08X}-{sram_end:08X}): {not_stm32}"
        ));
    }
    let end = LINK_BASE + image.len() as u32;
    let inside = |v: u32| v & 1 == 1 && (LINK_BASE..end).contains(&(v & !1));
    let reset = word(image, 4);
    if !inside(reset) {
        let shifted = FLASH_BASE..FLASH_BASE + image.len() as u32;
        if reset & 1 == 1 && shifted.contains(&(reset & !1)) {
            return Err(format!(
                "its reset vector {reset:08X} points into the bootloader: the image is linked at \
                 {FLASH_BASE:08X}h, built without the bootloader. The boards run images linked at \
                 {LINK_BASE:08X}h: build the workspace \"Firmware - Application standalone\" (UM 4.3)"
            ));
        }
        return Err(format!(
            "its reset vector {reset:08X} is not a Thumb address inside the image as linked for \
             the slot ({LINK_BASE:08X}-{:08X}): {not_stm32}, or linked for another address",
            end - 1
        ));
    }
    for at in (8..VECTORS).step_by(4) {
        let v = word(image, at);
        let n = at / 4;
        let name = match EXCEPTIONS.get(n - 1) {
            Some(e) => format!("{e} vector"),
            None => format!("vector of interrupt {}", n - 16),
        };
        if RESERVED.contains(&at) {
            if v != 0 {
                return Err(format!(
                    "the reserved word at {at:02X}h of its vector table is {v:08X}, not 0: {not_stm32}"
                ));
            }
        } else if v != 0 && !inside(v) {
            return Err(format!(
                "its {name} (at {at:02X}h) is {v:08X}, not a Thumb address inside the image \
                 ({LINK_BASE:08X}-{:08X}): {not_stm32} linked for the slot",
                end - 1
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;
    use alloc::vec::Vec;

    const V: Release = Release { major: 1, minor: 7 };

    /// A raw image as the toolchain writes it: a vector table pointing
    /// at a handler inside, reserved words 0, one unused interrupt 0.
    fn plain(size: usize) -> Vec<u8> {
        let mut image = vec![0x5a; size];
        image[..4].copy_from_slice(&0x2000_5000u32.to_le_bytes());
        for at in (4..VECTORS).step_by(4) {
            let v = if RESERVED.contains(&at) || at == 0x50 {
                0
            } else {
                LINK_BASE + 0x201
            };
            image[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        image
    }

    fn sealed(size: usize) -> Vec<u8> {
        let mut image = plain(size);
        seal(&mut image, V);
        image
    }

    fn with_word(mut image: Vec<u8>, at: usize, v: u32) -> Vec<u8> {
        image[at..at + 4].copy_from_slice(&v.to_le_bytes());
        image
    }

    #[test]
    fn a_plain_image_checks_with_no_release() {
        let image = plain(4_000);
        let info = check(&image).unwrap();
        assert_eq!(info.release, None);
        assert!(!info.described);
        assert_eq!(info.size, 4_000);
        assert_eq!(info.crc, image_crc(&image));
        assert!(info.release_words().contains("not stated"));
    }

    #[test]
    fn a_sealed_image_checks_with_its_release() {
        let image = sealed(4_000);
        let info = check(&image).unwrap();
        assert_eq!(info.release, Some(V));
        assert!(info.described);
        assert_eq!(info.crc, image_crc(&image));
    }

    #[test]
    fn a_stated_release_is_kept_unless_the_descriptor_names_another() {
        let s = Release { major: 2, minor: 0 };
        let plain = check(&plain(4_000)).unwrap();
        assert_eq!(plain.stating(Some(s)).unwrap().release, Some(s));
        assert_eq!(plain.stating(None).unwrap().release, None);
        let sealed = check(&sealed(4_000)).unwrap();
        assert_eq!(sealed.stating(None).unwrap().release, Some(V));
        assert_eq!(sealed.stating(Some(V)).unwrap().release, Some(V));
        let why = sealed.stating(Some(s)).unwrap_err();
        assert!(why.contains("says it is release 1.7, not 2.0"), "{why}");
    }

    #[test]
    fn campaigns_are_1_to_255() {
        let with = |crc| {
            Image {
                crc,
                ..check(&sealed(4_000)).unwrap()
            }
            .campaign()
        };
        assert_eq!(with(0), 1);
        assert_eq!(with(254), 255);
        assert_eq!(with(255), 1);
        assert_eq!(with(u32::MAX), (u32::MAX % 255) as u8 + 1);
    }

    #[test]
    fn a_descriptor_that_does_not_match_is_refused_in_words() {
        let image = sealed(4_000);
        let why = |b: &[u8]| check(b).unwrap_err();
        assert!(why(&image[..3_000]).starts_with("truncated: the image says 4000 bytes"));
        assert!(why(&[image.clone(), vec![0; 4]].concat()).contains("4 bytes more"));
        let mut bad = image;
        bad[2_000] ^= 1;
        assert!(why(&bad).starts_with("damaged"));
    }

    #[test]
    fn a_file_that_cannot_be_an_application_for_the_slot_is_refused_in_words() {
        let why = |b: Vec<u8>| check(&b).unwrap_err();
        assert!(why(vec![0; IMAGE_MAX + 1]).contains("larger than"));
        assert!(why(plain(VECTORS)).contains("too short"));
        assert!(why([b"\x7fELF".to_vec(), plain(400)].concat()).contains("ELF"));
        assert!(why(b":020000040800F2\n".repeat(40)).contains("Intel HEX"));
        assert!(why(vec![0; 1_000]).contains("initial stack pointer"));
        assert!(why(with_word(plain(4_000), 0, 0x2000_5004)).contains("initial stack pointer"));
        // Built without the bootloader: every vector 4 KiB lower.
        let mut at_base = plain(4_000);
        for at in (4..VECTORS).step_by(4) {
            let v = word(&at_base, at);
            if v != 0 {
                at_base = with_word(at_base, at, v - 0x1000);
            }
        }
        let w = why(at_base);
        assert!(w.contains("built without the bootloader"), "{w}");
        assert!(w.contains("08001000h"), "{w}");
        let even = why(with_word(plain(4_000), 4, LINK_BASE + 0x200));
        assert!(even.contains("reset vector 08001200"), "{even}");
        let far = why(with_word(plain(4_000), 4, LINK_BASE + 10_001));
        assert!(far.contains("reset vector"), "{far}");
        let irq = why(with_word(plain(4_000), 0x40 + 4 * 5, 0x0800_0001));
        assert!(irq.contains("vector of interrupt 5 (at 54h)"), "{irq}");
        let hard = why(with_word(plain(4_000), 0x0C, 0xFFFF_FFFF));
        assert!(hard.contains("HardFault vector"), "{hard}");
        let reserved = why(with_word(plain(4_000), 0x1C, 1));
        assert!(reserved.contains("reserved word at 1Ch"), "{reserved}");
        // A sealed image is held to the same table.
        let mut bad = with_word(plain(4_000), 4, 0);
        seal(&mut bad, V);
        assert!(why(bad).contains("reset vector"));
    }
}
