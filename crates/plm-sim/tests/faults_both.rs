//! Fault injection on the UART of a simulated modem, with plm-core's host
//! engine as the host, in virtual time: the runs both chips pass the same
//! way, written once over the chip ([`faulty::Modem`]), each run once per
//! chip (`st7580::…`, `st7570::…`). "The host recovers from every
//! injected fault without losing or duplicating a confirmed frame."
//!
//! UM0932 3.2.5-3.2.9 and ST7570 UM 5.2.2: a broken host frame is NAKed
//! or dropped, and the host restarts the whole T_REQ sequence; a broken
//! status message makes the host start over. The hole both protocols
//! leave (docs/protocol-notes.md, "Known limits" and "ST7570: link"): no
//! sequence numbers, so when the modem's ACK is lost the request is
//! executed twice. What only one chip does (the ST7580's STX 03h repeat,
//! the ST7570's repeat after a NAK and T_WBC, resets, the cable) is in
//! `faults.rs` and `st7570_faults.rs`.

mod faulty;

use faulty::{exchange, fault_at, with_fault, Modem, PAST_T_IC, SEC, TAG};
use plm_core::link::host::{Event, LinkError};
use plm_core::link::Stx;
use plm_core::time::MS;
use plm_sim::uart::OneShot;
use plm_sim::{ByteFaults, Dir};

// ---- host to modem ------------------------------------------------------

/// A host byte lost. Without its STX no frame began before T_REQ went
/// high: the wait is over, the bytes are ignored, T_ACK runs out. A frame
/// a byte short waits for a byte that never comes: T_IC cuts it
/// ([`Modem::CUT_FRAME`]). Either way the host starts over and the
/// request is executed once.
fn dropped_host_byte_is_never_answered_and_the_host_retries<M: Modem>() {
    for k in 0..M::FRAME {
        let ex = with_fault::<M>(Dir::HostToModem, k, OneShot::Drop);
        let cause = if k == 0 {
            LinkError::NoAck
        } else {
            M::CUT_FRAME
        };
        assert_eq!(ex.retries(), vec![cause], "byte {k}: {ex:#?}");
        let naks = usize::from(cause == LinkError::Nak);
        assert_eq!(ex.naks_received(), naks, "byte {k}: {ex:#?}");
        assert_eq!(ex.confirms::<M>(TAG), vec![Stx::First], "byte {k}: {ex:#?}");
        assert_eq!(ex.repeats(), 0, "byte {k}");
    }
}

/// A host byte damaged. A damaged STX begins no frame (as above); a
/// damaged length leaves the frame waiting for bytes that never come (cut
/// by T_IC); any later byte breaks the checksum: NAKed. Executed once: the
/// damaged frame is not taken.
fn corrupted_host_byte_is_naked_or_dropped_and_the_host_retries<M: Modem>() {
    for k in 0..M::FRAME {
        let ex = with_fault::<M>(Dir::HostToModem, k, OneShot::Corrupt(0x80));
        let cause = match k {
            0 => LinkError::NoAck,
            1 => M::CUT_FRAME,
            _ => LinkError::Nak,
        };
        assert_eq!(ex.retries(), vec![cause], "byte {k}: {ex:#?}");
        let naks = usize::from(cause == LinkError::Nak);
        assert_eq!(ex.naks_received(), naks, "byte {k}: {ex:#?}");
        assert_eq!(ex.confirms::<M>(TAG), vec![Stx::First], "byte {k}: {ex:#?}");
    }
}

/// A host byte held back past T_IC: the frame is cut short, the late tail
/// ignored, the host starts over.
fn host_byte_delayed_past_t_ic_breaks_the_frame_and_the_host_retries<M: Modem>() {
    for k in 1..M::FRAME {
        let ex = with_fault::<M>(Dir::HostToModem, k, OneShot::Delay(PAST_T_IC));
        assert_eq!(ex.retries(), vec![M::CUT_FRAME], "byte {k}: {ex:#?}");
        let naks = usize::from(M::CUT_FRAME == LinkError::Nak);
        assert_eq!(ex.naks_received(), naks, "byte {k}: {ex:#?}");
        assert_eq!(ex.confirms::<M>(TAG), vec![Stx::First], "byte {k}: {ex:#?}");
    }
}

// ---- modem to host ------------------------------------------------------

/// The status message lost or damaged: without its `?`, or short of a
/// byte, it never came and the host starts over; a status byte damaged is
/// still a status message (any value is one): no harm done.
fn broken_status_message_makes_the_host_retry<M: Modem>() {
    for k in 0..M::STATUS {
        for fault in [OneShot::Drop, OneShot::Corrupt(0x80)] {
            let ex = with_fault::<M>(Dir::ModemToHost, k, fault);
            let harmless = k > 0 && matches!(fault, OneShot::Corrupt(_));
            let retries = if harmless {
                vec![]
            } else {
                vec![LinkError::NoStatus]
            };
            assert_eq!(ex.retries(), retries, "byte {k} {fault:?}: {ex:#?}");
            assert_eq!(
                ex.confirms::<M>(TAG),
                vec![Stx::First],
                "byte {k} {fault:?}: {ex:#?}"
            );
        }
    }
}

/// The modem's ACK lost or damaged: the host cannot tell it from a lost
/// frame, starts over, and the modem executes the request again. Each
/// confirm is a first transmission, so both are frames: two confirms, one
/// per attempt, never more (a documented limit).
fn lost_modem_ack_makes_the_modem_execute_twice_a_documented_limit<M: Modem>() {
    for fault in [OneShot::Drop, OneShot::Corrupt(0x80)] {
        let ex = with_fault::<M>(Dir::ModemToHost, M::m2h_ack(), fault);
        assert_eq!(ex.retries(), vec![LinkError::NoAck], "{fault:?}: {ex:#?}");
        assert_eq!(
            ex.confirms::<M>(TAG),
            vec![Stx::First, Stx::First],
            "{fault:?}: {ex:#?}"
        );
    }
}

// ---- random faults ------------------------------------------------------

/// Random byte faults both ways from the UART's own RNG (1 % each of
/// drop, corrupt, delay past T_IC), fixed seeds: nothing hangs, every
/// request ends once, every confirm is of a request made and comes at
/// most once per attempt, nothing forged gets through, and once the
/// faults stop the link works at once.
fn random_byte_faults_both_ways_then_clean<M: Modem>() {
    for seed in 1..=6 {
        let mut d = M::powered(seed, 57_600);
        let faults = ByteFaults {
            drop: 0.01,
            corrupt: 0.01,
            delay: 0.01,
            delay_by: PAST_T_IC,
        };
        d.set_faults(Dir::HostToModem, faults);
        d.set_faults(Dir::ModemToHost, faults);
        let start = d.events().len();
        let tags: Vec<u16> = (0..30).map(|i| 0x4000 | (i * 0x0101)).collect();
        let tickets: Vec<_> = tags
            .iter()
            .map(|&tag| {
                let t = d.submit_tagged(tag);
                d.run_for(60 * MS);
                t
            })
            .collect();
        d.run_for(10 * SEC);
        assert_eq!(d.pending(), 0, "{} seed {seed}", M::NAME);
        let events: Vec<&Event> = d.events()[start..].iter().map(|(_, e)| e).collect();
        let mut retried = 0;
        for (t, &tag) in tickets.iter().zip(&tags) {
            let ends = events.iter().filter(|e| faulty::ended(e, *t)).count();
            assert_eq!(ends, 1, "{} seed {seed}, {t:?}", M::NAME);
            let retries = events
                .iter()
                .filter(|e| matches!(e, Event::Retry { ticket, .. } if ticket == t))
                .count();
            retried += retries;
            let confirms = events
                .iter()
                .filter(|e| matches!(e, Event::Frame(f) if M::is_confirm(f, tag)))
                .count();
            assert!(
                confirms <= 1 + retries,
                "{} seed {seed}, {tag:04x}: {confirms} confirms, {retries} retries",
                M::NAME
            );
        }
        for e in &events {
            if let Event::Frame(f) = e {
                assert!(
                    M::is_syntax_error(f) || tags.iter().any(|&tag| M::is_confirm(f, tag)),
                    "{} seed {seed}: forged {f:?}",
                    M::NAME
                );
            }
        }
        assert!(
            retried > 0,
            "{} seed {seed}: the faults did nothing",
            M::NAME
        );
        d.set_faults(Dir::HostToModem, ByteFaults::default());
        d.set_faults(Dir::ModemToHost, ByteFaults::default());
        faulty::assert_link_works(&mut d, 0xF000 + seed as u16);
    }
}

/// A fault on a byte the exchange does not carry changes nothing: the
/// harness's byte count ([`fault_at`]) is right for both chips, so the
/// runs above hit what they name. One past the last byte each way of a
/// clean exchange lands on the next exchange's first byte instead.
fn faults_land_where_the_runs_say<M: Modem>() {
    let mut d = M::powered(1, 57_600);
    // Host to modem: the frame and the ACK of the confirm, then the next
    // exchange's STX.
    fault_at(&mut d, Dir::HostToModem, M::h2m_ack() + 1, OneShot::Drop);
    let clean = exchange(&mut d, TAG);
    assert_eq!(clean.retries(), vec![], "{}: {clean:#?}", M::NAME);
    let next = exchange(&mut d, TAG + 1);
    assert_eq!(
        next.retries(),
        vec![LinkError::NoAck],
        "{}: {next:#?}",
        M::NAME
    );
}

macro_rules! per_chip {
    ($($run:ident),* $(,)?) => {
        mod st7580 {
            $(#[test] fn $run() { super::$run::<plm_sim::HostDriver>() })*
        }
        mod st7570 {
            $(#[test] fn $run() { super::$run::<plm_sim::st7570::drive::ModemDriver>() })*
        }
    };
}

per_chip!(
    dropped_host_byte_is_never_answered_and_the_host_retries,
    corrupted_host_byte_is_naked_or_dropped_and_the_host_retries,
    host_byte_delayed_past_t_ic_breaks_the_frame_and_the_host_retries,
    broken_status_message_makes_the_host_retry,
    lost_modem_ack_makes_the_modem_execute_twice_a_documented_limit,
    random_byte_faults_both_ways_then_clean,
    faults_land_where_the_runs_say,
);
