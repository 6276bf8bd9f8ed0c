// A small RFC 2217 (Telnet COM-PORT-OPTION) client for the browser tests:
// it drives `plm sim` the way a serial port driver would, so that the
// scripted navigator.serial of serial-shim.mjs is backed by the simulated
// ST7580.
//
// - Telnet negotiation (RFC 854/855): BINARY (RFC 856) and
//   SUPPRESS-GO-AHEAD (RFC 858) both ways, COM-PORT-OPTION (RFC 2217).
// - SET-BAUDRATE, SET-DATASIZE, SET-PARITY, SET-STOPSIZE (8N1) and
//   SET-CONTROL DTR ON (8) / OFF (9) and RTS ON (11) / OFF (12); the server answers each with the
//   code + 100 and the value in effect.
// - Data: IAC doubled on the way out, undoubled on the way in; Telnet
//   commands and subnegotiations are taken out of the byte stream.
//
// Writes and RTS changes go to the socket in the order they are asked for:
// the ST7580 host releases T_REQ right after the STX of its frame.

import net from 'node:net';
import { EventEmitter } from 'node:events';

export const IAC = 255;
export const DONT = 254;
export const DO = 253;
export const WONT = 252;
export const WILL = 251;
export const SB = 250;
export const SE = 240;

export const BINARY = 0;
export const SGA = 3;
export const COM_PORT_OPTION = 44;

/** COM-PORT-OPTION client command codes (RFC 2217); the server's are +100. */
export const SET_BAUDRATE = 1;
export const SET_DATASIZE = 2;
export const SET_PARITY = 3;
export const SET_STOPSIZE = 4;
export const SET_CONTROL = 5;
export const SERVER_OFFSET = 100;

/** SET-CONTROL values. */
export const DTR_ON = 8;
export const DTR_OFF = 9;
export const RTS_ON = 11;
export const RTS_OFF = 12;
/** SET-PARITY NONE, SET-STOPSIZE 1. */
export const PARITY_NONE = 1;
export const STOPSIZE_1 = 1;

const SUPPORTED = new Set([BINARY, SGA, COM_PORT_OPTION]);

/** `bytes` with every IAC doubled (RFC 854). */
export function escape(bytes) {
  const out = [];
  for (const b of bytes) {
    out.push(b);
    if (b === IAC) out.push(IAC);
  }
  return Buffer.from(out);
}

/**
 * The Telnet decoder of the server-to-client direction: turns socket bytes
 * into events ({type: 'data', bytes}, {type: 'will'|'wont'|'do'|'dont',
 * option}, {type: 'sb', option, data}, {type: 'command', code}). Sequences
 * may be split across reads anywhere.
 */
export class Decoder {
  constructor() {
    this.state = 'data';
    this.data = [];
    this.sb = [];
    this.sbOption = 0;
    this.verb = 0;
  }

  feed(chunk) {
    const events = [];
    const flush = () => {
      if (this.data.length) {
        events.push({ type: 'data', bytes: Buffer.from(this.data) });
        this.data = [];
      }
    };
    const emit = (e) => {
      flush();
      events.push(e);
    };
    for (const b of chunk) {
      switch (this.state) {
        case 'data':
          if (b === IAC) this.state = 'iac';
          else this.data.push(b);
          break;
        case 'iac':
          this.state = this.command(b, emit);
          break;
        case 'verb': {
          const type = { [WILL]: 'will', [WONT]: 'wont', [DO]: 'do', [DONT]: 'dont' }[this.verb];
          emit({ type, option: b });
          this.state = 'data';
          break;
        }
        case 'sb-option':
          this.sbOption = b;
          this.sb = [];
          this.state = 'sb';
          break;
        case 'sb':
          if (b === IAC) this.state = 'sb-iac';
          else this.sb.push(b);
          break;
        case 'sb-iac':
          if (b === IAC) {
            // IAC IAC inside SB is a data 255 (RFC 855).
            this.sb.push(IAC);
            this.state = 'sb';
          } else {
            emit({ type: 'sb', option: this.sbOption, data: Buffer.from(this.sb) });
            this.state = b === SE ? 'data' : this.command(b, emit);
          }
          break;
      }
    }
    flush();
    return events;
  }

  /** The byte after IAC, outside SB; returns the next state. */
  command(b, emit) {
    switch (b) {
      case IAC:
        this.data.push(IAC);
        return 'data';
      case WILL:
      case WONT:
      case DO:
      case DONT:
        this.verb = b;
        return 'verb';
      case SB:
        return 'sb-option';
      case SE:
        return 'data';
      default:
        emit({ type: 'command', code: b });
        return 'data';
    }
  }
}

/** `IAC SB COM-PORT-OPTION code value... IAC SE`, value escaped. */
export function comPort(code, value = []) {
  return Buffer.concat([
    Buffer.from([IAC, SB, COM_PORT_OPTION, code]),
    escape(value),
    Buffer.from([IAC, SE]),
  ]);
}

/**
 * One connection to an RFC 2217 server. Emits 'data' (Buffer of serial
 * bytes) and 'close'. `log` records what went to the port, in order:
 * {at, write: [bytes]}, {at, rts: bool} and {at, dtr: bool}.
 */
export class Rfc2217Client extends EventEmitter {
  /** Connects to `host:port`, negotiates, and sets `baud` 8N1. */
  static async connect({ host = '127.0.0.1', port, baud, timeout = 5_000 }) {
    const socket = await new Promise((resolve, reject) => {
      const s = net.connect({ host, port }, () => resolve(s));
      s.once('error', reject);
    });
    socket.setNoDelay(true);
    const client = new Rfc2217Client(socket, timeout);
    // RFC 2217: the client offers COM-PORT-OPTION; both sides go binary.
    client.send(Buffer.from([IAC, WILL, COM_PORT_OPTION, IAC, WILL, BINARY, IAC, DO, BINARY]));
    client.us.add(COM_PORT_OPTION).add(BINARY);
    client.him.add(BINARY);
    await client.setBaud(baud);
    await client.request(SET_DATASIZE, [8]);
    await client.request(SET_PARITY, [PARITY_NONE]);
    await client.request(SET_STOPSIZE, [STOPSIZE_1]);
    return client;
  }

  constructor(socket, timeout) {
    super();
    this.socket = socket;
    this.timeout = timeout;
    this.decoder = new Decoder();
    /** Options we do, and options the server does (as agreed or asked). */
    this.us = new Set();
    this.him = new Set();
    /** Server replies waited for, by server code. */
    this.waiting = new Map();
    this.log = [];
    this.closed = false;
    this.baud = 0;
    this.rts = false;
    socket.on('data', (chunk) => this.receive(chunk));
    socket.on('error', () => {});
    socket.on('close', () => {
      this.closed = true;
      for (const [, w] of this.waiting) w.reject(new Error('the RFC 2217 server closed the connection'));
      this.waiting.clear();
      this.emit('close');
    });
  }

  send(buf) {
    if (!this.closed) this.socket.write(buf);
  }

  receive(chunk) {
    for (const e of this.decoder.feed(chunk)) {
      switch (e.type) {
        case 'data':
          this.emit('data', e.bytes);
          break;
        // Agree to what we support, refuse the rest; answer only changes,
        // so that no negotiation loop can start (RFC 854).
        case 'do':
          if (SUPPORTED.has(e.option)) {
            if (!this.us.has(e.option)) this.send(Buffer.from([IAC, WILL, e.option]));
            this.us.add(e.option);
          } else {
            this.send(Buffer.from([IAC, WONT, e.option]));
          }
          break;
        case 'will':
          if (SUPPORTED.has(e.option)) {
            if (!this.him.has(e.option)) this.send(Buffer.from([IAC, DO, e.option]));
            this.him.add(e.option);
          } else {
            this.send(Buffer.from([IAC, DONT, e.option]));
          }
          break;
        case 'dont':
          this.us.delete(e.option);
          break;
        case 'wont':
          this.him.delete(e.option);
          break;
        case 'sb':
          if (e.option === COM_PORT_OPTION && e.data.length > 0) {
            const code = e.data[0];
            const w = this.waiting.get(code);
            if (w) {
              this.waiting.delete(code);
              w.resolve(e.data.subarray(1));
            }
          }
          break;
        default:
          break;
      }
    }
  }

  /** Sends COM-PORT command `code` with `value` and waits for its answer. */
  request(code, value) {
    const answer = code + SERVER_OFFSET;
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => {
        this.waiting.delete(answer);
        reject(new Error(`no answer to COM-PORT-OPTION command ${code} within ${this.timeout} ms`));
      }, this.timeout);
      this.waiting.set(answer, {
        resolve: (v) => {
          clearTimeout(timer);
          resolve(v);
        },
        reject: (e) => {
          clearTimeout(timer);
          reject(e);
        },
      });
      this.send(comPort(code, value));
    });
  }

  /** SET-BAUDRATE; fails unless the server now runs at `baud`. */
  async setBaud(baud) {
    const v = Buffer.alloc(4);
    v.writeUInt32BE(baud);
    const now = (await this.request(SET_BAUDRATE, [...v])).readUInt32BE(0);
    if (now !== baud) throw new Error(`the server refused ${baud} baud (it runs at ${now})`);
    this.baud = now;
  }

  /** Serial bytes to the port, IAC doubled. */
  write(bytes) {
    this.log.push({ at: performance.now(), write: [...bytes] });
    this.send(escape(bytes));
  }

  /** SET-CONTROL RTS ON / OFF, in order with the data. */
  setDtr(on) {
    this.log.push({ at: performance.now(), dtr: on });
    this.send(comPort(SET_CONTROL, [on ? DTR_ON : DTR_OFF]));
  }

  setRts(on) {
    this.rts = on;
    this.log.push({ at: performance.now(), rts: on });
    this.send(comPort(SET_CONTROL, [on ? RTS_ON : RTS_OFF]));
  }

  close() {
    if (!this.closed) this.socket.end();
    this.closed = true;
  }
}
