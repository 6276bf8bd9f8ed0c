//! The host of a simulated peer: a program on the peer's side of its UART
//! that drives its modem with plm-core's host engine and sends back every
//! data indication as a data request of the same layer, modulation and
//! channel (for demos and tests).

use plm_core::link::host::{Event, HostConfig, HostEngine, Transmit};
use plm_core::link::Dialect;
use plm_core::st7580::{
    Channel, Command, DataIndication, DataRequest, FrequencySet, SsDataRequest, TxParams,
};
use plm_core::time::Instant;

/// Clear header length of echoed SS frames: the least Table 45 allows
/// when a payload follows.
pub const SS_ECHO_HEADER: u8 = 4;

/// An echoing host.
#[derive(Debug, Clone)]
pub struct EchoHost {
    engine: HostEngine,
    /// Data indications echoed so far.
    pub echoed: u64,
}

impl EchoHost {
    /// An echoing host on a UART at `baud`.
    pub fn new(baud: u32) -> Self {
        EchoHost {
            engine: HostEngine::new(
                Dialect::St7580,
                HostConfig {
                    baud,
                    ..HostConfig::default()
                },
            ),
            echoed: 0,
        }
    }

    /// Sends a command of this host's own (a peer that talks first).
    pub fn submit(&mut self, now: Instant, cmd: &Command) {
        self.engine.submit(now, cmd.to_frame());
    }

    /// Bytes from the modem, each with its arrival time, oldest first
    /// (as [`crate::board::Board::handle_rx`]).
    pub fn handle_rx(&mut self, bytes: impl IntoIterator<Item = (Instant, u8)>) {
        let mut last = None;
        for (at, b) in bytes {
            self.engine.handle_rx(at, &[b]);
            last = Some(at);
        }
        if let Some(at) = last {
            self.pump(at);
        }
    }

    /// When [`EchoHost::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.engine.poll_timeout()
    }

    /// Runs what is due.
    pub fn handle_timeout(&mut self, now: Instant) {
        self.engine.handle_timeout(now);
        self.pump(now);
    }

    /// The next bytes or T_REQ change for the UART.
    pub fn poll_transmit(&mut self) -> Option<Transmit> {
        self.engine.poll_transmit()
    }

    fn pump(&mut self, now: Instant) {
        while let Some(ev) = self.engine.poll_event() {
            let Event::Frame(frame) = ev else { continue };
            if let Some(reply) = Command::from_frame(&frame).ok().and_then(echo) {
                self.echoed += 1;
                self.engine.submit(now, reply.to_frame());
            }
        }
    }
}

/// The request that sends an indication's payload back.
fn echo(cmd: Command) -> Option<Command> {
    let params = |i: &DataIndication| TxParams {
        modulation: i.info.modulation,
        frequency_set: match i.info.rx_channel {
            Channel::High => FrequencySet::High,
            Channel::Low => FrequencySet::Low,
        },
        ..TxParams::default()
    };
    Some(match cmd {
        Command::PhyDataIndication(i) => Command::PhyDataRequest(DataRequest {
            params: params(&i),
            payload: i.payload,
        }),
        Command::DlDataIndication(i) => Command::DlDataRequest(DataRequest {
            params: params(&i),
            payload: i.payload,
        }),
        Command::SsDataIndication(i) if i.payload.len() > SS_ECHO_HEADER as usize => {
            Command::SsDataRequest(SsDataRequest {
                params: params(&i),
                header_length: SS_ECHO_HEADER,
                header_and_payload: i.payload,
            })
        }
        _ => return None,
    })
}
