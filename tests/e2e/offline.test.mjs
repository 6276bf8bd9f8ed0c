// Offline and install: once visited, PLM Console works with no server and
// no network (web/sw.js), and Chromium finds it installable
// (web/manifest.webmanifest).
//
// Serves dist/ like the other suites, but through a wrapper that can hand
// out a changed index.html (a "new build") and, at the end, closes the
// server for good: the offline page can only come from the service worker.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs/promises';
import path from 'node:path';
import { dist, launchChromium, serveDist, watchedPage } from './harness.mjs';
import { shot } from './journeys.mjs';

let server;
let base;
let browser;
/** When set, `/` and `/index.html` carry this build marker (a new build). */
let build = null;

before(async () => {
  ({ server, base } = await serveDist());
  const [serveFile] = server.listeners('request');
  server.removeAllListeners('request');
  server.on('request', async (req, res) => {
    const { pathname } = new URL(req.url, base);
    if (build && (pathname === '/' || pathname === '/index.html')) {
      const html = await fs.readFile(path.join(dist, 'index.html'), 'utf8');
      const marked = html.replace('</head>', `<meta name="plm-build" content="${build}" /></head>`);
      res.writeHead(200, { 'content-type': 'text/html; charset=utf-8', 'cache-control': 'no-store' });
      res.end(marked);
      return;
    }
    serveFile(req, res);
  });
  browser = await launchChromium();
});

/**
 * Polls `fn(arg)` in the page until it is truthy, for up to 15 s. Not
 * `page.waitForFunction`: it takes the Promise an async function returns
 * for a truthy value and resolves at once, whatever the Promise holds.
 */
async function until(page, fn, arg, what) {
  const end = Date.now() + 15_000;
  while (!(await page.evaluate(fn, arg))) {
    if (Date.now() > end) throw new Error(`timed out waiting: ${what}`);
    await new Promise((r) => setTimeout(r, 200));
  }
}

after(async () => {
  await browser?.close();
  if (server?.listening) {
    server.closeAllConnections();
    await new Promise((r) => server.close(r));
  }
});

test('once visited, the console works offline, and it is installable', async (t) => {
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  const page = await watchedPage(t, context);

  // First visit: the page registers web/sw.js, which caches the build and
  // takes control of this very page (clients.claim).
  await page.goto(base);
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  await page.waitForFunction(() => navigator.serviceWorker.controller !== null, null, {
    timeout: 15_000,
  });
  const sw = await page.evaluate(() => navigator.serviceWorker.controller.scriptURL);
  assert.equal(sw, new URL('sw.js', base).href);

  // Every file index.html links is in the cache (names hashed by Trunk).
  const linked = await page.evaluate(() => {
    const urls = [...document.querySelectorAll('link[href]')].map((l) => l.href);
    // Trunk's loader script imports the JS and fetches the wasm by name.
    for (const s of document.scripts) {
      for (const m of s.text.matchAll(/'(\.\/[^']+\.(?:js|wasm))'/g)) {
        urls.push(new URL(m[1], location.href).href);
      }
    }
    return urls;
  });
  assert.ok(linked.some((u) => u.endsWith('_bg.wasm')), linked.join(', '));
  await until(
    page,
    async (urls) => {
      for (const u of urls) if (!(await caches.match(u))) return false;
      return true;
    },
    linked.filter((u) => !u.endsWith('/sw.js')),
    'every linked file cached',
  );

  // The manifest: linked, served, parsed by Chromium as we mean it.
  const href = await page.getAttribute('link[rel=manifest]', 'href');
  const manifestUrl = new URL(href, base).href;
  const manifest = await page.evaluate(async (u) => (await fetch(u)).json(), manifestUrl);
  assert.equal(manifest.name, 'PLM Console');
  assert.equal(manifest.start_url, './');
  assert.equal(manifest.display, 'standalone');
  const icon = manifest.icons.find((i) => i.type === 'image/svg+xml');
  assert.ok(icon && icon.sizes === 'any', JSON.stringify(manifest.icons));
  const iconType = await page.evaluate(
    async (u) => (await fetch(u)).headers.get('content-type'),
    new URL(icon.src, manifestUrl).href,
  );
  assert.equal(iconType, 'image/svg+xml');
  const cdp = await context.newCDPSession(page);
  const parsed = await cdp.send('Page.getAppManifest');
  assert.equal(parsed.url, manifestUrl);
  assert.deepEqual(parsed.errors, []);
  assert.equal(parsed.parsed.scope, base, 'the scope is the page');
  assert.equal(new URL(manifest.start_url, manifestUrl).href, base, 'start_url is the page');
  // Chromium's own installability check. A Playwright context is
  // off the record, which alone keeps the install prompt away.
  const { installabilityErrors } = await cdp.send('Page.getInstallabilityErrors');
  assert.deepEqual(
    installabilityErrors.filter((e) => e.errorId !== 'in-incognito'),
    [],
    'installable',
  );

  // A new build on the server is what an online reload shows (navigations
  // go to the network first), and it replaces the cached page.
  build = 'second';
  await page.reload();
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  assert.equal(await page.locator('meta[name=plm-build][content=second]').count(), 1);
  await until(
    page,
    async () => (await (await caches.match('./index.html'))?.text())?.includes('plm-build'),
    null,
    'the new build cached',
  );

  // Offline: no network for the page, and no server at all any more.
  await context.setOffline(true);
  server.closeAllConnections();
  await new Promise((r) => server.close(r));
  await assert.rejects(fetch(base), 'the server is gone');
  await page.reload();
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  assert.match(await page.textContent('#conn-port'), /simulated/);
  assert.equal(await page.locator('meta[name=plm-build][content=second]').count(), 1);
  // The page opens on the simulated street: its lamps are found offline too.
  await page.waitForFunction(
    () => document.querySelectorAll('#fleet-table tbody tr').length === 12,
    null,
    { timeout: 60_000, polling: 250 },
  );
  await shot(page, 'offline');
});
