//! What the ST7570 network tests share: a node's host (plm-core's host
//! engine, ST7570 dialect) asking its modem and waiting for the answer
//! that closes the request (`code::answers`), MIB reads and writes, and
//! 00A1h set to an operating mode and access layer.

// Each test crate that includes this module uses a part of it.
#![allow(dead_code)]

use plm_core::st7570::mib::{object, PlcConfiguration};
use plm_core::st7570::Command;
use plm_core::time::MS;
use plm_sim::st7570::drive::Outcome;
use plm_sim::st7570::net::Network;

/// 00A1h access layer (Table 137): PHY.
pub const PHY: u8 = 1;
/// 00A1h access layer (Table 137): MAC.
pub const MAC: u8 = 2;

/// The answer to `cmd` from node `node`'s modem, within 5 s.
pub fn answer(net: &mut Network, node: usize, cmd: Command) -> Command {
    match net.request(node, &cmd, 5_000 * MS) {
        Outcome::Answer(a) => a,
        other => panic!("node {node} {cmd:?}: {other:?}"),
    }
}

/// Writes a MIB object; panics unless it is confirmed.
pub fn write(net: &mut Network, node: usize, index: u16, data: &[u8]) {
    let cmd = Command::WriteDbRequest {
        index,
        data: data.to_vec(),
    };
    match answer(net, node, cmd) {
        Command::WriteDbConfirm { .. } => {}
        other => panic!("node {node} write {index:04X}h: {other:?}"),
    }
}

/// Reads a MIB object; panics unless it is confirmed.
pub fn read(net: &mut Network, node: usize, index: u16) -> Vec<u8> {
    match answer(net, node, Command::ReadDbRequest { index }) {
        Command::ReadDbConfirm { data, .. } => data,
        other => panic!("node {node} read {index:04X}h: {other:?}"),
    }
}

/// 00A1h's factory default with this operating mode and access layer.
pub fn plc(operating_mode: u8, layer: u8) -> Vec<u8> {
    let mut p = PlcConfiguration::decode(object(0x00A1).unwrap().default);
    p.operating_mode = operating_mode;
    p.access_layer_mode = layer;
    p.encode()
}

/// Makes node `node` a modem of this operating mode and access layer.
pub fn configure(net: &mut Network, node: usize, operating_mode: u8, layer: u8) {
    write(net, node, 0x00A1, &plc(operating_mode, layer));
}
