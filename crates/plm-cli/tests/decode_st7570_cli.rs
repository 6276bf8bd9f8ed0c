//! `plm decode --chip st7570` end to end: the real binary, real arguments,
//! real JSON. Frames are the manual's worked examples (8, 9, 10) where it
//! prints them, else built here byte by byte from the tables of 5.3
//! (length and checksum computed by this file, not by plm-core); the
//! expected fields are the manual's labels and values, written out.

use plm_core::st7570::code::ALL;
use serde_json::{json, Map, Value};
mod common;
use common::{decode, plm};

/// A frame as on the wire: STX 02h, Length = command + data + checksum
/// (Table 10), the checksum the 16-bit sum of Length, code and data, LSByte
/// first.
fn frame(code: u8, data: &[u8]) -> String {
    let mut f = vec![0x02, (data.len() + 3) as u8, code];
    f.extend_from_slice(data);
    let sum = f[1..].iter().fold(0u16, |a, b| a.wrapping_add(*b as u16));
    f.extend_from_slice(&sum.to_le_bytes());
    hex(&f)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn bytes(hex: &str) -> Vec<u8> {
    plm_core::hex::parse(hex).unwrap()
}

fn st7570(args: &[&str], input: &str) -> Vec<Value> {
    let mut all = vec!["decode", "--chip", "st7570"];
    all.extend_from_slice(args);
    all.push(input);
    decode(&all, None)
}

fn fields(v: &Value) -> &Map<String, Value> {
    v["fields"]
        .as_object()
        .unwrap_or_else(|| panic!("no fields in {v}"))
}

/// S0 002C8Fh, N0 002359h, S1 002B0Ch, N1 0023F6h: Table 3's estimations
/// (114.07, 90.49, 110.20, 92.06 dBµV), LSByte first.
const TABLE_3: [u8; 12] = [
    0x8F, 0x2C, 0x00, 0x59, 0x23, 0x00, 0x0C, 0x2B, 0x00, 0xF6, 0x23, 0x00,
];

fn table_3(prefix: &str) -> Value {
    json!({
        format!("{prefix}s0"): 114.07,
        format!("{prefix}s0_raw"): 11407,
        format!("{prefix}n0"): 90.49,
        format!("{prefix}n0_raw"): 9049,
        format!("{prefix}s1"): 110.20,
        format!("{prefix}s1_raw"): 11020,
        format!("{prefix}n1"): 92.06,
        format!("{prefix}n1_raw"): 9206,
    })
}

/// SNR0 and SNR1 of 9 step 3 in dB (3.6.1, Equation 2: 24.936 and 23.819,
/// as section 9 prints them), with the raw numbers.
fn snr_9_3() -> Value {
    json!({"snr0": 24.936, "snr0_raw": 0x10913, "snr1": 23.819, "snr1_raw": 0xFD33})
}

/// `a` with the members of `b` added.
fn with(a: Value, b: Value) -> Value {
    let mut a = a.as_object().unwrap().clone();
    a.extend(b.as_object().unwrap().clone());
    Value::Object(a)
}

/// P_SDU 00h..25h (9 step 1).
fn p_sdu() -> Vec<u8> {
    (0..38).collect()
}

/// ASK0 169, ASK1 93, FSK 42 (9 step 3), LSByte first.
const COUNTERS: [u8; 6] = [0xA9, 0x00, 0x5D, 0x00, 0x2A, 0x00];

/// One frame to decode in `layer`, sent by `from`, with every field it
/// must show and no other.
struct Case {
    what: &'static str,
    layer: &'static str,
    from: &'static str,
    hex: String,
    fields: Value,
}

fn case(
    what: &'static str,
    layer: &'static str,
    from: &'static str,
    hex: String,
    fields: Value,
) -> Case {
    Case {
        what,
        layer,
        from,
        hex,
        fields,
    }
}

/// Every command code of Table 15; 10h, 50h, 51h and 52h in both layers
/// (their layouts, or 52h's code names, differ).
fn cases() -> Vec<Case> {
    let mut spy_subframe = TABLE_3.to_vec();
    spy_subframe.extend(COUNTERS);
    spy_subframe.push(3);
    spy_subframe.extend(p_sdu());
    spy_subframe.extend([0x13, 0x09, 0x01, 0x33, 0xFD, 0x00]);
    let mut synchro_found = TABLE_3.to_vec();
    synchro_found.extend(COUNTERS);
    synchro_found.push(8);
    let mut spy_alarm = TABLE_3.to_vec();
    spy_alarm.extend([0; 7]);
    spy_alarm.extend([0x56, 0x9E, 0x89]);
    let spy_alarm_fields = with(
        table_3("al_"),
        json!({"pad": "00000000000000", "alarm": 0x569E89}),
    );
    let mut alarm_long = vec![0x02, 0x01, 0x00, 0x00];
    alarm_long.extend(TABLE_3);
    alarm_long.push(0);
    let mut no_subframe = TABLE_3.to_vec();
    no_subframe.extend([0; 58]);
    let counters = json!({"ask0": 169, "ask1": 93, "fsk": 42});
    let plc_8 = json!({
        "index": 0xA1,
        "data": "09001010210144f7000000000201",
        "object": "PLC configuration",
        "operating_mode": "Client",
        "bit_rate": "2400 bit/s",
        "zero_crossing_synchronization": "50 Hz",
        "target_output_gain": 16,
        "f0": 74000,
        "f1": 63300,
        "pad": 0,
        "access_layer_mode": "MAC",
        "tx_current_limiting": "enabled",
    });
    vec![
        // 9 step 2 with its checksum corrected (docs/protocol-notes.md).
        case(
            "PHY CMD_SynchroIndication",
            "phy",
            "modem",
            "021110f619000411001a1a00b60f0008014702".into(),
            // S0 66.46, N0 43.56, S1 66.82 (the text's "71.848" is not
            // Equation 1's), N1 40.22 dBµV.
            json!({"s0": 66.46, "s0_raw": 6646, "n0": 43.56, "n0_raw": 4356,
                   "s1": 66.82, "s1_raw": 6682, "n1": 40.22, "n1_raw": 4022,
                   "pga": 8, "phase": "0°"}),
        ),
        // 10.3.2.
        case(
            "MAC CMD_SynchroIndication FOUND",
            "mac",
            "modem",
            "02121001df2800221700032900b0160004015a02".into(),
            json!({"sync": "FOUND", "s0": 104.63, "s0_raw": 10463, "n0": 59.22, "n0_raw": 5922,
                   "s1": 104.99, "s1_raw": 10499, "n1": 58.08, "n1_raw": 5808, "pga": 4, "phase": "0°"}),
        ),
        case(
            "MAC CMD_SynchroIndication CONFIRMED",
            "mac",
            "modem",
            frame(0x10, &[0x02, 0x00, 0x00, 0x0C, 0x01, 0x00]),
            json!({"sync": "CONFIRMED", "pad": 0, "sa": 0xC00, "da": 1}),
        ),
        case(
            "MAC CMD_SynchroIndication LOST, NEW and NO-BODY addresses",
            "mac",
            "modem",
            frame(0x10, &[0x04, 0x01, 0xFE, 0x0F, 0x00, 0x00]),
            json!({
                "sync": "LOST",
                "cause": "Timeout not addressed expired",
                "add1": 0xFFE,
                "add1_group": "NEW",
                "add2": 0,
                "add2_group": "NO-BODY",
            }),
        ),
        case(
            "MAC CMD_SynchroIndication INTELLIGENT",
            "mac",
            "modem",
            frame(0x10, &[0x05, 0x06, 0x00, 0x0C, 0x68, 0x29]),
            json!({"sync": "INTELLIGENT", "cause": "LM_IS_INIT", "add": 0xC00, "s": 106.00, "s_raw": 10600}),
        ),
        case(
            "CMD_DesynchroRequest",
            "mac",
            "host",
            frame(0x11, &[0x01]),
            json!({"reset": "Rejects current synchronization"}),
        ),
        case(
            "CMD_SynchroStatus request",
            "phy",
            "host",
            frame(0x85, &[]),
            json!({}),
        ),
        case(
            "CMD_SynchroStatus answer",
            "phy",
            "modem",
            frame(0x85, &[0x02]),
            json!({"status": "LP_SYNC_LOSS"}),
        ),
        case(
            "CMD_ResetRequest from the host",
            "phy",
            "host",
            frame(0x21, &[0x01]),
            json!({"reset": "ON"}),
        ),
        case(
            "CMD_ResetRequest confirm from the modem",
            "phy",
            "modem",
            frame(0x21, &[0x00]),
            json!({"reset": "The reset request has been taken into account"}),
        ),
        // 8.
        case(
            "CMD_WriteDBRequest 00A1h",
            "phy",
            "host",
            "021341a10009001010210144f70000000002017e02".into(),
            plc_8.clone(),
        ),
        case(
            "CMD_WriteDBConfirm 00A1h",
            "mac",
            "modem",
            "021342a10009001010210144f70000000002017f02".into(),
            plc_8,
        ),
        case(
            "CMD_WriteDBError",
            "mac",
            "modem",
            frame(0x43, &[0x23]),
            json!({"error": "ERR_ILLEGAL_LOCAL_MAC_ADR"}),
        ),
        // 10.2.1, rebuilt.
        case(
            "CMD_ReadDBRequest 0002h",
            "mac",
            "host",
            "02059002009700".into(),
            json!({"index": 2, "object": "Timeout synchro confirmation"}),
        ),
        case(
            "CMD_ReadDBConfirm 0002h",
            "mac",
            "modem",
            "020791020003009d00".into(),
            json!({
                "index": 2,
                "data": "0300",
                "object": "Timeout synchro confirmation",
                "timeout_synchro_confirmation": 3,
            }),
        ),
        case(
            "CMD_ReadDBError",
            "mac",
            "modem",
            frame(0x92, &[0x12]),
            json!({"error": "ERR_REQUEST_NOT_ALLOWED"}),
        ),
        // 9 step 3.
        case(
            "PHY CMD_DataIndication",
            "phy",
            "modem",
            "023550000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f202122232425a9005d002a0013090133fd00c105".into(),
            with(
                with(json!({"p_sdu": hex(&p_sdu())}), snr_9_3()),
                counters.clone(),
            ),
        ),
        // 10.4.2.
        case(
            "MAC CMD_DataIndication",
            "mac",
            "modem",
            "02225000001c0000000102030405060708090a0b0c0d0e0f10111213141516171819d301".into(),
            json!({
                "ic": 0, "cc": 0, "dc": 0, "sa": 1, "da": 0xC00, "pad": 0,
                "m_sdu": hex(&(0..26).collect::<Vec<u8>>()),
            }),
        ),
        // 9 step 1.
        case(
            "PHY CMD_DataRequest",
            "phy",
            "host",
            "022951000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f2021222324253903".into(),
            json!({"p_sdu": hex(&p_sdu())}),
        ),
        // 4.8.5: a broadcast with IC = CC = 3.
        case(
            "MAC CMD_DataRequest to BROADCAST",
            "mac",
            "host",
            frame(0x51, &[0x6C, 0x00, 0x1F, 0xFF, 0x00, 0xAA, 0xBB]),
            json!({
                "ic": 3, "cc": 3, "dc": 0, "sa": 1, "da": 0xFFF, "da_group": "BROADCAST",
                "pad": 0, "m_sdu": "aabb",
            }),
        ),
        // 9 step 4 and 10.3.1: the same bytes, named by the layer.
        case(
            "PHY CMD_DataConfirm",
            "phy",
            "modem",
            "020452ff5501".into(),
            json!({"confirm_code": "LP_OK"}),
        ),
        case(
            "MAC CMD_DataConfirm",
            "mac",
            "modem",
            "020452ff5501".into(),
            json!({"confirm_code": "LM_OK"}),
        ),
        case(
            "PHY CMD_DataConfirm LP_NS",
            "phy",
            "modem",
            frame(0x52, &[0x04]),
            json!({"confirm_code": "LP_NS"}),
        ),
        case(
            "MAC CMD_DataConfirm LM_NS",
            "mac",
            "modem",
            frame(0x52, &[0x04]),
            json!({"confirm_code": "LM_NS"}),
        ),
        case("CMD_AlarmRequest", "mac", "host", frame(0x88, &[]), json!({})),
        case(
            "CMD_AlarmConfirm",
            "mac",
            "modem",
            frame(0x89, &[0x05]),
            json!({"confirm_code": "LP_IS"}),
        ),
        case(
            "CMD_AlarmIndication short",
            "mac",
            "modem",
            frame(0x8A, &[0x07, 0x00, 0x00, 0x00]),
            json!({"cnt": 7}),
        ),
        case(
            "CMD_AlarmIndication long",
            "phy",
            "modem",
            frame(0x8A, &alarm_long),
            with(json!({"cnt": 0x102, "pad": 0}), table_3("")),
        ),
        case(
            "SPY_No_SubframeIndication",
            "phy",
            "modem",
            frame(0xA0, &no_subframe),
            with(table_3(""), json!({"pad": "00".repeat(58)})),
        ),
        case(
            "SPY_SubframeIndication",
            "phy",
            "modem",
            frame(0xB0, &spy_subframe),
            with(
                with(table_3(""), counters.clone()),
                with(json!({"pga": 3, "p_sdu": hex(&p_sdu())}), snr_9_3()),
            ),
        ),
        case(
            "SPY_SearchSynchroIndication",
            "phy",
            "modem",
            frame(0xC0, &[]),
            json!({}),
        ),
        case(
            "SPY_SynchroFoundIndication",
            "phy",
            "modem",
            frame(0xD0, &synchro_found),
            with(with(table_3(""), counters), json!({"pga": 8})),
        ),
        case(
            "SPY_No_AlarmIndication",
            "phy",
            "modem",
            frame(0xE0, &spy_alarm),
            spy_alarm_fields.clone(),
        ),
        case(
            "SPY_AlarmIndication",
            "phy",
            "modem",
            frame(0xF0, &spy_alarm),
            spy_alarm_fields,
        ),
        case(
            "CMD_RC_Request",
            "mac",
            "host",
            frame(0x61, &[0x03, 0x00, 0x68, 0x29]),
            json!({"tx_pos": 3, "rc_threshold": 106.00, "rc_threshold_raw": 10600}),
        ),
        case(
            "CMD_RC_Confirm short",
            "mac",
            "modem",
            frame(0x62, &[0x00, 0x00]),
            json!({"result": "LP_TU", "repeater_state": "NEVER_REPEAT"}),
        ),
        case(
            "CMD_RC_Confirm long",
            "mac",
            "modem",
            frame(
                0x62,
                &[0xFF, 0x03, 0x8F, 0x2C, 0x00, 0x59, 0x23, 0x00, 0x05, 0x00],
            ),
            json!({"result": "LP_OK", "repeater_state": "REPEAT", "s": 114.07, "s_raw": 11407,
                   "n": 90.49, "n_raw": 9049, "rx_pos": 5}),
        ),
        case(
            "CMD_IS_Indication LM_LOCKED",
            "mac",
            "modem",
            frame(0x15, &[0x01, 0x00, 0x0C, 0x68, 0x29]),
            json!({"is_status": "LM_LOCKED", "add": 0xC00, "s": 106.00, "s_raw": 10600}),
        ),
        case(
            "CMD_IS_Indication LM_NOT_REGISTERED",
            "mac",
            "modem",
            frame(0x15, &[0x03]),
            json!({"is_status": "LM_NOT_REGISTERED"}),
        ),
        case(
            "CMD_SyntaxError",
            "phy",
            "modem",
            frame(0x20, &[0x01]),
            json!({"error": "Error"}),
        ),
    ]
}

#[test]
fn every_command_code_of_table_15_decodes_with_its_name_and_fields() {
    let cases = cases();
    for c in ALL {
        let layers: &[&str] = match c.code {
            0x10 | 0x50 | 0x51 | 0x52 => &["phy", "mac"],
            _ => &["phy", "mac"][..1],
        };
        for layer in layers {
            let found = cases
                .iter()
                .any(|k| bytes(&k.hex)[2] == c.code && (layers.len() == 1 || k.layer == *layer));
            assert!(found, "no case of {} ({:02X}h) in {layer}", c.name, c.code);
        }
    }
    for k in &cases {
        let lines = st7570(&["--layer", k.layer, "--from", k.from], &k.hex);
        let ctx = format!("{}: {lines:?}", k.what);
        assert_eq!(lines.len(), 1, "{ctx}");
        let v = &lines[0];
        let wire = bytes(&k.hex);
        let code = wire[2];
        assert_eq!(v["kind"], "frame", "{ctx}");
        assert_eq!(v["from"], k.from, "{ctx}");
        assert_eq!(v["stx"], 2, "{ctx}");
        assert_eq!(v["length"], wire[1], "{ctx}");
        assert_eq!(v["length"], wire.len() - 2, "{ctx}");
        assert_eq!(v["code"], code, "{ctx}");
        let name = ALL.iter().find(|c| c.code == code).unwrap().name;
        assert_eq!(v["command"], name, "{ctx}");
        assert_eq!(v["layer"], k.layer.to_uppercase(), "{ctx}");
        let n = wire.len();
        assert_eq!(
            v["checksum"],
            u16::from_le_bytes([wire[n - 2], wire[n - 1]]),
            "{ctx}"
        );
        assert_eq!(v["checksum_ok"], true, "{ctx}");
        assert_eq!(v["hex"], k.hex, "{ctx}");
        assert!(v.get("error").is_none(), "{ctx}");
        assert_eq!(&Value::Object(fields(v).clone()), &k.fields, "{ctx}");
    }
}

/// A status message: `?` and bytes 1..3 (Table 11).
fn status(b1: u8, b2: u8, b3: u8) -> String {
    hex(&[0x3F, b1, b2, b3])
}

#[test]
fn status_messages_decode_field_by_field_in_every_row_of_table_11() {
    let rows = [
        (
            "Not set",
            status(0x00, 0x04, 0x00),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Idle mode, Test modes",
                "layer": "PHY layer", "reset": "Hardware Reset", "fw_release": 1, "zc_fail": false,
            }),
        ),
        (
            "Client (PHY mode): busy, not synchronized, alarm",
            status(0x15, 0x06, 0x00),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Client",
                "sync": "modem not synchronized", "layer": "PHY layer", "busy": true,
                "reset": "Hardware Reset", "fw_release": 1, "alarm": true, "zc_fail": false,
            }),
        ),
        (
            "Client (MAC mode): TS_COUNTER 3, software reset, 5 invalid frames",
            status(0x12, 0x74, 0x05),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Client",
                "sync": "modem synchronized", "layer": "MAC layer", "busy": false,
                "ts_counter": 3, "reset": "Software Reset", "fw_release": 1, "alarm": false,
                "zc_fail": false, "invalid_frame": 5,
            }),
        ),
        (
            "Server (PHY mode): +120°",
            status(0x20, 0x04, 0x60),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Server",
                "sync": "modem synchronized", "layer": "PHY layer", "busy": false,
                "reset": "Hardware Reset", "fw_release": 1, "alarm": false, "zc_fail": false,
                "delta_phase": "+120°",
            }),
        ),
        (
            // 10.4.1.
            "Server (MAC mode): 3F 22 E4 80",
            "3f22e480".to_string(),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Server", "new": false,
                "sync": "modem synchronized", "layer": "MAC layer", "busy": false,
                "ts_counter": 7, "reset": "Hardware Reset", "fw_release": 1, "alarm": false,
                "zc_fail": false, "delta_phase": "±180°", "min_credit": 0, "repeater": false,
            }),
        ),
        (
            "Server (MAC mode): NEW, MIN_CREDIT 3, repeater",
            status(0x2A, 0x04, 0x07),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Server", "new": true,
                "sync": "modem synchronized", "layer": "MAC layer", "busy": false,
                "ts_counter": 0, "reset": "Hardware Reset", "fw_release": 1, "alarm": false,
                "zc_fail": false, "delta_phase": "Not measured", "min_credit": 3, "repeater": true,
            }),
        ),
        (
            "Monitor (only PHY mode): overcurrent, ZC_FAIL, -60°",
            status(0xB0, 0x05, 0xC0),
            json!({
                "overcurrent": true, "thermal_stop": false, "mode": "Monitor",
                "sync": "modem synchronized", "layer": "PHY layer", "busy": false,
                "reset": "Hardware Reset", "fw_release": 1, "alarm": false, "zc_fail": true,
                "delta_phase": "-60°",
            }),
        ),
        (
            // docs/protocol-notes.md: read with the Monitor row.
            "Monitor in MAC mode: thermal stop",
            status(0x72, 0x04, 0x20),
            json!({
                "overcurrent": false, "thermal_stop": true, "mode": "Monitor",
                "sync": "modem synchronized", "layer": "MAC layer", "busy": false,
                "reset": "Hardware Reset", "fw_release": 1, "alarm": false, "zc_fail": false,
                "delta_phase": "0°",
            }),
        ),
        (
            "Not set with bits where the row has 0",
            status(0x05, 0x04, 0xFF),
            json!({
                "overcurrent": false, "thermal_stop": false, "mode": "Idle mode, Test modes",
                "layer": "PHY layer", "reset": "Hardware Reset", "fw_release": 1, "zc_fail": false,
                "stray_byte_1": 0x05, "stray_byte_3": 0xFF,
            }),
        ),
    ];
    for (what, hex, want) in rows {
        let lines = st7570(&["--from", "modem"], &hex);
        assert_eq!(lines.len(), 1, "{what}: {lines:?}");
        let v = &lines[0];
        assert_eq!(v["kind"], "status", "{what}: {v}");
        assert_eq!(v["hex"], hex, "{what}");
        assert!(v.get("layer").is_none(), "a frame's key: {v}");
        assert_eq!(&Value::Object(fields(v).clone()), &want, "{what}");
    }
}

#[test]
fn the_layer_follows_status_messages_and_00a1h_unless_given() {
    let confirm = "020452ff5501";
    // A Client MAC status, a confirm, a Client PHY status, the same bytes.
    let input = format!("3f120400 {confirm} 3f100400 {confirm}");
    let lines = st7570(&[], &input);
    let named: Vec<(&Value, &Value)> = lines
        .iter()
        .filter(|v| v["kind"] == "frame")
        .map(|v| (&v["layer"], &fields(v)["confirm_code"]))
        .collect();
    assert_eq!(
        named,
        [
            (&json!("MAC"), &json!("LM_OK")),
            (&json!("PHY"), &json!("LP_OK"))
        ]
    );
    // --layer wins over the status messages.
    let fixed = st7570(&["--layer", "phy"], &input);
    assert_eq!(fields(&fixed[1])["confirm_code"], "LP_OK");
    assert_eq!(fixed[1]["layer"], "PHY");

    // 8: writing 00A1h with MAC mode; the confirm sets it, and the MAC
    // data indication of 10.4.2 that follows is read in MAC mode.
    let write = "021341a10009001010210144f70000000002017e02";
    let ok = "021342a10009001010210144f70000000002017f02";
    let indication = "02225000001c0000000102030405060708090a0b0c0d0e0f10111213141516171819d301";
    let lines = st7570(&[], &format!("{write} 06 {ok} 06 {indication}"));
    assert_eq!(lines[0]["layer"], "PHY", "the factory default before it");
    assert_eq!(lines[4]["layer"], "MAC");
    assert_eq!(fields(&lines[4])["da"], 0xC00);
    assert!(lines[4].get("error").is_none(), "{}", lines[4]);
    // Refused (CMD_WriteDBError), the write changes nothing: the same
    // bytes read in PHY mode are not a P_Data.Indication.
    let refused = frame(0x43, &[0x26]);
    let lines = st7570(&[], &format!("{write} {refused} {indication}"));
    assert_eq!(lines[2]["layer"], "PHY");
    assert!(
        lines[2]["error"]
            .as_str()
            .unwrap()
            .contains("50 data bytes"),
        "{}",
        lines[2]
    );
    // A write with a wrong checksum is NAKed: nothing changes either.
    let bad = "021341a10009001010210144f70000000002017f02";
    let lines = st7570(&[], &format!("{bad} {indication}"));
    assert_eq!(lines[0]["checksum_ok"], false);
    assert_eq!(lines[1]["layer"], "PHY");
}

#[test]
fn what_the_modem_will_refuse_is_said() {
    // 0001h exists only with the MAC layer (ERR_UNAVAILABLE_RESOURCE).
    let local = "0209410100000c00005700";
    let lines = st7570(&["--layer", "phy", "--from", "host"], local);
    let e = lines[0]["error"].as_str().unwrap();
    assert!(e.contains("ERR_UNAVAILABLE_RESOURCE"), "{e}");
    // 10.1.1: Station1, local address C00h, no initiator.
    assert_eq!(fields(&lines[0])["local_mac_add"], 0xC00);
    assert_eq!(fields(&lines[0])["init_mac_add_group"], "NO-BODY");
    assert!(st7570(&["--layer", "mac"], local)[0].get("error").is_none());
    // A PHY P_SDU is 38 bytes (Table 43: LM_SE).
    let short = frame(0x51, &[0; 37]);
    let e = st7570(&["--layer", "phy"], &short)[0]["error"].clone();
    assert!(e.as_str().unwrap().contains("LM_SE"), "{e}");
    // Data that fits no form of the command: the bytes and why.
    let lines = st7570(&[], &frame(0x52, &[0xFF, 0x00]));
    assert_eq!(fields(&lines[0])["data"], "ff00");
    assert_eq!(
        lines[0]["error"],
        "CMD_DataConfirm carries 1 data bytes, not 2"
    );
    // A confirm of an object that does not exist.
    let lines = st7570(&[], &frame(0x91, &[0x17, 0x00, 0x01]));
    assert_eq!(fields(&lines[0])["object"], Value::Null);
    assert_eq!(lines[0]["error"], "there is no MIB object 0017h");
}

#[test]
fn an_unknown_code_has_a_null_command_and_keeps_its_data() {
    let lines = st7570(&[], &frame(0x77, &[0xAB]));
    let v = &lines[0];
    assert_eq!(v.get("command"), Some(&Value::Null), "{v}");
    assert_eq!(fields(v)["data"], "ab");
    assert!(v.get("error").is_none());
}

#[test]
fn the_printed_checksum_of_9_step_2_is_reported_not_refused() {
    let lines = st7570(
        &["--layer", "phy"],
        "021110f619000411001a1a00b60f0008014a02",
    );
    assert_eq!(lines[0]["checksum_ok"], false);
    assert_eq!(lines[0]["checksum"], 0x024A);
    assert_eq!(fields(&lines[0])["s0"], 66.46);
    assert_eq!(fields(&lines[0])["s0_raw"], 6646);
}

#[test]
fn input_forms_and_sides_are_those_of_the_st7580() {
    // Stdin, dots and colons; ACK, NAK and status messages in one stream.
    let text = "3f.22.e4.80\n06 02:04:52:ff:55:01 15\n";
    let lines = decode(&["decode", "--chip", "st7570"], Some(text));
    let kinds: Vec<&str> = lines.iter().map(|v| v["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["status", "ack", "frame", "nak"]);
    assert_eq!(fields(&lines[2])["confirm_code"], "LM_OK");
    // Only the modem sends status messages.
    let host = st7570(&["--from", "host"], "3f22e480");
    assert_eq!(host[0]["kind"], "garbage");
}

#[test]
fn options_of_the_other_chip_are_refused_in_words() {
    let out = plm(
        &[
            "decode",
            "--chip",
            "st7570",
            "--mib-index",
            "2",
            "020452ff5501",
        ],
        None,
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("carries its INDEX"));
    let out = plm(
        &["decode", "--chip", "st7580", "--layer", "mac", "02002c2c00"],
        None,
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--layer is for the ST7570"));
    let out = plm(&["decode", "--board", "--layer", "mac", "00"], None);
    assert!(!out.status.success());
}
