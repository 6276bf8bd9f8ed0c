//! Fault injection on the UART of a simulated ST7570, with plm-core's
//! host engine (ST7570 dialect) as the host, in virtual time (issue 12,
//! "Must show": drop, corrupt, delay past T_IC, NAK storm, reset; no
//! confirmed frame lost or duplicated): what only the ST7570 does. The
//! runs both chips pass the same way are in `faults_both.rs`, the harness
//! (the request a MIB write of 0085h whose confirm names it) in
//! `faulty/mod.rs`.
//!
//! ST7570 UM 5.2.2: a broken modem frame is NAKed by the host and
//! repeated once after T_WBC, and a missed answer counts as ACK.

mod faulty;

use faulty::{
    assert_link_works, exchange, fault_at, with_fault, Exchange, Modem, PAST_T_IC, SEC, TAG,
};
use plm_core::link::host::{Event, LinkError};
use plm_core::link::Element;
use plm_core::st7570::mib::{index, object, PlcConfiguration};
use plm_core::st7570::{Address, Command, Credit, Layer, MacData, Status};
use plm_core::time::MS;
use plm_sim::st7570::drive::ModemDriver;
use plm_sim::st7570::mode;
use plm_sim::st7570::net::{NetConfig, Network};
use plm_sim::uart::OneShot;
use plm_sim::{ByteFaults, Dir};

const FRAME: usize = ModemDriver::FRAME;
// Modem to host in a clean exchange: the status (4 bytes), the ACK, the
// confirm.
const M2H_CONFIRM: usize = ModemDriver::STATUS + 1;
// Host to modem: the frame, then the ACK of the confirm.
const H2M_ACK: usize = FRAME;

// ---- host to modem ------------------------------------------------------

/// The host's ACK of the confirm lost: a missed answer counts as ACK
/// (5.2.2), so nothing is repeated and nothing is reported twice.
#[test]
fn lost_host_ack_counts_as_ack() {
    let ex = with_fault::<ModemDriver>(Dir::HostToModem, H2M_ACK, OneShot::Drop);
    assert!(ex.delivered());
    assert_eq!(ex.retries(), vec![]);
    assert_eq!(ex.confirms::<ModemDriver>(TAG).len(), 1, "{ex:#?}");
}

/// The host's ACK turned into NAK (06h ^ 13h = 15h): the modem repeats
/// the confirm after T_WBC, and the host takes it for the repeat it is.
#[test]
fn host_ack_read_as_nak_brings_a_repeat_reported_once() {
    let ex = with_fault::<ModemDriver>(Dir::HostToModem, H2M_ACK, OneShot::Corrupt(0x13));
    assert!(ex.delivered());
    assert_eq!(ex.confirms::<ModemDriver>(TAG).len(), 1, "{ex:#?}");
    let repeats = ex
        .events
        .iter()
        .filter(|e| matches!(e, Event::Repeat(f) if ModemDriver::is_confirm(f, TAG)))
        .count();
    assert_eq!(repeats, 1, "{ex:#?}");
}

// ---- modem to host ------------------------------------------------------

/// A confirm with a byte dropped, corrupted or held past T_IC: the host
/// NAKs what it got once the modem has finished sending it, the modem
/// repeats it once after T_WBC (5.2.2), and the host reports it once;
/// never twice, never lost. A frame whose STX is lost or whose length is
/// out of 3..250 is garbage, NAKed as T_IC ends it; a head cut by a stall
/// is NAKed when its announced length would have ended, or (STX alone)
/// its stalled tail is NAKed as garbage (docs/protocol-notes.md "ST7570:
/// link").
#[test]
fn broken_modem_frame_is_repeated_and_reported_once() {
    let confirm = M2H_CONFIRM;
    for k in confirm..confirm + FRAME {
        for fault in [
            OneShot::Drop,
            OneShot::Corrupt(0x08),
            OneShot::Delay(PAST_T_IC),
        ] {
            if k == confirm && fault == OneShot::Delay(PAST_T_IC) {
                continue; // a late STX is a whole frame, late
            }
            let ex = with_fault::<ModemDriver>(Dir::ModemToHost, k, fault);
            assert!(ex.delivered(), "byte {k} {fault:?}: {ex:#?}");
            assert_eq!(
                ex.confirms::<ModemDriver>(TAG).len(),
                1,
                "byte {k} {fault:?}: {ex:#?}"
            );
            assert!(ex.naks_sent() >= 1, "byte {k} {fault:?}: {ex:#?}");
        }
    }
}

/// The confirm's tail lost after its command byte: the host has the
/// length, so it holds the NAK of the head until the frame would have
/// ended. Sent as T_IC cut the head, the NAK would reach the modem while
/// it is still sending and be ignored (5.2.2: only an answer after the
/// frame counts), and the silence after it would count as ACK.
#[test]
fn modem_frame_whose_tail_is_lost_is_naked_when_it_would_have_ended() {
    let mut d = ModemDriver::powered(1, 57_600);
    fault_at(&mut d, Dir::ModemToHost, M2H_CONFIRM + 3, OneShot::Drop);
    for _ in M2H_CONFIRM + 4..M2H_CONFIRM + FRAME {
        d.wire(Dir::ModemToHost).inject(OneShot::Drop);
    }
    let ex = exchange(&mut d, TAG);
    assert!(ex.delivered(), "{ex:#?}");
    assert_eq!(ex.naks_sent(), 1, "{ex:#?}");
    assert_eq!(ex.confirms::<ModemDriver>(TAG).len(), 1, "{ex:#?}");
    assert_link_works(&mut d, 1);
}

/// What the link cannot recover (5.2.2): the modem repeats a NAKed frame
/// only once and takes the repeat as delivered whatever the answer, so a
/// confirm whose repeat is broken too is lost; only a confirm timeout
/// above the link can tell (the request was `Delivered`).
#[test]
fn a_broken_repeat_is_lost_a_documented_limit() {
    let mut d = ModemDriver::powered(1, 57_600);
    // The confirm's STX, then the repeat's (10 bytes later).
    fault_at(&mut d, Dir::ModemToHost, M2H_CONFIRM, OneShot::Drop);
    fault_at(&mut d, Dir::ModemToHost, FRAME - 1, OneShot::Drop);
    let ex = exchange(&mut d, TAG);
    assert!(ex.delivered(), "{ex:#?}");
    assert_eq!(ex.naks_sent(), 2, "{ex:#?}");
    assert_eq!(ex.confirms::<ModemDriver>(TAG).len(), 0, "{ex:#?}");
    assert_link_works(&mut d, 1);
}

// ---- NAK storm ----------------------------------------------------------

/// Every host frame reaches the modem damaged: NAK after NAK, and after
/// three attempts the host gives up once, with Nak; nothing was executed.
/// The storm over, the link works at once.
#[test]
fn nak_storm_fails_the_request_once_and_the_link_recovers() {
    let mut d = ModemDriver::powered(2, 57_600);
    // The checksum's low byte of every attempt flipped.
    for _ in 0..3 {
        fault_at(&mut d, Dir::HostToModem, FRAME - 2, OneShot::Corrupt(0x01));
    }
    let ex = exchange(&mut d, 0x5555);
    assert_eq!(ex.failed(), [LinkError::Nak], "{ex:#?}");
    assert!(!ex.delivered());
    assert_eq!(ex.naks_received(), 3);
    assert_eq!(
        ex.confirms::<ModemDriver>(0x5555).len(),
        0,
        "a NAKed frame is not executed"
    );
    assert_link_works(&mut d, 0x6666);
}

/// The modem's frames all damaged on the way: the host NAKs each, the
/// modem repeats each once and gives it up; the host reports none of
/// them twice and sends no answer to a repeat it already accepted.
#[test]
fn modem_frames_naked_are_repeated_once_and_never_doubled() {
    let mut d = ModemDriver::powered(3, 57_600);
    d.wire(Dir::ModemToHost).faults = ByteFaults {
        corrupt: 0.05,
        ..ByteFaults::default()
    };
    let mut confirms = 0;
    let mut tickets = Vec::new();
    for v in 0..30u16 {
        let ex = exchange(&mut d, 0x7000 + v);
        assert!(
            ex.confirms::<ModemDriver>(0x7000 + v).len() <= 1 + ex.retries().len(),
            "{ex:#?}"
        );
        confirms += ex.confirms::<ModemDriver>(0x7000 + v).len();
        tickets.push(ex);
    }
    let naks: usize = tickets.iter().map(Exchange::naks_sent).sum();
    assert!(naks > 0, "the faults did nothing");
    assert!(confirms >= 25, "{confirms} confirms of 30");
    d.wire(Dir::ModemToHost).faults = ByteFaults::default();
    assert_link_works(&mut d, 1);
}

// ---- reset --------------------------------------------------------------

/// RESETn pulsed while a write is under way, at every moment of the
/// exchange: the request ends once (confirmed or failed), is never
/// confirmed twice, and the modem comes back with its settings
/// (auto-reconfiguration, 7.1) and RESET = 0 in its status.
#[test]
fn reset_mid_request_ends_it_once() {
    let mut hit = 0;
    for at in (0..4_000).step_by(100) {
        let mut d = ModemDriver::powered(4, 57_600);
        let start = d.events.len();
        let ticket = d.submit(&faulty::write(0x4242));
        d.run_for(at);
        let now = d.now();
        d.port.modem.set_resetn(now, true);
        d.run_for(MS);
        let now = d.now();
        d.port.modem.set_resetn(now, false);
        d.run_until(
            10 * SEC,
            |e| matches!(e, Event::Delivered(t) | Event::Failed(t, _) if *t == ticket),
        );
        d.run_for(SEC);
        let ex = Exchange {
            ticket,
            events: d.events[start..].iter().map(|(_, e)| e.clone()).collect(),
        };
        let ends = ex
            .events
            .iter()
            .filter(|e| matches!(e, Event::Delivered(t) | Event::Failed(t, _) if *t == ticket))
            .count();
        assert_eq!(ends, 1, "reset at {at} µs: {ex:#?}");
        assert!(
            ex.confirms::<ModemDriver>(0x4242).len() <= 1,
            "reset at {at} µs: {ex:#?}"
        );
        if !ex.retries().is_empty() || ex.confirms::<ModemDriver>(0x4242).is_empty() {
            hit += 1;
        }
        assert_eq!(d.host.pending(), 0);
        assert_link_works(&mut d, at as u16);
        let status = Status::from_message(&d.host.last_status().unwrap()).unwrap();
        assert!(!status.reset, "RESET = 0: hardware");
    }
    // The exchange lasts about 3.5 ms at 57600 baud: most moments hit it.
    assert!(hit >= 20, "the reset hit {hit} exchanges of 40");
}

// ---- random faults ------------------------------------------------------

// ---- indications --------------------------------------------------------

/// A MAC Client whose UART drops, corrupts and delays bytes both ways,
/// and a Server echoing: every echo is indicated to the Client's host at
/// most once (a repeat after a NAK is reported as a repeat), and every
/// request ends once.
#[test]
fn indications_are_never_doubled_through_a_faulty_uart() {
    for seed in 1..=3 {
        let mut net = Network::new(NetConfig {
            seed,
            responders: vec![(1, false)],
            ..NetConfig::new(2)
        });
        net.run_for(10 * MS);
        let mut p = PlcConfiguration::decode(object(index::PLC_CONFIGURATION).unwrap().default);
        p.operating_mode = mode::CLIENT;
        p.access_layer_mode = Layer::Mac.access_layer_mode();
        let cmd = Command::WriteDbRequest {
            index: index::PLC_CONFIGURATION,
            data: p.encode(),
        };
        assert!(matches!(
            net.request(0, &cmd, 5 * SEC),
            plm_sim::st7570::drive::Outcome::Answer(Command::WriteDbConfirm { .. })
        ));
        net.run_for(200 * MS);
        let faults = ByteFaults {
            drop: 0.005,
            corrupt: 0.01,
            delay: 0.005,
            delay_by: PAST_T_IC,
        };
        net.node(0).wire(Dir::HostToModem).faults = faults;
        net.node(0).wire(Dir::ModemToHost).faults = faults;
        let start = net.nodes[0].driver.events.len();
        let mut tickets = Vec::new();
        for i in 0..20u8 {
            let m = MacData {
                credit: Credit {
                    ic: 0,
                    cc: 0,
                    dc: 0,
                },
                address: Address { sa: 0, da: 1 },
                pad: 0,
                m_sdu: vec![b'e', i, i ^ 0x5A],
            };
            tickets.push(net.submit(0, &Command::MacDataRequest(m)));
            net.run_for(1_500 * MS);
        }
        net.run_for(5 * SEC);
        let events: Vec<Event> = net.nodes[0].driver.events[start..]
            .iter()
            .map(|(_, e)| e.clone())
            .collect();
        for t in &tickets {
            let ends = events
                .iter()
                .filter(|e| matches!(e, Event::Delivered(x) | Event::Failed(x, _) if x == t))
                .count();
            assert_eq!(ends, 1, "seed {seed}, {t:?}");
        }
        let mut echoes: Vec<Vec<u8>> = events
            .iter()
            .filter_map(|e| match e {
                Event::Frame(f) => match Command::from_frame(f, Layer::Mac) {
                    Ok(Command::MacDataIndication(m)) => Some(m.m_sdu),
                    _ => None,
                },
                _ => None,
            })
            .collect();
        let n = echoes.len();
        echoes.sort();
        echoes.dedup();
        assert_eq!(echoes.len(), n, "seed {seed}: an indication doubled");
        let retried = events
            .iter()
            .filter(|e| matches!(e, Event::Retry { .. } | Event::Sent(Element::Nak)))
            .count();
        assert!(retried > 0, "seed {seed}: the faults did nothing");
        assert!(n >= 15, "seed {seed}: {n} echoes of 20");
    }
}
