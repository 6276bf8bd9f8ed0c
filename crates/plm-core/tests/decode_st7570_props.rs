//! Property tests of the ST7570 decoder (`plm decode --chip st7570`):
//! arbitrary bytes, and streams of every command of Table 15 with data of
//! any length, status messages and MIB 00A1h frames that switch the
//! access layer, never panic it; nothing is lost; every frame says which
//! layer it was read in, the given layer whenever one is given; and every
//! element survives its JSON.

use plm_core::decode::{Decoded, Decoder};
use plm_core::link::{Dialect, LocalFrame, Source};
use plm_core::st7570::{code, Layer};
use proptest::collection::vec;
use proptest::prelude::*;

/// Data lengths of the forms of Table 15's commands, and any other.
fn data_len() -> impl Strategy<Value = usize> {
    prop_oneof![
        3 => prop::sample::select(vec![0usize, 1, 2, 4, 5, 6, 10, 14, 15, 16, 17, 19, 22, 50, 63, 70]),
        1 => 0usize..=Dialect::St7570.max_data(),
    ]
}

/// A frame of a Table 15 code (or any code), its data random but for
/// a SYNC or INDEX worth reading in front.
fn command_frame() -> impl Strategy<Value = Vec<u8>> {
    let codes: Vec<u8> = code::ALL.iter().map(|c| c.code).collect();
    (
        prop_oneof![6 => prop::sample::select(codes), 1 => any::<u8>()],
        data_len().prop_flat_map(|n| vec(any::<u8>(), n)),
        prop::sample::select(vec![0u8, 1, 2, 4, 5, 0xA1]),
    )
        .prop_map(|(code, mut data, first)| {
            if let Some(b) = data.first_mut() {
                *b = first;
            }
            frame(code, data)
        })
}

fn frame(code: u8, data: Vec<u8>) -> Vec<u8> {
    LocalFrame::new(code, data).emit(Dialect::St7570).unwrap()
}

/// MIB 00A1h written, confirmed or read back (Table 137), with an Access
/// layer mode of 1 (PHY), 2 (MAC) or a value the modem refuses.
fn plc_configuration() -> impl Strategy<Value = Vec<u8>> {
    (
        prop::sample::select(vec![0x41u8, 0x42, 0x91]),
        vec(any::<u8>(), 14),
        0u8..4,
    )
        .prop_map(|(code, mut value, layer)| {
            value[12] = layer;
            let mut data = vec![0xA1, 0x00];
            data.extend(value);
            frame(code, data)
        })
}

fn input() -> impl Strategy<Value = Vec<u8>> {
    let element = prop_oneof![
        4 => command_frame(),
        2 => vec(any::<u8>(), 3).prop_map(|s| [vec![0x3F], s].concat()),
        1 => plc_configuration(),
        1 => prop::sample::select(vec![vec![0x06u8], vec![0x15], vec![0x02], vec![0x3F]]),
        1 => vec(any::<u8>(), 1..6),
        1 => (command_frame(), any::<prop::sample::Index>()).prop_map(|(f, i)| {
            let cut = 1 + i.index(f.len() - 1);
            f[..cut].to_vec()
        }),
    ];
    prop_oneof![
        1 => vec(any::<u8>(), 0..600),
        4 => vec(element, 0..16).prop_map(|s| s.concat()),
    ]
}

fn source() -> impl Strategy<Value = Source> {
    prop_oneof![Just(Source::Host), Just(Source::Modem), Just(Source::Any)]
}

fn layer() -> impl Strategy<Value = Option<Layer>> {
    prop_oneof![Just(None), Just(Some(Layer::Phy)), Just(Some(Layer::Mac))]
}

fn run(source: Source, fixed: Option<Layer>, bytes: &[u8], chunk: usize) -> Vec<Decoded> {
    let mut d = Decoder::new(Dialect::St7570, source);
    if let Some(l) = fixed {
        d.fix_layer(l);
    }
    let mut out = Vec::new();
    for c in bytes.chunks(chunk) {
        d.push(c);
        out.extend(std::iter::from_fn(|| d.next()));
    }
    d.finish();
    out.extend(std::iter::from_fn(|| d.next()));
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn any_bytes_decode_without_panic_or_loss(
        source in source(),
        fixed in layer(),
        bytes in input(),
        chunk in 1usize..64,
    ) {
        let whole = run(source, fixed, &bytes, bytes.len().max(1));
        let hex: String = whole.iter().map(|d| d.hex.as_str()).collect();
        prop_assert_eq!(hex, plm_core::hex::encode(&bytes));
        for d in &whole {
            if d.kind == "frame" {
                let layer = d.layer.as_deref();
                prop_assert!(matches!(layer, Some("PHY" | "MAC")), "{:?}", d);
                if let Some(l) = fixed {
                    prop_assert_eq!(layer, Some(l.name()));
                }
                prop_assert!(d.fields.is_some());
            } else {
                prop_assert_eq!(&d.layer, &None);
            }
            prop_assert_eq!(&Decoded::from_json(&d.to_json()).unwrap(), d);
        }
        // How the bytes arrive changes nothing, the layer context included.
        prop_assert_eq!(run(source, fixed, &bytes, chunk), whole);
    }
}
