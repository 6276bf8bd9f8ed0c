//! What the console knows of an ST7570's S-FSK network, from what its
//! modem tells the host (ST7570 UM 5.3): the status message decoded per
//! mode (Table 11), the synchronization history (Tables 17-18, 20, 65),
//! the nodes heard (Tables 37-38, 52), alarms (Tables 45, 57, 59),
//! repeater calls (Table 63), frames received, and in Monitor mode the
//! slot-by-slot SPY indications (5.3.17-5.3.22). Kept apart from the
//! views so that it can be tested natively; the Network and Data views
//! read it, [`crate::stores::Console`] feeds it.

use plm_core::field::Value;
use plm_core::link::LocalFrame;
use plm_core::st7570::fields::{self as f, sn_dbuv, snr_db};
use plm_core::st7570::mac::ns_count;
use plm_core::st7570::{Address, Command, Credit, Layer, MacSync, SignalNoise, Status};
use plm_core::time::Instant;

/// Entries kept in each history, newest last.
pub const KEPT: usize = 100;
/// Slots kept in the SPY timeline.
pub const SPY_SLOTS: usize = 120;

/// One line of a history: when, and what, in words.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// On the transport's clock.
    pub at: Instant,
    /// In words, with the manual's names.
    pub what: String,
}

/// A node heard, by its MAC address.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Heard {
    /// Frames heard from it.
    pub frames: u64,
    /// The last one.
    pub last: Instant,
    /// Its last frame's credits.
    pub credit: Option<Credit>,
    /// S0, N0, S1, N1 of its last frame that carried them (PHY, SPY).
    pub sn: Option<SignalNoise>,
    /// SNR0 and SNR1, dB, of its last frame that carried them.
    pub snr: Option<(f64, f64)>,
    /// The delta-phase the status message gave with its last frame
    /// (Table 4 code; Server and Monitor rows of Table 11).
    pub delta_phase: Option<u8>,
}

/// What a slot of the SPY timeline held (Monitor mode).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpyKind {
    /// A0h: no subframe.
    NoSubframe,
    /// B0h: a subframe.
    Subframe,
    /// C0h: searching for synchronization.
    Search,
    /// D0h: synchronization found.
    Found,
    /// E0h: no alarm in the window.
    NoAlarm,
    /// F0h: an alarm in the window.
    Alarm,
}

impl SpyKind {
    /// The slot's mark in the timeline and its CSS class suffix.
    pub fn mark(self) -> (&'static str, &'static str) {
        match self {
            SpyKind::NoSubframe => ("·", "none"),
            SpyKind::Subframe => ("S", "subframe"),
            SpyKind::Search => ("?", "search"),
            SpyKind::Found => ("F", "found"),
            SpyKind::NoAlarm => ("-", "none"),
            SpyKind::Alarm => ("A", "alarm"),
        }
    }
}

/// A frame the modem indicated to its host.
#[derive(Debug, Clone, PartialEq)]
pub struct Received {
    /// When.
    pub at: Instant,
    /// MAC mode: source and destination addresses.
    pub address: Option<(u16, u16)>,
    /// MAC mode: the credits.
    pub credit: Option<Credit>,
    /// M_SDU (MAC) or P_SDU (PHY).
    pub payload: Vec<u8>,
}

/// The network as the host's modem tells it.
#[derive(Debug, Clone, Default)]
pub struct NetworkLog {
    layer: Option<Layer>,
    /// The last status message, read per its row of Table 11.
    pub status: Option<(Instant, Status)>,
    /// Synchronization found, confirmed, lost (with the cause).
    pub syncs: Vec<Event>,
    /// Nodes heard, in the order of their MAC addresses (a list kept in
    /// order: a map type of its own would bring its own copy of the tree
    /// code into the console's wasm).
    pub heard: Vec<(u16, Heard)>,
    /// Alarms sent and received.
    pub alarms: Vec<Event>,
    /// Repeater calls and their results.
    pub calls: Vec<Event>,
    /// Frames indicated, newest last.
    pub received: Vec<Received>,
    /// Monitor mode: one entry per SPY indication, newest last.
    pub spy: Vec<(Instant, SpyKind, String)>,
}

/// Adds `item` to a bounded history, the oldest out when full (plain
/// lists: a `VecDeque` of each item type would bring its own code into
/// the console's wasm, and these hold a hundred items).
fn keep<T>(list: &mut Vec<T>, max: usize, item: T) {
    if list.len() == max {
        list.remove(0);
    }
    list.push(item);
}

/// S/N in words: `S0 62.0 / N0 30.0, S1 61.5 / N1 30.0 dBµV`.
pub fn sn_text(sn: &SignalNoise) -> String {
    let d = |v: u32| crate::numbers::fixed(sn_dbuv(v), 1);
    format!(
        "S0 {} / N0 {}, S1 {} / N1 {} dBµV",
        d(sn.s0),
        d(sn.n0),
        d(sn.s1),
        d(sn.n1)
    )
}

/// A 12-bit MAC address as the manual writes it (`C00h`).
pub fn address_text(a: u16) -> String {
    format!("{a:03X}h")
}

/// The manual's name of `code` in `table`, or the code marked undefined,
/// worded as the decoder words an enumerated value ([`Value`]'s display).
pub fn named(table: &[&'static str], code: u8) -> String {
    let name = table.get(code as usize).copied().filter(|s| !s.is_empty());
    Value::Enum { raw: code, name }.to_string()
}

/// A CONFIRM_CODE of `table` (Tables 43, 48) named, with what it means
/// when it is not OK (`plm_core::st7570::fields::confirm_meaning`).
pub fn confirm_text(table: &[&'static str], code: u8) -> String {
    let name = named(table, code);
    match f::confirm_meaning(table.get(code as usize).copied().unwrap_or("")) {
        Some(meaning) => format!("{name}: {meaning}"),
        None => name,
    }
}

/// A MAC CMD_SynchroIndication in words (Table 18).
pub fn sync_text(s: &MacSync) -> String {
    match *s {
        MacSync::Found(_) => "FOUND: PRE+SSD detected".to_string(),
        MacSync::Confirmed { sa, da, .. } => format!(
            "CONFIRMED by the frame from {} to {}",
            address_text(sa),
            address_text(da)
        ),
        MacSync::Lost { cause, add1, add2 } => format!(
            "LOST, cause {cause}: {} (ADD1 {}, ADD2 {})",
            named(f::LOST_CAUSES, cause),
            address_text(add1),
            address_text(add2)
        ),
        MacSync::Intelligent { cause, add, .. } => format!(
            "INTELLIGENT: {} (initiator {})",
            named(f::INTELLIGENT_CAUSES, cause),
            address_text(add)
        ),
        MacSync::Other { sync, .. } => format!("SYNC {sync} (undefined)"),
    }
}

impl NetworkLog {
    /// Forgets everything (a new connection).
    pub fn clear(&mut self) {
        *self = NetworkLog::default();
    }

    /// The access layer the modem's frames are read in: the one the last
    /// status message gave, else PHY (the factory default of 00A1h).
    pub fn layer(&self) -> Layer {
        self.layer.unwrap_or(Layer::Phy)
    }

    /// A status message came (the three bytes after `?`).
    pub fn on_status(&mut self, at: Instant, data: &[u8]) {
        if let Some(s) = Status::parse(data) {
            self.layer = Some(s.layer());
            self.status = Some((at, s));
        }
    }

    /// Something happened that the host did (an alarm sent, a repeater
    /// call's result), in words.
    pub fn note_alarm(&mut self, at: Instant, what: String) {
        keep(&mut self.alarms, KEPT, Event { at, what });
    }

    /// A repeater call's outcome, in words.
    pub fn note_call(&mut self, at: Instant, what: String) {
        keep(&mut self.calls, KEPT, Event { at, what });
    }

    /// A frame from the modem that answers no request: an indication.
    pub fn on_indication(&mut self, at: Instant, frame: &LocalFrame) {
        let Ok(cmd) = Command::from_frame(frame, self.layer()) else {
            return;
        };
        let delta_phase = self.status.map(|(_, s)| s.delta_phase).filter(|&d| d != 0);
        match cmd {
            Command::PhySynchroIndication(e) => {
                self.sync(at, format!("PRE+SSD found ({})", sn_text(&e.sn)))
            }
            Command::MacSynchroIndication(s) => self.sync(at, sync_text(&s)),
            Command::SynchroStatus { status } => self.sync(
                at,
                match status {
                    1 => "LP_SYNC_FOUND".to_string(),
                    2 => "LP_SYNC_LOSS".to_string(),
                    s => format!("STATUS {s} (undefined)"),
                },
            ),
            Command::IsIndication { is_status, locked } => self.sync(
                at,
                match locked {
                    Some(l) => format!(
                        "{}: initiator {}",
                        named(f::IS_STATUSES, is_status),
                        address_text(l.add)
                    ),
                    None => named(f::IS_STATUSES, is_status),
                },
            ),
            Command::MacDataIndication(m) => {
                let h = self.node(m.address.sa);
                h.frames += 1;
                h.last = at;
                h.credit = Some(m.credit);
                h.delta_phase = delta_phase.or(h.delta_phase);
                keep(
                    &mut self.received,
                    KEPT,
                    Received {
                        at,
                        address: Some((m.address.sa, m.address.da)),
                        credit: Some(m.credit),
                        payload: m.m_sdu,
                    },
                );
            }
            Command::PhyDataIndication(p) => {
                self.heard_phy(at, &p.p_sdu, None, (p.snr0, p.snr1), delta_phase);
                keep(
                    &mut self.received,
                    KEPT,
                    Received {
                        at,
                        address: None,
                        credit: None,
                        payload: p.p_sdu.to_vec(),
                    },
                );
            }
            Command::AlarmIndication { cnt, long } => {
                let what = match long {
                    Some((sn, _)) => format!("alarm received ({cnt} so far; {})", sn_text(&sn)),
                    None => format!("alarm received ({cnt} so far)"),
                };
                self.note_alarm(at, what);
            }
            Command::SpyNoSubframeIndication { sn, .. } => {
                self.spy(at, SpyKind::NoSubframe, sn_text(&sn))
            }
            Command::SpySubframeIndication(s) => {
                let who = self.heard_phy(at, &s.p_sdu, Some(s.sn), (s.snr0, s.snr1), delta_phase);
                let text = match who {
                    Some(sa) => format!("subframe from {}; {}", address_text(sa), sn_text(&s.sn)),
                    None => format!("subframe; {}", sn_text(&s.sn)),
                };
                self.spy(at, SpyKind::Subframe, text);
            }
            Command::SpySearchSynchroIndication => {
                self.spy(at, SpyKind::Search, "searching for synchronization".into())
            }
            Command::SpySynchroFoundIndication { sn, pga, .. } => self.spy(
                at,
                SpyKind::Found,
                format!("found; {}, PGA {pga}", sn_text(&sn)),
            ),
            Command::SpyNoAlarmIndication(a) => self.spy(at, SpyKind::NoAlarm, sn_text(&a.sn)),
            Command::SpyAlarmIndication(a) => self.spy(
                at,
                SpyKind::Alarm,
                format!("alarm {:06X}h; {}", a.alarm, sn_text(&a.sn)),
            ),
            _ => {}
        }
    }

    /// The entry of the node at `address`, made when first heard.
    fn node(&mut self, address: u16) -> &mut Heard {
        let i = match self.heard.binary_search_by_key(&address, |(a, _)| *a) {
            Ok(i) => i,
            Err(i) => {
                self.heard.insert(i, (address, Heard::default()));
                i
            }
        };
        &mut self.heard[i].1
    }

    fn sync(&mut self, at: Instant, what: String) {
        keep(&mut self.syncs, KEPT, Event { at, what });
    }

    fn spy(&mut self, at: Instant, kind: SpyKind, text: String) {
        keep(&mut self.spy, SPY_SLOTS, (at, kind, text));
    }

    /// A P_SDU heard with its estimations: when it is the first subframe
    /// of a MAC frame (FI, then NS, CREDIT and ADDRESS: 4.4.1, Figure 14)
    /// its SA is known and the node is counted.
    fn heard_phy(
        &mut self,
        at: Instant,
        p_sdu: &[u8],
        sn: Option<SignalNoise>,
        snr: (u32, u32),
        delta_phase: Option<u8>,
    ) -> Option<u16> {
        let head = p_sdu.get(2..8)?;
        ns_count([head[0], head[1]])?;
        let sa = Address::from_bytes([head[3], head[4], head[5]]).sa;
        let h = self.node(sa);
        h.frames += 1;
        h.last = at;
        h.credit = Some(Credit::from_byte(head[2]));
        h.sn = sn.or(h.sn);
        h.snr = Some((snr_db(snr.0), snr_db(snr.1)));
        h.delta_phase = delta_phase.or(h.delta_phase);
        Some(sa)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::st7570::MacData;

    /// A confirm code that is not OK says what it means (Tables 43, 48).
    #[test]
    fn confirm_codes_say_what_they_mean() {
        assert_eq!(
            confirm_text(&f::MAC_CONFIRM_CODES[..], 0x00),
            "LM_TU: the MAC layer is busy: send again"
        );
        assert_eq!(confirm_text(&f::MAC_CONFIRM_CODES[..], 0xFF), "LM_OK");
        assert_eq!(confirm_text(&f::ALARM_CONFIRM_CODES[..], 0xFF), "LP_OK");
        for table in [
            &f::MAC_CONFIRM_CODES,
            &f::PHY_CONFIRM_CODES,
            &f::ALARM_CONFIRM_CODES,
        ] {
            for (code, name) in table.iter().enumerate().filter(|(_, n)| !n.is_empty()) {
                let meant = f::confirm_meaning(name).is_some();
                assert_eq!(meant, !name.ends_with("_OK"), "{name} ({code:02X}h)");
            }
        }
        assert_eq!(
            confirm_text(&f::MAC_CONFIRM_CODES[..], 0x07),
            "7 (undefined)"
        );
    }

    fn frame(cmd: &Command) -> LocalFrame {
        cmd.to_frame()
    }

    #[test]
    fn a_server_s_synchronization_history_names_the_causes() {
        let mut log = NetworkLog::default();
        let mac_server = Status {
            mode: 2,
            mac: true,
            ..Status::default()
        };
        log.on_status(1, &mac_server.emit());
        let lost = Command::MacSynchroIndication(MacSync::Lost {
            cause: 2,
            add1: 5,
            add2: 0,
        });
        let confirmed = Command::MacSynchroIndication(MacSync::Confirmed {
            pad: 0,
            sa: 0xC00,
            da: 5,
        });
        log.on_indication(10, &frame(&confirmed));
        log.on_indication(20, &frame(&lost));
        let what: Vec<&str> = log.syncs.iter().map(|e| e.what.as_str()).collect();
        assert_eq!(
            what,
            [
                "CONFIRMED by the frame from C00h to 005h",
                "LOST, cause 2: Timeout frame not OK expired (ADD1 005h, ADD2 000h)"
            ]
        );
    }

    #[test]
    fn nodes_heard_are_counted_by_source_address_with_credits_and_delta_phase() {
        let mut log = NetworkLog::default();
        // A Server's status row with DELTA_PHASE +120° (code 3).
        let server = Status {
            mode: 2,
            mac: true,
            delta_phase: 3,
            ..Status::default()
        };
        log.on_status(1, &server.emit());
        let data = |sa| {
            Command::MacDataIndication(MacData {
                credit: Credit {
                    ic: 2,
                    cc: 1,
                    dc: 0,
                },
                address: Address { sa, da: 0xC00 },
                pad: 0,
                m_sdu: b"hi".to_vec(),
            })
        };
        log.on_indication(5, &frame(&data(1)));
        log.on_indication(6, &frame(&data(1)));
        log.on_indication(7, &frame(&data(2)));
        assert_eq!(log.heard.len(), 2);
        let h = &log.heard[0].1;
        assert_eq!((h.frames, h.last, h.delta_phase), (2, 6, Some(3)));
        assert_eq!(
            h.credit,
            Some(Credit {
                ic: 2,
                cc: 1,
                dc: 0
            })
        );
        assert_eq!(log.received.last().unwrap().address, Some((2, 0xC00)));
        // Kept in the order of the addresses.
        log.on_indication(8, &frame(&data(0)));
        let order: Vec<u16> = log.heard.iter().map(|(a, _)| *a).collect();
        assert_eq!(order, [0, 1, 2]);
    }

    #[test]
    fn phy_frames_are_read_in_the_layer_the_status_gives() {
        let mut log = NetworkLog::default();
        let phy_client = Status {
            mode: 1,
            mac: false,
            ..Status::default()
        };
        log.on_status(1, &phy_client.emit());
        assert_eq!(log.layer(), Layer::Phy);
        let ind = Command::PhyDataIndication(plm_core::st7570::PhyDataIndication {
            p_sdu: [0xEE; f::P_SDU_LEN],
            demodulation: Default::default(),
            snr0: 0,
            snr1: 0,
        });
        log.on_indication(3, &frame(&ind));
        assert_eq!(log.received.len(), 1);
        assert!(log.heard.is_empty(), "no MAC header in that P_SDU");
    }

    /// Runs `s` for `ms` of the page's clock, feeding `log` as the
    /// console's stores do.
    fn drive(s: &mut crate::session::Session, log: &mut NetworkLog, page: &mut f64, ms: u32) {
        use crate::driver::Budget;
        use crate::session::Note;
        for _ in 0..ms / 4 {
            *page += 4_000.0;
            let t = s.tick(*page, Budget::UNLIMITED);
            for n in t.notes {
                match n {
                    Note::Status { at, message } => log.on_status(at, message.data()),
                    Note::Unsolicited { at, frame, .. } => log.on_indication(at, &frame),
                    _ => {}
                }
            }
            for (r, o) in t.replies {
                r(o);
            }
        }
    }

    /// The console's simulated ST7570 network (node 0 and three Servers).
    fn simulated_network() -> crate::session::Session {
        crate::session::Session::new(
            Some(Box::new(crate::transport::sfsk::SfskTransport::new(
                4, 57_600, 7,
            ))),
            plm_core::link::Dialect::St7570,
        )
    }

    /// The session's simulated network.
    fn net(s: &mut crate::session::Session) -> &mut crate::transport::sfsk::SfskTransport {
        s.transport_mut().and_then(|t| t.sfsk()).unwrap()
    }

    /// Writes 00A1h with operating `mode` and access `layer` (Table 137)
    /// and reads it back, as the set-up card does: the status message of
    /// the read is the new mode's.
    fn set_up(s: &mut crate::session::Session, mode: u8, layer: u8) {
        use plm_core::st7570::mib::{index, object, PlcConfiguration};
        let mut plc = PlcConfiguration::decode(object(index::PLC_CONFIGURATION).unwrap().default);
        (plc.operating_mode, plc.access_layer_mode) = (mode, layer);
        s.request(
            s.chip().mib_write(index::PLC_CONFIGURATION, &plc.encode()),
            Box::new(|_| {}),
        );
        s.request(
            s.chip().mib_read(index::PLC_CONFIGURATION),
            Box::new(|_| {}),
        );
    }

    /// The console's simulated network with its modem a PHY Monitor: one
    /// SPY indication per slot (searching, no Client on the line) makes
    /// the timeline.
    #[test]
    fn a_monitor_s_spy_indications_make_the_timeline() {
        let mut s = simulated_network();
        let (mut log, mut page) = (NetworkLog::default(), 1_000_000.0);
        set_up(&mut s, 3, 1);
        drive(&mut s, &mut log, &mut page, 3_000);
        assert_eq!(log.status.map(|(_, st)| st.mode), Some(3));
        let kinds: Vec<SpyKind> = log.spy.iter().map(|(_, k, _)| *k).collect();
        assert!(kinds.len() >= 8, "{kinds:?}");
        assert!(kinds.iter().all(|k| *k == SpyKind::Search), "{kinds:?}");
    }

    /// The simulated network of the console's ST7570 profile, driven
    /// through the session as the page drives it: a MAC Client asks
    /// Server 001h, which answers; cut off by noise it loses
    /// synchronization (cause 2, with the MAC timeouts 60 times as fast)
    /// and finds it again once reconnected.
    #[test]
    fn a_simulated_server_answers_loses_synchronization_and_finds_it_again() {
        use crate::session::{Outcome, Session};
        use plm_core::st7570::Address;

        let mut s = simulated_network();
        let mut log = NetworkLog::default();
        let mut page = 1_000_000.0;
        let mut run = |s: &mut Session, log: &mut NetworkLog, ms: u32| drive(s, log, &mut page, ms);
        let sfsk = |s: &mut Session| net(s).servers();
        // Scaled first: a timeout already running keeps its deadline.
        net(&mut s).set_timeout_scale(60);
        set_up(&mut s, 1, 2);
        run(&mut s, &mut log, 1_000);
        let ask = || {
            Command::MacDataRequest(MacData {
                credit: Credit::default(),
                address: Address { sa: 0, da: 1 },
                pad: 0,
                m_sdu: b"?".to_vec(),
            })
            .to_frame()
        };
        let confirmed = std::rc::Rc::new(std::cell::Cell::new(0));
        let count = |c: &std::rc::Rc<std::cell::Cell<u32>>| {
            let c = c.clone();
            Box::new(move |o: Outcome| {
                if let Outcome::Answer {
                    command: Some(f), ..
                } = o
                {
                    if f.data == [0xFF] {
                        c.set(c.get() + 1);
                    }
                }
            })
        };
        s.request(ask(), count(&confirmed));
        run(&mut s, &mut log, 4_000);
        assert_eq!(confirmed.get(), 1, "LM_OK");
        let answer = log.received.last().expect("Server 001h answered");
        assert_eq!(answer.address, Some((1, 0xC00)));
        assert!(answer.payload.starts_with(b"!001"), "{:?}", answer.payload);
        // Confirmed by that frame, then lost once 0003h (40 s / 60) passed
        // with no frame at all.
        let one = &sfsk(&mut s)[0];
        assert!(!one.synchronized);
        let causes: Vec<_> = one.syncs.iter().map(|(_, y)| y.clone()).collect();
        assert!(
            matches!(
                causes[..],
                [
                    ..,
                    MacSync::Confirmed { .. },
                    MacSync::Lost { cause: 2, .. }
                ]
            ),
            "{causes:?}"
        );

        // Cut off, it hears nothing: the Client's frame goes (LM_OK) and
        // no answer comes.
        net(&mut s).cut_off(1, true);
        s.request(ask(), count(&confirmed));
        run(&mut s, &mut log, 4_000);
        assert_eq!((confirmed.get(), log.received.len()), (2, 1));
        let one = &sfsk(&mut s)[0];
        assert!(one.cut_off && !one.synchronized);
        assert_eq!(one.syncs.len(), causes.len(), "{:?}", one.syncs);

        // Reconnected: found and confirmed again, and it answers.
        net(&mut s).cut_off(1, false);
        s.request(ask(), count(&confirmed));
        run(&mut s, &mut log, 4_000);
        assert_eq!((confirmed.get(), log.received.len()), (3, 2));
        let one = &sfsk(&mut s)[0];
        assert!(
            one.syncs
                .iter()
                .skip(causes.len())
                .any(|(_, y)| matches!(y, MacSync::Confirmed { .. })),
            "{:?}",
            one.syncs
        );

        // An alarm from Server 001h (synchronized: 0003h at 40 s again)
        // reaches the Client's host.
        net(&mut s).set_timeout_scale(1);
        s.request(ask(), count(&confirmed));
        run(&mut s, &mut log, 2_000);
        net(&mut s).raise_alarm(1);
        run(&mut s, &mut log, 3_000);
        let alarms: Vec<&str> = log.alarms.iter().map(|e| e.what.as_str()).collect();
        assert!(
            matches!(alarms[..], [a] if a.starts_with("alarm received (")),
            "{alarms:?}"
        );
    }

    #[test]
    fn monitor_slots_make_a_timeline_of_bounded_length() {
        let mut log = NetworkLog::default();
        let monitor = Status {
            mode: 3,
            mac: true,
            ..Status::default()
        };
        log.on_status(0, &monitor.emit());
        for i in 0..(SPY_SLOTS as u64 + 5) {
            log.on_indication(i, &frame(&Command::SpySearchSynchroIndication));
        }
        assert_eq!(log.spy.len(), SPY_SLOTS);
        assert_eq!(log.spy.first().unwrap().0, 5);
        assert_eq!(log.spy.last().unwrap().1, SpyKind::Search);
    }
}
