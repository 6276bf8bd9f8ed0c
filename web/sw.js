// PLM Console service worker: the console works offline once visited.
//
// Trunk names the build's files after their content
// (`plm-console-<hash>_bg.wasm`, `style-<hash>.css`), so nothing here names
// them: on install the worker reads index.html for what it links and
// caches that. Requests are then answered so that
// - a navigation (index.html) goes to the network first, so a new build
//   (or `trunk serve`'s rebuild) is picked up whenever the server is
//   reachable, and the cached index.html is only the fallback when it is not;
// - a hashed file comes from the cache first: its name changes whenever its
//   content does, so a cached copy can never be stale;
// - any other file of ours (manifest, icon: stable names) goes to the
//   network first and falls back to the cache.
// The worker only ever touches same-origin GET requests; everything else
// (and WebSerial, which is no fetch at all) passes by untouched.

// Bump when this file's caching changes: activate deletes every other cache.
const VERSION = 'v2';
const PREFIX = 'plm-console-';
const CACHE = `${PREFIX}${VERSION}`;

// Stable names cached on their own terms, not as files the page links:
// the page itself (under both names) and the manifest (whose icons are
// read from it).
const STABLE = ['./', './index.html', './manifest.webmanifest'];

// Trunk's content hash: `-` and a 64-bit hash in hex (no leading zeros, so
// up to 16 digits) before the extension (`_bg` for the wasm-bindgen module).
const HASHED = /-[0-9a-f]{1,16}(_bg)?\.[a-z0-9]+$/;

const scopeUrl = (p) => new URL(p, self.registration.scope).href;

self.addEventListener('install', (event) => {
  // A new worker takes over at once rather than waiting for every tab to
  // close: navigations are network first and hashed files never change, so
  // a page of the previous build keeps working (it has loaded everything).
  self.skipWaiting();
  event.waitUntil(precache());
});

self.addEventListener('activate', (event) => {
  event.waitUntil(
    (async () => {
      const names = await caches.keys();
      await Promise.all(
        names.filter((n) => n.startsWith(PREFIX) && n !== CACHE).map((n) => caches.delete(n)),
      );
      // Control the page that registered us too, so that the first visit
      // is already enough to work offline next time.
      await self.clients.claim();
    })(),
  );
});

self.addEventListener('fetch', (event) => {
  const request = event.request;
  if (request.method !== 'GET') return;
  const url = new URL(request.url);
  if (url.origin !== self.location.origin) return;
  if (request.mode === 'navigate') {
    event.respondWith(navigate(event));
  } else if (HASHED.test(url.pathname)) {
    event.respondWith(cacheFirst(request));
  } else {
    event.respondWith(networkFirst(request));
  }
});

/** Caches index.html, everything it links, the manifest and its icons. */
async function precache() {
  const cache = await caches.open(CACHE);
  // `no-cache`: revalidate with the server, never an old HTTP-cached page.
  const index = await fetch(scopeUrl('./index.html'), { cache: 'no-cache' });
  if (!index.ok) throw new Error(`index.html: HTTP ${index.status}`);
  await rememberInTurn(cache, index);
  const manifest = await fetch(scopeUrl('./manifest.webmanifest'), { cache: 'no-cache' });
  if (manifest.ok) {
    await cache.put(scopeUrl('./manifest.webmanifest'), manifest.clone());
    const icons = (await manifest.json()).icons ?? [];
    await cache.addAll(icons.map((i) => new URL(i.src, manifest.url).href));
  }
}

// One `remember` at a time, in the order the pages arrived, so that one
// build's clean-up never deletes the files of a newer one being cached.
let turn = Promise.resolve();
function rememberInTurn(cache, response) {
  const mine = turn.then(() => remember(cache, response));
  turn = mine.catch(() => {});
  return mine;
}

/**
 * Stores index.html under both `./` and `./index.html`, caches every
 * same-origin file it links that is not cached yet, and drops hashed files
 * of older builds, so the cache holds one build (a dev server rebuilding
 * many times a day would otherwise fill it with old wasm).
 */
async function remember(cache, response) {
  const html = await response.clone().text();
  await cache.put(scopeUrl('./index.html'), response.clone());
  await cache.put(scopeUrl('./'), response);
  const stable = STABLE.map(scopeUrl);
  const linked = new Set();
  // Trunk writes `href="./x"`, `src="./x"` and, in its loader script,
  // `'./x.js'` / `'./x_bg.wasm'`; all relative, as `public_url = "./"`.
  // A release build's HTML is minified (Trunk.toml), which drops the quotes
  // where HTML allows it (`href=./style-<hash>.css`): an unquoted value runs
  // to the next space or `>` (HTML 13.1.2.3, unquoted attribute value).
  // (STABLE and this worker, registered from index.html too, are apart.)
  const attribute = /(?:href|src)\s*=\s*(?:"([^"]+)"|([^\s"'=<>`]+))|'(\.\/[^']+)'/g;
  for (const m of html.matchAll(attribute)) {
    const href = new URL(m[1] ?? m[2] ?? m[3], scopeUrl('./'));
    href.hash = '';
    const ours = href.origin === self.location.origin;
    if (ours && href.href !== self.location.href && !stable.includes(href.href)) {
      linked.add(href.href);
    }
  }
  for (const url of linked) {
    if (!(await cache.match(url))) await cache.add(url);
  }
  for (const request of await cache.keys()) {
    const url = new URL(request.url);
    if (HASHED.test(url.pathname) && !linked.has(url.href)) await cache.delete(request);
  }
}

/** Navigations: the network's index.html when reachable, else the cached one. */
async function navigate(event) {
  const cache = await caches.open(CACHE);
  try {
    const response = await fetch(event.request);
    const url = new URL(event.request.url);
    url.search = '';
    const index = url.href === scopeUrl('./') || url.href === scopeUrl('./index.html');
    if (index && response.ok && !response.redirected) {
      // Possibly a new build: cache it and its files while the page loads.
      event.waitUntil(rememberInTurn(cache, response.clone()).catch(() => {}));
    }
    return response;
  } catch (err) {
    const cached = (await cache.match(event.request, { ignoreSearch: true }))
      ?? (await cache.match(scopeUrl('./index.html')));
    if (cached) return cached;
    throw err;
  }
}

async function cacheFirst(request) {
  const cache = await caches.open(CACHE);
  const cached = await cache.match(request);
  if (cached) return cached;
  const response = await fetch(request);
  if (response.ok) await cache.put(request, response.clone());
  return response;
}

async function networkFirst(request) {
  const cache = await caches.open(CACHE);
  try {
    const response = await fetch(request);
    if (response.ok) await cache.put(request, response.clone());
    return response;
  } catch (err) {
    const cached = await cache.match(request, { ignoreSearch: true });
    if (cached) return cached;
    throw err;
  }
}
