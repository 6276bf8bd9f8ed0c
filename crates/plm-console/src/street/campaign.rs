//! A firmware update campaign on the street session: plm-core's
//! ([`plm_core::app::street::Campaign`]), started, paused, cancelled and
//! resumed from the views on the session's clock.

use super::StreetSession;
use plm_core::app::{Address, Release};

impl StreetSession {
    /// Starts updating `targets` with `image` (reporting release `stated`
    /// once it runs, when the file names none), refused in words (before
    /// anything is sent) when the image cannot be a whole firmware image.
    pub fn start_update(
        &mut self,
        image: Vec<u8>,
        stated: Option<Release>,
        targets: &[Address],
    ) -> Result<(), String> {
        let now = self.now();
        self.street.start_update(now, image, stated, targets)
    }

    /// Goes on with a campaign saved by `Update::save`.
    pub fn resume_update(&mut self, image: Vec<u8>, saved: &[u8]) -> Result<(), String> {
        let now = self.now();
        self.street.resume_update(now, image, saved)
    }

    /// Pauses or resumes sending.
    pub fn pause_update(&mut self, paused: bool) {
        self.street.pause_update(paused);
    }

    /// Cancels: boards not swapped yet forget the campaign and keep their
    /// release; boards swapped already finish.
    pub fn cancel_update(&mut self) {
        self.street.cancel_update();
    }

    /// Forgets a campaign that is over (its results were seen).
    pub fn dismiss_update(&mut self) {
        self.street.dismiss_update();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::sim::SimTransport;
    use plm_core::app::update::BoardState;
    use plm_core::app::{Concentrator, Release, RequesterConfig};
    use plm_core::time::{Duration, MS};
    use plm_sim::board::street_address;
    use plm_sim::rfu::{firmware_image, plain_image};
    use plm_sim::{Attach, StreetProfile};

    const S: Duration = 1_000 * MS;
    const NEW: Release = Release { major: 1, minor: 9 };

    fn street(lamps: usize) -> StreetSession {
        let t = Box::new(SimTransport::street(
            lamps,
            Attach::Board,
            57_600,
            5,
            StreetProfile::Uniform,
        ));
        StreetSession::new(t, Concentrator::usart(RequesterConfig::default()))
    }

    fn run(s: &mut StreetSession, d: Duration) {
        let start = s.now();
        s.run_until(start, start + d);
        s.take();
    }

    fn release_of(s: &StreetSession, node: usize) -> Release {
        s.fleet()[&street_address(node)]
            .discovered
            .unwrap()
            .firmware
    }

    /// Two lamps of three updated through the session: the sweep stops
    /// for the update and comes back, the fleet shows the new release;
    /// a bad image is refused before anything is sent.
    #[test]
    fn lamps_are_updated_through_the_session() {
        let mut s = street(3);
        s.discover();
        run(&mut s, 40 * S);
        assert_eq!(s.fleet().len(), 3);
        let old = release_of(&s, 3);
        let mut truncated = firmware_image(NEW, 3_000);
        truncated.truncate(2_000);
        assert!(s
            .start_update(truncated, None, &[street_address(1)])
            .unwrap_err()
            .starts_with("truncated"));
        assert!(s.campaign().is_none(), "nothing started");

        let targets = [street_address(1), street_address(2)];
        s.start_update(firmware_image(NEW, 3_000), None, &targets)
            .unwrap();
        assert!(!s.sweep().on, "the sweep leaves the line to the update");
        run(&mut s, 120 * S);
        let c = s.campaign().unwrap();
        assert!(c.update().is_done(), "{:?}", c.update().report());
        assert!(c.update().boards().all(|(_, st)| *st == BoardState::Done));
        assert_eq!(release_of(&s, 1), NEW);
        assert_eq!(release_of(&s, 2), NEW);
        assert_eq!(release_of(&s, 3), old);
        assert!(s.sweep().on, "the sweep is back");
        s.dismiss_update();
        assert!(s.campaign().is_none());
    }

    /// A plain `.bin` (as ST's toolchain writes it) updates a lamp: with
    /// no release stated the lamp shows what it reports after its
    /// restart; with one, that release; a descriptor's release other than
    /// the one stated is refused before anything is sent.
    #[test]
    fn a_plain_image_updates_a_lamp() {
        let mut s = street(2);
        s.discover();
        run(&mut s, 30 * S);
        let plain = plain_image(3, 3_000);
        s.start_update(plain.clone(), None, &[street_address(1)])
            .unwrap();
        run(&mut s, 60 * S);
        let c = s.campaign().unwrap();
        let report = c.update().report();
        assert!(
            report[0]
                .1
                .starts_with("updated: it restarted and answers, reporting release 0.0"),
            "{report:?}"
        );
        assert_eq!(release_of(&s, 1), plm_core::app::rfu::RELEASE_NOT_STATED);
        s.dismiss_update();

        let stated = Release { major: 2, minor: 1 };
        s.start_update(plain_image(4, 3_000), Some(stated), &[street_address(2)])
            .unwrap();
        run(&mut s, 60 * S);
        let c = s.campaign().unwrap();
        assert_eq!(c.update().report()[0].1, "updated to 2.1");
        assert_eq!(release_of(&s, 2), stated);
        s.dismiss_update();

        let why = s
            .start_update(
                firmware_image(NEW, 3_000),
                Some(stated),
                &[street_address(2)],
            )
            .unwrap_err();
        assert!(why.contains("says it is release 1.9, not 2.1"), "{why}");
        assert!(s.campaign().is_none(), "nothing started");
    }

    /// A campaign saved mid-way goes on in a new session (a reload with
    /// the same street behind the cable) and finishes.
    #[test]
    fn a_saved_campaign_resumes_in_a_new_session() {
        let mut s = street(2);
        s.discover();
        run(&mut s, 30 * S);
        let image = firmware_image(NEW, 4_000);
        s.start_update(image.clone(), None, &[street_address(1), street_address(2)])
            .unwrap();
        run(&mut s, 6 * S);
        let saved = s.campaign().unwrap().update().save();
        // The page goes; the street (behind the cable) stays.
        let transport = s.drive.transport.take().unwrap();
        let mut s = StreetSession::new(transport, Concentrator::usart(RequesterConfig::default()));
        assert!(
            s.resume_update(vec![0; 10], &saved).is_err(),
            "another image"
        );
        s.resume_update(image.clone(), &saved).unwrap();
        // A damaged save (cut short, or with a byte changed) is refused
        // and the running campaign goes on as it was.
        let running = s.campaign().unwrap().update().save();
        for n in 0..saved.len() {
            assert!(s.resume_update(image.clone(), &saved[..n]).is_err());
        }
        let mut wrong = saved.clone();
        wrong[0] ^= 1;
        assert!(s
            .resume_update(image, &wrong)
            .unwrap_err()
            .contains("not a saved"));
        assert_eq!(s.campaign().unwrap().update().save(), running);
        run(&mut s, 120 * S);
        let c = s.campaign().unwrap();
        assert!(
            c.update().boards().all(|(_, st)| *st == BoardState::Done),
            "{:?}",
            c.update().report()
        );
    }
}
