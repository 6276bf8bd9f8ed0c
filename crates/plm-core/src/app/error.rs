//! Error codes of error frames (STEVAL-IHP007V1 UM 4.5 `APP_ERROR_t`,
//! 4.6.3 "Error code list", and the HID board codes of Appendix A), each
//! with the seed's name and what it means for the person at the console.

use core::fmt;

/// One error code, as error frames carry it (2 bytes, high first:
/// `user_error_code = buffer[8]<<8 | buffer[9]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ErrorCode(pub u16);

/// Every code the seed defines: value, name, words.
pub const ERROR_CODES: &[(u16, &str, &str)] = &[
    (0x00, "APP_ERROR_NONE", "no error"),
    (0x01, "APP_ERROR_GENERIC", "generic communication error"),
    (
        0x02,
        "APP_ERROR_COMM_TIMEOUT",
        "communication timeout: the board did not answer in time",
    ),
    (
        0x03,
        "APP_ERROR_SERVICE_GRP_UNKNOWN",
        "service group unknown",
    ),
    (
        0x04,
        "APP_ERROR_SERVICE_CMD_ERROR",
        "the board refused the service command (unknown command or wrong data)",
    ),
    (0x05, "APP_ERROR_COMMUNICATION", "communication error"),
    (
        0x06,
        "APP_ERROR_ISOLATED_NODE",
        "node unreachable: no answer over the power line",
    ),
    (0x07, "APP_ERROR_HARDWARE", "hardware error on the board"),
    (
        0x08,
        "APP_ERROR_WRONG_PROG_COMMAND",
        "wrong programming command",
    ),
    (
        0x09,
        "APP_ERROR_WRONG_PROG_GROUP",
        "wrong programming group",
    ),
    (
        0x0a,
        "APP_ERROR_DEVICE_BLANK",
        "the device is blank (never configured)",
    ),
    (
        0x0b,
        "APP_ERROR_RTC_ERROR",
        "the board could not set its clock",
    ),
    (
        0x0c,
        "APP_ERROR_WATCHDOG_DISABLED",
        "hardware reset impossible: the watchdog is disabled",
    ),
    (
        0x0d,
        "APP_ERROR_NODE_INIT_FAILED",
        "node initialisation failed",
    ),
    (
        0x0e,
        "APP_ERROR_RTC_DISABLED",
        "the board's clock (RTC) is disabled",
    ),
    (
        0x10,
        "HID response error",
        "the HID ballast answered with an error",
    ),
    (
        0x11,
        "HID command unknown",
        "the HID ballast does not know this command",
    ),
    (
        0x12,
        "HID board response timeout",
        "the HID ballast did not answer: check the ballast and its cable",
    ),
    (
        0x13,
        "HID packet delivery impossible",
        "the board could not deliver the command to the HID ballast",
    ),
];

impl ErrorCode {
    /// APP_ERROR_SERVICE_CMD_ERROR.
    pub const SERVICE_CMD_ERROR: ErrorCode = ErrorCode(0x04);
    /// APP_ERROR_ISOLATED_NODE.
    pub const ISOLATED_NODE: ErrorCode = ErrorCode(0x06);
    /// APP_ERROR_WRONG_PROG_GROUP.
    pub const WRONG_PROG_GROUP: ErrorCode = ErrorCode(0x09);
    /// APP_ERROR_RTC_ERROR.
    pub const RTC_ERROR: ErrorCode = ErrorCode(0x0b);
    /// HID command unknown.
    pub const HID_COMMAND_UNKNOWN: ErrorCode = ErrorCode(0x11);
    /// HID board response timeout.
    pub const HID_TIMEOUT: ErrorCode = ErrorCode(0x12);

    fn entry(self) -> Option<&'static (u16, &'static str, &'static str)> {
        ERROR_CODES.iter().find(|e| e.0 == self.0)
    }

    /// The seed's name, `None` for a code it does not define.
    pub fn name(self) -> Option<&'static str> {
        self.entry().map(|e| e.1)
    }

    /// Whether the code comes from the HID ballast (10h-13h).
    pub fn is_hid(self) -> bool {
        (0x10..=0x13).contains(&self.0)
    }
}

/// The code in words, with its name and value.
impl fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.entry() {
            Some((v, name, words)) => write!(f, "{words} ({name}, {v:04X}h)"),
            None => write!(
                f,
                "error {:04X}h, which the board manual does not define",
                self.0
            ),
        }
    }
}
