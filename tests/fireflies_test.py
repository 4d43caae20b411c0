#!/usr/bin/env python3
"""Fireflies do not become squares (issue 29).

A glass vase (smooth-subtracted) on a table, 16 spp at 160x90: its caustic's
fireflies fall into its shadow. nlm and nlr drew them as bright squares the
width of their window (11 px) and lost the shadow; the halves are now clamped
against each other before the filter (runtime/denoise_fireflies.h). Measured
as a person sees it: the displayed bytes (PNG tone curve, sRGB) against a
512-spp undenoised reference, in 10x10 blocks, the mean absolute difference.
No block of the default render (nlr), nor of nlm or `--adaptive`, may be much
worse than the same block undenoised.

    /usr/bin/python3 tests/fireflies_test.py [--sdfc build/cli/sdfc]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import matplotlib.image as mpimg
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "tests", "scenes", "glass_vase.sdf")
SIZE = "160x90"
BLOCK = 10
# A block may be this much worse than undenoised (bytes of 255, mean |error|):
# the filter trades noise for a little blur; a firefly square is ~10 and more.
SLACK = 3.0


def render_png(sdfc, out, flags):
    r = subprocess.run([sdfc, "render", SCENE, "--size", SIZE, "--seed", "7", "-o", out] + flags,
                       capture_output=True, text=True, timeout=600)
    if r.returncode != 0 or "[vulkan" in r.stderr:
        sys.exit(f"FAIL: sdfc render {' '.join(flags)}: exit {r.returncode}\n{r.stderr}")
    return np.round(mpimg.imread(out)[:, :, :3] * 255).astype(np.float64)


def block_errors(img, ref):
    d = np.abs(img - ref).mean(axis=-1)
    h, w = d.shape
    d = d[: h - h % BLOCK, : w - w % BLOCK]
    return d.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean(axis=(1, 3))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    args = p.parse_args()
    failures = 0
    with tempfile.TemporaryDirectory(prefix="fireflies ") as work:
        ref = render_png(args.sdfc, os.path.join(work, "ref.png"), ["--spp", "512", "--denoise", "none", "-q"])
        raw = render_png(args.sdfc, os.path.join(work, "raw.png"), ["--spp", "16", "--denoise", "none", "-q"])
        raw_err = block_errors(raw, ref)
        # The default first (nlr since issue 29), then each filter named.
        for name, flags in [("default", []), ("nlr", ["--denoise", "nlr"]), ("nlm", ["--denoise", "nlm"]),
                            ("nlr --adaptive", ["--denoise", "nlr", "--adaptive"])]:
            img = render_png(args.sdfc, os.path.join(work, "x.png"), ["--spp", "16", "-q"] + flags)
            err = block_errors(img, ref)
            excess = err - raw_err
            worst = np.unravel_index(np.argmax(excess), excess.shape)
            ok = excess.max() <= SLACK
            failures += not ok
            print(f"{'ok' if ok else 'FAIL'}: {name}: worst block ({worst[1] * BLOCK}, {worst[0] * BLOCK}) "
                  f"{err[worst]:.1f} against undenoised {raw_err[worst]:.1f} (at most +{SLACK}); "
                  f"mean block error {err.mean():.2f}, undenoised {raw_err.mean():.2f}")
    print("PASS" if failures == 0 else f"{failures} FAILED")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
