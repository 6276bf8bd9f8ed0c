//! The serial port `plm board` talks through, behind one small trait:
//! a local serial device (the `serialport` crate), or a remote one over
//! RFC 2217 (`rfc2217://HOST:PORT`, [`crate::rfc2217::client`]).
//!
//! Both are opened 8N1 at the baud rate asked, RTS released: on a bare
//! ST7580, RTS drives T_REQ (UM0932 3.2.8), which must stay released
//! until the host has a frame to send.

use crate::rfc2217::client::Client;
use std::io::{self, ErrorKind, Read, Write};
use std::time::Duration;

/// The URL scheme of a remote port.
pub const RFC2217: &str = "rfc2217://";

/// A serial port: bytes both ways and the RTS line.
pub trait Port {
    /// Writes all of `bytes`.
    fn write(&mut self, bytes: &[u8]) -> io::Result<()>;
    /// What arrived, waiting up to `wait` when nothing is there yet;
    /// empty if nothing came. An error means the port is gone.
    fn read(&mut self, wait: Duration) -> io::Result<Vec<u8>>;
    /// Asserts (`true`) or releases RTS, after the bytes written before.
    fn set_rts(&mut self, asserted: bool) -> io::Result<()>;
}

/// Opens `url` at `baud`: `rfc2217://HOST:PORT`, or a device path
/// (`/dev/ttyUSB0`, `COM3`). The error says what went wrong in words.
pub fn open(url: &str, baud: u32) -> Result<Box<dyn Port>, String> {
    if let Some(addr) = url.strip_prefix(RFC2217) {
        let addr = addr.trim_end_matches('/');
        if !addr.contains(':') {
            return Err(format!(
                "{url}: an RFC 2217 port is rfc2217://HOST:PORT (the port number is missing)"
            ));
        }
        return Client::open(addr, baud)
            .map(|c| Box::new(Rfc2217Port(c)) as Box<dyn Port>)
            .map_err(|e| format!("cannot open {url}: {}", connect_words(&e)));
    }
    if url.contains("://") {
        return Err(format!(
            "{url}: not a port this tool opens; give a serial device (/dev/ttyUSB0, COM3) \
             or rfc2217://HOST:PORT"
        ));
    }
    SerialDevice::open(url, baud)
        .map(|p| Box::new(p) as Box<dyn Port>)
        .map_err(|e| format!("cannot open {url}: {}", serial_words(&e)))
}

/// A connection error in words, with what to try.
fn connect_words(e: &io::Error) -> String {
    match e.kind() {
        ErrorKind::ConnectionRefused => {
            "nothing listens there (connection refused): is the server (ser2net, plm sim) running, \
             on that port?"
                .into()
        }
        _ => e.to_string(),
    }
}

fn serial_words(e: &serialport::Error) -> String {
    match e.kind() {
        serialport::ErrorKind::NoDevice => format!(
            "{} (is the adapter plugged in, and is the device name right?)",
            e.description
        ),
        serialport::ErrorKind::Io(ErrorKind::NotFound) => {
            "no such device (is the adapter plugged in, and is the device name right?)".into()
        }
        serialport::ErrorKind::Io(ErrorKind::PermissionDenied) => {
            "permission denied (on Linux, join the 'dialout' group or use sudo)".into()
        }
        _ => e.description.clone(),
    }
}

/// A remote serial port over RFC 2217.
struct Rfc2217Port(Client);

impl Port for Rfc2217Port {
    fn write(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.0.send_data(bytes)
    }

    fn read(&mut self, wait: Duration) -> io::Result<Vec<u8>> {
        self.0.read_data(wait)
    }

    fn set_rts(&mut self, asserted: bool) -> io::Result<()> {
        // In the Telnet stream: after the data written before it.
        self.0.set_rts(asserted)
    }
}

/// A local serial device.
struct SerialDevice {
    port: Box<dyn serialport::SerialPort>,
    /// Why RTS cannot be set, if it cannot (a pseudo-terminal has no
    /// modem lines: fine for a board's USART, not for T_REQ).
    no_rts: Option<String>,
}

impl SerialDevice {
    fn open(path: &str, baud: u32) -> serialport::Result<SerialDevice> {
        let mut port = serialport::new(path, baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(Duration::from_millis(5))
            .open()?;
        let no_rts = port
            .write_request_to_send(false)
            .err()
            .map(|e| e.description);
        Ok(SerialDevice { port, no_rts })
    }
}

fn io_error(e: serialport::Error) -> io::Error {
    io::Error::other(e.description)
}

impl Port for SerialDevice {
    fn write(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.port.write_all(bytes)
    }

    fn read(&mut self, wait: Duration) -> io::Result<Vec<u8>> {
        self.port
            .set_timeout(wait.max(Duration::from_millis(1)))
            .map_err(io_error)?;
        let mut buf = [0u8; 1024];
        match self.port.read(&mut buf) {
            Ok(0) => Err(io::Error::new(
                ErrorKind::UnexpectedEof,
                "the device is gone (unplugged?)",
            )),
            Ok(n) => Ok(buf[..n].to_vec()),
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                Ok(Vec::new())
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => Ok(Vec::new()),
            Err(e) => Err(e),
        }
    }

    fn set_rts(&mut self, asserted: bool) -> io::Result<()> {
        // The bytes written before must be on the wire first (tcdrain):
        // a host releases T_REQ after the STX of its frame has left.
        if let Some(why) = &self.no_rts {
            return Err(io::Error::other(format!(
                "this device's RTS line cannot be set ({why}); a bare modem needs it for T_REQ \
                 (is it a pseudo-terminal? use --via board, or an adapter with RTS)"
            )));
        }
        self.port.flush()?;
        self.port.write_request_to_send(asserted).map_err(io_error)
    }
}
