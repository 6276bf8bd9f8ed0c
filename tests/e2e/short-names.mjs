// Short names for the wasm's imports from its wasm-bindgen glue and for
// its exports the glue calls (`wasm.<name>`). Each import is named
// `__wbg_<method>_<16 hex digits>` in the wasm and as a key of the glue's
// import object, closure trampolines are exported with a hash too: a few
// hundred such names, whose hashes gzip cannot shrink. minify-dist.mjs
// calls this on a release build; the names mean nothing to anyone (they
// are the glue's private link to the wasm).
//
// The wasm's import section is rewritten (WebAssembly core spec 5.5.5:
// module name, field name, import description) and every name in the glue
// with it. A name is only renamed when the glue holds it exactly once, as
// a key (`name:`); the module name only when the glue names it once; an
// export (5.5.10) only when the glue never writes it in quotes.

/** Unsigned LEB128 (WebAssembly core spec 5.2.2). */
export function leb(n) {
  const out = [];
  do {
    let b = n & 0x7f;
    n = Math.floor(n / 128);
    if (n) b |= 0x80;
    out.push(b);
  } while (n);
  return Buffer.from(out);
}

/** `a`, `b`, ..., `Z`, `ba`, ...: the n-th short name. */
function shortName(n) {
  const letters = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ';
  let s = '';
  do {
    s = letters[n % letters.length] + s;
    n = Math.floor(n / letters.length);
  } while (n);
  return s;
}

const count = (text, s) => text.split(s).length - 1;

/**
 * The wasm (a Buffer) and its glue (text) with short import and export
 * names: `{ wasm, js, renamed }`; both unchanged when there is nothing to
 * rename.
 */
export function shortenNames(wasm, js) {
  const imports = shortenImportSection(wasm, js);
  const exports = shortenExports(imports.parts, imports.js, imports.fresh);
  const renamed = imports.renamed + exports.renamed;
  return renamed ? { wasm: Buffer.concat(exports.parts), js: exports.js, renamed } : { wasm, js, renamed };
}

function shortenImportSection(wasm, js) {
  let p = 8;
  const u32 = () => {
    let r = 0;
    for (let shift = 0; ; shift += 7) {
      const b = wasm[p++];
      r += (b & 0x7f) * 2 ** shift;
      if (!(b & 0x80)) return r;
    }
  };
  const name = () => {
    const n = u32();
    const s = wasm.toString('utf8', p, p + n);
    p += n;
    return s;
  };
  const parts = [wasm.subarray(0, 8)];
  let renamed = 0;
  const used = new Set();
  let next = 0;
  const fresh = () => {
    let s;
    do s = shortName(next++);
    while (used.has(s));
    return s;
  };
  while (p < wasm.length) {
    const start = p;
    const id = wasm[p++];
    const size = u32();
    const end = p + size;
    if (id !== 2) {
      parts.push(wasm.subarray(start, end));
      p = end;
      continue;
    }
    const modules = new Map();
    const entries = [];
    for (let n = u32(); n > 0; n--) {
      const module = name();
      const field = name();
      const descStart = p;
      const kind = wasm[p++];
      if (kind === 0) u32(); // function: type index
      else if (kind === 1) {
        p++; // table: reference type, then limits
        if (wasm[p++] & 1) u32();
        u32();
      } else if (kind === 2) {
        if (wasm[p++] & 1) u32(); // memory: limits
        u32();
      } else if (kind === 3) p += 2; // global: value type, mutability
      else u32(); // tag: attribute and type index
      entries.push({ module, field, desc: wasm.subarray(descStart, p) });
      modules.set(module, (modules.get(module) ?? 0) + 1);
    }
    // The glue's own module: the one most imports come from.
    const [glue] = [...modules].sort((a, b) => b[1] - a[1])[0] ?? [];
    const quoted = JSON.stringify(glue);
    const moduleName = glue !== undefined && count(js, quoted) === 1 ? 'w' : glue;
    if (moduleName !== glue) js = js.replace(quoted, JSON.stringify(moduleName));
    used.add(moduleName);
    const body = [leb(entries.length)];
    for (const e of entries) {
      let { module, field } = e;
      if (module === glue) {
        module = moduleName;
        // Exactly once in the glue, and as a key of the import object.
        if (count(js, field) === 1 && count(js, `${field}:`) === 1 && field.length > 2) {
          const s = fresh();
          js = js.replace(`${field}:`, `${s}:`);
          field = s;
          renamed++;
        }
      }
      const m = Buffer.from(module);
      const f = Buffer.from(field);
      body.push(leb(m.length), m, leb(f.length), f, e.desc);
    }
    const section = Buffer.concat(body);
    parts.push(Buffer.from([2]), leb(section.length), section);
    p = end;
  }
  return { parts, js, renamed, used, fresh };
}

/**
 * The exports the glue only ever names as `wasm.<name>` renamed in the
 * export section (WebAssembly core spec 5.5.10) and in the glue.
 */
function shortenExports(parts, js, fresh) {
  let renamed = 0;
  const out = parts.map((part) => {
    if (part[0] !== 7) return part;
    let p = 1;
    const u32 = () => {
      let r = 0;
      for (let shift = 0; ; shift += 7) {
        const b = part[p++];
        r += (b & 0x7f) * 2 ** shift;
        if (!(b & 0x80)) return r;
      }
    };
    u32(); // section size
    const body = [];
    const n = u32();
    body.push(leb(n));
    for (let i = 0; i < n; i++) {
      const len = u32();
      let field = part.toString('utf8', p, p + len);
      p += len;
      const descStart = p;
      p++; // export kind
      u32(); // index
      // Whole names only (`x_16` is not `x`); the glue may also have a
      // function of the same name (terser renames it), never a string.
      const whole = (prefix) => new RegExp(`${prefix}${field}(?![\\w$])`, 'g');
      const quoted = js.includes(`"${field}"`) || js.includes(`'${field}'`) || js.includes(`\`${field}`);
      if (field.length > 2 && !quoted && whole('wasm\\.').test(js)) {
        const s = fresh();
        js = js.replace(whole('wasm\\.'), `wasm.${s}`);
        field = s;
        renamed++;
      }
      const f = Buffer.from(field);
      body.push(leb(f.length), f, part.subarray(descStart, p));
    }
    const section = Buffer.concat(body);
    return Buffer.concat([Buffer.from([7]), leb(section.length), section]);
  });
  return { parts: out, js, renamed };
}
