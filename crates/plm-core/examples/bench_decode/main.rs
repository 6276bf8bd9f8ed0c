//! `cargo xtask bench`: throughput of the stream decoder and allocations per
//! decoded frame, measured natively, per chip.
//!
//! Method: a deterministic 4 MiB capture of a busy host interface is
//! decoded in 4 KiB chunks, as a serial port delivers it. ST7580: status
//! messages, requests, confirms, indications with 16-250 byte payloads,
//! ACKs, 1 % garbage bytes. ST7570: both directions of a MAC Server
//! (status messages, M_Data indications and requests of 1-242 bytes,
//! confirms, synchronization, alarm, intelligent synchronization and
//! repeater call frames, MIB reads and writes) switched by MIB 00A1h
//! writes to a PHY Monitor and back (spy indications, P_Data
//! indications), ACKs, garbage bytes. Each figure is the median of 7 runs
//! after one warm-up run. Allocations are counted by a counting global
//! allocator around the decoding loop only, divided by the frames decoded.

mod st7570;

use plm_core::decode::Decoder;
use plm_core::link::{Dialect, Element, LocalFrame, Source, StreamDecoder};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

struct Counting;
static ALLOCS: AtomicU64 = AtomicU64::new(0);

// SAFETY: defers to the system allocator; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// xorshift64*: deterministic input without a dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.below(256) as u8).collect()
    }
}

fn capture(size: usize) -> (Vec<u8>, usize) {
    let mut rng = Rng(0x5EED);
    let mut out = Vec::with_capacity(size + 300);
    let mut frames = 0;
    while out.len() < size {
        match rng.below(10) {
            0 => out.extend([0x3F, rng.below(256) as u8]),
            1 => out.push(0x06),
            2 => out.push((rng.below(256) as u8) | 0x80),
            _ => {
                let code = [0x2C, 0x0C, 0x0D, 0x24, 0x25, 0x26, 0x50, 0x52][rng.below(8) as usize];
                let len = 16 + rng.below(235) as usize;
                let data: Vec<u8> = (0..len).map(|_| rng.below(256) as u8).collect();
                out.extend(LocalFrame::new(code, data).emit(Dialect::St7580).unwrap());
                frames += 1;
                out.push(0x06);
            }
        }
    }
    (out, frames)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn measure(name: &str, input: &[u8], frames: usize, mut run: impl FnMut(&[u8]) -> usize) {
    run(input);
    let mut secs = Vec::new();
    let mut allocs = Vec::new();
    for _ in 0..7 {
        let a0 = ALLOCS.load(Ordering::Relaxed);
        let t0 = Instant::now();
        let got = run(input);
        secs.push(t0.elapsed().as_secs_f64());
        allocs.push((ALLOCS.load(Ordering::Relaxed) - a0) as f64);
        assert_eq!(got, frames, "{name}: decoded {got} frames of {frames}");
    }
    let s = median(secs);
    let mb = input.len() as f64 / 1e6;
    println!(
        "{name:<34} {:>8.1} MB/s   {:>6.2} allocations/frame   ({:.2} MB, {frames} frames, {:.1} ms)",
        mb / s,
        median(allocs) / frames as f64,
        mb,
        s * 1e3
    );
}

/// The stream decoder and the named-field decoder over `input`.
fn measure_both(chip: &str, dialect: Dialect, source: Source, input: &[u8], frames: usize) {
    println!("stream decoder, {chip}, 4 KiB chunks, median of 7 runs:");
    measure("link::StreamDecoder (elements)", input, frames, |bytes| {
        let mut d = StreamDecoder::new(dialect, source);
        let mut n = 0;
        for chunk in bytes.chunks(4096) {
            d.push(chunk);
            while let Some(e) = d.next() {
                n += matches!(
                    e,
                    Element::Frame {
                        checksum_ok: true,
                        ..
                    }
                ) as usize;
            }
        }
        d.finish();
        while let Some(e) = d.next() {
            n += matches!(
                e,
                Element::Frame {
                    checksum_ok: true,
                    ..
                }
            ) as usize;
        }
        n
    });
    measure("decode::Decoder (named fields)", input, frames, |bytes| {
        let mut d = Decoder::new(dialect, source);
        let mut n = 0;
        for chunk in bytes.chunks(4096) {
            d.push(chunk);
            while let Some(e) = d.next() {
                n += (e.checksum_ok == Some(true)) as usize;
            }
        }
        d.finish();
        while let Some(e) = d.next() {
            n += (e.checksum_ok == Some(true)) as usize;
        }
        n
    });
}

fn main() {
    let (input, frames) = capture(4 << 20);
    measure_both("ST7580", Dialect::St7580, Source::Modem, &input, frames);
    let (input, frames) = st7570::capture(4 << 20, &mut Rng(0x5EED));
    measure_both("ST7570", Dialect::St7570, Source::Any, &input, frames);
}
