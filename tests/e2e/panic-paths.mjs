// The panic paths of a release build ended at once. Every panic of the
// page ends in a trap: the wasm is built with panic = "abort", the page
// sets no panic hook, and std's own hook writes to wasm32-unknown-unknown's
// standard error, which goes nowhere, so the message that the functions
// below format is never seen. Each of them never returns (`-> !`); its
// body becomes `unreachable` (WebAssembly core spec 5.4.1), the trap it
// ended in anyway, and what only they used (the message formatting, std's
// panic handler) is then dropped by wasm-opt. minify-dist.mjs calls this
// on a release build, before order-functions.mjs (it reads the names)
// (docs/console.md, "Size").

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { leb } from './short-names.mjs';
import { uleb } from './panic-locations.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const wasmOpt = path.join(here, 'node_modules/.bin/wasm-opt');

/** core's, alloc's and std's functions that only format a panic and panic. */
const DIVERGING = new RegExp(
  '^<?(core|alloc|std)(\\[[0-9a-f]+\\])?::(' +
    [
      'panicking::(panic_fmt|panic|panic_bounds_check|assert_failed_inner|panic_const::panic_const_[a-z_]+)',
      'panicking::assert_failed::<[a-z0-9]+, [a-z0-9]+>',
      'vec::Vec<_, _>>::(swap_remove|remove|split_off|insert)::assert_failed',
      'slice::copy_from_slice_impl::len_mismatch_fail',
      'thread::local::panic_access_error',
      'option::(unwrap_failed|expect_failed)',
      'result::unwrap_failed',
      'str::slice_error_fail(_rt)?',
      'slice::index::slice_[a-z_]+_fail',
      'cell::panic_already_(mutably_)?borrowed',
      'cell::lazy::panic_poisoned',
      'raw_vec::(capacity_overflow|handle_error)',
      'alloc::handle_alloc_error',
    ].join('|') +
    ')(::h[0-9a-f]{16})?$',
);

/** Imported functions and the names of the name section (5.5.2, 7.4.1). */
function names(wasm) {
  let imported = 0;
  const byIndex = new Map();
  const name = (p) => {
    const [n, q] = uleb(wasm, p);
    return [wasm.toString('utf8', q, q + n), q + n];
  };
  let p = 8;
  while (p < wasm.length) {
    const id = wasm[p];
    const [size, start] = uleb(wasm, p + 1);
    const end = start + size;
    if (id === 2) {
      let [n, q] = uleb(wasm, start);
      for (; n > 0; n--) {
        [, q] = name(q);
        [, q] = name(q);
        const kind = wasm[q++];
        if (kind === 0) {
          imported++;
          [, q] = uleb(wasm, q);
        } else if (kind === 1) {
          q++;
          q = uleb(wasm, wasm[q] & 1 ? uleb(wasm, q + 1)[1] : q + 1)[1];
        } else if (kind === 2) {
          q = uleb(wasm, wasm[q] & 1 ? uleb(wasm, q + 1)[1] : q + 1)[1];
        } else if (kind === 3) q += 2;
        else [, q] = uleb(wasm, q + 1);
      }
    } else if (id === 0) {
      const [section, q0] = name(start);
      if (section === 'name') {
        let q = q0;
        while (q < end) {
          const sub = wasm[q];
          const [len, body] = uleb(wasm, q + 1);
          if (sub === 1) {
            let [n, r] = uleb(wasm, body);
            for (; n > 0; n--) {
              let index, text;
              [index, r] = uleb(wasm, r);
              [text, r] = name(r);
              byIndex.set(index, text);
            }
          }
          q = body + len;
        }
      }
    }
    p = end;
  }
  return { imported, byIndex };
}

/**
 * The wasm (with its function names) with the bodies of the functions
 * DIVERGING names made `unreachable`, and what nothing uses any more
 * removed; which functions.
 */
export function endPanics(input) {
  const { imported, byIndex } = names(input);
  if (byIndex.size === 0) throw new Error('panic-paths: the wasm has no function names (wasm-opt -g in index.html)');
  const parts = [input.subarray(0, 8)];
  const ended = [];
  let p = 8;
  while (p < input.length) {
    const head = p;
    const id = input[p];
    const [size, start] = uleb(input, p + 1);
    const end = start + size;
    if (id !== 10) {
      parts.push(input.subarray(head, end));
      p = end;
      continue;
    }
    let [n, q] = uleb(input, start);
    const bodies = [leb(n)];
    for (let i = 0; i < n; i++) {
      let len;
      [len, q] = uleb(input, q);
      const name = byIndex.get(imported + i) ?? '';
      const diverging = DIVERGING.test(name);
      if (diverging) ended.push(name);
      // No locals, `unreachable`, `end`.
      const body = diverging ? Buffer.from([0, 0x00, 0x0b]) : input.subarray(q, q + len);
      bodies.push(leb(body.length), body);
      q += len;
    }
    const code = Buffer.concat(bodies);
    parts.push(Buffer.from([10]), leb(code.length), code);
    p = end;
  }
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'panic-paths-'));
  try {
    const before = path.join(dir, 'before.wasm');
    const after = path.join(dir, 'after.wasm');
    fs.writeFileSync(before, Buffer.concat(parts));
    execFileSync(wasmOpt, [before, '-o', after, '--remove-unused-module-elements', '-g']);
    return { wasm: fs.readFileSync(after), ended };
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}
