//! A job on the street, run on a concentrator: what discovery, a round of
//! reads, a read in slots, a firmware update and a single request have in
//! common, so that every driver (`plm board`, plm-sim's street, the
//! console) runs them with one loop ([`drive`]) over one router ([`Run`]).
//! Sans-IO: [`Run`] submits the job's requests one at a time, each after
//! the fate of the one before, hands the job each fate and what boards send
//! unasked, and sends what it answers them.

use super::concentrator::{Concentrator, Happening};
use super::discovery::{Discovery, Rounds};
use super::frame::{Address, AppFrame};
use super::message::Message;
use super::read_all::ReadAll;
use super::requester::{AppEvent, Request, RequestId};
use super::sweep::Round;
use super::update::Update;
use crate::drive::{self, Io};
use crate::time::Instant;
use alloc::string::String;

/// A sans-IO job that hands out requests and takes what comes back.
pub trait Job {
    /// The next request to send now, if any (called only when the last
    /// one's fate is known).
    fn poll(&mut self, now: Instant) -> Option<Request>;
    /// The fate of the last request that expected an answer: the answer,
    /// or why there is none (lent: the happening stays whole for the
    /// driver).
    fn on_answer(&mut self, now: Instant, answer: Result<&Message, &str>);
    /// A frame that came unasked; the frame to send back, if any.
    fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame>;
    /// When [`Job::poll`] is due for time.
    fn poll_timeout(&self) -> Option<Instant>;
    /// Whether it is over.
    fn is_done(&self) -> bool;
}

/// A job lent to a run: the caller keeps it.
impl<J: Job + ?Sized> Job for &mut J {
    fn poll(&mut self, now: Instant) -> Option<Request> {
        (**self).poll(now)
    }
    fn on_answer(&mut self, now: Instant, answer: Result<&Message, &str>) {
        (**self).on_answer(now, answer)
    }
    fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        (**self).hear(address, message)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        (**self).poll_timeout()
    }
    fn is_done(&self) -> bool {
        (**self).is_done()
    }
}

/// A job and the request it began with, not yet sent (discovery and a
/// read in slots begin with a request).
#[derive(Debug, Clone)]
pub struct Begun<J> {
    first: Option<Request>,
    /// The job.
    pub job: J,
}

impl<J> Begun<J> {
    /// `job`, whose first request is `first`.
    pub fn new(job: J, first: Option<Request>) -> Self {
        Begun { first, job }
    }
}

impl<J: Job> Job for Begun<J> {
    fn poll(&mut self, now: Instant) -> Option<Request> {
        self.first.take().or_else(|| self.job.poll(now))
    }
    fn on_answer(&mut self, now: Instant, answer: Result<&Message, &str>) {
        self.job.on_answer(now, answer)
    }
    fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        self.job.hear(address, message)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        self.job.poll_timeout()
    }
    fn is_done(&self) -> bool {
        self.first.is_none() && self.job.is_done()
    }
}

/// [`Job`] over the broadcasting engines' own methods (`handle_timeout`
/// gives the next broadcast, `on_message` hears a board).
macro_rules! broadcasts {
    ($engine:ty, $hear:expr) => {
        impl Job for $engine {
            fn poll(&mut self, now: Instant) -> Option<Request> {
                self.handle_timeout(now)
            }
            fn on_answer(&mut self, _: Instant, _: Result<&Message, &str>) {}
            fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
                $hear(self, address, message)
            }
            fn poll_timeout(&self) -> Option<Instant> {
                <$engine>::poll_timeout(self)
            }
            fn is_done(&self) -> bool {
                <$engine>::is_done(self)
            }
        }
    };
}

broadcasts!(Discovery, Discovery::on_message);
broadcasts!(Rounds, Rounds::on_message);
// A read in slots answers nothing.
broadcasts!(ReadAll, |r: &mut ReadAll, a, m| {
    r.on_message(a, m);
    None
});

impl Job for Round {
    fn poll(&mut self, now: Instant) -> Option<Request> {
        Round::poll(self, now)
    }
    fn on_answer(&mut self, _: Instant, answer: Result<&Message, &str>) {
        Round::on_answer(self, answer)
    }
    fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        Round::hear(self, address, message)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        Round::poll_timeout(self)
    }
    fn is_done(&self) -> bool {
        Round::is_done(self)
    }
}

impl Job for Update {
    fn poll(&mut self, now: Instant) -> Option<Request> {
        Update::poll(self, now)
    }
    fn on_answer(&mut self, now: Instant, answer: Result<&Message, &str>) {
        Update::on_answer(self, now, answer)
    }
    fn hear(&mut self, _: Address, _: &Message) -> Option<AppFrame> {
        None
    }
    fn poll_timeout(&self) -> Option<Instant> {
        Update::poll_timeout(self)
    }
    fn is_done(&self) -> bool {
        Update::is_done(self)
    }
}

/// One request and its fate: the job of asking one board one thing.
#[derive(Debug, Clone)]
pub struct Ask {
    request: Option<Request>,
    /// The answer, or why there is none; `None` while it is awaited, and
    /// for a request that expects no answer.
    pub answer: Option<Result<Message, String>>,
}

impl Ask {
    /// Asks `request`.
    pub fn new(request: Request) -> Ask {
        Ask {
            request: Some(request),
            answer: None,
        }
    }
}

impl Job for Ask {
    fn poll(&mut self, _: Instant) -> Option<Request> {
        self.request.take()
    }
    fn on_answer(&mut self, _: Instant, answer: Result<&Message, &str>) {
        self.answer = Some(answer.cloned().map_err(String::from));
    }
    fn hear(&mut self, _: Address, _: &Message) -> Option<AppFrame> {
        None
    }
    fn poll_timeout(&self) -> Option<Instant> {
        None
    }
    fn is_done(&self) -> bool {
        self.request.is_none()
    }
}

/// A job run on a concentrator.
#[derive(Debug, Clone)]
pub struct Run<J> {
    job: J,
    /// The job's request whose fate is awaited.
    awaiting: Option<RequestId>,
    /// The job's next request, held back by its driver ([`Run::pump_unless`]).
    held: Option<Request>,
}

impl<J: Job> Run<J> {
    /// Runs `job`.
    pub fn new(job: J) -> Self {
        Run {
            job,
            awaiting: None,
            held: None,
        }
    }

    /// The job.
    pub fn job(&self) -> &J {
        &self.job
    }

    /// The job, to act on it (abort an update, ...).
    pub fn job_mut(&mut self) -> &mut J {
        &mut self.job
    }

    /// The job, once it is over.
    pub fn into_job(self) -> J {
        self.job
    }

    /// Submits the job's next request, if one is due now and the last
    /// one's fate is known. Returns its id.
    pub fn pump(&mut self, conc: &mut Concentrator, now: Instant) -> Option<RequestId> {
        self.pump_unless(conc, now, false)
    }

    /// [`Run::pump`], unless `hold`: then the job's next request, if it
    /// has one, waits for a later pump ([`Run::is_held`]); the console
    /// holds it while the page draws, so that no redraw sits between a
    /// modem frame and its ACK.
    pub fn pump_unless(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        hold: bool,
    ) -> Option<RequestId> {
        if self.awaiting.is_some() {
            return None;
        }
        let request = self.held.take().or_else(|| self.job.poll(now))?;
        if hold {
            self.held = Some(request);
            return None;
        }
        let id = conc.submit(now, request);
        self.awaiting = Some(id);
        Some(id)
    }

    /// Whether the job's next request is held back ([`Run::pump_unless`]).
    pub fn is_held(&self) -> bool {
        self.held.is_some()
    }

    /// A happening of the concentrator: the fate of the job's request, or
    /// a frame a board sent unasked (the job's answer to it is sent).
    /// Returns whether it was the job's.
    pub fn handle(&mut self, conc: &mut Concentrator, now: Instant, h: &Happening) -> bool {
        let Happening::App(e) = h else {
            return false;
        };
        if let AppEvent::Unsolicited {
            address, message, ..
        } = e
        {
            if let Some(reply) = self.job.hear(*address, message) {
                conc.send(now, reply);
            }
            return true;
        }
        if self.awaiting.is_none() || e.fate_of() != self.awaiting {
            return false;
        }
        self.awaiting = None;
        match e {
            AppEvent::Answered { answer, .. } => self.job.on_answer(now, Ok(answer)),
            AppEvent::Failed { reason, .. } => self.job.on_answer(now, Err(reason)),
            // Sent, and no answer expected.
            _ => {}
        }
        true
    }

    /// When [`Run::pump`] is due for time (a request held back: at once).
    pub fn poll_timeout(&self) -> Option<Instant> {
        match (self.awaiting, &self.held) {
            (Some(_), _) => None,
            (None, Some(_)) => Some(0),
            (None, None) => self.job.poll_timeout(),
        }
    }

    /// Whether the job is over, its last request's fate known.
    pub fn is_done(&self) -> bool {
        self.awaiting.is_none() && self.held.is_none() && self.job.is_done()
    }
}

/// What routes a concentrator's happenings to the work it runs: a
/// [`Run`] of one job, or the whole street
/// ([`super::street::Street`]). [`drive`] drives any.
pub trait Router {
    /// Its work at `now`, after a turn: the next requests submitted.
    fn pump(&mut self, conc: &mut Concentrator, now: Instant);
    /// A happening of the concentrator.
    fn handle(&mut self, conc: &mut Concentrator, now: Instant, h: &Happening);
    /// When [`Router::pump`] is due for time.
    fn poll_timeout(&self, now: Instant) -> Option<Instant>;
    /// Whether it is over (the driver stops).
    fn is_done(&self) -> bool;
}

impl<J: Job> Router for Run<J> {
    fn pump(&mut self, conc: &mut Concentrator, now: Instant) {
        Run::pump(self, conc, now);
    }
    fn handle(&mut self, conc: &mut Concentrator, now: Instant, h: &Happening) {
        Run::handle(self, conc, now, h);
    }
    fn poll_timeout(&self, _: Instant) -> Option<Instant> {
        Run::poll_timeout(self)
    }
    fn is_done(&self) -> bool {
        Run::is_done(self)
    }
}

/// The loop of every street driver: runs `run` (a job's [`Run`], or the
/// street) on `conc` over `io` until it is over or `limit` is reached
/// (returns whether it is over). `each` is called after every turn with
/// its time and its happenings (often none), which `run` has already had.
pub fn drive<T: Router + ?Sized, I: Io + ?Sized>(
    run: &mut T,
    conc: &mut Concentrator,
    io: &mut I,
    limit: Instant,
    mut each: impl FnMut(&mut T, Instant, &[Happening]) -> Result<(), I::Error>,
) -> Result<bool, I::Error> {
    let mut seen = alloc::vec::Vec::new();
    loop {
        let now = io.now();
        run.pump(conc, now);
        // What the turn brought, and what came of the request just
        // submitted (a broadcast is sent at once).
        while let Some(h) = conc.poll_happening() {
            run.handle(conc, now, &h);
            seen.push(h);
        }
        each(run, now, &seen)?;
        if !seen.is_empty() {
            seen.clear();
            continue;
        }
        if run.is_done() || now >= limit {
            drive::flush(conc, io)?;
            return Ok(run.is_done());
        }
        let until = run.poll_timeout(now).map_or(limit, |t| t.min(limit));
        drive::turn(conc, io, until, |_, _| {})?;
    }
}

/// Submits `request` and runs until its fate (answered, failed, or sent
/// when it expects no answer) or until `limit` has passed: one request of
/// a driver that waits for it. Returns the request's id and its fate
/// (`None`: none by the limit). `each` sees every happening on the way.
pub fn fate<I: Io + ?Sized>(
    conc: &mut Concentrator,
    io: &mut I,
    request: Request,
    limit: crate::time::Duration,
    mut each: impl FnMut(Instant, &Happening),
) -> Result<(RequestId, Option<AppEvent>), I::Error> {
    let id = conc.submit(io.now(), request);
    let until = io.now() + limit;
    // A turn first, even when the fate is known at once (a broadcast is
    // "sent" as it is queued): the request's bytes go out, and the port
    // is read, before the caller moves on (a process that exits with
    // bytes unread on its socket resets the connection, and what it wrote
    // last may be lost).
    while io.now() < until {
        let now = drive::turn(conc, io, until, |_, _| {})?;
        while let Some(h) = conc.poll_happening() {
            each(now, &h);
            if let Happening::App(e) = h {
                if e.fate_of() == Some(id) {
                    return Ok((id, Some(e)));
                }
            }
        }
    }
    Ok((id, None))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::requester::RequesterConfig;

    /// A request held back by its driver waits, is due at once, keeps the
    /// job from being over, and goes at the next pump; its fate then
    /// closes the job.
    #[test]
    fn a_held_request_goes_at_the_next_pump() {
        let mut conc = Concentrator::usart(RequesterConfig::default());
        let mut run = Run::new(Ask::new(Request::all(Message::Ping)));
        assert_eq!(run.pump_unless(&mut conc, 0, true), None);
        assert!(run.is_held() && !run.is_done());
        assert_eq!(run.poll_timeout(), Some(0));
        assert!(conc.poll_happening().is_none(), "nothing sent");
        let id = run.pump_unless(&mut conc, 5, false).expect("sent now");
        assert!(!run.is_held() && !run.is_done());
        assert_eq!(run.poll_timeout(), None, "its fate awaited");
        let mut fates = 0;
        while let Some(h) = conc.poll_happening() {
            if matches!(&h, Happening::App(e) if e.fate_of() == Some(id)) {
                fates += 1;
                assert!(run.handle(&mut conc, 5, &h));
            }
        }
        assert_eq!(fates, 1, "a broadcast is sent as it is queued");
        assert!(run.is_done());
    }
}
