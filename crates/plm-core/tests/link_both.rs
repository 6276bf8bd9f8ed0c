//! The link tests both chips pass the same way, written once over the
//! chip ([`harness::chip::Chip`]): the host and device engines of one
//! dialect against each other, in virtual time, byte by byte (see
//! `harness/mod.rs`), checked against UM0932 3.2.5-3.2.9 and ST7570 UM
//! 5.2.2-5.2.3. What only one chip does is in `link_engines.rs` (ST7580)
//! and `st7570_link.rs`.

mod harness;

use harness::chip::{Chip, BOTH};
use harness::{
    first_wire, is_delivered, is_failed, is_repeat, is_retry, statuses_sent, Dir, Fault, Part,
};
use plm_core::link::device::DeviceEvent;
use plm_core::link::host::{Event, LinkError, Transmit};
use plm_core::link::{Element, StatusMessage, ACK};
use plm_core::time::wire_time;

const BAUD: u32 = 57_600;

/// One request and its answer, nothing going wrong.
fn happy_path(chip: &Chip, baud: u32) {
    let b1 = wire_time(1, baud);
    let mut sim = chip.bench(baud);
    let req = (chip.request)();
    let bytes = chip.emit(&req);
    let reply = (chip.confirm)(&req);
    let ticket = sim.submit(req.clone());
    sim.run_to_idle();

    // UM0932 3.2.8, ST7570 UM 5.2.2: T_REQ low, status, STX, T_REQ high
    // once STX is out, the rest of the frame; then the host ACKs the
    // modem's confirm.
    let tx: Vec<Transmit> = sim.host_tx.iter().map(|(_, t)| t.clone()).collect();
    assert_eq!(
        tx,
        vec![
            Transmit::TReq { asserted: true },
            Transmit::Bytes(vec![0x02]),
            Transmit::TReq { asserted: false },
            Transmit::Bytes(bytes[1..].to_vec()),
            Transmit::Bytes(vec![ACK]),
        ],
        "{}",
        chip.name
    );

    // What each side received: the status message (UM0932 Table 8,
    // ST7570 UM Table 11), the ACK, the confirm; the request, the ACK.
    let mut d2h = vec![0x3F];
    d2h.resize(chip.status_len, 0);
    d2h.push(ACK);
    d2h.extend(chip.emit(&reply));
    assert_eq!(sim.received(Dir::DevToHost), d2h, "{}", chip.name);
    let mut h2d = bytes.clone();
    h2d.push(ACK);
    assert_eq!(sim.received(Dir::HostToDev), h2d, "{}", chip.name);

    // Timing. The status goes out as soon as T_REQ falls (the modem is
    // idle), the STX as soon as the status is in, the ACK at once.
    let status_end = wire_time(chip.status_len, baud);
    let status: Vec<_> = sim
        .wire(Dir::DevToHost)
        .take(chip.status_len)
        .copied()
        .collect();
    assert_eq!(status[0].part, Part::Status { n: 0, offset: 0 });
    assert_eq!(
        (status[0].start, status[chip.status_len - 1].at),
        (0, status_end)
    );
    let stx = sim.frame_bytes(Dir::HostToDev, 0)[0];
    assert_eq!((stx.sent, stx.start), (0x02, status_end));
    // The device sees T_REQ released right when the STX is through.
    assert_eq!(sim.treq, vec![(0, true), (stx.at, false)]);
    let frame_end = sim.frame_end(Dir::HostToDev, 0);
    assert_eq!(frame_end, status_end + wire_time(bytes.len(), baud));
    let ack = first_wire(&sim, Dir::DevToHost, Part::Ack);
    assert_eq!(ack.start, frame_end);
    assert_eq!(
        sim.host_events_where(is_delivered),
        vec![(frame_end + b1, Event::Delivered(ticket))]
    );
    let idle = vec![0; chip.status_len - 1];
    assert_eq!(
        sim.host.last_status(),
        Some(StatusMessage::new(chip.dialect, &idle))
    );

    // The confirm: reported once, when its last byte is in, and ACKed.
    let reply_end = sim.frame_end(Dir::DevToHost, 0);
    assert_eq!(
        sim.host_events_where(|e| matches!(e, Event::Frame(_))),
        vec![(reply_end, Event::Frame(reply.clone()))]
    );
    assert_eq!(first_wire(&sim, Dir::HostToDev, Part::Ack).start, reply_end);
    assert!(sim
        .host_events_where(|e| is_retry(e) || is_failed(e) || is_repeat(e))
        .is_empty());

    // The device: one request, its confirm delivered without a repeat.
    assert_eq!(sim.requests(), vec![req]);
    assert_eq!(
        sim.dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. })),
        vec![(
            reply_end + b1,
            DeviceEvent::Delivered {
                frame: reply,
                repeated: false
            }
        )]
    );
    assert_eq!(sim.frame_bytes(Dir::DevToHost, 1), vec![], "no repeat");
    assert_eq!(sim.host.pending(), 0);
    assert!(sim.dev.is_idle());
}

#[test]
fn happy_path_57600() {
    for chip in &BOTH {
        happy_path(chip, 57_600);
    }
}

#[test]
fn happy_path_9600() {
    for chip in &BOTH {
        happy_path(chip, 9_600);
    }
}

/// T_REQ falls while the modem is sending a frame of its own: the host
/// ACKs that frame, and only then does the modem, master of the line
/// (UM0932 3.2.5, ST7570 UM 5.2.2), answer T_REQ with its status.
#[test]
fn modem_frame_while_host_waits_for_status() {
    for chip in &BOTH {
        let b1 = wire_time(1, BAUD);
        let mut sim = chip.bench(BAUD);
        let ind = (chip.indication)();
        sim.dev_submit(ind.clone());
        // Three bytes into the modem's frame, the host wants to send.
        sim.run_until(3 * b1);
        let req = (chip.request)();
        let ticket = sim.submit(req.clone());
        sim.run_to_idle();

        let ind_end = sim.frame_end(Dir::DevToHost, 0);
        assert_eq!(sim.treq[0], (3 * b1, true), "{}", chip.name);
        assert!(3 * b1 < ind_end, "T_REQ fell while the modem was sending");
        let h2d: Vec<_> = sim.wire(Dir::HostToDev).copied().collect();
        assert_eq!((h2d[0].part, h2d[0].start), (Part::Ack, ind_end));
        let status = first_wire(&sim, Dir::DevToHost, Part::Status { n: 0, offset: 0 });
        assert_eq!(status.start, ind_end + b1);
        assert_eq!(
            sim.frame_start(Dir::HostToDev, 0),
            status.start + wire_time(chip.status_len, BAUD)
        );

        // Host events in order: the indication, the status, its own
        // delivery, the confirm.
        let order: Vec<Event> = sim
            .host_events
            .iter()
            .map(|(_, e)| e.clone())
            .filter(|e| {
                matches!(
                    e,
                    Event::Frame(_) | Event::Delivered(_) | Event::Received(Element::Status(_))
                )
            })
            .collect();
        assert_eq!(order.len(), 4, "{}: {order:?}", chip.name);
        assert_eq!(order[0], Event::Frame(ind.clone()));
        assert!(matches!(order[1], Event::Received(Element::Status(_))));
        assert_eq!(order[2], Event::Delivered(ticket));
        assert_eq!(order[3], Event::Frame((chip.confirm)(&req)));
        assert!(sim
            .host_events_where(|e| is_retry(e) || is_failed(e) || is_repeat(e))
            .is_empty());
        assert_eq!(sim.requests(), vec![req]);
        assert_eq!(
            sim.dev_events_where(|e| matches!(e, DeviceEvent::Delivered { .. }))[0].1,
            DeviceEvent::Delivered {
                frame: ind,
                repeated: false
            }
        );
    }
}

/// A damaged byte of the host's frame: the modem NAKs it at once, and the
/// host restarts the whole sequence (UM0932 3.2.8 "a complete sequence
/// must be restarted", ST7570 UM 5.2.3): T_REQ high for T_IC, a fresh
/// edge, a new status, the frame again; the modem runs it once.
#[test]
fn nak_restarts_the_whole_sequence_and_the_modem_executes_once() {
    for chip in &BOTH {
        let mut sim = chip.bench(BAUD);
        let t_ic = sim.host.config().timeouts.t_ic;
        sim.inject(Dir::HostToDev, Some(1), Fault::Corrupt(0xFF), |c| {
            c.part.is_frame_byte(0, 3)
        });
        let req = (chip.request)();
        let ticket = sim.submit(req.clone());
        sim.run_to_idle();

        let received = sim.dev_received();
        assert!(
            matches!(
                &received[0].1,
                Element::Frame {
                    checksum_ok: false,
                    ..
                }
            ),
            "{}: {received:?}",
            chip.name
        );
        let nak = first_wire(&sim, Dir::DevToHost, Part::Nak);
        assert_eq!(nak.start, sim.frame_end(Dir::HostToDev, 0), "NAK at once");
        assert_eq!(
            sim.host_events_where(is_retry),
            vec![(
                nak.at,
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause: LinkError::Nak
                }
            )]
        );
        let stx0 = sim.frame_bytes(Dir::HostToDev, 0)[0];
        let stx1 = sim.frame_bytes(Dir::HostToDev, 1)[0];
        assert_eq!(
            sim.treq,
            vec![
                (0, true),
                (stx0.at, false),
                (nak.at + t_ic, true),
                (stx1.at, false)
            ],
            "{}",
            chip.name
        );
        assert_eq!(statuses_sent(&sim), vec![0, nak.at + t_ic]);
        let again: Vec<u8> = sim
            .frame_bytes(Dir::HostToDev, 1)
            .iter()
            .map(|w| w.got.unwrap())
            .collect();
        assert_eq!(again, chip.emit(&req));

        let end1 = sim.frame_end(Dir::HostToDev, 1);
        assert_eq!(
            sim.host_events_where(is_delivered),
            vec![(end1 + wire_time(1, BAUD), Event::Delivered(ticket))]
        );
        assert!(sim.host_events_where(is_failed).is_empty());
        assert_eq!(
            sim.requests(),
            vec![req.clone()],
            "exactly one accepted request"
        );
        assert_eq!(sim.host_frames(), vec![(chip.confirm)(&req)]);
    }
}

/// The modem's ACK of the host's frame is lost: the host waits T_ACK and
/// restarts the whole sequence. Local frames carry no sequence number
/// (UM0932 3.2, ST7570 UM Table 10): the modem cannot tell the restarted
/// frame from a new request, so it runs the request twice and confirms
/// twice, and the host, which ACKed the first confirm while it still
/// waited for its own ACK, reports both. Layers above must match
/// confirms to requests with this in mind.
#[test]
fn a_lost_ack_restarts_the_sequence_after_t_ack_and_the_modem_runs_the_request_twice() {
    for chip in &BOTH {
        let mut sim = chip.bench(BAUD);
        let t = sim.host.config().timeouts;
        sim.inject(Dir::DevToHost, Some(1), Fault::Drop, |c| {
            c.part == Part::Ack
        });
        let req = (chip.request)();
        let ticket = sim.submit(req.clone());
        sim.run_to_idle();

        let end0 = sim.frame_end(Dir::HostToDev, 0);
        assert_eq!(
            sim.host_events_where(is_retry),
            vec![(
                end0 + t.t_ack,
                Event::Retry {
                    ticket,
                    attempt: 1,
                    cause: LinkError::NoAck
                }
            )],
            "{}",
            chip.name
        );
        // The whole sequence again: T_REQ low after T_IC high, a new
        // status, the same frame.
        let stx1 = sim.frame_bytes(Dir::HostToDev, 1)[0];
        assert_eq!(
            sim.treq[2..],
            [(end0 + t.t_ack + t.t_ic, true), (stx1.at, false)]
        );
        assert_eq!(statuses_sent(&sim), vec![0, end0 + t.t_ack + t.t_ic]);
        let end1 = sim.frame_end(Dir::HostToDev, 1);
        assert_eq!(
            sim.host_events_where(is_delivered),
            vec![(end1 + wire_time(1, BAUD), Event::Delivered(ticket))]
        );
        assert!(sim.host_events_where(is_failed).is_empty());
        assert_eq!(sim.requests(), vec![req.clone(), req.clone()]);
        let confirm = (chip.confirm)(&req);
        assert_eq!(sim.host_frames(), vec![confirm.clone(), confirm]);
        assert!(sim.host_events_where(is_repeat).is_empty());
    }
}
