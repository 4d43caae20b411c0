"""A reader of the scanline OpenEXR files sdfc writes (float or uint channels,
no or ZIP compression), for tests on machines with no EXR module.

    channels, (width, height) = read_exr("x.exr")   # name -> (height, width) array
"""
import struct
import zlib

import numpy as np


def _attributes(data):
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        kind = data[end + 1:tend].decode()
        (size,) = struct.unpack_from("<i", data, tend + 1)
        attrs[name] = (kind, data[tend + 5:tend + 5 + size])
        pos = tend + 5 + size
    return attrs, pos + 1


def _channel_list(raw):
    out, pos = [], 0
    while raw[pos] != 0:
        end = raw.index(b"\0", pos)
        (ptype,) = struct.unpack_from("<i", raw, end + 1)
        out.append((raw[pos:end].decode(), ptype))
        pos = end + 1 + 16
    return out


def _unzip(block, expected):
    t = bytearray(zlib.decompress(block))
    for i in range(1, len(t)):
        t[i] = (t[i - 1] + t[i] - 128) & 0xFF
    half = (len(t) + 1) // 2
    out = bytearray(len(t))
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    assert len(out) == expected
    return bytes(out)


def read_exr(path):
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"\x76\x2f\x31\x01", "not an EXR file"
    attrs, pos = _attributes(data)
    channels = _channel_list(attrs["channels"][1])
    compression = attrs["compression"][1][0]
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines = {0: 1, 3: 16}[compression]
    chunks = (h + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    dtypes = {0: "<u4", 2: "<f4"}
    planes = {name: np.zeros((h, w), dtype=dtypes[t]) for name, t in channels}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        n = min(lines, y1 - y + 1)
        expected = n * w * 4 * len(channels)
        block = data[off + 8:off + 8 + size]
        raw = block if size == expected else _unzip(block, expected)
        p = 0
        for row in range(n):
            for name, t in channels:
                planes[name][y - y0 + row] = np.frombuffer(raw, dtype=dtypes[t], count=w, offset=p)
                p += w * 4
    return planes, (w, h)
