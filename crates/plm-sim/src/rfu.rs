//! The board firmware's RFU manager (STEVAL-IHP007V1 UM 4.2): what a
//! simulated board does with the remote firmware update commands
//! (`plm_core::app::rfu`), on its [`Flash`]. Decisions:
//! docs/protocol-notes.md, "Remote firmware update".
//!
//! - A header opens a campaign on the free slot (erased at once), or
//!   resumes the same campaign (same number, size and CRC) with the
//!   segments already held.
//! - Segments are written as they come, in any order, a repeat written
//!   again; data of another campaign is ignored.
//! - The swap checks that every segment is held and that the slot's image
//!   has the CRC-32 sent, writes the trial boot record, is acknowledged,
//!   and the board resets [`SWAP_RESET`] later.
//! - An image that comes up confirms itself [`CONFIRM_AFTER`] after its
//!   start; one that does not resets [`FAIL_AFTER`] after it, and the
//!   bootloader goes back to the old image. A simulated image "comes up"
//!   when its descriptor names the release its header announced
//!   ([`firmware_image`] builds such images), or, with no descriptor
//!   ([`plain_image`]), when its vector table is an application's; it
//!   reports the release its header announced (0.0 when none was stated).

use crate::flash::{Boot, Flash, Record};
use crate::rng::Rng;
use plm_core::app::rfu::image::{self, VECTORS};
use plm_core::app::rfu::{self, Header, RfuReason, RfuState, Status, BITMAP_LEN, SEGMENT};
use plm_core::app::{Release, Service};
use plm_core::time::{Duration, Instant, MS};
use std::sync::{Arc, OnceLock};

/// From the swap's acknowledgement to the reset into the new image (the
/// ACK must leave first).
pub const SWAP_RESET: Duration = 300 * MS;
/// How long a new image runs before it confirms itself (model).
pub const CONFIRM_AFTER: Duration = 5_000 * MS;
/// How long an image that does not come up lasts before the watchdog
/// resets the board (model).
pub const FAIL_AFTER: Duration = 2_000 * MS;
/// Bytes of the simulated boards' factory image.
pub const FACTORY_SIZE: usize = 24 * 1024;

/// A simulated raw image of `size` bytes as ST's toolchain writes one
/// (UM 4.3: the application's `.bin`, no descriptor): an initial stack
/// pointer, every vector into slot 0 (the reserved ones 0), then bytes that
/// stand for code (`seed` varies them). It names no release.
pub fn plain_image(seed: u8, size: usize) -> Vec<u8> {
    let size = size.clamp(VECTORS + 4, rfu::IMAGE_MAX);
    let mut bytes: Vec<u8> = (0..size)
        .map(|i| (i as u32).wrapping_mul(2_654_435_761).to_be_bytes()[0] ^ seed)
        .collect();
    bytes[..4].copy_from_slice(&0x2000_5000u32.to_le_bytes());
    for (n, at) in (4..VECTORS).step_by(4).enumerate() {
        let v = if image::RESERVED.contains(&at) {
            0
        } else {
            image::LINK_BASE + VECTORS as u32 + 4 * n as u32 + 1
        };
        bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
    }
    bytes
}

/// A simulated firmware image of `size` bytes (at least a vector table and
/// the descriptor) for release `version`: a [`plain_image`] sealed with its
/// descriptor (`plm_core::app::rfu::image`), so that the console and
/// `plm board rfu` check its release, size and CRC too.
pub fn firmware_image(version: Release, size: usize) -> Vec<u8> {
    let mut bytes = plain_image(version.minor, size.max(image::IMAGE_MIN));
    image::seal(&mut bytes, version);
    bytes
}

/// The factory image of release `version`, shared by every board.
fn factory_image(version: Release) -> Arc<[u8]> {
    static FACTORY: OnceLock<(Release, Arc<[u8]>)> = OnceLock::new();
    let (v, image) =
        FACTORY.get_or_init(|| (version, firmware_image(version, FACTORY_SIZE).into()));
    if *v == version {
        image.clone()
    } else {
        firmware_image(version, FACTORY_SIZE).into()
    }
}

/// Whether the image `record` names comes up: its descriptor names the
/// release its header announced (an image of another release stands for
/// firmware that crashes at start); an image without one, when it passes
/// the check tools make (a vector table of an application for the slot).
fn comes_up(flash: &Flash, record: &Record) -> bool {
    let bytes = flash.image(record.slot as usize, record.size as usize);
    match image::release_of(&bytes) {
        Some(release) => release == record.version,
        None => image::check(&bytes).is_ok(),
    }
}

/// A campaign under way.
#[derive(Debug, Clone)]
struct Campaign {
    header: Header,
    slot: usize,
    bitmap: Vec<u8>,
    received: u16,
}

impl Campaign {
    fn has(&self, i: usize) -> bool {
        self.bitmap[i / 8] & (1 << (i % 8)) != 0
    }

    fn complete(&self) -> bool {
        self.received as usize == self.header.segments()
    }
}

/// What the manager answers a request with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Answer {
    /// The APP_ACK_FRAME.
    Ack,
    /// APP_ERROR_SERVICE_CMD_ERROR (the status says why).
    Refused,
    /// A reply.
    Reply(Service),
    /// Nothing (segments).
    Nothing,
}

/// The RFU manager of one board, with the board's flash.
#[derive(Debug, Clone)]
pub struct RfuManager {
    flash: Flash,
    running: Boot,
    campaign: Option<Campaign>,
    /// The campaign last heard of and what went wrong with it.
    last: (u8, RfuReason),
    /// The campaign whose image runs, confirmed.
    done: Option<u8>,
    reset_at: Option<Instant>,
    confirm_at: Option<Instant>,
}

impl RfuManager {
    /// A board fresh from the factory with release `version`, started at
    /// `now`.
    pub fn factory(now: Instant, version: Release) -> RfuManager {
        RfuManager::start(now, Flash::factory(factory_image(version), version))
    }

    /// A board starting at `now` on `flash`.
    pub fn start(now: Instant, mut flash: Flash) -> RfuManager {
        let running = flash
            .boot()
            .expect("a board's flash always holds an image that starts");
        let mut m = RfuManager {
            flash,
            running,
            campaign: None,
            last: (0, RfuReason::None),
            done: None,
            reset_at: None,
            confirm_at: None,
        };
        m.after_start(now);
        m
    }

    fn after_start(&mut self, now: Instant) {
        if self.running.reverted {
            self.last.1 = RfuReason::Reverted;
        }
        if self.running.trial {
            if comes_up(&self.flash, &self.running.record) {
                self.confirm_at = Some(now + CONFIRM_AFTER);
            } else {
                self.reset_at = Some(now + FAIL_AFTER);
            }
        }
    }

    /// The release of the image that runs (service 06h).
    pub fn version(&self) -> Release {
        self.running.record.version
    }

    /// The flash, for tests and the simulator's faults.
    pub fn flash_mut(&mut self) -> &mut Flash {
        &mut self.flash
    }

    /// The board loses power and gets it back at `now`: RAM is gone (the
    /// campaign with it), the bootloader starts again.
    pub fn power_cycle(&mut self, now: Instant) {
        self.flash.power_on();
        self.reset(now);
    }

    /// The board resets at `now` (watchdog, or after a swap): as a power
    /// cycle, but a flash whose power went stays without.
    pub fn reset(&mut self, now: Instant) {
        // A campaign under way is lost with the RAM: "done" no longer
        // describes the campaign the status reports on.
        let done = self.done.filter(|_| self.campaign.is_none());
        let last = self.last;
        *self = RfuManager::start(now, self.flash.clone());
        // What the board reports survives in its flash (model): the
        // reason of the last campaign and whether one finished.
        self.done = done.filter(|_| !self.running.trial && !self.running.reverted);
        if self.last.1 == RfuReason::None {
            self.last = last;
        }
    }

    /// When [`RfuManager::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        plm_core::time::earliest(self.reset_at, self.confirm_at)
    }

    /// Runs what is due; `true` when the board reset (the caller forgets
    /// its own RAM state too).
    pub fn handle_timeout(&mut self, now: Instant) -> bool {
        if self.confirm_at.is_some_and(|t| t <= now) {
            self.confirm_at = None;
            let r = self.running.record;
            self.flash.write_record(Record {
                seq: self.flash.next_seq(),
                trial: false,
                ..r
            });
            self.running.trial = false;
            self.done = Some(self.last.0);
        }
        if self.reset_at.is_some_and(|t| t <= now) {
            self.reset(now);
            return true;
        }
        false
    }

    /// What the board does with an RFU request (`None`: not an RFU
    /// command).
    pub fn handle(&mut self, now: Instant, s: &Service, rng: &mut Rng) -> Option<Answer> {
        Some(match s {
            Service::RfuHeader(h) => self.header(h, rng),
            Service::RfuData {
                campaign,
                segment,
                data,
            } => {
                self.data(*campaign, *segment as usize, data, rng);
                Answer::Nothing
            }
            Service::RfuSwap { campaign, crc } => self.swap(now, *campaign, *crc),
            Service::RfuStatusGet { .. } => Answer::Reply(Service::RfuStatus(self.status())),
            Service::RfuAbort { campaign } => {
                if self
                    .campaign
                    .as_ref()
                    .is_some_and(|c| c.header.campaign == *campaign)
                {
                    self.campaign = None;
                    self.last = (*campaign, RfuReason::Aborted);
                }
                Answer::Ack
            }
            _ => return None,
        })
    }

    fn refuse(&mut self, campaign: u8, why: RfuReason) -> Answer {
        self.last = (campaign, why);
        Answer::Refused
    }

    fn header(&mut self, h: &Header, rng: &mut Rng) -> Answer {
        if h.size == 0 || h.size as usize > rfu::IMAGE_MAX {
            return self.refuse(h.campaign, RfuReason::TooLarge);
        }
        if h.segment as usize != SEGMENT {
            return self.refuse(h.campaign, RfuReason::SegmentSize);
        }
        if self.running.trial {
            // The last update's image has not confirmed itself: its
            // fallback, in the other slot, must not be erased yet.
            return self.refuse(h.campaign, RfuReason::OtherCampaign);
        }
        if self.campaign.as_ref().is_some_and(|c| c.header == *h) {
            return Answer::Ack; // the same campaign again: resume
        }
        let slot = self.flash.free_slot();
        self.flash.erase_slot(slot, rng);
        self.campaign = Some(Campaign {
            header: *h,
            slot,
            bitmap: vec![0; BITMAP_LEN],
            received: 0,
        });
        self.last = (h.campaign, RfuReason::None);
        Answer::Ack
    }

    fn data(&mut self, campaign: u8, segment: usize, data: &[u8], rng: &mut Rng) {
        let Some(c) = self.campaign.as_mut() else {
            return;
        };
        if c.header.campaign != campaign {
            self.last = (c.header.campaign, RfuReason::OtherCampaign);
            return;
        }
        let count = c.header.segments();
        let want = if segment + 1 == count {
            c.header.size as usize - SEGMENT * (count - 1)
        } else {
            SEGMENT
        };
        if segment >= count || data.len() != want {
            return;
        }
        self.flash.program(c.slot, segment * SEGMENT, data, rng);
        if !c.has(segment) {
            c.bitmap[segment / 8] |= 1 << (segment % 8);
            c.received += 1;
        }
    }

    fn swap(&mut self, now: Instant, campaign: u8, crc: u32) -> Answer {
        // Swapped already, the ACK lost and the swap asked again (before
        // the restart, or after it with the new image running): the same
        // answer again.
        if self.last == (campaign, RfuReason::None)
            && (self.reset_at.is_some() || self.running.record.crc == crc)
            && self.campaign.is_none()
        {
            return Answer::Ack;
        }
        let Some(c) = self
            .campaign
            .as_ref()
            .filter(|c| c.header.campaign == campaign)
        else {
            return self.refuse(campaign, RfuReason::OtherCampaign);
        };
        if !c.complete() {
            return self.refuse(campaign, RfuReason::Missing);
        }
        let (slot, header) = (c.slot, c.header);
        if crc != header.crc {
            return self.refuse(campaign, RfuReason::Crc);
        }
        if self.flash.image_crc(slot, header.size as usize) != crc {
            // What it holds will never check: forget it, so that the
            // campaign's header starts it over (protocol-notes.md).
            self.campaign = None;
            return self.refuse(campaign, RfuReason::Crc);
        }
        self.flash.write_record(Record {
            seq: self.flash.next_seq(),
            slot: slot as u8,
            size: header.size,
            crc,
            version: header.version,
            trial: true,
        });
        self.reset_at = Some(now + SWAP_RESET);
        self.last = (campaign, RfuReason::None);
        self.campaign = None;
        Answer::Ack
    }

    /// RFU_STATUS_GET's reply.
    pub fn status(&self) -> Status {
        let (campaign, state, received, bitmap) = match &self.campaign {
            Some(c) => (
                c.header.campaign,
                if c.complete() {
                    RfuState::Complete
                } else {
                    RfuState::Receiving
                },
                c.received,
                c.bitmap.clone(),
            ),
            None => {
                let state = match (self.running.trial, self.done) {
                    (true, _) => RfuState::Trial,
                    (false, Some(_)) => RfuState::Done,
                    _ => RfuState::Idle,
                };
                (self.last.0, state, 0, vec![0; BITMAP_LEN])
            }
        };
        Status {
            campaign,
            state: state.byte(),
            reason: self.last.1.byte(),
            received,
            bitmap,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::app::rfu::Header;

    const S: Duration = 1_000 * MS;
    const OLD: Release = Release { major: 1, minor: 4 };
    const NEW: Release = Release { major: 1, minor: 5 };

    fn send_all(
        m: &mut RfuManager,
        campaign: u8,
        image: &[u8],
        skip: Option<usize>,
        rng: &mut Rng,
    ) {
        for (n, seg) in image.chunks(SEGMENT).enumerate().rev() {
            if Some(n) != skip {
                let s = Service::RfuData {
                    campaign,
                    segment: n as u16,
                    data: seg.to_vec(),
                };
                assert_eq!(m.handle(0, &s, rng), Some(Answer::Nothing));
            }
        }
    }

    fn run(m: &mut RfuManager, from: Instant, to: Instant) -> Instant {
        let mut now = from;
        while let Some(t) = m.poll_timeout().filter(|t| *t <= to) {
            now = t;
            m.handle_timeout(now);
        }
        now.max(to)
    }

    #[test]
    fn an_update_with_a_missing_segment_resumes_swaps_and_confirms() {
        let mut rng = Rng::new(1);
        let mut m = RfuManager::factory(0, OLD);
        assert_eq!(m.version(), OLD);
        let image = firmware_image(NEW, 5_000);
        let h = Header::of(9, NEW, &image);
        assert_eq!(
            m.handle(0, &Service::RfuHeader(h), &mut rng),
            Some(Answer::Ack)
        );
        send_all(&mut m, 9, &image, Some(17), &mut rng);
        let st = m.status();
        assert_eq!(st.state(), Some(RfuState::Receiving));
        assert_eq!(st.missing(h.segments()).collect::<Vec<_>>(), [17]);
        // Too early: refused, and the status says why.
        let swap = Service::RfuSwap {
            campaign: 9,
            crc: h.crc,
        };
        assert_eq!(m.handle(0, &swap, &mut rng), Some(Answer::Refused));
        assert_eq!(m.status().reason(), Some(RfuReason::Missing));
        // The header again (a console that was closed): the segments stay.
        assert_eq!(
            m.handle(0, &Service::RfuHeader(h), &mut rng),
            Some(Answer::Ack)
        );
        assert_eq!(m.status().received as usize, h.segments() - 1);
        let seg = &image[17 * SEGMENT..18 * SEGMENT];
        let data = Service::RfuData {
            campaign: 9,
            segment: 17,
            data: seg.to_vec(),
        };
        m.handle(0, &data, &mut rng);
        assert_eq!(m.status().state(), Some(RfuState::Complete));
        assert_eq!(m.handle(0, &swap, &mut rng), Some(Answer::Ack));
        let t = run(&mut m, 0, SWAP_RESET);
        assert_eq!(
            (m.version(), m.status().state()),
            (NEW, Some(RfuState::Trial))
        );
        run(&mut m, t, t + CONFIRM_AFTER);
        assert_eq!(m.status().state(), Some(RfuState::Done));
        // It stays after any number of starts.
        m.power_cycle(20 * S);
        assert_eq!(m.version(), NEW);
    }

    #[test]
    fn refusals_say_why() {
        let mut rng = Rng::new(2);
        let mut m = RfuManager::factory(0, OLD);
        let image = firmware_image(NEW, 3_000);
        let mut h = Header::of(3, NEW, &image);
        h.size = rfu::IMAGE_MAX as u32 + 1;
        assert_eq!(
            m.handle(0, &Service::RfuHeader(h), &mut rng),
            Some(Answer::Refused)
        );
        assert_eq!(m.status().reason(), Some(RfuReason::TooLarge));
        let h = Header::of(3, NEW, &image);
        m.handle(0, &Service::RfuHeader(h), &mut rng);
        send_all(&mut m, 3, &image, None, &mut rng);
        let wrong = Service::RfuSwap {
            campaign: 3,
            crc: h.crc ^ 1,
        };
        assert_eq!(m.handle(0, &wrong, &mut rng), Some(Answer::Refused));
        assert_eq!(m.status().reason(), Some(RfuReason::Crc));
        // Data of another campaign is not written.
        let other = Service::RfuData {
            campaign: 4,
            segment: 0,
            data: vec![0; SEGMENT],
        };
        m.handle(0, &other, &mut rng);
        assert_eq!(m.status().reason(), Some(RfuReason::OtherCampaign));
        assert_eq!(m.status().state(), Some(RfuState::Complete));
        assert_eq!(
            m.handle(0, &Service::RfuAbort { campaign: 3 }, &mut rng),
            Some(Answer::Ack)
        );
        assert_eq!(
            (m.status().state(), m.status().reason()),
            (Some(RfuState::Idle), Some(RfuReason::Aborted))
        );
        assert_eq!(m.version(), OLD);
    }

    #[test]
    fn an_image_that_does_not_come_up_goes_back_to_the_old_one() {
        let mut rng = Rng::new(3);
        let mut m = RfuManager::factory(0, OLD);
        // An image without the simulated firmware's mark: it never comes up.
        let image: Vec<u8> = (0..4_000u32).map(|i| (i * 13) as u8).collect();
        let h = Header::of(5, NEW, &image);
        m.handle(0, &Service::RfuHeader(h), &mut rng);
        send_all(&mut m, 5, &image, None, &mut rng);
        let swap = Service::RfuSwap {
            campaign: 5,
            crc: h.crc,
        };
        assert_eq!(m.handle(0, &swap, &mut rng), Some(Answer::Ack));
        let t = run(&mut m, 0, SWAP_RESET);
        assert_eq!(m.version(), NEW, "it starts on trial");
        run(&mut m, t, t + FAIL_AFTER + CONFIRM_AFTER);
        assert_eq!(m.version(), OLD);
        assert_eq!(m.status().reason(), Some(RfuReason::Reverted));
    }

    /// The power goes at every page operation of an update (transfer,
    /// swap, first start, confirmation): the board then starts, runs the
    /// old or the new release, and a second full update succeeds.
    #[test]
    fn a_power_cut_at_any_moment_leaves_a_board_that_starts_and_updates() {
        let image = firmware_image(NEW, 2_000);
        let h = Header::of(1, NEW, &image);
        let update = |m: &mut RfuManager, rng: &mut Rng, campaign: u8| {
            let h = Header { campaign, ..h };
            m.handle(0, &Service::RfuHeader(h), rng);
            send_all(m, campaign, &image, None, rng);
            m.handle(
                0,
                &Service::RfuSwap {
                    campaign,
                    crc: h.crc,
                },
                rng,
            );
            let t = run(m, 0, SWAP_RESET);
            run(m, t, t + CONFIRM_AFTER);
        };
        let mut cut = 0;
        loop {
            let mut rng = Rng::new(cut);
            let mut m = RfuManager::factory(0, OLD);
            m.flash_mut().cut_after(cut as u32);
            update(&mut m, &mut rng, 1);
            let finished = !m.flash_mut().is_dead();
            m.power_cycle(100 * S);
            assert!([OLD, NEW].contains(&m.version()), "cut after {cut}");
            run(&mut m, 100 * S, 110 * S);
            update(&mut m, &mut rng, 2);
            m.power_cycle(200 * S);
            assert_eq!(m.version(), NEW, "cut after {cut}: the second update");
            if finished {
                break;
            }
            cut += 1;
        }
        assert!(cut > 60, "{cut} operations cut");
    }
}
