//! Property tests of the ST7570 typed codecs (docs/architecture.md
//! "Testing"): `parse(emit(x)) == x` for every command of Table 15 in both
//! access layers, for the status message in every row of Table 11 and for
//! every MIB object's value; and arbitrary bytes never panic a parser, and
//! what parses emits the same bytes back (nothing is dropped).

use plm_core::field::Kind;
use plm_core::link::{Dialect, Frame, Source};
use plm_core::st7570::mib::{self, PlcConfiguration, TicRepeater};
use plm_core::st7570::status::Row;
use plm_core::st7570::validate::{self, Context};
use plm_core::st7570::{
    code, Address, Command, Credit, Demodulation, IsLocked, Layer, MacData, MacSync, RcHeard,
    SignalNoise, SpyAlarm, SpySubframe, Status, SyncEstimate,
};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::strategy::{BoxedStrategy, Union, ValueTree};
use proptest::test_runner::TestRunner;
use std::collections::HashSet;

/// Largest data field of an ST7570 local frame (Table 10).
const MAX_DATA: usize = 247;

fn bytes(max: usize) -> impl Strategy<Value = Vec<u8>> {
    vec(any::<u8>(), 0..=max)
}

fn u24() -> impl Strategy<Value = u32> {
    0u32..=0xFF_FFFF
}

fn sn() -> impl Strategy<Value = SignalNoise> {
    (u24(), u24(), u24(), u24()).prop_map(|(s0, n0, s1, n1)| SignalNoise { s0, n0, s1, n1 })
}

fn demodulation() -> impl Strategy<Value = Demodulation> {
    any::<(u16, u16, u16)>().prop_map(|(ask0, ask1, fsk)| Demodulation { ask0, ask1, fsk })
}

fn estimate() -> impl Strategy<Value = SyncEstimate> {
    (sn(), any::<u8>(), any::<u8>()).prop_map(|(sn, pga, phase)| SyncEstimate { sn, pga, phase })
}

fn mac_data() -> impl Strategy<Value = MacData> {
    (
        0u8..8,
        0u8..8,
        0u8..4,
        0u16..0x1000,
        0u16..0x1000,
        any::<u8>(),
        bytes(MAX_DATA - 5),
    )
        .prop_map(|(ic, cc, dc, sa, da, pad, m_sdu)| MacData {
            credit: Credit { ic, cc, dc },
            address: Address { sa, da },
            pad,
            m_sdu,
        })
}

fn p_sdu() -> impl Strategy<Value = [u8; 38]> {
    vec(any::<u8>(), 38).prop_map(|v| v.try_into().unwrap())
}

fn mac_sync() -> impl Strategy<Value = MacSync> {
    prop_oneof![
        estimate().prop_map(MacSync::Found),
        any::<(u8, u16, u16)>().prop_map(|(pad, sa, da)| MacSync::Confirmed { pad, sa, da }),
        any::<(u8, u16, u16)>().prop_map(|(cause, add1, add2)| MacSync::Lost { cause, add1, add2 }),
        any::<(u8, u16, u16)>().prop_map(|(cause, add, s)| MacSync::Intelligent { cause, add, s }),
        (
            any::<u8>().prop_filter("undefined SYNC", |s| ![1, 2, 4, 5].contains(s)),
            bytes(MAX_DATA - 1)
        )
            .prop_map(|(sync, data)| MacSync::Other { sync, data }),
    ]
}

/// One strategy per variant that `layer` parses to.
fn arms(layer: Layer) -> Vec<BoxedStrategy<Command>> {
    use Command::*;
    let mut arms = vec![
        any::<u8>()
            .prop_map(|reset| DesynchroRequest { reset })
            .boxed(),
        Just(SynchroStatusRequest).boxed(),
        any::<u8>()
            .prop_map(|status| SynchroStatus { status })
            .boxed(),
        any::<u8>().prop_map(|reset| ResetRequest { reset }).boxed(),
        (any::<u16>(), bytes(MAX_DATA - 2))
            .prop_map(|(index, data)| WriteDbRequest { index, data })
            .boxed(),
        (any::<u16>(), bytes(MAX_DATA - 2))
            .prop_map(|(index, data)| WriteDbConfirm { index, data })
            .boxed(),
        any::<u8>().prop_map(|error| WriteDbError { error }).boxed(),
        any::<u16>()
            .prop_map(|index| ReadDbRequest { index })
            .boxed(),
        (any::<u16>(), bytes(MAX_DATA - 2))
            .prop_map(|(index, data)| ReadDbConfirm { index, data })
            .boxed(),
        any::<u8>().prop_map(|error| ReadDbError { error }).boxed(),
        any::<u8>()
            .prop_map(|confirm_code| DataConfirm { confirm_code })
            .boxed(),
        Just(AlarmRequest).boxed(),
        any::<u8>()
            .prop_map(|confirm_code| AlarmConfirm { confirm_code })
            .boxed(),
        (any::<u32>(), proptest::option::of((sn(), any::<u8>())))
            .prop_map(|(cnt, long)| AlarmIndication { cnt, long })
            .boxed(),
        (sn(), vec(any::<u8>(), 58))
            .prop_map(|(sn, pad)| SpyNoSubframeIndication { sn, pad })
            .boxed(),
        (sn(), demodulation(), any::<u8>(), p_sdu(), u24(), u24())
            .prop_map(|(sn, demodulation, pga, p_sdu, snr0, snr1)| {
                SpySubframeIndication(SpySubframe {
                    sn,
                    demodulation,
                    pga,
                    p_sdu,
                    snr0,
                    snr1,
                })
            })
            .boxed(),
        Just(SpySearchSynchroIndication).boxed(),
        (sn(), demodulation(), any::<u8>())
            .prop_map(|(sn, demodulation, pga)| SpySynchroFoundIndication {
                sn,
                demodulation,
                pga,
            })
            .boxed(),
        (sn(), any::<[u8; 7]>(), u24())
            .prop_map(|(sn, pad, alarm)| SpyNoAlarmIndication(SpyAlarm { sn, pad, alarm }))
            .boxed(),
        (sn(), any::<[u8; 7]>(), u24())
            .prop_map(|(sn, pad, alarm)| SpyAlarmIndication(SpyAlarm { sn, pad, alarm }))
            .boxed(),
        any::<(u16, u16)>()
            .prop_map(|(tx_pos, rc_threshold)| RcRequest {
                tx_pos,
                rc_threshold,
            })
            .boxed(),
        (
            any::<u8>(),
            any::<u8>(),
            proptest::option::of((u24(), u24(), any::<u16>())),
        )
            .prop_map(|(result, repeater_state, heard)| RcConfirm {
                result,
                repeater_state,
                heard: heard.map(|(s, n, rx_pos)| RcHeard { s, n, rx_pos }),
            })
            .boxed(),
        (any::<u8>(), proptest::option::of(any::<(u16, u16)>()))
            .prop_map(|(is_status, locked)| IsIndication {
                is_status,
                locked: locked.map(|(add, s)| IsLocked { add, s }),
            })
            .boxed(),
        any::<u8>().prop_map(|error| SyntaxError { error }).boxed(),
        (
            any::<u8>().prop_filter("not in Table 15", |c| code::lookup(*c).is_none()),
            bytes(MAX_DATA),
        )
            .prop_map(|(code, data)| Unknown { code, data })
            .boxed(),
    ];
    arms.extend(match layer {
        Layer::Phy => vec![
            estimate().prop_map(PhySynchroIndication).boxed(),
            (p_sdu(), demodulation(), u24(), u24())
                .prop_map(|(p_sdu, demodulation, snr0, snr1)| {
                    Command::PhyDataIndication(plm_core::st7570::PhyDataIndication {
                        p_sdu,
                        demodulation,
                        snr0,
                        snr1,
                    })
                })
                .boxed(),
            bytes(MAX_DATA)
                .prop_map(|p_sdu| PhyDataRequest { p_sdu })
                .boxed(),
        ],
        Layer::Mac => vec![
            mac_sync().prop_map(MacSynchroIndication).boxed(),
            mac_data().prop_map(MacDataIndication).boxed(),
            mac_data().prop_map(MacDataRequest).boxed(),
        ],
    });
    arms
}

#[test]
fn the_strategies_cover_every_code_of_table_15_in_both_layers() {
    let mut runner = TestRunner::deterministic();
    for layer in [Layer::Phy, Layer::Mac] {
        let codes: HashSet<u8> = arms(layer)
            .into_iter()
            .map(|arm| arm.new_tree(&mut runner).unwrap().current().code())
            .collect();
        for c in code::ALL {
            assert!(codes.contains(&c.code), "{} in {layer:?}", c.name);
        }
    }
}

/// Data of the lengths the tables give (so that fixed-length layouts are
/// reached), or of any length.
fn table_lengths() -> impl Strategy<Value = Vec<u8>> {
    let lengths = vec![0usize, 1, 2, 4, 5, 6, 10, 14, 15, 17, 19, 22, 50, 63, 70];
    prop_oneof![
        select(lengths).prop_flat_map(|n| vec(any::<u8>(), n)),
        bytes(MAX_DATA),
    ]
}

fn round_trip(cmd: &Command, layer: Layer) -> Result<(), TestCaseError> {
    let bytes = cmd.to_frame().emit(Dialect::St7570).expect("fits a frame");
    let frame = Frame::new_checked(&bytes[..], Dialect::St7570).unwrap();
    prop_assert!(frame.checksum_ok());
    let back = Command::parse(frame.code(), frame.data(), layer);
    prop_assert_eq!(back.as_ref(), Ok(cmd), "{:02x?}", bytes);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn every_phy_command_survives_emit_and_parse(cmd in Union::new(arms(Layer::Phy))) {
        round_trip(&cmd, Layer::Phy)?;
    }

    #[test]
    fn every_mac_command_survives_emit_and_parse(cmd in Union::new(arms(Layer::Mac))) {
        round_trip(&cmd, Layer::Mac)?;
    }

    /// Arbitrary data never panics a parser, a layout or the chip's checks,
    /// and whatever parses emits exactly the data it came from.
    #[test]
    fn arbitrary_data_never_panics_and_parses_losslessly(
        code in prop_oneof![select(code::ALL.iter().map(|c| c.code).collect::<Vec<_>>()), any::<u8>()],
        data in table_lengths(),
        mac in any::<bool>(),
        from_modem in any::<bool>(),
        mode in any::<u8>(),
    ) {
        let layer = if mac { Layer::Mac } else { Layer::Phy };
        let from = if from_modem { Source::Modem } else { Source::Host };
        if let Ok(cmd) = Command::parse(code, &data, layer) {
            prop_assert_eq!(cmd.code(), code);
            prop_assert_eq!(cmd.data(), data.clone());
            let ctx = Context { layer, mode, ..Context::default() };
            let _ = validate::check_request(&cmd, &ctx);
        }
        for (f, _) in plm_core::st7570::describe(code, layer, from, &data) {
            prop_assert!(f.end() <= data.len() || f.size == 0, "{} read past the data", f.name);
        }
    }

    #[test]
    fn arbitrary_mib_requests_never_panic(index in prop_oneof![0u16..0x100, any::<u16>()], data in bytes(20),
                                          mac in any::<bool>(), mode in any::<u8>()) {
        let layer = if mac { Layer::Mac } else { Layer::Phy };
        let ctx = Context { layer, mode, fima: 0, lima: 0xFFF };
        let _ = validate::check_write(index, &data, &ctx);
        let _ = validate::check_read(index, &ctx);
        let _ = PlcConfiguration::decode(&data);
    }

    /// Every status message reads and emits back to the same bytes (bits in
    /// a row's fixed-0 cells are kept), and the value survives emit/parse.
    #[test]
    fn every_status_message_survives_parse_and_emit(b in any::<[u8; 3]>()) {
        let s = Status::parse(&b).expect("3 bytes");
        prop_assert_eq!(s.emit(), b);
        prop_assert_eq!(Status::parse(&s.emit()), Some(s));
        prop_assert_eq!(Status::from_message(&s.to_message()), Some(s));
        prop_assert_eq!(s.stray.iter().zip(s.row().mask()).all(|(x, m)| x & m == 0), true);
    }

    #[test]
    fn status_of_any_other_length_is_refused(data in bytes(8)) {
        prop_assume!(data.len() != 3);
        prop_assert_eq!(Status::parse(&data), None);
    }

    /// Every MIB object's value, every settable field set to a value its
    /// range allows: the chip's checks accept it and its fields read back
    /// as set.
    #[test]
    fn every_mib_value_survives_encode_and_decode(
        i in 0..mib::OBJECTS.len(),
        picks in vec(any::<u64>(), 16),
    ) {
        let o = &mib::OBJECTS[i];
        let mut data = vec![0u8; o.len];
        let mut set = Vec::new();
        for (f, pick) in o.fields.iter().zip(&picks) {
            let value = match f.kind {
                Kind::Bytes => continue,
                Kind::Enum(names) => {
                    let defined: Vec<usize> = (0..names.len()).filter(|i| !names[*i].is_empty()).collect();
                    defined[(*pick as usize) % defined.len()] as i64
                }
                _ if !f.settable || f.max == f.min => f.min,
                _ => f.min + (*pick % (f.max - f.min + 1) as u64) as i64,
            };
            f.set(&mut data, value);
            set.push((f, value));
        }
        prop_assert!(o.check_value(&data).is_ok(), "{}: {:?}", o.name, o.check_value(&data));
        for (f, value) in set {
            prop_assert_eq!(f.get(&data), Some(value), "{}.{}", o.name, f.name);
        }
        if o.index == mib::index::PLC_CONFIGURATION {
            prop_assert_eq!(PlcConfiguration::decode(&data).encode(), data.clone());
        }
        if o.index == mib::index::TIC_REPEATER {
            prop_assert_eq!(TicRepeater::from_byte(data[0]).byte(), data[0]);
        }
        // Written as the value (or as its write layout's zeros) in a layer
        // and mode that may write it, the chip accepts it.
        if o.access.write {
            let layer = if o.scope.mac { Layer::Mac } else { Layer::Phy };
            let mode = (0..8).find(|m| o.scope.write_modes & (1 << m) != 0).unwrap();
            let ctx = Context { layer, mode, fima: 0, lima: 0xFFF };
            let written = if o.write.is_some() { vec![0u8; o.write_len()] } else { data.clone() };
            prop_assert!(validate::check_write(o.index, &written, &ctx).is_ok(),
                         "{}: {:?}", o.name, validate::check_write(o.index, &written, &ctx));
        }
    }
}

#[test]
fn every_row_of_table_11_is_reached_by_byte_1() {
    let rows: HashSet<Row> = (0..=255u8).map(Row::of).collect();
    assert_eq!(rows.len(), Row::ALL.len());
}
