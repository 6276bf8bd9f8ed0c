//! Connection profiles (docs/architecture.md): what is at the other end of
//! the serial port, and so which session drives it. One connection at a
//! time, simulated or over WebSerial, for every profile.

use plm_core::link::Dialect;
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
    /// A bare ST7570's host interface (ST7570 UM 5): the modem views, on
    /// a simulated S-FSK network or a real modem.
    St7570,
}

impl Profile {
    /// Every profile, in the order of the chooser.
    pub const ALL: [Profile; 4] = [
        Profile::StreetBoard,
        Profile::StreetModem,
        Profile::Modem,
        Profile::St7570,
    ];

    /// In words, for the chooser.
    pub fn label(self) -> &'static str {
        match self {
            Profile::StreetBoard => "Street via concentrator board (USART)",
            Profile::StreetModem => "Street via bare ST7580 (console as concentrator)",
            Profile::Modem => "ST7580 modem (host interface)",
            Profile::St7570 => "ST7570 modem (host interface, S-FSK)",
        }
    }

    /// The key in the page's address (`?profile=board`) and in storage.
    pub fn key(self) -> &'static str {
        match self {
            Profile::StreetBoard => "board",
            Profile::StreetModem => "concentrator",
            Profile::Modem => "st7580",
            Profile::St7570 => "st7570",
        }
    }

    /// The profile of a key.
    pub fn from_key(key: &str) -> Option<Profile> {
        Profile::ALL.into_iter().find(|p| p.key() == key)
    }

    /// Whether the street session drives it.
    pub fn is_street(self) -> bool {
        matches!(self, Profile::StreetBoard | Profile::StreetModem)
    }

    /// The chip whose host interface the console speaks (the street
    /// profiles' modem is an ST7580).
    pub fn dialect(self) -> Dialect {
        match self {
            Profile::St7570 => Dialect::St7570,
            _ => Dialect::St7580,
        }
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
