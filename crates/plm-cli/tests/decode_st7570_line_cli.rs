//! `plm decode --chip st7570 --line`: frames from the ST7570's power line
//! (IEC 61334-5-1, ST7570 UM 3.2 and 4.4) through the real binary. The
//! frames are built here byte by byte from the layout recorded in
//! docs/protocol-notes.md ("ST7570: MAC and PHY frames on the line"), with
//! an FCS computed by this file's own bitwise CRC-24, not by plm-core;
//! and the line vectors of tests/vectors/st7570_line.jsonl (written by
//! tests/vectors/make_st7570_line.py), each FCS form named.

use serde_json::{json, Value};
mod common;
use common::{decode, plm};

/// CRC-24, polynomial 5D6DCBh, register from 0, MSBit first, no final XOR.
fn crc24(bytes: &[u8]) -> u32 {
    let mut r: u32 = 0;
    for b in bytes {
        r ^= (*b as u32) << 16;
        for _ in 0..8 {
            r = if r & 0x80_0000 != 0 {
                (r << 1) ^ 0x5D_6DCB
            } else {
                r << 1
            } & 0xFF_FFFF;
        }
    }
    r
}

/// The long MAC frame: NS code, CREDIT, ADDRESS (SA b23..b12, DA
/// b11..b0), PAD, M_sdu, pad, FCS over CREDIT..pad; 36 bytes a subframe.
fn long_frame(credit: u8, sa: u16, da: u16, m_sdu: &[u8]) -> Vec<u8> {
    const NS: [u8; 7] = [0x6C, 0x3A, 0x56, 0x71, 0x1D, 0x4B, 0x27];
    let ns = (10 + m_sdu.len()).div_ceil(36);
    let pad = ns * 36 - 10 - m_sdu.len();
    let addr = (sa as u32) << 12 | da as u32;
    let mut f = vec![NS[ns - 1], NS[ns - 1], credit];
    f.extend_from_slice(&addr.to_be_bytes()[1..]);
    f.push(pad as u8);
    f.extend_from_slice(m_sdu);
    f.resize(f.len() + pad, 0);
    let fcs = crc24(&f[2..]);
    f.extend_from_slice(&fcs.to_be_bytes()[1..]);
    f
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn line(bytes: &[u8]) -> Value {
    let out = decode(&["decode", "--chip", "st7570", "--line", &hex(bytes)], None);
    assert_eq!(out.len(), 1, "one object: {out:?}");
    out.into_iter().next().unwrap()
}

/// UM 10.3.1: credit 00h, SA C00h, DA 001h, M_sdu 00h..19h.
fn seed_10_3() -> Vec<u8> {
    long_frame(0x00, 0xC00, 0x001, &(0..26).collect::<Vec<u8>>())
}

#[test]
fn a_long_mac_frame_by_name() {
    let f = seed_10_3();
    assert_eq!(f.len(), 36);
    assert_eq!(
        line(&f),
        json!({
            "kind": "mac_frame",
            "hex": hex(&f),
            "ns": 1,
            "fields": {"ic": 0, "cc": 0, "dc": 0, "sa": 3072, "da": 1, "pad": 0},
            "m_sdu": "000102030405060708090a0b0c0d0e0f10111213141516171819",
            "pad_bytes": "",
            "fcs": 0xFF3B89,
            "fcs_ok": true,
            "fcs_form": "catalogue",
        })
    );
}

#[test]
fn phy_frames_with_their_windows() {
    // 3.2: PRE AAAAh, SSD 54C7h, P_sdu = FI 0000h + 36 bytes, then the
    // 3-byte window: here the alarm pattern 569E89h (7.2).
    let f = seed_10_3();
    let mut phy = vec![0xAA, 0xAA, 0x54, 0xC7, 0x00, 0x00];
    phy.extend_from_slice(&f);
    phy.extend_from_slice(&[0x56, 0x9E, 0x89]);
    assert_eq!(phy.len(), 45);
    let v = line(&phy);
    assert_eq!(v["kind"], "phy_frames");
    assert_eq!(v["fi"], 0);
    assert_eq!(v["windows"], json!(["alarm"]));
    assert_eq!(v["fields"]["sa"], 3072);
    assert_eq!(v["fcs_ok"], true);
}

#[test]
fn subframes_of_a_broadcast_with_credits() {
    // IC = CC = 3, DC = 1: 011 011 01b; DA FFFh is Table 6's BROADCAST.
    let m: Vec<u8> = (0..100).map(|i| (i * 3) as u8).collect();
    let f = long_frame(0b0110_1101, 0xC00, 0xFFF, &m);
    assert_eq!(f.len(), 4 * 36);
    let subframes: Vec<u8> = f
        .chunks(36)
        .flat_map(|c| [&[0x00, 0x00][..], c].concat())
        .collect();
    let v = line(&subframes);
    assert_eq!(v["kind"], "mac_subframes");
    assert_eq!(v["ns"], 4);
    assert_eq!(
        v["fields"],
        json!({"ic": 3, "cc": 3, "dc": 1, "sa": 3072, "da": 4095, "da_group": "BROADCAST", "pad": 34})
    );
    assert_eq!(v["m_sdu"], hex(&m));
    assert_eq!(v["pad_bytes"], hex(&[0; 34]));
    assert_eq!(v["fcs_ok"], true);
}

#[test]
fn a_damaged_frame_is_shown_with_its_fcs_wrong() {
    let mut f = seed_10_3();
    f[20] ^= 0x04;
    let v = line(&f);
    assert_eq!(v["kind"], "mac_frame");
    assert_eq!(v["fcs_ok"], false);
    assert_eq!(v["fcs"], 0xFF3B89);
    let e = v["error"].as_str().unwrap();
    assert!(e.starts_with("bad FCS: received FF3B89h"), "{e}");
}

/// A frame written the way Gurux's DLMS library writes it decodes with its
/// FCS form named (over the pad bytes, as its C and C# writers send it, or
/// without them, as its writer's FCS length reads); the catalogue form
/// this project sends is named too; a frame neither explains is flagged
/// with each form's FCS in the error.
#[test]
fn every_fcs_form_of_the_line_vectors_is_named() {
    const VECTORS: &str = include_str!("../../../tests/vectors/st7570_line.jsonl");
    let mut forms = Vec::new();
    for text in VECTORS.lines().filter(|l| !l.trim().is_empty()) {
        let v: Value = serde_json::from_str(text).unwrap();
        let name = v["name"].as_str().unwrap();
        let got = decode(
            &[
                "decode",
                "--chip",
                "st7570",
                "--line",
                v["hex"].as_str().unwrap(),
            ],
            None,
        );
        assert_eq!(got.len(), 1, "{name}: one object");
        let got = &got[0];
        for (k, want) in v["expect"].as_object().unwrap() {
            let error = got["error"].as_str().unwrap_or("");
            match k.as_str() {
                "error_starts" => {
                    assert!(error.starts_with(want.as_str().unwrap()), "{name}: {error}")
                }
                "error_mentions" => {
                    for m in want.as_array().unwrap() {
                        assert!(
                            error.contains(m.as_str().unwrap()),
                            "{name}: {error} lacks {m}"
                        );
                    }
                }
                _ => assert_eq!(got.get(k).unwrap_or(&Value::Null), want, "{name}: {k}"),
            }
        }
        forms.push(got["fcs_form"].as_str().unwrap_or("none").to_string());
    }
    for form in ["catalogue", "gurux", "gurux_without_pad", "none"] {
        assert!(forms.iter().any(|f| f == form), "no vector in form {form}");
    }
}

#[test]
fn not_a_frame_in_words() {
    let mut phy = vec![0xAA, 0xAA, 0x54, 0xC6, 0x00, 0x00];
    phy.extend_from_slice(&seed_10_3());
    phy.extend_from_slice(&[0, 0, 0]);
    let v = line(&phy);
    assert_eq!(v["kind"], "garbage");
    assert_eq!(v["error"], "start subframe delimiter 54C6h, expected 54C7h");
    let v = line(&[0x00; 10]);
    assert_eq!(v["kind"], "garbage");
    assert_eq!(
        v["error"],
        "10 bytes is not a whole number of 38-byte subframes"
    );
}

#[test]
fn from_stdin_and_only_for_the_st7570() {
    let f = seed_10_3();
    let out = decode(
        &["decode", "--chip", "st7570", "--line"],
        Some(&format!("{}\n", hex(&f))),
    );
    assert_eq!(out[0]["fcs_ok"], true);

    let out = plm(&["decode", "--chip", "st7580", "--line", "00"], None);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "plm decode: --line is for the ST7570's power line frames: add --chip st7570"
    );
}
