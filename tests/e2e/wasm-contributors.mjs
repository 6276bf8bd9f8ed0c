// Where the console's bytes go: the code of the console's wasm, by crate
// (and by module for the project's own crates), read from the function
// names that rustc leaves in the wasm before wasm-bindgen and wasm-opt
// (target/wasm32-unknown-unknown/release/plm-console.wasm, which the
// release build leaves behind). Shares of that code, not gzipped bytes:
// wasm-opt shrinks everything, but the shares tell where to look.
//
//   node tests/e2e/wasm-contributors.mjs [file.wasm] [top]

import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '../..');

/** The pre-bindgen wasm of a release build, if there is one. */
export function releaseWasm() {
  const target = process.env.CARGO_TARGET_DIR ? path.resolve(root, process.env.CARGO_TARGET_DIR) : path.join(root, 'target');
  const file = path.join(target, 'wasm32-unknown-unknown/release/plm-console.wasm');
  return fs.existsSync(file) ? file : null;
}

/** A WebAssembly binary reader: unsigned LEB128, names, sections. */
class Reader {
  constructor(buf, pos = 0, end = buf.length) {
    Object.assign(this, { buf, pos, end });
  }
  byte() {
    return this.buf[this.pos++];
  }
  u32() {
    let result = 0;
    let shift = 0;
    for (;;) {
      const b = this.byte();
      result += (b & 0x7f) * 2 ** shift;
      if (!(b & 0x80)) return result;
      shift += 7;
    }
  }
  name() {
    const n = this.u32();
    const s = this.buf.toString('utf8', this.pos, this.pos + n);
    this.pos += n;
    return s;
  }
  limits() {
    const flag = this.byte();
    this.u32();
    if (flag & 1) this.u32();
  }
}

/** Code bytes per function index, data bytes, and the function names. */
export function parse(buf) {
  const r = new Reader(buf, 8);
  let imported = 0;
  const bodies = [];
  const names = new Map();
  let data = 0;
  while (r.pos < r.end) {
    const id = r.byte();
    const size = r.u32();
    const end = r.pos + size;
    const s = new Reader(buf, r.pos, end);
    if (id === 2) {
      for (let n = s.u32(); n > 0; n--) {
        s.name();
        s.name();
        const kind = s.byte();
        if (kind === 0) {
          s.u32();
          imported++;
        } else if (kind === 1) {
          s.byte();
          s.limits();
        } else if (kind === 2) s.limits();
        else if (kind === 3) s.pos += 2;
        else s.pos += 1 + (s.u32(), 0);
      }
    } else if (id === 10) {
      for (let n = s.u32(); n > 0; n--) {
        const len = s.u32();
        bodies.push(len);
        s.pos += len;
      }
    } else if (id === 11) {
      data += size;
    } else if (id === 0 && s.name() === 'name') {
      while (s.pos < end) {
        const sub = s.byte();
        const len = s.u32();
        if (sub === 1) {
          for (let n = s.u32(); n > 0; n--) names.set(s.u32(), s.name());
        } else s.pos += len;
      }
    }
    r.pos = end;
  }
  return { imported, bodies, names, data };
}

/** Where a (mangled or plain) Rust symbol belongs: crate, or crate::module for ours. */
export function owner(symbol) {
  const path = [];
  const m = /^_ZN(.*)E$/.exec(symbol);
  if (m) {
    // Legacy mangling: <len><ident>... ; a trait impl starts `_$LT$path..`.
    let rest = m[1];
    while (path.length < 2) {
      const d = /^(\d+)/.exec(rest);
      if (!d) break;
      const n = Number(d[1]);
      let ident = rest.slice(d[1].length, d[1].length + n);
      rest = rest.slice(d[1].length + n);
      const inner =
        /^_?\$LT\$(?:\$RF\$)?(?:mut\$u20\$)?([A-Za-z_0-9]+)(?:\.\.([A-Za-z_0-9]+))?.*?(?:\$u20\$as\$u20\$([A-Za-z_0-9]+)(?:\.\.([A-Za-z_0-9]+))?)?/.exec(
          ident,
        );
      if (inner) {
        // `<X as Y>`: X's, or Y's when X is a type parameter.
        const generic = /^[A-Z]$/.test(inner[1]) && inner[3];
        path.push(...(generic ? [inner[3], inner[4]] : [inner[1], inner[2]]).filter(Boolean));
        break;
      }
      path.push(ident);
    }
  } else {
    // Demangled: `<X as Y>::f` belongs to X, or to Y when X is generic.
    const impl = /^<&?(?:mut )?([^ <>]+)(?:<[^>]*>)? as ([^ <>]+)/.exec(symbol);
    const own = impl && (/^[A-Z]$|^\[|^\(/.test(impl[1]) ? impl[2] : impl[1]);
    path.push(...(own ?? symbol).replace(/^<+/, '').split('::').slice(0, 2));
  }
  const [krate, module] = path;
  return /^plm_/.test(krate ?? '') && module ? `${krate}::${module}` : (krate ?? symbol);
}

/** The `top` largest owners of code, with their share, and the total. */
export function contributors(file, top = 12) {
  const { imported, bodies, names, data } = parse(fs.readFileSync(file));
  const by = new Map();
  let code = 0;
  bodies.forEach((len, i) => {
    const name = names.get(imported + i) ?? '(unnamed)';
    // wasm-bindgen's descriptors: run by wasm-bindgen, then removed.
    if (name.startsWith('__wbindgen_describe') || name.includes('WasmDescribe')) return;
    const who = owner(name);
    by.set(who, (by.get(who) ?? 0) + len);
    code += len;
  });
  const rows = [...by.entries()].sort((a, b) => b[1] - a[1]).slice(0, top);
  return { code, data, rows };
}

/** The lines `cargo xtask bench` prints. */
export function report(file, top = 12) {
  const { code, data, rows } = contributors(file, top);
  const pct = (n) => `${((100 * n) / code).toFixed(1)}%`.padStart(6);
  return [
    `Where the bytes go: ${(code / 1024).toFixed(0)} KiB of code and ${(data / 1024).toFixed(0)} KiB of data before wasm-opt (${path.basename(file)}); largest shares of the code:`,
    ...rows.map(([who, n]) => `  ${pct(n)}  ${who}`),
  ];
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const file = process.argv[2] ?? releaseWasm();
  if (!file) {
    console.error('no release wasm: build the console first (cargo xtask dist)');
    process.exit(1);
  }
  console.log(report(file, Number(process.argv[3] ?? 12)).join('\n'));
}
