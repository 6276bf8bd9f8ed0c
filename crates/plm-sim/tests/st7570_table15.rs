//! Table 15 of the ST7570 user manual, code by code, in both access layers
//! (00A1h byte 12: PHY, MAC; issue 12, "Must show"): plm-core's host engine
//! (ST7570 dialect) asks a simulated ST7570 over its UART in virtual time,
//! on a line with a Client (node 0) to synchronize to, and each row says
//! the answer the manual gives: the confirm with its data, or the code it
//! refuses with when the state does not allow the request (Tables 43, 48,
//! 63; the MIB errors of 6.3) or CMD_SyntaxError (5.3.26).
//!
//! Codes and names come from plm-core's descriptions (`code::ALL`, the
//! name lists of `st7570::fields`, the MIB table): the rows say "LP_NS",
//! not 04h. Where the manual is silent the row says so and cites the
//! decision in docs/protocol-notes.md ("ST7570: simulated modem").

mod st7570_host;

use plm_core::link::host::Event;
use plm_core::st7570::code::{self, CommandType};
use plm_core::st7570::fields::{
    ALARM_CONFIRM_CODES, MAC_CONFIRM_CODES, MIB_ERRORS, PHY_CONFIRM_CODES, RC_RESULTS,
};
use plm_core::st7570::mib::{object, OPERATING_MODES};
use plm_core::st7570::{Address, Command, Credit, Layer, MacData, MacSync};
use plm_core::time::MS;
use plm_sim::st7570::drive::Outcome;
use plm_sim::st7570::net::{NetConfig, Network};
use plm_sim::st7570::{mode, NEW};
use st7570_host::{configure, write, MAC, PHY};
use Situation::*;

/// The modem under test; node 0 is a Client on the same line.
const DUT: usize = 1;

/// The state the modem under test is in when the request comes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Situation {
    /// 00A1h mode IDLE ("Not set"), as after a factory reset.
    Idle,
    /// 00A1h mode "Test on Ch.0": a continuous tone, no time slots.
    Test,
    /// A Client that has sent nothing yet.
    Client,
    /// A Client with a data request of its own on the line.
    ClientSending,
    /// A Client whose zero crossing is lost (ZC_FAIL, 3.6.8).
    ClientNoMains,
    /// A Server that heard nobody.
    Server,
    /// A Server synchronized on node 0's frame (local address NEW).
    ServerSynced,
    /// As [`ServerSynced`], then CMD_DesynchroRequest (5.3.3).
    ServerDesynced,
    /// As [`ServerSynced`], local address 001h, NEVER_REPEAT (000Bh).
    ServerNamed,
    /// As [`ServerNamed`], ALWAYS_REPEAT.
    Repeater,
    /// As [`Repeater`], with a data request of its own on the line.
    RepeaterSending,
    /// A Monitor that heard nobody.
    Monitor,
    /// A MAC Server searching with intelligent synchronization (0009h).
    IsRunning,
}

/// What the manual says comes back.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Want {
    /// Exactly this answer.
    Is(Command),
    /// An answer with this code whose first data byte is this (a
    /// CMD_RC_Confirm LP_OK of a Server carries what it heard).
    Head(u8, u8),
    /// The request is acknowledged and nothing answers it.
    Nothing,
}

/// One row: a request, in a layer and a situation, and its answer.
struct Row {
    section: &'static str,
    layer: Layer,
    situation: Situation,
    request: Command,
    want: Want,
}

/// The byte the manual's name stands for in one of plm-core's name lists.
fn named(names: &[&str], name: &str) -> u8 {
    names
        .iter()
        .position(|n| *n == name)
        .unwrap_or_else(|| panic!("{name} not in {names:?}")) as u8
}

fn data_confirm(layer: Layer, name: &str) -> Want {
    let names: &[&str] = match layer {
        Layer::Phy => &PHY_CONFIRM_CODES,
        Layer::Mac => &MAC_CONFIRM_CODES,
    };
    Want::Is(Command::DataConfirm {
        confirm_code: named(names, name),
    })
}

fn alarm_confirm(name: &str) -> Want {
    Want::Is(Command::AlarmConfirm {
        confirm_code: named(&ALARM_CONFIRM_CODES, name),
    })
}

/// A CMD_RC_Confirm without the Server's appended S, N, RX_POS.
fn rc_confirm(name: &str, repeater_state: u8) -> Want {
    Want::Is(Command::RcConfirm {
        result: named(&RC_RESULTS, name),
        repeater_state,
        heard: None,
    })
}

fn mib_error(write: bool, name: &str) -> Want {
    let error = named(&MIB_ERRORS, name);
    Want::Is(match write {
        true => Command::WriteDbError { error },
        false => Command::ReadDbError { error },
    })
}

const SYNTAX_ERROR: Want = Want::Is(Command::SyntaxError { error: 0x01 });

fn data_request(layer: Layer) -> Command {
    match layer {
        Layer::Phy => Command::PhyDataRequest {
            p_sdu: vec![0x5A; 38],
        },
        Layer::Mac => mac_request(b"table 15"),
    }
}

/// A broadcast MAC frame, IC 0.
fn mac_request(m_sdu: &[u8]) -> Command {
    Command::MacDataRequest(MacData {
        credit: Credit::default(),
        address: Address { sa: 0, da: 0xFFF },
        pad: 0,
        m_sdu: m_sdu.to_vec(),
    })
}

fn layer_byte(layer: Layer) -> u8 {
    match layer {
        Layer::Phy => PHY,
        Layer::Mac => MAC,
    }
}

fn rc(tx_pos: u16) -> Command {
    Command::RcRequest {
        tx_pos,
        rc_threshold: 0,
    }
}

fn wr(index: u16, data: &[u8]) -> Command {
    Command::WriteDbRequest {
        index,
        data: data.to_vec(),
    }
}

fn rd(index: u16) -> Command {
    Command::ReadDbRequest { index }
}

/// Runs until node `node` has sent its pending request and the frames
/// that go with its acceptance (a MAC Client's SYNC = FOUND, 10.3.1).
fn settle(net: &mut Network, node: usize) {
    net.run_until(1_000 * MS, |n, e| {
        n == node && matches!(e, Event::Delivered(_))
    });
    net.run_for(20 * MS);
}

/// A line with node 0 and the modem under test in `situation`.
fn build(layer: Layer, situation: Situation) -> Network {
    let mut net = Network::new(NetConfig::new(2));
    net.run_for(10 * MS);
    let l = layer_byte(layer);
    let dut_mode = match situation {
        Idle => mode::IDLE,
        Test => named(OPERATING_MODES, "Test on Ch.0"),
        Client | ClientSending | ClientNoMains => mode::CLIENT,
        Monitor => mode::MONITOR,
        _ => mode::SERVER,
    };
    configure(&mut net, DUT, dut_mode, l);
    if matches!(
        situation,
        ServerSynced | ServerDesynced | ServerNamed | Repeater | RepeaterSending
    ) {
        // A frame from node 0's Client: the Server synchronizes on its
        // PRE+SSD (4.6.1) and, in MAC mode, confirms on it (4.6).
        configure(&mut net, 0, mode::CLIENT, l);
        net.submit(0, &data_request(layer));
        net.run_for(1_000 * MS);
    }
    match situation {
        ClientSending => {
            net.submit(DUT, &data_request(layer));
            settle(&mut net, DUT);
        }
        ClientNoMains => net.set_mains_lost(DUT, true),
        ServerNamed | Repeater | RepeaterSending => {
            // Table 74: local 001h, unlocked (InitMACAdd 0).
            write(&mut net, DUT, 0x0001, &[0x01, 0x00, 0x00, 0x00]);
        }
        IsRunning => write(&mut net, DUT, 0x0009, &[1, 0]),
        ServerDesynced => {
            net.submit(DUT, &Command::DesynchroRequest { reset: 1 });
            settle(&mut net, DUT);
        }
        _ => {}
    }
    if matches!(situation, Repeater | RepeaterSending) {
        // Table 97: b1..b0 = 01b, ALWAYS_REPEAT.
        write(&mut net, DUT, 0x000B, &[0x01]);
    }
    if situation == RepeaterSending {
        net.submit(DUT, &data_request(layer));
        settle(&mut net, DUT);
    }
    net
}

/// The rows for the requests both layers answer alike (MIB, reset,
/// CMD_SyntaxError for what is no request).
fn both_layers(layer: Layer, rows: &mut Vec<Row>) {
    let mut row = |section, situation, request, want| {
        rows.push(Row {
            section,
            layer,
            situation,
            request,
            want,
        })
    };
    // 5.3.4, Tables 23-25: after the reset, 21h with RESET = 0, whether
    // the configuration is kept (0) or the factory defaults loaded (1).
    for reset in [0, 1] {
        let confirm = Want::Is(Command::ResetRequest { reset: 0 });
        row(
            "5.3.4",
            ServerSynced,
            Command::ResetRequest { reset },
            confirm,
        );
    }
    // 5.3.5-5.3.7, 6.3, Table 30.
    let alarm = object(0x0085).unwrap();
    let echo = Want::Is(Command::WriteDbConfirm {
        index: 0x0085,
        data: vec![4, 3, 5],
    });
    row("5.3.6", Idle, wr(0x0085, &[4, 3, 5]), echo);
    let unknown = mib_error(true, "ERR_UNAVAILABLE_RESOURCE");
    row("6.3 T70", Idle, wr(0x0017, &[0]), unknown);
    let length = mib_error(true, "ERR_ILLEGAL_DATA_COMMAND");
    row("6.5.26", Idle, wr(0x0085, &[4, 3]), length);
    let mut mode7 = st7570_host::plc(mode::IDLE, layer_byte(layer));
    mode7[0] = (mode7[0] & !0x07) | 7;
    let range = mib_error(true, "ERR_PARAM_VAL_OUTOFRANGE");
    row("6.5.30 T137", Idle, wr(0x00A1, &mode7), range);
    // 5.3.8-5.3.10, Table 35.
    let default = Want::Is(Command::ReadDbConfirm {
        index: 0x0085,
        data: alarm.default.to_vec(),
    });
    row("5.3.9", Idle, rd(0x0085), default);
    let unknown = mib_error(false, "ERR_UNAVAILABLE_RESOURCE");
    row("6.3 T70", Idle, rd(0x0017), unknown);
    // 6.5.29: 00A0h is written only (protocol-notes "MIB": 12h).
    let write_only = mib_error(false, "ERR_REQUEST_NOT_ALLOWED");
    row("6.5.29", Idle, rd(0x00A0), write_only);
    // 5.3.26: a 90h whose data is not an INDEX (protocol-notes
    // "ST7570: simulated modem", CMD_SyntaxError).
    let three = Command::Unknown {
        code: code::CMD_READ_DB_REQUEST,
        data: vec![0x85, 0x00, 0x00],
    };
    row("5.3.26", Idle, three, SYNTAX_ERROR);
    // 5.3.26: a code not in Table 15.
    let unknown = Command::Unknown {
        code: 0x33,
        data: vec![],
    };
    row("5.3.26", Idle, unknown, SYNTAX_ERROR);
    // Codes of Table 15 the host does not send (confirms, errors,
    // indications): CMD_SyntaxError (protocol-notes "ST7570: simulated
    // modem"; 5.3.26 names codes absent from Table 15).
    for c in code::ALL.iter().filter(|c| c.kind != CommandType::Request) {
        let not_a_request = Command::Unknown {
            code: c.code,
            data: vec![],
        };
        row("5.3.26", Idle, not_a_request, SYNTAX_ERROR);
    }
}

/// The line requests (51h, 88h) in every situation, with Tables 43 and
/// 48's codes.
fn line_requests(layer: Layer, rows: &mut Vec<Row>) {
    let (ns, tu, ok) = match layer {
        Layer::Phy => ("LP_NS", "LP_TU", "LP_OK"),
        Layer::Mac => ("LM_NS", "LM_TU", "LM_OK"),
    };
    let mut situations = vec![
        (Idle, ns, "LP_NS"),
        (Test, ns, "LP_NS"),
        (Client, ok, "LP_OK"),
        (ClientSending, tu, "LP_TU"),
        (ClientNoMains, ns, "LP_NS"),
        (Server, ns, "LP_NS"),
        (ServerSynced, ok, "LP_OK"),
        (ServerDesynced, ns, "LP_NS"),
        (Monitor, ns, "LP_NS"),
    ];
    if layer == Layer::Mac {
        situations.push((IsRunning, "LM_IS", "LP_IS"));
    }
    for (situation, data, alarm) in situations {
        rows.push(Row {
            section: "5.3.12-13 T43",
            layer,
            situation,
            request: data_request(layer),
            want: data_confirm(layer, data),
        });
        rows.push(Row {
            section: "5.3.15-16 T48",
            layer,
            situation,
            request: Command::AlarmRequest,
            want: alarm_confirm(alarm),
        });
    }
    // LM_SE (Table 43): a P_SDU is 38 bytes (Table 40), an M_SDU 1..242
    // (Table 41); the length is checked before the state.
    let short = match layer {
        Layer::Phy => Command::PhyDataRequest {
            p_sdu: vec![0x5A; 37],
        },
        Layer::Mac => mac_request(b""),
    };
    for situation in [Idle, ServerSynced] {
        rows.push(Row {
            section: "5.3.13 T43",
            layer,
            situation,
            request: short.clone(),
            want: data_confirm(layer, "LM_SE"),
        });
    }
}

/// Table 15 in PHY mode: what only PHY mode answers, or answers its own
/// way.
fn phy_rows(rows: &mut Vec<Row>) {
    let mut row = |section, situation, request, want| {
        rows.push(Row {
            section,
            layer: Layer::Phy,
            situation,
            request,
            want,
        })
    };
    // 5.3.2, Table 20: 1 LP_SYNC_FOUND, 2 LP_SYNC_LOSS. A PHY Client
    // makes the time slots: synchronized (protocol-notes "ST7570:
    // simulated modem", "Nobody on the line").
    for (situation, status) in [
        (Idle, 2),
        (Server, 2),
        (Monitor, 2),
        (ClientNoMains, 2),
        (ServerSynced, 1),
        (ServerDesynced, 2),
        (Client, 1),
    ] {
        let want = Want::Is(Command::SynchroStatus { status });
        row("5.3.2 T20", situation, Command::SynchroStatusRequest, want);
    }
    // 5.3.3, Table 21: "PHY mode: none".
    for situation in [Idle, ServerSynced] {
        let desync = Command::DesynchroRequest { reset: 1 };
        row("5.3.3 T21", situation, desync, Want::Nothing);
    }
    // Table 40: a PHY P_SDU is 38 bytes; a MAC request to a PHY modem is
    // one of another length.
    row(
        "5.3.13 T43",
        ServerSynced,
        mac_request(b"x"),
        data_confirm(Layer::Phy, "LM_SE"),
    );
    // 5.3.23: "If the node is set at PHY layer, the command does not take
    // any effect", even with a transmission in progress.
    for situation in [Client, ClientSending] {
        row("5.3.23", situation, rc(0), Want::Nothing);
    }
    // 6.5.12: in PHY mode 000Bh takes only the T_IC selector (b7).
    let repeater = mib_error(true, "ERR_ILLEGAL_DATA_COMMAND");
    row("6.5.12 T97", Idle, wr(0x000B, &[0x01]), repeater);
    // 6.5.1-6.5.23: the MAC objects do not exist in PHY mode (11h).
    row(
        "6.5.2",
        Idle,
        wr(0x0001, &[1, 0, 0, 0]),
        mib_error(true, "ERR_UNAVAILABLE_RESOURCE"),
    );
    row(
        "6.5.1",
        Idle,
        rd(0x0000),
        mib_error(false, "ERR_UNAVAILABLE_RESOURCE"),
    );
}

/// Table 15 in MAC mode: what only MAC mode answers, or answers its own
/// way.
fn mac_rows(rows: &mut Vec<Row>) {
    let mut row = |section, situation, request, want| {
        rows.push(Row {
            section,
            layer: Layer::Mac,
            situation,
            request,
            want,
        })
    };
    // 5.3.2: "Only in PHY mode" (protocol-notes: CMD_SyntaxError).
    row(
        "5.3.2",
        ServerSynced,
        Command::SynchroStatusRequest,
        SYNTAX_ERROR,
    );
    // 5.3.3, Tables 21, 18: SYNC = 4 (LOST), CAUSE = 5, ADD1 the local
    // address, ADD2 the initiator's (InitMACAdd, 0 when unlocked).
    for (situation, local) in [(ServerSynced, NEW), (ServerNamed, 0x001), (Server, NEW)] {
        let lost = Want::Is(Command::MacSynchroIndication(MacSync::Lost {
            cause: 5,
            add1: local,
            add2: 0,
        }));
        row(
            "5.3.3 T21",
            situation,
            Command::DesynchroRequest { reset: 1 },
            lost,
        );
    }
    // Table 22 defines RESET = 1 only (protocol-notes "ST7570:
    // simulated modem": another value does nothing).
    let reset0 = Command::DesynchroRequest { reset: 0 };
    row("5.3.3 T22", ServerSynced, reset0, Want::Nothing);
    // 6.5.29 note: writing 01h to 00A0h is CMD_DesynchroRequest; the write
    // is confirmed.
    let echo = Want::Is(Command::WriteDbConfirm {
        index: 0x00A0,
        data: vec![1],
    });
    row("6.5.29", ServerSynced, wr(0x00A0, &[1]), echo);
    // 5.3.23-5.3.24, Table 63. The Client calls at sub-slot 0 and gets no
    // appended data; REPEATER STATE is 000Bh's (0 NEVER_REPEAT by default).
    for (situation, tx_pos, want) in [
        (Idle, 0, rc_confirm("LP_NS", 0)),
        (Monitor, 0, rc_confirm("LP_NS", 0)),
        (Server, 0, rc_confirm("LP_NS", 0)),
        (IsRunning, 0, rc_confirm("LP_NS", 0)),
        // A MAC Client is synchronized by its first transmission (10.3.1).
        (Client, 0, rc_confirm("LP_NS", 0)),
        (ClientSending, 0, rc_confirm("LP_OK", 0)),
        // "local MAC Address = NEW, TxPosition = 0".
        (ServerSynced, 0, rc_confirm("LP_NI", 0)),
        (ServerSynced, 5, rc_confirm("LP_NOT_VALID", 0)),
        (ServerNamed, 0, rc_confirm("LP_NOT_VALID", 0)),
        // Accepted only while a transmission or reception is in progress
        // (7.3): none.
        (Repeater, 0, rc_confirm("LP_TU", 1)),
        (RepeaterSending, 0, Want::Head(code::CMD_RC_CONFIRM, 0xFF)),
    ] {
        row("5.3.23-24 T63", situation, rc(tx_pos), want);
    }
    // 6.3 and the objects' error tables: wrong mode (12h), read only
    // (12h), bad addresses (23h, 24h).
    let not_allowed = mib_error(true, "ERR_REQUEST_NOT_ALLOWED");
    row("6.5.22", Server, wr(0x0015, &[1]), not_allowed.clone());
    row("6.5.3", Monitor, wr(0x0002, &[5, 0]), not_allowed.clone());
    row("6.5.21", ServerSynced, wr(0x0014, &[0]), not_allowed);
    let local = mib_error(true, "ERR_ILLEGAL_LOCAL_MAC_ADR");
    row("6.5.2 T74", Server, wr(0x0001, &[0x00, 0x10, 0, 0]), local);
    let init = mib_error(true, "ERR_ILLEGAL_INITIATOR_MAC_ADR");
    row("6.5.2 T74", Server, wr(0x0001, &[0x01, 0, 0x01, 0]), init);
}

fn table_15() -> Vec<Row> {
    let mut rows = Vec::new();
    for layer in [Layer::Phy, Layer::Mac] {
        both_layers(layer, &mut rows);
        line_requests(layer, &mut rows);
    }
    phy_rows(&mut rows);
    mac_rows(&mut rows);
    rows
}

/// What the modem under test answers `request`, as the row sees it.
fn ask(net: &mut Network, request: &Command) -> Want {
    let asked = net.now();
    let got = net.request(DUT, request, 5_000 * MS);
    // 5.3.12: "If refused, the modem generates an immediate negative
    // CMD_DataConfirm"; the refusals of 88h and 61h alike (Tables 48, 63).
    if let Outcome::Answer(
        Command::DataConfirm { confirm_code: c }
        | Command::AlarmConfirm { confirm_code: c }
        | Command::RcConfirm { result: c, .. },
    ) = &got
    {
        let took = net.now() - asked;
        assert!(
            *c == 0xFF || took < 20 * MS,
            "{request:?}: refused after {took} µs"
        );
    }
    match got {
        Outcome::Answer(a) => match (&a, a.to_frame().data.first()) {
            (Command::RcConfirm { heard: Some(_), .. }, Some(&b)) => Want::Head(a.code(), b),
            _ => Want::Is(a),
        },
        Outcome::TimedOut => {
            let delivered = net.nodes[DUT]
                .driver
                .events
                .iter()
                .rev()
                .any(|(_, e)| matches!(e, Event::Delivered(_)));
            match delivered {
                true => Want::Nothing,
                false => panic!("{request:?}: not delivered"),
            }
        }
        Outcome::Failed(why) => panic!("{request:?}: {why:?}"),
    }
}

#[test]
fn every_code_of_table_15_in_both_layers_gets_the_manuals_answer() {
    let rows = table_15();
    let mut built: Vec<(Layer, Situation, Network)> = Vec::new();
    let mut wrong = Vec::new();
    for r in &rows {
        let at = built
            .iter()
            .position(|(l, s, _)| (*l, *s) == (r.layer, r.situation))
            .unwrap_or_else(|| {
                built.push((r.layer, r.situation, build(r.layer, r.situation)));
                built.len() - 1
            });
        let mut net = built[at].2.clone();
        let got = ask(&mut net, &r.request);
        if got != r.want {
            wrong.push(format!(
                "{} {:?} {:?} {:?}: want {:?}, got {:?}",
                r.section, r.layer, r.situation, r.request, r.want, got
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // Every code of Table 15 is asked in both layers.
    for layer in [Layer::Phy, Layer::Mac] {
        for c in code::ALL {
            assert!(
                rows.iter()
                    .any(|r| r.layer == layer && r.request.code() == c.code),
                "{} in {layer:?}",
                c.name
            );
        }
    }
}
