//! Property tests of the stream decoder (docs/architecture.md "Testing"):
//! arbitrary bytes never panic it, nothing is lost or invented, chunking
//! does not matter, and it resynchronises on every valid frame after
//! garbage.

use plm_core::decode::{self, Decoder};
use plm_core::link::{Dialect, Element, Frame, GarbageReason, LocalFrame, Source, StreamDecoder};
use proptest::collection::vec;
use proptest::prelude::*;

fn dialect() -> impl Strategy<Value = Dialect> {
    prop_oneof![Just(Dialect::St7580), Just(Dialect::St7570)]
}

fn source() -> impl Strategy<Value = Source> {
    prop_oneof![Just(Source::Host), Just(Source::Modem), Just(Source::Any)]
}

/// A valid frame of `dialect`: any code, a data field it can carry (mostly
/// short, sometimes up to the maximum).
fn local_frame(dialect: Dialect) -> impl Strategy<Value = LocalFrame> {
    let max = dialect.max_data();
    (
        any::<u8>(),
        prop_oneof![4 => vec(any::<u8>(), 0..=12), 1 => vec(any::<u8>(), 0..=max)],
    )
        .prop_map(|(code, data)| LocalFrame::new(code, data))
}

fn frame_bytes(dialect: Dialect) -> impl Strategy<Value = Vec<u8>> {
    local_frame(dialect).prop_map(move |f| f.emit(dialect).expect("data fits"))
}

/// Bytes that look like the things a host interface carries, and their
/// near misses: random bytes, STX/ACK/NAK/`?` bytes, valid frames, frames
/// with a broken checksum or a changed byte, and cut-off frames.
fn noise(dialect: Dialect) -> impl Strategy<Value = Vec<u8>> {
    let segment = prop_oneof![
        3 => vec(any::<u8>(), 1..8),
        2 => vec(prop_oneof![Just(0x02u8), Just(0x03), Just(0x06), Just(0x15), Just(0x3F)], 1..4),
        1 => (prop_oneof![Just(0x02u8), Just(0x03)], any::<u8>()).prop_map(|(s, l)| vec![s, l]),
        1 => frame_bytes(dialect),
        1 => (frame_bytes(dialect), any::<prop::sample::Index>(), 1u8..=255).prop_map(
            |(mut f, i, x)| {
                let i = i.index(f.len());
                f[i] ^= x;
                f
            }
        ),
        1 => (frame_bytes(dialect), any::<prop::sample::Index>()).prop_map(|(f, i)| {
            let cut = 1 + i.index(f.len() - 1);
            f[..cut].to_vec()
        }),
    ];
    vec(segment, 0..12).prop_map(|s| s.concat())
}

/// Input for the "never panics" properties: sometimes plain random bytes,
/// mostly structured noise (random bytes rarely form a frame).
fn input(dialect: Dialect) -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![1 => vec(any::<u8>(), 0..600), 3 => noise(dialect)]
}

fn setup() -> impl Strategy<Value = (Dialect, Source, Vec<u8>)> {
    (dialect(), source()).prop_flat_map(|(d, s)| (Just(d), Just(s), input(d)))
}

/// Decodes pushing `bytes` in chunks of the given sizes (cycled), with an
/// empty push between chunks, taking elements as they become available.
fn decode_chunked(dialect: Dialect, source: Source, bytes: &[u8], sizes: &[usize]) -> Vec<Element> {
    let mut d = StreamDecoder::new(dialect, source);
    let mut out = Vec::new();
    let mut rest = bytes;
    for size in sizes.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (chunk, tail) = rest.split_at((*size).min(rest.len()));
        d.push(chunk);
        d.push(&[]);
        out.extend(std::iter::from_fn(|| d.next()));
        rest = tail;
    }
    d.finish();
    out.extend(std::iter::from_fn(|| d.next()));
    out
}

fn wire(dialect: Dialect, elements: &[Element]) -> Vec<u8> {
    elements.iter().flat_map(|e| e.to_bytes(dialect)).collect()
}

/// Whether a frame with a right checksum starts somewhere in
/// `input[from..to]` and runs past `to`.
fn valid_frame_crossing(dialect: Dialect, input: &[u8], from: usize, to: usize) -> bool {
    (from..to).any(|i| {
        matches!(Frame::new_checked(&input[i..], dialect),
            Ok(f) if f.checksum_ok() && i + f.total_len() > to)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn nothing_is_lost_or_invented((dialect, source, bytes) in setup()) {
        let elements = StreamDecoder::decode_all(dialect, source, &bytes);
        prop_assert_eq!(wire(dialect, &elements), bytes);
        for (i, e) in elements.iter().enumerate() {
            match e {
                Element::Frame { checksum_ok, .. } => {
                    // The flag tells the truth about the bytes.
                    let b = e.to_bytes(dialect);
                    let f = Frame::new_checked(&b[..], dialect).expect("a whole frame");
                    prop_assert_eq!(f.total_len(), b.len());
                    prop_assert_eq!(f.checksum_ok(), *checksum_ok);
                }
                Element::Status(_) => {
                    prop_assert!(source != Source::Host, "the host sends no status");
                    prop_assert_eq!(e.to_bytes(dialect).len(), dialect.status_len());
                }
                Element::Garbage { bytes, reason } => {
                    prop_assert!(!bytes.is_empty());
                    if *reason == GarbageReason::Truncated {
                        prop_assert_eq!(i, elements.len() - 1, "only the end cuts a frame");
                        prop_assert!(dialect.is_stx(bytes[0]));
                    }
                    if let Some(Element::Garbage { reason: next, .. }) = elements.get(i + 1) {
                        // Runs of garbage are reported whole.
                        prop_assert_eq!(*reason, GarbageReason::Unexpected);
                        prop_assert_eq!(*next, GarbageReason::Truncated);
                    }
                }
                Element::Ack | Element::Nak => {}
            }
        }
    }

    #[test]
    fn chunking_does_not_change_the_elements(
        (dialect, source, bytes) in setup(),
        sizes in vec(1usize..40, 1..8),
    ) {
        let whole = StreamDecoder::decode_all(dialect, source, &bytes);
        prop_assert_eq!(decode_chunked(dialect, source, &bytes, &sizes), whole.clone());
        prop_assert_eq!(decode_chunked(dialect, source, &bytes, &[1]), whole);
    }

    #[test]
    fn the_json_decoder_takes_any_bytes((dialect, source, bytes) in setup(), sizes in vec(1usize..40, 1..8)) {
        let whole = decode::decode_all(dialect, source, &bytes);
        let elements = StreamDecoder::decode_all(dialect, source, &bytes);
        prop_assert_eq!(whole.len(), elements.len());
        let mut hex = String::new();
        for (d, e) in whole.iter().zip(&elements) {
            prop_assert_eq!(&d.kind, e.kind());
            hex.push_str(&d.hex);
        }
        prop_assert_eq!(hex, plm_core::hex::encode(&bytes));

        let mut dec = Decoder::new(dialect, source);
        let mut chunked = Vec::new();
        let mut rest = &bytes[..];
        for size in sizes.iter().cycle() {
            if rest.is_empty() {
                break;
            }
            let (chunk, tail) = rest.split_at((*size).min(rest.len()));
            dec.push(chunk);
            chunked.extend(std::iter::from_fn(|| dec.next()));
            rest = tail;
        }
        dec.finish();
        chunked.extend(std::iter::from_fn(|| dec.next()));
        prop_assert_eq!(chunked, whole);
    }

    #[test]
    fn a_valid_frame_alone_is_one_element(
        (dialect, source, frame) in (dialect(), source())
            .prop_flat_map(|(d, s)| (Just(d), Just(s), local_frame(d))),
    ) {
        let bytes = frame.emit(dialect).unwrap();
        let elements = StreamDecoder::decode_all(dialect, source, &bytes);
        prop_assert_eq!(elements.len(), 1);
        let checksum = u16::from_le_bytes([bytes[bytes.len() - 2], bytes[bytes.len() - 1]]);
        prop_assert_eq!(
            &elements[0],
            &Element::Frame { frame, checksum, checksum_ok: true }
        );
    }

    #[test]
    fn finds_a_valid_frame_after_arbitrary_garbage(
        (dialect, source, garbage, frame) in (dialect(), source()).prop_flat_map(|(d, s)| {
            (Just(d), Just(s), input(d), local_frame(d))
        }),
    ) {
        let mut bytes = garbage.clone();
        bytes.extend(frame.emit(dialect).unwrap());
        // The decoder cannot know where the garbage ends: it takes the
        // first frame with a right checksum it meets (stream.rs). If the
        // garbage itself holds such a frame and that frame runs into the
        // real one, the real frame's bytes are (rightly) part of it, and no
        // decoder without timing could tell. Random bytes make that a
        // 1-in-65536 coincidence per candidate; leave those inputs out.
        prop_assume!(!valid_frame_crossing(dialect, &bytes, 0, garbage.len()));
        let elements = StreamDecoder::decode_all(dialect, source, &bytes);
        let last = elements.last().expect("at least the frame");
        prop_assert!(
            matches!(last, Element::Frame { frame: f, checksum_ok: true, .. } if *f == frame),
            "last element {:?}, expected {:?}", last, frame
        );
        prop_assert_eq!(wire(dialect, &elements), bytes);
    }

    #[test]
    fn finds_every_valid_frame_between_garbage(
        (dialect, source, parts, tail) in (dialect(), source()).prop_flat_map(|(d, s)| {
            (
                Just(d),
                Just(s),
                vec((input(d), local_frame(d)), 1..5),
                input(d),
            )
        }),
    ) {
        let mut bytes = Vec::new();
        let mut garbage_ranges = Vec::new();
        let mut frames = Vec::new(); // (offset, frame)
        for (garbage, frame) in &parts {
            let from = bytes.len();
            bytes.extend(garbage);
            garbage_ranges.push((from, bytes.len()));
            frames.push((bytes.len(), frame.clone()));
            bytes.extend(frame.emit(dialect).unwrap());
        }
        bytes.extend(&tail);
        // As above: a valid frame that starts in a run of garbage and runs
        // into the next real frame hides it; leave such inputs out.
        for (from, to) in &garbage_ranges {
            prop_assume!(!valid_frame_crossing(dialect, &bytes, *from, *to));
        }
        let elements = StreamDecoder::decode_all(dialect, source, &bytes);
        prop_assert_eq!(wire(dialect, &elements), bytes.clone());
        // Where each element starts in the input.
        let mut at = 0;
        let mut found = Vec::new();
        for e in &elements {
            if let Element::Frame { frame, checksum_ok: true, .. } = e {
                found.push((at, frame.clone()));
            }
            at += e.to_bytes(dialect).len();
        }
        for f in &frames {
            prop_assert!(found.contains(f), "frame at {} not found in {:?}", f.0, elements);
        }
    }
}
