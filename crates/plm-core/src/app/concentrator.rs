//! The concentrator: the host's end of a street, sans-IO. One
//! [`Requester`] over either of the two ways in (docs/architecture.md,
//! "Connection profiles"):
//!
//! - [`Carrier::Usart`]: a concentrator **board** on the host's serial
//!   port; its USART carries application frames (4.6), and its firmware
//!   forwards them over the power line;
//! - [`Carrier::Modem`]: a bare **ST7580** on the host's serial port; the
//!   concentrator itself wraps each application frame in a line frame
//!   ([`LineFrame`]) inside a DL_DataRequest, with plm-core's host link
//!   engine, exactly as a simulated board's firmware does.
//!
//! The console, `plm board` and the tests all drive this one type.

use super::frame::{Address, AppFrame};
use super::line::LineFrame;
use super::requester::{AppEvent, Request, RequestId, Requester, RequesterConfig};
use super::usart::{UsartDecoder, UsartElement};
use crate::link::host::{self, HostConfig, HostEngine, Transmit};
use crate::link::Dialect;
use crate::st7580::{Command, DataRequest, TxParams};
use crate::time::{earliest, Duration, Instant, MS};
use alloc::collections::VecDeque;

/// A USART that stays quiet this long ends whatever frame was begun
/// (USB serial adapters deliver bytes in bursts a few ms apart).
pub const USART_IDLE: Duration = 50 * MS;

/// How the concentrator reaches the line.
#[derive(Debug, Clone)]
pub enum Carrier {
    /// A concentrator board's USART.
    Usart {
        /// Stream decoder of what the board sends.
        decoder: UsartDecoder,
        /// Arrival of the last byte, while a frame is incomplete.
        last_rx: Option<Instant>,
    },
    /// A bare ST7580.
    Modem {
        /// Host link engine (UM0932 3.2).
        engine: alloc::boxed::Box<HostEngine>,
        /// The address this concentrator sends from.
        address: Address,
        /// How line frames are transmitted.
        params: TxParams,
    },
}

/// What happened, for the layers above.
#[derive(Debug, Clone, PartialEq)]
pub enum Happening {
    /// A request's fate, or a frame that answers none.
    App(AppEvent),
    /// A USART element, either way (`to_board`: sent by the host).
    Usart {
        /// Sent by the host.
        to_board: bool,
        /// The element.
        element: UsartElement,
    },
    /// Something on the modem's host interface.
    Link(host::Event),
    /// A board was heard on the line, with the frame's SNR (dB; `None`
    /// for FSK frames, UM0932 Table 39).
    Heard {
        /// The board.
        address: Address,
        /// SNR.
        snr: Option<i8>,
    },
}

crate::drive::engine!(Concentrator, Happening, poll_happening);

/// The concentrator.
#[derive(Debug, Clone)]
pub struct Concentrator {
    requester: Requester,
    carrier: Carrier,
    transmits: VecDeque<Transmit>,
    happenings: VecDeque<Happening>,
}

impl Concentrator {
    /// The host's own address on the line when a bare modem is the
    /// concentrator, unless the user gives another (decided here:
    /// ST's prefix 0080E1h and node 0; docs/protocol-notes.md).
    pub const ADDRESS: Address = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x00]);

    /// Through a concentrator board's USART.
    pub fn usart(config: RequesterConfig) -> Self {
        Self::with(
            config,
            Carrier::Usart {
                decoder: UsartDecoder::new(),
                last_rx: None,
            },
        )
    }

    /// Through a bare ST7580 at `baud`, sending from `address`.
    pub fn modem(config: RequesterConfig, baud: u32, address: Address, params: TxParams) -> Self {
        let engine = alloc::boxed::Box::new(HostEngine::new(
            Dialect::St7580,
            HostConfig {
                baud,
                ..HostConfig::default()
            },
        ));
        Self::with(
            config,
            Carrier::Modem {
                engine,
                address,
                params,
            },
        )
    }

    fn with(config: RequesterConfig, carrier: Carrier) -> Self {
        Concentrator {
            requester: Requester::new(config),
            carrier,
            transmits: VecDeque::new(),
            happenings: VecDeque::new(),
        }
    }

    /// The requester (settings, pending count).
    pub fn requester(&self) -> &Requester {
        &self.requester
    }

    /// Changes the requester's settings.
    pub fn set_config(&mut self, config: RequesterConfig) {
        self.requester.set_config(config);
    }

    /// The carrier.
    pub fn carrier(&self) -> &Carrier {
        &self.carrier
    }

    /// Queues a request.
    pub fn submit(&mut self, now: Instant, request: Request) -> RequestId {
        let id = self.requester.submit(now, request);
        self.pump(now);
        id
    }

    /// Answers a frame that came unasked (e.g. acknowledges a discovery
    /// reply) without waiting for anything.
    pub fn send(&mut self, now: Instant, frame: AppFrame) {
        self.carry(now, frame);
        self.pump(now);
    }

    /// Fails everything pending (the port is gone).
    pub fn abort_all(&mut self, reason: &str) {
        self.requester.abort_all(reason);
        if let Carrier::Modem { engine, .. } = &mut self.carrier {
            engine.abort(host::LinkError::NoStatus);
        }
        self.drain_requester_events();
    }

    /// Bytes from the serial port.
    pub fn handle_rx(&mut self, now: Instant, bytes: &[u8]) {
        match &mut self.carrier {
            Carrier::Usart { decoder, last_rx } => {
                decoder.push(bytes);
                *last_rx = decoder.is_partial().then_some(now);
            }
            Carrier::Modem { engine, .. } => engine.handle_rx(now, bytes),
        }
        self.pump(now);
    }

    /// Runs what is due.
    pub fn handle_timeout(&mut self, now: Instant) {
        match &mut self.carrier {
            Carrier::Usart { decoder, last_rx } => {
                if last_rx.is_some_and(|t| now >= t + USART_IDLE) {
                    decoder.idle();
                    *last_rx = None;
                }
            }
            Carrier::Modem { engine, .. } => engine.handle_timeout(now),
        }
        if self.requester.poll_timeout().is_some_and(|t| t <= now) {
            self.requester.handle_timeout(now);
        }
        self.pump(now);
    }

    /// The next write or T_REQ change for the serial port.
    pub fn poll_transmit(&mut self) -> Option<Transmit> {
        self.transmits.pop_front()
    }

    /// The next happening.
    pub fn poll_happening(&mut self) -> Option<Happening> {
        self.happenings.pop_front()
    }

    /// When [`Concentrator::handle_timeout`] is next due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        let carrier = match &self.carrier {
            Carrier::Usart { last_rx, .. } => last_rx.map(|t| t + USART_IDLE),
            Carrier::Modem { engine, .. } => engine.poll_timeout(),
        };
        earliest(carrier, self.requester.poll_timeout())
    }

    fn carry(&mut self, now: Instant, frame: AppFrame) {
        match &mut self.carrier {
            Carrier::Usart { .. } => match frame.emit() {
                Ok(bytes) => {
                    self.happenings.push_back(Happening::Usart {
                        to_board: true,
                        element: UsartElement::Frame {
                            frame,
                            bytes: bytes.clone(),
                        },
                    });
                    self.transmits.push_back(Transmit::Bytes(bytes));
                }
                Err(e) => self.requester_failed_to_emit(&frame, e),
            },
            Carrier::Modem {
                engine,
                address,
                params,
            } => {
                let line = LineFrame::from_app(&frame, *address);
                let cmd = Command::DlDataRequest(DataRequest {
                    params: *params,
                    payload: line.emit(),
                });
                engine.submit(now, cmd.to_frame());
            }
        }
    }

    fn requester_failed_to_emit(&mut self, frame: &AppFrame, e: super::frame::FrameError) {
        self.happenings
            .push_back(Happening::App(AppEvent::Malformed {
                address: frame.address,
                error: super::message::MessageError::Length {
                    frame: frame.frame_type.name().unwrap_or("frame"),
                    expected: "at most 100 bytes",
                    got: match e {
                        super::frame::FrameError::TooLong(n) => n,
                        _ => frame.payload.len(),
                    },
                },
            }));
    }

    fn drain_requester_events(&mut self) {
        while let Some(e) = self.requester.poll_event() {
            self.happenings.push_back(Happening::App(e));
        }
    }

    /// Moves frames and events between the requester and the carrier
    /// until nothing moves.
    fn pump(&mut self, now: Instant) {
        loop {
            let mut moved = false;
            while let Some(frame) = self.requester.poll_send() {
                self.carry(now, frame);
                moved = true;
            }
            match &mut self.carrier {
                Carrier::Usart { decoder, .. } => {
                    while let Some(el) = decoder.next() {
                        if let UsartElement::Frame { frame, .. } = &el {
                            self.requester.handle_frame(now, frame);
                            moved = true;
                        }
                        self.happenings.push_back(Happening::Usart {
                            to_board: false,
                            element: el,
                        });
                    }
                }
                Carrier::Modem {
                    engine, address, ..
                } => {
                    while let Some(t) = engine.poll_transmit() {
                        self.transmits.push_back(t);
                    }
                    while let Some(ev) = engine.poll_event() {
                        if let host::Event::Frame(f) = &ev {
                            if let Ok(Command::DlDataIndication(ind)) = Command::from_frame(f) {
                                if let Some(line) =
                                    LineFrame::parse(&ind.payload).filter(|l| l.is_for(*address))
                                {
                                    let snr = (ind.info.snr != 0xFF).then_some(ind.info.snr as i8);
                                    self.happenings.push_back(Happening::Heard {
                                        address: line.source,
                                        snr,
                                    });
                                    self.requester.handle_frame(now, &line.to_app());
                                    moved = true;
                                }
                            }
                        }
                        self.happenings.push_back(Happening::Link(ev));
                    }
                }
            }
            self.drain_requester_events();
            if !moved {
                break;
            }
        }
    }
}
