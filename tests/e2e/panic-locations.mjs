// The panic locations of a release build folded into one. Every place
// that can panic (an index, an `unwrap`, a `RefCell` borrow) hands the
// panic machinery a `core::panic::Location` in the data: a `&str` of its
// source file, its line and its column, 16 bytes on wasm32, about 700 of
// them, whose pointers and numbers gzip cannot shrink. The page never
// shows them: it sets no panic hook, and std's own hook writes to
// wasm32-unknown-unknown's standard error, which goes nowhere. So each
// location becomes the same one (an empty file, line 0, column 0), a
// file name that nothing else points at is zeroed, and a call's location
// argument (`i32.const` of a location's address just before a `call`,
// core spec 5.4.1 and 5.4.7) names the first location, which now reads the
// same as every other. minify-dist.mjs calls this on a release build
// (docs/console.md, "Size").
//
// A location is found by its shape (the Rust reference, "The Rust
// runtime", `Location`: file, line, col; a `&str` is pointer then length):
// 4-aligned, a pointer into the data to a text of printable ASCII ending
// in `.rs` exactly as long as the length says, a line and a column within
// reason. The data section is read as the WebAssembly core spec 5.5.12
// gives it; its bytes are rewritten in place, nothing else moves.

/** Unsigned LEB128 (WebAssembly core spec 5.2.2) from `p`: value, next. */
export function uleb(wasm, p) {
  let v = 0;
  for (let shift = 0; ; shift += 7) {
    const b = wasm[p++];
    v += (b & 0x7f) * 2 ** shift;
    if (!(b & 0x80)) return [v, p];
  }
}

/** The active data segments: memory address and where their bytes lie. */
function segments(wasm) {
  const out = [];
  let p = 8;
  while (p < wasm.length) {
    const id = wasm[p];
    const [size, start] = uleb(wasm, p + 1);
    if (id === 11) {
      let [n, q] = uleb(wasm, start);
      for (; n > 0; n--) {
        let flags;
        [flags, q] = uleb(wasm, q);
        let address = null;
        if (flags === 2) [, q] = uleb(wasm, q);
        if (flags !== 1) {
          // An offset of `i32.const N end` (0x41 ... 0x0b); any other
          // expression leaves the segment unread.
          if (wasm[q] === 0x41) {
            let v;
            [v, q] = uleb(wasm, q + 1);
            if (wasm[q] === 0x0b) address = v;
          }
          while (wasm[q] !== 0x0b) q++;
          q++;
        }
        let len;
        [len, q] = uleb(wasm, q);
        if (address !== null) out.push({ address, at: q, len });
        q += len;
      }
    }
    p = start + size;
  }
  return out;
}

/** The code section's bounds: where it begins and ends. */
function code(wasm) {
  let p = 8;
  while (p < wasm.length) {
    const id = wasm[p];
    const [size, start] = uleb(wasm, p + 1);
    if (id === 10) return [start, start + size];
    p = start + size;
  }
  return [0, 0];
}

/**
 * Each `i32.const A` followed by a `call` whose A is in `from` made
 * `i32.const to`, its LEB128 as long as before (core spec 5.2.2 allows the
 * padding); how many.
 */
function retarget(wasm, from, to) {
  const [start, end] = code(wasm);
  let n = 0;
  for (let q = start; q < end; q++) {
    if (wasm[q] !== 0x41) continue;
    const [v, next] = uleb(wasm, q + 1);
    const len = next - q - 1;
    // Signed LEB128: the last byte's bit 6 is the sign, which must be 0.
    if (!from.has(v) || len > 5 || wasm[next - 1] & 0x40 || wasm[next] !== 0x10) continue;
    if (to >= 2 ** (7 * len - 1)) continue;
    for (let k = 0, x = to; k < len; k++, x = Math.floor(x / 128)) {
      wasm[q + 1 + k] = (x & 0x7f) | (k < len - 1 ? 0x80 : 0);
    }
    n++;
  }
  return n;
}

/** Every `i32.const` operand of the code section that is an address. */
function codeConstants(wasm) {
  const found = new Set();
  let p = 8;
  while (p < wasm.length) {
    const id = wasm[p];
    const [size, start] = uleb(wasm, p + 1);
    if (id === 10) {
      // Read as if every 0x41 byte began an `i32.const`: an address that is
      // not one is only kept the more.
      for (let q = start; q < start + size; q++) {
        if (wasm[q] === 0x41) found.add(uleb(wasm, q + 1)[0]);
      }
    }
    p = start + size;
  }
  return found;
}

/**
 * The wasm with its panic locations folded into one, their file names
 * zeroed where nothing else points at them and the calls given the first;
 * how many locations, names and calls.
 */
export function foldPanicLocations(input) {
  const wasm = Buffer.from(input);
  const segs = segments(wasm);
  const where = (address, len) => {
    const s = segs.find((g) => address >= g.address && address + len <= g.address + g.len);
    return s && s.at + (address - s.address);
  };
  const text = (address, len) => {
    const at = where(address, len);
    if (at === undefined || len < 4 || len > 300) return null;
    const s = wasm.subarray(at, at + len);
    return s.every((b) => b >= 0x20 && b < 0x7f) && s.toString('latin1').endsWith('.rs') ? at : null;
  };
  const locations = [];
  for (const g of segs) {
    for (let o = (4 - (g.address % 4)) % 4; o + 16 <= g.len; o += 4) {
      const at = g.at + o;
      const [file, len, line, col] = [0, 4, 8, 12].map((k) => wasm.readUInt32LE(at + k));
      if (line >= 1 && line < 100000 && col >= 1 && col < 1000 && text(file, len) !== null) {
        locations.push({ at, address: g.address + o, file, len });
        o += 12;
      }
    }
  }
  if (locations.length === 0) return { wasm, locations: 0, names: 0, calls: 0 };
  const one = locations[0].file;
  for (const { at } of locations) {
    wasm.writeUInt32LE(one, at);
    wasm.fill(0, at + 4, at + 16);
  }
  const calls = retarget(wasm, new Set(locations.map((l) => l.address)), locations[0].address);
  // A file name is zeroed only when no word of the data and no constant
  // of the code points into it any more.
  const pointed = codeConstants(wasm);
  for (const g of segs) {
    for (let o = 0; o + 4 <= g.len; o++) pointed.add(wasm.readUInt32LE(g.at + o));
  }
  const names = new Map(locations.map(({ file, len }) => [file, len]));
  let zeroed = 0;
  for (const [file, len] of names) {
    let used = false;
    for (let a = file; a < file + len && !used; a++) used = pointed.has(a);
    if (used) continue;
    const at = where(file, len);
    wasm.fill(0, at, at + len);
    zeroed++;
  }
  return { wasm, locations: locations.length, names: zeroed, calls };
}
