// What panic-locations.mjs folds: a location's shape in the data (file,
// line, column), and only a file name nothing else points at is zeroed.

import assert from 'node:assert/strict';
import test from 'node:test';
import { foldPanicLocations } from './panic-locations.mjs';
import { leb } from './short-names.mjs';

/** A module of one active data segment at `address` holding `bytes`, and code. */
function module(address, bytes, code = Buffer.alloc(0)) {
  const expr = Buffer.concat([Buffer.from([0x41]), leb(address), Buffer.from([0x0b])]);
  const segment = Buffer.concat([leb(1), leb(0), expr, leb(bytes.length), bytes]);
  const section = (id, body) => Buffer.concat([Buffer.from([id]), leb(body.length), body]);
  return Buffer.concat([
    Buffer.from([0, 0x61, 0x73, 0x6d, 1, 0, 0, 0]),
    section(10, code),
    section(11, segment),
  ]);
}

const u32 = (...words) => Buffer.concat(words.map((w) => { const b = Buffer.alloc(4); b.writeUInt32LE(w); return b; }));

test('locations become one, their file names zeroed unless pointed at', () => {
  const base = 0x100000;
  const a = Buffer.from('src/a.rs');
  const b = Buffer.from('src/bb.rs.');
  // a.rs at base, bb.rs at base + 8 (its text is 9 bytes), then locations.
  const data = Buffer.concat([
    a,
    b,
    Buffer.alloc(2),
    u32(base, 8, 12, 5),
    u32(base + 8, 9, 300, 17),
    u32(base, 7, 1, 1), // its text does not end in .rs: no location
    u32(base, 8, 0, 1), // line 0: no location
  ]);
  // The code calls with the second location (a padded LEB128), and points
  // at bb.rs: its name stays.
  const second = Buffer.from([0x41, 0xa4, 0x80, 0xc0, 0x00, 0x10, 0x00]);
  const code = Buffer.concat([second, Buffer.from([0x41]), leb(base + 8), Buffer.from([0x1a])]);
  const wasm = module(base, data, code);
  const out = foldPanicLocations(wasm);
  assert.equal(out.locations, 2);
  assert.equal(out.names, 0, 'a.rs is the one left pointed at, bb.rs the code points at');
  const at = wasm.indexOf(a);
  const word = (k) => out.wasm.readUInt32LE(at + 20 + 4 * k);
  assert.deepEqual([0, 1, 2, 3, 4, 5, 6, 7].map(word), [base, 0, 0, 0, base, 0, 0, 0]);
  assert.deepEqual([8, 9, 10, 11, 12, 13, 14, 15].map(word), [base, 7, 1, 1, base, 8, 0, 1]);
  assert.equal(out.wasm.length, wasm.length);
  assert.equal(out.calls, 1);
  assert.ok(out.wasm.includes(Buffer.from([0x41, 0x94, 0x80, 0xc0, 0x00, 0x10, 0x00])), 'the call names the first location');

  const alone = foldPanicLocations(module(base, data));
  assert.equal(alone.names, 1, 'bb.rs, pointed at by nothing now, is zeroed');
  assert.ok(alone.wasm.includes(a));
  assert.ok(!alone.wasm.includes(Buffer.from('src/bb.rs')));
});
