#!/usr/bin/env python3
"""Equirectangular environment maps for sky(map: ...): writers for EXR
(uncompressed, float32 RGB) and Radiance .hdr (flat RGBE scanlines), and the
procedural "studio" map the example and the tests use (no photographs are
committed: the map is made by this script).

    python3 tools/envmap.py studio examples/studio.exr [--width 256]
    python3 tools/envmap.py constant out.exr --value 1 [--width 8]

The layout is sdfc's and Mitsuba 3's: y up, the image's top row looking up,
u = atan2(x, -z) / 2 pi across the width.
"""
import argparse
import struct

import numpy as np


def write_exr(path, rgb):
    """rgb: float array (height, width, 3), written as an uncompressed EXR."""
    rgb = np.ascontiguousarray(rgb, dtype="<f4")
    h, w, _ = rgb.shape

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + attr("channels", "chlist", chlist) +
              attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box) +
              attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0") +
              attr("pixelAspectRatio", "float", struct.pack("<f", 1)) +
              attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    block = 8 + w * 3 * 4
    start = len(header) + 8 * h
    offsets = struct.pack(f"<{h}Q", *[start + y * block for y in range(h)])
    with open(path, "wb") as f:
        f.write(header + offsets)
        for y in range(h):
            f.write(struct.pack("<ii", y, w * 12))
            for c in (2, 1, 0):
                f.write(rgb[y, :, c].tobytes())


def write_hdr(path, rgb):
    """rgb: float array (height, width, 3), written as flat RGBE scanlines."""
    rgb = np.asarray(rgb, dtype=np.float64)
    h, w, _ = rgb.shape
    peak = rgb.max(axis=2)
    mant, expo = np.frexp(peak)
    scale = np.where(peak > 1e-32, mant * 256.0 / np.maximum(peak, 1e-300), 0.0)
    rgbe = np.zeros((h, w, 4), np.uint8)
    rgbe[..., :3] = np.clip(rgb * scale[..., None], 0, 255).astype(np.uint8)
    rgbe[..., 3] = np.where(peak > 1e-32, expo + 128, 0).astype(np.uint8)
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + f"-Y {h} +X {w}\n".encode())
        f.write(rgbe.tobytes())


def directions(w, h):
    """The unit direction at each texel centre, (h, w, 3)."""
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    phi, theta = np.meshgrid(2 * np.pi * u, np.pi * v)
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)


def studio(w):
    """A soft studio: a warm key light high on one side (peak about 60), a
    cool rim light low on the other, a dim blue-grey dome and a dark floor;
    smooth, so that a bilinear and a piecewise-constant reading agree."""
    h = w // 2
    d = directions(w, h)

    def lobe(direction, sharpness):
        c = np.asarray(direction, float)
        c /= np.linalg.norm(c)
        return np.exp(sharpness * (d @ c - 1.0))[..., None]

    dome = np.where(d[..., 1:2] > 0, 0.25 + 0.35 * d[..., 1:2], 0.08 + 0.04 * (1 + d[..., 1:2]))
    colour = dome * np.array([0.75, 0.85, 1.0])
    colour = colour + 60.0 * lobe([0.6, 0.7, 0.4], 40.0) * np.array([1.0, 0.85, 0.6])
    colour = colour + 6.0 * lobe([-0.8, 0.15, -0.5], 12.0) * np.array([0.5, 0.7, 1.0])
    return colour.astype(np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("kind", choices=["studio", "constant"])
    ap.add_argument("output", help=".exr or .hdr")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--value", type=float, default=1.0)
    a = ap.parse_args()
    rgb = studio(a.width) if a.kind == "studio" else np.full((a.width // 2, a.width, 3), a.value, np.float32)
    (write_hdr if a.output.lower().endswith(".hdr") else write_exr)(a.output, rgb)


if __name__ == "__main__":
    main()
