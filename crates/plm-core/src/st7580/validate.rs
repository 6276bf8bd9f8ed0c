//! The checks the ST7580 applies to a request before executing it, with
//! the Table 14 cause it answers and the reason in words. The simulated
//! modem refuses with these; console forms refuse with them before anything
//! is sent.

use super::fields::tx_options;
use super::{mib, plc, Command, ErrorCause, Modulation, TxParams};
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
        tx_options::TX_GAIN
            .check(g as i64)
            .map_err(|e| wpv(format!("{e}")))?;
    }
    Ok(())
}

/// Checks a request as the chip does. `dl_crc_len` is the DL CRC length in
/// bytes from MIB 00h (1, 2 or 4): a DL frame's payload plus CRC, and an SS
/// frame's header and payload plus 29 bytes of IV, HL and digest plus CRC,
/// must fit the PHY length byte (UM0932 Tables 3 and 4).
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
            let total = r.header_and_payload.len();
            let hl = r.header_length as usize;
            let wpl = |reason| {
                Err(Refusal {
                    cause: ErrorCause::WrongParameterLength,
                    reason,
                })
            };
            if total > SS_MAX_BUFFER {
                return wpl(format!(
                    "header and payload are {total} bytes, more than {SS_MAX_BUFFER}"
                ));
            }
            // The SS_SDU (Table 4) adds IV, HL and digest, and rides in a DL
            // frame whose CRC must fit the PHY length byte too (Table 3).
            let frame = total + plc::SS_OVERHEAD + dl_crc_len;
            if frame > plc::MAX_LENGTH {
                return wpl(format!(
                    "header and payload of {total} bytes plus {} bytes of IV, HL and digest and a {dl_crc_len}-byte CRC exceed the {} bytes of a PHY frame",
                    plc::SS_OVERHEAD,
                    plc::MAX_LENGTH
                ));
            }
            if hl > total {
                return wpl(format!(
                    "header length {hl} is longer than the {total} bytes given"
                ));
            }
            // Table 45 (see protocol notes): at least 4 header bytes before an
            // encrypted payload, at least 16 when there is no payload.
            let min = if hl < total { 4 } else { 16 };
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
    fn ss_requests_must_fit_a_dl_frame_with_its_crc() {
        let wpl = |hl, len, crc| {
            check_request(&ss(hl, len), crc).map_err(|e| e.cause)
                == Err(ErrorCause::WrongParameterLength)
        };
        // 255 = header and payload + 29 (IV, HL, digest) + CRC.
        assert!(check_request(&ss(4, 222), 4).is_ok());
        assert!(wpl(4, 223, 4));
        assert!(check_request(&ss(4, 224), 2).is_ok());
        assert!(wpl(4, 225, 2));
        assert!(check_request(&ss(4, 225), 1).is_ok());
        assert!(wpl(4, 226, 1), "226 of Table 45 leaves no room for a CRC");
        let e = check_request(&ss(4, 223), 4).unwrap_err();
        assert!(e.reason.contains("4-byte CRC"), "{e}");
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
        assert_eq!(
            check_request(&ss(11, 10), 4).unwrap_err().cause,
            ErrorCause::WrongParameterLength
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
        assert!(e.reason.contains("3000..=148500 Hz"), "{e}");
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
