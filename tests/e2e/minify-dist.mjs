// Minifies the JavaScript of a release build in dist/ (the wasm-bindgen
// glue, without the stream classes the wasm no longer exports, and the
// service worker) with terser, puts the wasm's functions in an order gzip
// does well with (order-functions.mjs), gives the wasm's imports and
// exports between it and the glue short names (short-names.mjs), ends
// its panic paths at once (panic-paths.mjs), folds its panic locations
// into one (panic-locations.mjs), and
// rewrites the Subresource Integrity hashes index.html gives for them. `cargo xtask dist` runs it
// after Trunk: the console's 350 KiB budget counts every JS file, and
// Trunk's own minifier leaves these two as they are. The sources keep
// their comments; only the copies the browser downloads are minified.
// Last, it makes the page's Content-Security-Policy strict (strictPolicy).
//
// node minify-dist.mjs [DIST]   (default: ../../dist)

import crypto from 'node:crypto';
import fs from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { minify } from 'terser';
import { orderFunctions } from './order-functions.mjs';
import { foldPanicLocations } from './panic-locations.mjs';
import { endPanics } from './panic-paths.mjs';
import { shortenNames } from './short-names.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const dist = path.resolve(process.argv[2] ?? path.join(here, '../../dist'));
const sri = (body) => `sha384-${crypto.createHash('sha384').update(body).digest('base64')}`;

/**
 * The glue without the wasm-streams classes (IntoUnderlyingSource, -Sink,
 * -ByteSource) that Leptos's server functions bring and the console never
 * uses: the linker (.cargo/wasm-ld.sh) does not export them from the wasm.
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
  // The wasm-bindgen glue (beside its wasm) is a module; the service
  // worker and its registration are classic scripts.
  const wasmFile = path.join(dist, name.replace(/\.js$/, '_bg.wasm'));
  const wasm = await fs.readFile(wasmFile).catch(() => null);
  const module = wasm !== null;
  if (module) before = dropStreamClasses(before);
  if (wasm) {
    const ended = endPanics(wasm);
    const short = shortenNames(orderFunctions(ended.wasm), before);
    const folded = foldPanicLocations(short.wasm);
    before = short.js;
    await fs.writeFile(wasmFile, folded.wasm);
    const oldWasm = sri(wasm);
    if (html.includes(oldWasm)) html = html.replaceAll(oldWasm, sri(folded.wasm));
    console.log(`minify-dist: ${path.basename(wasmFile)}: ${short.renamed} imports renamed`);
    console.log(`minify-dist: ${ended.ended.length} panic paths ended at once`);
    console.log(`minify-dist: ${folded.locations} panic locations folded (${folded.calls} calls), ${folded.names} file names zeroed`);
  }
  const out = await minify(before, { module, compress: true, mangle: true });
  if (out.code === undefined) throw new Error(`${name}: terser produced nothing`);
  await fs.writeFile(file, out.code);
  const old = sri(original);
  if (html.includes(old)) html = html.replaceAll(old, sri(out.code));
  console.log(`minify-dist: ${name} ${before.length} -> ${out.code.length} bytes`);
}

/**
 * index.html's Content-Security-Policy made strict for the release build:
 * the development server's allowances (index.html says which) are
 * replaced by the SHA-256 of each inline script left, Trunk's loader.
 * A page without the policy, or a policy without those allowances, is an
 * error: the release build never ships without it.
 */
function strictPolicy(page) {
  const meta = /<meta\b[^>]*http-equiv=["']?Content-Security-Policy["']?[^>]*>/i.exec(page);
  const content = meta && /content="([^"]*)"/.exec(meta[0]);
  if (!content) throw new Error('minify-dist: index.html has no Content-Security-Policy');
  const hashes = [...page.matchAll(/<script\b([^>]*)>([\s\S]*?)<\/script>/g)]
    .filter(([, attributes]) => !/\bsrc=/.test(attributes))
    .map(([, , body]) => `'sha256-${crypto.createHash('sha256').update(body).digest('base64')}'`);
  let relaxed = 0;
  const strict = content[1]
    .split(';')
    .map((d) => d.trim())
    .map((d) => {
      const [name, ...sources] = d.split(/\s+/);
      const kept = sources.filter((x) => {
        const dev = (name === 'script-src' && x === "'unsafe-inline'") || (name === 'connect-src' && x === 'ws:');
        relaxed += dev;
        return !dev;
      });
      if (name === 'script-src') kept.push(...hashes);
      return [name, ...kept].join(' ');
    })
    .join('; ');
  if (relaxed !== 2) throw new Error(`minify-dist: the policy's development allowances are not as index.html says: ${content[1]}`);
  console.log(`minify-dist: Content-Security-Policy: ${strict}`);
  return page.replace(meta[0], meta[0].replace(content[0], `content="${strict}"`));
}

html = strictPolicy(html);
await fs.writeFile(path.join(dist, 'index.html'), html);
