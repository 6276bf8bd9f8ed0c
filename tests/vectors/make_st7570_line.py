#!/usr/bin/env python3
"""Writes st7570_line.jsonl: long MAC frames on the ST7570's power line
(IEC 61334-5-1; ST7570 UM 3.2, 4.4) with each form of FCS that
`plm decode --chip st7570 --line` names, and one it must flag.

The layout and both FCS forms are built here from their description in
docs/protocol-notes.md ("ST7570: MAC and PHY frames on the line"), not
from plm-core nor from any encoder's code:

  long MAC frame, 36*NS bytes:
    NS (2) | CREDIT (1) | ADDRESS (3) | PAD (1) | M_sdu | pad (PAD) | FCS (3)
  MAC subframe, 38 bytes: FI (2) | the next 36 bytes
  PHY frame, 45 bytes: AAAAh | 54C7h | subframe | pause (000000h) or alarm

  FCS, generator G = x^24 + 5D6DCBh, sent MSByte first:
  - catalogue (what this project sends): the remainder of M(x)*x^24 by G,
    M = CREDIT up to the last pad byte;
  - Gurux's register form: the remainder of M(x) itself by G, its 24 bits
    reversed; its C and C# writers take M up to the last pad byte (form
    "gurux"), its writer's length expression without the pad bytes
    ("gurux_without_pad"); with no pad bytes the two are one.

Line format: name, source, hex, expect: the members of the decoded
object to compare (kind, fi, windows, ns, fields, m_sdu, pad_bytes, fcs,
fcs_ok, fcs_form; null = absent), and for a flagged frame error_starts
and error_mentions (text the error must start with and contain).
Run: python3 tests/vectors/make_st7570_line.py > tests/vectors/st7570_line.jsonl
"""
import json

G = 1 << 24 | 0x5D6DCB
NS = [0x6C, 0x3A, 0x56, 0x71, 0x1D, 0x4B, 0x27]


def remainder(m):
    """m(x) mod G(x), bits of the whole number as coefficients."""
    while m.bit_length() > 24:
        m ^= G << (m.bit_length() - 25)
    return m


def catalogue_fcs(msg):
    return remainder(int.from_bytes(msg, "big") << 24)


def gurux_fcs(msg):
    r = remainder(int.from_bytes(msg, "big"))
    return int(f"{r:024b}"[::-1], 2)


# The catalogue form is the CRC-24 of the catalogues: its check value.
assert catalogue_fcs(b"123456789") == 0xB0C390
# And the seed's frame (UM 10.3) keeps the FCS the notes give it.
assert catalogue_fcs(bytes([0, 0xC0, 0, 1, 0]) + bytes(range(26))) == 0xFF3B89


def long_frame(credit, sa, da, m_sdu, form):
    """The long frame with its FCS in `form`."""
    ns = -(-(10 + len(m_sdu)) // 36)
    pad = ns * 36 - 10 - len(m_sdu)
    body = bytes([credit]) + ((sa << 12) | da).to_bytes(3, "big") + bytes([pad]) + m_sdu + bytes(pad)
    fcs = {"catalogue": lambda: catalogue_fcs(body),
           "gurux": lambda: gurux_fcs(body),
           "gurux_without_pad": lambda: gurux_fcs(body[:len(body) - pad])}[form]()
    return bytes([NS[ns - 1]] * 2) + body + fcs.to_bytes(3, "big")


def subframes(long, fi=0x0000):
    return b"".join(fi.to_bytes(2, "big") + long[i:i + 36] for i in range(0, len(long), 36))


def phy_frames(long, fi=0x0000):
    sub = subframes(long, fi)
    return b"".join(b"\xAA\xAA\x54\xC7" + sub[i:i + 38] + bytes(3) for i in range(0, len(sub), 38))


def header(credit, sa, da, pad):
    return {"ic": credit >> 5, "cc": credit >> 2 & 7, "dc": credit & 3, "sa": sa, "da": da, "pad": pad}


V = []


def v(name, source, data, expect):
    V.append({"name": name, "source": source, "hex": data.hex(), "expect": expect})


def frame_expect(long, credit, sa, da, m_sdu, form, kind="mac_frame"):
    ns = len(long) // 36
    pad = long[6]
    e = {"kind": kind, "ns": ns, "fields": header(credit, sa, da, pad), "m_sdu": m_sdu.hex(),
         "pad_bytes": bytes(pad).hex(), "fcs": int.from_bytes(long[-3:], "big"), "fcs_ok": True,
         "fcs_form": form, "error": None}
    if kind == "mac_frame":
        e["fi"] = None
    else:
        e["fi"] = 0
    if kind == "phy_frames":
        e["windows"] = ["pause"] * ns
    return e


SEED = bytes(range(26))          # UM 10.3: M_sdu 00h..19h, one subframe, no pad
LONG = bytes(range(0x28))        # 40 bytes: two subframes, 22 pad bytes

for form in ["catalogue", "gurux"]:
    f = long_frame(0x00, 0xC00, 0x001, SEED, form)
    v(f"UM 10.3's frame, FCS in the {form} form (no pad bytes)",
      "ST7570 UM 10.3.1; docs/protocol-notes.md", f, frame_expect(f, 0x00, 0xC00, 0x001, SEED, form))
assert long_frame(0x00, 0xC00, 0x001, SEED, "gurux") == long_frame(0x00, 0xC00, 0x001, SEED, "gurux_without_pad")

for form, who in [("catalogue", "as this project sends it"),
                  ("gurux", "as Gurux's C and C# writers send it (FCS over the pad bytes)"),
                  ("gurux_without_pad", "with Gurux's FCS over CREDIT..M_sdu (pad bytes left out)")]:
    f = long_frame(0x6C, 0xC00, 0xFFF, LONG, form)
    v(f"40-byte M_sdu broadcast, IC=CC=3, {who}", "ST7570 UM 4.4, 4.8.5; docs/protocol-notes.md", f,
      dict(frame_expect(f, 0x6C, 0xC00, 0xFFF, LONG, form), fields=dict(header(0x6C, 0xC00, 0xFFF, 22),
                                                                        da_group="BROADCAST")))

g = long_frame(0x6C, 0xC00, 0xFFF, LONG, "gurux")
v("the Gurux frame in its two subframes", "ST7570 UM 4.4; docs/protocol-notes.md", subframes(g),
  dict(frame_expect(g, 0x6C, 0xC00, 0xFFF, LONG, "gurux", "mac_subframes"),
       fields=dict(header(0x6C, 0xC00, 0xFFF, 22), da_group="BROADCAST")))
v("the Gurux frame in two PHY frames", "ST7570 UM 3.2, 4.4; docs/protocol-notes.md", phy_frames(g),
  dict(frame_expect(g, 0x6C, 0xC00, 0xFFF, LONG, "gurux", "phy_frames"),
       fields=dict(header(0x6C, 0xC00, 0xFFF, 22), da_group="BROADCAST")))

# One M_sdu bit flipped in the Gurux frame: its FCS is now no form's.
bad = bytearray(g)
bad[10] ^= 0x01
body = bytes(bad[2:-3])
forms = [catalogue_fcs(body), gurux_fcs(body), gurux_fcs(body[:-22])]
assert int.from_bytes(bad[-3:], "big") not in forms
v("the Gurux frame with one M_sdu bit flipped: no form explains its FCS", "docs/protocol-notes.md", bytes(bad),
  {"kind": "mac_frame", "ns": 2, "m_sdu": bytes(bad[7:47]).hex(), "fcs": int.from_bytes(bad[-3:], "big"),
   "fcs_ok": False, "fcs_form": None, "error_starts": "bad FCS",
   "error_mentions": [f"{x:06X}h" for x in [int.from_bytes(bad[-3:], "big")] + forms]})

for line in V:
    print(json.dumps(line, ensure_ascii=False))
