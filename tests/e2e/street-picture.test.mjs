// Browser journeys of the street picture on the Street view, at a field
// technician's laptop size (1366×768): the lamps in address order on
// opening, a failed lamp standing out, a click opening a lamp's page, a
// pole list imported (the order follows it, and is kept), a malformed
// one refused in words with nothing changed.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { browserSuite, watchedPage } from './harness.mjs';
import { lamp, shot } from './journeys.mjs';

const suite = browserSuite();

const LAMPS = 12;
const mark = (page, n) => page.locator(`#street-picture g[data-address="${lamp(n)}"]`);
/** The lamps of the picture, in its order. */
const order = (page) =>
  page.$$eval('#street-picture g[data-address]', (gs) => gs.map((g) => g.dataset.address));

/** A fresh page at 1366×768, once every lamp of the picture was read. */
async function open(t, query = '') {
  const context = await suite.browser.newContext({ viewport: { width: 1366, height: 768 } });
  const page = await watchedPage(t, context);
  await page.goto(suite.base + query);
  await page.locator('#view-street').waitFor({ state: 'visible' });
  await page.waitForFunction(
    (n) => {
      const gs = [...document.querySelectorAll('#street-picture g[data-address]')];
      return gs.length === n && gs.every((g) => g.dataset.look !== 'unread');
    },
    LAMPS,
    { timeout: 60_000, polling: 250 },
  );
  return page;
}

/** Whether an element is inside the window as the page opens (not scrolled). */
async function inView(page, locator) {
  await page.evaluate(() => window.scrollTo(0, 0));
  const box = await locator.boundingBox();
  return box !== null && box.y >= 0 && box.y + box.height <= 768 && box.x + box.width <= 1366;
}

test('the street picture on opening: every lamp in address order, said so, above the table', async (t) => {
  const page = await open(t);
  const ascending = Array.from({ length: LAMPS }, (_, i) => lamp(i + 1));
  assert.deepEqual(await order(page), ascending);
  assert.match(await page.textContent('#street-order'), /^Address order \(no pole list\)/);
  // Each lamp named under its mark, with its SNR bar; the legend counts.
  assert.equal(await page.locator('#street-picture text.pk-name').count(), LAMPS);
  assert.equal(await page.locator('#street-picture .pk-snr').count(), LAMPS);
  assert.match(await page.textContent('#street-picture .pk-legend'), /dim set: as last set from this console/);
  assert.ok(await inView(page, page.locator('#street-picture svg.pk')), 'the picture is in view as the page opens');
  const picture = await page.locator('#street-picture svg.pk').boundingBox();
  const table = await page.locator('#fleet-table').boundingBox();
  assert.ok(picture.y + picture.height <= table.y, 'the picture is above the table');
  await shot(page, 'street-picture');
});

test('a failed lamp and a silent one stand out in the picture; a click opens a lamp page', async (t) => {
  const page = await open(t);
  await page.locator(`#fleet-table tbody tr[data-address="${lamp(5)}"]`).click();
  await page.click('#lamp-sim-fail');
  await page.locator(`#fleet-table tbody tr[data-address="${lamp(9)}"]`).click();
  await page.click('#lamp-sim-cut');
  await page.click('#lamp-close');
  await page.locator(`#street-picture g[data-address="${lamp(5)}"][data-look="failed"]`).waitFor({ timeout: 60_000 });
  await page.locator(`#street-picture g[data-address="${lamp(9)}"][data-look="silent"]`).waitFor({ timeout: 60_000 });
  // A ring around each, none around the others; named above the picture.
  assert.equal(await mark(page, 5).locator('.pk-halo').count(), 1);
  assert.equal(await mark(page, 9).locator('.pk-halo').count(), 1);
  assert.equal(await page.locator('#street-picture .pk-halo').count(), 2);
  assert.match(await page.textContent('#street-trouble'), new RegExp(`${lamp(5)} failed`));
  assert.match(await page.textContent('#street-trouble'), new RegExp(`${lamp(9)} not answering`));
  assert.ok(await inView(page, mark(page, 5)), 'the failed lamp is in view without scrolling');
  assert.ok(await inView(page, page.locator('#street-trouble')), 'so are the words naming it');
  await shot(page, 'street-picture-failed');
  // A click on a mark opens that lamp's page.
  await mark(page, 5).click();
  await page.locator('#lamp-panel h3', { hasText: lamp(5) }).waitFor();
  await mark(page, 7).click();
  await page.locator('#lamp-panel h3', { hasText: lamp(7) }).waitFor();
  // The picture marks the lamp whose page is open, and only that one.
  await page.locator(`#street-picture g.pk-focus[data-address="${lamp(7)}"]`).waitFor();
  assert.equal(await page.locator('#street-picture .pk-focus').count(), 1);
  await shot(page, 'street-picture-lamp');
});

test('a pole list orders the picture and is kept; a malformed one is refused with nothing changed', async (t) => {
  const page = await open(t);
  // The street runs from lamp 12 down to lamp 1, 30 m apart.
  const rows = Array.from({ length: LAMPS }, (_, i) => `${lamp(LAMPS - i)},Pole ${i + 1},${30 * i}`);
  const list = `address,pole,position m\r\n${rows.join('\r\n')}\r\n`;
  await page.setInputFiles('#street-poles', { name: 'poles.csv', mimeType: 'text/csv', buffer: Buffer.from(list) });
  await page.locator('#street-poles-note', { hasText: 'pole list poles.csv: 12 pole(s)' }).waitFor();
  const descending = Array.from({ length: LAMPS }, (_, i) => lamp(LAMPS - i));
  await page.waitForFunction((first) => document.querySelector('#street-picture g[data-address]').dataset.address === first, lamp(LAMPS));
  assert.deepEqual(await order(page), descending);
  assert.equal(await page.textContent('#street-order'), "Pole order: the pole list's 12 pole(s)");
  assert.equal(await mark(page, LAMPS).locator('text.pk-name').textContent(), 'Pole 1');
  assert.equal(await mark(page, 1).locator('text.pk-small').first().textContent(), '330 m');
  await shot(page, 'street-picture-poles');

  // A lamp listed twice: refused, naming the line; the list and its order stay.
  const kept = await page.evaluate(() => localStorage.getItem('plm-console.poles'));
  assert.equal(kept, list);
  const bad = `${lamp(1)},A\n${lamp(2)},B\n${lamp(1)},C\n`;
  await page.setInputFiles('#street-poles', { name: 'bad.csv', mimeType: 'text/csv', buffer: Buffer.from(bad) });
  await page
    .locator('#street-poles-note', {
      hasText: `pole list bad.csv refused, nothing changed: line 3: lamp ${lamp(1)} is listed on line 1 already`,
    })
    .waitFor();
  // A position that is not whole metres, in a file that is not UTF-8 after it.
  await page.setInputFiles('#street-poles', {
    name: 'metres.csv',
    mimeType: 'text/csv',
    buffer: Buffer.from(`${lamp(1)},A,12.5\n`),
  });
  await page.locator('#street-poles-note', { hasText: 'line 1: position "12.5"' }).waitFor();
  await shot(page, 'street-picture-refused');
  assert.deepEqual(await order(page), descending);
  assert.equal(await page.evaluate(() => localStorage.getItem('plm-console.poles')), kept);

  // Kept across a reload; forgotten on request.
  await page.reload();
  await page.waitForFunction((n) => document.querySelectorAll('#street-picture g[data-address]').length === n, LAMPS);
  assert.deepEqual(await order(page), descending);
  await page.click('#street-poles-clear');
  await page.locator('#street-order', { hasText: 'Address order (no pole list)' }).waitFor();
  assert.deepEqual(await order(page), [...descending].reverse());
  assert.equal(await page.evaluate(() => localStorage.getItem('plm-console.poles')), null);
});

test('a long street: small marks in rows that wrap, the picture in view, a lamp found by the pointer', async (t) => {
  const context = await suite.browser.newContext({ viewport: { width: 1366, height: 768 } });
  const page = await watchedPage(t, context);
  await page.goto(`${suite.base}?lamps=500`);
  // Lamps appear as discovery hears them; a hundred are enough to see the layout.
  await page.waitForFunction(() => Number(document.querySelector('#fleet-table')?.dataset.rows ?? 0) >= 100, null, {
    timeout: 180_000,
    polling: 500,
  });
  await shot(page, 'street-picture-long');
  // Measured at once: the picture is written again as lamps are found.
  const seen = await page.evaluate(() => {
    const svg = document.querySelector('#street-picture svg.pk');
    const box = svg.getBoundingClientRect();
    return {
      top: box.top,
      left: box.left,
      width: box.width,
      height: box.height,
      lamps: Number(document.querySelector('#fleet-table').dataset.rows),
      names: document.querySelectorAll('#street-picture text.pk-name').length,
      // Small marks are a few paths for the whole street, no element per lamp.
      elements: svg.querySelectorAll('*').length,
    };
  });
  assert.equal(seen.names, 0, 'no words under small marks');
  assert.ok(seen.elements < 40, `${seen.elements} elements for ${seen.lamps} lamps`);
  const rows = Math.ceil(seen.lamps / 58);
  assert.ok(Math.abs(seen.height - rows * 26) <= 2 * rows + 26, `${rows} rows of 26 px: ${seen.height} px`);
  // 500 lamps take 9 rows: the picture would still end within the window.
  assert.ok(seen.top + (9 * 26 * seen.width) / 1320 <= 768, `the picture starts at ${seen.top} px`);
  // The first lamp's cell (after the row numbers' 34 px), under the pointer:
  // its words as the tooltip, a click opens its page and marks its cell.
  const scale = seen.width / 1320;
  await page.mouse.move(seen.left + (34 + 11) * scale, seen.top + 9 * scale);
  const title = await page.getAttribute('#street-picture-street', 'title');
  assert.match(title, /^0080e1[0-9a-f]{6}: /);
  await page.mouse.click(seen.left + (34 + 11) * scale, seen.top + 9 * scale);
  await page.locator('#lamp-panel h3', { hasText: title.slice(0, 12) }).waitFor();
  await page.locator('#street-picture rect.pk-focus').waitFor();
  // Over the row numbers' margin, no lamp.
  await page.mouse.move(seen.left + 5 * scale, seen.top + 9 * scale);
  assert.equal(await page.getAttribute('#street-picture-street', 'title'), null);
});
