// The demo street over its first three minutes (plm-sim's street
// profile, docs/console.md "The simulated street"): the default Street
// page at 15 s and at 180 s of simulated time, at a field technician's
// laptop size, run 10 times as fast as the page's clock. At 15 s every
// lamp burns, of different powers and temperatures, the far lamp heard
// the weakest of all; by 180 s the worn lamp has failed and is raised
// as an alert, the others burn on, the far lamp still answers, and the
// mains have moved.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs/promises';
import { browserSuite, watchedPage } from './harness.mjs';
import { everyLampRead, lamp, shot } from './journeys.mjs';

const suite = browserSuite();

const LAMPS = 12;
const SPEED = 10;

/** The street's clock, s of simulated time. */
const streetSeconds = (page) => page.evaluate(() => window.plmBench.streetSeconds());

/** Waits until the street's clock reaches `s` seconds. */
async function until(page, s) {
  await page.waitForFunction((s) => window.plmBench.streetSeconds() >= s, s, {
    timeout: (s / SPEED) * 1000 + 60_000,
    polling: 100,
  });
}

/** The fleet as the CSV export gives it: one object per lamp by address. */
async function fleet(page) {
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#street-export-csv')]);
  const lines = (await fs.readFile(await download.path(), 'utf8')).trim().split('\r\n');
  const keys = lines[0].split(',');
  return Object.fromEntries(
    lines.slice(1).map((l) => {
      const row = Object.fromEntries(l.split(',').map((v, i) => [keys[i], v]));
      return [row.Address, row];
    }),
  );
}

const distinct = (rows, key) => new Set(Object.values(rows).map((r) => r[key])).size;

test('the demo street at 15 s and at 180 s: lamps that differ, a worn one failing, a weak one answering', async (t) => {
  const context = await suite.browser.newContext({ acceptDownloads: true, viewport: { width: 1366, height: 768 } });
  const page = await watchedPage(t, context);
  await page.goto(suite.base + `?speed=${SPEED}`);
  await page.locator('#view-street').waitFor({ state: 'visible' });

  await until(page, 15);
  await everyLampRead(page, LAMPS, { polling: 100 });
  const early = await streetSeconds(page);
  await shot(page, 'street-demo-15s');
  t.diagnostic(`first screenshot at ${early.toFixed(1)} s of simulated time`);
  assert.ok(early < 30, `every lamp read by ${early.toFixed(1)} s of simulated time`);
  const first = await fleet(page);
  assert.equal(Object.keys(first).length, LAMPS);
  assert.ok(Object.values(first).every((r) => r.Lamp === 'RUN'), JSON.stringify(first));
  // Lamps of different powers, ages and temperatures.
  assert.ok(distinct(first, 'Power W') >= 3, JSON.stringify(first));
  assert.ok(distinct(first, 'Temp °C') >= 3, JSON.stringify(first));
  assert.ok(distinct(first, 'Hours') >= 10, JSON.stringify(first));
  // The far lamp is heard, the weakest of the street.
  const snr = (n) => Number(first[lamp(n)]['SNR dB']);
  for (let n = 1; n < LAMPS; n++) assert.ok(snr(n) > snr(LAMPS), `lamp ${n}: ${snr(n)} dB, far lamp ${snr(LAMPS)} dB`);

  await until(page, 180);
  // The worn lamp has failed (about two minutes in) and is raised as an
  // alert; every other lamp burns on.
  const alert = page.locator('#street-alerts li', { hasText: 'lamp failed' });
  await alert.first().waitFor({ timeout: 60_000 });
  await page.waitForFunction(
    () => [...document.querySelectorAll('#fleet-table tbody td[data-key="state"]')].some((c) => c.textContent === 'FAILURE'),
    null,
    { timeout: 60_000, polling: 100 },
  );
  const late = await streetSeconds(page);
  await shot(page, 'street-demo-180s');
  t.diagnostic(`second screenshot at ${late.toFixed(1)} s of simulated time`);
  const second = await fleet(page);
  const failed = Object.values(second).filter((r) => r.Lamp === 'FAILURE');
  assert.equal(failed.length, 1, JSON.stringify(second));
  const worn = failed[0].Address;
  assert.notEqual(worn, lamp(LAMPS), 'the worn lamp is not the far one');
  assert.equal(Number(failed[0]['Power W']), 0);
  assert.equal(await alert.count(), 1);
  assert.match(await alert.first().textContent(), new RegExp(worn));
  for (const r of Object.values(second).filter((r) => r.Address !== worn)) assert.equal(r.Lamp, 'RUN', r.Address);
  // The far lamp still answers: last seen within a minute of the street's
  // newest answer (clock times, HH:MM:SS).
  const seconds = (r) => r['Last seen'].split(':').reduce((a, v) => a * 60 + Number(v), 0);
  const newest = Math.max(...Object.values(second).map(seconds));
  const far = seconds(second[lamp(LAMPS)]);
  assert.ok((newest - far + 86_400) % 86_400 < 60, JSON.stringify(second[lamp(LAMPS)]));
  // The mains moved between the two.
  const moved = Object.keys(first).filter((a) => first[a]['Supply V'] !== second[a]['Supply V']);
  assert.ok(moved.length >= 3, `supply moved at ${moved.length} lamps`);
});
