// A scripted navigator.serial for the browser end-to-end tests.
//
// Injected with Playwright's page.addInitScript before the page loads (so
// it is a plain script, not a module). It replaces navigator.serial with
// one that offers a single USB-UART adapter whose bytes and RTS line go,
// through bindings the test exposes (page.exposeBinding), to Node, where
// tests/e2e/rfc2217.mjs drives a real `plm sim` over RFC 2217. The
// console's WebSerial transport runs unchanged on top of it.
//
// What it keeps of the Web Serial API, because the transport depends on it:
// - requestPort() needs a user gesture (transient activation) and grants
//   the port; getPorts() lists granted ports that are plugged in; grants
//   survive a reload (localStorage), as the browser's permissions do.
// - open({baudRate, ...}) refuses an open port (InvalidStateError) and a
//   port that is gone (NetworkError); readable and writable are real
//   ReadableStream / WritableStream, null while closed.
// - close() refuses while a stream is locked (TypeError).
// - setSignals({requestToSend, dataTerminalReady}) needs an open port.
//   (Unlike most operating systems, open() leaves DTR and RTS released.)
// - Unplugging errors both streams with NetworkError, makes readable null,
//   and fires 'disconnect' at the port, seen on navigator.serial with the
//   port as its target (the Serial object is the port's parent).
//
// Bindings (Node side): __plmSerialOpen(id, options) -> true,
// __plmSerialWrite(id, bytes), __plmSerialSignals(id, {rts} or {dtr}),
// __plmSerialClose(id). Node delivers modem bytes with
// window.__plmSerialShim.receive(id, bytes). Tests unplug and plug with
// window.__plmSerialShim.unplug(id) / replug(id).
(() => {
  'use strict';
  const GRANTED = 'plm-e2e-shim.granted';
  /** The adapter on offer: an FTDI USB-UART, as on ST's evaluation boards. */
  const ADAPTERS = [{ id: 'ftdi-0', info: { usbVendorId: 0x0403, usbProductId: 0x6015 } }];

  const lost = () => new DOMException('The device has been lost.', 'NetworkError');
  const notOpen = () => new DOMException('The port is closed.', 'InvalidStateError');
  const granted = () => new Set(JSON.parse(localStorage.getItem(GRANTED) ?? '[]'));
  const grant = (id) => localStorage.setItem(GRANTED, JSON.stringify([...granted().add(id)]));

  /** What happened, for the tests to look at. */
  const log = [];
  const note = (id, what) => log.push({ at: performance.now(), id, ...what });

  /** An event fired at `port` as navigator.serial sees it. */
  function portEvent(type, port) {
    const ev = new Event(type, { bubbles: true });
    Object.defineProperty(ev, 'target', { get: () => port });
    return ev;
  }

  class FakeSerialPort extends EventTarget {
    constructor(id, info) {
      super();
      this._id = id;
      this._info = info;
      this._open = false;
      this._opening = false;
      this._plugged = true;
      this._rx = null;
      this._tx = null;
      this._early = [];
      this.readable = null;
      this.writable = null;
      this.onconnect = null;
      this.ondisconnect = null;
    }

    get connected() {
      return this._plugged;
    }

    getInfo() {
      return { ...this._info };
    }

    async open(options) {
      if (!this._plugged) throw lost();
      if (this._open || this._opening) throw new DOMException('The port is already open.', 'InvalidStateError');
      const baudRate = options?.baudRate;
      if (!Number.isInteger(baudRate) || baudRate <= 0) throw new TypeError('baudRate must be a positive integer');
      const settings = {
        baudRate,
        dataBits: options.dataBits ?? 8,
        stopBits: options.stopBits ?? 1,
        parity: options.parity ?? 'none',
        flowControl: options.flowControl ?? 'none',
      };
      this._opening = true;
      try {
        await window.__plmSerialOpen(this._id, settings);
      } finally {
        this._opening = false;
      }
      note(this._id, { open: settings });
      this._open = true;
      this._rts = false;
      this._dtr = false;
      this._asked = false;
      this.readable = new ReadableStream({
        start: (c) => {
          this._rx = c;
          for (const chunk of this._early.splice(0)) c.enqueue(chunk);
        },
        cancel: () => {
          this._rx = null;
        },
      });
      const port = this;
      this.writable = new WritableStream({
        start: (c) => {
          port._tx = c;
        },
        write(chunk) {
          if (!port._open || !port._plugged) throw lost();
          const bytes = Array.from(chunk instanceof Uint8Array ? chunk : new Uint8Array(chunk));
          note(port._id, { write: bytes });
          // In order with setSignals: bindings reach Node in call order.
          window.__plmSerialWrite(port._id, bytes).catch(() => {});
        },
      });
    }

    async setSignals(signals = {}) {
      if (!this._open) throw notOpen();
      if (!this._plugged) throw lost();
      if ('requestToSend' in signals) {
        // Windows' usbser driver applies the level of the call before
        // (window.__plmSerialQuirks.rtsLate, set by a test).
        const asked = Boolean(signals.requestToSend);
        const rts = window.__plmSerialQuirks?.rtsLate ? this._asked ?? false : asked;
        this._asked = asked;
        this._rts = rts;
        note(this._id, { rts });
        window.__plmSerialSignals(this._id, { rts }).catch(() => {});
      }
      if ('dataTerminalReady' in signals) {
        this._dtr = Boolean(signals.dataTerminalReady);
        note(this._id, { dtr: this._dtr });
        window.__plmSerialSignals(this._id, { dtr: this._dtr }).catch(() => {});
      }
    }

    async getSignals() {
      if (!this._open) throw notOpen();
      return { clearToSend: true, dataSetReady: true, dataCarrierDetect: false, ringIndicator: false };
    }

    async close() {
      if (!this._open) throw notOpen();
      if (this.readable?.locked || this.writable?.locked) {
        throw new TypeError('Cannot close a port while its readable or writable stream is locked.');
      }
      this._shut();
      note(this._id, { close: true });
      await window.__plmSerialClose(this._id);
    }

    async forget() {
      const g = granted();
      g.delete(this._id);
      localStorage.setItem(GRANTED, JSON.stringify([...g]));
    }

    _shut() {
      this._open = false;
      this._rx = null;
      this._tx = null;
      this._early = [];
      this.readable = null;
      this.writable = null;
    }

    _receive(bytes) {
      if (!this._open && !this._opening) return;
      const chunk = new Uint8Array(bytes);
      if (!this._rx) {
        // Bytes that came while open() was finishing.
        if (this._opening) this._early.push(chunk);
        return;
      }
      try {
        this._rx.enqueue(chunk);
      } catch {
        // The reader was cancelled: the bytes are lost, as on a real port.
      }
    }

    _unplug() {
      if (!this._plugged) return;
      this._plugged = false;
      note(this._id, { unplugged: true });
      if (this._open) {
        try {
          this._rx?.error(lost());
        } catch {}
        try {
          this._tx?.error(lost());
        } catch {}
        this._shut();
        window.__plmSerialClose(this._id).catch(() => {});
      }
      this.dispatchEvent(portEvent('disconnect', this));
      serial.dispatchEvent(portEvent('disconnect', this));
    }

    _replug() {
      if (this._plugged) return;
      this._plugged = true;
      note(this._id, { replugged: true });
      this.dispatchEvent(portEvent('connect', this));
      serial.dispatchEvent(portEvent('connect', this));
    }
  }

  const ports = new Map(ADAPTERS.map((a) => [a.id, new FakeSerialPort(a.id, a.info)]));

  class FakeSerial extends EventTarget {
    constructor() {
      super();
      this.onconnect = null;
      this.ondisconnect = null;
    }

    async requestPort(_options) {
      // The browser shows its chooser only in answer to a click or a key.
      if (!navigator.userActivation?.isActive) {
        throw new DOMException('Must be handling a user gesture to show a permission request.', 'SecurityError');
      }
      const port = [...ports.values()].find((p) => p._plugged);
      if (!port) throw new DOMException('No port selected by the user.', 'NotFoundError');
      grant(port._id);
      note(port._id, { granted: true });
      return port;
    }

    async getPorts() {
      const g = granted();
      return [...ports.values()].filter((p) => g.has(p._id) && p._plugged);
    }
  }

  const serial = new FakeSerial();
  Object.defineProperty(Navigator.prototype, 'serial', {
    configurable: true,
    enumerable: true,
    get: () => serial,
  });

  window.__plmSerialShim = {
    log,
    ports: () => [...ports.keys()],
    receive(id, bytes) {
      ports.get(id)?._receive(bytes);
    },
    unplug(id = ADAPTERS[0].id) {
      ports.get(id)?._unplug();
    },
    replug(id = ADAPTERS[0].id) {
      ports.get(id)?._replug();
    },
    state(id = ADAPTERS[0].id) {
      const p = ports.get(id);
      return { open: p._open, plugged: p._plugged, rts: p._rts ?? false, dtr: p._dtr ?? false };
    },
  };
})();
