// Browser end-to-end journeys of PLM Console with the ST7570 (issue 12):
// the chip chosen in the connection bar and remembered, and its MIB read,
// written and refused through the same session and forms as the ST7580's,
// against the simulated S-FSK network in the page.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { launchChromium, serveDist, watchedPage } from './harness.mjs';
import { macAsk, macClient, refusedFrequency, sendAlarm, shot, ST7570_F, tab, titles } from './journeys.mjs';

let server;
let base;
let browser;

before(async () => {
  ({ server, base } = await serveDist());
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  await new Promise((r) => (server ? server.close(r) : r()));
});

async function open(t, query = '') {
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  const page = await watchedPage(t, context);
  await page.goto(base + query + '#modem');
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  return page;
}

test('the ST7570 is chosen in the connection bar, remembered, and configured as a MAC Client', async (t) => {
  const page = await open(t);
  await page.selectOption('#profile', 'st7570');
  await page.locator('#conn-chip', { hasText: 'ST7570' }).waitFor();
  await page.locator('#conn-transport', { hasText: 'simulated S-FSK network' }).waitFor();
  await page.locator('#conn-port', { hasText: 'ST7570 (simulated, 3 Servers on the line)' }).waitFor();
  // Every ST7570 object, from the declarative MIB (Table 71).
  await page.locator('#mib-00a1').waitFor();
  await page.click('#mib-read-all');
  await page.locator('#mib-progress', { hasText: /Read all \d+ objects|Read \d+ of \d+ objects/ }).waitFor({ timeout: 30_000 });

  const card = page.locator('#mib-00a1');
  const status = card.locator('[data-role=status]');
  // Read all filled the card: it no longer says "not read yet".
  await status.filter({ hasText: 'read from the modem' }).waitFor();
  await card.locator('[data-action=read]').click();
  await status.filter({ hasText: 'read from the modem' }).waitFor();
  assert.equal(await card.locator('[name=access_layer_mode]').inputValue(), '1');
  // A MAC Client: operating mode 1, access layer 2 (Table 137).
  await card.locator('[name=operating_mode]').selectOption('1');
  await card.locator('[name=access_layer_mode]').selectOption('2');
  await card.locator('[data-action=write]').click();
  await status.filter({ hasText: 'written and read back: the modem has it' }).waitFor();
  await card.locator('[data-action=read]').click();
  await status.filter({ hasText: 'read from the modem' }).waitFor();
  assert.equal(await card.locator('[name=operating_mode]').inputValue(), '1');
  await shot(page, 'st7570-modem');

  await tab(page, 'traffic');
  const all = await titles(page);
  assert.ok(all.includes('CMD_WriteDBRequest'), all.join(', '));
  assert.ok(all.includes('CMD_ReadDBConfirm'), all.join(', '));
  // The command filter offers the ST7570's commands, not the ST7580's.
  assert.equal(await page.locator('#filter-command option[value="MIB_WriteRequest"]').count(), 0);
  await page.selectOption('#filter-command', 'CMD_WriteDBRequest');
  await page.waitForFunction(() => {
    const t = [...document.querySelectorAll('#traffic-table tbody td.title')].map((c) => c.textContent);
    return t.length > 0 && t.every((x) => x.startsWith('CMD_WriteDBRequest'));
  });
  await page.selectOption('#filter-command', '');
  await shot(page, 'st7570-traffic');

  // The chip is remembered: a reload opens on the ST7570 again.
  await page.reload();
  await page.locator('#conn-chip', { hasText: 'ST7570' }).waitFor({ timeout: 15_000 });
});

test('an out-of-range ST7570 value is refused in the form with the reason, and nothing is sent', async (t) => {
  const page = await open(t, '?profile=st7570');
  await refusedFrequency(page, 'st7570-refused', ST7570_F);
});

test('a MAC Client asks a Server and sees its answer, the synchronization of that Server lost and found, and alarms both ways', async (t) => {
  const page = await open(t, '?profile=st7570');
  await macClient(page);

  // MAC timeouts 60 times as fast: 0003h's 40 s become 0.7 s.
  await tab(page, 'network');
  await page.locator('#net-sim-scale').selectOption('60');
  await page.locator('#net-status', { hasText: 'Client' }).waitFor({ timeout: 10_000 });

  await macAsk(page);
  await shot(page, 'st7570-data');

  await tab(page, 'network');
  const server = page.locator('#sim-server-1');
  await server.filter({ hasText: 'CONFIRMED' }).waitFor({ timeout: 10_000 });
  await page.locator('#net-nodes-table tr[data-key="001h"]').waitFor();
  // No frame for 0003h: lost, cause 2.
  await server.filter({ hasText: 'LOST, cause 2: Timeout frame not OK expired' }).waitFor({ timeout: 10_000 });
  assert.match(await server.locator('td.sync').textContent(), /^not synchronized$/);
  // Cut off, it hears nothing; reconnected, the next frame finds it again.
  await server.locator('button.cut').click();
  await server.locator('button.cut', { hasText: 'Reconnect' }).click();
  await server.locator('button.cut', { hasText: 'Cut off' }).waitFor();
  // Back to the manual's timeouts, so that it stays synchronized a while.
  await page.locator('#net-sim-scale').selectOption('1');
  await macAsk(page);
  await tab(page, 'network');
  await server.locator('td.fields').filter({ hasText: /^\d+\.\d+ s CONFIRMED/ }).waitFor({ timeout: 10_000 });

  // Alarms both ways: one from Server 001h received, one sent.
  await server.locator('button.alarm').click();
  await page.locator('#net-alarm-history', { hasText: 'alarm received' }).waitFor({ timeout: 10_000 });
  await sendAlarm(page);
  await page.locator('#net-alarms').scrollIntoViewIfNeeded();
  await shot(page, 'st7570-network');
});
