//! Property tests of the ST7580 typed codecs (docs/architecture.md
//! "Testing"): `parse(emit(x)) == x` for every command of UM0932 3.3 and
//! every MIB object of UM0932 4, the factory defaults of Table 52, and
//! `parse` on arbitrary bytes (never a panic, the lengths of the manual's
//! tables, and the same bytes back except the bits the manual marks
//! unused).

use plm_core::field::Kind;
use plm_core::link::{Dialect, Frame, LocalFrame};
use plm_core::mib;
use plm_core::st7580::code::{self, ALL};
use plm_core::st7580::mib::{self as st_mib, Counters, MibObject, ModemConfig, PhyConfig};
use plm_core::st7580::{
    Channel, Command, DataConfirm, DataIndication, DataRequest, ErrorCause, FrequencySet,
    IndicationInfo, Modulation, ResetCause, ResetData, SsDataRequest, Temperature, TxParams,
};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::strategy::{BoxedStrategy, Union, ValueTree};
use proptest::test_runner::TestRunner;
use std::collections::HashSet;
use std::mem::discriminant;

/// Largest data field of an ST7580 local frame (UM0932 Table 6).
const MAX_DATA: usize = 255;

fn bytes(max: usize) -> impl Strategy<Value = Vec<u8>> {
    vec(any::<u8>(), 0..=max)
}

fn error_cause() -> impl Strategy<Value = ErrorCause> {
    // Every byte is a cause (Table 14 names five, the rest are preserved);
    // `from_byte` gives the one representation each byte has.
    any::<u8>().prop_map(ErrorCause::from_byte)
}

fn modulation() -> impl Strategy<Value = Modulation> {
    (0u8..8).prop_map(Modulation::from_bits)
}

fn temperature() -> impl Strategy<Value = Temperature> {
    (0u8..4).prop_map(Temperature::from_bits)
}

fn tx_params() -> impl Strategy<Value = TxParams> {
    (
        modulation(),
        (0u8..2).prop_map(FrequencySet::from_bits),
        any::<bool>(),
        any::<bool>(),
        proptest::option::of(0u32..=0xFF_FFFF),
        proptest::option::of(0u8..=31),
    )
        .prop_map(
            |(
                modulation,
                frequency_set,
                frequency_overwrite,
                zero_crossing_sync,
                tx_frequency,
                tx_gain,
            )| TxParams {
                modulation,
                frequency_set,
                frequency_overwrite,
                zero_crossing_sync,
                tx_frequency,
                tx_gain,
            },
        )
}

fn data_request() -> impl Strategy<Value = DataRequest> {
    tx_params().prop_flat_map(|params| {
        bytes(MAX_DATA - params.len()).prop_map(move |payload| DataRequest { params, payload })
    })
}

fn ss_data_request() -> impl Strategy<Value = SsDataRequest> {
    (tx_params(), any::<u8>()).prop_flat_map(|(params, header_length)| {
        bytes(MAX_DATA - params.len() - 1).prop_map(move |header_and_payload| SsDataRequest {
            params,
            header_length,
            header_and_payload,
        })
    })
}

fn data_confirm() -> impl Strategy<Value = DataConfirm> {
    (
        temperature(),
        0u8..=31,
        temperature(),
        0u8..=31,
        0u8..=127,
        any::<bool>(),
        any::<i16>(),
    )
        .prop_map(
            |(
                max_temp,
                max_gain,
                min_temp,
                min_gain,
                overcurrent_events,
                overcurrent,
                zc_delay,
            )| {
                DataConfirm {
                    max_temp,
                    max_gain,
                    min_temp,
                    min_gain,
                    overcurrent_events,
                    overcurrent,
                    zc_delay,
                }
            },
        )
}

fn indication_info() -> impl Strategy<Value = IndicationInfo> {
    (
        modulation(),
        (0u8..2).prop_map(Channel::from_bits),
        0u8..=15,
        any::<u8>(),
        any::<i16>(),
    )
        .prop_map(
            |(modulation, rx_channel, pga, snr, zc_delay)| IndicationInfo {
                modulation,
                rx_channel,
                pga,
                snr,
                zc_delay,
            },
        )
}

fn data_indication() -> impl Strategy<Value = DataIndication> {
    // Four bytes of IndicationData, then up to 251 payload bytes (Table 39).
    (indication_info(), bytes(MAX_DATA - 4))
        .prop_map(|(info, payload)| DataIndication { info, payload })
}

fn reset_data() -> impl Strategy<Value = ResetData> {
    (
        (0u8..4).prop_map(ResetCause::from_bits),
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(reset_cause, a, m, p, s)| ResetData {
            reset_cause,
            autoreconfiguration_error: a,
            modem_config_error: m,
            phy_config_error: p,
            ss_key_error: s,
        })
}

fn is_known(c: u8) -> bool {
    ALL.iter().any(|(k, ..)| *k == c)
}

/// One strategy per `Command` variant, so that coverage can be checked.
fn command_arms() -> Vec<BoxedStrategy<Command>> {
    use Command::*;
    vec![
        Just(BioResetRequest).boxed(),
        any::<u8>()
            .prop_map(|confirm_data| BioResetConfirm { confirm_data })
            .boxed(),
        error_cause().prop_map(BioResetError).boxed(),
        reset_data().prop_map(BioResetIndication).boxed(),
        (any::<u8>(), bytes(MAX_DATA - 1))
            .prop_map(|(index, data)| MibWriteRequest { index, data })
            .boxed(),
        Just(MibWriteConfirm).boxed(),
        error_cause().prop_map(MibWriteError).boxed(),
        any::<u8>()
            .prop_map(|index| MibReadRequest { index })
            .boxed(),
        bytes(MAX_DATA)
            .prop_map(|data| MibReadConfirm { data })
            .boxed(),
        error_cause().prop_map(MibReadError).boxed(),
        any::<u8>()
            .prop_map(|index| MibEraseRequest { index })
            .boxed(),
        Just(MibEraseConfirm).boxed(),
        error_cause().prop_map(MibEraseError).boxed(),
        bytes(MAX_DATA)
            .prop_map(|data| PingRequest { data })
            .boxed(),
        bytes(MAX_DATA)
            .prop_map(|data| PingConfirm { data })
            .boxed(),
        data_request().prop_map(PhyDataRequest).boxed(),
        data_confirm().prop_map(PhyDataConfirm).boxed(),
        error_cause().prop_map(PhyDataError).boxed(),
        data_indication().prop_map(PhyDataIndication).boxed(),
        data_request().prop_map(DlDataRequest).boxed(),
        data_confirm().prop_map(DlDataConfirm).boxed(),
        error_cause().prop_map(DlDataError).boxed(),
        data_indication().prop_map(DlDataIndication).boxed(),
        data_indication().prop_map(DlSnifferIndication).boxed(),
        ss_data_request().prop_map(SsDataRequest).boxed(),
        data_confirm().prop_map(SsDataConfirm).boxed(),
        error_cause().prop_map(SsDataError).boxed(),
        data_indication().prop_map(SsDataIndication).boxed(),
        data_indication().prop_map(SsSnifferIndication).boxed(),
        any::<u8>()
            .prop_map(|error| CmdSyntaxError { error })
            .boxed(),
        (
            any::<u8>().prop_filter("a code UM0932 does not define", |c| !is_known(*c)),
            bytes(MAX_DATA),
        )
            .prop_map(|(code, data)| Unknown { code, data })
            .boxed(),
    ]
}

fn command() -> impl Strategy<Value = Command> {
    Union::new(command_arms())
}

#[test]
fn the_command_strategy_covers_every_variant_and_every_code() {
    let mut runner = TestRunner::deterministic();
    let mut variants = HashSet::new();
    let mut codes = HashSet::new();
    let mut unknown = 0;
    for arm in command_arms() {
        let cmd = arm.new_tree(&mut runner).unwrap().current();
        assert!(variants.insert(discriminant(&cmd)), "two arms give {cmd:?}");
        match cmd.name() {
            Some(_) => assert!(codes.insert(cmd.code())),
            None => unknown += 1,
        }
    }
    assert_eq!(variants.len(), 31, "31 variants: 30 commands and Unknown");
    assert_eq!(unknown, 1);
    let all: HashSet<u8> = ALL.iter().map(|(c, ..)| *c).collect();
    assert_eq!(codes, all);
}

/// The checksum of UM0932 Table 6, computed here from the wire bytes
/// independently of `plm_core::link::checksum`.
fn wire_checksum_ok(frame: &[u8]) -> bool {
    let n = frame.len();
    let sum = frame[1..n - 2]
        .iter()
        .fold(0u16, |a, b| a.wrapping_add(*b as u16));
    sum == u16::from_le_bytes([frame[n - 2], frame[n - 1]])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn every_command_survives_emit_and_parse(cmd in command()) {
        let data = cmd.data();
        prop_assert!(data.len() <= MAX_DATA);
        prop_assert_eq!(Command::parse(cmd.code(), &data), Ok(cmd.clone()));

        let wire = cmd.to_frame().emit(Dialect::St7580).expect("fits a local frame");
        prop_assert_eq!(wire.len(), data.len() + 5);
        prop_assert_eq!(wire[0], 0x02);
        prop_assert_eq!(wire[1] as usize, data.len(), "ST7580 length counts the data only");
        prop_assert!(wire_checksum_ok(&wire));
        let f = Frame::new_checked(&wire[..], Dialect::St7580).expect("a whole frame");
        prop_assert!(f.checksum_ok());
        prop_assert_eq!(f.total_len(), wire.len());
        prop_assert_eq!(f.code(), cmd.code());
        prop_assert_eq!(f.data(), &data[..]);
        prop_assert_eq!(Command::from_frame(&LocalFrame::parse(&f)), Ok(cmd));
    }
}

fn counters(n: usize) -> impl Strategy<Value = Counters> {
    vec(any::<u16>(), n).prop_map(Counters)
}

fn modem_config() -> impl Strategy<Value = ModemConfig> {
    (0u8..=3, any::<bool>(), 0u8..=3, any::<bool>()).prop_map(
        |(access_mode, sniffer_mode, crc_length, dl_crc_on_phy_length)| ModemConfig {
            access_mode,
            sniffer_mode,
            crc_length,
            dl_crc_on_phy_length,
        },
    )
}

fn phy_config() -> impl Strategy<Value = PhyConfig> {
    (
        (
            0u32..=0xFF_FFFF,
            0u32..=0xFF_FFFF,
            any::<bool>(),
            any::<bool>(),
            any::<bool>(),
            any::<bool>(),
            0u8..=31,
        ),
        (
            any::<i16>(),
            0u8..=3,
            0u8..=3,
            any::<bool>(),
            0u8..=3,
            any::<bool>(),
            any::<u16>(),
        ),
    )
        .prop_map(
            |(
                (high_frequency, low_frequency, dual, high_psk, low_psk, current_control, tx_gain),
                (zc_delay, psk_pre, bit_rate, dev1, fsk_pre, uw16, uw),
            )| PhyConfig {
                high_frequency,
                low_frequency,
                rx_mode_dual: dual,
                rx_high_psk: high_psk,
                rx_low_psk: low_psk,
                current_control,
                tx_gain,
                zc_delay,
                psk_preamble_length: psk_pre,
                fsk_bit_rate: bit_rate,
                fsk_deviation_1: dev1,
                fsk_preamble_length: fsk_pre,
                fsk_unique_word_16: uw16,
                fsk_unique_word: uw,
            },
        )
}

fn mib_arms() -> Vec<BoxedStrategy<MibObject>> {
    vec![
        modem_config().prop_map(MibObject::ModemConfig).boxed(),
        phy_config().prop_map(MibObject::PhyConfig).boxed(),
        any::<[u8; 16]>().prop_map(MibObject::SsKey).boxed(),
        any::<u8>().prop_map(MibObject::Reserved).boxed(),
        indication_info()
            .prop_map(MibObject::LastDataIndication)
            .boxed(),
        data_confirm().prop_map(MibObject::LastTxConfirm).boxed(),
        // Tables 58-60: 5, 4 and 5 two-byte counters.
        counters(5).prop_map(MibObject::PhyData).boxed(),
        counters(4).prop_map(MibObject::DlData).boxed(),
        counters(5).prop_map(MibObject::SsData).boxed(),
        (any::<u8>(), any::<u8>(), any::<u8>())
            .prop_map(|(t_sr, t_ack, t_ic)| MibObject::HostInterfaceTimeout { t_sr, t_ack, t_ic })
            .boxed(),
        any::<u32>().prop_map(MibObject::FirmwareVersion).boxed(),
    ]
}

#[test]
fn the_mib_strategy_covers_every_object() {
    let mut runner = TestRunner::deterministic();
    let indexes: HashSet<u8> = mib_arms()
        .into_iter()
        .map(|arm| arm.new_tree(&mut runner).unwrap().current().index())
        .collect();
    let table: HashSet<u8> = st_mib::OBJECTS.iter().map(|o| o.index as u8).collect();
    assert_eq!(indexes, table);
    assert_eq!(indexes.len(), 11, "Table 52: 00h..0Ah");
}

/// The bits of an object's value that its layout gives a settable meaning;
/// reserved, unused and undescribed bits are 0 in the mask.
fn meaningful_bits(o: &mib::Object) -> Vec<u8> {
    let mut mask = vec![0u8; o.len];
    for f in o.fields.iter().filter(|f| f.settable) {
        let end = match (f.kind, f.size) {
            (Kind::Bytes, 0) => o.len,
            _ => f.offset + f.size,
        };
        match f.bits {
            Some((lo, width)) => mask[f.offset] |= (((1u16 << width) - 1) << lo) as u8,
            None => mask[f.offset..end].iter_mut().for_each(|b| *b = 0xFF),
        }
    }
    mask
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn every_mib_object_survives_encode_and_decode(o in Union::new(mib_arms())) {
        let bytes = o.encode();
        let table = st_mib::object(o.index()).expect("a Table 52 object");
        prop_assert_eq!(bytes.len(), table.len);
        prop_assert_eq!(MibObject::decode(o.index(), &bytes), Ok(o));
    }

    /// Any value of the right length decodes, and encodes back to the same
    /// bytes except the bits Tables 53-62 leave reserved or unused: the
    /// typed structs and the declarative layouts agree bit for bit.
    #[test]
    fn any_mib_value_decodes_and_keeps_its_meaningful_bits(
        o in select(st_mib::OBJECTS),
        raw in vec(any::<u8>(), 16),
    ) {
        let value = &raw[..o.len];
        let decoded = MibObject::decode(o.index as u8, value).expect("right length");
        prop_assert_eq!(decoded.index() as u16, o.index);
        let mask = meaningful_bits(&o);
        let masked: Vec<u8> = value.iter().zip(&mask).map(|(v, m)| v & m).collect();
        prop_assert_eq!(decoded.encode(), masked);
    }

    #[test]
    fn mib_decode_refuses_wrong_lengths_and_unknown_indexes(
        index in any::<u8>(),
        value in bytes(20),
    ) {
        let result = MibObject::decode(index, &value);
        match st_mib::object(index) {
            None => prop_assert_eq!(result, Err(mib::MibError::UnknownObject(index as u16))),
            Some(o) if o.len != value.len() => prop_assert_eq!(
                result,
                Err(mib::MibError::WrongLength { object: o.name, expected: o.len, got: value.len() })
            ),
            Some(_) => prop_assert!(result.is_ok()),
        }
    }
}

#[test]
fn every_factory_default_is_valid_and_round_trips() {
    assert_eq!(st_mib::OBJECTS.len(), 11);
    for o in st_mib::OBJECTS {
        assert_eq!(o.default.len(), o.len, "{}", o.name);
        assert_eq!(o.check_value(o.default), Ok(()), "{}", o.name);
        let decoded = MibObject::decode(o.index as u8, o.default)
            .unwrap_or_else(|e| panic!("{}: {e}", o.name));
        assert_eq!(decoded.index() as u16, o.index);
        assert_eq!(decoded.encode(), o.default, "{}", o.name);
        assert_eq!(MibObject::factory_default(o.index as u8), Some(decoded));
    }
}

/// Whether UM0932 accepts `data` as the data field of `code`, from the
/// lengths of Tables 16-51 (written here independently of the parser).
fn length_fits(code: u8, data: &[u8]) -> bool {
    use code::*;
    let n = data.len();
    // Tables 35/45: byte 0, 3 TX frequency bytes if bit 0, a TX gain byte if bit 3.
    let params = |d: &[u8]| {
        d.first()
            .map(|b| 1 + 3 * (b & 1) as usize + ((b >> 3) & 1) as usize)
    };
    match code {
        BIO_RESET_REQUEST | MIB_WRITE_CONFIRM | MIB_ERASE_CONFIRM => n == 0,
        BIO_RESET_CONFIRM | BIO_RESET_INDICATION | MIB_READ_REQUEST | MIB_ERASE_REQUEST
        | CMD_SYNTAX_ERROR | BIO_RESET_ERROR | MIB_WRITE_ERROR | MIB_READ_ERROR
        | MIB_ERASE_ERROR | PHY_DATA_ERROR | DL_DATA_ERROR | SS_DATA_ERROR => n == 1,
        MIB_WRITE_REQUEST => n >= 1,
        PHY_DATA_CONFIRM | DL_DATA_CONFIRM | SS_DATA_CONFIRM => n == 5,
        PHY_DATA_INDICATION
        | DL_DATA_INDICATION
        | DL_SNIFFER_INDICATION
        | SS_DATA_INDICATION
        | SS_SNIFFER_INDICATION => n >= 4,
        PHY_DATA_REQUEST | DL_DATA_REQUEST => params(data).is_some_and(|p| n >= p),
        SS_DATA_REQUEST => params(data).is_some_and(|p| n > p),
        _ => true, // ping, MIB_ReadConfirm, unknown codes: any data
    }
}

/// The bits of a data field that carry a value; the rest are the bits the
/// manual calls unused, which a parsed command does not keep.
fn used_bits(code: u8, data: &[u8]) -> Vec<u8> {
    use code::*;
    let mut mask = vec![0xFFu8; data.len()];
    match code {
        // Table 19: bits 6-7 unused.
        BIO_RESET_INDICATION => mask[0] = 0x3F,
        // Table 37: bit 7 of bytes 0 and 1 unused.
        PHY_DATA_CONFIRM | DL_DATA_CONFIRM | SS_DATA_CONFIRM => {
            mask[0] = 0x7F;
            mask[1] = 0x7F;
        }
        _ => {}
    }
    mask
}

/// Codes whose data has no unused bit the parsed command drops: the
/// re-emitted data must be the input, byte for byte. Requests keep the
/// unused bits of their TX gain byte (Tables 35/45), for validation to
/// refuse them.
fn without_unused_bits(code: u8) -> bool {
    use code::*;
    !matches!(
        code,
        BIO_RESET_INDICATION | PHY_DATA_CONFIRM | DL_DATA_CONFIRM | SS_DATA_CONFIRM
    )
}

fn any_code() -> impl Strategy<Value = u8> {
    let known: Vec<u8> = ALL.iter().map(|(c, ..)| *c).collect();
    prop_oneof![3 => select(known), 1 => any::<u8>()]
}

fn any_data() -> impl Strategy<Value = Vec<u8>> {
    // Short fields hit the exact lengths; long ones the maxima.
    prop_oneof![3 => bytes(8), 1 => bytes(MAX_DATA)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    #[test]
    fn parse_takes_any_data_and_gives_back_its_bytes(code in any_code(), data in any_data()) {
        match Command::parse(code, &data) {
            Ok(cmd) => {
                prop_assert!(length_fits(code, &data), "accepted {code:02X}h {data:02x?}");
                prop_assert_eq!(cmd.code(), code);
                prop_assert_eq!(cmd.name(), code::name(code));
                let again = cmd.data();
                if without_unused_bits(code) {
                    prop_assert_eq!(&again, &data);
                } else {
                    let mask = used_bits(code, &data);
                    let masked: Vec<u8> = data.iter().zip(&mask).map(|(d, m)| d & m).collect();
                    prop_assert_eq!(&again, &masked);
                }
                prop_assert_eq!(Command::parse(code, &again), Ok(cmd));
            }
            Err(e) => {
                prop_assert!(!length_fits(code, &data), "refused {code:02X}h {data:02x?}: {e}");
                prop_assert!(code::name(code).is_some(), "unknown codes are kept, never refused");
                prop_assert_eq!(e.code, code);
                prop_assert_eq!(e.got, data.len());
                prop_assert!(e.min <= e.max);
                prop_assert!(data.len() < e.min || data.len() > e.max, "{}", e);
            }
        }
    }
}
