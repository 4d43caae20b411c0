#!/usr/bin/env python3
"""The denoisers against the issue-13 target table, computed small.

Issue 13's target compares, on the castle against a converged reference, 16 spp
denoised with 256 spp undenoised (bench/results/DENOISE_640x360.md has the 640x360
table). Here the same table at 160x90 (a 512-spp white-noise reference, made
in the test: no cache, no timing), and checks what the filter must do:
  - nlr (the default filter to use) at 16 spp beats svgf at 16 spp (relMSE
    and FLIP) and 16 spp undenoised by >= 1.5x (relMSE),
  - nlr's error falls as the samples rise (4 -> 16 -> 64 spp): no bias floor,
and prints where 16-spp nlr (and nlm) stand against 256 spp undenoised.

    /usr/bin/python3 tests/denoise_target_test.py [--sdfc build/cli/sdfc]
"""
import argparse
import os
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import flip  # noqa: E402
import sdfbench as sb  # noqa: E402

SIZE = "160x90"
SCENE = os.path.join(ROOT, "examples", "castle.sdf")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="denoise_target_") as work:
        return check(args, work)


def check(args, work):
    def image(spp, denoiser="none", extra=(), seed=7):
        out = os.path.join(work, f"{denoiser}_{spp}_{seed}.pfm")
        sb.render(args.sdfc, SCENE, out, ["--size", SIZE, "--spp", str(spp), "--seed", str(seed),
                                          "--denoise", denoiser, "-q"] + list(extra))
        return sb.read_pfm(out)

    ref = image(512, extra=["--white-noise"], seed=1001)
    table = {}
    for spp, denoiser in [(16, "none"), (256, "none"), (16, "svgf"), (16, "nlm"),
                          (4, "nlr"), (16, "nlr"), (64, "nlr")]:
        img = image(spp, denoiser)
        table[(spp, denoiser)] = (sb.relmse(img, ref), flip.mean_flip(img, ref))
        print(f"castle {SIZE} {spp:4d} spp {denoiser:5s} relMSE {table[(spp, denoiser)][0]:.3g} "
              f"FLIP {table[(spp, denoiser)][1]:.4f}")
    rel = {k: v[0] for k, v in table.items()}
    failures = []
    if not rel[(16, "nlr")] < rel[(16, "svgf")]:
        failures.append("nlr at 16 spp does not beat svgf at 16 spp")
    if not table[(16, "nlr")][1] < table[(16, "svgf")][1]:
        failures.append("nlr at 16 spp does not beat svgf at 16 spp in FLIP")
    # Small: a filter's window covers more of the scene, so it gains less than
    # at 640x360 (1.75x here when written, 5.2x there).
    if not rel[(16, "nlr")] * 1.5 < rel[(16, "none")]:
        failures.append("nlr at 16 spp is not 1.5x better than 16 spp undenoised")
    if not rel[(4, "nlr")] > rel[(16, "nlr")] > rel[(64, "nlr")]:
        failures.append("nlr's error does not fall 4 -> 16 -> 64 spp")
    for d in ("nlr", "nlm"):
        print(f"16 spp {d} "
              f"vs 256 spp undenoised (the issue's target, < 1 wanted): "
              f"relMSE {rel[(16, d)] / rel[(256, 'none')]:.2f}x, "
              f"FLIP {table[(16, d)][1] / table[(256, 'none')][1]:.2f}x "
              "(the reference's own noise is in every figure)")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
