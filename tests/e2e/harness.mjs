// What every browser script here shares: the release build in dist/ served
// on 127.0.0.1 (a secure context, as WebSerial needs) and Debian's Chromium
// driven by playwright-core with the flags this machine's closed network
// needs (see /work/.library/env: no background networking).

import assert from 'node:assert/strict';
import { before, after } from 'node:test';
import http from 'node:http';
import fs from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
export const dist = path.resolve(process.env.PLM_DIST ?? path.join(here, '../../dist'));
export const artifacts = path.join(here, 'artifacts');

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript',
  '.wasm': 'application/wasm',
  '.css': 'text/css',
  '.json': 'application/json',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.webmanifest': 'application/manifest+json',
};

/** Serves dist/ on a free port; resolves to { server, base }. */
export async function serveDist() {
  await fs.access(path.join(dist, 'index.html')).catch(() => {
    throw new Error(`no console build in ${dist}: run \`cargo xtask dist\` first`);
  });
  await fs.mkdir(artifacts, { recursive: true });
  const server = await new Promise((resolve) => {
    const s = http.createServer(async (req, res) => {
      const url = new URL(req.url, 'http://127.0.0.1');
      let file = path.normalize(path.join(dist, decodeURIComponent(url.pathname)));
      if (!file.startsWith(dist)) {
        res.writeHead(403).end();
        return;
      }
      if (url.pathname.endsWith('/')) file = path.join(file, 'index.html');
      try {
        const body = await fs.readFile(file);
        const type = TYPES[path.extname(file)] ?? 'application/octet-stream';
        res.writeHead(200, { 'content-type': type, 'cache-control': 'no-store' }).end(body);
      } catch {
        res.writeHead(404).end('not found');
      }
    });
    s.listen(0, '127.0.0.1', () => resolve(s));
  });
  return { server, base: `http://127.0.0.1:${server.address().port}/` };
}

/** Headless Debian Chromium (CHROMIUM overrides the path). */
export function launchChromium() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: [
      '--headless',
      '--no-sandbox',
      '--disable-gpu',
      '--disable-quic',
      '--no-first-run',
      '--disable-background-networking',
      '--disable-component-update',
      '--disable-sync',
    ],
  });
}

/**
 * Every error the page reports (uncaught exceptions and console errors),
 * collected from now on: the array fills as they come.
 */
export function pageErrors(page) {
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(m.text());
  });
  return errors;
}

/**
 * Every Content-Security-Policy violation in `page` becomes a console
 * error (so a watched page fails on it), with what was refused.
 */
export function reportPolicyViolations(page) {
  return page.addInitScript(() =>
    addEventListener('securitypolicyviolation', (e) =>
      console.error(`Content-Security-Policy violation: ${e.effectiveDirective} refused ${e.blockedURI || 'inline'} (${e.sourceFile}:${e.lineNumber})`),
    ),
  );
}

/**
 * A new page in `context`; after the test `t` the context is closed and
 * the test fails if the page reported an error.
 */
export async function watchedPage(t, context) {
  const page = await context.newPage();
  const errors = pageErrors(page);
  reportPolicyViolations(page);
  t.after(async () => {
    await context.close();
    assert.deepEqual(errors, [], 'no errors in the page');
  });
  return page;
}

/**
 * A test file's console and browser: dist/ served and Chromium started
 * before its tests, both closed after them. `suite.base` is the page's
 * address, `suite.browser` the browser.
 */
export function browserSuite() {
  const suite = { server: null, base: null, browser: null };
  before(async () => {
    ({ server: suite.server, base: suite.base } = await serveDist());
    suite.browser = await launchChromium();
  });
  after(async () => {
    await suite.browser?.close();
    await new Promise((r) => (suite.server ? suite.server.close(r) : r()));
  });
  return suite;
}
