#!/usr/bin/python3
"""Interleaved A/B of several sdfc builds on bench/large_scenes.py's point clouds
(docs/design/large_scenes.md): CPU ms per sample (user + sys, (9 spp - 1 spp) / 8, 640x360),
medians of --repeats rounds, every build and count once per round, and the
100,000 vs 100 ratio per build.

  bench/large_ab.py --sdfc A/cli/sdfc,B/cli/sdfc [--counts 100,100000] [--repeats 5]
                    [--out bench/results/large_ab.md]

Needs /usr/bin/time (package `time`) and /usr/bin/python3 (numpy, for large_scenes).
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import large_scenes as ls  # noqa: E402


def load():
    return os.getloadavg()[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", required=True, help="comma-separated sdfc binaries (A,B,...)")
    ap.add_argument("--counts", default="100,100000")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    builds = args.sdfc.split(",")
    counts = [int(c) for c in args.counts.split(",")]
    dir_ = tempfile.mkdtemp(prefix="sdfc_ab_")
    scenes = {c: ls.write_instanced(dir_, c) for c in counts}
    runs = {(b, c): [] for b in builds for c in counts}
    # Warm-up: a build's first render of a scene compiles its pipeline (lavapipe
    # caches it on disk), which would land in the 1-spp run of round 1.
    for c in counts:
        for b in builds:
            ls.ms_once(b, scenes[c], dir_, 1)
    load_start = load()
    for r in range(args.repeats):
        for c in counts:
            for b in builds:
                runs[(b, c)].append(ls.cpu_ms_per_sample(b, scenes[c], dir_))
        print("round %d: %s" % (r + 1, ", ".join("%s/%d %.0f" % (os.path.basename(os.path.dirname(
            os.path.dirname(b))) or b, c, runs[(b, c)][-1]) for c in counts for b in builds)), flush=True)
    lines = ["CPU ms per sample (user + sys, (9 spp - 1 spp) / 8, 640x360), medians of %d interleaved rounds; "
             "load %.1f at the start, %.1f at the end (%s UTC)." % (args.repeats, load_start, load(),
                                                                 time.strftime("%Y-%m-%d %H:%M", time.gmtime())),
             "",
             "| build | " + " | ".join("%d" % c for c in counts) + " | ratio %d / %d | runs |" % (counts[-1], counts[0]),
             "|---|" + "---:|" * len(counts) + "---:|---|"]
    for b in builds:
        med = [statistics.median(runs[(b, c)]) for c in counts]
        lines.append("| %s | %s | %.3f | %s |" % (b, " | ".join("%.0f" % m for m in med), med[0] / med[-1],
                                                  "; ".join(", ".join("%.0f" % v for v in runs[(b, c)])
                                                            for c in counts)))
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
