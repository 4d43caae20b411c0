#!/usr/bin/env python3
"""`sdfc render`'s progress in a log (issue 48): one bar over all the samples and
the denoise. Its lines (stderr is not a terminal here) are monotonic in samples
and in percent, the denoise has a line of its own, and 100% comes once, last.
Before, each of the denoiser's two halves of the samples ran to 100%, and the
denoise printed nothing.

    render_progress_test.py SDFC
"""
import os
import re
import subprocess
import sys
import tempfile

SDFC = sys.argv[1]
HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(os.path.dirname(HERE), "bench", "scenes", "hello.sdf")
LINE = re.compile(r"^render: (\d+)/(\d+) spp(, denoising)? \((\d+)%\), ([0-9.]+)s elapsed, ETA (\S+)$")
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def progress_lines(args):
    with tempfile.TemporaryDirectory(prefix="sdfc_progress_") as d:
        r = subprocess.run([SDFC, "render", SCENE, "-o", os.path.join(d, "x.png")] + args,
                           stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, timeout=120)
        check(r.returncode == 0, f"render {' '.join(args)} exits 0 ({r.returncode})")
        lines = [m.groups() for m in map(LINE.match, r.stderr.splitlines()) if m]
        print("\n".join("  " + l for l in r.stderr.splitlines() if l.startswith("render:")))
        return lines


for args, denoised in ((["--size", "320x180", "--spp", "16"], True),
                       (["--size", "320x180", "--spp", "16", "--denoise", "svgf"], True),
                       (["--size", "320x180", "--spp", "8", "--denoise", "none"], False)):
    name = " ".join(args)
    lines = progress_lines(args)
    check(len(lines) >= (3 if denoised else 1), f"{name}: progress lines ({len(lines)})")
    if not lines:
        continue
    spp = [int(l[0]) for l in lines]
    percent = [int(l[3]) for l in lines]
    total = int(args[args.index("--spp") + 1])
    check(all(int(l[1]) == total for l in lines), f"{name}: every line counts all {total} spp")
    check(spp == sorted(spp), f"{name}: samples never fall {spp}")
    check(percent == sorted(percent), f"{name}: percent never falls {percent}")
    check(percent.count(100) == 1 and percent[-1] == 100, f"{name}: 100% once, at the end")
    check(spp[-1] == total, f"{name}: the last line has all the samples")
    stages = [l for l in lines if l[2]]
    if denoised:
        check(len(stages) >= 1 and int(stages[0][0]) == total and stages[0][3] != "100",
              f"{name}: a line for the denoise, after the samples, before 100%")
    else:
        check(not stages, f"{name}: no denoise line")

print("FAILED: " + "; ".join(failures) if failures else "all passed")
sys.exit(1 if failures else 0)
