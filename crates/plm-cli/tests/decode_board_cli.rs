//! `plm decode --board` end to end: the real binary decoding a street-light
//! controller board's USART (STEVAL-IHP007V1 UM 4.6, Appendix A), and the
//! `app` key `plm decode --chip st7580` adds to DL frames that carry an
//! application frame over the power line.

use plm_core::app::hid::{self, Hid};
use plm_core::app::service::{Clock, Service};
use plm_core::app::{Address, ErrorCode, LineFrame, Message};
use plm_core::link::Dialect;
use plm_core::st7580::{Command, DataRequest, TxParams};
use serde_json::{json, Value};
mod common;
use common::{decode, plm};

const BOARD: Address = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x2A]);

fn board(hex: &str) -> Vec<Value> {
    decode(&["decode", "--board", hex], None)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn wire(m: &Message) -> Vec<u8> {
    m.to(BOARD).emit().unwrap()
}

#[test]
fn a_clock_reply_shows_its_named_fields() {
    let bytes = wire(&Message::Service(Service::ClockNow(Clock {
        hours: 7,
        minutes: 45,
        seconds: 0,
    })));
    let lines = board(&hex(&bytes));
    assert_eq!(lines.len(), 1, "{lines:?}");
    let v = &lines[0];
    let crc = u16::from_be_bytes([bytes[12], bytes[13]]);
    assert_eq!(
        *v,
        json!({
            "kind": "frame",
            "hex": hex(&bytes),
            "length": 14,
            "code": 1,
            "frame_type": "APP_SERVICE_FRAME",
            "broadcast": false,
            "address": "0080e100002a",
            "command": "SERVICE_PLM_CLOCK_GET",
            "direction": "reply",
            "fields": {"hours": 7, "minutes": 45, "seconds": 0},
            "crc": crc,
            "crc_ok": true,
        })
    );
}

#[test]
fn hid_commands_and_replies_are_named_after_appendix_a() {
    let dim = wire(&Message::Hid(Hid::Dimming(40)));
    let get = wire(&Message::Hid(Hid::Get(0x07)));
    let reply = wire(&Message::Hid(Hid::Reply {
        param: 0x07,
        value: (-12i16).to_be_bytes().to_vec(),
    }));
    let ack = wire(&Message::Hid(Hid::Dimming(40)).ack());
    let lines = board(&format!(
        "{} {} {} {}",
        hex(&dim),
        hex(&get),
        hex(&reply),
        hex(&ack)
    ));
    assert_eq!(lines.len(), 4, "{lines:?}");
    assert_eq!(lines[0]["command"], "Lamp dimming");
    assert_eq!(lines[0]["fields"], json!({"dimming_value": 40}));
    assert_eq!(lines[1]["command"], "Get HID parameter");
    assert_eq!(lines[1]["direction"], "request");
    assert_eq!(
        lines[1]["fields"],
        json!({"param_to_get": "BOARD TEMPERATURE"})
    );
    assert_eq!(lines[2]["direction"], "reply");
    assert_eq!(
        lines[2]["fields"],
        json!({"param_to_get": "BOARD TEMPERATURE", "board_temperature": -12})
    );
    assert_eq!(lines[3]["command"], "APP_ACK_FRAME");
    assert_eq!(
        lines[3]["fields"],
        json!({"frame_type": "APP_DATA_FRAME", "command_echo": hid::SET})
    );
}

#[test]
fn an_error_frame_says_what_went_wrong() {
    let lines = board(&hex(&wire(&Message::Error(ErrorCode::HID_TIMEOUT))));
    let f = &lines[0]["fields"];
    assert_eq!(f["error_code"], 0x12);
    assert_eq!(f["error_name"], "HID board response timeout");
    assert!(
        f["meaning"].as_str().unwrap().contains("did not answer"),
        "{f}"
    );
}

#[test]
fn garbage_and_a_damaged_frame_are_shown_not_dropped() {
    let ping = wire(&Message::Ping);
    let mut damaged = wire(&Message::Ping);
    damaged[9] ^= 0xFF;
    let input = format!("ff {} {}", hex(&ping), hex(&damaged));
    let lines = board(&input);
    let kinds: Vec<&str> = lines.iter().map(|v| v["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["garbage", "frame", "frame"], "{lines:?}");
    assert_eq!(lines[0]["hex"], "ff");
    assert_eq!(lines[1]["crc_ok"], true);
    assert_eq!(lines[2]["crc_ok"], false);
    assert_eq!(lines[2]["command"], "APP_PING_FRAME");
    assert_eq!(lines[2]["hex"], hex(&damaged));
    let all: String = lines.iter().map(|v| v["hex"].as_str().unwrap()).collect();
    assert_eq!(all, input.replace(' ', ""), "no byte is lost");
}

#[test]
fn a_payload_that_does_not_fit_is_explained() {
    // SERVICE_PLM_CLOCK_GET with 1 data byte: neither request (0) nor
    // reply (3), 4.6.4.
    let f = plm_core::app::AppFrame::new(plm_core::app::FrameType::Service, BOARD, vec![0x08, 1]);
    let lines = board(&hex(&f.emit().unwrap()));
    assert_eq!(lines[0]["command"], "SERVICE_PLM_CLOCK_GET");
    assert_eq!(lines[0]["fields"], json!({"payload": "0801"}));
    let error = lines[0]["error"].as_str().unwrap();
    assert!(error.contains("not 1"), "{error}");
}

#[test]
fn reads_stdin_when_no_hex_is_given() {
    let bytes = hex(&wire(&Message::Service(Service::FwRelGet)));
    let spaced: String = bytes
        .as_bytes()
        .chunks(2)
        .map(|c| format!("{} ", std::str::from_utf8(c).unwrap()))
        .collect();
    let from_stdin = decode(&["decode", "--board"], Some(&format!("{spaced}\n")));
    assert_eq!(from_stdin, board(&bytes));
    assert_eq!(from_stdin[0]["command"], "SERVICE_FW_REL_GET");
    assert_eq!(from_stdin[0]["direction"], "request");
}

#[test]
fn board_and_chip_do_not_go_together() {
    let out = plm(&["decode", "--board", "--chip", "st7580", "00"], None);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--chip") && stderr.contains("--board"),
        "{stderr}"
    );
    let out = plm(&["decode", "--board", "--from", "host", "00"], None);
    assert!(!out.status.success());
}

#[test]
fn bad_hex_is_refused_with_a_message() {
    let out = plm(&["decode", "--board", "0a 0x"], None);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("not hex"), "{stderr}");
}

#[test]
fn a_dl_data_request_shows_the_application_frame_it_carries() {
    let concentrator = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x01]);
    let frame = Message::Hid(Hid::Get(hid::ALL)).to(BOARD);
    let line = LineFrame::from_app(&frame, concentrator);
    let cmd = Command::DlDataRequest(DataRequest {
        params: TxParams::default(),
        payload: line.emit(),
    });
    let bytes = cmd.to_frame().emit(Dialect::St7580).unwrap();
    let lines = decode(&["decode", "--chip", "st7580", &hex(&bytes)], None);
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0]["command"], "DL_DataRequest");
    let app = &lines[0]["fields"]["app"];
    assert_eq!(
        *app,
        json!({
            "kind": "frame",
            "hex": hex(&line.emit()),
            "code": 0,
            "frame_type": "APP_DATA_FRAME",
            "broadcast": false,
            "destination": "0080e100002a",
            "source": "0080e1000001",
            "command": "Get HID parameter",
            "direction": "request",
            "fields": {"param_to_get": "GET ALL PARAMETERS"},
        })
    );
}
