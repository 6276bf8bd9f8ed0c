//! The simulated ST7570's MIB (ST7570 UM 6, Table 71): every object's
//! value, the side effects of a write the manual gives, the counters, and
//! what survives a reset (7.1, Tables 149-150). Which write is allowed and
//! what error a refused one draws is plm-core's `st7570::validate`; this
//! store only applies what it accepted.

use plm_core::mib::Object;
use plm_core::st7570::mib::{self as mib, index, PlcConfiguration, TicRepeater, OBJECTS};
use plm_core::st7570::validate::Context;

/// 0006h Invalid frame counter.
pub const INVALID_FRAMES: u16 = 0x0006;
/// 0007h Minimum delta credit.
pub const MIN_DELTA_CREDIT: u16 = 0x0007;
/// 000Fh Transmitted frame counter.
pub const TRANSMITTED_FRAMES: u16 = 0x000F;
/// 0082h TX output gain / current limiting.
pub const TX_GAIN: u16 = 0x0082;
/// 0084h Transmitted alarm counter.
pub const TRANSMITTED_ALARMS: u16 = 0x0084;
/// 0085h N_TX, N_RX, N_REJ.
pub const ALARM_PARAMETERS: u16 = 0x0085;
/// 0009h Timeout intelligent synchronization (minutes).
pub const IS_TIMEOUT: u16 = 0x0009;

/// ST7570 UM 7.1.1, Table 149: the PHY settings auto-reconfiguration
/// restores (00A2h, which Table 71 calls reserved, has no value to keep).
pub const PHY_RECONFIGURED: &[u16] = &[
    index::PLC_CONFIGURATION,
    TX_GAIN,
    index::TIC_REPEATER,
    ALARM_PARAMETERS,
    0x0086,
    0x00A4,
    0x00C2,
    0x00D1,
];

/// ST7570 UM 7.1.2, Table 150: the MAC settings it restores. 000Bh is in
/// both tables (TIC selector, repeater state): the whole byte is kept.
pub const MAC_RECONFIGURED: &[u16] = &[
    index::LOCAL_INIT_MAC_ADD,
    0x0005,
    index::TIC_REPEATER,
    index::FIMA_LIMA,
    0x0002,
    0x0003,
    0x0004,
    IS_TIMEOUT,
    0x0008,
    0x0015,
    0x000C,
    0x0016,
    0x0012,
    0x0013,
];

/// The objects whose write resets them to their default rather than
/// storing the data (6.5.7, 6.5.8 and the counters' tables: written with
/// PAD bytes of any value). 0082h also has its own write layout, but its
/// write carries a value ([`Store::write`]).
pub fn write_resets(o: &Object) -> bool {
    o.write.is_some() && o.index != TX_GAIN
}

/// The MIB values.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Store {
    values: Vec<(u16, Vec<u8>)>,
    /// What 00A1h and 0000h say ([`Store::context`]), read again when
    /// either is written: the modem asks for its layer and mode at every
    /// look at its deadlines.
    context: Context,
}

impl Default for Store {
    /// Every object at its factory default.
    fn default() -> Self {
        let mut store = Store {
            values: OBJECTS
                .iter()
                .map(|o| (o.index, o.default.to_vec()))
                .collect(),
            context: Context::default(),
        };
        store.read_context();
        store
    }
}

impl Store {
    /// The value of `index`, if the object exists.
    pub fn get(&self, index: u16) -> Option<&[u8]> {
        self.values
            .iter()
            .find(|(i, _)| *i == index)
            .map(|(_, v)| v.as_slice())
    }

    fn slot(&mut self, index: u16) -> Option<&mut Vec<u8>> {
        self.values
            .iter_mut()
            .find(|(i, _)| *i == index)
            .map(|(_, v)| v)
    }

    /// Stores a value whole (no checks: the caller validated it).
    pub fn set(&mut self, index: u16, value: &[u8]) {
        if let Some(v) = self.slot(index) {
            v.clear();
            v.extend_from_slice(value);
        }
        if matches!(index, index::PLC_CONFIGURATION | index::FIMA_LIMA) {
            self.read_context();
        }
    }

    /// What decides availability and mode checks (00A1h, 0000h).
    pub fn context(&self) -> Context {
        self.context
    }

    fn read_context(&mut self) {
        self.context = Context::from_mib(
            self.get(index::PLC_CONFIGURATION).unwrap_or_default(),
            self.get(index::FIMA_LIMA).unwrap_or_default(),
        );
    }

    /// 00A1h.
    pub fn plc(&self) -> PlcConfiguration {
        PlcConfiguration::decode(self.get(index::PLC_CONFIGURATION).unwrap_or_default())
    }

    /// 000Bh.
    pub fn tic_repeater(&self) -> TicRepeater {
        TicRepeater::from_byte(self.byte(index::TIC_REPEATER, 0))
    }

    /// Byte `at` of an object (0 when absent).
    pub fn byte(&self, index: u16, at: usize) -> u8 {
        self.get(index)
            .and_then(|v| v.get(at).copied())
            .unwrap_or(0)
    }

    /// A 16-bit LSByte-first word of an object (6.1).
    pub fn word(&self, index: u16, at: usize) -> u16 {
        u16::from_le_bytes([self.byte(index, at), self.byte(index, at + 1)])
    }

    /// 0001h LocalMACAdd.
    pub fn local_address(&self) -> u16 {
        self.word(index::LOCAL_INIT_MAC_ADD, 0)
    }

    /// 0000h FIMA.
    pub fn fima(&self) -> u16 {
        self.word(index::FIMA_LIMA, 0)
    }

    /// Applies a write `validate::check_write` accepted and returns the
    /// data of the CMD_WriteDBConfirm: the object's value after the write
    /// (6.1: the confirm has the read confirm's format, so a counter
    /// confirms its reset value and 0082h its 3 bytes).
    pub fn write(&mut self, o: &Object, data: &[u8]) -> Vec<u8> {
        match o.index {
            _ if write_resets(o) => self.set(o.index, o.default),
            // 6.5.29: 00A0h is a command, not a value (it cannot be read).
            index::NEW_SYNCHRONIZATION => return data.to_vec(),
            // 6.5.24: current limiting and target gain; the actual gain
            // follows the target (no line load is simulated yet). Table
            // 149 lists digital gain and current control under both 00A1h
            // and 0082h: they are one setting, kept equal in both.
            TX_GAIN => {
                self.set(TX_GAIN, &[data[0], data[1], data[1]]);
                let mut plc = self.plc();
                plc.tx_current_limiting = data[0] == 1;
                plc.target_output_gain = data[1];
                self.set_plc(plc);
            }
            index::PLC_CONFIGURATION => {
                self.set(o.index, data);
                let plc = self.plc();
                let gain = plc.target_output_gain;
                self.set(TX_GAIN, &[plc.tx_current_limiting as u8, gain, gain]);
            }
            _ => self.set(o.index, data),
        }
        self.get(o.index).unwrap_or_default().to_vec()
    }

    /// Writes 00A1h from values, keeping its PAD and unused bits.
    fn set_plc(&mut self, plc: PlcConfiguration) {
        let Some(v) = self.slot(index::PLC_CONFIGURATION) else {
            return;
        };
        let fresh = plc.encode();
        for f in [
            &mib::plc::TARGET_OUTPUT_GAIN,
            &mib::plc::TX_CURRENT_LIMITING,
        ] {
            f.set(v, f.get(&fresh).unwrap_or(0));
        }
        self.read_context();
    }

    /// Adds `n` to a 4-byte LSByte-first counter (wrapping like the chip's
    /// 32-bit registers).
    pub fn count(&mut self, index: u16, n: u32) {
        if let Some(v) = self.slot(index) {
            if let Ok(b) = <[u8; 4]>::try_from(v.as_slice()) {
                let c = u32::from_le_bytes(b).wrapping_add(n);
                v.copy_from_slice(&c.to_le_bytes());
            }
        }
    }

    /// A 4-byte counter's value.
    pub fn counter(&self, index: u16) -> u32 {
        self.get(index)
            .and_then(|v| <[u8; 4]>::try_from(v).ok())
            .map_or(0, u32::from_le_bytes)
    }

    /// The store after a reset: with auto-reconfiguration (`keep`) the
    /// objects of Tables 149 and 150 keep their values, every other object
    /// (counters, 0007h, estimations, 00ABh, 00ACh) returns to its default;
    /// without it (CMD_ResetRequest RESET = 1) everything does.
    pub fn after_reset(&self, keep: bool) -> Store {
        let mut fresh = Store::default();
        if keep {
            for i in PHY_RECONFIGURED.iter().chain(MAC_RECONFIGURED) {
                if let Some(v) = self.get(*i) {
                    fresh.set(*i, v);
                }
            }
        }
        fresh
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::st7570::Layer;

    /// The context kept is the one the MIB says after every kind of write
    /// (a whole value, 0082h's gain into 00A1h, a reset).
    #[test]
    fn the_context_follows_the_mib() {
        let said = |s: &Store| {
            Context::from_mib(
                s.get(index::PLC_CONFIGURATION).unwrap(),
                s.get(index::FIMA_LIMA).unwrap(),
            )
        };
        let mut s = Store::default();
        assert_eq!(s.context(), said(&s));
        let mut plc = s.plc();
        plc.operating_mode = 2;
        plc.access_layer_mode = Layer::Mac.access_layer_mode();
        let o = mib::object(index::PLC_CONFIGURATION).unwrap();
        s.write(o, &plc.encode());
        assert_eq!((s.context().mode, s.context().layer), (2, Layer::Mac));
        s.write(
            mib::object(index::FIMA_LIMA).unwrap(),
            &[0x01, 0x0C, 0x02, 0x0D],
        );
        assert_eq!((s.context().fima, s.context().lima), (0x0C01, 0x0D02));
        s.write(mib::object(TX_GAIN).unwrap(), &[1, 7]);
        assert_eq!(s.context(), said(&s));
        let kept = s.after_reset(true);
        assert_eq!(kept.context(), said(&kept));
        assert_eq!(kept.context().mode, 2);
        let fresh = s.after_reset(false);
        assert_eq!(fresh.context(), Context::default());
    }

    #[test]
    fn every_restored_object_exists_and_counters_are_not_restored() {
        for i in PHY_RECONFIGURED.iter().chain(MAC_RECONFIGURED) {
            assert!(mib::object(*i).is_some(), "{i:04X}h");
        }
        let resets: Vec<u16> = OBJECTS
            .iter()
            .filter(|o| write_resets(o))
            .map(|o| o.index)
            .collect();
        assert_eq!(
            resets,
            [0x0006, 0x0007, 0x000A, 0x000F, 0x0010, 0x0011, 0x0083, 0x0084]
        );
        for i in resets {
            assert!(!PHY_RECONFIGURED.contains(&i) && !MAC_RECONFIGURED.contains(&i));
        }
    }

    #[test]
    fn gain_is_one_setting_in_00a1h_and_0082h() {
        let mut s = Store::default();
        let o = mib::object(TX_GAIN).unwrap();
        assert_eq!(s.write(o, &[1, 0x1F]), [1, 0x1F, 0x1F]);
        let plc = s.plc();
        assert!(plc.tx_current_limiting);
        assert_eq!(plc.target_output_gain, 0x1F);
        assert_eq!(
            plc.f0,
            PlcConfiguration::decode(mib::object(0x00A1).unwrap().default).f0
        );
    }
}
