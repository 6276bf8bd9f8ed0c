// Browser end-to-end journeys of the Street view against the simulated
// street the page opens on (12 lamps behind a concentrator board's USART).

import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs/promises';
import { browserSuite, watchedPage } from './harness.mjs';
import { everyLampRead, lamp, shot, tab } from './journeys.mjs';

const suite = browserSuite();

const LAMPS = 12;
const row = (page, n) => page.locator(`#fleet-table tbody tr[data-address="${lamp(n)}"]`);
const cell = (page, n, key) => row(page, n).locator(`td[data-key="${key}"]`);
const number = async (page, n, key) => Number(await cell(page, n, key).textContent());


/**
 * Records in the page, at every frame drawn, what the Street view shows
 * (rows, rows read, progress, frames sent) whenever it changes, with the
 * page's time: `window.streetLog`.
 */
const recordStreet = () => {
  window.streetLog = [];
  let last = '';
  const look = () => {
    const cells = [...document.querySelectorAll('#fleet-table tbody td[data-key="state"]')];
    const now = {
      rows: cells.length,
      read: cells.filter((c) => c.textContent === 'RUN').length,
      progress: document.querySelector('#street-progress')?.textContent ?? '',
      sent: parseInt(document.querySelector('#street-sent')?.textContent ?? '0', 10),
    };
    const key = JSON.stringify(now);
    if (key !== last) {
      last = key;
      window.streetLog.push({ at: performance.now(), ...now });
    }
    requestAnimationFrame(look);
  };
  requestAnimationFrame(look);
};

/**
 * A fresh page, waiting until every lamp of the street was found and
 * read; `meanwhile(page)` is called once the page is there. `query`:
 * `?street=uniform` for a journey that counts exact values (every lamp
 * the same 150 W lamp, nothing failing unless asked).
 */
async function open(t, meanwhile = async () => {}, query = '') {
  const context = await suite.browser.newContext({
    acceptDownloads: true,
    viewport: { width: 1400, height: 900 },
  });
  const page = await watchedPage(t, context);
  await page.addInitScript(recordStreet);
  await page.goto(suite.base + query);
  await page.locator('#view-street').waitFor({ state: 'visible' });
  await meanwhile(page);
  await everyLampRead(page, LAMPS);
  return page;
}

/** The page's time (s) at which the Street view first showed every lamp read. */
const filledAt = async (page) =>
  page.evaluate((n) => window.streetLog.find((s) => s.rows === n && s.read === n).at / 1000, LAMPS);

test('the page opens on the simulated street: every lamp found, read and lit within 10 s', async (t) => {
  const page = await open(t, async (page) => {
    await page.locator('#street-progress', { hasText: /discovering: [1-9]/ }).waitFor();
    await shot(page, 'street-discovering');
  });
  assert.equal(await page.getAttribute('#tab-street', 'aria-selected'), 'true');
  assert.match(await page.textContent('#street-port'), /concentrator board \(simulated, 12 lamps\)/);
  for (let n = 1; n <= LAMPS; n++) {
    assert.equal(await cell(page, n, 'firmware').textContent(), '1.4');
    assert.ok((await number(page, n, 'power')) > 0, `lamp ${n} draws power`);
    assert.ok((await cell(page, n, 'snr').textContent()) !== '', `lamp ${n} has an SNR`);
  }
  await shot(page, 'street');
  // While discovery runs the view says how many were found and are left,
  // and each lamp's row is there as soon as it is heard.
  const log = await page.evaluate(() => window.streetLog);
  const discovering = log.filter((s) => s.progress.startsWith('discovering:'));
  assert.match(discovering[0].progress, /^discovering: 0 found, about \d+ left…$/);
  assert.ok(
    discovering.some((s) => s.rows > 0 && s.rows < LAMPS && s.progress.startsWith(`discovering: ${s.rows} found`)),
    'rows appear one by one while discovery runs',
  );
  const filled = await filledAt(page);
  t.diagnostic(`every lamp's row filled at ${filled.toFixed(2)} s of page time`);
  assert.ok(filled <= 10, `every row filled at ${filled.toFixed(2)} s of page time, more than 10 s`);
});

test('after a reload the known lamps are read at once, without a discovery; then it looks for new ones', async (t) => {
  const page = await open(t);
  // What was found is kept for this connection.
  const kept = await page.evaluate(() => localStorage.getItem('plm-console.streets'));
  assert.match(kept, /^board · concentrator board \(simulated, 12 lamps\) · 57600 Bd · seed 7580\t1 [0-9a-f]{2} ([0-9a-f]{22}){12}$/);
  await page.reload();
  // Every lamp is in the table before any is read.
  await page.waitForFunction((n) => document.querySelectorAll('#fleet-table tbody tr').length === n, LAMPS);
  await shot(page, 'street-reloaded');
  await everyLampRead(page, LAMPS);
  const filled = await filledAt(page);
  t.diagnostic(`after the reload every lamp's row filled at ${filled.toFixed(2)} s of page time`);
  assert.ok(filled <= 10, `every row filled at ${filled.toFixed(2)} s of page time after the reload`);
  const log = await page.evaluate(() => window.streetLog);
  // The page shows the street at most five times a second
  // (stores::STREET_DRAW_US): the frame that shows the last lamp read may
  // already say that the discovery after the reads has begun.
  const shown = log.find((s) => s.rows === LAMPS && s.read === LAMPS);
  const before = log.filter((s) => s.at < shown.at);
  assert.deepEqual(
    before.filter((s) => s.progress.startsWith('discovering')),
    [],
    'no discovery before every lamp was read',
  );
  assert.ok(before.every((s) => s.rows === 0 || s.rows === LAMPS), 'the known lamps came at once');
  // Two requests per lamp (its state, its SNR): a discovery frame would be one more.
  const sent = shown.sent;
  assert.ok(sent <= 2 * LAMPS, `${sent} frames sent until every lamp was read`);
  // Then a discovery of the same session looks for new lamps, and finds none.
  await page.waitForFunction(() => window.streetLog.some((s) => s.progress.startsWith('discovering')), null, {
    timeout: 30_000,
  });
  await page.locator('#street-progress', { hasText: 'sweep' }).waitFor({ timeout: 60_000 });
  assert.equal(await page.locator('#fleet-table tbody tr').count(), LAMPS);
  await shot(page, 'street-reloaded-read');

  // A record that cannot be read is forgotten, said in words, and the
  // street discovered again.
  await page.evaluate(() => {
    const [id] = localStorage.getItem('plm-console.streets').split('\t');
    localStorage.setItem('plm-console.streets', `${id}\t1 zz 00`);
  });
  await page.reload();
  await page.locator('#link-problem', { hasText: 'cannot be read (its session is not two hex digits); it is forgotten and the street is discovered again' }).waitFor();
  await page.locator('#street-progress', { hasText: 'discovering' }).waitFor();
  await everyLampRead(page, LAMPS);
});

test('a column header sorts the fleet table by it, the other way on a second click', async (t) => {
  const page = await open(t);
  const header = page.locator('#fleet-table th[data-key="address"]');
  const addresses = () =>
    page.$$eval('#fleet-table tbody tr', (rows) => rows.map((r) => r.dataset.address));
  const ascending = Array.from({ length: LAMPS }, (_, i) => lamp(i + 1));
  // The table opens sorted by address, ascending.
  assert.deepEqual(await addresses(), ascending);
  assert.match(await header.textContent(), /▲$/);
  await header.click();
  await page.waitForFunction((first) => document.querySelector('#fleet-table tbody tr').dataset.address === first, lamp(LAMPS));
  assert.deepEqual(await addresses(), [...ascending].reverse());
  assert.match(await header.textContent(), /▼$/);
  await header.click();
  await page.waitForFunction((first) => document.querySelector('#fleet-table tbody tr').dataset.address === first, lamp(1));
  assert.deepEqual(await addresses(), ascending);
  // Another column takes the sort, ascending; the address loses its arrow.
  const firmware = page.locator('#fleet-table th[data-key="firmware"]');
  await firmware.click();
  await page.waitForFunction(() => document.querySelector('#fleet-table th[data-key="firmware"]').textContent.endsWith('▲'));
  assert.doesNotMatch(await header.textContent(), /[▲▼]/);
});

test('dim one lamp and see its power follow; dim all by broadcast', async (t) => {
  const page = await open(t, undefined, '?street=uniform');
  const before3 = await number(page, 3, 'power');
  await row(page, 3).click();
  await page.locator('#lamp-panel h3', { hasText: lamp(3) }).waitFor();
  // Typing in the lamp's page goes on while the lamp is read meanwhile
  // (its state and plots are redrawn, the forms are not).
  await page.fill('#lamp-dim-level', '');
  await page.focus('#lamp-dim-level');
  await page.keyboard.type('2');
  const state = await page.locator('#plot-power path.plot-line').getAttribute('d');
  await page.evaluate(() => document.querySelector('#lamp-read').click());
  await page.locator('#lamp-note', { hasText: 'read: done' }).waitFor({ timeout: 30_000 });
  await page.waitForFunction((was) => document.querySelector('#plot-power path.plot-line').getAttribute('d') !== was, state);
  await page.keyboard.type('0');
  assert.equal(await page.inputValue('#lamp-dim-level'), '20');
  assert.equal(await page.evaluate(() => document.activeElement.id), 'lamp-dim-level');
  await page.click('#lamp-dim');
  await page.waitForFunction(
    ([sel, was]) => Number(document.querySelector(sel)?.textContent) < was,
    [`#fleet-table tr[data-address="${lamp(3)}"] td[data-key="power"]`, before3],
    { timeout: 30_000 },
  );
  assert.equal(await cell(page, 3, 'dimming').textContent(), '20');
  await shot(page, 'street-lamp');

  await page.fill('#street-dim-level', '40');
  await page.click('#street-dim-all');
  await page.locator('#street-message', { hasText: 'dimming 40 % sent to every lamp (broadcast)' }).waitFor();
  // Power = rated × (0.5 + 0.5 × dimming / 100): 105 W at 40 % for 150 W lamps.
  await page.waitForFunction(
    (n) => {
      const cells = [...document.querySelectorAll('#fleet-table tbody td[data-key="power"]')];
      return cells.length === n && cells.every((c) => Number(c.textContent) === 105);
    },
    LAMPS,
    { timeout: 60_000, polling: 250 },
  );

  // Two lamps picked by their checkboxes (the row's page stays as it was),
  // dimmed as a selection, and picked off again.
  for (const n of [2, 4]) await row(page, n).locator('td.pick input').check();
  await page.locator('#street-dim-selected', { hasText: 'Dim selected (2)' }).waitFor();
  await page.locator('#lamp-panel h3', { hasText: lamp(3) }).waitFor();
  await page.fill('#street-dim-level', '60');
  await page.click('#street-dim-selected');
  await page.locator('#street-message', { hasText: 'dimming 60 % sent to 2 lamp(s)' }).waitFor();
  await page.waitForFunction(
    (sel) => Number(document.querySelector(sel)?.textContent) === 60,
    `#fleet-table tr[data-address="${lamp(4)}"] td[data-key="dimming"]`,
    { timeout: 60_000, polling: 250 },
  );
  await row(page, 2).locator('td.pick input').uncheck();
  await page.locator('#street-dim-selected', { hasText: 'Dim selected (1)' }).waitFor();
});

test('a failed lamp and an unreachable one are raised as alerts', async (t) => {
  // Uniform: the troubled lamps counted are the two made so.
  const page = await open(t, undefined, '?street=uniform');
  await row(page, 5).click();
  await page.click('#lamp-sim-fail');
  await row(page, 9).click();
  await page.click('#lamp-sim-cut');
  const alerts = page.locator('#street-alerts');
  await alerts.locator('li', { hasText: `${lamp(5)} lamp failed` }).waitFor({ timeout: 60_000 });
  await alerts.locator('li', { hasText: `${lamp(9)} stopped answering` }).waitFor({ timeout: 60_000 });
  assert.equal(await cell(page, 5, 'state').textContent(), 'FAILURE');
  assert.equal(await cell(page, 9, 'state').textContent(), 'UNREACHABLE');
  assert.match(await row(page, 5).getAttribute('class'), /trouble/);
  await page.fill('#street-filter', 'trouble');
  assert.equal(await page.locator('#fleet-table tbody tr').count(), 2);
  await shot(page, 'street-alerts');
});

test('random lamp failures set in the Simulator view are raised as alerts', async (t) => {
  const page = await open(t);
  await tab(page, 'simulator');
  await page.fill('#sim-failure-rate', 'lots');
  await page.click('#sim-apply-failures');
  await page.locator('#sim-failure-note', { hasText: 'nothing changed' }).waitFor();
  // 60 per lit hour: each of the 12 lamps fails about once a minute.
  await page.fill('#sim-failure-rate', '60');
  await page.click('#sim-apply-failures');
  await page.locator('#sim-failure-note', { hasText: 'about every 1.0 minutes' }).waitFor();
  await shot(page, 'simulator-failures');
  await tab(page, 'street');
  await page
    .locator('#street-alerts li', { hasText: 'lamp failed' })
    .first()
    .waitFor({ timeout: 90_000 });
});

test('the fleet table exports to CSV', async (t) => {
  const page = await open(t);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#street-export-csv')]);
  assert.equal(download.suggestedFilename(), 'street.csv');
  const text = await fs.readFile(await download.path(), 'utf8');
  const lines = text.trim().split('\r\n');
  assert.equal(lines[0], 'Address,Firmware,Lamp,Dimming %,Power W,Energy Wh (est.),Bus V,Lamp V,Supply V,Temp °C,Hours,Power-ons,SNR dB,Last seen');
  assert.equal(lines.length, 1 + LAMPS);
  // The street's energy, estimated from the readings once a lamp is read twice.
  await page.locator('#street-energy', { hasText: /^Energy: \d+\.\d Wh over the [1-9]\d* s this console watched \(estimated/ }).waitFor();
  // Last seen: the local clock time of the lamp's last answer.
  assert.ok(lines.slice(1).every((l) => /^0080e1[0-9a-f]{6},1\.4,RUN,.*,\d\d:\d\d:\d\d$/.test(l)), lines.join('\n'));
});

test('a dimming value out of range is refused with the reason and nothing is sent', async (t) => {
  const page = await open(t);
  // Stop the background poll so that the count of frames sent stays still.
  await page.uncheck('#street-sweep');
  await page.waitForTimeout(3_000);
  const sent = await page.textContent('#street-sent');
  await page.fill('#street-dim-level', '150');
  await page.click('#street-dim-all');
  await page
    .locator('#street-message', { hasText: 'nothing sent: dimming is 0 to 100 %, not 150' })
    .waitFor();
  await page.waitForTimeout(1_000);
  assert.equal(await page.textContent('#street-sent'), sent);
  await shot(page, 'street-refused');
});
