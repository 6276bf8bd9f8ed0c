//! The checks the ST7570 applies to a MIB request (ST7570 UM 6.1-6.3 and
//! the error tables of 6.5) and to a data request (Table 43), with the
//! code it answers and the reason in words. The simulated modem refuses
//! with these; console forms refuse with them before anything is sent.

use super::fields::{mac_data, M_SDU_MAX, P_SDU_LEN};
use super::mib::{self, index, modes, PlcConfiguration};
use super::{Command, Layer};
use crate::mib::{MibError, Object};
use alloc::format;
use alloc::string::String;
use core::fmt;

/// The MIB error codes of Table 70.
pub mod error {
    /// No object with this index, or not in the current access layer.
    pub const ERR_UNAVAILABLE_RESOURCE: u8 = 0x11;
    /// Request not allowed (in this operating mode, or on this object).
    pub const ERR_REQUEST_NOT_ALLOWED: u8 = 0x12;
    /// The format or a value of the data is not valid for the object.
    pub const ERR_ILLEGAL_DATA_COMMAND: u8 = 0x22;
    /// Invalid local MAC address.
    pub const ERR_ILLEGAL_LOCAL_MAC_ADR: u8 = 0x23;
    /// Invalid initiator MAC address.
    pub const ERR_ILLEGAL_INITIATOR_MAC_ADR: u8 = 0x24;
    /// Parameter value out of range.
    pub const ERR_PARAM_VAL_OUTOFRANGE: u8 = 0x26;
}
use error::*;

/// What the modem is configured as: it decides which objects exist and
/// which writes are allowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Context {
    /// The access layer (00A1h byte 12).
    pub layer: Layer,
    /// The operating mode (00A1h byte 0 b0..b2).
    pub mode: u8,
    /// FIMA (0000h).
    pub fima: u16,
    /// LIMA (0000h).
    pub lima: u16,
}

impl Default for Context {
    /// The factory configuration: PHY, IDLE, FIMA C00h, LIMA DFFh.
    fn default() -> Self {
        Context {
            layer: Layer::Phy,
            mode: 0,
            fima: 0x0C00,
            lima: 0x0DFF,
        }
    }
}

impl Context {
    /// The context of the values of 00A1h and 0000h.
    pub fn from_mib(plc_configuration: &[u8], fima_lima: &[u8]) -> Self {
        let p = PlcConfiguration::decode(plc_configuration);
        let w = |i: usize| {
            fima_lima
                .get(i..i + 2)
                .map_or(0, |b| u16::from_le_bytes([b[0], b[1]]))
        };
        Context {
            layer: p.layer().unwrap_or(Layer::Phy),
            mode: p.operating_mode,
            fima: w(0),
            lima: w(2),
        }
    }
}

/// Why the modem refuses a MIB request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// The code of CMD_WriteDBError / CMD_ReadDBError (Table 70).
    pub error: u8,
    /// Why, in words.
    pub reason: String,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.reason)
    }
}

fn refuse(error: u8, reason: String) -> Refusal {
    Refusal { error, reason }
}

/// The object, if it exists in the context's layer (11h otherwise).
fn available(index: u16, ctx: &Context) -> Result<&'static Object, Refusal> {
    let o = mib::object(index).ok_or_else(|| {
        refuse(
            ERR_UNAVAILABLE_RESOURCE,
            format!("there is no MIB object {index:04X}h"),
        )
    })?;
    if !mib::in_layer(o, ctx.layer) {
        return Err(refuse(
            ERR_UNAVAILABLE_RESOURCE,
            format!(
                "{} ({index:04X}h) exists only with the MAC access layer, the modem is in PHY mode",
                o.name
            ),
        ));
    }
    Ok(o)
}

/// The code an object answers for a value out of its range (the error
/// tables of 6.5: most say ERR_ILLEGAL_DATA_COMMAND).
fn value_error(o: &Object, field: &str) -> u8 {
    match (o.index, field) {
        (index::FIMA_LIMA, _) | (index::LOCAL_INIT_MAC_ADD, "init_mac_add") => {
            ERR_ILLEGAL_INITIATOR_MAC_ADR
        }
        (index::LOCAL_INIT_MAC_ADD, _) => ERR_ILLEGAL_LOCAL_MAC_ADR,
        (0x0008 | 0x0015 | index::PLC_CONFIGURATION, _) => ERR_PARAM_VAL_OUTOFRANGE,
        _ => ERR_ILLEGAL_DATA_COMMAND,
    }
}

/// Checks a CMD_WriteDBRequest as the chip does; the object on success.
pub fn check_write(index: u16, data: &[u8], ctx: &Context) -> Result<&'static Object, Refusal> {
    let o = available(index, ctx)?;
    if !o.access.write {
        return Err(refuse(
            ERR_REQUEST_NOT_ALLOWED,
            format!("{} ({index:04X}h) is read-only", o.name),
        ));
    }
    if data.len() != o.write_len() {
        return Err(refuse(
            ERR_ILLEGAL_DATA_COMMAND,
            format!(
                "{} is written with {} data bytes, not {}",
                o.name,
                o.write_len(),
                data.len()
            ),
        ));
    }
    if ctx.mode < 8 && o.scope.write_modes & (1 << ctx.mode) == 0 {
        let why = if o.scope.write_modes == modes::MONITOR {
            "only a Monitor"
        } else {
            "a Monitor cannot"
        };
        return Err(refuse(
            ERR_REQUEST_NOT_ALLOWED,
            format!("{}: {why} writes it", o.name),
        ));
    }
    // 6.5.12: in PHY mode only the TIC selector bit may be set.
    if index == index::TIC_REPEATER && ctx.layer == Layer::Phy && data[0] & 0x7F != 0 {
        return Err(refuse(
            ERR_ILLEGAL_DATA_COMMAND,
            format!(
                "in PHY mode {} takes only 00h or 80h, not {:02X}h",
                o.name, data[0]
            ),
        ));
    }
    if let Err(MibError::Field(e)) = o.check_write(data) {
        return Err(refuse(value_error(o, e.field), format!("{}: {e}", o.name)));
    }
    // Table 74: InitMACAdd is NO-BODY (0000h) or FIMA..LIMA.
    if index == index::LOCAL_INIT_MAC_ADD {
        let init = u16::from_le_bytes([data[2], data[3]]);
        if init != 0 && !(ctx.fima..=ctx.lima).contains(&init) {
            return Err(refuse(
                ERR_ILLEGAL_INITIATOR_MAC_ADR,
                format!(
                    "InitMACAdd {init:03X}h is neither NO-BODY (000h) nor within FIMA..LIMA ({:03X}h..{:03X}h)",
                    ctx.fima, ctx.lima
                ),
            ));
        }
    }
    Ok(o)
}

/// Checks a CMD_ReadDBRequest as the chip does; the object on success.
pub fn check_read(index: u16, ctx: &Context) -> Result<&'static Object, Refusal> {
    let o = available(index, ctx)?;
    if !o.access.read {
        return Err(refuse(
            ERR_REQUEST_NOT_ALLOWED,
            format!(
                "{} ({index:04X}h) is written only, it cannot be read",
                o.name
            ),
        ));
    }
    Ok(o)
}

/// The CONFIRM_CODE the modem answers at once to a CMD_DataRequest whose
/// length it refuses (Table 43: LM_SE, 03h): a PHY P_SDU is 38 bytes, a
/// MAC M_SDU 1..242 bytes.
pub fn check_data_request(cmd: &Command) -> Result<(), (u8, String)> {
    const LM_SE: u8 = 0x03;
    match cmd {
        Command::PhyDataRequest { p_sdu } if p_sdu.len() != P_SDU_LEN => Err((
            LM_SE,
            format!("a P_SDU is {P_SDU_LEN} bytes, not {}", p_sdu.len()),
        )),
        Command::MacDataRequest(d) if d.m_sdu.is_empty() || d.m_sdu.len() > M_SDU_MAX => Err((
            LM_SE,
            format!(
                "an M_SDU is 1..={M_SDU_MAX} bytes, not {} ({} data bytes after the {}-byte header)",
                d.m_sdu.len(),
                d.m_sdu.len(),
                mac_data::HEADER_LEN
            ),
        )),
        _ => Ok(()),
    }
}

/// Checks a request the host sends, MIB or data: the code the modem would
/// answer (a MIB error code, or a CONFIRM_CODE) and why.
pub fn check_request(cmd: &Command, ctx: &Context) -> Result<(), (u8, String)> {
    match cmd {
        Command::WriteDbRequest { index, data } => check_write(*index, data, ctx)
            .map(|_| ())
            .map_err(|r| (r.error, r.reason)),
        Command::ReadDbRequest { index } => check_read(*index, ctx)
            .map(|_| ())
            .map_err(|r| (r.error, r.reason)),
        _ => check_data_request(cmd),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mac(mode: u8) -> Context {
        Context {
            layer: Layer::Mac,
            mode,
            ..Context::default()
        }
    }

    fn code(r: Result<&'static Object, Refusal>) -> u8 {
        r.map(|_| 0).unwrap_or_else(|r| r.error)
    }

    #[test]
    fn error_codes_of_the_6_5_tables() {
        let phy = Context::default();
        assert_eq!(
            code(check_write(0x0017, &[0], &mac(1))),
            0x11,
            "unused index"
        );
        assert_eq!(code(check_write(0x0000, &[0; 4], &phy)), 0x11, "MAC only");
        assert_eq!(code(check_write(0x0000, &[0; 3], &mac(1))), 0x22, "length");
        assert_eq!(code(check_write(0x0000, &[0, 0x10, 0, 0], &mac(1))), 0x24);
        assert_eq!(code(check_write(0x0001, &[0, 0x10, 0, 0], &mac(2))), 0x23);
        assert_eq!(code(check_write(0x0001, &[1, 0, 0, 0x0B], &mac(2))), 0x24);
        assert_eq!(code(check_write(0x0001, &[1, 0, 0, 0x0C], &mac(2))), 0);
        assert_eq!(code(check_write(0x0002, &[3, 0], &mac(3))), 0x12, "Monitor");
        assert_eq!(code(check_write(0x0002, &[3, 0], &mac(2))), 0);
        assert_eq!(
            code(check_write(0x0015, &[1], &mac(2))),
            0x12,
            "not Monitor"
        );
        assert_eq!(code(check_write(0x0015, &[2], &mac(3))), 0x26);
        assert_eq!(code(check_write(0x0008, &[0x0F], &mac(3))), 0);
        assert_eq!(code(check_write(0x0008, &[0x10], &mac(3))), 0x26);
        assert_eq!(
            code(check_write(0x000B, &[0x81], &phy)),
            0x22,
            "PHY: 00h/80h"
        );
        assert_eq!(code(check_write(0x000B, &[0x80], &phy)), 0);
        assert_eq!(code(check_write(0x000B, &[0x83], &mac(2))), 0);
        assert_eq!(code(check_write(0x000D, &[0; 10], &phy)), 0x12, "read-only");
        assert_eq!(code(check_write(0x0014, &[0], &mac(2))), 0x12, "read-only");
        assert_eq!(code(check_read(0x00A0, &phy)), 0x12, "write-only");
        assert_eq!(code(check_write(0x0082, &[1, 31], &phy)), 0, "2 bytes");
        assert_eq!(code(check_write(0x0082, &[1, 31, 31], &phy)), 0x22);
        assert_eq!(code(check_write(0x0006, &[0xAA; 4], &mac(1))), 0, "PAD");
        assert_eq!(code(check_write(0x0007, &[0xAA], &mac(1))), 0, "PAD");
        let mut plc = mib::object(0x00A1).unwrap().default.to_vec();
        plc[12] = 3;
        assert_eq!(code(check_write(0x00A1, &plc, &phy)), 0x26);
        assert_eq!(code(check_write(0x00A1, &plc[..13], &phy)), 0x22);
    }

    #[test]
    fn data_request_lengths() {
        let phy = |n| Command::PhyDataRequest {
            p_sdu: alloc::vec![0; n],
        };
        assert!(check_data_request(&phy(38)).is_ok());
        assert_eq!(check_data_request(&phy(37)).unwrap_err().0, 0x03);
        let mac = |n| {
            Command::MacDataRequest(super::super::MacData {
                m_sdu: alloc::vec![0; n],
                ..Default::default()
            })
        };
        assert!(check_data_request(&mac(1)).is_ok() && check_data_request(&mac(242)).is_ok());
        assert_eq!(check_data_request(&mac(0)).unwrap_err().0, 0x03);
        assert_eq!(check_data_request(&mac(243)).unwrap_err().0, 0x03);
    }
}
