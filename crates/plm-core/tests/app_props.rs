//! Property tests of the STEVAL-IHP007V1 application layer (seed 004 UM
//! 4.6, Appendix A): every typed message, frame and line frame reads back
//! as itself; the USART stream decoder takes any bytes, loses none and
//! finds every good frame after garbage once the line went idle; the
//! requester and the concentrator (both carriers) take any input at any
//! time without panicking, and settle every request.

use plm_core::app::hid::{self, Hid};
use plm_core::app::rfu;
use plm_core::app::service::{Clock, Discovered, Release, Service, SlotRead};
use plm_core::app::{
    Address, AppEvent, AppFrame, Concentrator, ErrorCode, FrameError, FrameType, Happening,
    LineFrame, Message, Request, RequestId, Requester, RequesterConfig, UsartDecoder, UsartElement,
};
use plm_core::link::{Dialect, LocalFrame};
use plm_core::st7580::code as c;
use plm_core::st7580::{Channel, Command, DataIndication, IndicationInfo, Modulation, TxParams};
use plm_core::time::Instant;
use proptest::collection::vec;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// `USER_PAYLOAD_SIZE` (4.5).
const MAX_PAYLOAD: usize = 100;

/// The bare ST7580 concentrator's own address.
const ME: Address = Address([0, 0x80, 0xE1, 0, 0, 9]);

fn address() -> impl Strategy<Value = Address> {
    any::<[u8; 6]>().prop_map(Address)
}

/// A few boards, so that answers and requests meet.
fn board() -> impl Strategy<Value = Address> {
    (0u8..4).prop_map(|n| Address([0, 0x80, 0xE1, 0, 0, n]))
}

fn frame_type() -> impl Strategy<Value = FrameType> {
    any::<u8>().prop_map(FrameType::from_byte)
}

fn release() -> impl Strategy<Value = Release> {
    any::<(u8, u8)>().prop_map(|(major, minor)| Release { major, minor })
}

/// Any time of day the bytes can carry (ranges are checked by
/// `validate`, not by the parser).
fn clock() -> impl Strategy<Value = Clock> {
    any::<(u8, u8, u8)>().prop_map(|(hours, minutes, seconds)| Clock {
        hours,
        minutes,
        seconds,
    })
}

/// Every variant of [`Service`] (4.6.4).
fn service() -> impl Strategy<Value = Service> {
    use Service::*;
    let params = || vec(any::<u8>(), 32);
    let no_data = prop_oneof![
        Just(SoftwareReset),
        Just(HardwareReset),
        Just(InputsGet),
        Just(FwRelGet),
        Just(ClockGet),
        Just(IoConfigGet),
        Just(SnGet),
    ];
    let one_byte = prop_oneof![
        any::<u8>().prop_map(|group| ParamGet { group }),
        any::<u8>().prop_map(Inputs),
        any::<u8>().prop_map(OutputsSet),
        any::<u8>().prop_map(IoConfigSet),
        any::<u8>().prop_map(IoConfig),
        any::<u8>().prop_map(SnSet),
        any::<u8>().prop_map(Sn),
    ];
    let more = prop_oneof![
        (any::<u8>(), params()).prop_map(|(group, data)| ParamSet { group, data }),
        (any::<u8>(), params()).prop_map(|(group, data)| Params { group, data }),
        (release(), release()).prop_map(|(firmware, stack)| FwRel { firmware, stack }),
        clock().prop_map(ClockSet),
        clock().prop_map(ClockNow),
        any::<(u8, u8)>().prop_map(|(session, window)| Discover { session, window }),
        (release(), release(), any::<u8>()).prop_map(|(firmware, stack, snr)| {
            DiscoverReply(Discovered {
                firmware,
                stack,
                snr,
            })
        }),
        // Random addresses share no bytes: 15 fit in a request.
        (any::<(u8, u8, u8)>(), vec(address(), 0..=15)).prop_map(
            |((slot_ms, param, first_ms), addresses)| ReadInSlots(SlotRead {
                slot_ms,
                param,
                first_ms,
                addresses
            })
        ),
        // User commands this project does not know.
        (0x14u8..=0xFF, vec(any::<u8>(), 0..MAX_PAYLOAD))
            .prop_map(|(command, data)| Raw { command, data }),
    ];
    let rfu = prop_oneof![
        (any::<(u8, u32, u32, u8)>(), release()).prop_map(
            |((campaign, size, crc, segment), version)| RfuHeader(rfu::Header {
                campaign,
                size,
                version,
                crc,
                segment,
            })
        ),
        (any::<(u8, u16)>(), vec(any::<u8>(), 0..=rfu::SEGMENT)).prop_map(
            |((campaign, segment), data)| RfuData {
                campaign,
                segment,
                data
            }
        ),
        any::<(u8, u32)>().prop_map(|(campaign, crc)| RfuSwap { campaign, crc }),
        any::<u8>().prop_map(|campaign| RfuStatusGet { campaign }),
        any::<u8>().prop_map(|campaign| RfuAbort { campaign }),
        (
            any::<(u8, u8, u8, u16)>(),
            vec(any::<u8>(), rfu::BITMAP_LEN)
        )
            .prop_map(|((campaign, state, reason, received), bitmap)| RfuStatus(
                rfu::Status {
                    campaign,
                    state,
                    reason,
                    received,
                    bitmap,
                }
            )),
    ];
    prop_oneof![no_data, one_byte, more, rfu]
}

/// Every variant of [`Hid`] (Appendix A); replies carry a value of their
/// parameter's length (other lengths are user data).
fn hid() -> impl Strategy<Value = Hid> {
    prop_oneof![
        any::<u8>().prop_map(Hid::Reset),
        any::<u8>().prop_map(Hid::Dimming),
        any::<u8>().prop_map(Hid::Get),
        prop::sample::select(hid::PARAMS)
            .prop_flat_map(|p| (Just(p.code), vec(any::<u8>(), p.len)))
            .prop_map(|(param, value)| Hid::Reply { param, value }),
    ]
}

/// Every variant of [`Message`], each with a payload that fits a frame.
fn message() -> impl Strategy<Value = Message> {
    let bytes = || vec(any::<u8>(), 0..MAX_PAYLOAD);
    prop_oneof![
        hid().prop_map(Message::Hid),
        // User data that is no HID command: a HID-shaped payload reads as HID.
        vec(any::<u8>(), 1..=MAX_PAYLOAD)
            .prop_filter("not HID", |d| Hid::parse(d).is_none())
            .prop_map(Message::Data),
        service().prop_map(Message::Service),
        Just(Message::Ping),
        (frame_type(), any::<u8>())
            .prop_map(|(frame_type, echo)| Message::Ack { frame_type, echo }),
        any::<u16>().prop_map(|e| Message::Error(ErrorCode(e))),
        (any::<u8>(), bytes()).prop_map(|(group, data)| Message::Programming { group, data }),
        (any::<u8>(), bytes()).prop_map(|(index, data)| Message::Mib { index, data }),
        (7u8..=0x7F, vec(any::<u8>(), 0..=MAX_PAYLOAD)).prop_map(|(frame_type, payload)| {
            Message::Unknown {
                frame_type,
                payload,
            }
        }),
    ]
}

fn app_frame() -> impl Strategy<Value = AppFrame> {
    (
        frame_type(),
        any::<bool>(),
        address(),
        vec(any::<u8>(), 0..=MAX_PAYLOAD),
    )
        .prop_map(|(frame_type, broadcast, address, payload)| AppFrame {
            frame_type,
            broadcast,
            address,
            payload,
        })
}

fn line_frame() -> impl Strategy<Value = LineFrame> {
    (
        frame_type(),
        any::<bool>(),
        address(),
        address(),
        vec(any::<u8>(), 0..=MAX_PAYLOAD),
    )
        .prop_map(
            |(frame_type, broadcast, destination, source, payload)| LineFrame {
                frame_type,
                broadcast,
                destination,
                source,
                payload,
            },
        )
}

/// A frame from one of the few boards, as a board would send it.
fn board_frame() -> impl Strategy<Value = AppFrame> {
    (message(), board(), any::<bool>()).prop_map(
        |(m, a, b)| {
            if b {
                m.broadcast(a)
            } else {
                m.to(a)
            }
        },
    )
}

fn good_bytes() -> impl Strategy<Value = Vec<u8>> {
    app_frame().prop_map(|f| f.emit().expect("payload fits"))
}

/// Bytes like those a board USART carries, and their near misses: random
/// bytes, length-like bytes, good frames, frames with a changed byte, cut
/// frames.
fn usart_noise() -> impl Strategy<Value = Vec<u8>> {
    let segment = prop_oneof![
        3 => vec(any::<u8>(), 1..8),
        2 => vec(10u8..=110, 1..4),
        2 => good_bytes(),
        1 => (good_bytes(), any::<prop::sample::Index>(), 1u8..=255).prop_map(|(mut f, i, x)| {
            let i = i.index(f.len());
            f[i] ^= x;
            f
        }),
        1 => (good_bytes(), any::<prop::sample::Index>()).prop_map(|(f, i)| {
            let cut = 1 + i.index(f.len() - 1);
            f[..cut].to_vec()
        }),
    ];
    vec(segment, 0..10).prop_map(|s| s.concat())
}

fn usart_input() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![1 => vec(any::<u8>(), 0..400), 3 => usart_noise()]
}

fn bytes_of(elements: &[UsartElement]) -> Vec<u8> {
    elements.iter().flat_map(|e| e.bytes().to_vec()).collect()
}

/// Decodes pushing `bytes` in chunks of the given sizes (cycled), taking
/// elements as they come, then the line goes idle.
fn decode_chunked(bytes: &[u8], sizes: &[usize]) -> Vec<UsartElement> {
    let mut d = UsartDecoder::new();
    let mut out = Vec::new();
    let mut rest = bytes;
    for size in sizes.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (chunk, tail) = rest.split_at((*size).min(rest.len()));
        d.push(chunk);
        out.extend(std::iter::from_fn(|| d.next()));
        rest = tail;
    }
    d.idle();
    out.extend(std::iter::from_fn(|| d.next()));
    out
}

/// What happens to a requester or concentrator, in order.
#[derive(Debug, Clone)]
enum Op {
    /// A request from the host.
    Submit(Request),
    /// Time passes (any amount, deadlines or not), then `handle_timeout`.
    Wait(u64),
    /// A frame from a board (requester), or bytes from the port
    /// (concentrator).
    Frame(AppFrame),
    /// Bytes from the port (the concentrator's carrier).
    Bytes(Vec<u8>),
}

fn request() -> impl Strategy<Value = Request> {
    prop_oneof![
        4 => (board(), message()).prop_map(|(a, m)| Request::to(a, m)),
        1 => message().prop_map(Request::all),
    ]
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        3 => request().prop_map(Op::Submit),
        3 => prop_oneof![0u64..2_000, 0u64..5_000_000].prop_map(Op::Wait),
        3 => board_frame().prop_map(Op::Frame),
        1 => vec(any::<u8>(), 0..40).prop_map(Op::Bytes),
    ]
}

fn config() -> impl Strategy<Value = RequesterConfig> {
    (1u64..3_000_000, 1u8..4, 1usize..6).prop_map(|(timeout, max_attempts, max_in_flight)| {
        RequesterConfig {
            timeout,
            max_attempts,
            max_in_flight,
        }
    })
}

/// Final events by request: each request must end exactly once.
#[derive(Default)]
struct Fates(BTreeMap<RequestId, u32>);

impl Fates {
    fn see(&mut self, e: &AppEvent) {
        if let AppEvent::Answered { id, .. } | AppEvent::Sent { id } | AppEvent::Failed { id, .. } =
            e
        {
            *self.0.entry(*id).or_default() += 1;
        }
    }

    fn check(&self, submitted: &[RequestId]) -> Result<(), TestCaseError> {
        for id in submitted {
            prop_assert_eq!(self.0.get(id).copied(), Some(1), "{:?} ends once", id);
        }
        prop_assert_eq!(self.0.len(), submitted.len());
        Ok(())
    }
}

/// An ST7580 frame as the modem sends it: a DL_DataIndication carrying a
/// line frame (for us or not), or any code with any data.
fn modem_bytes(me: Address) -> impl Strategy<Value = Vec<u8>> {
    let indication =
        (board_frame(), any::<bool>(), any::<u8>()).prop_map(move |(f, to_me, snr)| {
            let mut line = LineFrame::from_app(&f, f.address);
            if to_me {
                line.destination = me;
            }
            Command::DlDataIndication(DataIndication {
                info: IndicationInfo {
                    modulation: Modulation::BPsk,
                    rx_channel: Channel::High,
                    pga: 3,
                    snr,
                    zc_delay: 0,
                },
                payload: line.emit(),
            })
            .to_frame()
            .emit(Dialect::St7580)
            .expect("fits")
        });
    let any_frame = (
        prop_oneof![
            Just(c::DL_DATA_CONFIRM),
            Just(c::DL_DATA_ERROR),
            Just(c::DL_DATA_INDICATION),
            Just(c::DL_SNIFFER_INDICATION),
            any::<u8>()
        ],
        vec(any::<u8>(), 0..30),
    )
        .prop_map(|(code, data)| LocalFrame::new(code, data).emit(Dialect::St7580).unwrap());
    prop_oneof![
        3 => indication,
        2 => any_frame,
        // ACK, NAK and status messages (UM0932 3.2.3, 3.2.4).
        2 => vec(prop_oneof![Just(0x06u8), Just(0x15), Just(0x3F), any::<u8>()], 1..4),
        1 => vec(any::<u8>(), 1..20),
    ]
}

/// Runs `ops` on a concentrator, then lets time run until nothing is due;
/// every request ends exactly once.
fn run_concentrator(
    mut k: Concentrator,
    ops: Vec<Op>,
    modem: Option<Vec<Vec<u8>>>,
) -> Result<(), TestCaseError> {
    let mut now: Instant = 0;
    let mut submitted = Vec::new();
    let mut fates = Fates::default();
    let mut modem = modem.unwrap_or_default().into_iter();
    let drain = |k: &mut Concentrator, fates: &mut Fates| {
        while k.poll_transmit().is_some() {}
        while let Some(h) = k.poll_happening() {
            if let Happening::App(e) = &h {
                fates.see(e);
            }
        }
    };
    for op in ops {
        match op {
            Op::Submit(r) => submitted.push(k.submit(now, r)),
            Op::Wait(dt) => {
                now += dt;
                k.handle_timeout(now);
            }
            Op::Frame(f) => match modem.next() {
                // Over a modem, a frame op is an ST7580 frame from the modem.
                Some(b) => k.handle_rx(now, &b),
                None => k.handle_rx(now, &f.emit().expect("fits")),
            },
            Op::Bytes(b) => k.handle_rx(now, &b),
        }
        drain(&mut k, &mut fates);
    }
    let mut rounds = 0;
    while let Some(t) = k.poll_timeout() {
        rounds += 1;
        prop_assert!(rounds < 10_000, "the concentrator keeps asking for time");
        now = now.max(t);
        k.handle_timeout(now);
        drain(&mut k, &mut fates);
    }
    prop_assert_eq!(k.requester().pending(), 0);
    fates.check(&submitted)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn every_message_reads_back_as_itself(m in message(), a in address(), broadcast in any::<bool>()) {
        prop_assert_eq!(Message::parse(m.frame_type(), &m.payload()), Ok(m.clone()));
        let frame = if broadcast { m.broadcast(a) } else { m.to(a) };
        let bytes = frame.emit().expect("payload fits");
        prop_assert_eq!(bytes[0] as usize, bytes.len());
        let back = AppFrame::parse(&bytes).expect("a good frame");
        prop_assert_eq!(&back, &frame);
        prop_assert_eq!(Message::of(&back), Ok(m));
    }

    #[test]
    fn every_service_reads_back_as_itself(s in service()) {
        prop_assert_eq!(Service::parse(&s.payload()), Ok(s));
    }

    #[test]
    fn every_hid_command_reads_back_as_itself(h in hid()) {
        prop_assert_eq!(Hid::parse(&h.payload()), Some(h));
    }

    #[test]
    fn every_app_frame_reads_back_as_itself(f in app_frame()) {
        let bytes = f.emit().expect("payload fits");
        prop_assert_eq!(bytes.len(), 10 + f.payload.len());
        prop_assert_eq!(AppFrame::parse(&bytes), Ok(f.clone()));
        // A changed byte is always caught (CRC-16 finds every burst of up
        // to 16 bits, Appendix C), as a wrong CRC or a wrong length.
        let mut bad = bytes.clone();
        let i = bytes.len() / 2;
        bad[i] ^= 0x5A;
        prop_assert!(AppFrame::parse(&bad).is_err());
        let too_long = AppFrame { payload: vec![0; MAX_PAYLOAD + 1], ..f };
        prop_assert_eq!(too_long.emit(), Err(FrameError::TooLong(MAX_PAYLOAD + 1)));
    }

    #[test]
    fn every_line_frame_reads_back_as_itself(l in line_frame()) {
        prop_assert_eq!(LineFrame::parse(&l.emit()), Some(l.clone()));
        let app = l.to_app();
        prop_assert_eq!(app.address, l.source);
        prop_assert_eq!(&app.payload, &l.payload);
    }

    #[test]
    fn the_usart_decoder_takes_any_bytes_and_loses_none(
        bytes in usart_input(),
        sizes in vec(1usize..40, 1..8),
    ) {
        let whole = UsartDecoder::decode_all(&bytes);
        prop_assert_eq!(bytes_of(&whole), bytes.clone());
        for e in &whole {
            match e {
                UsartElement::Frame { frame, bytes } => {
                    prop_assert_eq!(AppFrame::parse(bytes), Ok(frame.clone()));
                }
                UsartElement::BadCrc { frame, bytes } => {
                    let bad_crc = matches!(AppFrame::parse(bytes), Err(FrameError::BadCrc { .. }));
                    prop_assert!(bad_crc);
                    prop_assert_eq!(&AppFrame::parse_unchecked(bytes).unwrap().0, frame);
                }
                UsartElement::Garbage(b) => prop_assert!(!b.is_empty()),
            }
        }
        // How the bytes arrive does not change what is found.
        prop_assert_eq!(decode_chunked(&bytes, &sizes), whole.clone());
        prop_assert_eq!(decode_chunked(&bytes, &[1]), whole);
    }

    #[test]
    fn every_good_frame_after_garbage_and_an_idle_line_is_found(
        garbage in usart_input(),
        frames in vec(app_frame(), 1..5),
        sizes in vec(1usize..40, 1..8),
    ) {
        let mut d = UsartDecoder::new();
        d.push(&garbage);
        d.idle();
        let before: Vec<UsartElement> = std::iter::from_fn(|| d.next()).collect();
        prop_assert_eq!(bytes_of(&before), garbage);
        prop_assert!(!d.is_partial());
        let wire: Vec<u8> = frames.iter().flat_map(|f| f.emit().unwrap()).collect();
        let mut rest = &wire[..];
        let mut after = Vec::new();
        for size in sizes.iter().cycle() {
            if rest.is_empty() {
                break;
            }
            let (chunk, tail) = rest.split_at((*size).min(rest.len()));
            d.push(chunk);
            after.extend(std::iter::from_fn(|| d.next()));
            rest = tail;
        }
        d.idle();
        after.extend(std::iter::from_fn(|| d.next()));
        let found: Vec<AppFrame> = after
            .iter()
            .filter_map(|e| match e {
                UsartElement::Frame { frame, .. } => Some(frame.clone()),
                _ => None,
            })
            .collect();
        prop_assert_eq!(after.len(), frames.len(), "{:?}", after);
        prop_assert_eq!(found, frames);
    }

    #[test]
    fn the_requester_takes_anything_at_any_time_and_ends_every_request(
        cfg in config(),
        ops in vec(op(), 0..40),
    ) {
        let mut r = Requester::new(cfg);
        let mut now: Instant = 0;
        let mut submitted = Vec::new();
        let mut fates = Fates::default();
        let drain = |r: &mut Requester, fates: &mut Fates| {
            while let Some(f) = r.poll_send() {
                prop_assert!(f.emit().is_ok());
            }
            while let Some(e) = r.poll_event() {
                fates.see(&e);
            }
            Ok(())
        };
        for op in ops {
            match op {
                Op::Submit(req) => submitted.push(r.submit(now, req)),
                Op::Wait(dt) => {
                    now += dt;
                    r.handle_timeout(now);
                }
                Op::Frame(f) => r.handle_frame(now, &f),
                Op::Bytes(b) => {
                    // Whatever frame the bytes make, from any address.
                    if let Ok(f) = AppFrame::parse_unchecked(&b).map(|(f, _)| f) {
                        r.handle_frame(now, &f);
                    }
                }
            }
            drain(&mut r, &mut fates)?;
        }
        let mut rounds = 0;
        while let Some(t) = r.poll_timeout() {
            rounds += 1;
            prop_assert!(rounds < 10_000);
            now = now.max(t);
            r.handle_timeout(now);
            drain(&mut r, &mut fates)?;
        }
        prop_assert_eq!(r.pending(), 0);
        fates.check(&submitted)?;
    }

    #[test]
    fn a_usart_concentrator_takes_anything_at_any_time(
        cfg in config(),
        ops in vec(op(), 0..40),
    ) {
        run_concentrator(Concentrator::usart(cfg), ops, None)?;
    }

    #[test]
    fn a_modem_concentrator_takes_anything_at_any_time(
        cfg in config(),
        ops in vec(op(), 0..40),
        modem in vec(modem_bytes(ME), 40),
    ) {
        let k = Concentrator::modem(cfg, 57_600, ME, TxParams::default());
        run_concentrator(k, ops, Some(modem))?;
    }
}
