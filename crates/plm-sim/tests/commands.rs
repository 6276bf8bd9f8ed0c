//! plm-core's host engine drives the simulated ST7580 through every request
//! of UM0932 Table 10, with the confirms, errors (Table 14) and indications
//! the manual gives.

use plm_core::link::host::{Event, LinkError};
use plm_core::link::{Element, LocalFrame};
use plm_core::st7580::mib::{index, MibObject, ModemConfig, PhyConfig};
use plm_core::st7580::{
    code, ActiveLayer, Command, DataRequest, ErrorCause, Modulation, ResetCause, Status,
    Temperature, TxParams,
};
use plm_core::time::MS;
use plm_sim::{Fault, HostDriver, Outcome, Sim, SimConfig};

fn driver(nodes: usize) -> HostDriver {
    let mut d = HostDriver::new(Sim::new(SimConfig {
        nodes,
        ..SimConfig::default()
    }));
    d.run_for(100 * MS);
    d
}

fn answer(d: &mut HostDriver, cmd: Command) -> Command {
    match d.request(&cmd, 2_000 * MS) {
        Outcome::Answer(a) => a,
        other => panic!("{cmd:?}: {other:?}"),
    }
}

fn read(d: &mut HostDriver, index: u8) -> Vec<u8> {
    match answer(d, Command::MibReadRequest { index }) {
        Command::MibReadConfirm { data } => data,
        other => panic!("read {index:02X}h: {other:?}"),
    }
}

fn write(d: &mut HostDriver, index: u8, data: Vec<u8>) {
    assert_eq!(
        answer(d, Command::MibWriteRequest { index, data }),
        Command::MibWriteConfirm
    );
}

fn phy(payload: &[u8], modulation: Modulation) -> DataRequest {
    DataRequest {
        params: TxParams {
            modulation,
            ..TxParams::default()
        },
        payload: payload.to_vec(),
    }
}

fn status(d: &HostDriver) -> Status {
    Status::from_message(&d.host.last_status().expect("a status message"))
}

#[test]
fn power_on_indicates_every_object_at_its_default() {
    let d = driver(1);
    let Command::BioResetIndication(r) = &d.frames()[0] else {
        panic!("{:?}", d.frames())
    };
    assert_eq!(r.reset_cause, ResetCause::PowerOn);
    assert!(r.autoreconfiguration_error && r.modem_config_error);
    assert!(r.phy_config_error && r.ss_key_error);
    assert_eq!(r.byte(), 0x3C);
}

#[test]
fn every_object_reads_its_factory_default_and_unknown_ones_are_refused() {
    let mut d = driver(1);
    for o in plm_core::st7580::mib::OBJECTS {
        assert_eq!(read(&mut d, o.index as u8), o.default, "{}", o.name);
    }
    assert_eq!(
        answer(&mut d, Command::MibReadRequest { index: 0x0B }),
        Command::MibReadError(ErrorCause::WrongParameterValue)
    );
}

#[test]
fn mib_write_read_erase_follow_the_access_rules() {
    let mut d = driver(1);
    let mut p = match MibObject::factory_default(index::PHY_CONFIG) {
        Some(MibObject::PhyConfig(p)) => p,
        _ => unreachable!(),
    };
    p.high_frequency = 110_000;
    p.tx_gain = 9;
    write(&mut d, index::PHY_CONFIG, p.encode());
    assert_eq!(PhyConfig::decode(&read(&mut d, index::PHY_CONFIG)), p);
    let refused = |d: &mut HostDriver, cmd| match answer(d, cmd) {
        Command::MibWriteError(c) | Command::MibEraseError(c) => c,
        other => panic!("{other:?}"),
    };
    // Wrong length (WPL), read-only object, out-of-range value (WPV).
    let short = Command::MibWriteRequest {
        index: 1,
        data: vec![0; 13],
    };
    assert_eq!(refused(&mut d, short), ErrorCause::WrongParameterLength);
    let ro = Command::MibWriteRequest {
        index: 0x0A,
        data: vec![0; 4],
    };
    assert_eq!(refused(&mut d, ro), ErrorCause::WrongParameterValue);
    let zero_timeout = Command::MibWriteRequest {
        index: 9,
        data: vec![0, 40, 10],
    };
    assert_eq!(
        refused(&mut d, zero_timeout),
        ErrorCause::WrongParameterValue
    );
    // Only the counters can be erased.
    let erase = |index| Command::MibEraseRequest { index };
    assert_eq!(refused(&mut d, erase(1)), ErrorCause::WrongParameterValue);
    assert_eq!(answer(&mut d, erase(6)), Command::MibEraseConfirm);
    assert_eq!(read(&mut d, 6), vec![0; 10]);
}

#[test]
fn ping_echoes_any_payload_and_unknown_codes_get_cmd_syntax_error() {
    let mut d = driver(1);
    let data: Vec<u8> = (0..=255u8).take(250).collect();
    assert_eq!(
        answer(&mut d, Command::PingRequest { data: data.clone() }),
        Command::PingConfirm { data }
    );
    for code in [0x77u8, 0x2D, 0x3E] {
        let odd = Command::Unknown { code, data: vec![] };
        assert_eq!(answer(&mut d, odd), Command::CmdSyntaxError { error: code });
    }
}

#[test]
fn software_reset_confirms_then_indicates_and_keeps_written_objects() {
    let mut d = driver(1);
    let mc = ModemConfig {
        access_mode: 0,
        sniffer_mode: true,
        crc_length: 1,
        dl_crc_on_phy_length: true,
    };
    write(&mut d, index::MODEM_CONFIG, mc.encode());
    write(&mut d, index::HOST_INTERFACE_TIMEOUT, vec![100, 30, 5]);
    assert_eq!(
        answer(&mut d, Command::BioResetRequest),
        Command::BioResetConfirm { confirm_data: 0 }
    );
    d.run_for(200 * MS);
    let Some(Command::BioResetIndication(r)) = d.frames().last().cloned() else {
        panic!("{:?}", d.frames())
    };
    assert_eq!(r.reset_cause, ResetCause::ResetRequest);
    assert!(!r.modem_config_error && r.phy_config_error && r.ss_key_error);
    assert!(r.autoreconfiguration_error);
    // Autoreconfiguration kept 00h; 09h is back at its default.
    assert_eq!(ModemConfig::decode(&read(&mut d, 0)), mc);
    assert_eq!(read(&mut d, 9), vec![0xC8, 0x28, 0x0A]);
}

#[test]
fn status_message_carries_live_bits() {
    let mut d = driver(1);
    answer(&mut d, Command::PingRequest { data: vec![] });
    let s = status(&d);
    assert!(s.configuration_status, "00h-02h still at their defaults");
    assert_eq!(s.active_layer, ActiveLayer::Dl, "factory MIB 00h is 11h");
    assert!(!s.transmitting);
    for i in 0..3u8 {
        let o = plm_core::st7580::mib::object(i).expect("object");
        let mut v = o.default.to_vec();
        if i == 0 {
            v[0] = 0x12; // SS layer
        } else {
            let last = v.len() - 1;
            v[last] ^= 1;
        }
        write(&mut d, i, v);
    }
    answer(&mut d, Command::PingRequest { data: vec![] });
    let s = status(&d);
    assert!(!s.configuration_status);
    assert_eq!(s.active_layer, ActiveLayer::Ss);
    // During a transmission the status says so (Table 8 bit 1), which is
    // "not now" (UM0932 3.2.8, docs/protocol-notes.md "Status message
    // availability"): the modem takes no frame and the host waits, so a
    // second data request is no longer refused with Busy: it goes out
    // after the first one's confirm, and the MIB read behind it too.
    let long = phy(&[0x55; 200], Modulation::BPskCoded);
    d.submit(&Command::PhyDataRequest(long.clone()));
    d.run_for(30 * MS);
    let start = d.events.len();
    d.submit(&Command::PhyDataRequest(long));
    let timeouts = plm_core::st7580::mib::object(9).expect("09h").default;
    assert_eq!(read(&mut d, 9), timeouts.to_vec());
    let seen: Vec<&Event> = d.events[start..].iter().map(|(_, e)| e).collect();
    let busy = seen
        .iter()
        .filter(|e| matches!(e, Event::Received(Element::Status(s)) if Status::from_message(s).transmitting))
        .count();
    assert!(busy > 10, "{busy} statuses said transmitting");
    let sent = |c: u8| {
        seen.iter()
            .position(|e| matches!(e, Event::Sent(Element::Frame { frame, .. }) if frame.code == c))
    };
    let confirmed = seen
        .iter()
        .position(|e| matches!(e, Event::Frame(f) if f.code == code::PHY_DATA_CONFIRM))
        .expect("PHY_DataConfirm at the end of the transmission");
    assert!(sent(code::PHY_DATA_REQUEST).expect("the second data request") > confirmed);
    assert!(
        seen.iter()
            .all(|e| !matches!(e, Event::Frame(f) if f.code == code::PHY_DATA_ERROR)),
        "no PHY_DataError"
    );
    let confirms = seen
        .iter()
        .filter(|e| matches!(e, Event::Frame(f) if f.code == code::PHY_DATA_CONFIRM))
        .count();
    assert_eq!(
        confirms, 2,
        "both transmissions confirmed before the MIB read"
    );
    // 06h: two transmitted, none refused.
    let counters = read(&mut d, 6);
    assert_eq!(&counters[4..8], &[0, 2, 0, 0]);
}

#[test]
fn a_hot_modem_refuses_to_transmit() {
    let mut d = driver(1);
    d.sim.inject(Fault::Temperature(Temperature::Above125));
    let dl = Command::DlDataRequest(phy(b"hot", Modulation::BPsk));
    assert_eq!(
        answer(&mut d, dl),
        Command::DlDataError(ErrorCause::ThermalError)
    );
    assert_eq!(status(&d).temperature, Temperature::Above125);
    assert_eq!(&read(&mut d, 7)[6..8], &[0, 1], "DL refused counter");
}

#[test]
fn data_requests_are_validated_like_the_chip() {
    let mut d = driver(1);
    let reserved = Command::PhyDataRequest(phy(b"x", Modulation::Reserved));
    assert_eq!(
        answer(&mut d, reserved),
        Command::PhyDataError(ErrorCause::WrongParameterValue)
    );
    // A DL payload that does not fit with its 4-byte CRC (factory CRC-32).
    let big = Command::DlDataRequest(phy(&[0; 252], Modulation::BPsk));
    assert_eq!(
        answer(&mut d, big),
        Command::DlDataError(ErrorCause::WrongParameterLength)
    );
    // Too short a data field for the request: WPL.
    let frame = LocalFrame::new(0x0C, vec![]);
    let cmd = Command::Unknown {
        code: frame.code,
        data: frame.data,
    };
    assert_eq!(
        answer(&mut d, cmd),
        Command::MibReadError(ErrorCause::WrongParameterLength)
    );
}

/// MIB 09h changes the modem's timeouts: with T_ACK 10 ms, a frame the
/// host does not acknowledge is repeated (STX 03h) 10 ms after its end.
#[test]
fn mib_09h_changes_the_timeouts() {
    let mut d = driver(1);
    write(&mut d, index::HOST_INTERFACE_TIMEOUT, vec![200, 10, 10]);
    let mut sim = d.sim;
    sim.host_read();
    let frame = Command::PingRequest { data: vec![7] }
        .to_frame()
        .emit(plm_core::link::Dialect::St7580)
        .unwrap();
    sim.set_treq(true);
    sim.advance_to(sim.now() + 5 * MS);
    let got = sim.host_read();
    assert_eq!(got.len(), 2, "status message");
    assert_eq!(got[0].1, plm_core::link::STATUS_FIRST);
    sim.write(&frame);
    sim.set_treq(false);
    sim.advance_to(sim.now() + 100 * MS);
    let got = sim.host_read();
    // ACK, then PingConfirm (02 01 2D 07 ck ck), then its repeat.
    assert_eq!(got[0].1, plm_core::link::ACK);
    let confirm = &got[1..7];
    assert_eq!(confirm[0].1, 0x02);
    let repeat = &got[7..13];
    assert_eq!(repeat[0].1, 0x03);
    let gap = repeat[0].0 - confirm[5].0;
    // The repeat's STX arrives one character time after it was written.
    let ch = plm_core::time::wire_time(1, sim.baud());
    assert_eq!(gap - ch, 10 * MS);
    assert_eq!(got.len(), 13, "one repeat only");
}

#[test]
fn a_transmitting_modem_takes_no_frame_from_a_host_that_ignores_the_status() {
    // A host that sends whatever the status says (issue 13, point 2).
    let mut d = driver(1);
    d.host.set_not_now(0, 10 * MS);
    let long = phy(&[0x55; 200], Modulation::BPskCoded);
    d.submit(&Command::PhyDataRequest(long));
    d.run_for(10 * MS);
    // Acked, the transmission runs for about 350 ms. A ping now is sent
    // after a status with bit 1 set: the modem ignores it (UM0932 3.2.8,
    // like a frame outside T_SR): no ACK, no NAK, every attempt.
    let start = d.events.len();
    let ticket = d.submit(&Command::PingRequest { data: vec![7] });
    d.run_until(
        2_000 * MS,
        |e| matches!(e, Event::Delivered(t) | Event::Failed(t, _) if *t == ticket),
    );
    let seen: Vec<&Event> = d.events[start..].iter().map(|(_, e)| e).collect();
    let no_acks = seen
        .iter()
        .filter(|e| {
            matches!(
                e,
                Event::Retry {
                    cause: LinkError::NoAck,
                    ..
                }
            )
        })
        .count();
    assert_eq!(no_acks, 2, "{seen:#?}");
    assert!(seen.contains(&&Event::Failed(ticket, LinkError::NoAck)));
    assert!(!seen
        .iter()
        .any(|e| matches!(e, Event::Received(Element::Nak))));
    // Three attempts within the transmission: none executed.
    d.run_for(500 * MS);
    let pings = d.events[start..]
        .iter()
        .filter(|(_, e)| matches!(e, Event::Frame(f) if f.code == code::PING_CONFIRM))
        .count();
    assert_eq!(pings, 0);
}
