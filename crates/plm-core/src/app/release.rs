//! A release `x.y` of a board's firmware or stack (STEVAL-IHP007V1 UM
//! 4.6.4, SERVICE_FW_REL_GET), as discovery reports it and an RFU image
//! header announces it (4.2).

use core::fmt;

/// A release `x.y`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
pub struct Release {
    /// x.
    pub major: u8,
    /// y.
    pub minor: u8,
}

impl Release {
    /// `x.y` as people write a release (spaces around it allowed); the
    /// reason in words if it is not one.
    pub fn parse(text: &str) -> Result<Release, alloc::string::String> {
        let t = text.trim();
        let bad = || alloc::format!("'{t}' is not a release: two numbers 0-255 as x.y, e.g. 1.5");
        let (x, y) = t.split_once('.').ok_or_else(bad)?;
        Ok(Release {
            major: x.parse().map_err(|_| bad())?,
            minor: y.parse().map_err(|_| bad())?,
        })
    }
}

impl fmt::Display for Release {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.major, self.minor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn releases_are_read_as_people_write_them() {
        assert_eq!(Release::parse(" 1.5 "), Ok(Release { major: 1, minor: 5 }));
        assert_eq!(
            Release::parse("255.0"),
            Ok(Release {
                major: 255,
                minor: 0
            })
        );
        for bad in ["2", "1.", ".5", "1.256", "a.b", "1.5.1"] {
            let why = Release::parse(bad).unwrap_err();
            assert!(why.contains("is not a release"), "{bad}: {why}");
        }
    }
}
