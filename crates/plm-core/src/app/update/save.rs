//! A campaign kept across a closed console or a pulled cable: what
//! [`Update::save`] writes and [`Update::resume`] reads (docs/
//! protocol-notes.md, "The update engine"). The image itself is kept
//! beside it (the console's storage, or the CLI's image file) and checked
//! against the saved header's CRC-32 on resume.
//!
//! Layout, numbers big-endian: `PLMRFU` 01h; the header as the 0Ch
//! request's payload, after its length; gap, restart and back-off in µs
//! (u64); repair rounds, silences, restarts; the phase (tag, segment u16);
//! bytes sent (u64); the boards (u16), each: address, state tag,
//! silences, restarts, then for a board receiving its status asks and the
//! segments it misses (u16 count, u16 each), for a failed one its reason
//! (u16 length, UTF-8).
//!
//! On resume, a request whose answer never came is asked again (every RFU
//! request may be repeated: a header of the campaign a board holds
//! resumes it, a swap already made is acknowledged again), a board
//! restarting gets the restart time again, a board done has its release
//! read back again (it may have been replaced, or gone back to its old
//! image, while nobody watched), and back-offs start afresh.

use super::{BoardState, Phase, Target, Update, UpdateConfig, Waiting};
use crate::app::frame::Address;
use crate::app::rfu::{self, Header};
use crate::app::service::Service;
use crate::time::Instant;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

const MAGIC: &[u8; 7] = b"PLMRFU\x01";

/// Most bytes a saved campaign may say it sent: 1 TiB, nine years of
/// the fastest line (28.8 kbit/s), so that counting on cannot overflow.
const SENT_MOST: u64 = 1 << 40;

impl Update {
    /// The campaign's progress, to keep until [`Update::resume`].
    pub fn save(&self) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        let header = Service::RfuHeader(self.header).payload();
        out.push(header.len() as u8);
        out.extend(header);
        let c = &self.config;
        for d in [c.gap, c.restart, c.backoff] {
            out.extend(d.to_be_bytes());
        }
        out.extend([c.repair_rounds, c.silences, c.restarts]);
        let (tag, n) = match self.phase {
            Phase::Announce => (0, 0),
            Phase::Broadcast(n) => (1, n),
            Phase::Repair => (2, 0),
            Phase::Swap => (3, 0),
            Phase::Abort => (4, 0),
            Phase::Over => (5, 0),
        };
        out.push(tag);
        out.extend((n as u16).to_be_bytes());
        out.extend(self.sent.to_be_bytes());
        out.extend((self.targets.len() as u16).to_be_bytes());
        for t in &self.targets {
            out.extend(t.address.0);
            let tag = match &t.state {
                BoardState::Announcing => 0,
                BoardState::Receiving { .. } => 1,
                BoardState::Complete => 2,
                BoardState::Restarting(_) => 3,
                BoardState::Done => 4,
                BoardState::Aborted => 5,
                BoardState::Failed(_) => 6,
            };
            out.extend([tag, t.silences, t.restarts]);
            match &t.state {
                BoardState::Receiving { missing, asked } => {
                    out.push(*asked);
                    out.extend((missing.len() as u16).to_be_bytes());
                    for m in missing {
                        out.extend((*m as u16).to_be_bytes());
                    }
                }
                BoardState::Failed(why) => {
                    out.extend((why.len() as u16).to_be_bytes());
                    out.extend(why.as_bytes());
                }
                _ => {}
            }
        }
        out
    }

    /// The campaign `saved` describes, at `now`, sending `image`. Refused
    /// in words when `saved` is not a saved campaign or `image` is not the
    /// image it was sending.
    pub fn resume(image: Vec<u8>, saved: &[u8], now: Instant) -> Result<Update, String> {
        let mut r = Reader(saved);
        if r.take(MAGIC.len())? != MAGIC {
            return Err("not a saved firmware update (or one of another version)".into());
        }
        let len = r.u8()? as usize;
        let header: Header = match Service::parse(r.take(len)?) {
            Ok(Service::RfuHeader(h)) => h,
            _ => return Err("the saved update's header does not parse".into()),
        };
        if image.len() != header.size as usize || rfu::image_crc(&image) != header.crc {
            return Err(format!(
                "this image is not the one the saved update was sending (campaign {}, release {}, {} bytes, CRC-32 {:08X})",
                header.campaign, header.version, header.size, header.crc
            ));
        }
        let config = UpdateConfig {
            gap: r.u64()?,
            restart: r.u64()?,
            backoff: r.u64()?,
            repair_rounds: r.u8()?,
            silences: r.u8()?,
            restarts: r.u8()?,
        };
        config
            .check()
            .map_err(|why| format!("the saved update's pacing is refused: {why}"))?;
        let tag = r.u8()?;
        let n = r.u16()? as usize;
        let phase = match tag {
            0 => Phase::Announce,
            1 => Phase::Broadcast(n),
            2 => Phase::Repair,
            3 => Phase::Swap,
            4 => Phase::Abort,
            5 => Phase::Over,
            _ => return Err("the saved update's phase is unknown".into()),
        };
        let segments = header.segments();
        if n > segments {
            return Err(format!(
                "the saved update's broadcast is at segment {n}, past the image's {segments}"
            ));
        }
        let sent = r.u64()?;
        if sent > SENT_MOST {
            return Err(format!(
                "the saved update says {sent} bytes sent, more than a power line carries in years"
            ));
        }
        let count = r.u16()?;
        if count == 0 {
            return Err("the saved update has no board".into());
        }
        let mut targets = Vec::new();
        for _ in 0..count {
            let mut address = Address([0; 6]);
            address.0.copy_from_slice(r.take(6)?);
            let tag = r.u8()?;
            let (silences, restarts) = (r.u8()?, r.u8()?);
            let state = match tag {
                0 => BoardState::Announcing,
                1 => {
                    let asked = r.u8()?;
                    let n = r.u16()?;
                    let missing: Vec<usize> = (0..n)
                        .map(|_| r.u16().map(usize::from))
                        .collect::<Result<_, _>>()?;
                    if let Some(m) = missing.iter().find(|&&m| m >= segments) {
                        return Err(format!(
                            "a saved board misses segment {m}, past the image's {segments}"
                        ));
                    }
                    BoardState::Receiving { missing, asked }
                }
                2 => BoardState::Complete,
                3 => BoardState::Restarting(now),
                // Read back at once (`rechecked`): the board may have been
                // replaced, or its trial cut short, while nobody watched.
                4 => BoardState::Restarting(now),
                5 => BoardState::Aborted,
                6 => {
                    let n = r.u16()? as usize;
                    let why = core::str::from_utf8(r.take(n)?)
                        .map_err(|_| String::from("a saved reason is not UTF-8"))?;
                    BoardState::Failed(why.into())
                }
                _ => return Err("a saved board's state is unknown".into()),
            };
            if targets.iter().any(|t: &Target| t.address == address) {
                return Err("the saved update names a board twice".into());
            }
            targets.push(Target {
                address,
                rechecked: tag == 4,
                firmware: None,
                state,
                silences,
                restarts,
                not_before: now,
            });
        }
        if !r.0.is_empty() {
            return Err("the saved update has bytes after its last board".into());
        }
        Ok(Update {
            header,
            image,
            config,
            targets,
            phase,
            waiting: Waiting::Nothing,
            sent,
        })
    }
}

/// Reads a saved campaign front to back.
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.0.len() < n {
            return Err("the saved update is cut short".into());
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_be_bytes([self.u8()?, self.u8()?]))
    }

    fn u64(&mut self) -> Result<u64, String> {
        let mut b = [0; 8];
        b.copy_from_slice(self.take(8)?);
        Ok(u64::from_be_bytes(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::message::Message;
    use crate::app::service::Release;

    /// Hands `u` an answer, owned as tests build them.
    fn answer(u: &mut Update, now: Instant, a: Result<Message, String>) {
        u.on_answer(now, a.as_ref().map_err(String::as_str));
    }

    #[test]
    fn a_campaign_saved_mid_way_resumes_where_it_was() {
        let image: Vec<u8> = (0..1_000u32).map(|i| (i * 3) as u8).collect();
        let a = [Address::from_u64(1), Address::from_u64(2)];
        let v = Release { major: 3, minor: 2 };
        let mut u = Update::new(7, v, image.clone(), &a, UpdateConfig::default()).unwrap();
        u.poll(0).unwrap();
        answer(&mut u, 0, Err("silent".into()));
        u.poll(0).unwrap();
        answer(
            &mut u,
            0,
            Ok(Message::Ack {
                frame_type: crate::app::frame::FrameType::Service,
                echo: 0x0c,
            }),
        );
        for t in 0..4 {
            u.poll(t * 250_000).unwrap();
        }
        let saved = u.save();
        let mut back = Update::resume(image.clone(), &saved, 5_000_000).unwrap();
        assert_eq!(back.save(), saved);
        assert_eq!(back.bytes_sent(), 4 * 96);
        // The broadcast goes on with segment 4.
        let r = back.poll(5_000_000).unwrap();
        assert!(matches!(
            r.message,
            Message::Service(Service::RfuData { segment: 4, .. })
        ));
        // Another image, or a damaged save, is refused in words.
        let mut other = image.clone();
        other[0] ^= 1;
        assert!(Update::resume(other, &saved, 0)
            .unwrap_err()
            .contains("not the one"));
        assert!(Update::resume(image.clone(), &saved[..saved.len() - 1], 0).is_err());
        assert!(Update::resume(image, &[0; 40], 0)
            .unwrap_err()
            .contains("not a saved"));
    }
}
