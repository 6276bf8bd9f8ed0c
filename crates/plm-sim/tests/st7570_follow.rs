//! The answering Servers take on the Client's bit rate, f0 and f1
//! (`NetConfig::servers_follow`, docs/protocol-notes.md "ST7570:
//! simulated network"): a Client set up as ST7570 UM 8 sets it up (MAC
//! Client, 2400 bit/s) reaches them; Servers kept at the factory
//! settings do not hear it.

mod st7570_host;

use plm_core::link::host::Event;
use plm_core::st7570::mib::PlcConfiguration;
use plm_core::st7570::{Address, Command, Credit, Layer, MacData};
use plm_core::time::MS;
use plm_sim::st7570::mode;
use plm_sim::st7570::net::{NetConfig, Network};
use st7570_host::{answer, write};

/// ST7570 UM 8: the data of its CMD_WriteDBRequest of 00A1h (MAC
/// Client, 2400 bit/s, 50 Hz, gain 10h, f0 74 kHz, f1 63.3 kHz, current
/// limiting enabled).
const SECTION_8: [u8; 14] = [
    0x09, 0x00, 0x10, 0x10, 0x21, 0x01, 0x44, 0xF7, 0x00, 0x00, 0x00, 0x00, 0x02, 0x01,
];

/// The Client's address (0001h's factory default, FIMA).
const CLIENT: u16 = 0x0C00;

/// Node 0 driven by the test; Servers 1, 2 and 3 (a repeater) answering.
fn line(servers_follow: bool) -> Network {
    let mut net = Network::new(NetConfig {
        responders: vec![(1, false), (2, false), (3, true)],
        servers_follow,
        ..NetConfig::new(4)
    });
    net.run_for(10 * MS);
    net
}

/// Writes 00A1h at node 0; the confirm's data.
fn set_up(net: &mut Network, data: &[u8]) -> Vec<u8> {
    let cmd = Command::WriteDbRequest {
        index: 0x00A1,
        data: data.to_vec(),
    };
    match answer(net, 0, cmd) {
        Command::WriteDbConfirm {
            index: 0x00A1,
            data,
        } => data,
        other => panic!("{other:?}"),
    }
}

/// Sends `m_sdu` to Server `da`; the MAC frames indicated to the Client
/// within 3 s after its confirm.
fn exchange(net: &mut Network, da: u16, m_sdu: &[u8]) -> Vec<MacData> {
    let request = Command::MacDataRequest(MacData {
        credit: Credit {
            ic: 0,
            cc: 0,
            dc: 0,
        },
        address: Address { sa: 0, da },
        pad: 0,
        m_sdu: m_sdu.to_vec(),
    });
    match answer(net, 0, request) {
        Command::DataConfirm { confirm_code } => assert_eq!(confirm_code, 0xFF, "LM_OK"),
        other => panic!("{other:?}"),
    }
    let from = net.nodes[0].driver.events.len();
    net.run_for(3_000 * MS);
    net.nodes[0].driver.events[from..]
        .iter()
        .filter_map(|(_, e)| match e {
            Event::Frame(f) => match Command::from_frame(f, Layer::Mac) {
                Ok(Command::MacDataIndication(m)) => Some(m),
                _ => None,
            },
            _ => None,
        })
        .collect()
}

fn plc(net: &Network, node: usize) -> PlcConfiguration {
    net.modem(node).mib().plc()
}

#[test]
fn servers_take_on_the_section_8_set_up_and_answer_it() {
    let mut net = line(true);
    assert_eq!(set_up(&mut net, &SECTION_8), SECTION_8);
    net.run_for(100 * MS);
    let client = plc(&net, 0);
    for s in 1..4 {
        let p = plc(&net, s);
        assert_eq!(
            (p.bit_rate_2400, p.f0, p.f1),
            (true, 74_000, 63_300),
            "Server {s}"
        );
        // Their own role and settings stay theirs.
        assert_eq!(
            (p.operating_mode, p.layer(), p.tx_current_limiting),
            (mode::SERVER, Some(Layer::Mac), false),
            "Server {s}"
        );
    }
    assert!(client.tx_current_limiting);
    let got = exchange(&mut net, 2, b"section 8");
    assert_eq!(got.len(), 1, "{got:?}");
    assert_eq!(got[0].address, Address { sa: 2, da: CLIENT });
    assert_eq!(got[0].m_sdu, b"section 8");
}

#[test]
fn factory_servers_do_not_hear_a_2400_bit_client() {
    let mut net = line(false);
    assert_eq!(set_up(&mut net, &SECTION_8), SECTION_8);
    net.run_for(100 * MS);
    for s in 1..4 {
        assert!(!plc(&net, s).bit_rate_2400, "Server {s}");
    }
    assert_eq!(exchange(&mut net, 2, b"section 8"), []);
    assert_eq!(net.nodes[2].responder.as_ref().unwrap().indicated, 0);
    // At the factory bit rate they answer.
    let mut factory = PlcConfiguration::decode(&SECTION_8);
    factory.bit_rate_2400 = false;
    set_up(&mut net, &factory.encode());
    assert_eq!(exchange(&mut net, 2, b"1200").len(), 1);
}

#[test]
fn servers_follow_a_later_change_of_tones_and_back_to_the_factory_ones() {
    let mut net = line(true);
    set_up(&mut net, &SECTION_8);
    assert_eq!(exchange(&mut net, 1, b"first").len(), 1);
    // Other tones (CENELEC A), once the Servers are synchronized.
    let mut other = PlcConfiguration::decode(&SECTION_8);
    other.f0 = 86_000;
    other.f1 = 72_000;
    set_up(&mut net, &other.encode());
    assert_eq!(exchange(&mut net, 1, b"second").len(), 1);
    assert_eq!((plc(&net, 3).f0, plc(&net, 3).f1), (86_000, 72_000));
    // CMD_ResetRequest with RESET = 1: the factory MIB (Table 24), IDLE
    // at 1200 bit/s; the Servers follow back.
    match answer(&mut net, 0, Command::ResetRequest { reset: 1 }) {
        Command::ResetRequest { reset: 0 } => {}
        other => panic!("{other:?}"),
    }
    net.run_for(100 * MS);
    for s in 1..4 {
        let p = plc(&net, s);
        assert_eq!((p.bit_rate_2400, p.f0, p.f1), (false, 74_000, 63_300));
    }
    let mut client = PlcConfiguration::decode(&SECTION_8);
    client.bit_rate_2400 = false;
    write(&mut net, 0, 0x00A1, &client.encode());
    assert_eq!(exchange(&mut net, 1, b"third").len(), 1);
}
