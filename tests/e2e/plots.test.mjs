// Browser journeys of the console's plots (views/plot.rs): a lamp's
// power, temperature and SNR on the Street view, the SNR of received
// frames on the Data view. Axes with clock times and units, the reading
// under the pointer, the lamps' readings kept across a reload, a damaged
// record of them forgotten in words. At the laptop size a field
// technician has (1366 × 768).

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { browserSuite, watchedPage } from './harness.mjs';
import { everyLampRead, lamp, shot, tab } from './journeys.mjs';

const suite = browserSuite();

const LAMPS = 12;
const CLOCK = /^\d\d:\d\d(:\d\d)?$/;

async function open(t, query = '', init = null) {
  const context = await suite.browser.newContext({ viewport: { width: 1366, height: 768 } });
  const page = await watchedPage(t, context);
  if (init) await page.addInitScript(init);
  await page.goto(suite.base + query);
  return page;
}

/** Waits until every lamp is read, then opens lamp `n`'s page. */
async function lampPage(page, n) {
  await everyLampRead(page, LAMPS);
  await page.locator(`#fleet-table tbody tr[data-address="${lamp(n)}"]`).click();
  await page.locator('#plot-power').waitFor();
}

/** Points of a lamp plot's line. */
const points = (page, id) =>
  page.evaluate((id) => (document.querySelector(`#${id} path.plot-line`)?.getAttribute('d').match(/[ML]/g) ?? []).length, id);

/**
 * Moves the mouse `share` of the way across plot `id` (at its middle
 * height) until its readout shows (a new reading redraws the plot and
 * takes the readout away), and returns the readout's text.
 */
async function pointAt(page, id, share) {
  const box = await page.locator(`#${id}`).boundingBox();
  for (let i = 0; i < 20; i++) {
    await page.mouse.move(box.x + box.width * share, box.y + box.height / 2 + (i % 2));
    const text = await page.evaluate((id) => document.querySelector(`#${id} .plot-readout`)?.textContent, id);
    if (text) return text;
    await page.waitForTimeout(100);
  }
  assert.fail(`no readout under the pointer on #${id}`);
}

test("a lamp's plots have clock times, units, a grid, min and max, and the reading under the pointer", async (t) => {
  const page = await open(t);
  await lampPage(page, 3);
  await page.waitForFunction(() => document.querySelectorAll('#plot-power path.plot-line').length === 1);
  for (const [id, name, unit] of [
    ['plot-power', 'Lamp power', 'W'],
    ['plot-temperature', 'Board temperature', '°C'],
    ['plot-snr', 'SNR ratio', 'dB'],
  ]) {
    const plot = page.locator(`#${id}`);
    const times = await plot.locator('text.plot-x').allTextContents();
    assert.ok(times.length >= 2, `${id}: ${times}`);
    for (const s of times) assert.match(s, CLOCK, `${id}: ${times}`);
    const values = await plot.locator('text.plot-y').allTextContents();
    assert.ok(values.length >= 3, `${id}: ${values}`);
    for (const v of values) assert.match(v, /^-?\d+$/, `${id}: ${values}`);
    assert.ok(new Set(values).size === values.length, `${id}: one label per tick: ${values}`);
    assert.equal(await plot.locator('text.plot-unit').textContent(), unit);
    assert.ok((await plot.locator('line.plot-grid').count()) >= 5, `${id}: a grid`);
    const caption = await page.locator('figure.lamp-plot', { has: plot }).locator('figcaption').textContent();
    assert.match(caption, new RegExp(`^${name} \\(${unit}\\) min -?\\d+ · max -?\\d+ · last -?\\d+$`));
  }
  // The simulated street's times are on its own clock, which started at the computer's time.
  await page.locator('#lamp-panel .plot-note', { hasText: "simulated street's clock" }).waitFor();

  // The reading under the pointer: the newest at the right end, with its
  // clock time (within a minute of the computer's) and unit.
  const readout = await pointAt(page, 'plot-power', 0.97);
  const m = readout.match(/^(\d\d):(\d\d):(\d\d) · (\d+) W$/);
  assert.ok(m, readout);
  const power = await page.locator(`#fleet-table tr[data-address="${lamp(3)}"] td[data-key="power"]`).textContent();
  assert.equal(m[4], power.trim());
  const skew = await page.evaluate(([h, mi, s]) => {
    const d = new Date();
    const now = d.getHours() * 3600 + d.getMinutes() * 60 + d.getSeconds();
    return Math.abs(((now - (h * 3600 + mi * 60 + s) + 43200 + 86400) % 86400) - 43200);
  }, [Number(m[1]), Number(m[2]), Number(m[3])]);
  assert.ok(skew <= 60, `the readout's clock is ${skew} s off the computer's`);
  assert.equal(await page.locator('#plot-power line.plot-rule').count(), 1);
  const temperature = await pointAt(page, 'plot-temperature', 0.05);
  assert.match(temperature, /^\d\d:\d\d:\d\d · -?\d+ °C$/);
  await pointAt(page, 'plot-power', 0.97);
  await shot(page, 'street-lamp-plots');
});

test("a lamp's readings are kept across a reload", async (t) => {
  // Ten times as fast: a reading every half second.
  const page = await open(t, '?speed=10');
  await lampPage(page, 5);
  await page.waitForFunction(() => (document.querySelector('#plot-power path.plot-line')?.getAttribute('d').match(/[ML]/g) ?? []).length >= 8, null, { timeout: 30_000 });
  const before = await points(page, 'plot-power');
  await page.reload();
  await page.locator(`#fleet-table tbody tr[data-address="${lamp(5)}"]`).click();
  await page.locator('#plot-power').waitFor();
  // The readings from before the reload are there, with what the page read since.
  const after = await points(page, 'plot-power');
  assert.ok(after >= before, `${after} points after the reload, ${before} before`);
  const stored = await page.evaluate(() => localStorage.getItem('plm-console.history'));
  assert.match(stored, /^plm-console history 1\t/);
  assert.ok(stored.includes(`\n${'0080e1000005'} `));
  await shot(page, 'street-lamp-reloaded');
});

test('a damaged record of the readings is forgotten in words, the page goes on', async (t) => {
  const page = await open(t, '', () => {
    localStorage.setItem('plm-console.history', 'plm-console history 1\tx\n0080e1000001 17 zz\n');
  });
  await page
    .locator('#link-problem', {
      hasText: "The lamps' readings kept in this browser cannot be read (line 2 has no readings of 9 bytes each in hex); they are forgotten.",
    })
    .waitFor();
  await lampPage(page, 1);
  assert.ok((await points(page, 'plot-power')) >= 1);
});

test('the SNR of received frames has axes with units and the reading under the pointer', async (t) => {
  const page = await open(t, '?profile=st7580#simulator');
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  await page.selectOption('#sim-nodes', '2');
  await page.click('#sim-apply-topology');
  await page.locator('#conn-port', { hasText: '1 echoing peer' }).waitFor();
  await tab(page, 'data');
  for (const payload of ['one', 'two', 'three']) {
    await page.fill('#data-payload', payload);
    await page.click('#data-send');
    await page.locator('#data-result', { hasText: 'DL_DataConfirm after' }).waitFor();
  }
  await page.waitForFunction(() => document.querySelectorAll('#snr-plot circle.snr-point').length >= 3, null, { timeout: 10_000 });
  const plot = page.locator('#snr-plot');
  const times = await plot.locator('text.plot-x').allTextContents();
  assert.ok(times.length >= 2, times.join(', '));
  for (const s of times) assert.match(s, /^\d+(\.\d+)?$/);
  assert.ok((await plot.locator('text.plot-y').count()) >= 2);
  const titles = await plot.locator('text.plot-title').allTextContents();
  assert.ok(titles.includes('SNR (dB)'), titles.join(', '));
  assert.ok(titles.some((s) => s.startsWith("time on the transport's clock (s)")), titles.join(', '));
  assert.match(await plot.locator('text.snr-count').textContent(), /^3 indications, SNR min -?\d+ dB, max -?\d+ dB$/);
  const readout = await pointAt(page, 'snr-plot', 0.97);
  assert.match(readout, /^\d+\.\d{6} s: DL_DataIndication, SNR -?\d+ dB$/);
  await shot(page, 'data-snr-plot');
});
