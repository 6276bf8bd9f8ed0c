#!/usr/bin/env python3
"""Writes um0932.jsonl: golden vectors from UM0932 chapters 3-4.

Frames are built here independently of plm-core (UM0932 Table 6: checksum
= 16-bit sum from Length to the last data byte, sent LSByte first), and
every expectation is written from the manual's tables, cited per vector.
Run: python3 tests/vectors/make_um0932.py > tests/vectors/um0932.jsonl
"""
import json

def frame(code, data=b"", stx=2):
    body = bytes([len(data), code]) + bytes(data)
    s = sum(body) & 0xFFFF
    return bytes([stx]) + body + bytes([s & 0xFF, s >> 8])

def h(b):
    return b.hex()

V = []
def v(name, source, hexbytes, expect, frm=None):
    V.append({"name": name, "source": source, "from": frm, "hex": h(hexbytes), "expect": expect})

F = lambda **kw: dict(kind="frame", checksum_ok=True, **kw)

# 3.2.2 Table 6: checksum up to the command byte when there is no data.
v("ping without data", "UM0932 3.2.2 Table 6", bytes.fromhex("02002c2c00"),
  [F(stx=2, length=0, code=0x2C, command="PingRequest", checksum=0x2C, fields={"data": ""})], "host")
# Table 6: checksum LSByte first: 04 + 2D + 4*FF = 042Dh -> 2D 04.
v("checksum LSByte first", "UM0932 3.2.2 Table 6", frame(0x2D, b"\xff" * 4),
  [F(length=4, command="PingConfirm", checksum=0x042D, hex="02042dffffffff2d04", fields={"data": "ffffffff"})], "modem")
v("repeat with STX 03h", "UM0932 3.2.7", frame(0x2D, b"\x01", stx=3),
  [F(stx=3, command="PingConfirm")], "modem")
v("wrong checksum is reported, not dropped", "UM0932 3.2.6", bytes.fromhex("02002c2c01"),
  [dict(kind="frame", checksum_ok=False, command="PingRequest", checksum=0x012C)], "host")
# 3.2.3 Table 7.
v("ACK and NAK", "UM0932 3.2.3 Table 7", bytes([0x06, 0x15]), [dict(kind="ack"), dict(kind="nak")], "modem")
# 3.2.4 Table 8.
v("status: transmitting, DL layer", "UM0932 3.2.4 Table 8", bytes([0x3F, 0x0A]),
  [dict(kind="status", fields={"configuration_status": False, "transmission_status": True, "reception_status": False,
                                "active_layer": "DL layer", "overcurrent_flag": False,
                                "estimated_st7580_temperature": "T < 70 °C"})], "modem")
v("status: every bit set", "UM0932 3.2.4 Table 8", bytes([0x3F, 0xFF]),
  [dict(kind="status", fields={"configuration_status": True, "transmission_status": True, "reception_status": True,
                                "active_layer": "ST7580 not configured", "overcurrent_flag": True,
                                "estimated_st7580_temperature": "T > 125 °C"})], "modem")
v("host never sends a status message", "UM0932 3.2.4", bytes([0x3F, 0x0A]),
  [dict(kind="garbage", reason="unexpected")], "host")
# 3.3.1-3.3.3.
v("BIO_ResetRequest", "UM0932 3.3.1 Table 10", frame(0x3C), [F(command="BIO_ResetRequest", length=0, fields={})], "host")
v("BIO_ResetConfirm data is 00h", "UM0932 3.3.2", frame(0x3D, b"\x00"), [F(command="BIO_ResetConfirm", fields={"confirm_data": 0})], "modem")
v("BIO_ResetIndication after power-on with MIB at defaults", "UM0932 3.3.3 Table 19", frame(0x3E, b"\x3c"),
  [F(command="BIO_ResetIndication", fields={"reset_cause": "RESETN pin or Power-ON", "autoreconfiguration_error": True,
     "autoreconfiguration_modem_config_object_error": True, "autoreconfiguration_phy_config_object_error": True,
     "autoreconfiguration_ss_key_object_error": True})], "modem")
v("BIO_ResetIndication after BIO_ResetRequest", "UM0932 3.3.3 Table 19", frame(0x3E, b"\x02"),
  [F(command="BIO_ResetIndication", fields={"reset_cause": "BIO_ResetRequest", "autoreconfiguration_error": False})], "modem")
v("BIO_ResetIndication after watchdog", "UM0932 3.3.3 Table 19", frame(0x3E, b"\x01"),
  [F(command="BIO_ResetIndication", fields={"reset_cause": "Watchdog"})], "modem")
# Table 14 error causes, on every error command of Table 12.
causes = {0x02: "Wrong parameter length (WPL)", 0x03: "Wrong parameter value (WPV)", 0x04: "Busy",
          0x0B: "Thermal error", 0xFF: "General error"}
errors = {0x3F: "BIO_ResetError", 0x0B: "MIB_WriteError", 0x0F: "MIB_ReadError", 0x13: "MIB_EraseError",
          0x27: "PHY_DataError", 0x53: "DL_DataError", 0x57: "SS_DataError"}
for code, name in errors.items():
    for cause, cname in causes.items():
        v(f"{name} {cname}", "UM0932 Tables 12, 14", frame(code, bytes([cause])),
          [F(command=name, code=code, fields={"error_data": cname})], "modem")
v("CMD_SyntaxError names the wrong code", "UM0932 3.3.23 Table 51", frame(0x36, b"\x99"),
  [F(command="CMD_SyntaxError", fields={"error": 0x99})], "modem")
v("unknown command code", "UM0932 3.3.23", frame(0x99, b"\x01\x02"), [F(command=None, code=0x99, fields={"data": "0102"})], "host")
# Table 52 factory defaults, read back by MIB_ReadRequest/MIB_ReadConfirm.
defaults = {
    0x00: ("Modem configuration", "11", {"access_mode": "DL layer", "sniffer_mode": False,
           "crc_length": "4 byte (CRC-32), little endian", "dl_crc_on_phy_length": False}),
    0x01: ("PHY configuration", "014ff00119400e15000002359b58", {"high_frequency": 86000, "low_frequency": 72000,
           "rx_mode": "high channel only", "rx_high_channel_modulation": "PSK", "rx_low_channel_modulation": "PSK",
           "current_control": True, "tx_gain": 21, "zc_delay": 0, "psk_preamble_length": "32 bit",
           "fsk_bit_rate": "2400 bps", "fsk_deviation": "1", "fsk_preamble_length": "32 bit",
           "fsk_unique_word_length": "16 bit", "fsk_unique_word_msbyte": 0x9B, "fsk_unique_word_lsbyte": 0x58}),
    0x02: ("SS key", "00" * 16, {"ss_key": "00" * 16}),
    0x03: ("Reserved", "00", {"reserved": 0}),
    0x04: ("Last data indication", "00000000", {"frame_modulation": "B-PSK", "rx_channel": "low channel",
           "pga_value": 0, "snr": 0, "zc_delay": 0}),
    0x05: ("Last TX confirm", "0000000000", {"max_temp": "T < 70 °C", "max_gain": 0, "min_temp": "T < 70 °C",
           "min_gain": 0, "overcurrent_events_number": 0, "overcurrent_notification": False, "zc_delay": 0}),
    0x06: ("PHY_Data", "00" * 10, {"received_unique_word_counter": 0, "phy_valid_received_frames_counter": 0,
           "phy_transmitted_frames_counter": 0, "phy_refused_transmission_counter": 0, "network_period": 0}),
    0x07: ("DL_Data", "00" * 8, {"dl_valid_received_frames_counter": 0, "dl_invalid_received_frames_counter": 0,
           "dl_transmitted_frames_counter": 0, "dl_refused_transmission_counter": 0}),
    0x08: ("SS_Data", "00" * 10, {"ss_valid_received_frames_counter": 0, "ss_not_authentic_received_frames_counter": 0,
           "ss_malformed_received_frames": 0, "ss_transmitted_frames_counter": 0, "ss_refused_transmission_counter": 0}),
    0x09: ("Host interface timeout", "c8280a", {"t_sr": 200, "t_ack": 40, "t_ic": 10}),
    0x0A: ("Firmware version", "00420097", {"fw_version": "00420097"}),
}
for index, (name, value, fields) in defaults.items():
    req = frame(0x0C, bytes([index]))
    cnf = frame(0x0D, bytes.fromhex(value))
    v(f"MIB {index:02X}h factory default", "UM0932 Table 52, Tables 53-62", req + cnf,
      [F(command="MIB_ReadRequest", fields={"index": index, "object": name}),
       F(command="MIB_ReadConfirm", fields=dict({"index": index, "object": name, "data": value}, **fields))])
v("MIB_WriteRequest PHY configuration", "UM0932 3.3.4 Table 21, Table 54",
  frame(0x08, bytes.fromhex("01" "014ff0" "011940" "0e15000002359b58")),
  [F(command="MIB_WriteRequest", fields={"index": 1, "object": "PHY configuration", "high_frequency": 86000})], "host")
v("MIB_WriteRequest host interface timeout", "UM0932 Table 61", frame(0x08, bytes.fromhex("09 64 14 05")),
  [F(command="MIB_WriteRequest", fields={"object": "Host interface timeout", "t_sr": 100, "t_ack": 20, "t_ic": 5})], "host")
v("MIB_EraseRequest PHY_Data", "UM0932 3.3.8", frame(0x10, b"\x06"),
  [F(command="MIB_EraseRequest", fields={"index": 6, "object": "PHY_Data"})], "host")
v("MIB_WriteConfirm and MIB_EraseConfirm carry no data", "UM0932 3.3.5, 3.3.9", frame(0x09) + frame(0x11),
  [F(command="MIB_WriteConfirm", length=0), F(command="MIB_EraseConfirm", length=0)], "modem")
# Table 35: byte 0 bits; custom frequency (bytes 1-3) and gain (byte 4).
v("PHY_DataRequest, MIB frequency, B-PSK", "UM0932 3.3.12 Table 35", frame(0x24, bytes([0x00]) + b"hi"),
  [F(command="PHY_DataRequest", fields={"custom_mib_frequency": "MIB", "frequency_overwrite": False,
     "frequency_set": "LowFrequency", "gain_selector": "MIB", "frame_modulation": "B-PSK",
     "zero_crossing_synchronization": False, "payload": "6869"})], "host")
v("DL_DataRequest, custom frequency and gain, Q-PSK coded, ZC", "UM0932 3.3.15 Table 35",
  frame(0x50, bytes([0b1101_1011]) + bytes.fromhex("0124f8") + bytes([0x1F]) + b"\x01\x02"),
  [F(command="DL_DataRequest", fields={"custom_mib_frequency": "Custom", "frequency_overwrite": True,
     "frequency_set": "LowFrequency", "gain_selector": "Custom", "frame_modulation": "Q-PSK coded",
     "zero_crossing_synchronization": True, "tx_frequency": 75000, "tx_gain": 31, "payload": "0102"})], "host")
v("PHY_DataRequest gain only: gain in byte 1", "UM0932 3.3.12 Table 35", frame(0x24, bytes([0b0011_1100, 0x0A]) + b"\xaa"),
  [F(command="PHY_DataRequest", fields={"frequency_set": "HighFrequency", "gain_selector": "Custom",
     "frame_modulation": "B-FSK", "tx_gain": 10, "payload": "aa"})], "host")
v("SS_DataRequest header length after options", "UM0932 3.3.19 Table 45", frame(0x54, bytes([0x10, 0x04]) + bytes(range(8))),
  [F(command="SS_DataRequest", fields={"frame_modulation": "Q-PSK", "header_length": 4, "header_and_payload": "0001020304050607"})], "host")
# Table 37: confirm data.
v("PHY_DataConfirm", "UM0932 3.3.13 Table 37", frame(0x25, bytes([(21 << 2) | 1, (3 << 2) | 0, 0x80 | 5, 0xFF, 0xF6])),
  [F(command="PHY_DataConfirm", fields={"max_temp": "70 °C < T < 100 °C", "max_gain": 21, "min_temp": "T < 70 °C",
     "min_gain": 3, "overcurrent_events_number": 5, "overcurrent_notification": True, "zc_delay": -10})], "modem")
v("DL_DataConfirm and SS_DataConfirm share Table 37", "UM0932 3.3.16, 3.3.20",
  frame(0x51, bytes([0, 0, 0, 0, 7])) + frame(0x55, bytes([0, 0, 0, 1, 0])),
  [F(command="DL_DataConfirm", fields={"zc_delay": 7}), F(command="SS_DataConfirm", fields={"zc_delay": 256})], "modem")
# Table 39: indication data.
v("PHY_DataIndication 8-PSK high channel", "UM0932 3.3.14 Table 39", frame(0x26, bytes([0x7A, 0x0C, 0x00, 0x20]) + b"\x55"),
  [F(command="PHY_DataIndication", fields={"frame_modulation": "8-PSK", "rx_channel": "high channel", "pga_value": 7,
     "snr": 12, "zc_delay": 32, "phy_payload": "55"})], "modem")
v("DL_DataIndication FSK: SNR 255 has no meaning", "UM0932 3.3.17 Table 39", frame(0x52, bytes([0x03, 0xFF, 0x00, 0x00]) + b"\x01"),
  [F(command="DL_DataIndication", fields={"frame_modulation": "B-FSK", "snr": None, "dl_payload": "01"})], "modem")
v("DL_SnifferIndication keeps the wrong CRC", "UM0932 3.3.18", frame(0x5A, bytes([0x07, 0xFE, 0, 0]) + b"\x01\xde\xad"),
  [F(command="DL_SnifferIndication", fields={"frame_modulation": "B-PSK coded with Peak Noise Avoidance", "snr": -2,
     "dl_payload_and_wrong_crc": "01dead"})], "modem")
v("SS_DataIndication and SS_SnifferIndication", "UM0932 3.3.21 Table 48, 3.3.22",
  frame(0x56, bytes([0x04, 0x05, 0, 0]) + b"\x01") + frame(0x5E, bytes([0x05, 0x05, 0, 0]) + b"\x02"),
  [F(command="SS_DataIndication", fields={"frame_modulation": "B-PSK coded", "ss_header_and_payload": "01"}),
   F(command="SS_SnifferIndication", fields={"frame_modulation": "Q-PSK coded", "ss_sdu": "02"})], "modem")
# Tables 39 and 48: the SNR is signed, 255 "no meaning" for FSK frames only:
# after a PSK frame FFh is -1 dB; MIB 04h (4.2.4) holds the same 4 bytes.
v("SS_DataIndication Q-PSK: SNR FFh is -1 dB", "UM0932 3.3.21 Table 48", frame(0x56, bytes([0x01, 0xFF, 0, 0]) + b"\x01"),
  [F(command="SS_DataIndication", fields={"frame_modulation": "Q-PSK", "snr": -1, "ss_header_and_payload": "01"})], "modem")
v("MIB 04h after a B-PSK frame: SNR FFh is -1 dB", "UM0932 4.2.4 Table 39", frame(0x0C, b"\x04") + frame(0x0D, bytes([0x00, 0xFF, 0, 0])),
  [F(command="MIB_ReadRequest"), F(command="MIB_ReadConfirm", fields={"frame_modulation": "B-PSK", "snr": -1})])
# What the manual forbids is said in `warning`, the frame still decoded.
v("a confirm from the host is not the host's to send", "UM0932 3.3, Table 11", frame(0x2D, b"\x01"),
  [F(command="PingConfirm", fields={"data": "01"},
     warning="PingConfirm comes from the ST7580, never from the host (UM0932 Tables 11, 12, 15)")], "host")
v("a request from the modem is not the modem's to send", "UM0932 3.3, Table 10", frame(0x2C, b"\x01"),
  [F(command="PingRequest", fields={"data": "01"},
     warning="PingRequest is a request: only the host sends it (UM0932 Table 10)")], "modem")
v("BIO_ResetConfirm data other than 00h", "UM0932 3.3.2", frame(0x3D, b"\x01"),
  [F(command="BIO_ResetConfirm", fields={"confirm_data": 1},
     warning="BIO_ResetConfirm data is always 00h, not 01h (UM0932 3.3.2)")], "modem")
v("SS_DataRequest header length beyond the buffer", "UM0932 3.3.19 Table 45, Table 14", frame(0x54, bytes([0x00, 0x09]) + bytes(8)),
  [F(command="SS_DataRequest", fields={"header_length": 9},
     warning="the modem will refuse this request with Wrong parameter value (WPV): header length 9 is longer than the 8 bytes given")], "host")
v("PHY_DataRequest gain byte with unused bits set", "UM0932 3.3.12 Table 35", frame(0x24, bytes([0x08, 0x35]) + b"\xaa"),
  [F(command="PHY_DataRequest", fields={"tx_gain": 21, "unused": 1, "payload": "aa"},
     warning="the modem will refuse this request with Wrong parameter value (WPV): tx_gain: 53 is out of range: 0 to 31 (bits 5-7 of the TX gain byte are unused: 0)")], "host")
v("a frame hidden after a false start is found", "UM0932 3.2.6", bytes([0x02, 0xF0]) + frame(0x2C),
  [dict(kind="garbage"), F(command="PingRequest")], "host")

for x in V:
    print(json.dumps(x, ensure_ascii=False))
