//! Reading a fuzzer's bytes as a script: small numbers, chunk lengths and
//! the rest, never running out (an exhausted input reads as zeros).

/// A cursor over the fuzzer's bytes.
pub struct Input<'a>(&'a [u8]);

impl<'a> Input<'a> {
    /// A cursor at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Input(data)
    }

    /// Whether every byte was read.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The next byte, 0 past the end.
    pub fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    /// The next two bytes, big-endian.
    pub fn u16(&mut self) -> u16 {
        u16::from_be_bytes([self.u8(), self.u8()])
    }

    /// Up to `n` next bytes.
    pub fn take(&mut self, n: usize) -> &'a [u8] {
        let (head, rest) = self.0.split_at(n.min(self.0.len()));
        self.0 = rest;
        head
    }

    /// The bytes not yet read.
    pub fn rest(&mut self) -> &'a [u8] {
        self.take(self.0.len())
    }
}

/// `data` cut into chunks whose lengths the first byte chooses (1 to 16
/// bytes; 0 means all at once), as a UART or TCP socket might deliver it.
pub fn chunks(data: &[u8]) -> impl Iterator<Item = &[u8]> {
    let (size, bytes) = match data.split_first() {
        Some((&b, rest)) if b & 0x0F != 0 => ((b & 0x0F) as usize, rest),
        Some((_, rest)) => (rest.len().max(1), rest),
        None => (1, data),
    };
    bytes.chunks(size)
}
