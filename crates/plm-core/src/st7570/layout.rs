//! Which layout of [`super::fields`] describes a frame's data: the one
//! lookup the decoder, console forms and the simulated modem share, so that
//! none of them chooses a table by itself.

use super::code as c;
use super::fields::{self as f, alarm_indication, is_indication, mac_data, mac_sync, rc_confirm};
use super::Layer;
use crate::field::{Field, Value};
use crate::link::Source;
use alloc::vec::Vec;

/// The layout of the data of a frame with `code`, sent by `from`, in
/// `layer`; `None` for a code Table 15 does not define or data that fits
/// none of the command's forms (a MAC CMD_SynchroIndication with an
/// undefined SYNC, a CMD_AlarmIndication of neither 4 nor 17 bytes).
/// 21h takes the confirm's layout only when the modem sent it.
pub fn layout(code: u8, layer: Layer, from: Source, data: &[u8]) -> Option<&'static [Field]> {
    let len = data.len();
    Some(match code {
        c::CMD_SYNCHRO_INDICATION => match layer {
            Layer::Phy => f::PHY_SYNCHRO_INDICATION,
            Layer::Mac => match data.first()? {
                1 => mac_sync::FOUND,
                2 => mac_sync::CONFIRMED,
                4 => mac_sync::LOST,
                5 => mac_sync::INTELLIGENT,
                _ => return None,
            },
        },
        c::CMD_DESYNCHRO_REQUEST => f::DESYNCHRO_REQUEST,
        c::CMD_SYNCHRO_STATUS if len == 0 => &[],
        c::CMD_SYNCHRO_STATUS => f::SYNCHRO_STATUS,
        c::CMD_RESET_REQUEST if from == Source::Modem => f::RESET_CONFIRM,
        c::CMD_RESET_REQUEST => f::RESET_REQUEST,
        c::CMD_WRITE_DB_REQUEST | c::CMD_WRITE_DB_CONFIRM | c::CMD_READ_DB_CONFIRM => f::DB_DATA,
        c::CMD_READ_DB_REQUEST => f::DB_INDEX,
        c::CMD_WRITE_DB_ERROR | c::CMD_READ_DB_ERROR => f::DB_ERROR,
        c::CMD_DATA_INDICATION => match layer {
            Layer::Phy => f::PHY_DATA_INDICATION,
            Layer::Mac => mac_data::LAYOUT,
        },
        c::CMD_DATA_REQUEST => match layer {
            Layer::Phy => f::PHY_DATA_REQUEST,
            Layer::Mac => mac_data::LAYOUT,
        },
        c::CMD_DATA_CONFIRM => match layer {
            Layer::Phy => f::PHY_DATA_CONFIRM,
            Layer::Mac => f::MAC_DATA_CONFIRM,
        },
        c::CMD_ALARM_REQUEST | c::SPY_SEARCH_SYNCHRO_INDICATION => &[],
        c::CMD_ALARM_CONFIRM => f::ALARM_CONFIRM,
        c::CMD_ALARM_INDICATION => match len {
            alarm_indication::SHORT_LEN => alarm_indication::SHORT,
            alarm_indication::LONG_LEN => alarm_indication::LONG,
            _ => return None,
        },
        c::SPY_NO_SUBFRAME_INDICATION => f::SPY_NO_SUBFRAME,
        c::SPY_SUBFRAME_INDICATION => f::SPY_SUBFRAME,
        c::SPY_SYNCHRO_FOUND_INDICATION => f::SPY_SYNCHRO_FOUND,
        c::SPY_NO_ALARM_INDICATION | c::SPY_ALARM_INDICATION => f::spy_alarm::LAYOUT,
        c::CMD_RC_REQUEST => f::RC_REQUEST,
        c::CMD_RC_CONFIRM if len == rc_confirm::LONG_LEN => rc_confirm::LONG,
        c::CMD_RC_CONFIRM => rc_confirm::SHORT,
        c::CMD_IS_INDICATION if len == is_indication::LONG_LEN => is_indication::LONG,
        c::CMD_IS_INDICATION => is_indication::SHORT,
        c::CMD_SYNTAX_ERROR => f::SYNTAX_ERROR,
        _ => return None,
    })
}

/// The named values of a frame's data (see [`layout`]); empty when no
/// layout fits. Fields the data is too short for are left out.
pub fn describe(code: u8, layer: Layer, from: Source, data: &[u8]) -> Vec<(&'static Field, Value)> {
    layout(code, layer, from, data).map_or_else(Vec::new, |l| crate::mib::describe(l, data))
}
