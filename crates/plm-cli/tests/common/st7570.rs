//! A host of `plm sim --chip st7570` for the tests: an RFC 2217 port
//! (`plm board`'s client) and plm-core's host engine in the ST7570
//! dialect, in wall time.

use super::WAIT;
use plm_cli::rfc2217::client::{com_port, Client};
use plm_cli::rfc2217::{cmd, control, escape};
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Transmit};
use plm_core::link::{Dialect, Element, Source, StreamDecoder};
use plm_core::st7570::mib::{index, object, PlcConfiguration};
use plm_core::st7570::{code, Address, Command, Credit, Layer, MacData, Status};
use plm_core::time::MS;
use std::time::{Duration, Instant};

pub const BAUD: u32 = 57_600;

/// The host: an RFC 2217 port and plm-core's host engine.
pub struct Host {
    pub port: Client,
    pub engine: HostEngine,
    start: Instant,
    /// Every event since the last [`Host::mark`].
    pub events: Vec<Event>,
    /// The layer its frames are read in (00A1h's, as last written).
    pub layer: Layer,
}

impl Host {
    pub fn new(port: Client) -> Host {
        let mut config = HostConfig::at_reset(Dialect::St7570, BAUD);
        // Bytes cross two processes and TCP: a frame may come in bursts
        // further apart than the chip's 5 characters (0.87 ms), and a
        // loaded machine may schedule either side late. The host
        // receives with 30 ms between characters and waits 100 ms for a
        // status or an ACK, as a host behind a USB bridge may.
        config.timeouts.t_ic = 30 * MS;
        config.timeouts.t_poll = 100 * MS;
        config.timeouts.t_ack = 100 * MS;
        Host {
            port,
            engine: HostEngine::new(Dialect::St7570, config),
            start: Instant::now(),
            events: Vec::new(),
            layer: Layer::Phy,
        }
    }

    pub fn now(&self) -> u64 {
        self.start.elapsed().as_micros() as u64
    }

    /// One turn: what came to the engine, its timers, its output to the
    /// port (bytes and RTS in one write: data, SET-CONTROL RTS, data, as a
    /// driver that releases T_REQ right after STX).
    pub fn step(&mut self) {
        let data = self
            .port
            .read_data(Duration::from_micros(500))
            .expect("plm sim is there");
        let now = self.now();
        if !data.is_empty() {
            self.engine.handle_rx(now, &data);
        }
        if self.engine.poll_timeout().is_some_and(|t| t <= now) {
            self.engine.handle_timeout(now);
        }
        let mut out = Vec::new();
        while let Some(t) = self.engine.poll_transmit() {
            match t {
                Transmit::Bytes(b) => out.extend(escape(&b)),
                Transmit::TReq { asserted } => out.extend(com_port(
                    cmd::SET_CONTROL,
                    &[if asserted {
                        control::RTS_ON
                    } else {
                        control::RTS_OFF
                    }],
                )),
            }
        }
        if !out.is_empty() {
            self.port.send(&out).expect("plm sim is there");
        }
        while let Some(e) = self.engine.poll_event() {
            self.events.push(e);
        }
    }

    /// Runs until `want` takes a frame the modem sent, or WAIT.
    pub fn frame<T>(&mut self, what: &str, mut want: impl FnMut(Command) -> Option<T>) -> T {
        let deadline = Instant::now() + WAIT;
        let mut seen = self.events.len();
        loop {
            while seen < self.events.len() {
                seen += 1;
                if let Event::Frame(f) = &self.events[seen - 1] {
                    if let Some(t) = Command::from_frame(f, self.layer).ok().and_then(&mut want) {
                        return t;
                    }
                }
            }
            assert!(
                Instant::now() < deadline,
                "no {what}; events: {:?}",
                self.events
            );
            self.step();
        }
    }

    /// Sends `cmd` and waits for the answer that closes it in the
    /// current layer (`code::answers`).
    pub fn request(&mut self, cmd: &Command) -> Command {
        self.events.clear();
        let ticket = self.engine.submit(self.now(), cmd.to_frame());
        let request = cmd.code();
        let layer = self.layer;
        let deadline = Instant::now() + WAIT;
        let mut seen = 0;
        loop {
            while seen < self.events.len() {
                seen += 1;
                match &self.events[seen - 1] {
                    Event::Frame(f) if code::answers(request, f.code, layer) => {
                        return Command::from_frame(f, layer).expect("an answer that parses");
                    }
                    Event::Failed(t, why) if *t == ticket => panic!("{cmd:?}: {why}"),
                    _ => {}
                }
            }
            assert!(Instant::now() < deadline, "{cmd:?}: {:?}", self.events);
            self.step();
        }
    }

    /// Sends `cmd`, which the link must give up on (nothing answers).
    pub fn unanswered(&mut self, cmd: &Command) -> LinkError {
        self.events.clear();
        let ticket = self.engine.submit(self.now(), cmd.to_frame());
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(why) = self.events.iter().find_map(|e| match e {
                Event::Failed(t, why) if *t == ticket => Some(*why),
                _ => None,
            }) {
                return why;
            }
            assert!(Instant::now() < deadline, "{cmd:?}: {:?}", self.events);
            self.step();
        }
    }

    pub fn read(&mut self, index: u16) -> Vec<u8> {
        match self.request(&Command::ReadDbRequest { index }) {
            Command::ReadDbConfirm { index: i, data } if i == index => data,
            other => panic!("read {index:04X}h: {other:?}"),
        }
    }

    pub fn write(&mut self, index: u16, data: &[u8]) -> Vec<u8> {
        let cmd = Command::WriteDbRequest {
            index,
            data: data.to_vec(),
        };
        match self.request(&cmd) {
            Command::WriteDbConfirm { index: i, data } if i == index => data,
            other => panic!("write {index:04X}h: {other:?}"),
        }
    }

    /// The status message that let the last request in.
    pub fn status(&self) -> Status {
        Status::from_message(&self.engine.last_status().expect("a status came"))
            .expect("a status message")
    }

    /// Waits `d` of wall time, serving the link meanwhile.
    pub fn idle(&mut self, d: Duration) {
        let until = Instant::now() + d;
        while Instant::now() < until {
            self.step();
        }
    }
}

/// T_REQ straight on the port: the status message (4 bytes, `?` first)
/// and its delay, and nothing else.
pub fn treq_status(port: &mut Client) -> (Vec<u8>, Duration) {
    let got = status_on_treq(port);
    port.set_rts(false).unwrap();
    got
}

/// T_REQ asserted (and left so): the status message's bytes, and how long
/// they took to come.
pub fn status_on_treq(port: &mut Client) -> (Vec<u8>, Duration) {
    let mut decoder = StreamDecoder::new(Dialect::St7570, Source::Modem);
    let asked = Instant::now();
    port.set_rts(true).unwrap();
    let deadline = asked + WAIT;
    let mut bytes = Vec::new();
    let status = loop {
        let data = port.read_data(Duration::from_millis(5)).unwrap();
        bytes.extend_from_slice(&data);
        decoder.push(&data);
        if let Some(e) = decoder.next() {
            break e;
        }
        assert!(
            Instant::now() < deadline,
            "no status after T_REQ: {bytes:02X?}"
        );
    };
    let took = asked.elapsed();
    match status {
        Element::Status(_) => {}
        other => panic!("T_REQ drew {other:?}"),
    }
    (bytes, took)
}

/// 00A1h's factory default made a MAC Client.
pub fn mac_client() -> Vec<u8> {
    let mut p = PlcConfiguration::decode(object(index::PLC_CONFIGURATION).unwrap().default);
    p.operating_mode = plm_sim::st7570::mode::CLIENT;
    p.access_layer_mode = Layer::Mac.access_layer_mode();
    p.encode()
}

/// A MAC frame from the Client to `da`, no credit: what the tests send.
pub fn mac_frame(da: u16, m_sdu: &[u8]) -> MacData {
    MacData {
        credit: Credit {
            ic: 0,
            cc: 0,
            dc: 0,
        },
        address: Address { sa: 0, da },
        pad: 0,
        m_sdu: m_sdu.to_vec(),
    }
}
