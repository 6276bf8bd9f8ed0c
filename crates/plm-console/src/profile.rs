//! Connection profiles (DESIGN.md): what is at the other end of the
//! serial port, and so which session drives it. One connection at a
//! time, simulated or over WebSerial, for every profile.

use plm_sim::Attach;

/// What the console is connected to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Profile {
    /// A street behind a concentrator board's USART (application frames,
    /// STEVAL UM 4.6). The page opens on it.
    #[default]
    StreetBoard,
    /// A street behind a bare ST7580: the console speaks the board
    /// protocol over the power line itself.
    StreetModem,
    /// A bare ST7580's host interface (UM0932 3): the modem views.
    Modem,
}

impl Profile {
    /// Every profile, in the order of the chooser.
    pub const ALL: [Profile; 3] = [Profile::StreetBoard, Profile::StreetModem, Profile::Modem];

    /// In words, for the chooser.
    pub fn label(self) -> &'static str {
        match self {
            Profile::StreetBoard => "Street via concentrator board (USART)",
            Profile::StreetModem => "Street via bare ST7580 (console as concentrator)",
            Profile::Modem => "ST7580 modem (host interface)",
        }
    }

    /// The key in the page's address (`?profile=board`) and in storage.
    pub fn key(self) -> &'static str {
        match self {
            Profile::StreetBoard => "board",
            Profile::StreetModem => "concentrator",
            Profile::Modem => "st7580",
        }
    }

    /// The profile of a key.
    pub fn from_key(key: &str) -> Option<Profile> {
        Profile::ALL.into_iter().find(|p| p.key() == key)
    }

    /// Whether the street session drives it.
    pub fn is_street(self) -> bool {
        self != Profile::Modem
    }

    /// What a simulated node 0 is for it.
    pub fn attach(self) -> Attach {
        match self {
            Profile::StreetBoard => Attach::Board,
            _ => Attach::Modem,
        }
    }

    /// Whether the port has a T_REQ line (RTS) to drive.
    pub fn has_treq(self) -> bool {
        self != Profile::StreetBoard
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip() {
        for p in Profile::ALL {
            assert_eq!(Profile::from_key(p.key()), Some(p));
        }
        assert_eq!(Profile::default(), Profile::StreetBoard);
    }
}
