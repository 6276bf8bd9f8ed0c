//! The host and device link engines against each other, in virtual time,
//! byte by byte over a simulated UART (see `harness/mod.rs`), checked
//! against UM0932 3.2.5-3.2.9.

mod harness;

use harness::chip::{
    dl_indication as indication, ping, ping_confirm as confirm, ping_responder, DL_DATA_IND,
    PING_CNF, PING_REQ,
};
use harness::{
    check_lossy, first_wire, is_delivered, is_failed, is_repeat, is_retry, lossy_requests,
    statuses_sent, Dir, Fault, Part, Sim,
};
use plm_core::link::device::{DeviceEngine, DeviceEvent};
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Transmit, BUSY_LIMIT};
use plm_core::link::{
    Dialect, Element, GarbageReason, LocalFrame, Stx, TicSelector, Timeouts, ACK,
};
use plm_core::time::{wire_time, Instant, MS};
use proptest::prelude::*;

const BAUD: u32 = 57_600;
/// UM0932 Table 9 defaults.
const T_IC: u64 = 10 * MS;
const T_ACK: u64 = 40 * MS;
const T_SR: u64 = 200 * MS;

/// One byte time at `baud`.
fn b(baud: u32) -> u64 {
    wire_time(1, baud)
}

fn emit(f: &LocalFrame) -> Vec<u8> {
    f.emit(Dialect::St7580).unwrap()
}

// ---- 1. happy path: link_both.rs --------------------------------------------

// ---- 2. NAK -------------------------------------------------------------

// (The NAK that restarts the sequence: link_both.rs.)

// ---- 3. lost ACK ----------------------------------------------------------

// (A lost ACK restarting the sequence: link_both.rs.)

// ---- 4. T_SR --------------------------------------------------------------

#[test]
fn no_status_on_any_attempt_fails_with_no_status() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    sim.inject(Dir::DevToHost, None, Fault::Drop, |c| c.part.is_status());
    let ticket = sim.submit(ping());
    sim.run_to_idle();

    // Each attempt: T_REQ low for T_SR, then high for T_IC.
    let a2 = T_SR + T_IC;
    let a3 = 2 * (T_SR + T_IC);
    assert_eq!(
        sim.treq,
        vec![
            (0, true),
            (T_SR, false),
            (a2, true),
            (a2 + T_SR, false),
            (a3, true),
            (a3 + T_SR, false)
        ]
    );
    assert_eq!(
        sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_delivered(e)),
        vec![
            (
                T_SR,
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause: LinkError::NoStatus
                }
            ),
            (
                a2 + T_SR,
                Event::Retry {
                    ticket,
                    attempt: 2,
                    cause: LinkError::NoStatus
                }
            ),
            (a3 + T_SR, Event::Failed(ticket, LinkError::NoStatus)),
        ]
    );
    // The modem did answer every falling edge; the host never sent a byte.
    assert_eq!(statuses_sent(&sim), vec![0, a2, a3]);
    assert_eq!(sim.wire(Dir::HostToDev).count(), 0);
    assert!(sim.requests().is_empty());
    assert_eq!(sim.host.pending(), 0);
}

#[test]
fn modem_silent_for_a_while_then_delivered() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // Everything the modem sends in the first 300 ms is lost.
    sim.inject(Dir::DevToHost, None, Fault::Drop, |c| c.start < 300 * MS);
    let req = ping();
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();
    let e = sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_delivered(e));
    assert_eq!(e.len(), 3, "{e:?}");
    assert_eq!(
        e[0].1,
        Event::Retry {
            ticket,
            attempt: 1,
            cause: LinkError::NoStatus
        }
    );
    assert_eq!(
        e[1].1,
        Event::Retry {
            ticket,
            attempt: 2,
            cause: LinkError::NoStatus
        }
    );
    assert_eq!(e[2].1, Event::Delivered(ticket));
    assert_eq!(sim.requests(), vec![req.clone()]);
    assert_eq!(sim.host_frames(), vec![confirm(&req)]);
}

#[test]
fn device_ignores_a_frame_whose_stx_comes_after_t_sr() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // The host's first STX is held back past T_SR (the host's UART stalls,
    // the rest of the frame queues behind it).
    sim.inject(Dir::HostToDev, Some(1), Fault::Delay(T_SR + 5 * MS), |c| {
        c.part.is_frame_byte(0, 0)
    });
    let req = ping();
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    let status_end = wire_time(2, BAUD);
    let stx0 = sim.frame_bytes(Dir::HostToDev, 0)[0];
    assert!(stx0.at > status_end + T_SR, "the STX is late");
    // The late frame reached the device whole and right...
    let late = sim
        .dev_received()
        .into_iter()
        .find(|(_, e)| matches!(e, Element::Frame { .. }))
        .unwrap();
    assert_eq!(late.0, sim.frame_end(Dir::HostToDev, 0));
    assert!(matches!(
        late.1,
        Element::Frame {
            checksum_ok: true,
            ..
        }
    ));
    // ...and was ignored (UM0932 3.2.8): no ACK, no NAK, no request for
    // it; the next thing the modem sent is the status of the restart.
    let sent = sim.dev_sent();
    assert!(matches!(sent[0].1, Element::Status(_)));
    assert!(matches!(sent[1].1, Element::Status(_)), "{sent:?}");
    assert!(sent[1].0 >= late.0);
    let dev_requests = sim.dev_events_where(|e| matches!(e, DeviceEvent::Request(_)));
    assert_eq!(dev_requests.len(), 1);
    assert!(
        dev_requests[0].0 > sent[1].0,
        "the one request is the restarted frame"
    );
    assert_eq!(sim.requests(), vec![req]);

    // The host saw no ACK within T_ACK and restarted.
    let e = sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_delivered(e));
    assert_eq!(
        e.iter().map(|(_, e)| e.clone()).collect::<Vec<_>>(),
        vec![
            Event::Retry {
                ticket,
                attempt: 1,
                cause: LinkError::NoAck
            },
            Event::Delivered(ticket)
        ]
    );
}

// ---- 5. T_IC --------------------------------------------------------------

#[test]
fn gap_in_host_frame_is_dropped_by_device_and_host_retries() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    let req = indication_as_request();
    // A stall longer than T_IC before byte 4 of the host's first frame.
    sim.inject(Dir::HostToDev, Some(1), Fault::Delay(15 * MS), |c| {
        c.part.is_frame_byte(0, 4)
    });
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    let f0 = sim.frame_bytes(Dir::HostToDev, 0);
    // UM0932 3.2.6: T_IC after byte 3 the device drops what it has.
    let received = sim.dev_received();
    let first = emit(&req)[..4].to_vec();
    assert_eq!(
        received[0],
        (
            f0[3].at + T_IC,
            Element::Garbage {
                bytes: first,
                reason: GarbageReason::Truncated
            }
        )
    );
    // UM0932 3.2.8, "in other cases, it answers with a NAK": the frame
    // cut short is NAKed as T_IC ends it, and the host restarts at once
    // instead of waiting out T_ACK. Then the second status, the ACK of
    // the restarted frame and the confirm.
    let sent = sim.dev_sent();
    let kinds: Vec<&str> = sent.iter().map(|(_, e)| e.kind()).collect();
    assert_eq!(kinds, ["status", "nak", "status", "ack", "frame"]);
    assert_eq!(sent[1].0, f0[3].at + T_IC);
    assert_eq!(
        sim.dev_events_where(|e| *e == DeviceEvent::FrameCut).len(),
        1
    );
    let e = sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_delivered(e));
    assert_eq!(
        e.iter().map(|(_, e)| e.clone()).collect::<Vec<_>>(),
        vec![
            Event::Retry {
                ticket,
                attempt: 1,
                cause: LinkError::Nak
            },
            Event::Delivered(ticket)
        ]
    );
    assert_eq!(sim.requests(), vec![req]);
}

/// A request frame without 02h/03h/06h/15h after its STX.
fn indication_as_request() -> LocalFrame {
    LocalFrame::new(PING_REQ, vec![0x10, 0x20, 0x30, 0x40])
}

#[test]
fn gap_in_modem_frame_is_dropped_by_host_and_repeat_accepted() {
    let mut sim = Sim::with_baud(BAUD);
    let ind = indication();
    sim.inject(Dir::DevToHost, Some(1), Fault::Delay(15 * MS), |c| {
        c.part.is_frame_byte(0, 4)
    });
    sim.dev_submit(ind.clone());
    sim.run_to_idle();

    let f0 = sim.frame_bytes(Dir::DevToHost, 0);
    let garbage = sim.host_events_where(|e| matches!(e, Event::Received(Element::Garbage { .. })));
    assert_eq!(
        garbage[0],
        (
            f0[3].at + T_IC,
            Event::Received(Element::Garbage {
                bytes: emit(&ind)[..4].to_vec(),
                reason: GarbageReason::Truncated
            })
        )
    );
    // The host NAKs the frame cut short as T_IC ends it (3.2.7: "In other
    // cases, it answers with a NAK"), then ACKs the repeat.
    let repeat = sim.frame_bytes(Dir::DevToHost, 1);
    assert_eq!(repeat[0].sent, 0x03);
    let h2d: Vec<_> = sim
        .wire(Dir::HostToDev)
        .map(|w| (w.part, w.start))
        .collect();
    assert_eq!(
        h2d,
        vec![
            (Part::Nak, f0[3].at + T_IC),
            (Part::Ack, repeat.last().unwrap().at)
        ]
    );
    // The device repeated T_ACK after the frame as far as it knew (it does
    // not see its own UART stall).
    assert_eq!(repeat[0].start, wire_time(emit(&ind).len(), BAUD) + T_ACK);
    // The repeat is the frame, reported once.
    let repeated = LocalFrame {
        stx: Stx::Repeat,
        ..ind.clone()
    };
    assert_eq!(sim.host_frames(), vec![repeated]);
    assert!(sim.host_events_where(is_repeat).is_empty());
    // The repeat counts as delivered whatever the answer (3.2.7): the
    // device says so as it sends it.
    assert_eq!(
        sim.dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. })),
        vec![(
            repeat[0].start,
            DeviceEvent::Delivered {
                frame: ind,
                repeated: true
            }
        )]
    );
}

// ---- 6. STX 03h repeat ------------------------------------------------------

#[test]
fn lost_host_ack_gives_a_repeat_that_is_acked_but_not_reported_again() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // The host's ACK of the confirm is lost.
    sim.inject(Dir::HostToDev, Some(1), Fault::Drop, |c| {
        c.part == Part::Ack
    });
    let req = ping();
    let reply = confirm(&req);
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    assert_eq!(
        sim.host_events_where(|e| is_delivered(e) || is_failed(e) || is_retry(e))
            .into_iter()
            .map(|(_, e)| e)
            .collect::<Vec<_>>(),
        vec![Event::Delivered(ticket)]
    );
    let end0 = sim.frame_end(Dir::DevToHost, 0);
    let repeat = sim.frame_bytes(Dir::DevToHost, 1);
    assert_eq!(repeat[0].sent, 0x03);
    // UM0932 3.2.7: the repeat comes T_ACK after the frame, not before. The
    // confirm went out right behind the device's ACK of the ping.
    assert!(
        repeat[0].start >= end0 + T_ACK,
        "repeat at {} < {} + T_ACK",
        repeat[0].start,
        end0
    );
    assert!(
        repeat[0].start <= end0 + T_ACK + b(BAUD),
        "repeat late: {}",
        repeat[0].start
    );

    // Reported once as a frame, once as a repeat; both ACKed.
    let end1 = repeat.last().unwrap().at;
    assert_eq!(
        sim.host_events_where(|e| matches!(e, Event::Frame(_))),
        vec![(end0, Event::Frame(reply.clone()))]
    );
    let rep = LocalFrame {
        stx: Stx::Repeat,
        ..reply.clone()
    };
    assert_eq!(
        sim.host_events_where(is_repeat),
        vec![(end1, Event::Repeat(rep))]
    );
    let acks: Vec<_> = sim
        .wire(Dir::HostToDev)
        .filter(|w| w.part == Part::Ack)
        .map(|w| (w.start, w.got))
        .collect();
    assert_eq!(acks, vec![(end0, None), (end1, Some(ACK))]);
    assert_eq!(
        sim.dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. })),
        vec![(
            repeat[0].start,
            DeviceEvent::Delivered {
                frame: reply,
                repeated: true
            }
        )]
    );
    assert_eq!(sim.requests(), vec![req]);
}

#[test]
fn nak_of_a_modem_frame_makes_the_repeat_the_frame() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // A data byte of the confirm is damaged: the host NAKs it.
    sim.inject(Dir::DevToHost, Some(1), Fault::Corrupt(0x40), |c| {
        c.part.is_frame_byte(0, 3)
    });
    let req = ping();
    let reply = confirm(&req);
    sim.submit(req.clone());
    sim.run_to_idle();

    let end0 = sim.frame_end(Dir::DevToHost, 0);
    let bad = sim.host_events_where(|e| matches!(e, Event::Received(Element::Frame { .. })));
    assert!(
        matches!(bad[0], (t, Event::Received(Element::Frame { checksum_ok: false, .. })) if t == end0)
    );
    let h2d_after: Vec<_> = sim
        .wire(Dir::HostToDev)
        .filter(|w| w.start >= end0)
        .map(|w| (w.start, w.part))
        .collect();
    let repeat = sim.frame_bytes(Dir::DevToHost, 1);
    let end1 = repeat.last().unwrap().at;
    assert_eq!(h2d_after, vec![(end0, Part::Nak), (end1, Part::Ack)]);
    assert_eq!(repeat[0].sent, 0x03);
    assert!(repeat[0].start >= end0 + T_ACK && repeat[0].start <= end0 + T_ACK + b(BAUD));

    let rep = LocalFrame {
        stx: Stx::Repeat,
        ..reply.clone()
    };
    assert_eq!(
        sim.host_events_where(|e| matches!(e, Event::Frame(_))),
        vec![(end1, Event::Frame(rep))]
    );
    assert!(sim.host_events_where(is_repeat).is_empty());
    assert_eq!(
        sim.dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. })),
        vec![(
            repeat[0].start,
            DeviceEvent::Delivered {
                frame: reply,
                repeated: true
            }
        )]
    );
}

#[test]
fn the_ack_of_a_repeat_does_not_acknowledge_the_next_frame() {
    // Two indications queued in the modem. The host's ACK of the first is
    // lost, so the modem repeats it and then sends the second at once. The
    // host's ACK of the repeat reaches the modem while the second frame is
    // still on the wire: it cannot be the ACK of that frame. The second
    // frame is damaged on the line, the host NAKs it, and the modem must
    // repeat it (UM0932 3.2.7).
    let mut sim = Sim::with_baud(BAUD);
    let a = LocalFrame::new(DL_DATA_IND, vec![0x10, 0x11]);
    let b2 = LocalFrame::new(DL_DATA_IND, vec![0x20, 0x21]);
    sim.inject(Dir::HostToDev, Some(1), Fault::Drop, |c| {
        c.part == Part::Ack
    });
    sim.inject(Dir::DevToHost, Some(1), Fault::Corrupt(0x01), |c| {
        c.part.is_frame_byte(2, 3)
    });
    sim.dev_submit(a.clone());
    sim.dev_submit(b2.clone());
    sim.run_to_idle();

    let stx: Vec<u8> = (0..)
        .map_while(|n| sim.frame_bytes(Dir::DevToHost, n).first().map(|w| w.sent))
        .collect();
    assert_eq!(stx, [0x02, 0x03, 0x02, 0x03], "A, A again, B, B again");
    let rep_b = LocalFrame {
        stx: Stx::Repeat,
        ..b2.clone()
    };
    assert_eq!(sim.host_frames(), vec![a.clone(), rep_b]);
    assert_eq!(sim.host_events_where(is_repeat).len(), 1);
    let delivered: Vec<_> = sim
        .dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. }))
        .into_iter()
        .map(|(_, e)| e)
        .collect();
    assert_eq!(
        delivered,
        vec![
            DeviceEvent::Delivered {
                frame: a,
                repeated: true
            },
            DeviceEvent::Delivered {
                frame: b2,
                repeated: true
            }
        ]
    );
}

// ---- 7. a modem frame while the host waits for the status: link_both.rs ----

// ---- 8. MIB 09h timeouts ----------------------------------------------------

fn sim_with_timeouts(t: Timeouts) -> Sim {
    let mut sim = Sim::new(
        BAUD,
        HostConfig {
            timeouts: t,
            ..HostConfig::default()
        },
    )
    .responder(ping_responder());
    sim.dev.set_timeouts(t);
    sim
}

const SHORT: Timeouts = Timeouts::from_ms(100, 20, 5);

#[test]
fn shorter_t_ack_makes_the_host_retry_sooner() {
    let mut sim = sim_with_timeouts(SHORT);
    sim.inject(Dir::DevToHost, Some(1), Fault::Drop, |c| {
        c.part == Part::Ack
    });
    let ticket = sim.submit(ping());
    sim.run_to_idle();
    let end0 = sim.frame_end(Dir::HostToDev, 0);
    assert_eq!(
        sim.host_events_where(is_retry),
        vec![(
            end0 + 20 * MS,
            Event::Retry {
                ticket,
                attempt: 1,
                cause: LinkError::NoAck
            }
        )]
    );
    // ...and T_REQ falls again T_IC = 5 ms later.
    assert_eq!(sim.treq[2], (end0 + 25 * MS, true));
    assert_eq!(sim.host_events_where(is_delivered).len(), 1);
}

#[test]
fn shorter_t_ack_makes_the_device_repeat_sooner() {
    let mut sim = sim_with_timeouts(SHORT);
    sim.inject(Dir::HostToDev, Some(1), Fault::Drop, |c| {
        c.part == Part::Ack
    });
    sim.submit(ping());
    sim.run_to_idle();
    let end0 = sim.frame_end(Dir::DevToHost, 0);
    let start = sim.frame_start(Dir::DevToHost, 1);
    assert!(
        start >= end0 + 20 * MS && start <= end0 + 20 * MS + b(BAUD),
        "repeat at {start}, frame end {end0}"
    );
    assert_eq!(sim.host_events_where(is_repeat).len(), 1);
}

#[test]
fn shorter_t_sr_makes_the_host_give_up_waiting_sooner() {
    let mut sim = sim_with_timeouts(SHORT);
    sim.inject(Dir::DevToHost, None, Fault::Drop, |c| c.part.is_status());
    let ticket = sim.submit(ping());
    sim.run_to_idle();
    assert_eq!(
        sim.host_events_where(|e| is_retry(e) || is_failed(e)),
        vec![
            (
                100 * MS,
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause: LinkError::NoStatus
                }
            ),
            (
                205 * MS,
                Event::Retry {
                    ticket,
                    attempt: 2,
                    cause: LinkError::NoStatus
                }
            ),
            (310 * MS, Event::Failed(ticket, LinkError::NoStatus)),
        ]
    );
}

#[test]
fn shorter_t_ic_breaks_a_frame_the_default_tolerates() {
    let stall = |sim: &mut Sim| {
        sim.inject(Dir::HostToDev, Some(1), Fault::Delay(7 * MS), |c| {
            c.part.is_frame_byte(0, 4)
        })
    };
    // Default T_IC (10 ms): a 7 ms pause is fine.
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    stall(&mut sim);
    sim.submit(ping());
    sim.run_to_idle();
    assert!(sim.host_events_where(is_retry).is_empty());
    assert_eq!(sim.requests().len(), 1);
    // T_IC 5 ms: the same pause ends the frame.
    let mut sim = sim_with_timeouts(SHORT);
    stall(&mut sim);
    let ticket = sim.submit(ping());
    sim.run_to_idle();
    let f0 = sim.frame_bytes(Dir::HostToDev, 0);
    assert!(matches!(
        &sim.dev_received()[0],
        (t, Element::Garbage { reason: GarbageReason::Truncated, .. }) if *t == f0[3].at + 5 * MS
    ));
    assert_eq!(sim.host_events_where(is_retry).len(), 1);
    assert_eq!(
        sim.host_events_where(is_delivered),
        vec![(
            sim.frame_end(Dir::HostToDev, 1) + b(BAUD),
            Event::Delivered(ticket)
        )]
    );
    assert_eq!(sim.requests(), vec![ping()]);
}

// ---- 9. properties -----------------------------------------------------------

/// Bytes biased towards the ones the protocol gives a meaning to.
fn wire_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        any::<u8>(),
        Just(0x02u8),
        Just(0x03),
        Just(0x06),
        Just(0x15),
        Just(0x3F),
        0u8..6
    ]
}

#[derive(Debug, Clone)]
enum Op {
    /// Advance time, then bytes arrive.
    Rx(u32, Vec<u8>),
    /// Advance time, then `handle_timeout` (whether due or not).
    Timeout(u32),
    /// Jump to the engine's deadline and handle it.
    Deadline,
    /// Submit a frame (data may be too long to encode).
    Submit(u8, Vec<u8>),
    /// Device only: T_REQ changes.
    TReq(bool),
    /// Change the timeouts: T_SR, T_ACK, T_IC, T_POLL (ms), T_WBC (ms,
    /// may be 0).
    Timeouts(u8, u8, u8, u8, u8),
    /// Device only: MIB 000Bh's T_IC selector (ST7570; b7 set or not).
    Tic(bool),
}

fn timeouts(a: u8, b: u8, c: u8, poll: u8, wbc: u8) -> Timeouts {
    Timeouts {
        t_poll: poll as u64 * MS,
        t_wbc: wbc as u64 * MS,
        ..Timeouts::from_ms(a, b, c)
    }
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        6 => (0u32..30_000, prop::collection::vec(wire_byte(), 0..24)).prop_map(|(dt, b)| Op::Rx(dt, b)),
        2 => (0u32..300_000).prop_map(Op::Timeout),
        3 => Just(Op::Deadline),
        1 => (any::<u8>(), prop::collection::vec(any::<u8>(), 0..300)).prop_map(|(c, d)| Op::Submit(c, d)),
        2 => any::<bool>().prop_map(Op::TReq),
        1 => (1u8..=255, 1u8..=255, 1u8..=255, 1u8..=255, 0u8..=255)
            .prop_map(|(a, b, c, p, w)| Op::Timeouts(a, b, c, p, w)),
        1 => any::<bool>().prop_map(Op::Tic),
    ]
}

fn dialect() -> impl Strategy<Value = Dialect> {
    prop_oneof![Just(Dialect::St7580), Just(Dialect::St7570)]
}

/// After `handle_timeout(now)` with `now` at or past the deadline, the
/// next deadline is later: a driver sleeping until `poll_timeout()` never
/// spins.
fn check_progress(now: Instant, next: Option<Instant>) -> Result<(), TestCaseError> {
    prop_assert!(
        next.is_none_or(|d| d > now),
        "deadline {next:?} not after {now}"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn host_engine_survives_any_input(d in dialect(), baud in prop_oneof![Just(9_600u32), Just(57_600)], ops in prop::collection::vec(op(), 0..60)) {
        let mut host = HostEngine::new(d, HostConfig::at_reset(d, baud));
        let mut now: Instant = 0;
        let mut tickets = Vec::new();
        let mut ends = std::collections::HashMap::new();
        for op in ops {
            match op {
                Op::Rx(dt, bytes) => {
                    now += dt as u64;
                    // Arbitrary chunking: the bytes of one chunk arrive together.
                    host.handle_rx(now, &bytes);
                }
                Op::Timeout(dt) => {
                    now += dt as u64;
                    host.handle_timeout(now);
                }
                Op::Deadline => {
                    if let Some(t) = host.poll_timeout() {
                        now = now.max(t);
                        host.handle_timeout(now);
                        check_progress(now, host.poll_timeout())?;
                    }
                }
                Op::Submit(c, data) => tickets.push(host.submit(now, LocalFrame::new(c, data))),
                Op::TReq(_) | Op::Tic(_) => {}
                Op::Timeouts(a, b, c, p, w) => host.set_config(HostConfig { timeouts: timeouts(a, b, c, p, w), ..host.config() }),
            }
            while host.poll_transmit().is_some() {}
            while let Some(e) = host.poll_event() {
                if let Event::Delivered(t) | Event::Failed(t, _) = e {
                    prop_assert!(ends.insert(t, ()).is_none(), "{t:?} ended twice");
                }
            }
        }
        // Whatever happened, driving the deadlines brings every frame to
        // an end.
        for _ in 0..10_000 {
            let Some(t) = host.poll_timeout() else { break };
            now = now.max(t);
            host.handle_timeout(now);
            check_progress(now, host.poll_timeout())?;
            while host.poll_transmit().is_some() {}
            while let Some(e) = host.poll_event() {
                if let Event::Delivered(t) | Event::Failed(t, _) = e {
                    prop_assert!(ends.insert(t, ()).is_none(), "{t:?} ended twice");
                }
            }
        }
        prop_assert_eq!(host.poll_timeout(), None);
        prop_assert_eq!(host.pending(), 0);
        prop_assert_eq!(ends.len(), tickets.len());
    }

    #[test]
    fn device_engine_survives_any_input(d in dialect(), baud in prop_oneof![Just(9_600u32), Just(57_600)], ops in prop::collection::vec(op(), 0..60)) {
        let mut dev = DeviceEngine::new(d, baud);
        let mut now: Instant = 0;
        for op in ops {
            match op {
                Op::Rx(dt, bytes) => {
                    now += dt as u64;
                    dev.handle_rx(now, &bytes);
                }
                Op::Timeout(dt) => {
                    now += dt as u64;
                    dev.handle_timeout(now);
                }
                Op::Deadline => {
                    if let Some(t) = dev.poll_timeout() {
                        now = now.max(t);
                        dev.handle_timeout(now);
                        check_progress(now, dev.poll_timeout())?;
                    }
                }
                Op::Submit(c, data) => dev.submit(now, LocalFrame::new(c, data)),
                Op::TReq(a) => dev.set_treq(now, a),
                Op::Timeouts(a, b, c, p, w) => dev.set_timeouts(timeouts(a, b, c, p, w)),
                Op::Tic(ten_ms) => dev.set_tic(if ten_ms { TicSelector::TenMs } else { TicSelector::FiveCharacters }),
            }
            while dev.poll_transmit().is_some() {}
            while dev.poll_event().is_some() {}
        }
        dev.set_treq(now, false);
        for _ in 0..10_000 {
            let Some(t) = dev.poll_timeout() else { break };
            now = now.max(t);
            dev.handle_timeout(now);
            check_progress(now, dev.poll_timeout())?;
            while dev.poll_transmit().is_some() {}
            while dev.poll_event().is_some() {}
        }
        prop_assert_eq!(dev.poll_timeout(), None);
        prop_assert!(dev.is_idle());
    }
}

#[test]
fn additive_checksum_misses_compensating_errors() {
    // UM0932 Table 6: the checksum is the plain sum of the bytes. +1 on one
    // data byte and -1 on another leave it unchanged: the device accepts
    // the damaged frame. Inherent to the protocol; asserted so that the
    // limit of the lossy-line property below is on record.
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // Data 11 22 33: 11^01 = 10 (-1), 22^01 = 23 (+1).
    sim.inject(Dir::HostToDev, Some(1), Fault::Corrupt(0x01), |c| {
        c.part.is_frame_byte(0, 3)
    });
    sim.inject(Dir::HostToDev, Some(1), Fault::Corrupt(0x01), |c| {
        c.part.is_frame_byte(0, 4)
    });
    sim.submit(ping());
    sim.run_to_idle();
    assert_eq!(
        sim.requests(),
        vec![LocalFrame::new(PING_REQ, vec![0x10, 0x23, 0x33])]
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// N pings through a lossy line (losses, stalls past T_IC and T_SR,
    /// damaged bytes, both ways): each ticket ends exactly once, and
    /// nothing the line damaged is ever taken for a good frame.
    #[test]
    fn pings_over_a_lossy_line(
        seed in any::<u64>(),
        drop_pm in 0u64..40,
        corrupt_pm in 0u64..40,
        pings in prop::collection::vec((0u32..120_000, prop::collection::vec(any::<u8>(), 0..24)), 1..7),
    ) {
        let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
        let (payloads, tickets) =
            lossy_requests(&mut sim, (seed, drop_pm, corrupt_pm), PING_REQ, pings);
        check_lossy(&sim, PING_REQ, &payloads, &tickets)?;
        // The host accepted only confirms the device sent.
        for f in sim.host_frames() {
            prop_assert_eq!(f.code, PING_CNF);
            prop_assert!(payloads.contains(&f.data), "host accepted a confirm never sent: {:02x?}", f.data);
        }
        if drop_pm == 0 && corrupt_pm == 0 {
            // A clean line: everything delivered at the first attempt, each
            // request executed once, each confirm reported once.
            prop_assert_eq!(sim.host_events_where(is_delivered).len(), tickets.len());
            prop_assert!(sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_repeat(e)).is_empty());
            let reqs: Vec<Vec<u8>> = sim.requests().into_iter().map(|f| f.data).collect();
            prop_assert_eq!(&reqs, &payloads);
            let cnfs: Vec<Vec<u8>> = sim.host_frames().into_iter().map(|f| f.data).collect();
            prop_assert_eq!(&cnfs, &payloads);
        }
    }
}

#[test]
fn queued_frames_go_one_after_the_other() {
    // Two pings queued at once. The second T_REQ falls as soon as the
    // first is ACKed, while the modem is sending the first confirm: the
    // modem finishes it, gets its ACK, then answers with the status.
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    let p1 = LocalFrame::new(PING_REQ, vec![1]);
    let p2 = LocalFrame::new(PING_REQ, vec![2]);
    let a = sim.submit(p1.clone());
    let b2 = sim.submit(p2.clone());
    assert_ne!(a, b2);
    assert_eq!(sim.host.pending(), 2);
    sim.run_to_idle();
    let d = sim.host_events_where(is_delivered);
    assert_eq!(d.len(), 2);
    assert_eq!(
        (&d[0].1, &d[1].1),
        (&Event::Delivered(a), &Event::Delivered(b2))
    );
    assert_eq!(sim.treq[2], (d[0].0, true));
    let c1_end = sim.frame_end(Dir::DevToHost, 0);
    assert!(
        d[0].0 < c1_end,
        "T_REQ fell while the confirm was on the wire"
    );
    let status2 = first_wire(&sim, Dir::DevToHost, Part::Status { n: 1, offset: 0 });
    assert_eq!(
        status2.start,
        c1_end + b(BAUD),
        "status right after the host's ACK"
    );
    assert_eq!(sim.requests(), vec![p1.clone(), p2.clone()]);
    assert_eq!(sim.host_frames(), vec![confirm(&p1), confirm(&p2)]);
    assert!(sim
        .host_events_where(|e| is_retry(e) || is_failed(e) || is_repeat(e))
        .is_empty());
}

// ---- 10. T_REQ released before the STX; frames ready during the wait -------

/// Everything the device wrote by now, in order.
fn dev_written(dev: &mut DeviceEngine) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    while let Some(t) = dev.poll_transmit() {
        match t {
            Transmit::Bytes(b) => out.push(b),
            Transmit::TReq { .. } => panic!("the device has no T_REQ output"),
        }
    }
    out
}

const STATUS_IDLE: [u8; 2] = [0x3F, 0x00];

#[test]
fn t_req_released_before_the_stx_ends_the_wait_and_a_new_edge_is_answered_at_once() {
    let mut dev = DeviceEngine::new(Dialect::St7580, BAUD);
    dev.set_treq(0, true);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
    let status_end = wire_time(2, BAUD);
    // Waiting for the host's STX until T_SR after the status.
    assert_eq!(dev.poll_timeout(), Some(status_end + T_SR + 1));
    // UM0932 3.2.8: the host gives up this frame and releases T_REQ
    // before its STX: the wait is over, nothing is left to time.
    let released = status_end + 100;
    dev.set_treq(released, false);
    assert_eq!(dev.poll_timeout(), None);
    assert!(dev.is_idle());
    // Pulled low again microseconds later: answered like the first edge,
    // at once, not T_SR later.
    dev.set_treq(released + 5, true);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
    // And that status opens a wait of its own: a frame whose STX comes
    // within T_SR of it is taken.
    let req = emit(&ping());
    dev.handle_rx(released + 5 + status_end, &req[..1]);
    dev.set_treq(released + 5 + status_end, false);
    let mut t = released + 5 + status_end;
    for &byte in &req[1..] {
        t += b(BAUD);
        dev.handle_rx(t, &[byte]);
    }
    assert_eq!(dev_written(&mut dev), vec![vec![ACK]]);
    let mut requests = Vec::new();
    while let Some(e) = dev.poll_event() {
        if let DeviceEvent::Request(f) = e {
            requests.push(f);
        }
    }
    assert_eq!(requests, vec![ping()]);
}

#[test]
fn a_frame_ready_during_the_wait_goes_out_when_t_req_is_released_before_the_next_status() {
    let mut dev = DeviceEngine::new(Dialect::St7580, BAUD);
    dev.set_treq(0, true);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
    // The confirm of the previous request becomes ready while the modem
    // waits for the host's frame: held while the wait lasts.
    let cnf = indication();
    dev.submit(MS, cnf.clone());
    assert!(dev_written(&mut dev).is_empty());
    // T_REQ released and asserted again at once (the host read "not now"
    // in the status): the confirm goes out as the wait ends, before the
    // status of the new edge.
    dev.set_treq(2 * MS, false);
    dev.set_treq(2 * MS + 3, true);
    assert_eq!(dev_written(&mut dev), vec![emit(&cnf)]);
    // The status follows the confirm's exchange (here the host's ACK).
    let cnf_end = 2 * MS + wire_time(emit(&cnf).len(), BAUD);
    dev.handle_rx(cnf_end + b(BAUD), &[ACK]);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
}

#[test]
fn a_frame_ready_while_the_host_frame_comes_in_goes_before_the_status_of_the_next_t_req() {
    let b1 = b(BAUD);
    let mut dev = DeviceEngine::new(Dialect::St7580, BAUD);
    dev.set_treq(0, true);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
    let mut t = wire_time(2, BAUD);
    let req = emit(&ping());
    dev.handle_rx(t, &req[..1]);
    dev.set_treq(t, false);
    // Mid-frame: the previous request's confirm becomes ready, and the
    // host already pulls T_REQ for its next request.
    dev.submit(t + 1, indication());
    dev.set_treq(t + 2, true);
    for &byte in &req[1..] {
        t += b1;
        dev.handle_rx(t, &[byte]);
    }
    // ACK, then the confirm, and only then the new status.
    assert_eq!(dev_written(&mut dev), vec![vec![ACK], emit(&indication())]);
    let cnf_end = t + wire_time(1 + emit(&indication()).len(), BAUD);
    dev.handle_rx(cnf_end + b1, &[ACK]);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
}

#[test]
fn t_req_still_pending_is_served_before_frames_queued_outside_a_wait() {
    // The old rule stands where no host frame was awaited: a frame queued
    // while another is on the wire waits behind a pending T_REQ.
    let mut dev = DeviceEngine::new(Dialect::St7580, BAUD);
    dev.submit(0, indication());
    assert_eq!(dev_written(&mut dev), vec![emit(&indication())]);
    dev.set_treq(10, true);
    dev.submit(20, ping());
    let end = wire_time(emit(&indication()).len(), BAUD);
    dev.handle_rx(end + b(BAUD), &[ACK]);
    assert_eq!(dev_written(&mut dev), vec![STATUS_IDLE.to_vec()]);
}

#[test]
fn host_retries_a_not_now_status_with_a_new_edge_and_takes_the_modem_frame_first() {
    let b1 = b(BAUD);
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // Bits 1-2 of the status: transmission or reception in progress.
    sim.host.set_not_now(0b0000_0110, 0);
    sim.dev
        .set_status(plm_core::link::StatusMessage::new(Dialect::St7580, &[0x02]));
    let req = ping();
    let ticket = sim.submit(req.clone());
    sim.run_until(MS);
    // Each busy status: T_REQ released before any byte and pulled low
    // again at once, each edge answered within a status' wire time.
    let statuses = statuses_sent(&sim);
    assert!(statuses.len() >= 3, "{statuses:?}");
    let edges: Vec<Instant> = sim
        .treq
        .iter()
        .filter(|(_, a)| *a)
        .map(|(t, _)| *t)
        .collect();
    for (edge, status) in edges.iter().zip(&statuses) {
        assert!(
            status - edge <= b1,
            "status at {status} for the edge at {edge}"
        );
    }
    assert!(sim.wire(Dir::HostToDev).next().is_none(), "no frame yet");
    // A modem frame becomes ready during a wait: it comes before the next
    // status, and the host takes it.
    let ind = indication();
    sim.dev_submit(ind.clone());
    sim.run_until(2 * MS);
    sim.dev
        .set_status(plm_core::link::StatusMessage::new(Dialect::St7580, &[0]));
    sim.run_to_idle();
    assert_eq!(sim.host_frames()[0], ind);
    assert_eq!(sim.requests(), vec![req.clone()]);
    assert_eq!(sim.host_events_where(is_delivered).len(), 1);
    assert!(
        sim.host_events_where(|e| *e == Event::Delivered(ticket))
            .len()
            == 1
    );
    assert!(sim
        .host_events_where(|e| is_retry(e) || is_failed(e) || is_repeat(e))
        .is_empty());
    // The indication went out between two statuses, not after a T_SR.
    let ind_start = sim.frame_start(Dir::DevToHost, 0);
    assert!(ind_start < 2 * MS + wire_time(4, BAUD), "{ind_start}");
    assert!(sim.host_frames().contains(&confirm(&req)));
}

// ---- 11. status availability (issue 13, point 2) ------------------------

/// UM0932 Table 8 bit 1: a power line frame is being transmitted.
fn status_transmitting() -> plm_core::link::StatusMessage {
    plm_core::link::StatusMessage::new(Dialect::St7580, &[0x02])
}

/// UM0932 Table 8 bit 2: a power line frame is being received.
fn status_receiving() -> plm_core::link::StatusMessage {
    plm_core::link::StatusMessage::new(Dialect::St7580, &[0x04])
}

#[test]
fn modem_takes_no_frame_after_a_not_now_status() {
    // A host that sends whatever the status says (no "not now" bits).
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    sim.host.set_not_now(0, T_IC);
    sim.dev.set_status(status_transmitting());
    let req = ping();
    let ticket = sim.submit(req.clone());
    sim.run_until(30 * MS);
    // 3.2.8: the status did not confirm the data channel's availability;
    // the frame is ignored like one outside T_SR: no ACK, no NAK.
    assert!(sim.wire(Dir::HostToDev).next().is_some(), "the host sent");
    assert!(sim.requests().is_empty());
    assert!(sim.dev_sent().iter().all(|(_, e)| e.kind() == "status"));
    sim.dev
        .set_status(plm_core::link::StatusMessage::new(Dialect::St7580, &[0]));
    sim.run_to_idle();
    assert_eq!(sim.requests(), vec![req]);
    let e = sim.host_events_where(|e| is_retry(e) || is_delivered(e));
    assert_eq!(
        e.iter().map(|(_, e)| e.clone()).collect::<Vec<_>>(),
        vec![
            Event::Retry {
                ticket,
                attempt: 1,
                cause: LinkError::NoAck
            },
            Event::Delivered(ticket)
        ]
    );
}

#[test]
fn host_waits_for_a_status_that_is_not_not_now() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    sim.dev.set_status(status_transmitting());
    let req = ping();
    let ticket = sim.submit(req.clone());
    sim.run_until(100 * MS);
    // By default bits 1-2 are "not now": T_REQ released before any byte,
    // pulled low again T_IC later; nothing sent, no attempt spent.
    assert!(sim.wire(Dir::HostToDev).next().is_none(), "no frame yet");
    let edges: Vec<Instant> = sim
        .treq
        .iter()
        .filter(|(_, a)| *a)
        .map(|(t, _)| *t)
        .collect();
    assert!((8..=11).contains(&edges.len()), "{edges:?}");
    assert!(edges.windows(2).all(|w| w[1] - w[0] >= T_IC), "{edges:?}");
    sim.dev
        .set_status(plm_core::link::StatusMessage::new(Dialect::St7580, &[0]));
    sim.run_to_idle();
    assert_eq!(sim.requests(), vec![req]);
    assert_eq!(
        sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_delivered(e))
            .into_iter()
            .map(|(_, e)| e)
            .collect::<Vec<_>>(),
        vec![Event::Delivered(ticket)]
    );
}

#[test]
fn host_gives_up_on_a_modem_busy_for_good() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    // Received for ever.
    sim.dev.set_status(status_receiving());
    let ticket = sim.submit(ping());
    sim.run_until(3_000 * MS);
    let failed = sim.host_events_where(is_failed);
    assert_eq!(failed.len(), 1);
    assert_eq!(failed[0].1, Event::Failed(ticket, LinkError::Busy));
    let at = failed[0].0;
    assert!(
        (BUSY_LIMIT..BUSY_LIMIT + T_IC + MS).contains(&at),
        "failed at {at}"
    );
    assert!(sim.host_events_where(is_retry).is_empty());
    assert_eq!(sim.host.pending(), 0);
    assert!(sim.requests().is_empty());
}

#[test]
fn a_frame_the_modem_has_not_let_out_yet_can_be_withdrawn() {
    let mut sim = Sim::with_baud(BAUD).responder(ping_responder());
    sim.dev.set_status(status_receiving());
    let waiting = sim.submit(ping());
    let queued = sim.submit(ping());
    sim.run_until(20 * MS);
    assert!(sim.host.withdraw(sim.now, queued), "queued behind it");
    assert!(sim.host.withdraw(sim.now, waiting), "met only \"not now\"");
    assert!(!sim.host.withdraw(sim.now, waiting), "gone already");
    assert_eq!(sim.host.pending(), 0);
    sim.dev
        .set_status(plm_core::link::StatusMessage::new(Dialect::St7580, &[0]));
    sim.run_until(200 * MS);
    // Nothing sent, no event: the caller gave it up.
    assert!(sim.wire(Dir::HostToDev).next().is_none());
    assert!(sim
        .host_events_where(|e| is_retry(e) || is_failed(e) || is_delivered(e))
        .is_empty());
    // A frame that has left is not withdrawn: its fate comes as an event.
    let sent = sim.submit(ping());
    sim.run_to_idle();
    assert!(!sim.host.withdraw(sim.now, sent));
    assert_eq!(
        sim.host_events_where(is_delivered)
            .into_iter()
            .map(|(_, e)| e)
            .collect::<Vec<_>>(),
        vec![Event::Delivered(sent)]
    );
}
