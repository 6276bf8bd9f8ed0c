// Browser end-to-end journeys of the Firmware update view against the
// simulated street the page opens on, run 10 times as fast as the page's
// clock (`?speed=10`) so that minutes of power line traffic take seconds.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs/promises';
import { launchChromium, serveDist, watchedPage } from './harness.mjs';
import { everyLampRead, shot, tab } from './journeys.mjs';

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

const lamp = (n) => `0080e1${n.toString(16).padStart(6, '0')}`;
const firmware = (page, n) =>
  page.locator(`#fleet-table tbody tr[data-address="${lamp(n)}"] td[data-key="firmware"]`);

/** A fresh page on a street of `lamps`, every lamp found and read. */
async function open(t, lamps = 12) {
  const context = await browser.newContext({
    acceptDownloads: true,
    viewport: { width: 1400, height: 900 },
  });
  const page = await watchedPage(t, context);
  await page.goto(`${base}?speed=10&lamps=${lamps}`);
  await everyLampRead(page, lamps);
  return page;
}

/** Makes a simulated image of release `release` in the view. */
async function makeImage(page, release, size = 3000) {
  await tab(page, 'update');
  await page.fill('#update-make-release', release);
  await page.fill('#update-make-size', String(size));
  await page.click('#update-make');
  await page.locator('#update-image', { hasText: `release ${release}` }).waitFor();
}

const summary = (page, text) =>
  page.locator('#update-summary', { hasText: text }).waitFor({ timeout: 120_000 });

test('update one lamp with a generated image and see its release change', async (t) => {
  const page = await open(t);
  await makeImage(page, '1.5');
  assert.match(await page.textContent('#update-image'), /simulated-1\.5\.bin: 3000 bytes, release 1\.5, CRC-32 [0-9A-F]{8}/);
  await page.selectOption('#update-targets', `lamp:${lamp(3)}`);
  await page.click('#update-start');
  await page.locator('#update-boards tbody tr').first().waitFor();
  await shot(page, 'update-running');
  await summary(page, 'to 1 lamp(s): 1 updated, 0 not updated · took');
  assert.match(await page.textContent('#update-boards tbody tr'), /updated to 1\.5/);
  // The target list was rebuilt as the fleet changed; the choice stays.
  assert.equal(await page.inputValue('#update-targets'), `lamp:${lamp(3)}`);
  await shot(page, 'update-one');
  await tab(page, 'street');
  await page.waitForFunction(
    (sel) => document.querySelector(sel)?.textContent === '1.5',
    `#fleet-table tr[data-address="${lamp(3)}"] td[data-key="firmware"]`,
  );
  assert.equal(await firmware(page, 4).textContent(), '1.4', 'the others keep theirs');
});

test('a truncated image is refused before anything is sent', async (t) => {
  const page = await open(t);
  await makeImage(page, '1.6', 4000);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#update-save-image')]);
  const whole = await fs.readFile(await download.path());
  assert.equal(whole.length, 4000);
  await page.setInputFiles('#update-file', {
    name: 'cut.bin',
    mimeType: 'application/octet-stream',
    buffer: whole.subarray(0, 2500),
  });
  const note = page.locator('#update-image', { hasText: 'cut.bin refused: truncated' });
  await note.waitFor();
  assert.match(await note.textContent(), /the image says 4000 bytes and the file has 2500/);
  assert.match(await note.getAttribute('class'), /error/);
  assert.equal(await page.isDisabled('#update-start'), true, 'nothing can be started');
  assert.equal(await page.locator('#update-progress-card').count(), 0, 'no campaign');
  await shot(page, 'update-refused');
  // The whole file is taken.
  await page.setInputFiles('#update-file', {
    name: 'whole.bin',
    mimeType: 'application/octet-stream',
    buffer: whole,
  });
  await page.locator('#update-image', { hasText: 'whole.bin: 4000 bytes, release 1.6' }).waitFor();
  assert.equal(await page.isDisabled('#update-start'), false);
});

/**
 * A plain .bin as ST's toolchain writes it (UM 4.3): an STM32F103xB
 * vector table (ECh bytes) for an image linked at `base` (08001000h
 * after the bootloader, 08000000h without it), reserved words 0, then
 * bytes standing for code.
 */
function plainBin(size, base = 0x0800_1000) {
  const b = Buffer.alloc(size, 0x5a);
  b.writeUInt32LE(0x2000_5000, 0);
  for (let at = 4; at < 0xec; at += 4) {
    const reserved = [0x1c, 0x20, 0x24, 0x28, 0x34].includes(at);
    b.writeUInt32LE(reserved ? 0 : base + 0x200 + at + 1, at);
  }
  return b;
}

test('a plain .bin from the toolchain updates a lamp; one built without the bootloader is refused', async (t) => {
  const page = await open(t);
  await tab(page, 'update');
  await page.setInputFiles('#update-file', {
    name: 'standalone.bin',
    mimeType: 'application/octet-stream',
    buffer: plainBin(3000, 0x0800_0000),
  });
  const refused = page.locator('#update-image', { hasText: 'standalone.bin refused' });
  await refused.waitFor();
  assert.match(await refused.textContent(), /built without the bootloader/);
  assert.equal(await page.isDisabled('#update-start'), true, 'nothing can be started');
  await shot(page, 'update-plain-refused');

  await page.setInputFiles('#update-file', {
    name: 'PLM_HID_STANDALONE.bin',
    mimeType: 'application/octet-stream',
    buffer: plainBin(3000),
  });
  const taken = page.locator('#update-image', { hasText: 'PLM_HID_STANDALONE.bin: 3000 bytes' });
  await taken.waitFor();
  assert.match(await taken.textContent(), /names no release/);
  // A release that is not x.y is refused before anything is sent.
  await page.fill('#update-release', '2');
  await page.selectOption('#update-targets', `lamp:${lamp(5)}`);
  await page.click('#update-start');
  await page.locator('#update-message', { hasText: "nothing sent: '2' is not a release" }).waitFor();
  assert.equal(await page.locator('#update-progress-card').count(), 0, 'no campaign');
  await page.fill('#update-release', '2.3');
  await page.click('#update-start');
  await summary(page, 'release 2.3 to 1 lamp(s): 1 updated, 0 not updated · took');
  assert.match(await page.textContent('#update-boards tbody tr'), /updated to 2\.3/);
  await shot(page, 'update-plain');
  await tab(page, 'street');
  await page.waitForFunction(
    (sel) => document.querySelector(sel)?.textContent === '2.3',
    `#fleet-table tr[data-address="${lamp(5)}"] td[data-key="firmware"]`,
  );
});

test('a street of 10 with one lamp unreachable: the others updated, that one reported', async (t) => {
  const page = await open(t, 10);
  await page.click(`#fleet-table tbody tr[data-address="${lamp(7)}"]`);
  await page.click('#lamp-sim-cut');
  await makeImage(page, '1.7', 2000);
  await page.selectOption('#update-targets', 'all');
  await page.click('#update-start');
  await summary(page, 'to 10 lamp(s): 9 updated, 1 not updated · took');
  const row = page.locator('#update-boards tbody tr', { hasText: lamp(7) });
  assert.match(await row.textContent(), /not updated: .*did not answer/);
  assert.match(await row.getAttribute('class'), /trouble/);
  await shot(page, 'update-street');
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#update-export')]);
  const csv = await fs.readFile(await download.path(), 'utf8');
  assert.equal(csv.trim().split('\n').length, 11, csv);
  assert.match(csv, new RegExp(`${lamp(2)},"updated to 1.7"`));
  assert.match(csv, new RegExp(`${lamp(7)},"not updated: .*did not answer`));
});

test('leaving mid-update warns; after a reload the update resumes and finishes', async (t) => {
  const page = await open(t);
  await makeImage(page, '1.8', 6000);
  await page.selectOption('#update-targets', 'all');
  await page.click('#update-start');
  await page.waitForFunction(() => Number(document.querySelector('#update-progress')?.value) > 100);
  const dialogs = [];
  page.on('dialog', async (d) => {
    dialogs.push(d.type());
    await d.accept();
  });
  await page.reload();
  assert.deepEqual(dialogs, ['beforeunload'], 'the page asked before leaving');
  await tab(page, 'update');
  const banner = page.locator('#update-saved');
  await banner.waitFor();
  assert.match(await banner.textContent(), /release 1\.8 to 12 lamp\(s\), 6000-byte image/);
  await shot(page, 'update-saved');
  await page.click('#update-resume');
  await summary(page, 'to 12 lamp(s): 12 updated, 0 not updated · took');
  await shot(page, 'update-resumed');
  await page.locator('#update-dismiss').click();
  // Closed: the results go, and nothing is offered to resume.
  await page.locator('#update-progress-card').waitFor({ state: 'detached' });
  assert.equal(await page.locator('#update-saved').count(), 0);
});
