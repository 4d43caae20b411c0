#!/usr/bin/env python3
"""Debug-view PNGs use their range (issue 29), and EXR keeps the raw values.

The castle at its own size, one PNG per debug view through `sdfc render` with
default flags: no view may have more than 20% of its pixels clipped (every
channel 0 or 255 and one at 255: white, or a pure primary). Before, the depth
view was white wherever a ray hit and the iterations view red everywhere. The
depth and steps PFMs hold raw distances and step counts (the PNG's mapping is
for display only): depth -1 on a miss, steps whole numbers up to the budget.

    /usr/bin/python3 tests/debug_views_test.py [--sdfc build/cli/sdfc]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import matplotlib.image as mpimg
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import sdfbench as sb  # noqa: E402

SCENE = os.path.join(ROOT, "examples", "castle.sdf")
VIEWS = ("normal", "albedo", "depth", "steps", "iterations")
MAX_CLIPPED = 0.20


def clipped_share(path):
    rgb = np.round(mpimg.imread(path)[:, :, :3] * 255).astype(np.int16)
    corner = np.all((rgb == 0) | (rgb == 255), axis=-1) & np.any(rgb == 255, axis=-1)
    return float(corner.mean())


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    args = p.parse_args()
    failures = 0
    with tempfile.TemporaryDirectory(prefix="debug views ") as work:  # a path with a space
        for view in VIEWS:
            png = os.path.join(work, f"castle {view}.png")
            r = subprocess.run([args.sdfc, "render", SCENE, "--view", view, "-o", png],
                               capture_output=True, text=True, timeout=300)
            if r.returncode != 0:
                print(f"FAIL: {view}: exit {r.returncode}\n{r.stderr}")
                failures += 1
                continue
            share = clipped_share(png)
            ok = share <= MAX_CLIPPED
            failures += not ok
            print(f"{'ok' if ok else 'FAIL'}: {view}: {share:.1%} of pixels clipped (at most {MAX_CLIPPED:.0%})")
            if "[vulkan" in r.stderr:
                print(f"FAIL: {view}: validation message\n{r.stderr}")
                failures += 1
        # The raw values stay in PFM.
        depth_pfm = os.path.join(work, "depth.pfm")
        sb.render(args.sdfc, SCENE, depth_pfm, ["--view", "depth", "--size", "160x90", "-q"])
        z = sb.read_pfm(depth_pfm)[..., 0]
        ok = (z.max() > 20) and np.any(z == -1) and np.all((z == -1) | (z > 0))
        failures += not ok
        print(f"{'ok' if ok else 'FAIL'}: depth PFM is raw distance (max {z.max():.1f}, misses -1)")
        steps_pfm = os.path.join(work, "steps.pfm")
        info = subprocess.run([args.sdfc, "render", SCENE, "--view", "steps", "--size", "160x90",
                               "-o", steps_pfm], capture_output=True, text=True, timeout=300)
        budget = int(re.search(r"budget (\d+)", info.stderr).group(1))
        s = sb.read_pfm(steps_pfm)
        ok = (np.all(s == np.rint(s)) and s.max() <= budget and s.max() > 10
              and np.all(s[..., 0] == s[..., 1]))
        failures += not ok
        print(f"{'ok' if ok else 'FAIL'}: steps PFM is the raw count (max {s.max():.0f}, budget {budget})")
    print("PASS" if failures == 0 else f"{failures} FAILED")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
