//! The fault suites' harness, written once over the chip: plm-core's host
//! engine and one simulated modem in virtual time ([`Modem`]: the
//! ST7580's [`HostDriver`], the ST7570's [`ModemDriver`]), a request whose
//! confirm names it by a tag, a one-shot fault on the `k`-th byte either
//! way ([`fault_at`]), and what the host reported about one request
//! ([`Exchange`]). `faults_both.rs` holds the runs both chips pass the
//! same way; `faults.rs` (ST7580) and `st7570_faults.rs` what only one
//! chip does.

#![allow(dead_code)] // each suite uses its part

use plm_core::link::host::{Event, LinkError, Ticket};
use plm_core::link::{Element, LocalFrame, Stx};
use plm_core::time::{Duration, Instant, MS};
use plm_core::{st7570, st7580};
use plm_sim::st7570::drive::ModemDriver;
use plm_sim::uart::OneShot;
use plm_sim::{ByteFaults, Dir, Fault, HostDriver, Sim, SimConfig};

pub const SEC: Duration = 1_000 * MS;
/// Past T_IC (the ST7580's reset T_IC is 10 ms, the ST7570's 5
/// characters), short of T_ACK (40 ms).
pub const PAST_T_IC: Duration = 15 * MS;

/// The tag of the targeted runs: the ST7580's ping `11 22 33` (frame `02
/// 03 2C 11 22 33 95 00`), the ST7570's write of `22 33 21` into 0085h:
/// no byte after the STX is an STX, `?`, ACK or NAK, so what a receiver
/// makes of the pieces is plain.
pub const TAG: u16 = 0x3322;

/// One simulated modem with its host, as the fault suites drive it.
pub trait Modem: Sized {
    /// The chip, for messages.
    const NAME: &'static str;
    /// Bytes of the tagged request's frame, and of its confirm.
    const FRAME: usize;
    /// Bytes of the status message, the first the modem sends in an
    /// exchange (UM0932 Table 8: `?` and one byte; ST7570 UM Table 11:
    /// `?` and three); its ACK follows, then the confirm.
    const STATUS: usize;
    /// What a host frame cut short by T_IC brings the host: the ST7580
    /// NAKs it (UM0932 3.2.8, "in other cases"), the ST7570 drops it
    /// (ST7570 UM 5.2.2) and the host's T_ACK runs out.
    const CUT_FRAME: LinkError;
    /// How long an exchange is followed after its request ended, for the
    /// modem's repeats and second confirms.
    const SETTLE: Duration;

    /// A modem powered on at `baud`, its UART faults drawing on an RNG
    /// seeded `seed`, what it sends at power-on taken.
    fn powered(seed: u64, baud: u32) -> Self;
    /// Queues the request tagged `tag`.
    fn submit_tagged(&mut self, tag: u16) -> Ticket;
    /// Whether `f` is the confirm of the request tagged `tag`.
    fn is_confirm(f: &LocalFrame, tag: u16) -> bool;
    /// Whether `f` is what the modem may send about a host frame broken
    /// on the way rather than a confirm: the ST7570's CMD_SyntaxError 01h
    /// (ST7570 UM 5.3.26); the ST7580 only NAKs.
    fn is_syntax_error(f: &LocalFrame) -> bool;
    /// Puts `fault` on the next byte written in direction `dir`.
    fn inject(&mut self, dir: Dir, fault: OneShot);
    /// Random byte faults in direction `dir` from now on.
    fn set_faults(&mut self, dir: Dir, faults: ByteFaults);
    /// Every host event so far, with its time.
    fn events(&self) -> &[(Instant, Event)];
    /// Runs until `done` holds for an event or `limit` µs have passed.
    fn run_until(&mut self, limit: Duration, done: impl FnMut(&Event) -> bool) -> bool;
    /// Requests the host still holds.
    fn pending(&self) -> usize;

    /// Where the modem's ACK is, modem to host, in a clean exchange.
    fn m2h_ack() -> usize {
        Self::STATUS
    }
    /// Where the confirm starts, modem to host, in a clean exchange.
    fn m2h_confirm() -> usize {
        Self::STATUS + 1
    }
    /// Where the host's ACK of the confirm is, host to modem.
    fn h2m_ack() -> usize {
        Self::FRAME
    }
    fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_| false);
    }
}

/// Puts `fault` on the `k`-th byte (from 0) written in direction `dir`
/// from now on: a one-shot fault hits the next byte written its way, so
/// zero-length stalls (which change nothing) go in front of it.
pub fn fault_at<M: Modem>(d: &mut M, dir: Dir, k: usize, fault: OneShot) {
    for _ in 0..k {
        d.inject(dir, OneShot::Delay(0));
    }
    d.inject(dir, fault);
}

pub fn ended(e: &Event, ticket: Ticket) -> bool {
    matches!(e, Event::Delivered(t) | Event::Failed(t, _) if *t == ticket)
}

/// What the host engine reported about one request.
#[derive(Debug)]
pub struct Exchange {
    pub ticket: Ticket,
    pub events: Vec<Event>,
}

impl Exchange {
    pub fn delivered(&self) -> bool {
        self.events
            .iter()
            .any(|e| matches!(e, Event::Delivered(t) if *t == self.ticket))
    }

    pub fn failed(&self) -> Vec<LinkError> {
        self.events
            .iter()
            .filter_map(|e| match e {
                Event::Failed(t, why) if *t == self.ticket => Some(*why),
                _ => None,
            })
            .collect()
    }

    pub fn retries(&self) -> Vec<LinkError> {
        self.events
            .iter()
            .filter_map(|e| match e {
                Event::Retry { ticket, cause, .. } if *ticket == self.ticket => Some(*cause),
                _ => None,
            })
            .collect()
    }

    /// The STX of every frame reported that `is` takes for the confirm.
    pub fn frames_where(&self, is: impl Fn(&LocalFrame) -> bool) -> Vec<Stx> {
        self.events
            .iter()
            .filter_map(|e| match e {
                Event::Frame(f) if is(f) => Some(f.stx),
                _ => None,
            })
            .collect()
    }

    /// The STX of every confirm of the request tagged `tag` reported as a
    /// frame (a repeat the host already took is [`Exchange::repeats`]).
    pub fn confirms<M: Modem>(&self, tag: u16) -> Vec<Stx> {
        self.frames_where(|f| M::is_confirm(f, tag))
    }

    pub fn repeats(&self) -> usize {
        self.events
            .iter()
            .filter(|e| matches!(e, Event::Repeat(_)))
            .count()
    }

    pub fn naks_received(&self) -> usize {
        self.events
            .iter()
            .filter(|e| matches!(e, Event::Received(Element::Nak)))
            .count()
    }

    pub fn naks_sent(&self) -> usize {
        self.events
            .iter()
            .filter(|e| matches!(e, Event::Sent(Element::Nak)))
            .count()
    }
}

/// Runs until `ticket` ends and [`Modem::SETTLE`] more; what the host
/// reported from event `start` on.
pub fn finish<M: Modem>(d: &mut M, start: usize, ticket: Ticket) -> Exchange {
    d.run_until(10 * SEC, |e| ended(e, ticket));
    d.run_for(M::SETTLE);
    Exchange {
        ticket,
        events: d.events()[start..].iter().map(|(_, e)| e.clone()).collect(),
    }
}

/// Sends the request tagged `tag` and follows it to its end.
pub fn exchange<M: Modem>(d: &mut M, tag: u16) -> Exchange {
    let start = d.events().len();
    let ticket = d.submit_tagged(tag);
    finish(d, start, ticket)
}

/// The next request goes through at once, confirmed once.
pub fn assert_link_works<M: Modem>(d: &mut M, tag: u16) {
    let ex = exchange(d, tag);
    assert!(ex.delivered(), "{}: {ex:#?}", M::NAME);
    assert_eq!(ex.retries(), vec![], "{}: {ex:#?}", M::NAME);
    assert_eq!(
        ex.confirms::<M>(tag),
        vec![Stx::First],
        "{}: {ex:#?}",
        M::NAME
    );
    assert_eq!(d.pending(), 0, "{}", M::NAME);
}

/// One fault on byte `k` of the exchange in `dir`, on a modem at 57 600
/// baud: the request tagged [`TAG`] is delivered, nothing fails, and the
/// link works after it; returns what happened.
pub fn with_fault<M: Modem>(dir: Dir, k: usize, fault: OneShot) -> Exchange {
    let mut d = M::powered(1, 57_600);
    fault_at(&mut d, dir, k, fault);
    let ex = exchange(&mut d, TAG);
    assert!(ex.delivered(), "{} byte {k}, {fault:?}: {ex:#?}", M::NAME);
    assert_eq!(ex.failed(), vec![], "{} byte {k}, {fault:?}", M::NAME);
    assert_link_works(&mut d, k as u16);
    ex
}

// ---- the ST7580 ---------------------------------------------------------

/// The ST7580's tagged request: PingRequest of `11 lo hi` (UM0932 Table
/// 41), whose PingConfirm echoes the data.
pub fn ping(data: &[u8]) -> st7580::Command {
    st7580::Command::PingRequest {
        data: data.to_vec(),
    }
}

fn ping_data(tag: u16) -> [u8; 3] {
    [0x11, tag as u8, (tag >> 8) as u8]
}

impl Modem for HostDriver {
    const NAME: &'static str = "ST7580";
    const FRAME: usize = 8;
    const STATUS: usize = 2;
    const CUT_FRAME: LinkError = LinkError::Nak;
    /// Past T_ACK and the STX 03h repeat.
    const SETTLE: Duration = 500 * MS;

    /// Powered on, its BIO_ResetIndication taken.
    fn powered(seed: u64, baud: u32) -> Self {
        let mut d = HostDriver::new(Sim::new(SimConfig {
            seed,
            baud,
            ..SimConfig::default()
        }));
        d.run_for(100 * MS);
        let frames = d.frames();
        assert!(
            matches!(&frames[..], [st7580::Command::BioResetIndication(r)] if r.reset_cause == st7580::ResetCause::PowerOn),
            "{frames:?}"
        );
        d
    }
    fn submit_tagged(&mut self, tag: u16) -> Ticket {
        self.submit(&ping(&ping_data(tag)))
    }
    fn is_confirm(f: &LocalFrame, tag: u16) -> bool {
        f.code == st7580::code::PING_CONFIRM && f.data == ping_data(tag)
    }
    fn is_syntax_error(_: &LocalFrame) -> bool {
        false
    }
    fn inject(&mut self, dir: Dir, fault: OneShot) {
        self.sim.inject(match fault {
            OneShot::Drop => Fault::DropByte(dir),
            OneShot::Corrupt(mask) => Fault::CorruptByte(dir, mask),
            OneShot::Delay(by) => Fault::DelayByte(dir, by),
        });
    }
    fn set_faults(&mut self, dir: Dir, faults: ByteFaults) {
        self.sim.set_byte_faults(dir, faults);
    }
    fn events(&self) -> &[(Instant, Event)] {
        &self.events
    }
    fn run_until(&mut self, limit: Duration, done: impl FnMut(&Event) -> bool) -> bool {
        HostDriver::run_until(self, limit, done)
    }
    fn pending(&self) -> usize {
        self.host.pending()
    }
}

// ---- the ST7570 ---------------------------------------------------------

/// The ST7570's tagged request: CMD_WriteDBRequest of 0085h (the alarm
/// parameters, three bytes of any value, Table 131) with `lo hi 21h`.
pub fn write(tag: u16) -> st7570::Command {
    st7570::Command::WriteDbRequest {
        index: 0x0085,
        data: vec![tag as u8, (tag >> 8) as u8, 0x21],
    }
}

impl Modem for ModemDriver {
    const NAME: &'static str = "ST7570";
    /// `02 08 41 85 00 lo hi 21 ck ck`.
    const FRAME: usize = 10;
    const STATUS: usize = 4;
    const CUT_FRAME: LinkError = LinkError::NoAck;
    /// Past T_WBC and the repeat after a NAK.
    const SETTLE: Duration = SEC;

    /// Powered on for 10 ms (it sends nothing at power-on).
    fn powered(seed: u64, baud: u32) -> Self {
        let mut d = ModemDriver::with_seed(baud, seed);
        d.run_for(10 * MS);
        assert!(d.events.is_empty(), "{:?}", d.events);
        d
    }
    fn submit_tagged(&mut self, tag: u16) -> Ticket {
        self.submit(&write(tag))
    }
    fn is_confirm(f: &LocalFrame, tag: u16) -> bool {
        f.code == st7570::code::CMD_WRITE_DB_CONFIRM
            && f.data[..] == [0x85, 0x00, tag as u8, (tag >> 8) as u8, 0x21]
    }
    fn is_syntax_error(f: &LocalFrame) -> bool {
        f.code == st7570::code::CMD_SYNTAX_ERROR && f.data == [0x01]
    }
    fn inject(&mut self, dir: Dir, fault: OneShot) {
        self.wire(dir).inject(fault);
    }
    fn set_faults(&mut self, dir: Dir, faults: ByteFaults) {
        self.wire(dir).faults = faults;
    }
    fn events(&self) -> &[(Instant, Event)] {
        &self.events
    }
    fn run_until(&mut self, limit: Duration, done: impl FnMut(&Event) -> bool) -> bool {
        ModemDriver::run_until(self, limit, done)
    }
    fn pending(&self) -> usize {
        self.host.pending()
    }
}
