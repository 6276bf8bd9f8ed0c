// The wasm's functions put in an order gzip does well with: by the crate
// and module they belong to (a trait's function by the type it is for, a
// generic one by its own path), and within those alike bodies side by
// side (their bytes in order), so that what a function shares with its
// neighbours is within gzip's 32 KB window. minify-dist.mjs calls this on
// a release build, whose wasm-opt run (index.html) keeps the functions'
// names for it (`-g`); the names are dropped here, as is the target
// features section, which that run keeps for this one, and the
// `__wasm_split_unstable` marker of Leptos's lazy splitting, which the
// console does not use and no browser reads.
//
// The order is given to binaryen's --reorder-functions-by-name as names
// (each function's rank), so that binaryen renumbers every call, table
// entry and export. Its stack IR passes write the code as compactly as
// the optimising run did.

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { leb } from './short-names.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const wasmOpt = path.join(here, 'node_modules/.bin/wasm-opt');

/** The module's sections: id, where it begins, where its contents do, end. */
function sections(wasm) {
  let p = 8;
  const u32 = () => {
    let r = 0;
    for (let shift = 0; ; shift += 7) {
      const b = wasm[p++];
      r += (b & 0x7f) * 2 ** shift;
      if (!(b & 0x80)) return r;
    }
  };
  const out = [];
  while (p < wasm.length) {
    const head = p;
    const id = wasm[p++];
    const size = u32();
    out.push({ id, head, start: p, end: p + size });
    p += size;
  }
  return out;
}

/** A reader of unsigned LEB128 numbers and names from `at`. */
function reader(wasm, at) {
  const r = {
    p: at,
    u32() {
      let v = 0;
      for (let shift = 0; ; shift += 7) {
        const b = wasm[r.p++];
        v += (b & 0x7f) * 2 ** shift;
        if (!(b & 0x80)) return v;
      }
    },
    name() {
      const n = r.u32();
      const s = wasm.toString('utf8', r.p, r.p + n);
      r.p += n;
      return s;
    },
  };
  return r;
}

/**
 * Where a function belongs, from its (demangled) name: the first two
 * parts of its path; `<X as Trait>::f` belongs to X, or to the trait when
 * X is a type parameter, a tuple or a slice.
 */
export function owner(name) {
  let s = name.replace(/::h[0-9a-f]{16}$/, '');
  const impl = /^<+&?(?:mut )?(?:dyn )?([^ ]+) as ([^>]+)>/.exec(s);
  if (impl) s = /^([A-Z]$|\(|\[)/.test(impl[1]) ? impl[2] : impl[1];
  return s.replace(/^<+/, '').replace(/<.*/, '').split('::').slice(0, 2).join('::');
}

/**
 * The defined functions' bodies and every function's name (by index),
 * read from the code (10) and name (custom "name", subsection 1) sections.
 */
function functions(wasm) {
  let imported = 0;
  const bodies = [];
  const names = new Map();
  for (const s of sections(wasm)) {
    const r = reader(wasm, s.start);
    if (s.id === 2) {
      for (let n = r.u32(); n > 0; n--) {
        r.name();
        r.name();
        const kind = wasm[r.p++];
        if (kind === 0) {
          r.u32();
          imported++;
        } else if (kind === 1) {
          r.p++;
          const flags = wasm[r.p++];
          r.u32();
          if (flags & 1) r.u32();
        } else if (kind === 2) {
          const flags = wasm[r.p++];
          r.u32();
          if (flags & 1) r.u32();
        } else if (kind === 3) r.p += 2;
        else {
          r.p++;
          r.u32();
        }
      }
    } else if (s.id === 10) {
      for (let n = r.u32(); n > 0; n--) {
        const len = r.u32();
        bodies.push(wasm.subarray(r.p, r.p + len));
        r.p += len;
      }
    } else if (s.id === 0 && r.name() === 'name') {
      while (r.p < s.end) {
        const sub = wasm[r.p++];
        const len = r.u32();
        const end = r.p + len;
        if (sub === 1) for (let n = r.u32(); n > 0; n--) names.set(r.u32(), r.name());
        r.p = end;
      }
    }
  }
  return { imported, bodies, names };
}

/**
 * The wasm (a Buffer) with its functions in order (see above), without
 * names or target features. A wasm without function names is an error:
 * its order could not be chosen.
 */
export function orderFunctions(wasm) {
  const { imported, bodies, names } = functions(wasm);
  if (names.size === 0) throw new Error('order-functions: the wasm has no function names (wasm-opt -g in index.html)');
  const order = bodies.map((body, i) => ({ index: imported + i, owner: owner(names.get(imported + i) ?? ''), body }));
  order.sort((a, b) => (a.owner < b.owner ? -1 : a.owner > b.owner ? 1 : Buffer.compare(a.body, b.body) || a.index - b.index));
  // The name section anew: every defined function named by its rank.
  const entries = order.map((f, rank) => {
    const name = Buffer.from(String(rank).padStart(6, '0'));
    return Buffer.concat([leb(f.index), leb(name.length), name]);
  });
  const sub = Buffer.concat([leb(entries.length), ...entries]);
  const body = Buffer.concat([leb(4), Buffer.from('name'), Buffer.from([1]), leb(sub.length), sub]);
  const parts = [wasm.subarray(0, 8)];
  for (const s of sections(wasm)) {
    const custom = s.id === 0 && reader(wasm, s.start).name();
    if (custom !== 'name' && custom !== '__wasm_split_unstable') parts.push(wasm.subarray(s.head, s.end));
  }
  parts.push(Buffer.from([0]), leb(body.length), body);
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'order-functions-'));
  try {
    const named = path.join(dir, 'named.wasm');
    const ordered = path.join(dir, 'ordered.wasm');
    fs.writeFileSync(named, Buffer.concat(parts));
    execFileSync(wasmOpt, [
      named,
      '-o',
      ordered,
      '--reorder-functions-by-name',
      '--strip-debug',
      '--strip-target-features',
      '--generate-stack-ir',
      '--optimize-stack-ir',
      '--optimize-level=2',
      '--shrink-level=2',
    ]);
    return fs.readFileSync(ordered);
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}
