#!/usr/bin/env python3
"""Float64 ground truth for single pixels at 1 bounce, to settle where sdfc and
Mitsuba 3 disagree (bench/README.md, "Independent reference").

At 1 bounce under a uniform white sky, a pixel is the mean over its area of
albedo x (the cosine-weighted share of the hemisphere that sees the sky). This
script intersects exactly (ray-box, ray-capped-cylinder, ray-plane, float64),
subsamples the pixel on an S x S grid and integrates the hemisphere with N
cosine-distributed rays per subsample.

    /usr/bin/python3 bench/pixel_truth.py cylinder 86,119 85,120
    /usr/bin/python3 bench/pixel_truth.py menger2 90,108 86,113 92,105

Scenes (160x120 pixels, as rendered by mitsuba_check.py / mitsuba_menger.py):
  cylinder  the capped cylinder of mirror_box_cylinder standing on the ground
            (radius 0.35, y in [0, 0.8], centre x 0.7, z 0.3), as before the
            shared scenes lifted it
  menger2   a level-2 Menger sponge of side 1 lifted 0.05 above the ground,
            camera as in mitsuba_menger.py
"""
import argparse
import itertools

import numpy as np

from mitsuba_menger import sponge_cells

W, H = 160, 120
CYLINDER = dict(center=np.array([0.7, 0.0, 0.3]), radius=0.35, height=0.8)


def camera(position, target, fov):
    f = np.subtract(target, position, dtype=float)
    f /= np.linalg.norm(f)
    r = np.cross(f, [0, 1, 0])
    r /= np.linalg.norm(r)
    return np.array(position, dtype=float), f, r, np.cross(r, f), np.tan(np.radians(fov) / 2)


def menger_boxes(level, size, lift):
    """The sponge's kept cells (mitsuba_menger.py's rule) as boxes (lo, hi)."""
    cell = size / 3 ** level
    lo = sponge_cells(level) * cell + np.array([-size / 2, lift, -size / 2])
    return lo, lo + cell


def hit_boxes(boxes, o, d):
    """Nearest t > 0 on any box (slab test), inf if none; o, d: (N, 3)."""
    lo, hi = boxes
    t = np.full(len(o), np.inf)
    inv = 1 / np.where(d == 0, 1e-300, d)
    for s in range(0, len(lo), 64):
        t1 = (lo[None, s:s + 64] - o[:, None]) * inv[:, None]
        t2 = (hi[None, s:s + 64] - o[:, None]) * inv[:, None]
        near, far = np.minimum(t1, t2).max(axis=2), np.maximum(t1, t2).min(axis=2)
        t = np.minimum(t, np.where((near <= far) & (far > 1e-9), np.maximum(near, 1e-9), np.inf).min(axis=1))
    return t


def hit_cylinder(o, d):
    """Nearest t > 0 on the capped cylinder, inf if none."""
    c, rad, hgt = CYLINDER["center"], CYLINDER["radius"], CYLINDER["height"]
    ox, oz, dx, dz = o[:, 0] - c[0], o[:, 2] - c[2], d[:, 0], d[:, 2]
    a, b, k = dx * dx + dz * dz, 2 * (ox * dx + oz * dz), ox * ox + oz * oz - rad * rad
    disc = b * b - 4 * a * k
    ok = (disc >= 0) & (a > 1e-300)
    sq = np.sqrt(np.where(ok, disc, 0))
    safe_a = np.where(a > 0, a, 1)
    t = np.full(len(o), np.inf)
    for tc in ((-b - sq) / (2 * safe_a), (-b + sq) / (2 * safe_a)):
        y = o[:, 1] + tc * d[:, 1]
        t = np.where(ok & (tc > 1e-9) & (y >= 0) & (y <= hgt) & (tc < t), tc, t)
    for yc in (0.0, hgt):
        tc = (yc - o[:, 1]) / np.where(d[:, 1] != 0, d[:, 1], 1e-300)
        x, z = o[:, 0] + tc * d[:, 0] - c[0], o[:, 2] + tc * d[:, 2] - c[2]
        t = np.where((tc > 1e-9) & (x * x + z * z <= rad * rad) & (tc < t), tc, t)
    return t


def cylinder_normal(p):
    c, hgt = CYLINDER["center"], CYLINDER["height"]
    if abs(p[1] - hgt) < 1e-9:
        return np.array([0.0, 1.0, 0.0])
    n = np.array([p[0] - c[0], 0.0, p[2] - c[2]])
    return n / np.linalg.norm(n)


def box_normal(boxes, p):
    lo, hi = boxes
    dist = np.abs(np.concatenate([p - lo, hi - p], axis=1))  # (boxes, 6)
    k = np.argmin(dist.min(axis=1))
    face = np.argmin(dist[k])
    n = np.zeros(3)
    n[face % 3] = -1 if face < 3 else 1
    return n


def cosine_directions(n, count, rng):
    u1, u2 = rng.random(count), rng.random(count)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    b1 = np.cross(n, a)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(n, b1)
    return (r * np.cos(phi))[:, None] * b1 + (r * np.sin(phi))[:, None] * b2 + np.sqrt(1 - u1)[:, None] * n


def pixel_value(scene, px, py, sub, rays, rng):
    eye, f, r, u, tan_half = scene["camera"]
    total = np.zeros(3)
    for i, j in itertools.product(range(sub), repeat=2):
        ndc_x = 2 * (px + (i + 0.5) / sub) / W - 1
        ndc_y = 1 - 2 * (py + (j + 0.5) / sub) / H
        d = f + ndc_x * (W / H) * tan_half * r + ndc_y * tan_half * u
        d /= np.linalg.norm(d)
        t_obj = scene["hit"](eye[None], d[None])[0]
        t_ground = -eye[1] / d[1] if d[1] < 0 else np.inf
        if t_obj < t_ground:
            p = eye + t_obj * d
            n, albedo = scene["normal"](p), scene["albedo"]
        elif np.isfinite(t_ground):
            p, n, albedo = eye + t_ground * d, np.array([0.0, 1.0, 0.0]), np.full(3, 0.5)
        else:
            total += 1  # the sky
            continue
        dirs = cosine_directions(n, rays, rng)
        origins = np.repeat((p + n * 1e-9)[None], rays, axis=0)
        blocked = np.isfinite(scene["hit"](origins, dirs)) | (dirs[:, 1] < 0)
        total += albedo * (1 - blocked.mean())
    return total / sub ** 2


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", choices=["cylinder", "menger2"])
    ap.add_argument("pixels", nargs="+", help="row,column")
    ap.add_argument("--sub", type=int, default=12, help="subsamples per pixel side")
    ap.add_argument("--rays", type=int, default=6000, help="hemisphere rays per subsample")
    args = ap.parse_args()
    if args.scene == "cylinder":
        scene = {"camera": camera([0, 1.2, 4.5], [0, 0.6, 0], 40), "hit": hit_cylinder,
                 "normal": cylinder_normal, "albedo": np.array([0.2, 0.5, 0.8])}
    else:
        boxes = menger_boxes(2, 1.0, 0.05)
        scene = {"camera": camera([1.55, 1.25, 2.1], [0, 0.45, 0], 40),
                 "hit": lambda o, d: hit_boxes(boxes, o, d),
                 "normal": lambda p: box_normal(boxes, p[None]), "albedo": np.array([0.8, 0.3, 0.25])}
    rng = np.random.default_rng(1)
    for pixel in args.pixels:
        row, col = map(int, pixel.split(","))
        value = pixel_value(scene, col, row, args.sub, args.rays, rng)
        print(f"pixel (row {row}, column {col}): {np.array2string(value, precision=4)} "
              f"({args.sub ** 2 * args.rays} hemisphere rays)")


if __name__ == "__main__":
    main()
