//! `plm decode` end to end: the real binary, real arguments, real JSON.

use plm_core::link::Dialect;
use plm_core::st7580::code::ALL;
use plm_core::st7580::{
    Channel, Command, DataConfirm, DataIndication, DataRequest, ErrorCause, FrequencySet,
    IndicationInfo, Modulation, ResetCause, ResetData, Temperature, TxParams,
};
use serde_json::{json, Map, Value};
mod common;
use common::{decode, plm};

fn decode_st7580(hex: &str) -> Vec<Value> {
    decode(&["decode", "--chip", "st7580", hex], None)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn wire(cmd: &Command) -> Vec<u8> {
    cmd.to_frame().emit(Dialect::St7580).unwrap()
}

fn fields(v: &Value) -> &Map<String, Value> {
    v["fields"]
        .as_object()
        .unwrap_or_else(|| panic!("no fields in {v}"))
}

/// PHY configuration factory default (UM0932 Table 52): 86 kHz / 72 kHz.
const PHY_DEFAULT: [u8; 14] = [
    0x01, 0x4F, 0xF0, 0x01, 0x19, 0x40, 0x0E, 0x15, 0x00, 0x00, 0x02, 0x35, 0x9B, 0x58,
];

fn params(modulation: Modulation, tx_frequency: Option<u32>, tx_gain: Option<u8>) -> TxParams {
    TxParams {
        modulation,
        frequency_set: FrequencySet::High,
        frequency_overwrite: false,
        zero_crossing_sync: tx_frequency.is_some(),
        tx_frequency,
        tx_gain,
    }
}

fn info(modulation: Modulation, pga: u8, snr: u8, zc_delay: i16) -> IndicationInfo {
    IndicationInfo {
        modulation,
        rx_channel: Channel::High,
        pga,
        snr,
        zc_delay,
    }
}

fn confirm(max_temp: Temperature, min_temp: Temperature, zc_delay: i16) -> DataConfirm {
    DataConfirm {
        max_temp,
        max_gain: 20,
        min_temp,
        min_gain: 18,
        overcurrent_events: 3,
        overcurrent: true,
        zc_delay,
    }
}

/// A command of every code of UM0932 with the named fields `plm decode`
/// must show for it (an empty map: no field at all).
fn cases() -> Vec<(Command, Value)> {
    use Command::*;
    vec![
        (BioResetRequest, json!({})),
        (
            BioResetConfirm { confirm_data: 0 },
            json!({"confirm_data": 0}),
        ),
        (
            BioResetError(ErrorCause::Busy),
            json!({"error_data": "Busy"}),
        ),
        (
            BioResetIndication(ResetData {
                reset_cause: ResetCause::ResetRequest,
                autoreconfiguration_error: true,
                modem_config_error: false,
                phy_config_error: true,
                ss_key_error: false,
            }),
            json!({
                "reset_cause": "BIO_ResetRequest",
                "autoreconfiguration_error": true,
                "autoreconfiguration_modem_config_object_error": false,
                "autoreconfiguration_phy_config_object_error": true,
                "autoreconfiguration_ss_key_object_error": false,
            }),
        ),
        (
            MibWriteRequest {
                index: 0x01,
                data: PHY_DEFAULT.to_vec(),
            },
            json!({
                "index": 1,
                "object": "PHY configuration",
                "high_frequency": 86000,
                "low_frequency": 72000,
                "tx_gain": 21,
                "current_control": true,
                "psk_preamble_length": "32 bit",
                "fsk_bit_rate": "2400 bps",
                "fsk_unique_word_length": "16 bit",
            }),
        ),
        (MibWriteConfirm, json!({})),
        (
            MibWriteError(ErrorCause::WrongParameterValue),
            json!({"error_data": "Wrong parameter value (WPV)"}),
        ),
        (
            MibReadRequest { index: 0x09 },
            json!({"index": 9, "object": "Host interface timeout"}),
        ),
        (
            MibReadConfirm {
                data: vec![0x00, 0x42, 0x00, 0x97],
            },
            json!({"data": "00420097"}),
        ),
        (
            MibReadError(ErrorCause::WrongParameterLength),
            json!({"error_data": "Wrong parameter length (WPL)"}),
        ),
        (
            MibEraseRequest { index: 0x06 },
            json!({"index": 6, "object": "PHY_Data"}),
        ),
        (MibEraseConfirm, json!({})),
        (
            MibEraseError(ErrorCause::GeneralError),
            json!({"error_data": "General error"}),
        ),
        (
            PingRequest {
                data: vec![1, 2, 3],
            },
            json!({"data": "010203"}),
        ),
        (PingConfirm { data: vec![0xAA] }, json!({"data": "aa"})),
        (
            PhyDataRequest(DataRequest {
                params: params(Modulation::QPsk, None, None),
                payload: b"Hello".to_vec(),
            }),
            json!({
                "frame_modulation": "Q-PSK",
                "custom_mib_frequency": "MIB",
                "frequency_set": "HighFrequency",
                "gain_selector": "MIB",
                "zero_crossing_synchronization": false,
                "payload": "48656c6c6f",
            }),
        ),
        (
            PhyDataConfirm(confirm(Temperature::From70To100, Temperature::Below70, -7)),
            json!({
                "max_temp": "70 °C < T < 100 °C",
                "max_gain": 20,
                "min_temp": "T < 70 °C",
                "min_gain": 18,
                "overcurrent_events_number": 3,
                "overcurrent_notification": true,
                "zc_delay": -7,
            }),
        ),
        (
            PhyDataError(ErrorCause::ThermalError),
            json!({"error_data": "Thermal error"}),
        ),
        (
            PhyDataIndication(DataIndication {
                info: info(Modulation::BPsk, 7, 12, 100),
                payload: vec![0xDE, 0xAD],
            }),
            json!({
                "frame_modulation": "B-PSK",
                "rx_channel": "high channel",
                "pga_value": 7,
                "snr": 12,
                "zc_delay": 100,
                "phy_payload": "dead",
            }),
        ),
        (
            DlDataRequest(DataRequest {
                params: params(Modulation::BPskCoded, Some(86_000), Some(20)),
                payload: vec![0x01],
            }),
            json!({
                "frame_modulation": "B-PSK coded",
                "custom_mib_frequency": "Custom",
                "tx_frequency": 86000,
                "gain_selector": "Custom",
                "tx_gain": 20,
                "zero_crossing_synchronization": true,
                "payload": "01",
            }),
        ),
        (
            DlDataConfirm(confirm(Temperature::Below70, Temperature::Below70, -300)),
            json!({"zc_delay": -300, "overcurrent_notification": true}),
        ),
        (
            DlDataError(ErrorCause::Other(0x42)),
            json!({"error_data": 0x42}),
        ),
        (
            DlDataIndication(DataIndication {
                info: info(Modulation::EightPsk, 15, (-3i8) as u8, -1),
                payload: vec![0x10, 0x20],
            }),
            json!({
                "frame_modulation": "8-PSK",
                "pga_value": 15,
                "snr": -3,
                "zc_delay": -1,
                "dl_payload": "1020",
            }),
        ),
        (
            DlSnifferIndication(DataIndication {
                info: info(Modulation::BFsk, 2, 0xFF, 0),
                payload: vec![0x01, 0xC0, 0xFF, 0xEE],
            }),
            // UM0932 Table 39: SNR 255 means "no meaning" for FSK frames.
            json!({
                "frame_modulation": "B-FSK",
                "snr": null,
                "dl_payload_and_wrong_crc": "01c0ffee",
            }),
        ),
        (
            SsDataRequest(plm_core::st7580::SsDataRequest {
                params: params(Modulation::BPskCodedPna, None, Some(31)),
                header_length: 4,
                header_and_payload: vec![0xA0, 0xA1, 0xA2, 0xA3, 0x01, 0x02, 0x03, 0x04],
            }),
            json!({
                "frame_modulation": "B-PSK coded with Peak Noise Avoidance",
                "gain_selector": "Custom",
                "tx_gain": 31,
                "header_length": 4,
                "header_and_payload": "a0a1a2a301020304",
            }),
        ),
        (
            SsDataConfirm(confirm(Temperature::Above125, Temperature::From100To125, 0)),
            json!({
                "max_temp": "T > 125 °C",
                "min_temp": "100 °C < T < 125 °C",
                "zc_delay": 0,
            }),
        ),
        (SsDataError(ErrorCause::Busy), json!({"error_data": "Busy"})),
        (
            SsDataIndication(DataIndication {
                info: info(Modulation::QPskCoded, 1, 20, 5),
                payload: vec![1, 2, 3, 4, 5],
            }),
            json!({
                "frame_modulation": "Q-PSK coded",
                "snr": 20,
                "ss_header_and_payload": "0102030405",
            }),
        ),
        (
            SsSnifferIndication(DataIndication {
                info: info(Modulation::BPsk, 0, 3, 0),
                payload: vec![0x55; 20],
            }),
            json!({"snr": 3, "pga_value": 0, "ss_sdu": "55".repeat(20)}),
        ),
        (CmdSyntaxError { error: 0x77 }, json!({"error": 0x77})),
    ]
}

#[test]
fn every_command_code_decodes_with_its_name_and_fields() {
    let cases = cases();
    for (code, name, _) in ALL {
        let (cmd, expected) = cases
            .iter()
            .find(|(c, _)| c.code() == *code)
            .unwrap_or_else(|| panic!("no case for {name} ({code:02X}h)"));
        let bytes = wire(cmd);
        let data = cmd.data();
        let lines = decode_st7580(&hex(&bytes));
        assert_eq!(lines.len(), 1, "{name}: {lines:?}");
        let v = &lines[0];
        let ctx = format!("{name}: {v}");
        assert_eq!(v["kind"], "frame", "{ctx}");
        assert_eq!(v["command"], *name, "{ctx}");
        assert_eq!(v["code"], *code, "{ctx}");
        assert_eq!(v["stx"], 2, "{ctx}");
        assert_eq!(v["length"], data.len(), "{ctx}");
        assert_eq!(v["checksum_ok"], true, "{ctx}");
        let sum = data.iter().fold(data.len() as u16 + *code as u16, |a, b| {
            a.wrapping_add(*b as u16)
        });
        assert_eq!(v["checksum"], sum, "{ctx}");
        assert_eq!(v["hex"], hex(&bytes), "{ctx}");
        assert!(v.get("error").is_none(), "{ctx}");
        assert!(v.get("warning").is_none(), "{ctx}");
        assert!(v.get("from").is_none(), "{ctx}");
        let got = fields(v);
        let want = expected.as_object().unwrap();
        if want.is_empty() {
            assert!(got.is_empty(), "{ctx}");
        }
        for (key, value) in want {
            assert_eq!(got.get(key), Some(value), "{ctx}: field {key}");
        }
    }
}

#[test]
fn zc_delay_and_frequencies_are_json_numbers() {
    let cmd = Command::DlDataConfirm(confirm(Temperature::Below70, Temperature::Below70, -300));
    let v = &decode_st7580(&hex(&wire(&cmd)))[0];
    assert_eq!(fields(v)["zc_delay"].as_i64(), Some(-300));
    let cmd = Command::MibWriteRequest {
        index: 1,
        data: PHY_DEFAULT.to_vec(),
    };
    let v = &decode_st7580(&hex(&wire(&cmd)))[0];
    assert_eq!(fields(v)["high_frequency"].as_u64(), Some(86_000));
}

#[test]
fn reads_stdin_when_no_hex_is_given() {
    let args = ["decode", "--chip", "st7580"];
    let from_stdin = decode(&args, Some("02 00 2c\n2c 00\n"));
    assert_eq!(from_stdin, decode_st7580("02002c2c00"));
    assert_eq!(from_stdin[0]["command"], "PingRequest");
}

#[test]
fn dots_and_colons_separate_bytes() {
    let plain = decode_st7580("02 01 0c 01 0e 00");
    assert_eq!(plain[0]["command"], "MIB_ReadRequest");
    assert_eq!(decode_st7580("02.01.0c.01.0e.00"), plain);
    assert_eq!(decode_st7580("02:01:0C:01:0E:00"), plain);
    // Several arguments are one input.
    let split = decode(
        &["decode", "--chip", "st7580", "02:01", "0c.01", "0e", "00"],
        None,
    );
    assert_eq!(split, plain);
}

#[test]
fn only_the_modem_sends_status_messages() {
    let host = decode(
        &["decode", "--chip", "st7580", "--from", "host", "3f 08"],
        None,
    );
    assert_eq!(host.len(), 1);
    assert_eq!(host[0]["kind"], "garbage");
    assert_eq!(host[0]["reason"], "unexpected");
    assert_eq!(host[0]["hex"], "3f08");
    assert_eq!(host[0]["from"], "host");

    let modem = decode(
        &["decode", "--chip", "st7580", "--from", "modem", "3f 08"],
        None,
    );
    assert_eq!(modem.len(), 1);
    assert_eq!(modem[0]["kind"], "status");
    assert_eq!(modem[0]["from"], "modem");
    // UM0932 Table 8: 08h = bits 3-4 equal to 1, the DL layer.
    assert_eq!(fields(&modem[0])["active_layer"], "DL layer");
    assert_eq!(fields(&modem[0])["transmission_status"], false);
}

#[test]
fn a_bad_checksum_is_reported_not_refused() {
    let out = plm(&["decode", "--chip", "st7580", "02 00 2c 2c 01"], None);
    assert_eq!(out.status.code(), Some(0));
    let lines = decode_st7580("02 00 2c 2c 01");
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0]["kind"], "frame");
    assert_eq!(lines[0]["command"], "PingRequest");
    assert_eq!(lines[0]["checksum_ok"], false);
    assert_eq!(lines[0]["checksum"], 0x012C);
    assert_eq!(lines[0]["hex"], "02002c2c01");
}

#[test]
fn an_unknown_code_has_a_null_command_and_keeps_its_data() {
    let lines = decode_st7580(&hex(&Command::Unknown {
        code: 0x77,
        data: vec![0xAB],
    }
    .to_frame()
    .emit(Dialect::St7580)
    .unwrap()));
    assert_eq!(lines.len(), 1);
    let v = &lines[0];
    assert_eq!(v["kind"], "frame");
    assert_eq!(
        v.get("command"),
        Some(&Value::Null),
        "present and null: {v}"
    );
    assert_eq!(v["code"], 0x77);
    assert_eq!(v["checksum_ok"], true);
    assert_eq!(fields(v)["data"], "ab");
}

#[test]
fn bad_hex_is_refused_with_a_message() {
    let out = plm(&["decode", "--chip", "st7580", "02 0g"], None);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("not hex"), "{stderr}");
    assert!(stderr.contains('g'), "names the character: {stderr}");
}

#[test]
fn the_chip_must_be_given() {
    let out = plm(&["decode", "02 00 2c 2c 00"], None);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--chip"), "{stderr}");
}

#[test]
fn a_read_confirm_is_named_by_the_request_before_it() {
    let request = wire(&Command::MibReadRequest { index: 0x01 });
    let confirm = wire(&Command::MibReadConfirm {
        data: PHY_DEFAULT.to_vec(),
    });
    let both = format!("{} {}", hex(&request), hex(&confirm));
    let lines = decode_st7580(&both);
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0]["command"], "MIB_ReadRequest");
    assert_eq!(lines[1]["command"], "MIB_ReadConfirm");
    let f = fields(&lines[1]);
    assert_eq!(f["index"], 1);
    assert_eq!(f["object"], "PHY configuration");
    assert_eq!(f["high_frequency"], 86000);
    assert_eq!(f["low_frequency"], 72000);

    // Alone, the confirm cannot be named...
    let alone = decode_st7580(&hex(&confirm));
    assert!(fields(&alone[0]).get("object").is_none());
    assert_eq!(fields(&alone[0])["data"], hex(&PHY_DEFAULT));
    // ...unless the user says which object was read.
    let told = decode(
        &[
            "decode",
            "--chip",
            "st7580",
            "--mib-index",
            "01h",
            &hex(&confirm),
        ],
        None,
    );
    assert_eq!(fields(&told[0])["object"], "PHY configuration");
}

#[test]
fn a_mixed_stream_gives_one_line_per_element() {
    let ping = hex(&wire(&Command::PingConfirm { data: vec![7] }));
    let lines = decode(
        &[
            "decode",
            "--chip",
            "st7580",
            "--from",
            "modem",
            &format!("3f08 06 {ping} 15 aabb"),
        ],
        None,
    );
    let kinds: Vec<&str> = lines.iter().map(|v| v["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["status", "ack", "frame", "nak", "garbage"]);
    assert_eq!(lines[4]["hex"], "aabb");
}

#[test]
fn a_repeat_is_named_and_an_ack_after_it_is_late() {
    // PingConfirm, its repeat with no ACK in between (the host's ACK came
    // after T_ACK, issue 15), then that late ACK and the repeat's own;
    // then a frame NAKed and repeated: a repeat, nothing late.
    let out = decode_st7580("02012d113f00 03012d113f00 06 06 02012d124000 15 03012d124000 06");
    let repeat: Vec<bool> = out.iter().map(|o| o["repeat"] == true).collect();
    let late: Vec<bool> = out.iter().map(|o| o["after_t_ack"] == true).collect();
    assert_eq!(
        repeat,
        [false, true, false, false, false, false, true, false]
    );
    assert_eq!(
        late,
        [false, false, true, false, false, false, false, false]
    );
    // Absent, not false, where nothing is to be said.
    assert!(out[0].get("repeat").is_none() && out[3].get("after_t_ack").is_none());
}

/// UM0932 Tables 39 and 48: the SNR byte is signed, and 255 has "no
/// meaning" for FSK frames only: after a PSK frame it is -1 dB.
#[test]
fn snr_ffh_is_minus_one_db_after_psk_and_no_value_after_fsk() {
    for (modulation, want) in [
        (Modulation::QPsk, json!(-1)),
        (Modulation::BPskCodedPna, json!(-1)),
        (Modulation::BFsk, Value::Null),
    ] {
        let cmd = Command::SsDataIndication(DataIndication {
            info: info(modulation, 3, 0xFF, 0),
            payload: vec![1, 2],
        });
        let v = &decode_st7580(&hex(&wire(&cmd)))[0];
        assert_eq!(fields(v)["snr"], want, "{modulation:?}: {v}");
    }
}

fn decode_from(from: &str, cmd: &Command) -> Value {
    let out = decode(
        &[
            "decode",
            "--chip",
            "st7580",
            "--from",
            from,
            &hex(&wire(cmd)),
        ],
        None,
    );
    assert_eq!(out.len(), 1, "{out:?}");
    out[0].clone()
}

/// What UM0932 forbids is said in `warning`, and the frame is still
/// decoded: a code sent the wrong way (3.3, Tables 10-15), a
/// BIO_ResetConfirm whose data is not 00h (3.3.2), an SS_DataRequest
/// against Table 45's header-length rules or a TX gain byte with its
/// unused bits set (the rules the simulated modem refuses with).
#[test]
fn what_the_manual_forbids_is_a_warning_on_a_decoded_frame() {
    let warning = |v: &Value| v["warning"].as_str().unwrap_or("").to_string();
    let ping = Command::PingConfirm { data: vec![7] };
    let v = decode_from("host", &ping);
    assert_eq!(v["command"], "PingConfirm");
    assert_eq!(fields(&v)["data"], "07");
    assert!(warning(&v).contains("never from the host"), "{v}");
    assert!(decode_from("modem", &ping).get("warning").is_none());
    assert!(decode_st7580(&hex(&wire(&ping)))[0]
        .get("warning")
        .is_none());

    let read = Command::MibReadRequest { index: 9 };
    let v = decode_from("modem", &read);
    assert_eq!(fields(&v)["object"], "Host interface timeout");
    assert!(warning(&v).contains("only the host sends it"), "{v}");
    assert!(decode_from("host", &read).get("warning").is_none());
    let error = Command::MibReadError(ErrorCause::Busy);
    assert!(warning(&decode_from("host", &error)).contains("MIB_ReadError comes from the ST7580"));

    let reset = Command::BioResetConfirm { confirm_data: 0x01 };
    let v = decode_from("modem", &reset);
    assert_eq!(fields(&v)["confirm_data"], 1);
    assert!(warning(&v).contains("always 00h, not 01h"), "{v}");
    let reset = Command::BioResetConfirm { confirm_data: 0x00 };
    assert!(decode_from("modem", &reset).get("warning").is_none());

    let ss = |header_length, len: usize| {
        Command::SsDataRequest(plm_core::st7580::SsDataRequest {
            params: params(Modulation::QPsk, None, None),
            header_length,
            header_and_payload: vec![0x5A; len],
        })
    };
    for (hl, len, says) in [
        (
            9,
            8,
            "Wrong parameter value (WPV): header length 9 is longer than the 8 bytes",
        ),
        (
            3,
            8,
            "Wrong parameter value (WPV): header length 3 is below 4",
        ),
        (15, 15, "header length 15 is below 16"),
    ] {
        let v = decode_from("host", &ss(hl, len));
        assert_eq!(fields(&v)["header_length"], hl, "{v}");
        assert!(v.get("error").is_none(), "{v}");
        assert!(warning(&v).contains(says), "{hl}/{len}: {v}");
    }
    // Tables 45 and 48: 226 bytes, whatever the DL CRC.
    assert!(decode_from("host", &ss(4, 226)).get("warning").is_none());

    let gain = Command::PhyDataRequest(DataRequest {
        params: params(Modulation::BPsk, None, Some(0xE0 | 10)),
        payload: vec![1],
    });
    let v = decode_from("host", &gain);
    assert_eq!(fields(&v)["tx_gain"], 10);
    assert_eq!(fields(&v)["unused"], 7);
    assert!(warning(&v).contains("Wrong parameter value (WPV)"), "{v}");
}
