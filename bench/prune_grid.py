#!/usr/bin/python3
"""The root union's prune grid (`--prune`, passes/prune_grid.cpp) on lavapipe,
against the default (planned bounding-volume checks) and with no checks, per
scene, in one interleaved run (issue 46).

    bench/prune_grid.py [--sdfc build/cli/sdfc] [--reps 3] [--size 320x180] [--spp 16]
                        [--out bench/results/prune_grid.md] [SCENE ...]

Scenes as bench/bounds_plan.py's (examples/, bench/scenes/, generated many-part
scenes). Configurations: the default; `--prune`; `--no-bounds`; `--prune
--no-bounds`; the order turned every other rep. Prints and writes the medians of
the sampling's spp/s and of the process's CPU seconds, and what the grid keeps
(`sdfc compile --emit ir --prune`). Writes a page and a .csv beside it.
"""
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import sdfbench as sb  # noqa: E402
from bounds_plan import default_scenes, page_start, scene_bench_arguments  # noqa: E402

CONFIGS = [("default", []), ("prune", ["--prune"]), ("none", ["--no-bounds"]),
           ("prune_none", ["--prune", "--no-bounds"])]


def grid(sdfc, scene):
    """The --emit ir line of the grid: (parts pruned, parts, share kept near a surface) or None."""
    out = subprocess.run([sdfc, "compile", scene, "--prune", "--emit", "ir"], capture_output=True, text=True).stdout
    m = re.search(r"prune grid \S+ cells of \S+ over (\d+) of (\d+) parts: a cell keeps (\d+)% of their cost "
                  r"\((\d+)% near a surface\)", out)
    return (int(m.group(1)), int(m.group(2)), int(m.group(4))) if m else None


def main():
    args = scene_bench_arguments(__doc__, "prune_grid.md")
    started = time.time()
    load0 = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for scene in args.scenes or default_scenes(work):
            name = os.path.basename(scene)
            g = grid(args.sdfc, scene)
            if g is None:
                print(f"{name:28s} no grid (fewer than two parts to prune)", file=sys.stderr)
                continue
            med = sb.interleaved_medians(args.sdfc, scene, work, CONFIGS, args.reps,
                                         ["--size", args.size, "--spp", str(args.spp), "--seed", "1"])
            row = {"scene": name, "pruned_parts": g[0], "parts": g[1], "kept_near_pct": g[2]}
            for c in med:
                row[f"{c}_spp_per_s"] = round(med[c]["spp_per_s"], 3)
                row[f"{c}_cpu_s"] = round(med[c]["cpu_s"], 3)
            rows.append(row)
            print(f"{name:28s} {g[0]:3d} of {g[1]:3d} parts, keeps {g[2]:3d}%  spp/s default "
                  f"{row['default_spp_per_s']:7.2f} prune {row['prune_spp_per_s']:7.2f} "
                  f"({row['prune_spp_per_s'] / row['default_spp_per_s']:.2f}x)  no bounds {row['none_spp_per_s']:7.2f} "
                  f"prune, no bounds {row['prune_none_spp_per_s']:7.2f}", file=sys.stderr, flush=True)
    lines = page_start(args, rows, "The prune grid (`--prune`) on lavapipe", "prune_grid.py", started, load0)
    lines[-1] += ("spp/s is the sampling's; the ratio in brackets is against the default (planned "
                  "bounding-volume checks). `keeps` is the share of the pruned parts' cost a cell near a surface "
                  "lists. Scenes with fewer than two parts to prune have no grid and are left out.")
    lines += ["", "| scene | parts pruned | keeps | spp/s default | `--prune` | `--no-bounds` | `--prune --no-bounds` |",
              "|---|---|---|---|---|---|---|"]
    for r in rows:
        d = r["default_spp_per_s"]
        lines.append(f"| {r['scene']} | {r['pruned_parts']} of {r['parts']} | {r['kept_near_pct']}% | {d:.2f} | "
                     f"{r['prune_spp_per_s']:.2f} ({r['prune_spp_per_s'] / d:.2f}x) | {r['none_spp_per_s']:.2f} "
                     f"({r['none_spp_per_s'] / d:.2f}x) | {r['prune_none_spp_per_s']:.2f} "
                     f"({r['prune_none_spp_per_s'] / d:.2f}x) |")
    ratios = sorted(r["prune_spp_per_s"] / r["default_spp_per_s"] for r in rows)
    lines += ["", f"`--prune` against the default: median {statistics.median(ratios):.2f}x, "
              f"worst {ratios[0]:.2f}x, best {ratios[-1]:.2f}x over {len(rows)} scenes.", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
