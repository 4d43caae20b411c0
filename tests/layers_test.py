#!/usr/bin/env python3
"""`sdfc render -o x.exr --layers` (issue 33, docs/layers.md): each layer equals
the matching render, the ids are exact, the variance is the samples' own.

- beauty R, G, B equal a `--denoise none` EXR of the same samples;
- albedo, N and Z equal --view albedo, normal (N x 0.5 + 0.5) and depth, with
  Z = 1e10 where the depth view says -1 (a miss);
- material and object are whole numbers and name the shape the pixel-centre
  ray hits (found here from the hit point: on the plane, the sphere or the box);
- variance.Y, averaged over the image, matches the variance of the mean
  luminance measured across independent renders (6 seeds);
- a non-EXR output or --denoise with --layers is a usage error (exit 2).

    /usr/bin/python3 tests/layers_test.py [--sdfc build/cli/sdfc]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
sys.path.insert(0, os.path.join(ROOT, "tests"))
import sdfbench as sb  # noqa: E402
from exr_channels import read_exr  # noqa: E402

W, H = 64, 36
CAMERA = ([0.0, 1.2, 4.5], [0.0, 0.5, 0.0], 40.0)
# object 0: the plane (material 0); 1: the sphere (material 1); 2: the box (material 0 again).
SCENE = f"""render(size: [{W}, {H}], spp: 8, bounces: 2)
camera(position: {CAMERA[0]}, target: {CAMERA[1]}, fov: {CAMERA[2]:g})
sky(top: [0.4, 0.6, 1.0], bottom: [1, 1, 1])
sun(direction: [-0.4, 1, 0.3], angle: 3, strength: 2)
let ground = diffuse(albedo: [0.5, 0.5, 0.5])
scene {{
  plane(normal: [0, 1, 0], offset: 0, material: ground)
  translate([-0.6, 0.5, 0]) {{ sphere(radius: 0.5, material: diffuse(albedo: [0.8, 0.3, 0.25])) }}
  translate([0.7, 0.35, 0.2]) {{ box(size: 0.7, material: ground) }}
}}
"""
FAILURES = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        FAILURES.append(what)


def run(sdfc, args):
    return subprocess.run([sdfc, *args], capture_output=True, text=True)


def render(sdfc, scene, out, *flags):
    p = run(sdfc, ["render", scene, "-o", out, "-q", *flags])
    if p.returncode != 0:
        raise RuntimeError(f"render {flags} failed ({p.returncode}): {p.stderr}")


def rays():
    """Unit pixel-centre ray directions (H, W, 3), as the kernel's pinhole camera."""
    eye, target, fov = (np.array(v, dtype=float) if i < 2 else v for i, v in enumerate(CAMERA))
    f = (target - eye) / np.linalg.norm(target - eye)
    r = np.cross(f, [0, 1, 0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    t = np.tan(np.radians(fov) / 2)
    x = (2 * (np.arange(W) + 0.5) / W - 1) * (W / H) * t
    y = (1 - 2 * (np.arange(H) + 0.5) / H) * t
    d = f + x[None, :, None] * r + y[:, None, None] * u
    return eye, d / np.linalg.norm(d, axis=2, keepdims=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    args = ap.parse_args()
    sdfc = args.sdfc
    with tempfile.TemporaryDirectory() as tmp:
        folder = os.path.join(tmp, "a folder with spaces")
        os.mkdir(folder)
        scene = os.path.join(folder, "three shapes.sdf")
        with open(scene, "w") as f:
            f.write(SCENE)
        layers_path = os.path.join(folder, "shot layers.exr")
        render(sdfc, scene, layers_path, "--layers", "--seed", "3")
        layers, size = read_exr(layers_path)
        check(size == (W, H), f"layers size {size}")
        expected = ["B", "G", "N.X", "N.Y", "N.Z", "R", "Z", "albedo.B", "albedo.G", "albedo.R", "material",
                    "object", "variance.Y"]
        check(sorted(layers) == expected, f"channels {sorted(layers)}")

        beauty_path = os.path.join(tmp, "beauty.exr")
        render(sdfc, scene, beauty_path, "--denoise", "none", "--seed", "3")
        beauty, _ = read_exr(beauty_path)
        d = max(float(np.max(np.abs(layers[c] - beauty[c]))) for c in "RGB")
        check(d == 0.0, f"R, G, B equal --denoise none's EXR (max difference {d:g})")

        views = {}
        for view in ("normal", "depth", "albedo"):
            out = os.path.join(tmp, view + ".pfm")
            render(sdfc, scene, out, "--view", view)
            views[view] = sb.read_pfm(out)
        n = np.stack([layers["N.X"], layers["N.Y"], layers["N.Z"]], axis=2)
        d = float(np.max(np.abs(n * 0.5 + 0.5 - views["normal"])))
        check(d <= 1e-6, f"N equals --view normal (max difference {d:g})")
        a = np.stack([layers["albedo.R"], layers["albedo.G"], layers["albedo.B"]], axis=2)
        d = float(np.max(np.abs(a - views["albedo"])))
        check(d <= 1e-6, f"albedo equals --view albedo (max difference {d:g})")
        depth = views["depth"][:, :, 0]
        hit = depth >= 0
        d = float(np.max(np.abs(layers["Z"][hit] - depth[hit]) / depth[hit]))
        check(d <= 1e-6, f"Z equals --view depth where it hit (max relative difference {d:g})")
        check(bool(np.all(layers["Z"][~hit] == 1e10)) and (~hit).sum() > 0,
              f"Z is 1e10 at the {(~hit).sum()} misses")

        # The ids: whole numbers, -1 at misses, and the shape at each hit point.
        mat, obj = layers["material"], layers["object"]
        check(bool(np.all(mat == np.round(mat)) and np.all(obj == np.round(obj))), "ids are whole numbers")
        check(bool(np.all(obj[~hit] == -1) and np.all(mat[~hit] == -1)), "ids are -1 at misses")
        eye, dirs = rays()
        p = eye + dirs * depth[:, :, None]
        on_plane = np.abs(p[:, :, 1]) < 1e-3
        on_sphere = np.abs(np.linalg.norm(p - [-0.6, 0.5, 0], axis=2) - 0.5) < 1e-3
        on_box = np.max(np.abs(p - [0.7, 0.35, 0.2]), axis=2) < 0.35 + 1e-3
        truth = np.where(on_plane & ~on_box, 0, np.where(on_sphere, 1, np.where(on_box & ~on_plane, 2, -2)))
        sure = hit & (truth >= 0)
        check(sure.sum() > 0.9 * hit.sum(), f"{sure.sum()} of {hit.sum()} hits placed on one shape here")
        wrong = int(np.sum(obj[sure] != truth[sure]))
        check(wrong == 0 and len(set(obj[sure].astype(int))) == 3, f"object ids match the shapes hit ({wrong} wrong)")
        want_mat = np.array([0, 1, 0])[truth[sure]]
        wrong = int(np.sum(mat[sure] != want_mat))
        check(wrong == 0, f"material ids match the shapes' materials ({wrong} wrong)")

        # variance.Y against the spread of independent renders' mean luminance.
        luma = lambda img: 0.2126 * img["R"] + 0.7152 * img["G"] + 0.0722 * img["B"]
        means = []
        # Independent samples (--white-noise): the sample variance / n is then the
        # variance of the mean; Sobol's stratified samples make the latter smaller.
        for seed in range(10, 16):
            out = os.path.join(tmp, f"seed{seed}.exr")
            render(sdfc, scene, out, "--layers", "--seed", str(seed), "--white-noise")
            img, _ = read_exr(out)
            means.append(luma(img))
            if seed == 10:
                predicted = img["variance.Y"]
        measured = np.var(np.stack(means), axis=0, ddof=1)
        ratio = float(measured.mean() / predicted.mean())
        # 6 seeds x 2304 pixels (correlated little): the ratio's noise is a few %.
        check(0.8 < ratio < 1.25, f"variance.Y: measured / predicted variance of the mean {ratio:.3f}")
        check(float(predicted[~hit].max()) < 1e-3 * float(predicted[hit].mean()),
              "variance.Y is near 0 at misses (the sky varies little over a pixel)")

        for bad, what in ((["-o", os.path.join(tmp, "x.png")], "a PNG output"),
                          (["-o", os.path.join(tmp, "x.exr"), "--denoise", "nlr"], "--denoise nlr"),
                          (["-o", os.path.join(tmp, "x.exr"), "--view", "normal"], "--view normal")):
            p = run(sdfc, ["render", scene, "--layers", *bad])
            check(p.returncode == 2 and p.stderr.startswith("sdfc: error: --layers"),
                  f"--layers with {what}: exit {p.returncode}, {p.stderr.strip()[:90]!r}")
    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        return 1
    print("all layers checks pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
