//! Field layouts of the ST7570 command data (ST7570 UM 5.3, Tables 16-67)
//! and the enumerations they use. Each layout is the one description of
//! its table: the typed codecs ([`super::Command`]), the decoder, console
//! forms and the simulated modem all read it. Sub-fields are LSByte first
//! (5.2.1) except the MAC ADDRESS (Table 38: MSByte first) and the spy
//! ALARM pattern (Table 57: MSByte first).

use crate::field::{sparse_names, Field, Order, Scale};

/// S0/N0/S1/N1 raw estimations (and every number the manual gives as
/// 100·dBµV): one step is 0.01 dBµV.
pub const SN_UNIT: &str = "0.01 dBµV";
/// SNR0/SNR1 fine estimations: one step is 640·log10(2)/2^19 dB.
pub const SNR_UNIT: &str = "640·log10(2)/2^19 dB";

/// 3.6.1, Equation 1: V_RMS [dBµV] = value / 100, given to the hundredth
/// as Table 3 and section 9 give it.
pub const DBUV: Scale = Scale {
    unit: "dBµV",
    factor: 0.01,
    decimals: 2,
};
/// 3.6.1, Equation 2: SNR [dB] = 10·64·value·log10(2)·2^-19, given to
/// three places as section 9 gives it (24.936 dB; one step is 0.00037 dB).
pub const SNR_DB: Scale = Scale {
    unit: "dB",
    factor: 640.0 * core::f64::consts::LOG10_2 / (1u32 << 19) as f64,
    decimals: 3,
};

/// A number in 0.01 dBµV (S0..N1, S, N, AL_*, thresholds), read in dBµV.
pub const fn in_dbuv(f: Field) -> Field {
    f.unit(SN_UNIT).scaled(&DBUV)
}

/// dBµV RMS of a raw signal or noise estimation (3.6.1, Equation 1).
pub fn sn_dbuv(value: u32) -> f64 {
    DBUV.of(value as i64)
}

/// dB of a raw SNR estimation (3.6.1, Equation 2).
pub fn snr_db(value: u32) -> f64 {
    SNR_DB.of(value as i64)
}

/// Electrical delta-phase codes of Table 4 (1200 bps column; at 2400 bps
/// each code also means the angle 180° away, 4.9.1). 7 is undefined.
pub const DELTA_PHASES: &[&str] = &["Not valid", "0°", "+60°", "+120°", "+180°", "-120°", "-60°"];
/// SYNC of a MAC CMD_SynchroIndication (Table 18); 0 and 3 are undefined.
pub const SYNC_STATES: &[&str] = &["", "FOUND", "CONFIRMED", "", "LOST", "INTELLIGENT"];
/// CAUSE of SYNC = 4 (LOST), Table 18.
pub const LOST_CAUSES: &[&str] = &[
    "",
    "Timeout not addressed expired",
    "Timeout frame not OK expired",
    "Timeout synchronization confirm expired",
    "Addressed by a wrong initiator",
    "Desynchronization request from host",
];
/// CAUSE of SYNC = 5 (INTELLIGENT), Table 18: 06h..08h.
pub const INTELLIGENT_CAUSES: &[&str] = &[
    "",
    "",
    "",
    "",
    "",
    "",
    "LM_IS_INIT",
    "LM_IS_SYNC_FAST",
    "LM_IS_NOT_INIT",
];
/// CONFIRM_CODE of CMD_DataConfirm in PHY mode (Table 43).
pub static PHY_CONFIRM_CODES: [&str; 256] = sparse_names(&[
    (0x00, "LP_TU"),
    (0x03, "LM_SE"),
    (0x04, "LP_NS"),
    (0x06, "LP_NOT_VALID"),
    (0xFF, "LP_OK"),
]);
/// CONFIRM_CODE of CMD_DataConfirm in MAC mode (Table 43).
pub static MAC_CONFIRM_CODES: [&str; 256] = sparse_names(&[
    (0x00, "LM_TU"),
    (0x01, "LM_NI"),
    (0x02, "LP_HF"),
    (0x03, "LM_SE"),
    (0x04, "LM_NS"),
    (0x05, "LM_IS"),
    (0x06, "LM_NOT_VALID"),
    (0xFF, "LM_OK"),
]);
/// What a CONFIRM_CODE of CMD_DataConfirm (Table 43) or CMD_AlarmConfirm
/// (Table 48) means, by its name in those tables; `None` for LP_OK and
/// LM_OK, which need no words.
pub fn confirm_meaning(name: &str) -> Option<&'static str> {
    Some(match name {
        "LP_TU" => "the modem's PHY layer is busy (another transmission pending or in progress, or outside the acceptance window): send again",
        "LM_TU" => "the MAC layer is busy: send again",
        "LM_NI" => "type not available",
        "LP_HF" => "error at the physical level",
        "LM_SE" => "length not correct on the data request",
        "LP_NS" | "LM_NS" => "the modem is not synchronized",
        "LP_IS" | "LM_IS" => "the modem is in Intelligent Synchronization search",
        "LP_NOT_VALID" => "no data request pending, or error at the physical layer",
        "LM_NOT_VALID" => "no data request pending",
        _ => return None,
    })
}

/// CONFIRM_CODE of CMD_AlarmConfirm (Table 48).
pub static ALARM_CONFIRM_CODES: [&str; 256] = sparse_names(&[
    (0x00, "LP_TU"),
    (0x04, "LP_NS"),
    (0x05, "LP_IS"),
    (0xFF, "LP_OK"),
]);
/// RESULT of CMD_RC_Confirm (Table 63).
pub static RC_RESULTS: [&str; 256] = sparse_names(&[
    (0x00, "LP_TU"),
    (0x01, "LP_NI"),
    (0x04, "LP_NS"),
    (0x06, "LP_NOT_VALID"),
    (0xFF, "LP_OK"),
]);
/// Repeater settings: CMD_RC_Confirm REPEATER STATE (Table 63) and MIB
/// 000Bh b1..b0 (Table 97, where 3 is spelt "REPEATER").
pub const REPEATER_STATES: &[&str] = &["NEVER_REPEAT", "ALWAYS_REPEAT", "NO_REPEAT", "REPEAT"];
/// IS_STATUS of CMD_IS_Indication (Table 65).
pub const IS_STATUSES: &[&str] = &[
    "",
    "LM_LOCKED",
    "LM_NOT_LOCKED",
    "LM_NOT_REGISTERED",
    "LM_TO_NOT_ADDRESSED",
];
/// MIB error codes (Table 70; Tables 30 and 35 list the ones of each
/// command). One byte on the wire although the table prints 011h.
pub static MIB_ERRORS: [&str; 256] = sparse_names(&[
    (0x11, "ERR_UNAVAILABLE_RESOURCE"),
    (0x12, "ERR_REQUEST_NOT_ALLOWED"),
    (0x22, "ERR_ILLEGAL_DATA_COMMAND"),
    (0x23, "ERR_ILLEGAL_LOCAL_MAC_ADR"),
    (0x24, "ERR_ILLEGAL_INITIATOR_MAC_ADR"),
    (0x26, "ERR_PARAM_VAL_OUTOFRANGE"),
]);

const fn le(f: Field) -> Field {
    f.order(Order::LsbFirst)
}

/// A 3-byte raw signal or noise estimation, LSByte first.
const fn sn(name: &'static str, label: &'static str, offset: usize) -> Field {
    in_dbuv(le(Field::uint(name, label, offset, 3)))
}

/// S0, N0, S1, N1 at bytes 0..11 (Tables 17, 50, 52, 55; shifted where
/// another table places them).
pub mod signal_noise {
    use super::*;
    /// Signal on channel 0.
    pub const S0: Field = sn("s0", "S0", 0);
    /// Noise on channel 0.
    pub const N0: Field = sn("n0", "N0", 3);
    /// Signal on channel 1.
    pub const S1: Field = sn("s1", "S1", 6);
    /// Noise on channel 1.
    pub const N1: Field = sn("n1", "N1", 9);
    /// Bytes of the four.
    pub const LEN: usize = 12;
}
use signal_noise::{N0, N1, S0, S1};

/// RX PGA gain, 0..8 (3.6.3).
const fn pga(offset: usize) -> Field {
    Field::uint("pga", "PGA", offset, 1).range(0, 8)
}
const fn phase(offset: usize) -> Field {
    Field::enumeration("phase", "PHASE", offset, 0, 8, DELTA_PHASES)
}
const fn ask0(offset: usize) -> Field {
    le(Field::uint("ask0", "ASK0", offset, 2))
}
const fn ask1(offset: usize) -> Field {
    le(Field::uint("ask1", "ASK1", offset, 2))
}
const fn fsk(offset: usize) -> Field {
    le(Field::uint("fsk", "FSK", offset, 2))
}
const fn snr(name: &'static str, label: &'static str, offset: usize) -> Field {
    le(Field::uint(name, label, offset, 3))
        .unit(SNR_UNIT)
        .scaled(&SNR_DB)
}
const fn mac_address(name: &'static str, label: &'static str, offset: usize) -> Field {
    le(Field::uint(name, label, offset, 2)).range(0, 0xFFF)
}
const fn byte(name: &'static str, label: &'static str, offset: usize) -> Field {
    Field::uint(name, label, offset, 1)
}

/// Bytes of a P_SDU (3.2: 38 bytes, 304 bits).
pub const P_SDU_LEN: usize = 38;
/// Largest M_SDU (4.4, Table 41).
pub const M_SDU_MAX: usize = 242;

/// 10h in PHY mode, P_Sync.Indication (Table 17).
pub const PHY_SYNCHRO_INDICATION: &[Field] = &[S0, N0, S1, N1, pga(12), phase(13)];

/// 10h in MAC mode (Table 18): SYNC, then one layout per SYNC value.
pub mod mac_sync {
    use super::*;
    /// Byte 0.
    pub const SYNC: Field = Field::enumeration("sync", "SYNC", 0, 0, 8, SYNC_STATES);
    /// SYNC = 1: FOUND, 15 bytes.
    pub const FOUND: &[Field] = &[
        SYNC,
        S0.shifted(1),
        N0.shifted(1),
        S1.shifted(1),
        N1.shifted(1),
        pga(13),
        phase(14),
    ];
    /// SYNC = 2: CONFIRMED, 6 bytes.
    pub const CONFIRMED: &[Field] = &[
        SYNC,
        byte("pad", "PAD", 1),
        mac_address("sa", "SA", 2),
        mac_address("da", "DA", 4),
    ];
    /// SYNC = 4: LOST, 6 bytes. ADD1 is the local address (the source
    /// address for CAUSE 4), ADD2 the initiator (the destination for 4).
    pub const LOST: &[Field] = &[
        SYNC,
        Field::enumeration("cause", "CAUSE", 1, 0, 8, LOST_CAUSES),
        mac_address("add1", "ADD1", 2),
        mac_address("add2", "ADD2", 4),
    ];
    /// SYNC = 5: INTELLIGENT, 6 bytes.
    pub const INTELLIGENT: &[Field] = &[
        SYNC,
        Field::enumeration("cause", "CAUSE", 1, 0, 8, INTELLIGENT_CAUSES),
        mac_address("add", "ADD", 2),
        in_dbuv(le(Field::uint("s", "S", 4, 2))),
    ];
    /// Data bytes of FOUND.
    pub const FOUND_LEN: usize = 15;
    /// Data bytes of CONFIRMED, LOST and INTELLIGENT.
    pub const SHORT_LEN: usize = 6;
}

/// 11h (Table 22).
pub const DESYNCHRO_REQUEST: &[Field] = &[Field::enumeration(
    "reset",
    "RESET",
    0,
    0,
    8,
    &["", "Rejects current synchronization"],
)];
/// 85h answer (Table 20).
pub const SYNCHRO_STATUS: &[Field] = &[Field::enumeration(
    "status",
    "STATUS",
    0,
    0,
    8,
    &["", "LP_SYNC_FOUND", "LP_SYNC_LOSS"],
)];
/// 21h from the host (Table 24): auto-reconfiguration bypass.
pub const RESET_REQUEST: &[Field] = &[Field::enumeration(
    "reset",
    "RESET",
    0,
    0,
    8,
    &["OFF", "ON"],
)];
/// 21h from the modem (Table 25).
pub const RESET_CONFIRM: &[Field] = &[Field::enumeration(
    "reset",
    "RESET",
    0,
    0,
    8,
    &["The reset request has been taken into account"],
)];
/// INDEX of 41h, 42h, 90h, 91h (Tables 27, 32): LSByte first.
pub const INDEX: Field = le(Field::uint("index", "INDEX", 0, 2));
/// 41h, 42h, 91h: INDEX then the object's DATA (Table 27).
pub const DB_DATA: &[Field] = &[INDEX, Field::bytes("data", "DATA", 2, 0)];
/// 90h (Table 32).
pub const DB_INDEX: &[Field] = &[INDEX];
/// 43h, 92h (Tables 30, 35).
pub const DB_ERROR: &[Field] = &[Field::enumeration("error", "ERROR", 0, 0, 8, &MIB_ERRORS)];

/// 50h in PHY mode (Table 37), 50 bytes.
pub const PHY_DATA_INDICATION: &[Field] = &[
    Field::bytes("p_sdu", "P_SDU", 0, P_SDU_LEN),
    ask0(38),
    ask1(40),
    fsk(42),
    snr("snr0", "SNR0", 44),
    snr("snr1", "SNR1", 47),
];
/// Bytes of a PHY CMD_DataIndication.
pub const PHY_DATA_INDICATION_LEN: usize = 50;
/// 51h in PHY mode (Table 40).
pub const PHY_DATA_REQUEST: &[Field] = &[Field::bytes("p_sdu", "P_SDU", 0, 0)];

/// CREDIT (b7..b5 IC, b4..b2 CC, b1..b0 DC) and the 24-bit ADDRESS
/// (b23..b12 SA, b11..b0 DA, MSByte first) of MAC data (Tables 38, 41).
pub mod mac_data {
    use super::*;
    /// Initial credit.
    pub const IC: Field = Field::bits_uint("ic", "IC", 0, 5, 3);
    /// Current credit.
    pub const CC: Field = Field::bits_uint("cc", "CC", 0, 2, 3);
    /// Delta credit.
    pub const DC: Field = Field::bits_uint("dc", "DC", 0, 0, 2);
    /// Source address.
    pub const SA: Field = Field::uint("sa", "SA", 1, 3).within(12, 12);
    /// Destination address.
    pub const DA: Field = Field::uint("da", "DA", 1, 3).within(0, 12);
    /// Padding (00h in a request, Table 41).
    pub const PAD: Field = Field::uint("pad", "PAD", 4, 1);
    /// The MAC service data unit, to the end (Table 41: up to 242 bytes).
    pub const M_SDU: Field = Field::bytes("m_sdu", "M_SDU", 5, 0);
    /// 50h and 51h in MAC mode.
    pub const LAYOUT: &[Field] = &[IC, CC, DC, SA, DA, PAD, M_SDU];
    /// Bytes before M_SDU.
    pub const HEADER_LEN: usize = 5;
}

/// 52h in PHY mode (Table 43).
pub const PHY_DATA_CONFIRM: &[Field] = &[Field::enumeration(
    "confirm_code",
    "CONFIRM_CODE",
    0,
    0,
    8,
    &PHY_CONFIRM_CODES,
)];
/// 52h in MAC mode (Table 43).
pub const MAC_DATA_CONFIRM: &[Field] = &[Field::enumeration(
    "confirm_code",
    "CONFIRM_CODE",
    0,
    0,
    8,
    &MAC_CONFIRM_CODES,
)];
/// 89h (Table 48).
pub const ALARM_CONFIRM: &[Field] = &[Field::enumeration(
    "confirm_code",
    "CONFIRM_CODE",
    0,
    0,
    8,
    &ALARM_CONFIRM_CODES,
)];

/// 8Ah (Table 45): CNT, then S0..N1 and PAD in the long form (MIB 0086h
/// b2 = 0).
pub mod alarm_indication {
    use super::*;
    /// Alarms received counter.
    pub const CNT: Field = le(Field::uint("cnt", "CNT", 0, 4));
    /// Short form, 4 bytes.
    pub const SHORT: &[Field] = &[CNT];
    /// Long form, 17 bytes.
    pub const LONG: &[Field] = &[
        CNT,
        S0.shifted(4),
        N0.shifted(4),
        S1.shifted(4),
        N1.shifted(4),
        byte("pad", "PAD", 16),
    ];
    /// Bytes of the short form.
    pub const SHORT_LEN: usize = 4;
    /// Bytes of the long form.
    pub const LONG_LEN: usize = 17;
}

/// A0h (Table 50), 70 bytes: S0..N1 then 58 PAD bytes.
pub const SPY_NO_SUBFRAME: &[Field] = &[S0, N0, S1, N1, Field::bytes("pad", "PAD", 12, 58)];
/// Bytes of A0h.
pub const SPY_NO_SUBFRAME_LEN: usize = 70;
/// B0h (Table 52), 63 bytes.
pub const SPY_SUBFRAME: &[Field] = &[
    S0,
    N0,
    S1,
    N1,
    ask0(12),
    ask1(14),
    fsk(16),
    pga(18),
    Field::bytes("p_sdu", "P_SDU", 19, P_SDU_LEN),
    snr("snr0", "SNR0", 57),
    snr("snr1", "SNR1", 60),
];
/// Bytes of B0h.
pub const SPY_SUBFRAME_LEN: usize = 63;
/// D0h (Table 55), 19 bytes.
pub const SPY_SYNCHRO_FOUND: &[Field] = &[S0, N0, S1, N1, ask0(12), ask1(14), fsk(16), pga(18)];
/// Bytes of D0h.
pub const SPY_SYNCHRO_FOUND_LEN: usize = 19;

/// E0h and F0h (Tables 57, 59), 22 bytes.
pub mod spy_alarm {
    use super::*;
    /// The alarm pattern the modem reports (3.5.2, Table 57).
    pub const PATTERN: u32 = 0x569E89;
    /// 22 bytes: AL_S0..AL_N1, 7 PAD bytes, ALARM (MSByte first).
    pub const LAYOUT: &[Field] = &[
        sn("al_s0", "AL_S0", 0),
        sn("al_n0", "AL_N0", 3),
        sn("al_s1", "AL_S1", 6),
        sn("al_n1", "AL_N1", 9),
        Field::bytes("pad", "PAD", 12, 7),
        Field::uint("alarm", "ALARM", 19, 3),
    ];
    /// Bytes of E0h and F0h.
    pub const LEN: usize = 22;
}

/// 61h (Table 61).
pub const RC_REQUEST: &[Field] = &[
    le(Field::uint("tx_pos", "TX_POS", 0, 2)),
    in_dbuv(le(Field::uint("rc_threshold", "RC_THRESHOLD", 2, 2))),
];

/// 62h (Table 63): RESULT, REPEATER STATE, and for a Server with LP_OK
/// the RC pattern heard.
pub mod rc_confirm {
    use super::*;
    /// Byte 0.
    pub const RESULT: Field = Field::enumeration("result", "RESULT", 0, 0, 8, &RC_RESULTS);
    /// Byte 1.
    pub const REPEATER_STATE: Field =
        Field::enumeration("repeater_state", "REPEATER STATE", 1, 0, 8, REPEATER_STATES);
    /// 2 bytes.
    pub const SHORT: &[Field] = &[RESULT, REPEATER_STATE];
    /// 10 bytes.
    pub const LONG: &[Field] = &[
        RESULT,
        REPEATER_STATE,
        sn("s", "S", 2),
        sn("n", "N", 5),
        le(Field::uint("rx_pos", "RX_POS", 8, 2)),
    ];
    /// Bytes of the short form.
    pub const SHORT_LEN: usize = 2;
    /// Bytes of the long form.
    pub const LONG_LEN: usize = 10;
}

/// 15h (Table 65): IS_STATUS, and for LM_LOCKED the best initiator.
pub mod is_indication {
    use super::*;
    /// Byte 0.
    pub const IS_STATUS: Field = Field::enumeration("is_status", "IS_STATUS", 0, 0, 8, IS_STATUSES);
    /// 1 byte.
    pub const SHORT: &[Field] = &[IS_STATUS];
    /// 5 bytes.
    pub const LONG: &[Field] = &[
        IS_STATUS,
        mac_address("add", "ADD", 1),
        in_dbuv(le(Field::uint("s", "S", 3, 2))),
    ];
    /// Bytes of the long form.
    pub const LONG_LEN: usize = 5;
}

/// 20h (Table 67).
pub const SYNTAX_ERROR: &[Field] = &[Field::enumeration(
    "error",
    "ERROR",
    0,
    0,
    8,
    &["", "Error"],
)];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_3_conversions() {
        // 3.6.1 Table 3: S0 002C8Fh = 114.07 dBµV ... N1 0023F6h = 92.06.
        for (raw, dbuv) in [
            (0x2C8F, 114.07),
            (0x2359, 90.49),
            (0x2B0C, 110.20),
            (0x23F6, 92.06),
        ] {
            assert!((sn_dbuv(raw) - dbuv).abs() < 1e-9, "{raw:x}");
        }
        // 9 step 3: SNR0 10913h = 24.936 dB, SNR1 FD33h = 23.819 dB.
        assert!((snr_db(0x10913) - 24.936).abs() < 5e-4);
        assert!((snr_db(0xFD33) - 23.819).abs() < 5e-4);
    }

    #[test]
    fn layouts_end_where_the_tables_say() {
        let end = |l: &[Field]| l.iter().map(Field::end).max().unwrap();
        assert_eq!(end(PHY_SYNCHRO_INDICATION), 14);
        assert_eq!(end(mac_sync::FOUND), mac_sync::FOUND_LEN);
        for l in [mac_sync::CONFIRMED, mac_sync::LOST, mac_sync::INTELLIGENT] {
            assert_eq!(end(l), mac_sync::SHORT_LEN);
        }
        assert_eq!(end(PHY_DATA_INDICATION), PHY_DATA_INDICATION_LEN);
        assert_eq!(end(alarm_indication::LONG), alarm_indication::LONG_LEN);
        assert_eq!(end(SPY_NO_SUBFRAME), SPY_NO_SUBFRAME_LEN);
        assert_eq!(end(SPY_SUBFRAME), SPY_SUBFRAME_LEN);
        assert_eq!(end(SPY_SYNCHRO_FOUND), SPY_SYNCHRO_FOUND_LEN);
        assert_eq!(end(spy_alarm::LAYOUT), spy_alarm::LEN);
        assert_eq!(end(rc_confirm::LONG), rc_confirm::LONG_LEN);
        assert_eq!(end(is_indication::LONG), is_indication::LONG_LEN);
    }
}
