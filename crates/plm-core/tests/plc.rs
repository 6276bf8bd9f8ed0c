//! Power line frames of UM0932 2.2-2.4 (`st7580::plc`): the published
//! vectors of the chosen algorithms (RFC 4493 AES-CMAC, NIST SP 800-38A
//! CTR, the CRC catalogue's check values) and the DL and SS frame layouts
//! of Tables 3 and 4.

use aes::cipher::{BlockEncrypt, KeyInit};
use plm_core::hex;
use plm_core::st7580::mib::ModemConfig;
use plm_core::st7580::plc::{self, DlCrc, DlOptions, DlReceived, PlcError, SsError};
use proptest::collection::vec;
use proptest::prelude::*;

fn h(text: &str) -> Vec<u8> {
    hex::parse(text).unwrap()
}

fn h16(text: &str) -> [u8; 16] {
    h(text).try_into().unwrap()
}

const ALL_CRCS: [DlCrc; 4] = [DlCrc::Crc8, DlCrc::Crc16Be, DlCrc::Crc32Le, DlCrc::Crc32Be];

fn opts(crc: DlCrc, crc_on_phy_length: bool) -> DlOptions {
    DlOptions {
        crc,
        crc_on_phy_length,
    }
}

// ---- The algorithms, against their published vectors ----

/// RFC 4493 section 4, AES-CMAC examples 1-4.
#[test]
fn rfc4493_aes_cmac_examples() {
    let key = h16("2b7e1516 28aed2a6 abf71588 09cf4f3c");
    let m = h("6bc1bee2 2e409f96 e93d7e11 7393172a
               ae2d8a57 1e03ac9c 9eb76fac 45af8e51
               30c81c46 a35ce411 e5fbc119 1a0a52ef
               f69f2445 df4f9b17 ad2b417b e66c3710");
    let cases = [
        (0, "bb1d6929 e9593728 7fa37d12 9b756746"),
        (16, "070a16b4 6b4d4144 f79bdd9d d04a287c"),
        (40, "dfa66747 de9ae630 30ca3261 1497c827"),
        (64, "51f0bebf 7e3b9d92 fc497417 79363cfe"),
    ];
    for (len, tag) in cases {
        assert_eq!(plc::cmac(&key, &[&m[..len]]), h16(tag), "Mlen = {len}");
        // The parts are concatenated, wherever they are split.
        assert_eq!(
            plc::cmac(&key, &[&m[..len / 3], &[], &m[len / 3..len]]),
            h16(tag)
        );
    }
}

/// NIST SP 800-38A F.5.1 CTR-AES128.Encrypt, and F.5.2 (decrypt) back.
#[test]
fn sp800_38a_f51_ctr_aes128() {
    let key = h16("2b7e151628aed2a6abf7158809cf4f3c");
    let counter = h16("f0f1f2f3f4f5f6f7f8f9fafbfcfdfeff");
    let plain = h("6bc1bee22e409f96e93d7e117393172a
                   ae2d8a571e03ac9c9eb76fac45af8e51
                   30c81c46a35ce411e5fbc1191a0a52ef
                   f69f2445df4f9b17ad2b417be66c3710");
    let cipher = h("874d6191b620e3261bef6864990db6ce
                    9806f66b7970fdff8617187bb9fffdff
                    5ae4df3edbd5d35e5b4f09020db03eab
                    1e031dda2fbe03d1792170a0f3009cee");
    let mut data = plain.clone();
    plc::ctr_apply(&key, &counter, &mut data);
    assert_eq!(data, cipher);
    plc::ctr_apply(&key, &counter, &mut data);
    assert_eq!(data, plain);
}

/// The check value of each chosen CRC (the CRC of ASCII "123456789"), in
/// the byte order of each MIB 00h option (Table 53).
#[test]
fn crc_check_values_in_table_53_byte_order() {
    let expected = [
        (DlCrc::Crc8, "F4"),
        (DlCrc::Crc16Be, "29 B1"),
        (DlCrc::Crc32Le, "26 39 F4 CB"),
        (DlCrc::Crc32Be, "CB F4 39 26"),
    ];
    for (crc, check) in expected {
        assert_eq!(crc.len(), h(check).len());
        assert_eq!(
            opts(crc, false).crc(0x55, b"123456789"),
            h(check),
            "{crc:?}"
        );
        // "DL CRC on PHY length": the length byte comes first ('1' = 31h).
        assert_eq!(opts(crc, true).crc(b'1', b"23456789"), h(check), "{crc:?}");
        assert_ne!(opts(crc, true).crc(b'2', b"23456789"), h(check), "{crc:?}");
    }
}

#[test]
fn options_from_mib_00h() {
    let factory = ModemConfig::decode(&[0x11]);
    assert_eq!(DlOptions::from_modem_config(&factory), DlOptions::default());
    assert_eq!(DlOptions::default().crc, DlCrc::Crc32Le);
    let c = ModemConfig::decode(&[0b0100_1001]);
    assert_eq!(DlOptions::from_modem_config(&c), opts(DlCrc::Crc16Be, true));
}

// ---- PHY and DL frames (Tables 2 and 3) ----

#[test]
fn phy_frames_carry_the_payload_length() {
    assert_eq!(plc::phy_frame(&[7, 8]).unwrap(), [2, 7, 8]);
    assert_eq!(plc::phy_frame(&[]).unwrap(), [0]);
    assert_eq!(plc::phy_open(&[2, 7, 8]).unwrap(), [7, 8]);
    assert_eq!(plc::phy_open(&[0]).unwrap(), [0u8; 0]);
    assert_eq!(plc::phy_frame(&[0; 255]).unwrap().len(), 256);
    assert_eq!(
        plc::phy_frame(&[0; 256]),
        Err(PlcError::TooLong { len: 256, max: 255 })
    );
    assert_eq!(plc::phy_open(&[]), Err(PlcError::Empty));
    assert_eq!(
        plc::phy_open(&[3, 7, 8]),
        Err(PlcError::LengthMismatch {
            declared: 3,
            got: 2
        })
    );
}

#[test]
fn dl_frame_layout_of_table_3() {
    let o = opts(DlCrc::Crc32Be, false);
    let f = plc::dl_frame(&o, b"123456789").unwrap();
    assert_eq!(f[0], 13, "DL length counts payload and CRC");
    assert_eq!(&f[1..10], b"123456789");
    assert_eq!(&f[10..], h("CB F4 39 26"));
    // The largest payload for each CRC fills the 255 of the length byte.
    for crc in ALL_CRCS {
        let o = opts(crc, true);
        let max = 255 - crc.len();
        assert_eq!(plc::dl_frame(&o, &vec![1; max]).unwrap()[0], 255);
        assert_eq!(
            plc::dl_frame(&o, &vec![1; max + 1]),
            Err(PlcError::TooLong { len: max + 1, max })
        );
    }
}

#[test]
fn dl_open_refuses_malformed_frames() {
    let o = opts(DlCrc::Crc32Le, false);
    let mut f = plc::dl_frame(&o, b"abc").unwrap();
    assert_eq!(plc::dl_open(&o, &[]), Err(PlcError::Empty));
    f.push(0);
    assert_eq!(
        plc::dl_open(&o, &f),
        Err(PlcError::LengthMismatch {
            declared: 7,
            got: 8
        })
    );
    f.truncate(f.len() - 2);
    assert_eq!(
        plc::dl_open(&o, &f),
        Err(PlcError::LengthMismatch {
            declared: 7,
            got: 6
        })
    );
    assert_eq!(
        plc::dl_open(&o, &[3, 1, 2, 3]),
        Err(PlcError::TooShortForCrc { len: 3, crc_len: 4 })
    );
    // An empty payload with a good CRC is a frame.
    let empty = plc::dl_frame(&o, &[]).unwrap();
    assert_eq!(
        plc::dl_open(&o, &empty),
        Ok(DlReceived::Good { payload: vec![] })
    );
}

/// The CRC on the PHY length makes a difference for every frame length: a
/// receiver configured the other way sees a wrong CRC.
#[test]
fn crc_on_phy_length_changes_every_crc() {
    for crc in ALL_CRCS {
        for len in 0..=255 - crc.len() {
            let payload: Vec<u8> = (0..len as u8).collect();
            let f = plc::dl_frame(&opts(crc, true), &payload).unwrap();
            assert!(
                matches!(
                    plc::dl_open(&opts(crc, false), &f),
                    Ok(DlReceived::WrongCrc { .. })
                ),
                "{crc:?}, {len} bytes"
            );
        }
    }
}

fn dl_case() -> impl Strategy<Value = (DlOptions, Vec<u8>)> {
    (0..4u8, any::<bool>()).prop_flat_map(|(code, on_len)| {
        let o = opts(DlCrc::from_code(code), on_len);
        (Just(o), vec(any::<u8>(), 0..=255 - o.crc.len()))
    })
}

proptest! {
    #[test]
    fn dl_frames_round_trip((o, payload) in dl_case()) {
        let f = plc::dl_frame(&o, &payload).unwrap();
        prop_assert_eq!(f.len(), 1 + payload.len() + o.crc.len());
        prop_assert_eq!(plc::dl_open(&o, &f), Ok(DlReceived::Good { payload }));
    }

    /// Every single-bit error after the length byte is caught, and the
    /// sniffer gets the payload and the CRC as received (UM0932 2.4).
    #[test]
    fn a_flipped_bit_gives_wrong_crc((o, payload) in dl_case(), bit in any::<prop::sample::Index>()) {
        let mut f = plc::dl_frame(&o, &payload).unwrap();
        let bit = 8 + bit.index((f.len() - 1) * 8);
        f[bit / 8] ^= 1 << (bit % 8);
        let split = f.len() - o.crc.len();
        prop_assert_eq!(
            plc::dl_open(&o, &f),
            Ok(DlReceived::WrongCrc { payload: f[1..split].to_vec(), crc: f[split..].to_vec() })
        );
    }

    /// No input panics.
    #[test]
    fn open_never_panics(code in 0..4u8, on_len in any::<bool>(), bytes in vec(any::<u8>(), 0..300), key in any::<[u8; 16]>()) {
        let _ = plc::phy_open(&bytes);
        let _ = plc::dl_open(&opts(DlCrc::from_code(code), on_len), &bytes);
        let _ = plc::ss_open(&key, &bytes);
    }
}

// ---- SS frames (Table 4) ----

const KEY: [u8; 16] = *b"street light key";
const IV: [u8; 12] = *b"twelve bytes";

fn aes_block(key: &[u8; 16], block: [u8; 16]) -> [u8; 16] {
    let mut b = block.into();
    aes::Aes128::new(key.into()).encrypt_block(&mut b);
    b.into()
}

#[test]
fn ss_sdu_layout_of_table_4() {
    let header = *b"HEAD";
    let payload = [0u8; 20];
    let data = [&header[..], &payload].concat();
    let sdu = plc::ss_seal(&KEY, &IV, 4, &data).unwrap();
    assert_eq!(sdu.len(), data.len() + plc::SS_OVERHEAD);
    assert_eq!(plc::SS_OVERHEAD, 29);
    // Header in clear, then the payload ciphered with the key stream from
    // the counter block IV || 00000001h, 00000002h (protocol notes).
    assert_eq!(&sdu[..4], b"HEAD");
    let mut cb = [0u8; 16];
    cb[..12].copy_from_slice(&IV);
    cb[15] = 1;
    let k1 = aes_block(&KEY, cb);
    cb[15] = 2;
    let k2 = aes_block(&KEY, cb);
    assert_eq!(&sdu[4..24], &[&k1[..], &k2[..4]].concat()[..]);
    // IV, HL, digest.
    assert_eq!(&sdu[24..36], &IV);
    assert_eq!(sdu[36], 4);
    let digest = plc::cmac(&KEY, &[&sdu[..4], &sdu[4..24], &IV, &[4]]);
    assert_eq!(&sdu[37..], &digest);
    assert_eq!(plc::ss_open(&KEY, &sdu).unwrap(), data);
}

#[test]
fn ss_payload_is_not_sent_in_clear() {
    let data = b"hdr:switch lamp 3 to 40 percent";
    let sdu = plc::ss_seal(&KEY, &IV, 4, data).unwrap();
    assert_eq!(&sdu[..4], b"hdr:");
    assert!(!sdu.windows(4).any(|w| data[4..].windows(4).any(|d| d == w)));
    // The whole buffer as header (Table 45: 16 bytes or more) is all clear.
    let sdu = plc::ss_seal(&KEY, &IV, data.len(), data).unwrap();
    assert_eq!(&sdu[..data.len()], data);
    assert_eq!(plc::ss_open(&KEY, &sdu).unwrap(), data);
}

#[test]
fn ss_seal_limits() {
    assert_eq!(plc::ss_seal(&KEY, &IV, 226, &[0; 226]).unwrap().len(), 255);
    assert_eq!(
        plc::ss_seal(&KEY, &IV, 4, &[0; 227]),
        Err(PlcError::TooLong { len: 227, max: 226 })
    );
    assert_eq!(
        plc::ss_seal(&KEY, &IV, 11, &[0; 10]),
        Err(PlcError::HeaderTooLong {
            header_len: 11,
            len: 10
        })
    );
    // An SS frame is a DL frame: 226 + 29 leaves no room for a CRC.
    let sdu = plc::ss_seal(&KEY, &IV, 4, &[0; 222]).unwrap();
    assert!(plc::dl_frame(&opts(DlCrc::Crc32Le, false), &sdu).is_ok());
    assert!(plc::dl_frame(&opts(DlCrc::Crc32Le, false), &[&sdu[..], &[0]].concat()).is_err());
}

#[test]
fn ss_open_failures() {
    assert_eq!(plc::ss_open(&KEY, &[0; 28]), Err(SsError::TooShort));
    assert_eq!(plc::ss_open(&KEY, &[0; 29]), Err(SsError::Authentication));
    let sdu = plc::ss_seal(&KEY, &IV, 4, b"abcdefgh").unwrap();
    let mut other = KEY;
    other[15] ^= 1;
    assert_eq!(plc::ss_open(&other, &sdu), Err(SsError::Authentication));
    // A well-signed SDU whose HL exceeds the data before the IV.
    let mut forged = [&b"abcd"[..], &IV, &[5]].concat();
    let digest = plc::cmac(&KEY, &[&forged]);
    forged.extend_from_slice(&digest);
    assert_eq!(plc::ss_open(&KEY, &forged), Err(SsError::BadHeaderLength));
    forged[16] = 4;
    assert_eq!(plc::ss_open(&KEY, &forged), Err(SsError::Authentication));
}

fn ss_case() -> impl Strategy<Value = (usize, Vec<u8>)> {
    vec(any::<u8>(), 0..=226).prop_flat_map(|data| (0..=data.len(), Just(data)))
}

proptest! {
    #[test]
    fn ss_frames_round_trip((hl, data) in ss_case(), key in any::<[u8; 16]>(), iv in any::<[u8; 12]>()) {
        let sdu = plc::ss_seal(&key, &iv, hl, &data).unwrap();
        prop_assert_eq!(&sdu[..hl], &data[..hl]);
        prop_assert_eq!(&sdu[data.len()..data.len() + 12], &iv);
        prop_assert_eq!(sdu[data.len() + 12] as usize, hl);
        prop_assert_eq!(plc::ss_open(&key, &sdu), Ok(data));
    }

    #[test]
    fn ss_flipped_bit_fails_authentication((hl, data) in ss_case(), bit in any::<prop::sample::Index>()) {
        let mut sdu = plc::ss_seal(&KEY, &IV, hl, &data).unwrap();
        let bit = bit.index(sdu.len() * 8);
        sdu[bit / 8] ^= 1 << (bit % 8);
        prop_assert_eq!(plc::ss_open(&KEY, &sdu), Err(SsError::Authentication));
    }
}
