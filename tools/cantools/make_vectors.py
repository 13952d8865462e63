#!/usr/bin/env python3
"""Make codec test vectors for dbc/agsteer.dbc with cantools (an independent DBC codec).

For every message: random in-range values, the extremes of every signal, the not-available
raw value of every signal that has one, and (decode only) raw codes across each signal's
sentinel region (not available, error, reserved), which must decode as absent. The sentinel
rule is restated here from its sources, independently of build.rs: NMEA 2000 (data page 1)
reserves the top 3 codes of a field of 8 bits or more, 2 of 4-7 bits, 1 of 2-3 bits (canboat,
analyzer/fieldtype.c); J1939 (data page 0) reserves 0xFB.. and up of an 8/16/32-bit unsigned
parameter (J1939-71) and the top 2 codes of other lengths; signed fields follow canboat; a code
the DBC's range or value table declares is a value. Unused bits are padded with 1
(cantools padding=True), as agsteer sends them. cantools knows nothing of agsteer's roles, so
this script fills the rolling counter and computes the CRC-8 SAE J1850 (poly 0x1D, init 0xFF,
xorout 0xFF) over every other byte itself.

    pip install cantools            # made with cantools 45.1.0
    python3 tools/cantools/make_vectors.py > tools/cantools/vectors.json
"""
import json
import os
import random
import sys

import cantools

HERE = os.path.dirname(os.path.abspath(__file__))
DBC = os.path.join(HERE, "..", "..", "dbc", "agsteer.dbc")


def crc8_j1850(data):
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


assert crc8_j1850(b"123456789") == 0x4B


def role(sig):
    a = sig.dbc.attributes.get("AgRole") if sig.dbc else None
    return {1: "counter", 2: "crc"}.get(a.value if a else 0, "value")


def top_code(sig):
    return (1 << (sig.length - 1)) - 1 if sig.is_signed else (1 << sig.length) - 1


def sentinel_first(msg, sig):
    """The first raw code of the signal's sentinel region, or None."""
    if role(sig) != "value":
        return None
    size, top = sig.length, top_code(sig)
    if (msg.frame_id >> 24) & 1 or sig.is_signed:
        count = 3 if size >= 8 else 2 if size >= 4 else 1 if size >= 2 else 0
        first = top - count + 1 if count else None
    elif size in (8, 16, 32):
        first = 0xFB << (size - 8)
    else:
        first = top - 1 if size >= 2 else None
    if first is None:
        return None
    declared = round((sig.maximum - sig.offset) / sig.scale)
    if sig.choices:
        declared = max(declared, max(int(k) for k in sig.choices))
    first = max(first, declared + 1)
    return first if first <= top else None


def not_available(msg, sig):
    return sentinel_first(msg, sig) is not None


def na_raw(sig):
    return top_code(sig)


def to_raw(sig, v):
    return round((v - sig.offset) / sig.scale)


def make(msg, phys, counter, na=(), raw_override=None):
    """Encode with cantools: physical values (None = not available). `raw_override` puts a raw
    code (a sentinel) in a signal; such a vector is for decoding only."""
    raw_override = raw_override or {}
    raw = {}
    crc_sig = None
    for s in msg.signals:
        r = role(s)
        if r == "counter":
            raw[s.name] = counter
        elif r == "crc":
            raw[s.name] = 0
            crc_sig = s
        elif s.name in raw_override:
            raw[s.name] = raw_override[s.name]
        elif s.name in na:
            raw[s.name] = na_raw(s)
        else:
            raw[s.name] = to_raw(s, phys[s.name])
    # Cross-check cantools' own physical→raw on the non-NA values.
    if not na:
        enc_phys = msg.encode({**phys, **{k: raw[k] for k in raw if k not in phys}},
                              scaling=True, padding=True, strict=True)
    data = bytearray(msg.encode(raw, scaling=False, padding=True, strict=False))
    if not na:
        assert bytes(data) == bytes(enc_phys), (msg.name, phys)
    if crc_sig is not None:
        byte = crc_sig.start // 8
        data[byte] = crc8_j1850([b for i, b in enumerate(data) if i != byte])
    decoded = msg.decode(bytes(data), decode_choices=False, scaling=True)
    values = {}
    for s in msg.signals:
        if role(s) != "value":
            continue
        values[s.name] = None if s.name in na else float(decoded[s.name])
    v = {
        "message": msg.name,
        "id": "%08X" % msg.frame_id,
        "data": bytes(data).hex().upper(),
        "counter": counter,
        "values": values,
    }
    if raw_override:
        v["decode_only"] = True
    return v


def main():
    rng = random.Random(20261122)
    db = cantools.database.load_file(DBC)
    out = []
    for msg in db.messages:
        vals = [s for s in msg.signals if role(s) == "value"]
        for _ in range(25):
            phys = {}
            for s in vals:
                v = rng.uniform(s.minimum, s.maximum)
                if s.scale == 1 and s.offset == 0:
                    v = float(round(v))
                phys[s.name] = v
            out.append(make(msg, phys, rng.randrange(16)))
        for pick in (lambda s: s.minimum, lambda s: s.maximum):
            phys = {s.name: float(pick(s)) for s in vals}
            out.append(make(msg, phys, 15))
        na = tuple(s.name for s in vals if not_available(msg, s))
        if na:
            phys = {s.name: float(s.minimum) for s in vals}
            out.append(make(msg, phys, 0, na=na))
        # Every sentinel code (a sample of long regions) decodes as absent, one signal at a
        # time; the others at their minimum.
        for s in vals:
            first = sentinel_first(msg, s)
            if first is None:
                continue
            top = top_code(s)
            codes = sorted({first, first + 1, (first + top) // 2, top - 1, top} & set(range(first, top + 1)))
            for code in codes:
                phys = {v.name: float(v.minimum) for v in vals}
                out.append(make(msg, phys, 0, na=(s.name,), raw_override={s.name: code}))
    json.dump({"dbc": "dbc/agsteer.dbc", "cantools": cantools.__version__, "vectors": out},
              sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
