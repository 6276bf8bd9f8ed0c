// The journeys the issue asks for over both transports (simulated and
// WebSerial), written once: each test file sets up its transport, then
// calls these on an open page. Transport-specific checks stay in the test.

import assert from 'node:assert/strict';
import fs from 'node:fs/promises';
import path from 'node:path';
import { artifacts } from './harness.mjs';

/** The address of the simulated street's lamp `n` (plm_sim's street_address). */
export const lamp = (n) => `0080e1${n.toString(16).padStart(6, '0')}`;

/** Waits until the fleet table lists `n` lamps, every one read (`RUN`). */
export async function everyLampRead(page, n, { timeout = 60_000, polling = 250 } = {}) {
  await page.waitForFunction(
    (count) => {
      const cells = [...document.querySelectorAll('#fleet-table tbody td[data-key="state"]')];
      return cells.length === count && cells.every((c) => c.textContent === 'RUN');
    },
    n,
    { timeout, polling },
  );
}

/** Opens a view by its tab. */
export async function tab(page, slug) {
  await page.click(`#tab-${slug}`);
  await page.locator(`#view-${slug}`).waitFor({ state: 'visible' });
}

/** A screenshot into artifacts/. */
export async function shot(page, name) {
  await page.screenshot({ path: path.join(artifacts, `${name}.png`), fullPage: false });
}

/** Titles of the traffic rows drawn (Element column): those in view. */
export async function titles(page) {
  return page.locator('#traffic-table tbody tr td.title').allTextContents();
}

/** Modem view: read, change, write and read back MIB 01h (PHY config). */
export async function phyRoundTrip(page, shotName) {
  await tab(page, 'modem');
  const card = page.locator('#mib-01');
  const status = card.locator('[data-role=status]');
  await card.locator('[data-action=read]').click();
  await status.filter({ hasText: 'read from the modem' }).waitFor();
  const freq = card.locator('input[name=high_frequency]');
  assert.equal(await freq.inputValue(), '86000');
  assert.equal(await card.locator('[data-role=diff]').textContent(), 'equal to the factory default');

  await freq.fill('110000');
  await card.locator('input[name=tx_gain]').fill('20');
  await card.locator('[data-action=write]').click();
  await status.filter({ hasText: 'written and read back: the modem has it' }).waitFor();

  // Read it back once more, by hand.
  await card.locator('[data-action=read]').click();
  await status.filter({ hasText: 'read from the modem' }).waitFor();
  assert.equal(await freq.inputValue(), '110000');
  assert.equal(await card.locator('input[name=tx_gain]').inputValue(), '20');
  assert.match(
    await card.locator('[data-role=diff]').textContent(),
    /2 field\(s\) differ from the factory default: High frequency, TX gain/,
  );
  await shot(page, shotName);

  await tab(page, 'traffic');
  await page.selectOption('#filter-command', 'MIB_WriteRequest');
  // One write; the link repeats the same frame only when an attempt went
  // wrong (UM0932 3.2.7), which a loaded machine can cause, and then the
  // connection bar counts the repeats.
  const rows = page.locator('#traffic-table tbody tr');
  const sent = await rows.count();
  assert.ok(sent >= 1, 'the MIB_WriteRequest is in the log');
  for (const row of await rows.all()) assert.match(await row.textContent(), /high_frequency=110000/);
  if (sent > 1) {
    const repeats = Number(await page.textContent('#conn-retries b'));
    assert.ok(repeats >= sent - 1, `${sent} requests sent with ${repeats} repeats`);
  }
}

/**
 * Modem view: an out-of-range frequency is refused next to the field and
 * nothing is sent (no MIB_WriteRequest in the log; the caller may check
 * the wire too).
 */
export async function refusedFrequency(page, shotName, chip = ST7580_F) {
  await tab(page, 'traffic');
  const writes = async () => (await titles(page)).filter((t) => t === chip.write).length;
  const before = await writes();
  await tab(page, 'modem');
  const card = page.locator(chip.card);
  await card.locator(`input[name=${chip.field}]`).fill('200000');
  await card.locator('[data-action=write]').click();
  const reason = card.locator(`tr[data-field=${chip.field}] [data-role=problem]`);
  await reason.filter({ hasText: `200000 is out of range: ${chip.range} Hz` }).waitFor();
  assert.ok(await reason.isVisible());
  assert.match(await card.locator('[data-role=status]').textContent(), /^nothing sent/);
  await shot(page, shotName);
  // Give a wrongly sent request time to show up, then look for it.
  await page.waitForTimeout(300);
  await tab(page, 'traffic');
  const all = await titles(page);
  assert.ok(all.length > 0 || !chip.reset, 'the log has the reset indication');
  assert.equal(await writes(), before, `no ${chip.write} sent: ${all.join(', ')}`);
}

/** The frequency field of each chip's PHY configuration object. */
export const ST7580_F = { card: '#mib-01', field: 'high_frequency', range: '3000 to 148500', write: 'MIB_WriteRequest', reset: true };
export const ST7570_F = { card: '#mib-00a1', field: 'f0', range: '3000 to 140000', write: 'CMD_WriteDBRequest', reset: false };

/**
 * Traffic view: export the log to JSON Lines, clear, import it again and
 * see the same rows. Returns the exported entries.
 */
export async function exportImport(page, fileName, shotName) {
  await tab(page, 'traffic');
  await page.click('#traffic-pause');
  // The rows drawn (those in view) and how many the log keeps.
  const before = await titles(page);
  const kept = Number(/^(\d+) elements kept/.exec(await page.textContent('#traffic-counts'))[1]);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#traffic-export')]);
  assert.equal(download.suggestedFilename(), 'plm-traffic.jsonl');
  const file = path.join(artifacts, fileName);
  await download.saveAs(file);
  const lines = (await fs.readFile(file, 'utf8')).trim().split('\n');
  assert.equal(lines.length, kept);
  const entries = lines.map((l) => JSON.parse(l));
  for (const e of entries) {
    assert.equal(typeof e.time_us, 'number');
    assert.ok(['frame', 'ack', 'nak', 'status', 'garbage'].includes(e.kind), JSON.stringify(e));
    assert.match(e.hex, /^([0-9a-f]{2})+$/);
  }

  await page.click('#traffic-clear');
  assert.equal(await page.locator('#traffic-table tbody tr').count(), 0);
  await page.setInputFiles('#traffic-import', file);
  await page.locator('#traffic-message', { hasText: `Imported ${lines.length} elements` }).waitFor();
  assert.deepEqual(await titles(page), before);
  if (shotName) await shot(page, shotName);
  return entries;
}

/** ST7570: the Modem view's set-up card makes the modem a MAC Client. */
export async function macClient(page) {
  await tab(page, 'modem');
  await page.locator('#setup-role').selectOption('0');
  await page.click('#setup-write');
  const result = page.locator('#setup-result');
  await result.filter({ hasText: /read back|not written|failed/ }).waitFor({ timeout: 10_000 });
  assert.equal(await result.textContent(), 'MAC Client (initiator): 00A1h written, read back: the modem has it');
}

/**
 * ST7570, MAC Client: the Data view sends "?" to Server 001h, the modem
 * confirms LM_OK, and the Server's answer (its address and phase) is
 * among the received frames.
 */
export async function macAsk(page) {
  await tab(page, 'data');
  await page.fill('#sfsk-da', '001');
  await page.fill('#sfsk-payload', '?');
  const before = await page.locator('#sfsk-received-table tbody tr').count();
  const result = page.locator('#sfsk-result');
  // A Server's alarm burst on the line makes the MAC layer busy (LM_TU:
  // "send again") while the Client repeats it (7.2.3), and a technician
  // sends again a moment later: an immediate retry lands in the same burst.
  for (let tries = 1; ; tries++) {
    await page.click('#sfsk-send-btn');
    await result.filter({ hasText: /^(?!sending)./ }).waitFor({ timeout: 25_000 });
    if (tries === 6 || !(await result.textContent()).startsWith('CMD_DataConfirm: LM_TU')) break;
    await page.waitForTimeout(700);
  }
  assert.equal(await result.textContent(), 'CMD_DataConfirm: LM_OK');
  const answers = page.locator('#sfsk-received-table tbody tr', { hasText: '001h → ' }).filter({ hasText: '"!001 phase' });
  await page.waitForFunction(
    (n) => document.querySelectorAll('#sfsk-received-table tbody tr').length > n,
    before,
    { timeout: 10_000 },
  );
  await answers.first().waitFor();
}

/**
 * ST7570, Network view: the Client's alarm goes out (LP_OK), sent again
 * when a Server's alarm burst kept the line busy (LP_TU).
 */
export async function sendAlarm(page) {
  const history = page.locator('#net-alarm-history');
  const ok = history.filter({ hasText: 'alarm sent: LP_OK' });
  const busy = () =>
    page.evaluate(() => (document.querySelector('#net-alarm-history').textContent.match(/alarm sent: LP_TU/g) ?? []).length);
  for (let tries = 1; tries <= 3; tries++) {
    const before = await busy();
    await page.click('#net-alarm');
    const busyAgain = page.waitForFunction(
      (n) => (document.querySelector('#net-alarm-history').textContent.match(/alarm sent: LP_TU/g) ?? []).length > n,
      before,
      { timeout: 10_000 },
    ).then(() => 'busy', () => 'neither');
    const sent = ok.waitFor({ timeout: 10_000 }).then(() => 'ok', () => 'neither');
    const got = await Promise.race([sent, busyAgain]);
    if (got === 'ok') return;
  }
  assert.fail('the alarm was not sent: the line stayed busy');
}
