#!/usr/bin/env python3
"""Writes steval_app.jsonl: golden vectors of the STEVAL-IHP007V1 street-light
board's application frames (seed 004: UM 4.6, Appendix A, Appendix C).

Every frame is written here by hand from the seed's buffer[] listings,
independently of plm-core: buffer[0] is the length the seed states, the
CRC-16 is computed bitwise from the polynomial X^16+X^15+X^2+1 (reflected:
A001h, init 0, as the seed's CalcCRC16 shifts right) and appended high
byte first. `expect` is what `plm decode --board` must show for the frame,
written from the seed's names. crates/plm-core/tests/app_golden.rs reads
the vectors, checks the CRC again with its own bitwise code, and checks
the typed message each one is.

Run: python3 tests/vectors/make_steval.py > tests/vectors/steval_app.jsonl
"""
import json

# 4.5 APP_fstype_t
APP_DATA_FRAME, APP_SERVICE_FRAME, APP_PING_FRAME, APP_ERROR_FRAME = 0, 1, 2, 3
APP_ACK_FRAME = 5
BROADCAST_FLAG = 0x80
FRAME_TYPE = ["APP_DATA_FRAME", "APP_SERVICE_FRAME", "APP_PING_FRAME", "APP_ERROR_FRAME",
              "APP_PROGRAMMING_FRAME", "APP_ACK_FRAME", "APP_MIB_FRAME"]
# 4.5 APP_SER_CMD_t
SERVICE = {
    0x00: "SERVICE_SOFTWARE_RESET", 0x01: "SERVICE_HARDWARE_RESET", 0x02: "SERVICE_PARAM_SET",
    0x03: "SERVICE_PARAM_GET", 0x04: "SERVICE_INPUTS_GET", 0x05: "SERVICE_OUTPUTS_SET",
    0x06: "SERVICE_FW_REL_GET", 0x07: "SERVICE_PLM_CLOCK_SET", 0x08: "SERVICE_PLM_CLOCK_GET",
    0x09: "SERVICE_IO_CONFIG_SET", 0x0A: "SERVICE_IO_CONFIG_GET", 0x0B: "SERVICE_NET_DISCOVER_REQ",
    0x0F: "SERVICE_SN_SET", 0x10: "SERVICE_SN_GET",
    0x0C: "SERVICE_RFU_SET_IMG_HEADER", 0x0D: "SERVICE_RFU_SET_IMG_DATA",
    0x0E: "SERVICE_RFU_SWAP_IMG",
    # User-defined (4.5: "0x0b to 0x7f"), this project's (protocol notes).
    0x11: "RFU_STATUS_GET", 0x12: "RFU_ABORT", 0x13: "SERVICE_READ_IN_SLOTS",
}
PROG_GRP_USER_DATA = 0x02

# The board the frames are for (or from): any 6 bytes.
ADDR = [0x00, 0x80, 0xE1, 0x00, 0x00, 0x2A]
ADDR_HEX = "0080e100002a"


def crc16(data):
    """Appendix C: X^16+X^15+X^2+1, bit by bit, LSB first (A001h), init 0."""
    crc = 0
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


assert crc16(b"123456789") == 0xBB3D

V = []


def v(name, source, stated_len, body, expect):
    """body: buffer[0] up to the byte before the CRC, as the seed lists it."""
    assert body[0] == stated_len, name
    assert len(body) + 2 == stated_len, f"{name}: {len(body) + 2} bytes, seed says {stated_len}"
    crc = crc16(bytes(body))
    frame = bytes(body) + bytes([crc >> 8, crc & 0xFF])
    e = dict(kind="frame", length=stated_len, address=ADDR_HEX, crc=crc, crc_ok=True,
             hex=frame.hex())
    e.update(expect)
    V.append({"name": name, "source": source, "length": stated_len,
              "broadcast": bool(body[1] & BROADCAST_FLAG), "hex": frame.hex(), "expect": e})


def svc(code, direction, fields, broadcast=False):
    return dict(frame_type="APP_SERVICE_FRAME", code=APP_SERVICE_FRAME, broadcast=broadcast,
                command=SERVICE[code], direction=direction, fields=fields)


def ack(acked, echo):
    return dict(frame_type="APP_ACK_FRAME", code=APP_ACK_FRAME, broadcast=False,
                command="APP_ACK_FRAME", direction="reply",
                fields={"frame_type": FRAME_TYPE[acked], "command_echo": echo})


S = "STEVAL-IHP007V1 UM 4.6.4 "

# 4.6.4 PLM reset: software, hardware ("Any response from PLM module": none).
for code in (0x00, 0x01):
    v(f"{SERVICE[code]} request", S + "PLM reset", 11,
      [11, APP_SERVICE_FRAME, *ADDR, code], svc(code, "request", {}))

# 4.6.4 Set module parameters: buffer[0] = 44, sent with BROADCAST_FLAG.
USER_DATA = list(range(0x20, 0x40))  # 32 bytes, buffer[10 -> 41]
v("SERVICE_PARAM_SET request", S + "Set module parameters", 44,
  [44, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x02, PROG_GRP_USER_DATA, *USER_DATA],
  svc(0x02, "request", {"group": "PROG_GRP_USER_DATA", "parameters": bytes(USER_DATA).hex()},
      broadcast=True))
v("SERVICE_PARAM_SET ACK", S + "Set module parameters", 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x02], ack(APP_SERVICE_FRAME, 0x02))

# 4.6.4 Get module parameters.
PARAMS = [0xA0 ^ i for i in range(32)]
v("SERVICE_PARAM_GET request", S + "Get module parameters", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x03, PROG_GRP_USER_DATA],
  svc(0x03, "request", {"group": "PROG_GRP_USER_DATA"}))
v("SERVICE_PARAM_GET reply", S + "Get module parameters", 44,
  [44, APP_SERVICE_FRAME, *ADDR, 0x03, PROG_GRP_USER_DATA, *PARAMS],
  svc(0x03, "reply", {"group": "PROG_GRP_USER_DATA", "parameters": bytes(PARAMS).hex()}))

# 4.6.4 Get / set general purpose inputs/outputs configuration.
v("SERVICE_IO_CONFIG_GET request", S + "Get module general purpose inputs/outputs configuration", 11,
  [11, APP_SERVICE_FRAME, *ADDR, 0x0A], svc(0x0A, "request", {}))
v("SERVICE_IO_CONFIG_GET reply", S + "Get module general purpose inputs/outputs configuration", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x0A, 0x0F], svc(0x0A, "reply", {"io_configuration": 0x0F}))
v("SERVICE_IO_CONFIG_SET request", S + "Set module general purpose inputs/outputs configuration", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x09, 0xF0], svc(0x09, "request", {"io_configuration": 0xF0}))
v("SERVICE_IO_CONFIG_SET ACK", S + "Set module general purpose inputs/outputs configuration", 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x09], ack(APP_SERVICE_FRAME, 0x09))

# 4.6.4 Get module general purpose inputs value / set outputs value.
v("SERVICE_INPUTS_GET request", S + "Get module general purpose inputs value", 11,
  [11, APP_SERVICE_FRAME, *ADDR, 0x04], svc(0x04, "request", {}))
v("SERVICE_INPUTS_GET reply", S + "Get module general purpose inputs value", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x04, 0xA5], svc(0x04, "reply", {"inputs": 0xA5}))
v("SERVICE_OUTPUTS_SET request", S + "Set module general purpose outputs value", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x05, 0x3C], svc(0x05, "request", {"outputs": 0x3C}))
v("SERVICE_OUTPUTS_SET ACK", S + "Set module general purpose outputs value", 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x05], ack(APP_SERVICE_FRAME, 0x05))

# 4.6.4 Get module firmware release: buffer[0] = 15.
v("SERVICE_FW_REL_GET request", S + "Get module firmware release", 11,
  [11, APP_SERVICE_FRAME, *ADDR, 0x06], svc(0x06, "request", {}))
v("SERVICE_FW_REL_GET reply", S + "Get module firmware release", 15,
  [15, APP_SERVICE_FRAME, *ADDR, 0x06, 1, 2, 3, 4],
  svc(0x06, "reply", {"firmware_major": 1, "firmware_minor": 2, "stack_major": 3, "stack_minor": 4}))

# 4.6.4 Get / set module time clock value (the set with BROADCAST_FLAG).
v("SERVICE_PLM_CLOCK_GET request", S + "Get module time clock value", 11,
  [11, APP_SERVICE_FRAME, *ADDR, 0x08], svc(0x08, "request", {}))
v("SERVICE_PLM_CLOCK_GET reply", S + "Get module time clock value", 14,
  [14, APP_SERVICE_FRAME, *ADDR, 0x08, 12, 34, 56],
  svc(0x08, "reply", {"hours": 12, "minutes": 34, "seconds": 56}))
v("SERVICE_PLM_CLOCK_SET request", S + "Set module time clock value", 14,
  [14, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x07, 23, 59, 58],
  svc(0x07, "request", {"hours": 23, "minutes": 59, "seconds": 58}, broadcast=True))
v("SERVICE_PLM_CLOCK_SET ACK", S + "Set module time clock value", 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x07], ack(APP_SERVICE_FRAME, 0x07))

# 4.6.4 GET / Set PLM Module SNR ratio (0 to 31).
v("SERVICE_SN_GET request", S + "GET PLM Module SNR ratio", 11,
  [11, APP_SERVICE_FRAME, *ADDR, 0x10], svc(0x10, "request", {}))
v("SERVICE_SN_GET reply", S + "GET PLM Module SNR ratio", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x10, 31], svc(0x10, "reply", {"snr": 31}))
v("SERVICE_SN_SET request", S + "Set PLM Module SNR ratio", 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x0F, 10], svc(0x0F, "request", {"snr": 10}))
v("SERVICE_SN_SET ACK", S + "Set PLM Module SNR ratio", 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x0F], ack(APP_SERVICE_FRAME, 0x0F))

# SERVICE_NET_DISCOVER_REQ (0Bh): the seed names it without a layout; this
# is the project's (docs/protocol-notes.md): request [session, window s],
# reply [firmware x.y, stack x.y, SNR of the request].
D = "project decision (docs/protocol-notes.md); seed 4.5 names 0Bh only"
v("SERVICE_NET_DISCOVER_REQ request", D, 13,
  [13, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x0B, 5, 10],
  svc(0x0B, "request", {"session": 5, "window": 10}, broadcast=True))
# Rule 2 (slotted frames): [2, session, frame, slots, slot ms, share,
# names of the boards heard]; and the request as the seed lists it, with no
# data. Names (docs/protocol-notes.md): [p, the p bytes every address
# starts with, the other 6 - p bytes of each].
LAMP1 = [0x00, 0x80, 0xE1, 0x00, 0x00, 0x01]
LAMP2 = [0x00, 0x80, 0xE1, 0x00, 0x00, 0x02]
NAMES = [5, *LAMP1[:5], LAMP1[5], LAMP2[5]]
v("SERVICE_NET_DISCOVER_REQ request, rule 2", D, 25,
  [25, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x0B, 2, 5, 0, 16, 33, 255, *NAMES],
  svc(0x0B, "request", {"rule": 2, "session": 5, "frame": 0, "slots": 16, "slot_ms": 33,
                        "share": 255, "shared": 5, "heard": bytes(NAMES[1:]).hex()},
      broadcast=True))
v("SERVICE_NET_DISCOVER_REQ request, bare", D, 11,
  [11, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x0B],
  svc(0x0B, "request", {}, broadcast=True))
v("SERVICE_NET_DISCOVER_REQ reply", D, 16,
  [16, APP_SERVICE_FRAME, *ADDR, 0x0B, 1, 2, 3, 4, 20],
  svc(0x0B, "reply", {"firmware_major": 1, "firmware_minor": 2, "stack_major": 3,
                      "stack_minor": 4, "snr": 20}))

# Remote firmware update (4.2): the seed names 0Ch-0Eh without layouts; these
# are the project's (docs/protocol-notes.md, "Remote firmware update"), with
# two user-defined commands. Numbers big-endian; CRC-32/ISO-HDLC (zlib's).
import zlib
R = "project decision (docs/protocol-notes.md); seed 4.2 and 4.5 name 0Ch-0Eh only"
IMAGE = bytes((i * 7 + 3) & 0xFF for i in range(200))  # 3 segments of 96 bytes
IMAGE_CRC = zlib.crc32(IMAGE)
assert zlib.crc32(b"123456789") == 0xCBF43926
CAMPAIGN = 7
be32 = lambda x: [(x >> 24) & 0xFF, (x >> 16) & 0xFF, (x >> 8) & 0xFF, x & 0xFF]
v("SERVICE_RFU_SET_IMG_HEADER request", R, 23,
  [23, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x0C, CAMPAIGN, *be32(len(IMAGE)), 1, 5,
   *be32(IMAGE_CRC), 96],
  svc(0x0C, "request", {"campaign": CAMPAIGN, "image_size": len(IMAGE), "version_major": 1,
                        "version_minor": 5, "image_crc32": IMAGE_CRC, "segment_size": 96},
      broadcast=True))
v("SERVICE_RFU_SET_IMG_HEADER ACK", R, 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x0C], ack(APP_SERVICE_FRAME, 0x0C))
SEG1 = list(IMAGE[96:192])
v("SERVICE_RFU_SET_IMG_DATA request (a full segment)", R, 110,
  [110, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x0D, CAMPAIGN, 0x00, 0x01, *SEG1],
  svc(0x0D, "request", {"campaign": CAMPAIGN, "segment": 1, "data": bytes(SEG1).hex()},
      broadcast=True))
SEG2 = list(IMAGE[192:])
v("SERVICE_RFU_SET_IMG_DATA request (the last, short segment)", R, 14 + len(SEG2),
  [14 + len(SEG2), APP_SERVICE_FRAME, *ADDR, 0x0D, CAMPAIGN, 0x00, 0x02, *SEG2],
  svc(0x0D, "request", {"campaign": CAMPAIGN, "segment": 2, "data": bytes(SEG2).hex()}))
v("RFU_STATUS_GET request", R, 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x11, CAMPAIGN], svc(0x11, "request", {"campaign": CAMPAIGN}))
BITMAP = [0b101] + [0] * 79  # segments 0 and 2 held, 1 missing
v("RFU_STATUS_GET reply", R, 96,
  [96, APP_SERVICE_FRAME, *ADDR, 0x11, CAMPAIGN, 1, 3, 0x00, 0x02, *BITMAP],
  svc(0x11, "reply", {"campaign": CAMPAIGN, "state": "RECEIVING", "reason": "SEGMENTS_MISSING",
                      "received": 2, "bitmap": bytes(BITMAP).hex()}))
v("SERVICE_RFU_SWAP_IMG request", R, 16,
  [16, APP_SERVICE_FRAME, *ADDR, 0x0E, CAMPAIGN, *be32(IMAGE_CRC)],
  svc(0x0E, "request", {"campaign": CAMPAIGN, "image_crc32": IMAGE_CRC}))
v("SERVICE_RFU_SWAP_IMG ACK", R, 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x0E], ack(APP_SERVICE_FRAME, 0x0E))
v("RFU_ABORT request", R, 12,
  [12, APP_SERVICE_FRAME, *ADDR, 0x12, CAMPAIGN], svc(0x12, "request", {"campaign": CAMPAIGN}))
v("RFU_ABORT ACK", R, 12,
  [12, APP_ACK_FRAME, *ADDR, APP_SERVICE_FRAME, 0x12], ack(APP_SERVICE_FRAME, 0x12))

# SERVICE_READ_IN_SLOTS (13h, user-defined): [slot ms, HID param, first
# slot ms, names of the boards]; the boards answer with HID replies.
v("SERVICE_READ_IN_SLOTS request", R, 22,
  [22, APP_SERVICE_FRAME | BROADCAST_FLAG, *ADDR, 0x13, 62, 0x0A, 20, *NAMES],
  svc(0x13, "request", {"slot_ms": 62, "param": 10, "first_ms": 20, "shared": 5,
                        "addresses": bytes(NAMES[1:]).hex()}, broadcast=True))

# 4.6.2 Ping frames and their ACK (the ping's command echo: 0, protocol notes).
P = "STEVAL-IHP007V1 UM 4.6.2 Ping frames"
v("APP_PING_FRAME", P, 10, [10, APP_PING_FRAME, *ADDR],
  dict(frame_type="APP_PING_FRAME", code=APP_PING_FRAME, command="APP_PING_FRAME",
       direction="request", fields={}))
v("APP_PING_FRAME ACK", P, 12, [12, APP_ACK_FRAME, *ADDR, APP_PING_FRAME, 0x00],
  ack(APP_PING_FRAME, 0))

# 4.6.3 Error frames (and Appendix A's HID error codes 10h-13h):
# user_error_code = buffer[8] << 8 | buffer[9].
ERRORS = {0x0004: "APP_ERROR_SERVICE_CMD_ERROR", 0x0006: "APP_ERROR_ISOLATED_NODE",
          0x000B: "APP_ERROR_RTC_ERROR", 0x000E: "APP_ERROR_RTC_DISABLED",
          0x0010: "HID response error", 0x0011: "HID command unknown",
          0x0012: "HID board response timeout", 0x0013: "HID packet delivery impossible"}
for code, name in ERRORS.items():
    src = "STEVAL-IHP007V1 UM Appendix A, ERROR FRAME RESPONSE" if code >= 0x10 else \
        "STEVAL-IHP007V1 UM 4.6.3 Error frames"
    v(f"APP_ERROR_FRAME {code:04x}", src, 12, [12, APP_ERROR_FRAME, *ADDR, code >> 8, code & 0xFF],
      dict(frame_type="APP_ERROR_FRAME", code=APP_ERROR_FRAME, command="APP_ERROR_FRAME",
           direction="reply", fields={"error_code": code, "error_name": name}))

# 4.6.1 Data frame: user data, at least 1 byte.
v("APP_DATA_FRAME user data", "STEVAL-IHP007V1 UM 4.6.1", 15,
  [15, APP_DATA_FRAME, *ADDR, *b"Hello"],
  dict(frame_type="APP_DATA_FRAME", code=APP_DATA_FRAME, command="APP_DATA_FRAME",
       fields={"data": b"Hello".hex()}))

A = "STEVAL-IHP007V1 UM Appendix A "
HID_ACK = dict(frame_type="APP_ACK_FRAME", code=APP_ACK_FRAME, command="APP_ACK_FRAME",
               direction="reply", fields={"frame_type": "APP_DATA_FRAME", "command_echo": 0x73})


def hid(command, direction, fields, broadcast=False):
    return dict(frame_type="APP_DATA_FRAME", code=APP_DATA_FRAME, broadcast=broadcast,
                command=command, direction=direction, fields=fields)


# Appendix A HID board reset: 's' 00h reset_type (AAh software, 0Ch hardware).
v("HID board reset software", A + "HID board reset", 13,
  [13, APP_DATA_FRAME, *ADDR, 0x73, 0x00, 0xAA],
  hid("HID board reset", "request", {"reset_type": "Software reset"}))
v("HID board reset hardware", A + "HID board reset", 13,
  [13, APP_DATA_FRAME, *ADDR, 0x73, 0x00, 0x0C],
  hid("HID board reset", "request", {"reset_type": "Hardware reset"}))
# The ACK of every 's' command: buffer[8] APP_DATA_FRAME, buffer[9] 's'.
v("HID set ACK", A + "HID board reset, Lamp dimming", 12,
  [12, APP_ACK_FRAME, *ADDR, APP_DATA_FRAME, 0x73], HID_ACK)
# Appendix A Lamp dimming: 's' 01h dimming_value, with BROADCAST_FLAG.
v("Lamp dimming broadcast", A + "Lamp dimming", 13,
  [13, APP_DATA_FRAME | BROADCAST_FLAG, *ADDR, 0x73, 0x01, 50],
  hid("Lamp dimming", "request", {"dimming_value": 50}, broadcast=True))
v("Lamp dimming", A + "Lamp dimming", 13,
  [13, APP_DATA_FRAME, *ADDR, 0x73, 0x01, 100],
  hid("Lamp dimming", "request", {"dimming_value": 100}))

# Appendix A Get HID parameter: 'g' param_to_get, and the replies "To the
# COMM interface (USART- source concentrator)": 'g' param value...
PARAM = ["HARDWARE VERSION", "BUS VOLTAGE", "LAMP VOLTAGE", "HARDWARE STATUS", "LAMP POWER",
         "LAST FAILURE", "POWER SUPPLY VOLTAGE", "BOARD TEMPERATURE", "N° OF POWER ON",
         "LAMP LIFETIME", "GET ALL PARAMETERS"]
for p, name in enumerate(PARAM):
    v(f"Get HID parameter {p:02x} request", A + "Get HID parameter", 12,
      [12, APP_DATA_FRAME, *ADDR, 0x67, p],
      hid("Get HID parameter", "request", {"param_to_get": name}))


def w(x):
    """A 16-bit value, high byte first (_h then _l)."""
    x &= 0xFFFF
    return [x >> 8, x & 0xFF]


# Where the seed's listings slip, the reading the rest of Appendix A supports:
# the "GET BUS VOLTAGE" reply is printed with the g2 (lamp voltage) bytes,
# so 01h here carries the bus voltage like every other parameter carries its
# own; the ballast-side "GET ALL PARAMETERS" prints buffer[15] twice (the
# second is buffer[16]); its reply to the concentrator (buffer[0] = 36) has
# no slip and is followed here.
TEMP = -5
REPLIES = [
    (0x00, 14, [0x01, 0x02], {"hardware_release_xx": 1, "hardware_release_yy": 2}),
    (0x01, 14, w(400), {"bus_voltage": 400}),
    (0x02, 14, w(100), {"lamp_voltage": 100}),
    (0x03, 14, w(0x0006), {"hardware_status": "RUN"}),
    (0x04, 14, w(150), {"lamp_power": 150}),
    (0x05, 18, w(0x0004) + w(390) + w(20),
     {"last_hardware_status": "WARMUP", "last_bus_voltage": 390, "last_lamp_voltage": 20}),
    (0x06, 14, w(230), {"power_supply_voltage": 230}),
    (0x07, 14, w(TEMP), {"board_temperature": TEMP}),
    (0x08, 14, w(12), {"power_on_count": 12}),
    (0x09, 14, w(3000), {"lamp_lifetime": 3000}),
    (0x0A, 36, [0x01, 0x02] + w(400) + w(100) + w(0x0006) + w(150) + w(0x0004) + w(390) + w(20)
     + w(230) + w(TEMP) + w(12) + w(3000),
     {"hardware_release_xx": 1, "hardware_release_yy": 2, "bus_voltage": 400, "lamp_voltage": 100,
      "hardware_status": "RUN", "lamp_power": 150, "last_hardware_status": "WARMUP",
      "last_bus_voltage": 390, "last_lamp_voltage": 20, "power_supply_voltage": 230,
      "board_temperature": TEMP, "power_on_count": 12, "lamp_lifetime": 3000}),
]
for p, stated, value, fields in REPLIES:
    f = {"param_to_get": PARAM[p]}
    f.update(fields)
    v(f"Get HID parameter {p:02x} reply", A + "Get HID parameter, " + PARAM[p], stated,
      [stated, APP_DATA_FRAME, *ADDR, 0x67, p, *value],
      hid("Get HID parameter", "reply", f))

for vec in V:
    print(json.dumps(vec, ensure_ascii=False))
