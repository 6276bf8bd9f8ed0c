//! ST7570 command codes (ST7570 UM 5.3, Table 15): names, groups, types,
//! directions and the access layers that use them.

use super::Layer;

/// The three command types of ST7570 UM 5.3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CommandType {
    /// Sent by the host to use a service.
    Request,
    /// The modem's answer to a request (the manual's "Confirm/Error").
    Confirm,
    /// The modem's refusal of a request.
    Error,
    /// Unsolicited notification of the modem.
    Indication,
}

/// Who sends a command (ST7570 UM Tables 16-67, column "Source").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Ext. host to the ST7570.
    HostToModem,
    /// The ST7570 to its host.
    ModemToHost,
    /// Both: 21h (request and its confirm) and 85h (request and its answer).
    Both,
}

/// One row of Table 15.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Code {
    /// The code byte.
    pub code: u8,
    /// The manual's name (`CMD_SynchroIndication`).
    pub name: &'static str,
    /// The group of Table 15 (`Synchronization`).
    pub group: &'static str,
    /// Its type.
    pub kind: CommandType,
    /// Who sends it.
    pub direction: Direction,
    /// Used with the PHY access layer.
    pub phy: bool,
    /// Used with the MAC access layer.
    pub mac: bool,
}

macro_rules! codes {
    ($($konst:ident = $code:literal, $name:literal, $group:literal, $kind:ident, $dir:ident, $phy:literal, $mac:literal;)*) => {
        $(
            #[doc = concat!("`", $name, "` (", $group, ")")]
            pub const $konst: u8 = $code;
        )*

        /// Every command code of Table 15, in the table's order.
        pub const ALL: &[Code] = &[$(Code {
            code: $code,
            name: $name,
            group: $group,
            kind: CommandType::$kind,
            direction: Direction::$dir,
            phy: $phy,
            mac: $mac,
        }),*];
    };
}

// Layers: 85h is PHY only (5.3.2), the spy indications are PHY Monitor
// only (5.3.17-5.3.22), repeater call and intelligent synchronization are
// MAC services (5.3.23 "accepted or refused by the MAC layer only", 5.3.25).
codes! {
    CMD_SYNCHRO_INDICATION = 0x10, "CMD_SynchroIndication", "Synchronization", Indication, ModemToHost, true, true;
    CMD_DESYNCHRO_REQUEST = 0x11, "CMD_DesynchroRequest", "Synchronization", Request, HostToModem, true, true;
    CMD_SYNCHRO_STATUS = 0x85, "CMD_SynchroStatus", "Synchronization", Request, Both, true, false;
    CMD_RESET_REQUEST = 0x21, "CMD_ResetRequest", "Reset", Request, Both, true, true;
    CMD_WRITE_DB_REQUEST = 0x41, "CMD_WriteDBRequest", "MIB", Request, HostToModem, true, true;
    CMD_WRITE_DB_CONFIRM = 0x42, "CMD_WriteDBConfirm", "MIB", Confirm, ModemToHost, true, true;
    CMD_WRITE_DB_ERROR = 0x43, "CMD_WriteDBError", "MIB", Error, ModemToHost, true, true;
    CMD_READ_DB_REQUEST = 0x90, "CMD_ReadDBRequest", "MIB", Request, HostToModem, true, true;
    CMD_READ_DB_CONFIRM = 0x91, "CMD_ReadDBConfirm", "MIB", Confirm, ModemToHost, true, true;
    CMD_READ_DB_ERROR = 0x92, "CMD_ReadDBError", "MIB", Error, ModemToHost, true, true;
    CMD_DATA_INDICATION = 0x50, "CMD_DataIndication", "Data", Indication, ModemToHost, true, true;
    CMD_DATA_REQUEST = 0x51, "CMD_DataRequest", "Data", Request, HostToModem, true, true;
    CMD_DATA_CONFIRM = 0x52, "CMD_DataConfirm", "Data", Confirm, ModemToHost, true, true;
    CMD_ALARM_REQUEST = 0x88, "CMD_AlarmRequest", "Alarm", Request, HostToModem, true, true;
    CMD_ALARM_CONFIRM = 0x89, "CMD_AlarmConfirm", "Alarm", Confirm, ModemToHost, true, true;
    CMD_ALARM_INDICATION = 0x8A, "CMD_AlarmIndication", "Alarm", Indication, ModemToHost, true, true;
    SPY_NO_SUBFRAME_INDICATION = 0xA0, "SPY_No_SubframeIndication", "Spy", Indication, ModemToHost, true, false;
    SPY_SUBFRAME_INDICATION = 0xB0, "SPY_SubframeIndication", "Spy", Indication, ModemToHost, true, false;
    SPY_SEARCH_SYNCHRO_INDICATION = 0xC0, "SPY_SearchSynchroIndication", "Spy", Indication, ModemToHost, true, false;
    SPY_SYNCHRO_FOUND_INDICATION = 0xD0, "SPY_SynchroFoundIndication", "Spy", Indication, ModemToHost, true, false;
    SPY_NO_ALARM_INDICATION = 0xE0, "SPY_No_AlarmIndication", "Spy", Indication, ModemToHost, true, false;
    SPY_ALARM_INDICATION = 0xF0, "SPY_AlarmIndication", "Spy", Indication, ModemToHost, true, false;
    CMD_RC_REQUEST = 0x61, "CMD_RC_Request", "Repeater Call", Request, HostToModem, false, true;
    CMD_RC_CONFIRM = 0x62, "CMD_RC_Confirm", "Repeater Call", Confirm, ModemToHost, false, true;
    CMD_IS_INDICATION = 0x15, "CMD_IS_Indication", "Intelligent Synchronization", Indication, ModemToHost, false, true;
    CMD_SYNTAX_ERROR = 0x20, "CMD_SyntaxError", "Error", Error, ModemToHost, true, true;
}

/// The row of Table 15 for a code, `None` for a code the manual does not
/// define (the modem answers it with CMD_SyntaxError, 5.3.26).
pub fn lookup(code: u8) -> Option<&'static Code> {
    ALL.iter().find(|c| c.code == code)
}

/// The manual's name of a code.
pub fn name(code: u8) -> Option<&'static str> {
    lookup(code).map(|c| c.name)
}

/// Whether the host may send this code (a request, 21h and 85h included).
pub fn is_request(code: u8) -> bool {
    lookup(code).is_some_and(|c| c.kind == CommandType::Request)
}

/// Whether `layer` uses this code (Tables 15-67; see [`Code`]).
pub fn in_layer(code: u8, layer: Layer) -> bool {
    lookup(code).is_some_and(|c| match layer {
        Layer::Phy => c.phy,
        Layer::Mac => c.mac,
    })
}

/// The codes the modem answers `request` with in `layer`, CMD_SyntaxError
/// aside (5.3.26: any frame can draw it). Empty when nothing answers: a
/// PHY CMD_DesynchroRequest (Table 21), a CMD_RC_Request in PHY (5.3.23
/// "does not take any effect"), a CMD_SynchroStatus in MAC (5.3.2).
pub fn answers_to(request: u8, layer: Layer) -> &'static [u8] {
    match (request, layer) {
        // Table 21: MAC mode answers with SYNC = 4 (LOST), CAUSE = 5.
        (CMD_DESYNCHRO_REQUEST, Layer::Mac) => &[CMD_SYNCHRO_INDICATION],
        // Tables 19, 23: the answer has the request's code. 85h exists in
        // PHY mode only (5.3.2); what MAC mode answers is not said.
        (CMD_SYNCHRO_STATUS, Layer::Phy) => &[CMD_SYNCHRO_STATUS],
        (CMD_RESET_REQUEST, _) => &[CMD_RESET_REQUEST],
        (CMD_WRITE_DB_REQUEST, _) => &[CMD_WRITE_DB_CONFIRM, CMD_WRITE_DB_ERROR],
        (CMD_READ_DB_REQUEST, _) => &[CMD_READ_DB_CONFIRM, CMD_READ_DB_ERROR],
        (CMD_DATA_REQUEST, _) => &[CMD_DATA_CONFIRM],
        (CMD_ALARM_REQUEST, _) => &[CMD_ALARM_CONFIRM],
        (CMD_RC_REQUEST, Layer::Mac) => &[CMD_RC_CONFIRM],
        _ => &[],
    }
}

/// Whether `answer` closes `request` in `layer`: one of its answers, or
/// CMD_SyntaxError (5.3.26).
pub fn answers(request: u8, answer: u8, layer: Layer) -> bool {
    answer == CMD_SYNTAX_ERROR || answers_to(request, layer).contains(&answer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_15_has_26_distinct_codes_and_8_requests() {
        assert_eq!(ALL.len(), 26);
        let mut codes: alloc::vec::Vec<u8> = ALL.iter().map(|c| c.code).collect();
        codes.sort();
        codes.dedup();
        assert_eq!(codes.len(), 26);
        let requests: alloc::vec::Vec<u8> = ALL
            .iter()
            .filter(|c| c.kind == CommandType::Request)
            .map(|c| c.code)
            .collect();
        assert_eq!(requests, [0x11, 0x85, 0x21, 0x41, 0x90, 0x51, 0x88, 0x61]);
    }

    #[test]
    fn every_answer_is_sent_by_the_modem_in_that_layer() {
        for layer in [Layer::Phy, Layer::Mac] {
            for c in ALL.iter().filter(|c| c.kind == CommandType::Request) {
                for a in answers_to(c.code, layer) {
                    let row = lookup(*a).unwrap();
                    assert_ne!(row.direction, Direction::HostToModem, "{}", row.name);
                    assert!(in_layer(*a, layer), "{} in {layer:?}", row.name);
                }
                assert!(answers(c.code, CMD_SYNTAX_ERROR, layer));
            }
        }
        assert!(answers_to(CMD_DESYNCHRO_REQUEST, Layer::Phy).is_empty());
        assert!(!answers(CMD_DATA_REQUEST, CMD_DATA_INDICATION, Layer::Mac));
    }
}
