//! ST7580 command codes (UM0932 Tables 10, 11, 12 and 15).

/// The four command types of UM0932 3.3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CommandType {
    /// Sent by the host to use a service (Table 10).
    Request,
    /// Positive answer of the modem (Table 11).
    Confirm,
    /// Negative answer of the modem (Table 12).
    Error,
    /// Unsolicited notification of the modem (Table 15).
    Indication,
}

macro_rules! codes {
    ($($konst:ident = $code:literal, $name:literal, $ty:ident;)*) => {
        $(
            #[doc = concat!("`", $name, "`")]
            pub const $konst: u8 = $code;
        )*

        /// Every command code of UM0932 with its manual name and type.
        pub const ALL: &[(u8, &str, CommandType)] = &[$(($code, $name, CommandType::$ty)),*];
    };
}

codes! {
    BIO_RESET_REQUEST = 0x3C, "BIO_ResetRequest", Request;
    BIO_RESET_CONFIRM = 0x3D, "BIO_ResetConfirm", Confirm;
    BIO_RESET_ERROR = 0x3F, "BIO_ResetError", Error;
    BIO_RESET_INDICATION = 0x3E, "BIO_ResetIndication", Indication;
    MIB_WRITE_REQUEST = 0x08, "MIB_WriteRequest", Request;
    MIB_WRITE_CONFIRM = 0x09, "MIB_WriteConfirm", Confirm;
    MIB_WRITE_ERROR = 0x0B, "MIB_WriteError", Error;
    MIB_READ_REQUEST = 0x0C, "MIB_ReadRequest", Request;
    MIB_READ_CONFIRM = 0x0D, "MIB_ReadConfirm", Confirm;
    MIB_READ_ERROR = 0x0F, "MIB_ReadError", Error;
    MIB_ERASE_REQUEST = 0x10, "MIB_EraseRequest", Request;
    MIB_ERASE_CONFIRM = 0x11, "MIB_EraseConfirm", Confirm;
    MIB_ERASE_ERROR = 0x13, "MIB_EraseError", Error;
    PING_REQUEST = 0x2C, "PingRequest", Request;
    PING_CONFIRM = 0x2D, "PingConfirm", Confirm;
    PHY_DATA_REQUEST = 0x24, "PHY_DataRequest", Request;
    PHY_DATA_CONFIRM = 0x25, "PHY_DataConfirm", Confirm;
    PHY_DATA_ERROR = 0x27, "PHY_DataError", Error;
    PHY_DATA_INDICATION = 0x26, "PHY_DataIndication", Indication;
    DL_DATA_REQUEST = 0x50, "DL_DataRequest", Request;
    DL_DATA_CONFIRM = 0x51, "DL_DataConfirm", Confirm;
    DL_DATA_ERROR = 0x53, "DL_DataError", Error;
    DL_DATA_INDICATION = 0x52, "DL_DataIndication", Indication;
    DL_SNIFFER_INDICATION = 0x5A, "DL_SnifferIndication", Indication;
    SS_DATA_REQUEST = 0x54, "SS_DataRequest", Request;
    SS_DATA_CONFIRM = 0x55, "SS_DataConfirm", Confirm;
    SS_DATA_ERROR = 0x57, "SS_DataError", Error;
    SS_DATA_INDICATION = 0x56, "SS_DataIndication", Indication;
    SS_SNIFFER_INDICATION = 0x5E, "SS_SnifferIndication", Indication;
    CMD_SYNTAX_ERROR = 0x36, "CMD_SyntaxError", Error;
}

/// The manual's name of a command code, `None` for a code UM0932 does not
/// define.
pub fn name(code: u8) -> Option<&'static str> {
    ALL.iter().find(|(c, ..)| *c == code).map(|(_, n, _)| *n)
}

/// The type of a command code.
pub fn command_type(code: u8) -> Option<CommandType> {
    ALL.iter().find(|(c, ..)| *c == code).map(|(.., t)| *t)
}

/// Whether the modem executes this code when the host sends it (Table 10);
/// any other code gets CMD_SyntaxError (3.3.23).
pub fn is_request(code: u8) -> bool {
    command_type(code) == Some(CommandType::Request)
}

/// The confirm that answers `request` when it is accepted (Table 10).
pub fn confirm_for(request: u8) -> Option<u8> {
    Some(match request {
        BIO_RESET_REQUEST => BIO_RESET_CONFIRM,
        MIB_WRITE_REQUEST => MIB_WRITE_CONFIRM,
        MIB_READ_REQUEST => MIB_READ_CONFIRM,
        MIB_ERASE_REQUEST => MIB_ERASE_CONFIRM,
        PING_REQUEST => PING_CONFIRM,
        PHY_DATA_REQUEST => PHY_DATA_CONFIRM,
        DL_DATA_REQUEST => DL_DATA_CONFIRM,
        SS_DATA_REQUEST => SS_DATA_CONFIRM,
        _ => return None,
    })
}

/// Whether `answer` is what the modem sends back for `request`: its
/// confirm, its error, or CMD_SyntaxError (UM0932 3.3.23).
pub fn answers(request: u8, answer: u8) -> bool {
    answer == CMD_SYNTAX_ERROR
        || confirm_for(request) == Some(answer)
        || error_for(request) == Some(answer)
}

/// The error command that refuses `request` (UM0932 Table 12), if it can
/// be refused: PingRequest cannot.
pub fn error_for(request: u8) -> Option<u8> {
    Some(match request {
        BIO_RESET_REQUEST => BIO_RESET_ERROR,
        MIB_WRITE_REQUEST => MIB_WRITE_ERROR,
        MIB_READ_REQUEST => MIB_READ_ERROR,
        MIB_ERASE_REQUEST => MIB_ERASE_ERROR,
        PHY_DATA_REQUEST => PHY_DATA_ERROR,
        DL_DATA_REQUEST => DL_DATA_ERROR,
        SS_DATA_REQUEST => SS_DATA_ERROR,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_request_has_a_confirm_and_all_but_ping_an_error() {
        for &(c, name, t) in ALL {
            if t != CommandType::Request {
                assert_eq!(confirm_for(c), None, "{name}");
                continue;
            }
            let confirm = confirm_for(c).expect(name);
            assert_eq!(command_type(confirm), Some(CommandType::Confirm), "{name}");
            match error_for(c) {
                Some(e) => assert_eq!(command_type(e), Some(CommandType::Error), "{name}"),
                None => assert_eq!(c, PING_REQUEST),
            }
            assert!(answers(c, CMD_SYNTAX_ERROR) && answers(c, confirm));
            assert!(!answers(c, c));
        }
    }
}
