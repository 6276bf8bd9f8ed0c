//! plm-core's host engine (ST7570 dialect) drives the simulated ST7570 in
//! virtual time: the MIB of Table 71 with its defaults, writes, errors
//! (6.3) and counters, reset with and without auto-reconfiguration
//! (Tables 149-150), the status message of Table 11, CMD_SyntaxError
//! (5.3.26) and the confirm codes of Tables 43, 48 and 63.

use plm_core::link::host::Event;
use plm_core::st7570::mac::MacFrame;
use plm_core::st7570::mib::{object, PlcConfiguration, OBJECTS};
use plm_core::st7570::validate::error::*;
use plm_core::st7570::{
    Address, Command, Credit, Demodulation, Layer, MacData, MacSync, SignalNoise, Status,
};
use plm_core::time::MS;
use plm_sim::st7570::drive::{ModemDriver, Outcome};
use plm_sim::st7570::{mode, Heard, SlotUse, TestTone, NEW};

const PHY: u8 = 1;
const MAC: u8 = 2;

fn driver() -> ModemDriver {
    let mut d = ModemDriver::new(57_600);
    d.run_for(10 * MS);
    d
}

fn answer(d: &mut ModemDriver, cmd: Command) -> Command {
    match d.request(&cmd, 5_000 * MS) {
        Outcome::Answer(a) => a,
        other => panic!("{cmd:?}: {other:?}"),
    }
}

fn read(d: &mut ModemDriver, index: u16) -> Result<Vec<u8>, u8> {
    match answer(d, Command::ReadDbRequest { index }) {
        Command::ReadDbConfirm { index: i, data } if i == index => Ok(data),
        Command::ReadDbError { error } => Err(error),
        other => panic!("read {index:04X}h: {other:?}"),
    }
}

fn write(d: &mut ModemDriver, index: u16, data: &[u8]) -> Result<Vec<u8>, u8> {
    let cmd = Command::WriteDbRequest {
        index,
        data: data.to_vec(),
    };
    match answer(d, cmd) {
        Command::WriteDbConfirm { index: i, data } if i == index => Ok(data),
        Command::WriteDbError { error } => Err(error),
        other => panic!("write {index:04X}h: {other:?}"),
    }
}

fn plc(operating_mode: u8, layer: u8) -> Vec<u8> {
    let mut p = PlcConfiguration::decode(object(0x00A1).unwrap().default);
    p.operating_mode = operating_mode;
    p.access_layer_mode = layer;
    p.encode()
}

fn configure(d: &mut ModemDriver, operating_mode: u8, layer: u8) {
    let p = plc(operating_mode, layer);
    assert_eq!(write(d, 0x00A1, &p), Ok(p));
}

/// The status message the host got with its last request.
fn status(d: &ModemDriver) -> Status {
    Status::from_message(&d.host.last_status().expect("a status message")).unwrap()
}

/// Status as it is now: a read makes the host ask for it.
fn fresh_status(d: &mut ModemDriver) -> Status {
    read(d, 0x00A1).unwrap();
    status(d)
}

fn data_confirm(d: &mut ModemDriver, cmd: Command) -> u8 {
    match answer(d, cmd) {
        Command::DataConfirm { confirm_code } => confirm_code,
        other => panic!("{other:?}"),
    }
}

fn mac_request(ic: u8, da: u16, m_sdu: &[u8]) -> Command {
    Command::MacDataRequest(MacData {
        credit: Credit { ic, cc: ic, dc: 0 },
        address: Address { sa: 0, da },
        pad: 0,
        m_sdu: m_sdu.to_vec(),
    })
}

#[test]
fn every_object_reads_its_default_after_reset_in_both_layers() {
    let mut d = driver();
    for o in OBJECTS {
        let got = read(&mut d, o.index);
        let want = match (o.access.read, o.scope.phy) {
            (false, _) => Err(ERR_REQUEST_NOT_ALLOWED),
            (true, false) => Err(ERR_UNAVAILABLE_RESOURCE),
            (true, true) => Ok(o.default.to_vec()),
        };
        assert_eq!(got, want, "PHY {:04X}h {}", o.index, o.name);
    }
    configure(&mut d, mode::IDLE, MAC);
    for o in OBJECTS.iter().filter(|o| o.index != 0x00A1) {
        let want = if o.access.read {
            Ok(o.default.to_vec())
        } else {
            Err(ERR_REQUEST_NOT_ALLOWED)
        };
        assert_eq!(
            read(&mut d, o.index),
            want,
            "MAC {:04X}h {}",
            o.index,
            o.name
        );
    }
    assert_eq!(
        read(&mut d, 0x0017),
        Err(ERR_UNAVAILABLE_RESOURCE),
        "unused"
    );
}

#[test]
fn every_writable_object_is_confirmed_and_reads_back() {
    let mut d = driver();
    configure(&mut d, mode::SERVER, MAC);
    let values: &[(u16, &[u8])] = &[
        (0x0000, &[0x10, 0x0C, 0x00, 0x0D]),
        (0x0001, &[0x23, 0x01, 0x10, 0x0C]),
        (0x0002, &[5, 0]),
        (0x0003, &[60, 0]),
        (0x0004, &[10, 0]),
        (0x0005, &[1, 0, 2, 0, 3, 0, 4, 0, 5, 0]),
        (0x0008, &[0x03]),
        (0x0009, &[2, 0]),
        (0x000B, &[0x81]),
        (0x000C, &[0x10, 0x27, 0, 0]),
        (0x0012, &[0x34, 0x12]),
        (0x0013, &[1]),
        (0x0016, &[0x68, 0x29, 0, 0]),
        (0x0085, &[4, 3, 5]),
        (0x0086, &[0x01]),
        (0x00A4, &[0x02]),
        (0x00AB, &[4, 0, 0, 0]),
        (0x00AC, &[0x0A, 0, 0]),
        (0x00C2, &[2, 0, 0]),
        (0x00D1, &[0x10, 0, 0]),
    ];
    for (index, value) in values {
        assert_eq!(
            write(&mut d, *index, value).as_deref(),
            Ok(*value),
            "{index:04X}h"
        );
        assert_eq!(read(&mut d, *index).as_deref(), Ok(*value), "{index:04X}h");
    }
    // 6.5.24: written with 2 bytes, confirmed and read with 3 (the actual
    // gain); the gain is 00A1h's too (Table 149).
    assert_eq!(write(&mut d, 0x0082, &[1, 0x1A]), Ok(vec![1, 0x1A, 0x1A]));
    assert_eq!(read(&mut d, 0x0082), Ok(vec![1, 0x1A, 0x1A]));
    let p = PlcConfiguration::decode(&read(&mut d, 0x00A1).unwrap());
    assert_eq!((p.target_output_gain, p.tx_current_limiting), (0x1A, true));
    // 6.5.29: 00A0h is written, never read.
    assert_eq!(write(&mut d, 0x00A0, &[0]), Ok(vec![0]));
    // 6.5.22: only a Monitor writes 0015h.
    configure(&mut d, mode::MONITOR, MAC);
    assert_eq!(write(&mut d, 0x0015, &[1]), Ok(vec![1]));
    assert_eq!(read(&mut d, 0x0015), Ok(vec![1]));
    // Every writable object of Table 71 was written above or is a counter.
    for o in OBJECTS.iter().filter(|o| o.access.write) {
        let listed = values.iter().any(|(i, _)| *i == o.index)
            || [0x0082, 0x00A0, 0x00A1, 0x0015].contains(&o.index)
            || o.write.is_some();
        assert!(listed, "{:04X}h not written", o.index);
    }
}

#[test]
fn bad_writes_draw_the_error_the_chip_gives() {
    let mut d = driver();
    assert_eq!(
        write(&mut d, 0x0005, &[0; 10]),
        Err(ERR_UNAVAILABLE_RESOURCE),
        "PHY"
    );
    assert_eq!(
        write(&mut d, 0x000D, &[0; 10]),
        Err(ERR_REQUEST_NOT_ALLOWED),
        "read-only"
    );
    assert_eq!(
        write(&mut d, 0x0085, &[1, 2]),
        Err(ERR_ILLEGAL_DATA_COMMAND),
        "length"
    );
    assert_eq!(
        write(&mut d, 0x000B, &[0x81]),
        Err(ERR_ILLEGAL_DATA_COMMAND),
        "PHY 000Bh"
    );
    let mut bad = plc(mode::CLIENT, 3);
    assert_eq!(write(&mut d, 0x00A1, &bad), Err(ERR_PARAM_VAL_OUTOFRANGE));
    bad = plc(mode::SERVER, MAC);
    configure(&mut d, mode::SERVER, MAC);
    assert_eq!(
        write(&mut d, 0x0001, &[0, 0x10, 0, 0]),
        Err(ERR_ILLEGAL_LOCAL_MAC_ADR)
    );
    assert_eq!(
        write(&mut d, 0x0001, &[1, 0, 0, 0x0B]),
        Err(ERR_ILLEGAL_INITIATOR_MAC_ADR)
    );
    assert_eq!(
        write(&mut d, 0x0000, &[0, 0x10, 0, 0]),
        Err(ERR_ILLEGAL_INITIATOR_MAC_ADR)
    );
    assert_eq!(
        write(&mut d, 0x0015, &[1]),
        Err(ERR_REQUEST_NOT_ALLOWED),
        "not Monitor"
    );
    assert_eq!(
        read(&mut d, 0x00A0),
        Err(ERR_REQUEST_NOT_ALLOWED),
        "write-only"
    );
    // Nothing refused was stored.
    assert_eq!(read(&mut d, 0x00A1), Ok(bad));
    assert_eq!(read(&mut d, 0x0001), Ok(vec![0xFE, 0x0F, 0, 0]));
}

#[test]
fn counters_count_and_a_write_resets_them() {
    let mut d = driver();
    configure(&mut d, mode::CLIENT, MAC);
    // IC = 2: a Client sends 3 copies (4.8), each counted in 000Fh.
    assert_eq!(data_confirm(&mut d, mac_request(2, 0x123, b"hello")), 0xFF);
    d.run_for(1_000 * MS);
    assert_eq!(
        answer(&mut d, Command::AlarmRequest),
        Command::AlarmConfirm { confirm_code: 0xFF }
    );
    d.run_for(5_000 * MS);
    assert_eq!(read(&mut d, 0x000F), Ok(3u32.to_le_bytes().to_vec()));
    assert_eq!(
        read(&mut d, 0x0084),
        Ok(8u32.to_le_bytes().to_vec()),
        "N_TX = 8"
    );
    for index in [0x000F, 0x0084] {
        assert_eq!(
            write(&mut d, index, &[0xAA; 4]),
            Ok(vec![0; 4]),
            "{index:04X}h"
        );
        assert_eq!(read(&mut d, index), Ok(vec![0; 4]));
    }
    // 6.5.8: a write of 0007h puts it back to 7.
    assert_eq!(write(&mut d, 0x0007, &[0x55]), Ok(vec![7]));
}

#[test]
fn reset_with_and_without_auto_reconfiguration() {
    let mut d = driver();
    configure(&mut d, mode::SERVER, MAC);
    let groups = [1, 0, 2, 0, 3, 0, 4, 0, 5, 0];
    write(&mut d, 0x0005, &groups).unwrap();
    write(&mut d, 0x000B, &[0x83]).unwrap();
    write(&mut d, 0x0085, &[3, 3, 3]).unwrap();
    write(&mut d, 0x00AB, &[2, 0, 0, 0]).unwrap();
    assert!(!status(&d).reset, "hardware reset at power-on");
    // 5.3.4: confirmed with the same code, RESET = 0, after the reset.
    assert_eq!(
        answer(&mut d, Command::ResetRequest { reset: 0 }),
        Command::ResetRequest { reset: 0 }
    );
    // Tables 149-150 kept; 00ABh is in neither.
    assert_eq!(read(&mut d, 0x00A1), Ok(plc(mode::SERVER, MAC)));
    assert_eq!(read(&mut d, 0x0005), Ok(groups.to_vec()));
    assert_eq!(read(&mut d, 0x000B), Ok(vec![0x83]));
    assert_eq!(read(&mut d, 0x0085), Ok(vec![3, 3, 3]));
    assert_eq!(
        read(&mut d, 0x00AB),
        Ok(object(0x00AB).unwrap().default.to_vec())
    );
    let s = status(&d);
    assert!(s.reset && s.mac && s.repeater, "{s:?}");
    assert_eq!(s.mode, mode::SERVER);
    // RESET = 1: factory defaults, PHY IDLE again.
    assert_eq!(
        answer(&mut d, Command::ResetRequest { reset: 1 }),
        Command::ResetRequest { reset: 0 }
    );
    assert_eq!(read(&mut d, 0x00A1), Ok(plc(mode::IDLE, PHY)));
    assert_eq!(read(&mut d, 0x0005), Err(ERR_UNAVAILABLE_RESOURCE));
    assert_eq!(read(&mut d, 0x000B), Ok(vec![0]));
    assert!(status(&d).reset && !status(&d).mac);
    // A hardware reset restores too, and the status says so.
    configure(&mut d, mode::CLIENT, PHY);
    let now = d.now();
    d.port.modem.hardware_reset(now);
    d.run_for(50 * MS);
    assert_eq!(read(&mut d, 0x00A1), Ok(plc(mode::CLIENT, PHY)));
    assert!(!status(&d).reset);
}

#[test]
fn status_bits_follow_mode_and_layer() {
    let mut d = driver();
    let s = fresh_status(&mut d);
    assert_eq!((s.mode, s.mac, s.busy, s.fw_release), (0, false, false, 1));
    assert!(!s.synchronized());
    // A PHY Client makes the time slots: synchronized at once.
    configure(&mut d, mode::CLIENT, PHY);
    let s = fresh_status(&mut d);
    assert_eq!((s.mode, s.mac), (mode::CLIENT, false));
    assert!(s.synchronized());
    // Without the zero crossing there are no slots (ZC_FAIL, LP_NS).
    let now = d.now();
    d.port.modem.set_zc_fail(now, true);
    let s = fresh_status(&mut d);
    assert!(s.zc_fail && !s.synchronized());
    let p_sdu = Command::PhyDataRequest { p_sdu: vec![0; 38] };
    assert_eq!(data_confirm(&mut d, p_sdu), 0x04);
    let now = d.now();
    d.port.modem.set_zc_fail(now, false);
    assert!(fresh_status(&mut d).synchronized());
    // A MAC Client is synchronized by its first transmission (10.3.1).
    configure(&mut d, mode::CLIENT, MAC);
    assert!(!fresh_status(&mut d).synchronized());
    let t = d.submit(&mac_request(0, 0x123, b"x"));
    d.run_until(2_000 * MS, |e| matches!(e, Event::Delivered(x) if *x == t));
    let s = fresh_status(&mut d);
    assert!(s.busy && s.mac && s.synchronized(), "{s:?}");
    d.run_for(1_000 * MS);
    assert!(!fresh_status(&mut d).busy);
    assert!(matches!(
        d.frames(Layer::Mac)
            .iter()
            .find(|c| matches!(c, Command::MacSynchroIndication(_))),
        Some(Command::MacSynchroIndication(MacSync::Found(_)))
    ));
    // A MAC Server: NEW, not synchronized, MIN_CREDIT from 0007h,
    // REPEATER from 000Bh.
    configure(&mut d, mode::SERVER, MAC);
    let s = fresh_status(&mut d);
    assert_eq!(
        (s.mode, s.new, s.min_credit, s.repeater),
        (mode::SERVER, true, 7, false)
    );
    assert!(!s.synchronized());
    write(&mut d, 0x000B, &[0x01]).unwrap();
    write(&mut d, 0x0001, &[0x23, 0x01, 0, 0]).unwrap();
    let s = fresh_status(&mut d);
    assert!(s.repeater && !s.new);
    // Monitor and Test modes.
    configure(&mut d, mode::MONITOR, PHY);
    assert_eq!(fresh_status(&mut d).mode, mode::MONITOR);
    assert_eq!(d.port.modem.test_tone(), None);
    configure(&mut d, 4, PHY);
    assert_eq!(fresh_status(&mut d).mode, 0, "Test modes share MODE 0");
    // Table 137: a continuous tone on ch.0, ch.1, or both in turn.
    let p = PlcConfiguration::decode(&plc(0, PHY));
    assert_eq!(
        d.port.modem.test_tone(),
        Some((TestTone::Single(p.f0), p.target_output_gain))
    );
    configure(&mut d, 6, PHY);
    assert_eq!(
        d.port.modem.test_tone(),
        Some((TestTone::Alternate(p.f0, p.f1), 0x10))
    );
    let p_sdu = Command::PhyDataRequest { p_sdu: vec![0; 38] };
    assert_eq!(data_confirm(&mut d, p_sdu), 0x04, "no time slots");
}

#[test]
fn syntax_errors() {
    let mut d = driver();
    let syntax = Command::SyntaxError { error: 0x01 };
    let unknown = |code: u8, data: &[u8]| Command::Unknown {
        code,
        data: data.to_vec(),
    };
    assert_eq!(
        answer(&mut d, unknown(0x33, &[])),
        syntax,
        "not in Table 15"
    );
    assert_eq!(
        answer(&mut d, unknown(0x90, &[0, 0, 0])),
        syntax,
        "ReadDB length"
    );
    assert_eq!(
        answer(&mut d, unknown(0x21, &[])),
        syntax,
        "ResetRequest length"
    );
    assert_eq!(
        answer(&mut d, unknown(0x42, &[0, 0])),
        syntax,
        "a confirm code"
    );
    assert_eq!(answer(&mut d, unknown(0xB0, &[])), syntax, "a spy code");
    // 85h is a PHY command (5.3.2).
    assert_eq!(
        answer(&mut d, Command::SynchroStatusRequest),
        Command::SynchroStatus { status: 2 }
    );
    configure(&mut d, mode::CLIENT, MAC);
    assert_eq!(
        answer(&mut d, Command::SynchroStatusRequest),
        syntax,
        "85h in MAC"
    );
    // The modem still works.
    assert_eq!(read(&mut d, 0x00A1), Ok(plc(mode::CLIENT, MAC)));
}

#[test]
fn requests_refused_in_the_wrong_state_with_the_manuals_codes() {
    let mut d = driver();
    let p_sdu = |n: usize| Command::PhyDataRequest {
        p_sdu: vec![0x5A; n],
    };
    // IDLE runs no time slots: LP_NS.
    assert_eq!(data_confirm(&mut d, p_sdu(38)), 0x04);
    assert_eq!(
        answer(&mut d, Command::AlarmRequest),
        Command::AlarmConfirm { confirm_code: 0x04 }
    );
    // A P_SDU is 38 bytes: LM_SE first.
    assert_eq!(data_confirm(&mut d, p_sdu(37)), 0x03);
    // 5.3.23: CMD_RC_Request has no effect in PHY mode.
    let rc = Command::RcRequest {
        tx_pos: 0,
        rc_threshold: 0,
    };
    assert_eq!(d.request(&rc, 500 * MS), Outcome::TimedOut);
    // A Server has no synchronization with nobody on the line.
    configure(&mut d, mode::SERVER, MAC);
    assert_eq!(data_confirm(&mut d, mac_request(0, 0xFFF, b"x")), 0x04);
    assert_eq!(
        data_confirm(&mut d, mac_request(0, 0xFFF, b"")),
        0x03,
        "M_SDU 0"
    );
    let rc_confirm = |result, repeater_state| Command::RcConfirm {
        result,
        repeater_state,
        heard: None,
    };
    assert_eq!(answer(&mut d, rc.clone()), rc_confirm(0x04, 0));
    // An intelligent synchronization search runs for 0009h minutes: LM_IS,
    // then CMD_IS_Indication LM_NOT_LOCKED.
    write(&mut d, 0x0009, &[1, 0]).unwrap();
    assert_eq!(data_confirm(&mut d, mac_request(0, 0xFFF, b"x")), 0x05);
    assert_eq!(
        answer(&mut d, Command::AlarmRequest),
        Command::AlarmConfirm { confirm_code: 0x05 }
    );
    let found = d.run_until(
        61_000 * MS,
        |e| matches!(e, Event::Frame(f) if f.code == 0x15),
    );
    assert!(found);
    assert!(d.frames(Layer::Mac).contains(&Command::IsIndication {
        is_status: 0x02,
        locked: None
    }));
    assert_eq!(data_confirm(&mut d, mac_request(0, 0xFFF, b"x")), 0x04);
    // 5.3.3: CMD_DesynchroRequest in MAC mode answers LOST, CAUSE 5.
    assert_eq!(
        answer(&mut d, Command::DesynchroRequest { reset: 1 }),
        Command::MacSynchroIndication(MacSync::Lost {
            cause: 5,
            add1: NEW,
            add2: 0
        })
    );
    // A Client: one request at a time (LM_TU), an RC only with a
    // transmission in progress.
    configure(&mut d, mode::CLIENT, MAC);
    assert_eq!(
        answer(&mut d, rc.clone()),
        rc_confirm(0x04, 0),
        "not yet synchronized"
    );
    d.submit(&mac_request(0, 0x123, b"first"));
    assert_eq!(data_confirm(&mut d, mac_request(0, 0x123, b"second")), 0x00);
    assert_eq!(
        answer(&mut d, Command::AlarmRequest),
        Command::AlarmConfirm { confirm_code: 0x00 }
    );
    assert_eq!(
        answer(&mut d, rc.clone()),
        Command::RcConfirm {
            result: 0xFF,
            repeater_state: 0,
            heard: None
        }
    );
    d.run_for(1_000 * MS);
    assert_eq!(
        answer(&mut d, rc.clone()),
        rc_confirm(0x00, 0),
        "nothing in progress"
    );
    // 7.2.1: a second alarm request during the burst: LP_OK at once.
    let t0 = d.now();
    assert_eq!(
        answer(&mut d, Command::AlarmRequest),
        Command::AlarmConfirm { confirm_code: 0xFF }
    );
    assert!(d.now() - t0 > 8 * 300 * MS, "confirmed after the burst");
    let t1 = d.now();
    assert_eq!(
        answer(&mut d, Command::AlarmRequest),
        Command::AlarmConfirm { confirm_code: 0xFF }
    );
    assert!(d.now() - t1 < 100 * MS, "at once in the reject window");
}

#[test]
fn data_requests_leave_on_the_line_seam_in_time_slots() {
    let mut d = driver();
    configure(&mut d, mode::CLIENT, PHY);
    let p_sdu: Vec<u8> = (0..38).collect();
    let t0 = d.now();
    assert_eq!(
        data_confirm(
            &mut d,
            Command::PhyDataRequest {
                p_sdu: p_sdu.clone()
            }
        ),
        0xFF
    );
    let tx = d.port.modem.poll_line().expect("a PHY frame");
    assert_eq!(tx.slot, 300 * MS, "50 Hz, 1200 bit/s");
    assert!(
        tx.start > t0 && tx.start.is_multiple_of(tx.slot),
        "next slot"
    );
    assert_eq!(
        tx.slots,
        [SlotUse::Subframe(p_sdu.clone().try_into().unwrap())]
    );
    // Confirmed at the end of the frame, before its alarm window.
    assert!(d.now() >= tx.start + 280 * MS && d.now() < tx.end());
    // MAC: IC+1 copies of NS subframes, SA the local address, CC down.
    configure(&mut d, mode::CLIENT, MAC);
    let m_sdu = vec![0xA5; 100];
    assert_eq!(data_confirm(&mut d, mac_request(2, 0x123, &m_sdu)), 0xFF);
    let tx = d.port.modem.poll_line().expect("a MAC frame");
    let subframes: Vec<[u8; 38]> = tx
        .slots
        .iter()
        .map(|s| match s {
            SlotUse::Subframe(p) => *p,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(subframes.len(), 3 * 4, "100 bytes: NS = 4");
    for (k, copy) in subframes.chunks(4).enumerate() {
        let (fi, f) = MacFrame::from_subframes(copy).unwrap();
        assert_eq!(fi, 0);
        assert_eq!((f.address.sa, f.address.da), (0x0C00, 0x123), "SA = FIMA");
        assert_eq!((f.credit.ic, f.credit.cc), (2, 2 - k as u8));
        assert_eq!(f.m_sdu, m_sdu);
    }
}

#[test]
fn a_phy_server_synchronizes_on_what_it_hears() {
    let mut d = driver();
    configure(&mut d, mode::SERVER, PHY);
    assert_eq!(
        answer(&mut d, Command::SynchroStatusRequest),
        Command::SynchroStatus { status: 2 }
    );
    let heard = Heard {
        p_sdu: [0x42; 38],
        sn: SignalNoise {
            s0: 9000,
            n0: 3000,
            s1: 9100,
            n1: 3100,
        },
        pga: 3,
        phase: 1,
        demodulation: Demodulation {
            ask0: 0,
            ask1: 0,
            fsk: 304,
        },
        snr: (100, 200),
    };
    let now = d.now();
    assert!(d.port.modem.hear(now, &heard));
    d.run_for(100 * MS);
    let frames = d.frames(Layer::Phy);
    assert!(frames
        .iter()
        .any(|c| matches!(c, Command::PhySynchroIndication(e) if e.sn == heard.sn && e.pga == 3)));
    assert!(frames.iter().any(
        |c| matches!(c, Command::PhyDataIndication(i) if i.p_sdu == heard.p_sdu && i.snr0 == 100)
    ));
    assert_eq!(
        answer(&mut d, Command::SynchroStatusRequest),
        Command::SynchroStatus { status: 1 }
    );
    assert!(status(&d).synchronized());
    assert_eq!(
        data_confirm(&mut d, Command::PhyDataRequest { p_sdu: vec![1; 38] }),
        0xFF
    );
    // 6.5.14-6.5.15: the estimations of the last data indication.
    let le = |v: &[u32]| -> Vec<u8> {
        let mut out = Vec::new();
        for (i, x) in v.iter().enumerate() {
            let n = if i == 2 { 2 } else { 4 };
            out.extend_from_slice(&x.to_le_bytes()[..n]);
        }
        out
    };
    assert_eq!(read(&mut d, 0x000D), Ok(le(&[9000, 3000, 3])));
    assert_eq!(read(&mut d, 0x000E), Ok(le(&[9100, 3100, 1])));
    // Half duplex: the rest of its own slot, it hears nothing.
    let now = d.now();
    assert!(!d.port.modem.hear(now, &heard));
}

#[test]
fn alarms_heard_are_counted_indicated_and_flagged_once() {
    let mut d = driver();
    configure(&mut d, mode::SERVER, PHY);
    let sn = SignalNoise {
        s0: 8000,
        n0: 2000,
        s1: 8100,
        n1: 2100,
    };
    let now = d.now();
    assert!(
        !d.port.modem.hear_alarm(now, sn),
        "not synchronized: no slots"
    );
    configure(&mut d, mode::CLIENT, PHY);
    let slot = 300 * MS;
    // The alarm window of slot k: its last 3 bytes.
    let window = |k: u64| k * slot + 290 * MS;
    let k = d.now() / slot + 1;
    let alarm_in = |d: &mut ModemDriver, at: u64| {
        d.run_for(at - d.now());
        let now = d.now();
        d.port.modem.hear_alarm(now, sn)
    };
    let at = window(k);
    assert!(alarm_in(&mut d, at));
    assert!(
        fresh_status(&mut d).alarm,
        "the next status message says so"
    );
    assert!(!fresh_status(&mut d).alarm, "once only");
    let alarms = |d: &ModemDriver| {
        d.frames(Layer::Phy)
            .into_iter()
            .filter(|c| matches!(c, Command::AlarmIndication { .. }))
            .collect::<Vec<_>>()
    };
    assert!(alarms(&d).is_empty(), "N_RX = 2");
    let at = window(k + 1);
    assert!(alarm_in(&mut d, at), "the next slot");
    d.run_for(50 * MS);
    assert_eq!(
        alarms(&d),
        [Command::AlarmIndication { cnt: 2, long: None }]
    );
    // N_REJ = 9 slots of deafness.
    let at = window(k + 2);
    assert!(!alarm_in(&mut d, at));
    assert_eq!(read(&mut d, 0x0083), Ok(2u32.to_le_bytes().to_vec()));
    // 0086h b2 = 0: the long form, with the estimations.
    write(&mut d, 0x0086, &[0x00]).unwrap();
    let at = window(k + 12);
    assert!(alarm_in(&mut d, at));
    let at = window(k + 14);
    assert!(alarm_in(&mut d, at), "not consecutive: counts from 1");
    let at = window(k + 15);
    assert!(alarm_in(&mut d, at));
    d.run_for(50 * MS);
    assert_eq!(
        alarms(&d)[1..],
        [Command::AlarmIndication {
            cnt: 5,
            long: Some((sn, 0))
        }]
    );
}

#[test]
fn a_phy_monitor_searches_slot_by_slot_until_it_hears_a_subframe() {
    let mut d = driver();
    configure(&mut d, mode::MONITOR, PHY);
    let slot = 300 * MS;
    let t0 = d.now();
    d.run_for(3_000 * MS);
    let searching = |d: &ModemDriver| {
        d.events
            .iter()
            .filter(|(_, e)| matches!(e, Event::Frame(f) if f.code == 0xC0))
            .map(|(t, _)| *t)
            .collect::<Vec<_>>()
    };
    // 5.3.19: one at the start of each slot, nothing between.
    let starts = d.now() / slot - t0 / slot;
    let seen = searching(&d);
    assert_eq!(seen.len() as u64, starts, "{seen:?}");
    for t in &seen {
        assert!(t % slot < 10 * MS, "at a slot start: {t}");
    }
    let heard = Heard {
        p_sdu: [7; 38],
        sn: SignalNoise {
            s0: 1,
            n0: 2,
            s1: 3,
            n1: 4,
        },
        pga: 5,
        phase: 0,
        demodulation: Demodulation {
            ask0: 4,
            ask1: 0,
            fsk: 300,
        },
        snr: (6, 7),
    };
    let now = d.now();
    assert!(d.port.modem.hear(now, &heard));
    d.run_for(3_000 * MS);
    assert_eq!(
        searching(&d).len(),
        seen.len(),
        "synchronized: no more search"
    );
    let spy: Vec<Command> = d
        .frames(Layer::Phy)
        .into_iter()
        .filter(|c| c.code() >= 0xB0 && c.code() <= 0xD0)
        .filter(|c| *c != Command::SpySearchSynchroIndication)
        .collect();
    assert_eq!(spy.len(), 2, "{spy:?}");
    assert!(matches!(
        spy[0],
        Command::SpySynchroFoundIndication { pga: 5, .. }
    ));
    assert!(
        matches!(&spy[1], Command::SpySubframeIndication(s) if s.p_sdu == [7; 38] && s.snr1 == 7)
    );
}

/// ST7570 UM 5.3.26: a host frame whose length "has not been respected"
/// (cut short by T_IC) gets CMD_SyntaxError(01h), not a NAK (a NAK is
/// for a wrong checksum). Issue 13, point 5.
#[test]
fn a_host_frame_cut_short_gets_cmd_syntax_error_not_nak() {
    use plm_core::link::{Dialect, LocalFrame, ACK};
    use plm_sim::st7570::St7570;
    let mut m = St7570::new(57_600, 0);
    let drain = |m: &mut St7570, until: u64| {
        let mut out = Vec::new();
        while let Some(t) = m.poll_timeout().filter(|t| *t <= until) {
            m.handle_timeout(t);
        }
        while let Some(b) = m.poll_transmit() {
            out.extend(b);
        }
        out
    };
    // The reset indication first; ACK it.
    let _ = drain(&mut m, 5 * MS);
    m.handle_rx(5 * MS, &[ACK]);
    let _ = drain(&mut m, 60 * MS);
    m.set_treq(60 * MS, true);
    let status = drain(&mut m, 60 * MS);
    assert_eq!(status.first(), Some(&0x3F), "{status:02x?}");
    // A CMD_ReadDBRequest with its last two bytes missing.
    let req = LocalFrame::new(0x10, vec![0x00, 0x0B])
        .emit(Dialect::St7570)
        .unwrap();
    m.handle_rx(61 * MS, &req[..1]);
    m.set_treq(61 * MS, false);
    m.handle_rx(61 * MS + 200, &req[1..req.len() - 2]);
    let out = drain(&mut m, 100 * MS);
    let syntax = Command::SyntaxError { error: 0x01 }
        .to_frame()
        .emit(Dialect::St7570)
        .unwrap();
    // T_IC after the last byte: the frame, and nothing else (no NAK).
    assert_eq!(out, syntax, "{out:02x?}");
}
