//! `plm sim --chip st7570` end to end (issue 12, "Must show"): the real
//! binary serving a simulated S-FSK line of ST7570s over RFC 2217 on
//! loopback, driven by `plm board`'s RFC 2217 client
//! (`plm_cli::rfc2217::client`) and plm-core's host engine in the ST7570
//! dialect, in wall time: T_REQ answered by a status message within
//! T_POLL, a MIB object read, written and read back, the modem made a MAC
//! Client (00A1h), a MAC frame to a Server answered by its echo, and a
//! DTR (RESETn) pulse reported by the status message's RESET bit.

mod common;

use common::{Server, WAIT};
use plm_cli::rfc2217::client::{com_port, Client};
use plm_cli::rfc2217::{cmd, control, escape};
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Transmit};
use plm_core::link::{Dialect, Element, Source, StreamDecoder};
use plm_core::st7570::mib::{index, object, PlcConfiguration};
use plm_core::st7570::{code, Address, Command, Credit, Layer, MacData, Status};
use plm_core::time::MS;
use std::time::{Duration, Instant};

const BAUD: u32 = 57_600;
/// T_POLL (ST7570 UM Table 14): T_REQ low to the status message.
const T_POLL: Duration = Duration::from_millis(20);

/// The host: an RFC 2217 port and plm-core's host engine.
struct Host {
    port: Client,
    engine: HostEngine,
    start: Instant,
    /// Every event since the last [`Host::mark`].
    events: Vec<Event>,
    layer: Layer,
}

impl Host {
    fn new(port: Client) -> Host {
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

    fn now(&self) -> u64 {
        self.start.elapsed().as_micros() as u64
    }

    /// One turn: what came to the engine, its timers, its output to the
    /// port (bytes and RTS in one write: data, SET-CONTROL RTS, data, as a
    /// driver that releases T_REQ right after STX).
    fn step(&mut self) {
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
    fn frame<T>(&mut self, what: &str, mut want: impl FnMut(Command) -> Option<T>) -> T {
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
    fn request(&mut self, cmd: &Command) -> Command {
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
    fn unanswered(&mut self, cmd: &Command) -> LinkError {
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

    fn read(&mut self, index: u16) -> Vec<u8> {
        match self.request(&Command::ReadDbRequest { index }) {
            Command::ReadDbConfirm { index: i, data } if i == index => data,
            other => panic!("read {index:04X}h: {other:?}"),
        }
    }

    fn write(&mut self, index: u16, data: &[u8]) -> Vec<u8> {
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
    fn status(&self) -> Status {
        Status::from_message(&self.engine.last_status().expect("a status came"))
            .expect("a status message")
    }

    /// Waits `d` of wall time, serving the link meanwhile.
    fn idle(&mut self, d: Duration) {
        let until = Instant::now() + d;
        while Instant::now() < until {
            self.step();
        }
    }
}

/// T_REQ straight on the port: the status message (4 bytes, `?` first)
/// and its delay, and nothing else.
fn treq_status(port: &mut Client) -> (Vec<u8>, Duration) {
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
    port.set_rts(false).unwrap();
    match status {
        Element::Status(_) => {}
        other => panic!("T_REQ drew {other:?}"),
    }
    (bytes, took)
}

fn mac_client() -> Vec<u8> {
    let mut p = PlcConfiguration::decode(object(index::PLC_CONFIGURATION).unwrap().default);
    p.operating_mode = plm_sim::st7570::mode::CLIENT;
    p.access_layer_mode = Layer::Mac.access_layer_mode();
    p.encode()
}

/// A MAC frame from the Client to `da`, no credit: what the tests send.
fn mac_frame(da: u16, m_sdu: &[u8]) -> MacData {
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

#[test]
fn plm_sim_chip_st7570_through_rfc2217_and_the_host_engine() {
    let mut server = Server::start(&["--chip", "st7570", "--listen", "127.0.0.1:0"]);
    let banner = server.lines_up_to("powers on when the first client connects");
    let text = banner.join("\n");
    assert!(
        server
            .banner
            .contains("simulated ST7570 S-FSK line (node 0 of 4, seed 1)"),
        "{}",
        server.banner
    );
    assert!(
        text.contains("repeaters (000Bh ALWAYS_REPEAT): node 3"),
        "{text}"
    );
    let mut port = Client::open(&server.addr, BAUD).expect("an RFC 2217 port");

    // Nothing without T_REQ: the ST7570 sends no frame at power-on.
    let quiet = port.read_data(Duration::from_millis(300)).unwrap();
    assert!(quiet.is_empty(), "unasked: {quiet:02X?}");
    // T_REQ: the status message, `?` and 3 bytes, within T_POLL (the
    // median of five edges: a loaded machine may schedule one late).
    let mut delays = Vec::new();
    for _ in 0..5 {
        let (bytes, took) = treq_status(&mut port);
        assert_eq!(bytes.len(), 4, "{bytes:02X?}");
        assert_eq!(bytes[0], b'?');
        delays.push(took);
        // Released without a frame: T_SR passes, nothing more comes.
        let more = port.read_data(Duration::from_millis(250)).unwrap();
        assert!(more.is_empty(), "after the status: {more:02X?}");
    }
    delays.sort();
    assert!(delays[2] < T_POLL, "T_REQ -> status: {delays:?}");

    let mut host = Host::new(port);
    // MIB read, write, read back (0085h, Table 131).
    assert_eq!(host.read(0x0085), [8, 2, 9]);
    let st = host.status();
    assert_eq!(
        (st.mode, st.mac, st.reset, st.fw_release),
        (0, false, false, 1)
    );
    assert_eq!(host.write(0x0085, &[4, 3, 5]), [4, 3, 5]);
    assert_eq!(host.read(0x0085), [4, 3, 5]);

    // The modem a MAC Client (00A1h): the status says so.
    host.write(index::PLC_CONFIGURATION, &mac_client());
    host.layer = Layer::Mac;
    assert_eq!(host.read(index::PLC_CONFIGURATION), mac_client());
    let st = host.status();
    assert_eq!((st.mode, st.mac), (1, true), "{st:?}");
    let client = u16::from_le_bytes(
        host.read(index::LOCAL_INIT_MAC_ADD)[..2]
            .try_into()
            .unwrap(),
    );

    // A MAC frame to Server 2, its echo as a MAC data indication.
    let hello = mac_frame(2, b"hello over RFC 2217");
    match host.request(&Command::MacDataRequest(hello.clone())) {
        Command::DataConfirm { confirm_code } => assert_eq!(confirm_code, 0xFF, "LM_OK"),
        other => panic!("{other:?}"),
    }
    let echo = host.frame("the Server's echo", |c| match c {
        Command::MacDataIndication(m) => Some(m),
        _ => None,
    });
    assert_eq!(echo.address, Address { sa: 2, da: client });
    assert_eq!(echo.m_sdu, hello.m_sdu);

    // A DTR pulse resets the modem: held, it answers nothing; released,
    // it boots with its settings restored (7.1) and its status says
    // RESET = 0, hardware. A software reset first, so that the bit
    // changes.
    match host.request(&Command::ResetRequest { reset: 0 }) {
        Command::ResetRequest { reset } => assert_eq!(reset, 0),
        other => panic!("{other:?}"),
    }
    host.read(0x0085);
    assert!(host.status().reset, "RESET = 1 after CMD_ResetRequest");
    host.port.set_dtr(true).unwrap();
    assert_eq!(
        host.unanswered(&Command::ReadDbRequest { index: 0x0085 }),
        LinkError::NoStatus
    );
    host.port.set_dtr(false).unwrap();
    host.idle(Duration::from_millis(100));
    assert_eq!(host.read(0x0085), [4, 3, 5], "auto-reconfiguration");
    let st = host.status();
    assert!(!st.reset, "RESET = 0 after RESETn: {st:?}");
    assert_eq!((st.mode, st.mac), (1, true), "{st:?}");

    drop(host);
    server.interrupt();
}

/// `--alarms 1`: the Servers raise an alarm in turn every second; once
/// they are synchronized (the Client's frame to Server 1), the Client's
/// host receives CMD_AlarmIndication (ST7570 UM 5.3.15).
#[test]
fn plm_sim_st7570_alarms_reach_the_client() {
    let mut server = Server::start(&[
        "--chip",
        "st7570",
        "--alarms",
        "1",
        "--listen",
        "127.0.0.1:0",
    ]);
    let banner = server.lines_up_to("powers on when the first client connects");
    let text = banner.join("\n");
    assert!(
        text.contains("every 1 s a Server raises an alarm (nodes 1-3 in turn)"),
        "{text}"
    );
    let port = Client::open(&server.addr, BAUD).expect("an RFC 2217 port");
    let mut host = Host::new(port);
    host.write(index::PLC_CONFIGURATION, &mac_client());
    host.layer = Layer::Mac;
    let ask = mac_frame(1, b"?");
    match host.request(&Command::MacDataRequest(ask)) {
        Command::DataConfirm { confirm_code } => assert_eq!(confirm_code, 0xFF, "LM_OK"),
        other => panic!("{other:?}"),
    }
    host.frame("an alarm from a Server", |c| match c {
        Command::AlarmIndication { .. } => Some(()),
        _ => None,
    });
    drop(host);
    server.interrupt();
}
