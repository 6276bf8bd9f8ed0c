//! A view drawn again at most so often: changes that come faster are
//! shown together at the next turn. A street's readings come many times a
//! second; 500 lamps' table and picture laid out at each would take the
//! page's frames (issue 28), and a fifth of a second is not seen.

/// When a view was last shown, and whether a change waits.
#[derive(Debug, Clone, Copy)]
pub struct Throttle {
    every_us: f64,
    shown_us: f64,
    waiting: bool,
}

impl Throttle {
    /// Shown at most once every `every_us`.
    pub const fn new(every_us: f64) -> Throttle {
        Throttle {
            every_us,
            shown_us: f64::NEG_INFINITY,
            waiting: false,
        }
    }

    /// Whether to show the view at `now_us`, given whether it `changed`
    /// since the last call: at once when it was not shown for a while,
    /// else at the first call once the time is up.
    pub fn show(&mut self, changed: bool, now_us: f64) -> bool {
        self.show_after(changed, now_us, self.every_us)
    }

    /// [`Throttle::show`], the view shown again `after_us` after the last
    /// time at the soonest.
    pub fn show_after(&mut self, changed: bool, now_us: f64, after_us: f64) -> bool {
        self.waiting |= changed;
        if !self.waiting || now_us - self.shown_us < after_us {
            return false;
        }
        self.shown_us = now_us;
        self.waiting = false;
        true
    }

    /// Whether [`Throttle::show`] would show the view now.
    pub fn due(&self, changed: bool, now_us: f64) -> bool {
        (self.waiting || changed) && now_us - self.shown_us >= self.every_us
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changes_are_shown_at_most_once_a_period_and_none_is_lost() {
        let mut t = Throttle::new(200.0);
        assert!(!t.show(false, 0.0), "nothing changed");
        assert!(t.show(true, 10.0), "the first change at once");
        assert!(!t.show(true, 50.0), "too soon");
        assert!(!t.show(false, 150.0), "still too soon");
        assert!(
            t.show(false, 210.0),
            "the change waiting, once the time is up"
        );
        assert!(!t.show(false, 500.0), "shown: nothing waits");
        assert!(t.show(true, 600.0), "a while later, at once");
    }
}
