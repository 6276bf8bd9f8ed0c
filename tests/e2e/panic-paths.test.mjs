// What panic-paths.mjs ends: a function core names as panicking gets the
// body `unreachable`; any other is left as it is.

import assert from 'node:assert/strict';
import test from 'node:test';
import { endPanics } from './panic-paths.mjs';
import { leb } from './short-names.mjs';
import { parse } from './wasm-contributors.mjs';

const section = (id, body) => Buffer.concat([Buffer.from([id]), leb(body.length), body]);
const vec = (items) => Buffer.concat([leb(items.length), ...items]);
const text = (s) => Buffer.concat([leb(Buffer.byteLength(s)), Buffer.from(s)]);
const body = (...ops) => Buffer.concat([leb(ops.length + 1), Buffer.from([0, ...ops])]);

test('a panicking function of core becomes unreachable, its caller stays', () => {
  const panics = 'core[0123456789abcdef]::panicking::panic_fmt';
  const wasm = Buffer.concat([
    Buffer.from([0, 0x61, 0x73, 0x6d, 1, 0, 0, 0]),
    section(1, vec([Buffer.from([0x60, 0, 0])])),
    section(3, vec([leb(0), leb(0)])),
    section(7, vec([Buffer.concat([text('run'), Buffer.from([0]), leb(1)])])),
    // panic_fmt: nop, nop, end; run: call 0, end.
    section(10, vec([body(0x01, 0x01, 0x0b), body(0x10, 0x00, 0x0b)])),
    section(0, Buffer.concat([text('name'), section(1, vec([Buffer.concat([leb(0), text(panics)]), Buffer.concat([leb(1), text('run')])]))])),
  ]);
  const out = endPanics(wasm);
  assert.deepEqual(out.ended, [panics]);
  const { bodies, names } = parse(out.wasm);
  const at = (name) => [...names].find(([, n]) => n === name)[0];
  assert.equal(bodies[at(panics)], 3, 'no locals, unreachable, end');
  assert.equal(bodies[at('run')], 4, 'the call left as it was');
});
