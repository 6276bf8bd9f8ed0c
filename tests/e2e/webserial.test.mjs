// Browser end-to-end journeys of PLM Console through its WebSerial
// transport: the real transport code (crates/plm-console/src/transport/
// webserial.rs) runs on a scripted navigator.serial (serial-shim.mjs) whose
// port is backed, through page bindings and an RFC 2217 client
// (rfc2217.mjs), by a real `plm sim --chip st7580` process, one per test.
// So RTS really toggles T_REQ in the simulated modem, and every byte really
// crosses a UART model at the chosen baud rate.
//
// Like console.test.mjs, it serves the release build in dist/ (built by
// `cargo xtask test` / `cargo xtask dist`), drives Debian's Chromium with
// playwright-core, fails on any page error, and saves screenshots into
// artifacts/.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs/promises';
import { existsSync } from 'node:fs';
import path from 'node:path';
import readline from 'node:readline';
import { spawn, spawnSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { launchChromium, serveDist, pageErrors, watchedPage } from './harness.mjs';
import { everyLampRead, exportImport, macAsk, macClient, sendAlarm, phyRoundTrip, refusedFrequency, shot, ST7570_F, tab, titles } from './journeys.mjs';
import { Rfc2217Client } from './rfc2217.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '../..');
const shim = path.join(here, 'serial-shim.mjs');
const targetDir = process.env.CARGO_TARGET_DIR
  ? path.resolve(root, process.env.CARGO_TARGET_DIR)
  : path.join(root, 'target');
const plmBin = process.env.PLM_BIN ?? path.join(targetDir, 'debug', process.platform === 'win32' ? 'plm.exe' : 'plm');

let server;
let base;
let browser;


/** The `plm` binary, built if it is not there yet. */
function ensurePlm() {
  if (existsSync(plmBin)) return;
  console.log(`webserial: ${plmBin} is missing; building it (cargo build -p plm-cli)`);
  const r = spawnSync('cargo', ['build', '-p', 'plm-cli'], { cwd: root, stdio: 'inherit' });
  if (r.error || r.status !== 0 || !existsSync(plmBin)) {
    throw new Error(
      `the simulated modem (${plmBin}) is missing and \`cargo build -p plm-cli\` could not build it` +
        (r.error ? `: ${r.error.message}` : ` (exit ${r.status})`) +
        '. Build it by hand, or point PLM_BIN at a plm binary.',
    );
  }
}

/**
 * Starts `plm sim --listen 127.0.0.1:0` with `world` (by default a
 * simulated ST7580 with `--nodes 2`) and waits for the address it prints.
 * Resolves to {host, port, stop()}.
 */
async function startSim(world = ['--chip', 'st7580', '--nodes', '2']) {
  const child = spawn(plmBin, ['sim', '--listen', '127.0.0.1:0', ...world], {
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  const output = [];
  child.stderr.on('data', (d) => output.push(String(d)));
  const lines = readline.createInterface({ input: child.stdout });
  const address = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`plm sim printed no address in 10 s: ${output.join('')}`)), 10_000);
    child.once('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`plm sim exited (${code}) before listening: ${output.join('')}`));
    });
    lines.on('line', (line) => {
      output.push(line + '\n');
      const m = /as RFC 2217 on (\S+)/.exec(line);
      if (m) {
        clearTimeout(timer);
        resolve(m[1]);
      }
    });
  });
  const colon = address.lastIndexOf(':');
  return {
    host: address.slice(0, colon),
    port: Number(address.slice(colon + 1)),
    output,
    async stop() {
      if (child.exitCode !== null) return;
      const exited = new Promise((r) => child.once('exit', r));
      child.kill('SIGTERM');
      const timer = setTimeout(() => child.kill('SIGKILL'), 3_000);
      await exited;
      clearTimeout(timer);
    },
  };
}

/**
 * The Node side of the scripted port: each open() of the page's port is an
 * RFC 2217 connection to the simulator. `wire` collects every client
 * (with its log of writes and RTS changes).
 */
async function bridge(context, sim) {
  const wire = { clients: [], current: null, opens: [] };
  let page = null;
  wire.attach = (p) => {
    page = p;
    // A new document (a reload) has no open port: the browser closed the
    // old document's. (Not 'framenavigated': a change of tab changes the
    // URL's fragment, which is a navigation too.)
    page.on('domcontentloaded', () => {
      wire.current?.close();
      wire.current = null;
    });
  };
  await context.exposeBinding('__plmSerialOpen', async (_source, id, settings) => {
    wire.opens.push(settings);
    const client = await Rfc2217Client.connect({ host: sim.host, port: sim.port, baud: settings.baudRate });
    // Bytes reach the page as a USB-UART adapter delivers them: in
    // packets, sent when the line has been quiet for its latency timer
    // (2 ms here, FTDI's low-latency setting) or 62 bytes are waiting.
    // (`plm sim` writes each byte at its wire time; a page call per byte
    // would take longer than T_IC between bytes.) One page call at a time
    // carries every packet that is ready, as the USB host takes every
    // packet the adapter holds at each poll: on a busy machine a page call
    // takes tens of ms, and calls queued one per packet held a frame's
    // tail back past the host's T_IC (a confirm lost as a cut frame).
    let ready = [];
    let pending = [];
    let timer = null;
    let busy = false;
    const deliver = async () => {
      if (busy) return;
      busy = true;
      while (ready.length > 0) {
        const packets = ready;
        ready = [];
        try {
          await page?.evaluate(([i, ps]) => ps.forEach((b) => window.__plmSerialShim.receive(i, b)), [id, packets]);
        } catch {
          // The page went away: the bytes are lost, as on a pulled cable.
        }
      }
      busy = false;
    };
    const flush = () => {
      clearTimeout(timer);
      timer = null;
      if (pending.length > 0) ready.push(pending);
      pending = [];
      deliver();
    };
    client.on('data', (bytes) => {
      for (const b of bytes) {
        pending.push(b);
        if (pending.length === 62) flush();
      }
      clearTimeout(timer);
      timer = pending.length > 0 ? setTimeout(flush, 2) : null;
    });
    wire.clients.push(client);
    wire.current = client;
    return true;
  });
  await context.exposeBinding('__plmSerialWrite', (_source, _id, bytes) => {
    wire.current?.write(bytes);
  });
  await context.exposeBinding('__plmSerialSignals', (_source, _id, signals) => {
    if ('rts' in signals) wire.current?.setRts(signals.rts);
    if ('dtr' in signals) wire.current?.setDtr(signals.dtr);
  });
  await context.exposeBinding('__plmSerialClose', (_source, _id) => {
    wire.current?.close();
    wire.current = null;
  });
  return wire;
}

before(async () => {
  ensurePlm();
  ({ server, base } = await serveDist());
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  await new Promise((r) => (server ? server.close(r) : r()));
});

/**
 * A fresh page with the scripted port, backed by a fresh simulator with
 * `nodes` modems (node 0 on the port, the others echo). Fails the test on
 * page errors.
 */
async function open(t, { nodes = 2, world = ['--chip', 'st7580', '--nodes', String(nodes)], profile = 'st7580' } = {}) {
  const sim = await startSim(world);
  const context = await browser.newContext({
    acceptDownloads: true,
    viewport: { width: 1400, height: 900 },
  });
  const wire = await bridge(context, sim);
  await context.addInitScript({ path: shim });
  const page = await context.newPage();
  wire.attach(page);
  const errors = pageErrors(page);
  t.after(async () => {
    await context.close();
    for (const c of wire.clients) c.close();
    await sim.stop();
    assert.deepEqual(errors, [], 'no errors in the page');
  });
  await page.goto(base + `?profile=${profile}#${profile === 'st7580' ? 'traffic' : 'street'}`);
  // The simulated world of the profile is there first.
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  return { page, wire, sim, context };
}

/** Opens the WebSerial panel. */
async function panel(page) {
  if ((await page.getAttribute('#serial-toggle', 'aria-expanded')) !== 'true') {
    await page.click('#serial-toggle');
  }
  await page.locator('#serial-panel').waitFor({ state: 'visible' });
}

/**
 * Chooses WebSerial: grants the scripted port (unless it is remembered),
 * picks `baud`, connects, and waits for the modem's BIO_ResetIndication
 * (the simulated modems power on when the first client connects).
 */
async function connectSerial(page, { baud = 57600, grant = true, reset = true, screenshot } = {}) {
  await panel(page);
  if (grant) await page.click('#serial-choose');
  await page.locator('#serial-port option', { hasText: 'USB 0403:6015' }).waitFor({ state: 'attached' });
  await page.selectOption('#serial-baud', String(baud));
  if (screenshot) await shot(page, screenshot);
  await page.click('#serial-connect');
  await page.locator('#conn-port', { hasText: 'WebSerial' }).waitFor();
  await page.locator('#conn-state.ok').waitFor();
  await page.locator('#serial-panel').waitFor({ state: 'hidden' });
  if (reset) {
    await page.locator('#traffic-table tbody tr', { hasText: 'BIO_ResetIndication' }).first().waitFor();
  }
}

/** Bytes the console wrote to the port, and RTS changes, in order. */
function wireLog(wire) {
  return wire.clients.flatMap((c) => c.log);
}

/** Pings and expects the PingConfirm (failing with what came instead). */
async function ping(page) {
  await tab(page, 'diagnostics');
  await page.click('#ping-send');
  const result = page.locator('#ping-result');
  await page
    .locator('#ping-result.problem, #ping-result:has-text("PingConfirm")')
    .waitFor({ timeout: 10_000 });
  assert.match(await result.textContent(), /^PingConfirm/);
}

test('WebSerial: grant the scripted port, connect at 57600, RTS drives T_REQ, ping', async (t) => {
  const { page, wire } = await open(t);
  await connectSerial(page, { baud: 57600, screenshot: 'webserial-panel' });
  assert.match(await page.textContent('#conn-port'), /USB 0403:6015 \(WebSerial\)/);
  assert.equal(await page.inputValue('#baud'), '57600');
  // Opened 8N1 at 57600, no flow control; T_REQ released (RTS off) at once.
  assert.deepEqual(wire.opens, [
    { baudRate: 57600, dataBits: 8, stopBits: 1, parity: 'none', flowControl: 'none' },
  ]);
  const early = wireLog(wire);
  assert.deepEqual(early[0], { at: early[0].at, rts: false }, 'T_REQ released first');
  assert.equal(wire.current.baud, 57600, 'the simulator runs at 57600 baud (SET-BAUDRATE)');
  await shot(page, 'webserial-connected');

  await tab(page, 'diagnostics');
  await page.fill('#ping-payload', '01 02 03 04 05 ff');
  await page.click('#ping-send');
  const result = page.locator('#ping-result');
  await result.filter({ hasText: 'PingConfirm' }).waitFor();
  assert.match(
    await result.textContent(),
    /^PingConfirm in \d+\.\d ms \(payload echoed intact\): 01 02 03 04 05 ff$/,
  );

  // The request went out as the ST7580 wants it (UM0932 3.2.8): RTS on
  // (T_REQ low), then the STX, RTS off (T_REQ released), the rest; the
  // 0xFF of the payload crossed the Telnet stream doubled and came back.
  const log = wireLog(wire);
  const on = log.findIndex(
    (e, i) =>
      e.rts === true &&
      String(log[i + 1]?.write) === '2' &&
      log[i + 2]?.rts === false &&
      log[i + 3]?.write?.[1] === 0x2c,
  );
  assert.ok(on >= 0, `RTS on, STX, RTS off, PingRequest in ${JSON.stringify(log.map(({ at, ...e }) => e))}`);
  assert.deepEqual(log[on + 3].write.slice(0, 8), [0x06, 0x2c, 0x01, 0x02, 0x03, 0x04, 0x05, 0xff], 'length, PingRequest, payload');

  await tab(page, 'traffic');
  const seen = await titles(page);
  for (const want of ['BIO_ResetIndication', 'PingRequest', 'PingConfirm']) {
    assert.ok(seen.includes(want), `${want} in ${seen.join(', ')}`);
  }
  await shot(page, 'webserial-traffic');
});

test('WebSerial: read, change, write and read back the PHY configuration', async (t) => {
  const { page } = await open(t);
  await connectSerial(page);
  await phyRoundTrip(page, 'webserial-modem');
});

test('WebSerial: a DL frame to the echoing peer comes back as a DL_DataIndication', async (t) => {
  const { page } = await open(t, { nodes: 2 });
  await connectSerial(page);
  await tab(page, 'data');
  await page.selectOption('#data-layer', 'dl');
  await page.selectOption('#data-payload-kind', 'text');
  await page.fill('#data-payload', 'lamp 7 on');
  await page.click('#data-send');
  await page.locator('#data-result', { hasText: 'DL_DataConfirm' }).waitFor({ timeout: 15_000 });
  // "lamp 7 on" in hex.
  const row = page.locator('#indications-table tbody tr', { hasText: 'DL_DataIndication' }).first();
  await row.waitFor({ timeout: 15_000 });
  assert.match(await row.textContent(), /6c 61 6d 70 20 37 20 6f 6e/);
  await shot(page, 'webserial-data');
});

test('WebSerial: an out-of-range frequency is refused in the form and nothing is sent', async (t) => {
  const { page, wire } = await open(t);
  await connectSerial(page);
  await tab(page, 'modem');
  // Let the link settle (the reset indication's ACK), then count.
  await page.waitForTimeout(200);
  const sent = wireLog(wire).length;
  await refusedFrequency(page, 'webserial-modem-refused');
  assert.deepEqual(wireLog(wire).slice(sent), [], 'not a byte, not an RTS change on the port');
});

test('WebSerial: unplugged mid-command, the console says so, nothing is stuck, and it reconnects', async (t) => {
  const { page, wire } = await open(t);
  await connectSerial(page);
  await tab(page, 'diagnostics');
  // The request is handed to the link (T_REQ about to be asserted) and the
  // adapter is pulled out in the same moment.
  await page.evaluate(() => {
    document.querySelector('#ping-send').click();
    window.__plmSerialShim.unplug();
  });
  const result = page.locator('#ping-result.problem');
  await result.waitFor({ timeout: 5_000 });
  assert.doesNotMatch(await result.textContent(), /PingConfirm/);
  await page.locator('#conn-state:not(.ok)').waitFor();
  assert.match(await page.getAttribute('#conn-state', 'title'), /the serial port was unplugged/);
  await page.locator('.toast', { hasText: 'the serial port was unplugged' }).waitFor();
  await shot(page, 'webserial-unplugged');
  // Nothing stuck: a new request fails at once, in words.
  await page.click('#ping-send');
  await page.locator('#ping-result.problem', { hasText: /not connected|unplugged/ }).waitFor();
  // The port was released: the streams unlocked and the port closed.
  assert.deepEqual(await page.evaluate(() => window.__plmSerialShim.state()), { open: false, plugged: false, rts: false, dtr: false });
  await panel(page);
  assert.equal(await page.locator('#serial-port option', { hasText: 'USB 0403:6015' }).count(), 0, 'an unplugged port is not offered');

  // Plugged back in: offered again (remembered, no new grant), and it works.
  await page.evaluate(() => window.__plmSerialShim.replug());
  await connectSerial(page, { grant: false, reset: false });
  assert.equal(wire.clients.length, 2);
  await ping(page);
});

test('WebSerial: the granted port and settings are remembered across a reload; back to the simulator closes it', async (t) => {
  const { page, wire } = await open(t);
  await connectSerial(page, { baud: 38400 });
  assert.equal(wire.current.baud, 38400);
  await ping(page);
  await page.reload();
  await page.locator('#conn-state.ok').waitFor();
  assert.match(await page.textContent('#conn-port'), /simulated/, 'a reload starts on the simulated modem');
  await panel(page);
  // Remembered: the port (no new grant) and the baud rate.
  await page.locator('#serial-port option', { hasText: 'USB 0403:6015' }).waitFor({ state: 'attached' });
  assert.equal(await page.inputValue('#serial-baud'), '38400');
  assert.equal(await page.inputValue('#serial-polarity'), 'low');
  await page.click('#serial-connect');
  await page.locator('#conn-port', { hasText: 'WebSerial' }).waitFor();
  await ping(page);
  await panel(page);
  await page.click('#serial-use-sim');
  await page.locator('#conn-port', { hasText: 'simulated' }).waitFor();
  await page.waitForFunction(() => !window.__plmSerialShim.state().open);
  assert.equal(wire.current, null, 'the RFC 2217 connection was closed');
  await ping(page);
});

test('WebSerial: with RESETN wired to DTR (kept per port), Reset modem pulses DTR and the reset indication shows in Traffic', async (t) => {
  const { page, wire } = await open(t);
  await connectSerial(page);
  // Counted on the Traffic tab: a hidden table is not kept up to date.
  const resets = page.locator('#traffic-table tbody tr', { hasText: 'BIO_ResetIndication' });
  const before = await resets.count();
  await tab(page, 'diagnostics');
  assert.ok(await page.isHidden('#reset-resetn'), 'no hardware reset until the wiring is set');
  assert.ok(!wireLog(wire).some((e) => 'dtr' in e), 'DTR untouched while the setting is off');
  await page.check('#resetn-on-dtr');
  // Wired: DTR is released at once (operating systems assert it on open).
  await page.waitForFunction(() => window.__plmSerialShim.log.some((e) => e.dtr === false));
  await page.click('#reset-resetn');
  await page.locator('#reset-result', { hasText: 'RESETN pulsed' }).waitFor();
  await tab(page, 'traffic');
  await page.waitForFunction(
    (n) => [...document.querySelectorAll('#traffic-table tbody tr')].filter((tr) => tr.textContent.includes('BIO_ResetIndication')).length > n,
    before,
    { timeout: 10_000 },
  );
  const dtr = wireLog(wire).filter((e) => 'dtr' in e);
  assert.deepEqual(dtr.map((e) => e.dtr), [false, true, false], 'released, then asserted and released');
  assert.ok(dtr[2].at - dtr[1].at >= 10, `RESETN held low ${dtr[2].at - dtr[1].at} ms`);
  await tab(page, 'diagnostics');
  // The reset cause the modem gives: RESETN or power-on (UM0932 Table 19).
  await page.locator('#reset-cause', { hasText: 'RESETN' }).waitFor();
  await shot(page, 'webserial-resetn');
  await tab(page, 'traffic');
  await shot(page, 'webserial-resetn-traffic');

  // Kept for this port, not for the simulated modem.
  await page.reload();
  await page.locator('#conn-state.ok').waitFor();
  await tab(page, 'diagnostics');
  assert.ok(!(await page.isChecked('#resetn-on-dtr')), 'the simulated modem has its own setting');
  await connectSerial(page, { grant: false, reset: false });
  await tab(page, 'diagnostics');
  await page.locator('#resetn-on-dtr:checked').waitFor();
  assert.ok(await page.isVisible('#reset-resetn'));
});

test('WebSerial: an adapter that sets RTS one call late (Windows usbser) is told apart, and sending RTS twice fixes it', async (t) => {
  const { page, wire } = await open(t);
  await page.evaluate(() => {
    window.__plmSerialQuirks = { rtsLate: true };
  });
  await connectSerial(page);
  await tab(page, 'diagnostics');
  await page.click('#ping-send');
  // T_REQ moves one call late, so the modem answers when the host lets
  // go: the request fails or loses attempts; the second such request in a
  // row is told.
  await page.locator('#ping-result.problem, #ping-result:has-text("PingConfirm")').waitFor({ timeout: 15_000 });
  await page.click('#ping-send');
  const advice = page.locator('#link-problem', { hasText: 'Send each RTS change twice' });
  await advice.waitFor({ timeout: 10_000 });
  assert.match(await advice.textContent(), /Two requests in a row got no status message after T_REQ/);
  await shot(page, 'webserial-rts-late');
  await panel(page);
  await page.check('#serial-rts-twice');
  await page.click('#serial-connect');
  await page.locator('#serial-panel').waitFor({ state: 'hidden' });
  await ping(page);
  // Remembered.
  await panel(page);
  assert.ok(await page.isChecked('#serial-rts-twice'));
});

test('WebSerial: a new baud rate in the connection bar reopens the port at that rate', async (t) => {
  const { page, wire } = await open(t);
  await connectSerial(page, { baud: 57600 });
  await ping(page);
  await page.selectOption('#baud', '19200');
  // Web Serial fixes the rate at open(): the port is closed and opened
  // again, which here is a new RFC 2217 connection at 19200 baud.
  await page.waitForFunction(() => window.__plmSerialShim.log.filter((e) => e.open).length === 2);
  assert.deepEqual(
    wire.opens.map((o) => o.baudRate),
    [57600, 19200],
  );
  assert.equal(wire.current.baud, 19200, 'the simulated modem runs at 19200 baud');
  assert.match(await page.textContent('#conn-port'), /WebSerial/);
  await ping(page);
});

test('WebSerial: the traffic log exports to JSON Lines and imports again', async (t) => {
  const { page } = await open(t);
  await connectSerial(page);
  await ping(page);
  const entries = await exportImport(page, 'webserial-traffic.jsonl');
  assert.ok(entries.some((e) => e.command === 'PingConfirm' && e.from === 'modem'));
});

test('WebSerial: an ST7570 on the port (plm sim --chip st7570) is made a MAC Client, a Server answers its frame, alarms go both ways, and a wrong f0 is refused', async (t) => {
  // --alarms 2: the Servers raise an alarm in turn every 2 s.
  const { page, wire } = await open(t, { world: ['--chip', 'st7570', '--nodes', '4', '--alarms', '2'], profile: 'st7570' });
  // The ST7570 sends no frame at power-on (its status message says RESET).
  await connectSerial(page, { reset: false });
  assert.match(await page.textContent('#conn-chip'), /ST7570/);
  await macClient(page);
  await macAsk(page);
  await tab(page, 'network');
  await page.locator('#net-status', { hasText: 'Client' }).waitFor();
  await page.locator('#net-nodes-table tr[data-key="001h"]').waitFor();
  // No simulated line in the page: a real network shows what the modem hears.
  assert.equal(await page.locator('#net-sim').isVisible(), false);
  // A Server's alarm comes in; the Client's own goes out.
  await page.locator('#net-alarm-history', { hasText: 'alarm received' }).waitFor({ timeout: 20_000 });
  await sendAlarm(page);
  assert.ok(wireLog(wire).some((e) => e.rts === true), 'T_REQ driven by RTS');
  await shot(page, 'webserial-st7570-network');
  await refusedFrequency(page, 'webserial-st7570-refused', ST7570_F);
});

test('a browser without WebSerial is told so plainly, and the simulated modem still works', async (t) => {
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  await context.addInitScript(() => {
    delete Navigator.prototype.serial;
  });
  const page = await watchedPage(t, context);
  await page.goto(base + '?profile=st7580');
  await page.locator('#conn-state.ok').waitFor({ timeout: 15_000 });
  assert.equal(await page.textContent('#serial-toggle'), 'WebSerial: not in this browser');
  await panel(page);
  assert.match(await page.textContent('#serial-unavailable'), /This browser has no WebSerial .* The simulated modem works here\./);
  assert.equal(await page.locator('#serial-connect').count(), 0);
  await shot(page, 'webserial-unavailable');
  await page.click('#serial-close');
  await ping(page);
});

test('WebSerial: a concentrator board on the port: its street is found, read and dimmed', async (t) => {
  const { page, wire } = await open(t, { world: ['--board', '--street', '6', '--seed', '5'], profile: 'board' });
  await connectSerial(page, { reset: false });
  assert.match(await page.textContent('#street-port'), /WebSerial/);
  // Discovery and the first sweep run over the real WebSerial transport.
  await everyLampRead(page, 6);
  const power = async () =>
    Number(await page.textContent('#fleet-table tr[data-address="0080e1000002"] td[data-key="power"]'));
  const before = await power();
  await page.click('#fleet-table tr[data-address="0080e1000002"]');
  await page.fill('#lamp-dim-level', '10');
  await page.click('#lamp-dim');
  await page.waitForFunction(
    (was) => Number(document.querySelector('#fleet-table tr[data-address="0080e1000002"] td[data-key="power"]')?.textContent) < was,
    before,
    { timeout: 30_000 },
  );
  // A board's USART has no T_REQ: RTS is never asserted.
  assert.equal(wire.clients.flatMap((c) => c.log).filter((e) => e.rts === true).length, 0);
  await shot(page, 'webserial-street');
});

test('WebSerial: a firmware update over a real street survives a pulled cable and resumes where it was', async (t) => {
  const { page, wire } = await open(t, { world: ['--board', '--street', '3', '--seed', '5'], profile: 'board' });
  await connectSerial(page, { reset: false });
  const lit = (n) => everyLampRead(page, n, { timeout: 90_000 });
  await lit(3);
  await tab(page, 'update');
  await page.fill('#update-make-release', '1.6');
  await page.fill('#update-make-size', '3000');
  await page.click('#update-make');
  await page.selectOption('#update-targets', 'all');
  await page.click('#update-start');
  await page.waitForFunction(() => Number(document.querySelector('#update-progress')?.value) > 150, null, {
    timeout: 60_000,
  });
  // The adapter is pulled out mid-update: the campaign stays in the
  // browser's storage; plugged back in, the view offers it again.
  await page.evaluate(() => window.__plmSerialShim.unplug());
  await page.locator('#conn-state:not(.ok)').waitFor();
  await page.evaluate(() => window.__plmSerialShim.replug());
  await connectSerial(page, { grant: false, reset: false });
  await tab(page, 'update');
  const banner = page.locator('#update-saved');
  await banner.waitFor();
  assert.match(await banner.textContent(), /release 1\.6 to 3 lamp\(s\), 3000-byte image/);
  await page.click('#update-resume');
  await page
    .locator('#update-summary', { hasText: 'to 3 lamp(s): 3 updated, 0 not updated · took' })
    .waitFor({ timeout: 120_000 });
  await shot(page, 'webserial-update');
  assert.equal(wire.clients.length, 2, 'one connection before the cable was pulled, one after');
  // The boards run it: read back from the street's own answers.
  await tab(page, 'street');
  for (let n = 1; n <= 3; n++) {
    await page.waitForFunction(
      (sel) => document.querySelector(sel)?.textContent === '1.6',
      `#fleet-table tr[data-address="0080e100000${n}"] td[data-key="firmware"]`,
      { timeout: 60_000 },
    );
  }
});
