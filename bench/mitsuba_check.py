#!/usr/bin/env python3
"""Independent reference: the same scene in Mitsuba 3 (PyPI `mitsuba`, variant
scalar_rgb; its LLVM variants crash against Debian 12's LLVM 15) and in sdfc,
compared by mean radiance within the Monte Carlo noise, and by wall time.

The scene uses only what both renderers express identically: a diffuse sphere
on a diffuse ground under a uniform sky, a pinhole camera with a vertical field
of view, and a fixed path length. The infinite plane becomes a
rectangle in Mitsuba, 2e5 on a side (at 1e3 its edge lifted the horizon by a measurable 0.16% of the image).

    /usr/bin/python3 bench/mitsuba_check.py [--sdfc build/cli/sdfc] [--spp 256]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

SCENE = """render(size: [{w}, {h}], spp: {spp}, bounces: {bounces})
camera(position: [0, 1.2, 4.5], target: [0, 0.6, 0], fov: 40)
sky(color: [1, 1, 1])
scene {{
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([0, 0.7, 0]) {{ sphere(radius: 0.7, material: diffuse(albedo: [0.8, 0.3, 0.25])) }}
}}
"""


def read_pfm(path):
    with open(path, "rb") as f:
        f.readline()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1]


def render_sdfc(sdfc, scene_path, seed, out, flags=()):
    start = time.perf_counter()
    subprocess.run([sdfc, "render", scene_path, "-o", out, "--seed", str(seed), "-q", *flags], check=True)
    return read_pfm(out), time.perf_counter() - start


def render_mitsuba(w, h, spp, bounces, seed):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    from mitsuba import ScalarTransform4f as T
    scene = mi.load_dict({
        "type": "scene",
        # Path length: sdfc's `bounces` counts scattering events; Mitsuba's
        # max_depth counts segments, so B bounces = max_depth B + 1.
        "integrator": {"type": "path", "max_depth": bounces + 1},
        "sensor": {
            "type": "perspective", "fov": 40, "fov_axis": "y",
            # The default far clip (1e4) drops the ground within 0.02 pixel of
            # the horizon: measured as 1.6% more sky in the horizon row.
            "far_clip": 1e9,
            "to_world": T().look_at(origin=[0, 1.2, 4.5], target=[0, 0.6, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}},
        "ground": {
            "type": "rectangle",
            "to_world": T().rotate([1, 0, 0], -90).scale(1e5),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
        },
        "ball": {
            "type": "sphere", "center": [0, 0.7, 0], "radius": 0.7,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.8, 0.3, 0.25]}},
        },
    })
    start = time.perf_counter()
    image = np.array(mi.render(scene, spp=spp, seed=seed))[:, :, :3]
    return image, time.perf_counter() - start


def mean_and_error(a, b):
    """Mean radiance of two independent renders and the standard error of
    that mean, from their difference (pixels are independent estimates)."""
    mean = 0.5 * (a.mean(axis=(0, 1)) + b.mean(axis=(0, 1)))
    diff = (a - b).reshape(-1, 3)
    se = diff.std(axis=0) / np.sqrt(2) / np.sqrt(diff.shape[0]) / np.sqrt(2)
    return mean, se


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(os.path.dirname(__file__), "..", "build", "cli", "sdfc"))
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--bounces", type=int, default=3)
    ap.add_argument("--sdfc-flags", default="", help="extra sdfc render flags, e.g. --paper-baseline")
    args = ap.parse_args()
    w, h = map(int, args.size.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        scene_path = os.path.join(tmp, "shared.sdf")
        with open(scene_path, "w") as f:
            f.write(SCENE.format(w=w, h=h, spp=args.spp, bounces=args.bounces))
        flags = args.sdfc_flags.split()
        s1, ts1 = render_sdfc(args.sdfc, scene_path, 1, os.path.join(tmp, "s1.pfm"), flags)
        s2, ts2 = render_sdfc(args.sdfc, scene_path, 2, os.path.join(tmp, "s2.pfm"), flags)
        m1, tm1 = render_mitsuba(w, h, args.spp, args.bounces, 1)
        m2, tm2 = render_mitsuba(w, h, args.spp, args.bounces, 2)
    ms, ses = mean_and_error(s1, s2)
    mm, sem = mean_and_error(m1, m2)
    z = np.abs(ms - mm) / np.sqrt(ses ** 2 + sem ** 2)
    print(f"scene: diffuse sphere on diffuse ground, uniform sky, {w}x{h}, {args.spp} spp, "
          f"{args.bounces} bounces")
    print(f"mean radiance sdfc    {np.array2string(ms, precision=5)} +- {np.array2string(ses, precision=5)}")
    print(f"mean radiance Mitsuba {np.array2string(mm, precision=5)} +- {np.array2string(sem, precision=5)}")
    print(f"difference in standard errors (per channel): {np.array2string(z, precision=2)}")
    rmse = float(np.sqrt(np.mean((0.5 * (s1 + s2) - 0.5 * (m1 + m2)) ** 2)))
    print(f"per-pixel RMSE between the two pairs' means: {rmse:.4f}")
    print(f"wall time per render (same spp): sdfc {min(ts1, ts2):.2f} s (incl. compile and pipeline), "
          f"Mitsuba scalar_rgb {min(tm1, tm2):.2f} s")
    ok = bool(np.all(z < 4))
    print("agree within 4 standard errors" if ok else "DISAGREE: a bug to find")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
