// Minifies the JavaScript of a release build in dist/ (the wasm-bindgen
// glue, without the stream classes the wasm no longer exports, and the
// service worker) with terser, gives the wasm's imports and
// exports between it and the glue short names (short-names.mjs), and
// rewrites the Subresource Integrity hashes index.html gives for them. `cargo xtask dist` runs it
// after Trunk: the console's 350 KiB budget counts every JS file, and
// Trunk's own minifier leaves these two as they are. The sources keep
// their comments; only the copies the browser downloads are minified.
//
// node minify-dist.mjs [DIST]   (default: ../../dist)

import crypto from 'node:crypto';
import fs from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { minify } from 'terser';
import { shortenNames } from './short-names.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const dist = path.resolve(process.argv[2] ?? path.join(here, '../../dist'));
const sri = (body) => `sha384-${crypto.createHash('sha384').update(body).digest('base64')}`;

/**
 * The glue without the wasm-streams classes (IntoUnderlyingSource, -Sink,
 * -ByteSource) that Leptos's server functions bring and the console never
 * uses: index.html's wasm-opt options stop exporting them from the wasm.
 * Each is the class, its `Symbol.dispose` line and its finalization
 * registry, as wasm-bindgen writes them; anything of them left over is an
 * error (a new wasm-bindgen writing them otherwise).
 */
function dropStreamClasses(js) {
  const out = js
    .replace(/^export class IntoUnderlying\w+ \{\n[\s\S]*?^\}\n/gm, '')
    .replace(/^if \(Symbol\.dispose\) IntoUnderlying\w+\.prototype\[Symbol\.dispose\] = .*\n/gm, '')
    .replace(/^const IntoUnderlying\w+Finalization = [^;]*;\n/gm, '');
  if (/intounderlying/i.test(out)) throw new Error('minify-dist: the glue still names the wasm-streams classes');
  return out;
}

let html = await fs.readFile(path.join(dist, 'index.html'), 'utf8');
for (const name of (await fs.readdir(dist)).filter((f) => f.endsWith('.js')).sort()) {
  const file = path.join(dist, name);
  const original = await fs.readFile(file, 'utf8');
  let before = original;
  // The service worker is a classic script; the wasm-bindgen glue a module.
  const module = name !== 'sw.js';
  if (module) before = dropStreamClasses(before);
  const wasmFile = path.join(dist, name.replace(/\.js$/, '_bg.wasm'));
  const wasm = module ? await fs.readFile(wasmFile).catch(() => null) : null;
  if (wasm) {
    const short = shortenNames(wasm, before);
    before = short.js;
    await fs.writeFile(wasmFile, short.wasm);
    const oldWasm = sri(wasm);
    if (html.includes(oldWasm)) html = html.replaceAll(oldWasm, sri(short.wasm));
    console.log(`minify-dist: ${path.basename(wasmFile)}: ${short.renamed} imports renamed`);
  }
  const out = await minify(before, { module, compress: true, mangle: true });
  if (out.code === undefined) throw new Error(`${name}: terser produced nothing`);
  await fs.writeFile(file, out.code);
  const old = sri(original);
  if (html.includes(old)) html = html.replaceAll(old, sri(out.code));
  console.log(`minify-dist: ${name} ${before.length} -> ${out.code.length} bytes`);
}
await fs.writeFile(path.join(dist, 'index.html'), html);
