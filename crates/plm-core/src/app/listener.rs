//! The shape of the engines that broadcast and then listen to what comes
//! unasked (discovery, reads in slots): one trait, so that each driver
//! (`plm board`, the simulated street) writes its loop over them once.

use super::discovery::{Discovery, Rounds};
use super::frame::{Address, AppFrame};
use super::message::Message;
use super::read_all::ReadAll;
use super::requester::Request;
use crate::time::Instant;

/// A sans-IO engine that hands out broadcasts and takes what boards
/// send unasked.
pub trait Listener {
    /// A frame that came unasked; the frame to send back, if any.
    fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame>;
    /// When [`Listener::tick`] is due.
    fn due(&self) -> Option<Instant>;
    /// Time passed: the next broadcast, if any.
    fn tick(&mut self, now: Instant) -> Option<Request>;
    /// Whether it is over.
    fn done(&self) -> bool;
}

/// The trait over the engines' own methods: `on_message`,
/// `poll_timeout`, `handle_timeout`, `is_done`.
macro_rules! listener {
    ($engine:ty, $hear:expr) => {
        impl Listener for $engine {
            fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
                $hear(self, address, message)
            }
            fn due(&self) -> Option<Instant> {
                self.poll_timeout()
            }
            fn tick(&mut self, now: Instant) -> Option<Request> {
                self.handle_timeout(now)
            }
            fn done(&self) -> bool {
                self.is_done()
            }
        }
    };
}

listener!(Discovery, Discovery::on_message);
listener!(Rounds, Rounds::on_message);
// A read in slots answers nothing.
listener!(ReadAll, |r: &mut ReadAll, a, m| {
    r.on_message(a, m);
    None
});
