//! What both browser suites share: the page's timers, and a [`Session`]
//! driven by them as the console's own timer drives it (`app.rs`), so the
//! transports run exactly as in the page, in real time.

use js_sys::Promise;
use plm_console::clock::page_now_us;
use plm_console::driver::Budget;
use plm_console::session::{Note, Outcome, Session};
use plm_core::st7580::Command;
use std::cell::{Cell, RefCell};
use std::rc::Rc;
use wasm_bindgen_futures::JsFuture;

/// The console's timer period (`app.rs`).
pub const TICK_MS: i32 = 4;

/// Waits `ms` on the page's timers.
pub async fn sleep(ms: i32) {
    let promise = Promise::new(&mut |resolve, _| {
        web_sys::window()
            .expect("a window")
            .set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, ms)
            .expect("setTimeout");
    });
    JsFuture::from(promise).await.expect("a timer");
}

thread_local! {
    static TAKEN: Cell<bool> = const { Cell::new(false) };
}

/// The page to one test at a time, while it is held.
///
/// wasm-bindgen-test interleaves async tests at their awaits; these share
/// the page's timers and the one scripted serial adapter, and measure
/// time, so each takes the page first.
pub struct Exclusive(());

impl Exclusive {
    /// Waits until no other test holds the page.
    pub async fn take() -> Exclusive {
        while TAKEN.with(|t| t.replace(true)) {
            sleep(TICK_MS).await;
        }
        Exclusive(())
    }
}

impl Drop for Exclusive {
    fn drop(&mut self) {
        TAKEN.with(|t| t.set(false));
    }
}

/// A session and what it has said so far.
pub struct Driven {
    /// The session under test.
    pub session: Session,
    /// Every note, in order.
    pub notes: Vec<Note>,
    /// Every outcome of the requests sent through [`Driven::ask`], in
    /// order of arrival.
    pub outcomes: Rc<RefCell<Vec<Outcome<Command>>>>,
}

impl Driven {
    /// Drives `session`.
    pub fn new(session: Session) -> Self {
        Driven {
            session,
            notes: Vec::new(),
            outcomes: Rc::default(),
        }
    }

    /// One tick of the page's timer: time catches up with the page's
    /// clock, the replies are called.
    pub fn tick(&mut self) {
        let tick = self.session.tick(page_now_us(), Budget::UNLIMITED);
        self.notes.extend(tick.notes);
        for (reply, outcome) in tick.replies {
            reply(outcome);
        }
    }

    /// Ticks every [`TICK_MS`] until `done` holds or `limit_ms` of the
    /// page's clock have passed; says whether `done` held.
    pub async fn run_until(
        &mut self,
        limit_ms: f64,
        mut done: impl FnMut(&Driven) -> bool,
    ) -> bool {
        let end = page_now_us() + limit_ms * 1_000.0;
        loop {
            self.tick();
            if done(self) {
                return true;
            }
            if page_now_us() > end {
                return false;
            }
            sleep(TICK_MS).await;
        }
    }

    /// A reply that keeps the outcome, the answer read as an ST7580 command.
    pub fn keep(outcomes: Rc<RefCell<Vec<Outcome<Command>>>>) -> plm_console::session::Reply {
        Box::new(move |o: Outcome| {
            let o = o.read(|f| Command::from_frame(f).map_err(|e| e.to_string()));
            outcomes.borrow_mut().push(o)
        })
    }

    /// Sends `command` and waits (at most `limit_ms`) for its outcome.
    pub async fn ask(&mut self, command: Command, limit_ms: f64) -> Outcome<Command> {
        let before = self.outcomes.borrow().len();
        let outcomes = self.outcomes.clone();
        self.session
            .request(command.to_frame(), Self::keep(outcomes));
        let answered = self
            .run_until(limit_ms, |d| d.outcomes.borrow().len() > before)
            .await;
        assert!(answered, "no outcome for {command:?} within {limit_ms} ms");
        self.outcomes.borrow()[before].clone()
    }

    /// The modem's answer to `command`, which must come.
    pub async fn answer(&mut self, command: Command) -> Command {
        match self.ask(command.clone(), 3_000.0).await {
            Outcome::Answer { command, .. } => command,
            Outcome::Failed(why) => panic!("{command:?} failed: {why}"),
        }
    }

    /// Frames the modem sent on its own, in order.
    pub fn unsolicited(&self) -> Vec<Command> {
        self.notes
            .iter()
            .filter_map(|n| match n {
                Note::Unsolicited { frame, .. } => Command::from_frame(frame).ok(),
                _ => None,
            })
            .collect()
    }

    /// Waits (at most `limit_ms`) for the modem's boot BIO_ResetIndication.
    pub async fn booted(&mut self, limit_ms: f64) {
        let seen = self
            .run_until(limit_ms, |d| {
                d.unsolicited()
                    .iter()
                    .any(|c| matches!(c, Command::BioResetIndication(_)))
            })
            .await;
        assert!(seen, "no BIO_ResetIndication within {limit_ms} ms");
    }
}
