//! The simulated transport in headless Chromium: plm-sim's modem in the
//! page, driven in real time by the page's timers through the console's
//! session, as the console runs it. `cargo xtask test` runs this with
//! wasm-bindgen-test-runner.
#![cfg(target_arch = "wasm32")]

mod browser;

use browser::{Driven, Exclusive};
use plm_console::session::{Outcome, Session};
use plm_console::transport::sim::SimTransport;
use plm_console::transport::{LinkState, Transport};
use plm_core::st7580::mib::index;
use plm_core::st7580::{Command, DataRequest, TxParams};
use plm_sim::{ByteFaults, Dir, Fault};
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

fn simulated(nodes: usize) -> Driven {
    let t = SimTransport::new(nodes, 57_600, 7);
    Driven::new(Session::new(
        Some(Box::new(t)),
        plm_core::link::Dialect::St7580,
    ))
}

#[wasm_bindgen_test]
async fn the_modem_boots_and_answers_ping_and_mib_reads_in_real_time() {
    let _page = Exclusive::take().await;
    let mut d = simulated(1);
    let start = plm_console::clock::page_now_us();
    // UM0932 4.2.9: the modem announces its power-on reset.
    d.booted(1_000.0).await;
    let elapsed_ms = (plm_console::clock::page_now_us() - start) / 1_000.0;
    // The simulated modem boots in 20 ms of virtual time, which follows
    // the page's clock: not instantly, and not seconds late.
    assert!(
        (15.0..500.0).contains(&elapsed_ms),
        "booted after {elapsed_ms} ms"
    );

    match d
        .ask(
            Command::PingRequest {
                data: vec![1, 2, 3],
            },
            1_000.0,
        )
        .await
    {
        Outcome::Answer { command, rtt } => {
            assert_eq!(
                command,
                Command::PingConfirm {
                    data: vec![1, 2, 3]
                }
            );
            // 8 bytes out, 8 back at 57600 baud, plus the status message
            // and T_REQ handshake: a few ms of link time.
            assert!(rtt > 1_000 && rtt < 100_000, "rtt {rtt} µs");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        d.answer(Command::MibReadRequest {
            index: index::FIRMWARE_VERSION
        })
        .await,
        Command::MibReadConfirm {
            data: vec![0x00, 0x42, 0x00, 0x97]
        }
    );
    let acks = d.session.ack_latency();
    assert!(acks.count >= 3, "{acks:?}");
    // T_ACK is 40 ms (UM0932 Table 32); the page answers well within it.
    assert!(acks.page.max < 40_000, "{acks:?}");
}

#[wasm_bindgen_test]
async fn a_dl_frame_to_an_echoing_peer_comes_back_as_a_dl_data_indication() {
    let _page = Exclusive::take().await;
    let mut d = simulated(2);
    d.booted(1_000.0).await;
    let payload = b"street 7".to_vec();
    let confirm = d
        .answer(Command::DlDataRequest(DataRequest {
            params: TxParams::default(),
            payload: payload.clone(),
        }))
        .await;
    assert!(matches!(confirm, Command::DlDataConfirm(_)), "{confirm:?}");
    let echoed = d
        .run_until(3_000.0, |d| {
            d.unsolicited()
                .iter()
                .any(|c| matches!(c, Command::DlDataIndication(i) if i.payload == payload))
        })
        .await;
    assert!(echoed, "no DL_DataIndication: {:?}", d.unsolicited());
}

#[wasm_bindgen_test]
async fn an_unplugged_cable_fails_requests_in_words_until_plugged_back() {
    let _page = Exclusive::take().await;
    let mut d = simulated(1);
    d.booted(1_000.0).await;
    let sim = |d: &mut Driven, f: Fault| {
        let t = d.session.transport_mut().expect("a transport");
        t.simulator().expect("simulated").inject(f);
    };
    sim(&mut d, Fault::Unplug);
    assert!(matches!(d.session.state(), LinkState::Disconnected(_)));
    // In flight and later: both fail at once with the reason.
    let outcome = d.ask(Command::PingRequest { data: vec![] }, 200.0).await;
    assert_eq!(
        outcome,
        Outcome::Failed(
            "the simulated cable is unplugged: plug it back in (Simulator view)".into()
        )
    );
    sim(&mut d, Fault::Plug);
    assert!(d.session.state().is_connected());
    assert_eq!(
        d.answer(Command::PingRequest { data: vec![4] }).await,
        Command::PingConfirm { data: vec![4] }
    );
}

#[wasm_bindgen_test]
async fn requests_get_through_a_uart_that_drops_and_corrupts_bytes() {
    let _page = Exclusive::take().await;
    let mut d = simulated(1);
    d.booted(1_000.0).await;
    let faults = ByteFaults {
        drop: 0.01,
        corrupt: 0.01,
        ..ByteFaults::default()
    };
    {
        let sim = d
            .session
            .transport_mut()
            .and_then(|t| t.simulator())
            .expect("simulated");
        sim.set_byte_faults(Dir::HostToModem, faults);
        sim.set_byte_faults(Dir::ModemToHost, faults);
    }
    let mut answered = 0;
    for i in 0..20u8 {
        // UM0932 3.2.7-3.2.8: NAKs and missing ACKs are repeated by the
        // link; a request may still fail after its last attempt.
        if let Outcome::Answer {
            command: Command::PingConfirm { data },
            ..
        } = d
            .ask(Command::PingRequest { data: vec![i; 8] }, 5_000.0)
            .await
        {
            assert_eq!(data, vec![i; 8], "a corrupted answer was taken");
            answered += 1;
        }
    }
    assert!(answered >= 15, "only {answered} of 20 pings answered");
    assert!(
        d.notes
            .iter()
            .any(|n| matches!(n, plm_console::session::Note::Retry { .. })),
        "the faults made the link repeat something"
    );
}

#[wasm_bindgen_test]
fn the_transport_says_what_it_is() {
    let t = SimTransport::new(3, 19_200, 1);
    assert_eq!(t.kind(), "Simulated");
    assert_eq!(t.port(), "ST7580 (simulated, 2 echoing peers)");
    assert_eq!(t.baud(), 19_200);
    assert!(t.state().is_connected());
}
