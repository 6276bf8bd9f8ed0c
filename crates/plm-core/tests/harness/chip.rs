//! What differs between the two chips in the link tests both run
//! (`link_both.rs`): the request the modem's application answers and its
//! answer, an unsolicited modem frame, the status message's length, and
//! the bench with the chip's reset settings. The chips' own suites
//! (`link_engines.rs`, `st7570_link.rs`) take their frames from here too.

use super::{Responder, Sim};
use plm_core::link::host::HostConfig;
use plm_core::link::{Dialect, LocalFrame};

/// PingRequest and PingConfirm (UM0932 Table 10).
pub const PING_REQ: u8 = 0x2C;
pub const PING_CNF: u8 = 0x2D;
/// DL_DataIndication (UM0932), an unsolicited modem frame.
pub const DL_DATA_IND: u8 = 0x52;
/// CMD_ReadDBRequest, CMD_ReadDBConfirm (ST7570 UM Table 15).
pub const READ_DB_REQ: u8 = 0x90;
pub const READ_DB_CNF: u8 = 0x91;
/// CMD_DataIndication (ST7570), an unsolicited modem frame.
pub const DATA_IND: u8 = 0x50;

/// One chip's side of the bench.
pub struct Chip {
    /// For messages.
    pub name: &'static str,
    /// Its host interface.
    pub dialect: Dialect,
    /// Bytes of its status message, `?` included (UM0932 Table 8;
    /// ST7570 UM Table 11).
    pub status_len: usize,
    /// A request the modem's application answers.
    pub request: fn() -> LocalFrame,
    /// The answer to it.
    pub confirm: fn(&LocalFrame) -> LocalFrame,
    /// An unsolicited modem frame.
    pub indication: fn() -> LocalFrame,
    /// The modem's application.
    pub responder: fn() -> Responder,
}

impl Chip {
    /// A bench of two engines with the chip's reset settings at `baud`,
    /// the modem's application answering.
    pub fn bench(&self, baud: u32) -> Sim {
        Sim::new_in(self.dialect, baud, HostConfig::at_reset(self.dialect, baud))
            .responder((self.responder)())
    }

    /// `f` as the chip puts it on the wire.
    pub fn emit(&self, f: &LocalFrame) -> Vec<u8> {
        f.emit(self.dialect).unwrap()
    }
}

/// A ping whose bytes hold no 02h/03h/06h/15h/3Fh after the STX.
pub fn ping() -> LocalFrame {
    LocalFrame::new(PING_REQ, vec![0x11, 0x22, 0x33])
}

/// PingConfirm: the request's data back.
pub fn ping_confirm(req: &LocalFrame) -> LocalFrame {
    LocalFrame::new(PING_CNF, req.data.clone())
}

/// The ST7580's application for pings.
pub fn ping_responder() -> Responder {
    Box::new(|_, f| (f.code == PING_REQ).then(|| ping_confirm(f)))
}

/// A DL_DataIndication whose bytes hold no 02h/03h/06h/15h after the
/// STX, so that what a receiver makes of its pieces is easy to predict.
pub fn dl_indication() -> LocalFrame {
    LocalFrame::new(DL_DATA_IND, vec![0x10, 0x20, 0x30, 0x40])
}

/// CMD_ReadDBRequest of MIB 000Bh; no 02h/06h/15h/3Fh after its STX.
pub fn read_db() -> LocalFrame {
    LocalFrame::new(READ_DB_REQ, vec![0x0B, 0x00])
}

/// CMD_ReadDBConfirm with the index asked and one value byte.
pub fn read_db_confirm(req: &LocalFrame) -> LocalFrame {
    let mut data = req.data.clone();
    data.push(0x80);
    LocalFrame::new(READ_DB_CNF, data)
}

/// The ST7570's application: CMD_ReadDBConfirm to CMD_ReadDBRequest.
pub fn read_db_responder() -> Responder {
    Box::new(|_, f| (f.code == READ_DB_REQ).then(|| read_db_confirm(f)))
}

/// The `n`th data indication, with no 02h/06h/15h/3Fh after its STX.
pub fn data_indication(n: u8) -> LocalFrame {
    LocalFrame::new(DATA_IND, vec![0x40 + n, 0x41, 0x42, 0x43])
}

/// The ST7580.
pub const ST7580: Chip = Chip {
    name: "ST7580",
    dialect: Dialect::St7580,
    status_len: 2,
    request: ping,
    confirm: ping_confirm,
    indication: dl_indication,
    responder: ping_responder,
};

/// The ST7570.
pub const ST7570: Chip = Chip {
    name: "ST7570",
    dialect: Dialect::St7570,
    status_len: 4,
    request: read_db,
    confirm: read_db_confirm,
    indication: || data_indication(0),
    responder: read_db_responder,
};

/// Both chips, for the tests they share.
pub const BOTH: [Chip; 2] = [ST7580, ST7570];
