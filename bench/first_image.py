#!/usr/bin/env python3
"""The image a user gets without flags (issue 29): error and wall time.

    /usr/bin/python3 bench/first_image.py --before OLD_SDFC --after build/cli/sdfc \\
        --ref 'DIR/ref320_*.pfm' --size 320x180 --reps 3

Renders examples/castle.sdf with no flags but --size (and an output path:
PNG for the wall time, as a user would; PFM for the error) with each binary,
alternating before/after --reps times, and reports each one's relMSE (mean
(x - ref)^2 / (ref^2 + 0.01)) against the mean of the reference PFMs
(independent undenoised renders of equal spp, e.g. 8 x 256 spp with
bench/run.py's REFERENCE_FLAGS) with the reference's own noise subtracted
(its variance of the mean, from the spread of the PFMs), and the median whole-
process wall time of each. The render's own size, spp and seed are the scene's.
"""
import argparse
import glob
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import flip  # noqa: E402
import sdfbench as sb  # noqa: E402

SCENE = os.path.join(ROOT, "examples", "castle.sdf")


def run(sdfc, out, size, env):
    cmd = [sdfc, "render", SCENE, "-o", out] + (["--size", size] if size else [])
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - start
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    line = [l for l in r.stderr.splitlines() if l.startswith("sdfc: wrote")]
    return wall, line[-1] if line else ""


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--before", required=True)
    p.add_argument("--after", required=True)
    p.add_argument("--ref", required=True, help="glob of reference PFMs of equal spp")
    p.add_argument("--size", default="")
    p.add_argument("--reps", type=int, default=3)
    args = p.parse_args()
    refs = [sb.read_pfm(f) for f in sorted(glob.glob(args.ref))]
    ref = np.mean(refs, axis=0)
    var = np.var(refs, axis=0, ddof=1) / len(refs) if len(refs) > 1 else np.zeros_like(ref)
    floor = float(np.mean(var / (ref ** 2 + 0.01)))
    print(f"reference: {len(refs)} renders, own relMSE noise {floor:.3g}")
    env = dict(os.environ)
    walls = {"before": [], "after": []}
    with tempfile.TemporaryDirectory(prefix="first image ") as work:
        for name in ("before", "after"):
            sdfc = getattr(args, name)
            _, line = run(sdfc, os.path.join(work, f"{name}.pfm"), args.size, env)
            img = sb.read_pfm(os.path.join(work, f"{name}.pfm"))
            rel = sb.relmse(img, ref)
            print(f"{name}: relMSE {rel:.3g} (noise of the reference subtracted: {rel - floor:.3g}), "
                  f"FLIP {flip.mean_flip(img, ref):.4f}; {line}")
        for rep in range(args.reps):
            for name in ("before", "after") if rep % 2 == 0 else ("after", "before"):
                wall, _ = run(getattr(args, name), os.path.join(work, f"{name}.png"), args.size, env)
                walls[name].append(wall)
                print(f"  rep {rep} {name}: {wall:.2f} s wall (load {os.getloadavg()[0]:.1f})", flush=True)
    if not args.reps:
        return
    b, a = statistics.median(walls["before"]), statistics.median(walls["after"])
    print(f"median wall: before {b:.2f} s, after {a:.2f} s, after/before {a / b:.2f}")


if __name__ == "__main__":
    main()
