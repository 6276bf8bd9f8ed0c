//! A firmware update campaign on the street: plm-core's [`Update`] run
//! beside the street's other work (the sweep stops for it and comes back
//! after), with pause, cancel, and resume from what was saved.

use super::Street;
use crate::app::concentrator::{Concentrator, Happening};
use crate::app::frame::Address;
use crate::app::rfu::image;
use crate::app::service::Release;
use crate::app::update::{BoardState, Update, UpdateConfig};
use crate::app::Run;
use crate::time::Instant;
use alloc::string::String;
use alloc::vec::Vec;

/// A campaign under way (or over, its results kept until dismissed).
pub struct Campaign {
    /// The engine, run on the concentrator.
    run: Run<Update>,
    /// Paused by the user: nothing more is sent until resumed.
    pub paused: bool,
    /// When it started or resumed, on the driver's clock.
    pub since: Instant,
    /// When it was over.
    pub ended: Option<Instant>,
    /// The sweep ran before: it runs again when the update is over.
    sweep_was_on: bool,
}

impl Campaign {
    /// The engine: its boards, progress and report.
    pub fn update(&self) -> &Update {
        self.run.job()
    }

    /// When the engine has something to send again, if it waits for time.
    pub(super) fn poll_timeout(&self) -> Option<Instant> {
        self.run.poll_timeout()
    }
}

impl<R> Street<R> {
    /// The campaign, if one was started.
    pub fn campaign(&self) -> Option<&Campaign> {
        self.campaign.as_ref()
    }

    /// Whether an update has the line (started and not over).
    pub(super) fn updating(&self) -> bool {
        self.campaign
            .as_ref()
            .is_some_and(|c| !c.update().is_done())
    }

    /// Starts updating `targets` with `image` (reporting release `stated`
    /// once it runs, when the file names none), refused in words (before
    /// anything is sent) when the image cannot be a whole firmware image.
    pub fn start_update(
        &mut self,
        now: Instant,
        image: Vec<u8>,
        stated: Option<Release>,
        targets: &[Address],
    ) -> Result<(), String> {
        let info = image::check(&image)?.stating(stated)?;
        let u = Update::new(
            info.campaign(),
            info.release,
            image,
            targets,
            UpdateConfig::default(),
        )?;
        self.begin(now, u);
        Ok(())
    }

    /// Goes on with a campaign saved by [`Update::save`].
    pub fn resume_update(
        &mut self,
        now: Instant,
        image: Vec<u8>,
        saved: &[u8],
    ) -> Result<(), String> {
        let u = Update::resume(image, saved, now)?;
        self.begin(now, u);
        Ok(())
    }

    fn begin(&mut self, now: Instant, update: Update) {
        let sweep_was_on = self.sweep.on;
        self.set_sweep(now, false);
        self.campaign = Some(Campaign {
            run: Run::new(update),
            paused: false,
            since: now,
            ended: None,
            sweep_was_on,
        });
        self.out.campaign = true;
    }

    /// Pauses or resumes sending.
    pub fn pause_update(&mut self, paused: bool) {
        if let Some(c) = self.campaign.as_mut() {
            c.paused = paused;
            self.out.campaign = true;
        }
    }

    /// Cancels: boards not swapped yet forget the campaign and keep their
    /// release; boards swapped already finish.
    pub fn cancel_update(&mut self) {
        if let Some(c) = self.campaign.as_mut() {
            c.run.job_mut().abort();
            c.paused = false;
            self.out.campaign = true;
        }
    }

    /// Forgets a campaign that is over (its results were seen).
    pub fn dismiss_update(&mut self) {
        if self.campaign.as_ref().is_some_and(|c| c.update().is_done()) {
            self.campaign = None;
            self.out.campaign = true;
        }
    }

    /// Hands the engine's next request to the concentrator.
    pub(super) fn run_update(&mut self, conc: &mut Concentrator, now: Instant) {
        let Some(c) = self.campaign.as_mut() else {
            return;
        };
        if c.paused && !c.update().is_aborting() {
            return;
        }
        if c.run.pump(conc, now).is_some() {
            self.out.campaign = true;
        }
        self.update_over(now);
    }

    /// The fate of the engine's request, or a frame it hears; whether it
    /// was the campaign's.
    pub(super) fn campaign_handle(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        h: &Happening,
    ) -> bool {
        let Some(c) = self.campaign.as_mut() else {
            return false;
        };
        if !c.run.handle(conc, now, h) {
            return false;
        }
        self.out.campaign = true;
        self.update_over(now);
        true
    }

    /// Once the update is over: the boards updated show their new
    /// release, and the sweep comes back.
    fn update_over(&mut self, now: Instant) {
        let Some(c) = self.campaign.as_mut() else {
            return;
        };
        if c.ended.is_some() || !c.run.is_done() {
            return;
        }
        c.ended = Some(now);
        let sweep = core::mem::take(&mut c.sweep_was_on);
        let u = c.run.job();
        let stated = u.header().release();
        for (i, (a, s)) in u.boards().enumerate() {
            let release = stated.or(u.firmware(i));
            let lamp = self.fleet.get_mut(&a).and_then(|l| l.discovered.as_mut());
            if let (BoardState::Done, Some(d), Some(r)) = (s, lamp, release) {
                d.firmware = r;
            }
        }
        self.out.campaign = true;
        self.out.changed = true;
        self.out.found = true;
        if sweep {
            self.set_sweep(now, true);
        }
    }
}
