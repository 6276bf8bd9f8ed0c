//! The checks the ST7580 applies to a request before executing it, with
//! the Table 14 cause it answers and the reason in words. The simulated
//! modem refuses with these; console forms refuse with them before anything
//! is sent.

use super::fields::tx_options;
use super::{mib, Command, ErrorCause, Modulation, TxParams};
use alloc::format;
use alloc::string::String;
use core::fmt;

/// Why the modem refuses a request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// What the modem answers (Table 14).
    pub cause: ErrorCause,
    /// Why, in words.
    pub reason: String,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.reason)
    }
}

fn wpv(reason: String) -> Refusal {
    Refusal {
        cause: ErrorCause::WrongParameterValue,
        reason,
    }
}

/// Largest SS header + payload buffer (UM0932 Table 45, 3.3.21).
pub const SS_MAX_BUFFER: usize = 226;

fn check_params(p: &TxParams) -> Result<(), Refusal> {
    if p.modulation == Modulation::Reserved {
        return Err(wpv("frame modulation 6 is reserved (Table 35)".into()));
    }
    if let Some(hz) = p.tx_frequency {
        tx_options::TX_FREQUENCY
            .check(hz as i64)
            .map_err(|e| wpv(format!("{e}")))?;
    }
    if let Some(g) = p.tx_gain {
        // Table 35: the gain is bits 0-4 of its byte; bits 5-7, "Unused",
        // must be 0 like every unused or reserved bit (protocol notes).
        tx_options::TX_GAIN
            .check(g as i64)
            .map_err(|e| wpv(format!("{e} (bits 5-7 of the TX gain byte are unused: 0)")))?;
    }
    Ok(())
}

/// The header-length rules of an SS_DataRequest (UM0932 Table 45, 2.3):
/// header and payload, "from 0 to 226 byte", whatever the DL CRC (an SS
/// frame's length byte does not count its CRC, `plc::ss_frame`); a header
/// length within that buffer, at least 4 when a payload follows and at
/// least 16 when the header is the whole buffer. The one rule for the
/// simulated modem, the console's form and the decoder's warning.
pub fn check_ss_buffer(header_length: u8, len: usize) -> Result<(), Refusal> {
    let hl = header_length as usize;
    if len > SS_MAX_BUFFER {
        return Err(Refusal {
            cause: ErrorCause::WrongParameterLength,
            reason: format!("header and payload are {len} bytes, more than {SS_MAX_BUFFER}"),
        });
    }
    // A length that does not fit the buffer is a wrong value of the
    // header length parameter, not a wrong length of the command (Table 14).
    if hl > len {
        return Err(wpv(format!(
            "header length {hl} is longer than the {len} bytes given"
        )));
    }
    let min = if hl < len { 4 } else { 16 };
    if hl < min {
        return Err(wpv(format!(
            "header length {hl} is below {min} ({})",
            if min == 4 {
                "a payload follows"
            } else {
                "the header is the whole buffer"
            }
        )));
    }
    Ok(())
}

/// Checks a request as the chip does. `dl_crc_len` is the DL CRC length in
/// bytes from MIB 00h (1, 2 or 4): a DL frame's payload plus CRC must fit
/// the PHY length byte (UM0932 Tables 2 and 3).
pub fn check_request(cmd: &Command, dl_crc_len: usize) -> Result<(), Refusal> {
    match cmd {
        Command::MibWriteRequest { index, data } => mib::check_write(*index, data)
            .map(|_| ())
            .map_err(Refusal::from),
        Command::MibReadRequest { index } => {
            mib::check_read(*index).map(|_| ()).map_err(Refusal::from)
        }
        Command::MibEraseRequest { index } => {
            mib::check_erase(*index).map(|_| ()).map_err(Refusal::from)
        }
        Command::PhyDataRequest(r) => check_params(&r.params),
        Command::DlDataRequest(r) => {
            check_params(&r.params)?;
            if r.payload.len() + dl_crc_len > 255 {
                return Err(Refusal {
                    cause: ErrorCause::WrongParameterLength,
                    reason: format!(
                        "a DL payload of {} bytes plus a {dl_crc_len}-byte CRC exceeds the 255 bytes of a PHY frame",
                        r.payload.len()
                    ),
                });
            }
            Ok(())
        }
        Command::SsDataRequest(r) => {
            check_params(&r.params)?;
            check_ss_buffer(r.header_length, r.header_and_payload.len())
        }
        _ => Ok(()),
    }
}

impl From<crate::mib::MibError> for Refusal {
    fn from(e: crate::mib::MibError) -> Self {
        Refusal {
            cause: mib::error_cause(&e),
            reason: format!("{e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::st7580::{DataRequest, SsDataRequest};
    use alloc::vec;

    fn ss(hl: u8, len: usize) -> Command {
        Command::SsDataRequest(SsDataRequest {
            params: TxParams::default(),
            header_length: hl,
            header_and_payload: vec![0; len],
        })
    }

    #[test]
    fn ss_requests_take_226_bytes_with_every_crc() {
        // UM0932 Table 45: "from 0 to 226 byte"; Table 48: "up to 226".
        for crc in [1, 2, 4] {
            assert!(check_request(&ss(4, 226), crc).is_ok(), "CRC of {crc}");
            let e = check_request(&ss(4, 227), crc).unwrap_err();
            assert_eq!(e.cause, ErrorCause::WrongParameterLength);
            assert!(e.reason.contains("227 bytes"), "{e}");
        }
    }

    #[test]
    fn ss_header_rules_of_table_45() {
        assert!(check_request(&ss(4, 10), 4).is_ok());
        assert_eq!(
            check_request(&ss(3, 10), 4).unwrap_err().cause,
            ErrorCause::WrongParameterValue
        );
        assert!(check_request(&ss(16, 16), 4).is_ok());
        assert_eq!(
            check_request(&ss(15, 15), 4).unwrap_err().cause,
            ErrorCause::WrongParameterValue
        );
        assert_eq!(
            check_request(&ss(4, 227), 4).unwrap_err().cause,
            ErrorCause::WrongParameterLength
        );
        // A header length beyond the buffer is a wrong value (WPV).
        assert_eq!(
            check_request(&ss(11, 10), 4).unwrap_err().cause,
            ErrorCause::WrongParameterValue
        );
    }

    #[test]
    fn data_requests_refuse_reserved_modulation_and_foreign_frequencies() {
        let mut r = DataRequest::default();
        r.params.modulation = Modulation::Reserved;
        assert_eq!(
            check_request(&Command::PhyDataRequest(r.clone()), 4)
                .unwrap_err()
                .cause,
            ErrorCause::WrongParameterValue
        );
        r.params.modulation = Modulation::QPsk;
        r.params.tx_frequency = Some(200_000);
        let e = check_request(&Command::PhyDataRequest(r.clone()), 4).unwrap_err();
        assert!(e.reason.contains("3000 to 148500 Hz"), "{e}");
        r.params.tx_frequency = Some(86_000);
        r.payload = vec![0; 252];
        assert!(check_request(&Command::PhyDataRequest(r.clone()), 4).is_ok());
        assert_eq!(
            check_request(&Command::DlDataRequest(r), 4)
                .unwrap_err()
                .cause,
            ErrorCause::WrongParameterLength
        );
    }

    #[test]
    fn unused_gain_bits_are_refused_like_a_mib_objects() {
        // One policy for unused and reserved bits (protocol notes): Table
        // 35's TX gain byte, bits 5-7, as Table 54's byte 7 bits 5-7.
        let mut r = DataRequest::default();
        r.params.tx_gain = Some(0x20 | 21);
        let phy = Command::PhyDataRequest(r.clone());
        let parsed = Command::parse(phy.code(), &phy.data()).unwrap();
        assert_eq!(parsed, phy, "the unused bits are kept");
        let e = check_request(&parsed, 4).unwrap_err();
        assert_eq!(e.cause, ErrorCause::WrongParameterValue);
        assert!(e.reason.contains("unused"), "{e}");
        let mut phy_config = mib::OBJECTS[1].default.to_vec();
        phy_config[7] |= 0x20;
        let mib = Command::MibWriteRequest {
            index: 1,
            data: phy_config,
        };
        assert_eq!(
            check_request(&mib, 4).unwrap_err().cause,
            ErrorCause::WrongParameterValue
        );
        r.params.tx_gain = Some(21);
        assert!(check_request(&Command::PhyDataRequest(r), 4).is_ok());
    }

    #[test]
    fn mib_refusals_carry_the_table_14_cause() {
        let wr = |index, data: &[u8]| {
            check_request(
                &Command::MibWriteRequest {
                    index,
                    data: data.to_vec(),
                },
                4,
            )
        };
        assert_eq!(
            wr(0x01, &[0; 3]).unwrap_err().cause,
            ErrorCause::WrongParameterLength
        );
        assert_eq!(
            wr(0x0A, &[0; 4]).unwrap_err().cause,
            ErrorCause::WrongParameterValue
        );
        assert_eq!(
            wr(0x00, &[0x03]).unwrap_err().cause,
            ErrorCause::WrongParameterValue,
            "access mode 3"
        );
        assert_eq!(
            wr(0x00, &[0x20]).unwrap_err().cause,
            ErrorCause::WrongParameterValue,
            "reserved bit 5"
        );
        assert_eq!(
            wr(0x09, &[0, 40, 10]).unwrap_err().cause,
            ErrorCause::WrongParameterValue,
            "zero T_SR"
        );
        assert!(wr(
            0x01,
            &[0x01, 0x4F, 0xF0, 0x01, 0x19, 0x40, 0x0E, 0x15, 0x00, 0x00, 0x02, 0x35, 0x9B, 0x58]
        )
        .is_ok());
        let high = [
            0x02, 0x49, 0xF0, 0x01, 0x19, 0x40, 0x0E, 0x15, 0x00, 0x00, 0x02, 0x35, 0x9B, 0x58,
        ];
        let e = wr(0x01, &high).unwrap_err();
        assert!(
            e.reason
                .starts_with("high_frequency: 150000 is out of range"),
            "{e}"
        );
        assert_eq!(
            check_request(&Command::MibEraseRequest { index: 0x01 }, 4)
                .unwrap_err()
                .cause,
            ErrorCause::WrongParameterValue
        );
        assert!(check_request(&Command::MibEraseRequest { index: 0x06 }, 4).is_ok());
        assert_eq!(
            check_request(&Command::MibReadRequest { index: 0x0B }, 4)
                .unwrap_err()
                .cause,
            ErrorCause::WrongParameterValue
        );
    }
}
