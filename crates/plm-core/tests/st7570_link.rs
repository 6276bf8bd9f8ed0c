//! The host and device link engines in the ST7570 dialect against each
//! other, in virtual time, byte by byte over a simulated UART (see
//! `harness/mod.rs`), checked against ST7570 UM 5.2.2-5.2.3: T_POLL, T_SR,
//! T_IC (MIB 000Bh), T_ACK, NAK -> one repeat after T_WBC, a missed or
//! garbled ACK counting as ACK, a modem frame while the host waits for the
//! status message, NAK storms.

mod harness;

use harness::chip::{
    data_indication as indication, read_db, read_db_confirm as confirm, read_db_responder,
    READ_DB_CNF, READ_DB_REQ,
};
use harness::{
    check_lossy, first_wire, is_delivered, is_failed, is_repeat, is_retry, lossy_requests,
    statuses_sent, Dir, Fault, Part, Sim,
};
use plm_core::link::device::{DeviceEngine, DeviceEvent};
use plm_core::link::host::{Event, HostConfig, LinkError};
use plm_core::link::{
    Dialect, Element, GarbageReason, LocalFrame, StatusMessage, TicSelector, Timeouts, ACK, NAK,
};
use plm_core::time::{wire_time, Instant, MS};
use proptest::prelude::*;

const ST7570: Dialect = Dialect::St7570;
const BAUD: u32 = 57_600;
/// ST7570 UM Table 14.
const T_ACK: u64 = 40 * MS;
const T_POLL: u64 = 20 * MS;
const T_WBC: u64 = 5 * MS;
/// MIB 000Bh factory default (b7 = 0): 5 characters, 869 µs at 57 600.
const T_IC: u64 = 869;

/// CMD_IS_Indication: the same byte as NAK.
const IS_IND: u8 = 0x15;

fn b() -> u64 {
    wire_time(1, BAUD)
}

/// A bench of two ST7570 engines with their reset settings.
fn sim_at(baud: u32) -> Sim {
    Sim::new_in(ST7570, baud, HostConfig::at_reset(ST7570, baud)).responder(read_db_responder())
}

fn sim() -> Sim {
    sim_at(BAUD)
}

/// A bench whose both engines use `t`.
fn sim_with(t: Timeouts) -> Sim {
    let mut sim = Sim::new_in(
        ST7570,
        BAUD,
        HostConfig {
            timeouts: t,
            ..HostConfig::at_reset(ST7570, BAUD)
        },
    )
    .responder(read_db_responder());
    sim.dev.set_timeouts(t);
    sim
}

fn emit(f: &LocalFrame) -> Vec<u8> {
    f.emit(ST7570).unwrap()
}

fn outcome(e: &Event) -> bool {
    is_retry(e) || is_failed(e) || is_delivered(e)
}

fn delivered_by_dev(sim: &Sim) -> Vec<(Instant, DeviceEvent)> {
    sim.dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. }))
}

/// How many frames went `dir`.
fn frames_sent(sim: &Sim, dir: Dir) -> usize {
    (0..)
        .take_while(|n| !sim.frame_bytes(dir, *n).is_empty())
        .count()
}

// ---- 1. the sequence of 5.2.2: link_both.rs; the request's bytes ----------

#[test]
fn the_read_db_request_is_these_bytes() {
    assert_eq!(emit(&read_db()), [0x02, 0x05, 0x90, 0x0B, 0x00, 0xA0, 0x00]);
}

// ---- 2. T_POLL ---------------------------------------------------------------

#[test]
fn no_status_within_t_poll_restarts_and_the_modem_answers_the_new_edge() {
    let mut sim = sim();
    // The first status message is lost on the line.
    sim.inject(Dir::DevToHost, None, Fault::Drop, |c| {
        matches!(c.part, Part::Status { n: 0, .. })
    });
    let req = read_db();
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    // UM 5.2.2: the status comes within T_POLL; after T_POLL the host
    // gives up this attempt, leaves T_REQ high for T_IC and starts over.
    let again = T_POLL + T_IC;
    let stx = sim.frame_bytes(Dir::HostToDev, 0)[0];
    assert_eq!(
        sim.treq,
        vec![(0, true), (T_POLL, false), (again, true), (stx.at, false)]
    );
    // The modem answers the new falling edge at once, although the T_SR
    // window its first status opened is still running.
    assert_eq!(statuses_sent(&sim), vec![0, again]);
    assert_eq!(
        sim.host_events_where(outcome),
        vec![
            (
                T_POLL,
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause: LinkError::NoStatus
                }
            ),
            (
                sim.frame_end(Dir::HostToDev, 0) + b(),
                Event::Delivered(ticket)
            )
        ]
    );
    assert_eq!(sim.requests(), vec![req]);
}

#[test]
fn no_status_on_any_attempt_fails_after_three_t_polls() {
    let mut sim = sim();
    sim.inject(Dir::DevToHost, None, Fault::Drop, |c| c.part.is_status());
    let ticket = sim.submit(read_db());
    sim.run_to_idle();

    let a2 = T_POLL + T_IC;
    let a3 = 2 * (T_POLL + T_IC);
    assert_eq!(
        sim.treq,
        vec![
            (0, true),
            (T_POLL, false),
            (a2, true),
            (a2 + T_POLL, false),
            (a3, true),
            (a3 + T_POLL, false)
        ]
    );
    assert_eq!(
        sim.host_events_where(outcome),
        vec![
            (
                T_POLL,
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause: LinkError::NoStatus
                }
            ),
            (
                a2 + T_POLL,
                Event::Retry {
                    ticket,
                    attempt: 2,
                    cause: LinkError::NoStatus
                }
            ),
            (a3 + T_POLL, Event::Failed(ticket, LinkError::NoStatus)),
        ]
    );
    assert_eq!(statuses_sent(&sim), vec![0, a2, a3]);
    assert_eq!(sim.wire(Dir::HostToDev).count(), 0);
    assert_eq!(sim.host.pending(), 0);
}

#[test]
fn t_poll_is_configurable() {
    let t = Timeouts {
        t_poll: 7 * MS,
        ..Timeouts::at_reset(ST7570, BAUD)
    };
    let mut sim = sim_with(t);
    sim.inject(Dir::DevToHost, Some(4), Fault::Drop, |c| c.part.is_status());
    let ticket = sim.submit(read_db());
    sim.run_to_idle();
    assert_eq!(
        sim.host_events_where(is_retry),
        vec![(
            7 * MS,
            Event::Retry {
                ticket,
                attempt: 1,
                cause: LinkError::NoStatus
            }
        )]
    );
    assert_eq!(sim.host_events_where(is_delivered).len(), 1);
}

// ---- 3. T_SR -----------------------------------------------------------------

#[test]
fn the_modem_ignores_a_frame_whose_stx_comes_after_t_sr() {
    // T_SR shortened to 10 ms on both sides, the host's first STX held
    // back 15 ms on the line.
    let t = Timeouts {
        t_sr: 10 * MS,
        ..Timeouts::at_reset(ST7570, BAUD)
    };
    let mut sim = sim_with(t);
    sim.inject(Dir::HostToDev, Some(1), Fault::Delay(15 * MS), |c| {
        c.part.is_frame_byte(0, 0)
    });
    let req = read_db();
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    let status_end = wire_time(4, BAUD);
    let stx0 = sim.frame_bytes(Dir::HostToDev, 0)[0];
    assert!(stx0.at > status_end + 10 * MS, "the STX is late");
    // The late frame arrived whole and right, and was ignored (UM 5.2.2):
    // no ACK, no NAK, no request; the modem's next word is the status of
    // the restart.
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
    let sent: Vec<&str> = sim.dev_sent().iter().map(|(_, e)| e.kind()).collect();
    assert_eq!(sent, ["status", "status", "ack", "frame"]);
    assert_eq!(
        sim.host_events_where(outcome)
            .into_iter()
            .map(|(_, e)| e)
            .collect::<Vec<_>>(),
        vec![
            Event::Retry {
                ticket,
                attempt: 1,
                cause: LinkError::NoAck
            },
            Event::Delivered(ticket)
        ]
    );
    assert_eq!(sim.requests(), vec![req]);
}

// ---- 4. T_IC (MIB 000Bh) -------------------------------------------------------

/// Stalls the line `gap` before byte 4 of the host's first frame and runs
/// a ReadDB; returns the bench.
fn host_frame_with_a_gap(mut sim: Sim, gap: u64) -> Sim {
    sim.inject(Dir::HostToDev, Some(1), Fault::Delay(gap), |c| {
        c.part.is_frame_byte(0, 4)
    });
    sim.submit(read_db());
    sim.run_to_idle();
    sim
}

#[test]
fn a_gap_longer_than_t_ic_breaks_the_host_frame_and_the_host_retries() {
    // 1 ms > 5 characters at 57 600 baud (869 µs).
    let sim = host_frame_with_a_gap(sim(), MS);
    let f0 = sim.frame_bytes(Dir::HostToDev, 0);
    assert_eq!(
        sim.dev_received()[0],
        (
            f0[3].at + T_IC,
            Element::Garbage {
                bytes: emit(&read_db())[..4].to_vec(),
                reason: GarbageReason::Truncated
            }
        )
    );
    // No answer to the broken frame; the host restarts after T_ACK.
    let sent: Vec<&str> = sim.dev_sent().iter().map(|(_, e)| e.kind()).collect();
    assert_eq!(sent, ["status", "status", "ack", "frame"]);
    let end0 = sim.frame_end(Dir::HostToDev, 0) - MS;
    let retries = sim.host_events_where(is_retry);
    assert_eq!(retries.len(), 1);
    assert_eq!(retries[0].0, end0 + T_ACK, "T_ACK after the frame as sent");
    assert_eq!(sim.requests(), vec![read_db()]);
}

#[test]
fn t_ic_is_five_characters_or_10_ms_as_000bh_selects() {
    let broken = |sim: &Sim| !sim.host_events_where(is_retry).is_empty();
    // Factory default (b7 = 0): 5 characters, so a 3 ms pause breaks a
    // frame at 57 600 baud (869 µs) but not at 9600 baud (5.2 ms).
    assert!(broken(&host_frame_with_a_gap(sim_at(57_600), 3 * MS)));
    assert!(!broken(&host_frame_with_a_gap(sim_at(9_600), 3 * MS)));
    // 000Bh b7 = 1 on both sides: 10 ms, whatever the baud rate.
    let ten_ms = |baud: u32| {
        let tic = TicSelector::from_mib_000b(0x80);
        let mut config = HostConfig::at_reset(ST7570, baud);
        config.timeouts = config.timeouts.with_tic(tic, baud);
        let mut sim = Sim::new_in(ST7570, baud, config).responder(read_db_responder());
        sim.dev.set_tic(tic);
        sim
    };
    assert!(!broken(&host_frame_with_a_gap(ten_ms(57_600), 3 * MS)));
    assert!(!broken(&host_frame_with_a_gap(ten_ms(57_600), 9 * MS)));
    assert!(broken(&host_frame_with_a_gap(ten_ms(57_600), 11 * MS)));
}

#[test]
fn the_modems_t_ic_follows_000bh_the_baud_rate_and_a_reset() {
    let mut dev = DeviceEngine::new(ST7570, 9_600);
    assert_eq!(dev.timeouts().t_ic, 5_209);
    dev.set_baud(57_600);
    assert_eq!(dev.timeouts().t_ic, 869);
    dev.set_tic(TicSelector::TenMs);
    dev.set_baud(19_200);
    assert_eq!(dev.timeouts().t_ic, 10 * MS);
    dev.reset();
    assert_eq!(dev.timeouts(), Timeouts::at_reset(ST7570, 19_200));
    assert_eq!(dev.timeouts().t_ic, 2_605);
}

#[test]
fn a_gap_in_a_modem_frame_is_naked_and_repeated_not_lost() {
    let mut sim = sim();
    let ind = indication(0);
    sim.inject(Dir::DevToHost, Some(1), Fault::Delay(2 * MS), |c| {
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
    // The host NAKs the frame cut short as T_IC ends it (UM 5.2.2: "In
    // other cases, it answers with an NAK"; issue 13, point 5), after the
    // frame's end as the modem sent it, so the modem repeats it T_WBC
    // later; silence would have counted as ACK and lost it.
    let sent_end = wire_time(emit(&ind).len(), BAUD);
    let nak = f0[3].at + T_IC;
    assert!(nak > sent_end);
    let h2d: Vec<_> = sim
        .wire(Dir::HostToDev)
        .map(|w| (w.part, w.start))
        .collect();
    assert_eq!(h2d[0], (Part::Nak, nak));
    assert_eq!(h2d[1].0, Part::Ack);
    assert_eq!(h2d.len(), 2);
    assert_eq!(frames_sent(&sim, Dir::DevToHost), 2);
    let repeat = sim.frame_bytes(Dir::DevToHost, 1);
    assert_eq!(repeat[0].start, nak + b() + T_WBC);
    assert_eq!(
        delivered_by_dev(&sim),
        vec![(
            repeat[0].start,
            DeviceEvent::Delivered {
                frame: ind.clone(),
                repeated: true
            }
        )]
    );
    assert_eq!(sim.host_frames(), vec![ind]);
}

// ---- 5. T_ACK and NAK from the modem ----------------------------------------------

// (The NAK that restarts the sequence: link_both.rs.)

// (A lost ACK restarting the sequence: link_both.rs.)

#[test]
fn t_ack_is_configurable() {
    let t = Timeouts {
        t_ack: 15 * MS,
        ..Timeouts::at_reset(ST7570, BAUD)
    };
    let mut sim = sim_with(t);
    sim.inject(Dir::DevToHost, Some(1), Fault::Drop, |c| {
        c.part == Part::Ack
    });
    sim.submit(read_db());
    sim.run_to_idle();
    let end0 = sim.frame_end(Dir::HostToDev, 0);
    assert_eq!(sim.host_events_where(is_retry)[0].0, end0 + 15 * MS);
}

// ---- 6. modem frames: NAK -> one repeat after T_WBC ------------------------------

#[test]
fn nak_of_a_modem_frame_gives_one_repeat_after_t_wbc() {
    let mut sim = sim();
    sim.inject(Dir::DevToHost, Some(1), Fault::Corrupt(0x40), |c| {
        c.part.is_frame_byte(0, 3)
    });
    let req = read_db();
    let reply = confirm(&req);
    sim.submit(req.clone());
    sim.run_to_idle();

    let end0 = sim.frame_end(Dir::DevToHost, 0);
    let nak = first_wire(&sim, Dir::HostToDev, Part::Nak);
    assert_eq!(nak.start, end0, "the host NAKs at once");
    // UM 5.2.2: the repeat goes T_WBC after the NAK, with STX 02h.
    let repeat = sim.frame_bytes(Dir::DevToHost, 1);
    assert_eq!(repeat[0].start, nak.at + T_WBC);
    assert_eq!(repeat[0].sent, 0x02);
    let end1 = repeat.last().unwrap().at;
    assert_eq!(first_wire(&sim, Dir::HostToDev, Part::Ack).start, end1);
    // The repeat is the first good copy: reported once, as the frame.
    assert_eq!(
        sim.host_events_where(|e| matches!(e, Event::Frame(_))),
        vec![(end1, Event::Frame(reply.clone()))]
    );
    assert!(sim.host_events_where(is_repeat).is_empty());
    assert_eq!(
        delivered_by_dev(&sim),
        vec![(
            repeat[0].start,
            DeviceEvent::Delivered {
                frame: reply,
                repeated: true
            }
        )]
    );
    assert_eq!(frames_sent(&sim, Dir::DevToHost), 2);
}

#[test]
fn t_wbc_is_configurable() {
    let t = Timeouts {
        t_wbc: 12 * MS,
        ..Timeouts::at_reset(ST7570, BAUD)
    };
    let mut sim = sim_with(t);
    sim.inject(Dir::DevToHost, Some(1), Fault::Corrupt(0x40), |c| {
        c.part.is_frame_byte(0, 3)
    });
    sim.dev_submit(indication(0));
    sim.run_to_idle();
    let nak = first_wire(&sim, Dir::HostToDev, Part::Nak);
    assert_eq!(sim.frame_start(Dir::DevToHost, 1), nak.at + 12 * MS);
    assert_eq!(sim.host_frames(), vec![indication(0)]);
}

#[test]
fn a_nakked_repeat_is_not_repeated_again() {
    let mut sim = sim();
    sim.inject(Dir::DevToHost, None, Fault::Corrupt(0x40), |c| {
        matches!(
            c.part,
            Part::Frame {
                n: 0 | 1,
                offset: 3
            }
        )
    });
    let ind = indication(0);
    sim.dev_submit(ind.clone());
    sim.run_to_idle();

    // Two NAKs, two copies, then nothing: the frame is lost.
    let h2d: Vec<Part> = sim.wire(Dir::HostToDev).map(|w| w.part).collect();
    assert_eq!(h2d, [Part::Nak, Part::Nak]);
    assert_eq!(frames_sent(&sim, Dir::DevToHost), 2);
    assert!(sim.host_frames().is_empty());
    assert_eq!(
        delivered_by_dev(&sim),
        vec![(
            sim.frame_start(Dir::DevToHost, 1),
            DeviceEvent::Delivered {
                frame: ind,
                repeated: true
            }
        )]
    );
    assert!(sim.dev.is_idle());
}

// ---- 7. a missed or garbled ACK counts as ACK ---------------------------------------

#[test]
fn a_lost_ack_counts_as_ack_after_t_ack() {
    let mut sim = sim();
    sim.inject(Dir::HostToDev, Some(1), Fault::Drop, |c| {
        c.part == Part::Ack
    });
    let req = read_db();
    let reply = confirm(&req);
    sim.submit(req);
    sim.run_to_idle();

    let end0 = sim.frame_end(Dir::DevToHost, 0);
    // No repeat (the ST7580 would repeat with STX 03h here).
    assert_eq!(frames_sent(&sim, Dir::DevToHost), 1);
    assert_eq!(
        delivered_by_dev(&sim),
        vec![(
            end0 + T_ACK,
            DeviceEvent::Delivered {
                frame: reply.clone(),
                repeated: false
            }
        )]
    );
    assert_eq!(sim.host_frames(), vec![reply]);
}

#[test]
fn a_garbled_ack_counts_as_ack() {
    let mut sim = sim();
    // 06h -> 07h: a framing error where an ACK is awaited.
    sim.inject(Dir::HostToDev, Some(1), Fault::Corrupt(0x01), |c| {
        c.part == Part::Ack
    });
    let ind = indication(0);
    sim.dev_submit(ind.clone());
    sim.run_to_idle();

    let ack = first_wire(&sim, Dir::HostToDev, Part::Ack);
    assert_eq!(ack.got, Some(0x07));
    assert_eq!(frames_sent(&sim, Dir::DevToHost), 1);
    // The stray byte is taken for an ACK once T_IC says it is alone.
    assert_eq!(
        delivered_by_dev(&sim),
        vec![(
            ack.at + T_IC,
            DeviceEvent::Delivered {
                frame: ind.clone(),
                repeated: false
            }
        )]
    );
    assert_eq!(sim.host_frames(), vec![ind]);
}

#[test]
fn an_ack_damaged_into_a_nak_gives_a_repeat_the_host_reports_once() {
    let mut sim = sim();
    // 06h ^ 13h = 15h: the modem reads NAK and repeats after T_WBC, with
    // STX 02h like any frame. The host tells the repeat by its content and
    // by its timing.
    sim.inject(Dir::HostToDev, Some(1), Fault::Corrupt(ACK ^ NAK), |c| {
        c.part == Part::Ack
    });
    let ind = indication(0);
    sim.dev_submit(ind.clone());
    sim.run_to_idle();

    let ack = first_wire(&sim, Dir::HostToDev, Part::Ack);
    assert_eq!(ack.got, Some(NAK));
    let repeat = sim.frame_bytes(Dir::DevToHost, 1);
    assert_eq!(repeat[0].start, ack.at + T_WBC);
    let end1 = repeat.last().unwrap().at;
    assert_eq!(sim.host_frames(), vec![ind.clone()]);
    assert_eq!(
        sim.host_events_where(is_repeat),
        vec![(end1, Event::Repeat(ind.clone()))]
    );
    // The repeat is ACKed too.
    let acks: Vec<Instant> = sim
        .wire(Dir::HostToDev)
        .filter(|w| w.part == Part::Ack)
        .map(|w| w.start)
        .collect();
    assert_eq!(acks, vec![sim.frame_end(Dir::DevToHost, 0), end1]);
}

#[test]
fn the_same_frame_again_right_after_the_ack_is_a_new_frame() {
    // Two identical indications queued: the second leaves as soon as the
    // ACK of the first is in, before a repeat could (T_WBC): it is new.
    let mut sim = sim();
    let ind = indication(0);
    sim.dev_submit(ind.clone());
    sim.dev_submit(ind.clone());
    sim.run_to_idle();
    let end0 = sim.frame_end(Dir::DevToHost, 0);
    assert_eq!(sim.frame_start(Dir::DevToHost, 1), end0 + b());
    assert_eq!(sim.host_frames(), vec![ind.clone(), ind]);
    assert!(sim.host_events_where(is_repeat).is_empty());
}

#[test]
fn the_same_answer_to_a_request_asked_again_is_a_new_frame() {
    // The host reads one object, then asks for it again a few ms after
    // its ACK of the answer (a user clicking Read twice, a chained read):
    // the second answer, equal to the first, comes in the window where a
    // repeat could (T_WBC + 1 character .. 2 x T_WBC + 1 character after
    // the ACK). But the modem ACKed the request in between, which it does
    // not while it waits to repeat: it is the answer, not a repeat.
    for gap in [MS, 3 * MS, 4 * MS, 5 * MS, 6 * MS, 8 * MS] {
        let mut sim = sim();
        let req = read_db();
        sim.submit(req.clone());
        sim.run_to_idle();
        let ack = sim
            .wire(Dir::HostToDev)
            .filter(|w| w.part == Part::Ack)
            .map(|w| w.start)
            .last()
            .expect("the answer ACKed");
        sim.run_until(ack + gap);
        sim.submit(req.clone());
        sim.run_to_idle();
        assert_eq!(
            sim.host_frames(),
            vec![confirm(&req), confirm(&req)],
            "asked again {gap} µs after the ACK"
        );
        assert!(sim.host_events_where(is_repeat).is_empty());
    }
}

// ---- 8. a modem frame while the host waits for the status (the first: link_both.rs)

#[test]
fn a_nakked_modem_frame_and_its_repeat_while_host_waits_for_status() {
    let b1 = b();
    let mut sim = sim();
    let ind = indication(0);
    sim.inject(Dir::DevToHost, Some(1), Fault::Corrupt(0x40), |c| {
        c.part.is_frame_byte(0, 3)
    });
    sim.dev_submit(ind.clone());
    sim.run_until(3 * b1);
    let ticket = sim.submit(read_db());
    sim.run_to_idle();

    // NAK, the repeat T_WBC later, and only then (right behind the repeat,
    // which counts as delivered whatever the answer) the status: the host
    // keeps waiting for it as long as the modem talks (T_POLL after each
    // byte).
    let nak = first_wire(&sim, Dir::HostToDev, Part::Nak);
    let repeat_end = sim.frame_end(Dir::DevToHost, 1);
    assert_eq!(sim.frame_start(Dir::DevToHost, 1), nak.at + T_WBC);
    let status = first_wire(&sim, Dir::DevToHost, Part::Status { n: 0, offset: 0 });
    assert_eq!(status.start, repeat_end);
    assert!(
        status.start > 3 * b1 + T_WBC,
        "later than T_WBC after T_REQ"
    );
    assert_eq!(sim.host_frames()[0], ind);
    assert_eq!(
        sim.host_events_where(outcome)
            .into_iter()
            .map(|(_, e)| e)
            .collect::<Vec<_>>(),
        vec![Event::Delivered(ticket)]
    );
}

// ---- 9. NAK storms ---------------------------------------------------------------

#[test]
fn a_nak_storm_on_host_frames_is_bounded_then_the_link_recovers() {
    let mut sim = sim();
    // The next three host frames are damaged: three NAKs.
    sim.inject(Dir::HostToDev, Some(3), Fault::Corrupt(0x20), |c| {
        matches!(c.part, Part::Frame { offset: 3, .. })
    });
    let req = read_db();
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    let naks: Vec<Instant> = sim
        .wire(Dir::DevToHost)
        .filter(|w| w.part == Part::Nak)
        .map(|w| w.at)
        .collect();
    assert_eq!(naks.len(), 3);
    let cause = LinkError::Nak;
    assert_eq!(
        sim.host_events_where(outcome),
        vec![
            (
                naks[0],
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause
                }
            ),
            (
                naks[1],
                Event::Retry {
                    ticket,
                    attempt: 2,
                    cause
                }
            ),
            (naks[2], Event::Failed(ticket, cause)),
        ]
    );
    assert!(sim.requests().is_empty());
    assert_eq!(sim.host.pending(), 0);
    assert_eq!(sim.treq.last().map(|(_, a)| *a), Some(false));

    // The storm over, the next request goes through at once.
    let ticket2 = sim.submit(req.clone());
    sim.run_to_idle();
    assert_eq!(
        sim.host_events_where(outcome).last().unwrap().1,
        Event::Delivered(ticket2)
    );
    assert_eq!(sim.requests(), vec![req]);
}

#[test]
fn a_nak_storm_on_modem_frames_costs_two_copies_each_and_blocks_nothing() {
    let mut sim = sim();
    // Every modem frame is damaged; status messages and ACKs are not.
    sim.inject(Dir::DevToHost, None, Fault::Corrupt(0x40), |c| {
        matches!(c.part, Part::Frame { offset: 3, .. })
    });
    for n in 0..4 {
        sim.dev_submit(indication(n));
    }
    // Meanwhile the host sends a request.
    sim.run_until(3 * b());
    let req = read_db();
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    // 4 indications and the confirm, each sent twice and NAKed twice.
    assert_eq!(frames_sent(&sim, Dir::DevToHost), 10);
    let naks = sim.wire(Dir::HostToDev).filter(|w| w.part == Part::Nak);
    assert_eq!(naks.count(), 10);
    assert!(sim.host_frames().is_empty());
    let delivered = delivered_by_dev(&sim);
    assert_eq!(delivered.len(), 5);
    assert!(delivered
        .iter()
        .all(|(_, e)| matches!(e, DeviceEvent::Delivered { repeated: true, .. })));
    // The host's own request got through at the first attempt.
    assert_eq!(
        sim.host_events_where(outcome)
            .into_iter()
            .map(|(_, e)| e)
            .collect::<Vec<_>>(),
        vec![Event::Delivered(ticket)]
    );
    assert_eq!(sim.requests(), vec![req]);
    assert!(sim.dev.is_idle());
    assert_eq!(sim.host.pending(), 0);
}

// ---- 10. receivers are state machines, not byte scanners ---------------------------

#[test]
fn nak_ack_and_status_bytes_inside_frames_and_status_messages() {
    let mut sim = sim();
    // CMD_IS_Indication's code is the NAK byte; its data holds ACK, NAK,
    // `?` and STX bytes.
    let is_ind = LocalFrame::new(IS_IND, vec![0x01, ACK, NAK, 0x3F, 0x02, 0x15]);
    sim.dev_submit(is_ind.clone());
    sim.run_to_idle();
    // A status message whose bytes are STX, ACK and NAK.
    sim.dev
        .set_status(StatusMessage::new(ST7570, &[0x02, ACK, NAK]));
    // A request whose data holds them too.
    let req = LocalFrame::new(0x41, vec![0x0B, 0x00, ACK, NAK, 0x3F, 0x02]);
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    let received: Vec<Element> = sim
        .host_events
        .iter()
        .filter_map(|(_, e)| match e {
            Event::Received(el) => Some(el.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(received.len(), 3, "{received:?}");
    assert!(
        matches!(&received[0], Element::Frame { frame, checksum_ok: true, .. } if *frame == is_ind)
    );
    assert_eq!(
        received[1],
        Element::Status(StatusMessage::new(ST7570, &[0x02, ACK, NAK]))
    );
    assert_eq!(received[2], Element::Ack);
    assert_eq!(sim.host_frames(), vec![is_ind]);
    assert_eq!(sim.requests(), vec![req]);
    assert_eq!(
        sim.host_events_where(outcome),
        vec![(
            sim.frame_end(Dir::HostToDev, 0) + b(),
            Event::Delivered(ticket)
        )]
    );
    let dev_got: Vec<&str> = sim.dev_received().iter().map(|(_, e)| e.kind()).collect();
    assert_eq!(dev_got, ["ack", "frame"]);
}

// ---- 11. properties -------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, failure_persistence: None, ..ProptestConfig::default() })]

    /// N ReadDB requests through a lossy line (losses, stalls past T_IC,
    /// T_POLL and T_SR, damaged bytes, both ways): each ticket ends exactly
    /// once, nothing damaged is taken for a good frame, and on a clean line
    /// everything goes through at once.
    #[test]
    fn requests_over_a_lossy_st7570_line(
        seed in any::<u64>(),
        drop_pm in 0u64..40,
        corrupt_pm in 0u64..40,
        baud in prop_oneof![Just(9_600u32), Just(57_600)],
        reqs in prop::collection::vec((0u32..120_000, prop::collection::vec(any::<u8>(), 0..24)), 1..7),
    ) {
        let mut sim = sim_at(baud);
        let (payloads, tickets) =
            lossy_requests(&mut sim, (seed, drop_pm, corrupt_pm), READ_DB_REQ, reqs);
        check_lossy(&sim, READ_DB_REQ, &payloads, &tickets)?;
        prop_assert!(sim.dev.is_idle());
        // The host accepted only confirms the device sent, and no device
        // frame was sent more than twice.
        for f in sim.host_frames() {
            prop_assert_eq!(f.code, READ_DB_CNF);
            let mut sent = f.data.clone();
            sent.pop();
            prop_assert!(payloads.contains(&sent), "host accepted a confirm never sent: {:02x?}", f.data);
        }
        let copies = sim.dev_sent().into_iter().filter(|(_, e)| matches!(e, Element::Frame { .. })).count();
        prop_assert!(copies <= 2 * sim.requests().len());
        if drop_pm == 0 && corrupt_pm == 0 {
            prop_assert_eq!(sim.host_events_where(is_delivered).len(), tickets.len());
            prop_assert!(sim.host_events_where(|e| is_retry(e) || is_failed(e) || is_repeat(e)).is_empty());
            let reqs: Vec<Vec<u8>> = sim.requests().into_iter().map(|f| f.data).collect();
            prop_assert_eq!(&reqs, &payloads);
            let cnfs: Vec<LocalFrame> = sim.host_frames();
            let want: Vec<LocalFrame> = sim.requests().iter().map(confirm).collect();
            prop_assert_eq!(cnfs, want);
        }
    }
}
