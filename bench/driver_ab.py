#!/usr/bin/python3
"""Castle spp/s on the two lavapipes, interleaved in one run (issue 13 part 2).

    bench/driver_ab.py [--sdfc build/cli/sdfc] [--reps 5] [--size 640x360] [--spp 16]
                       [--configs system bundled system:--bounds bundled:--bounds]

Alternates `--driver system` (Debian's Mesa 22.3.6) and `--driver bundled`
(Mesa 25.0.7 from tools/lavapipe25.sh) render by render, so both see the same
machine load (the order reversed every other rep), and prints the medians of
sampling spp/s, pipeline ms and whole process seconds, and each configuration's
ratio to the first. A configuration is DRIVER[:FLAG,FLAG...] (extra render flags).
Writes bench/results/driver_ab.csv.
"""
import argparse
import csv
import os
import statistics
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import sdfbench as sb  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "castle.sdf"))
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--configs", nargs="+", default=["system", "bundled"])
    ap.add_argument("--out", default=os.path.join(HERE, "results", "driver_ab.csv"))
    args = ap.parse_args()

    drivers = args.configs
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for rep in range(args.reps):
            for driver in drivers if rep % 2 == 0 else drivers[::-1]:
                name, _, extra = driver.partition(":")
                env = dict(os.environ, SDFC_DRIVER=name)
                info = sb.render(args.sdfc, args.scene, os.path.join(work, "x.pfm"),
                                 ["--size", args.size, "--spp", str(args.spp), "--seed", "1"]
                                 + [f for f in extra.split(",") if f], env=env)
                rows.append({"driver": driver, "rep": rep, "spp_per_s": info["spp_per_s"],
                             "pipeline_ms": info.get("pipeline_ms"), "wall_s": info["wall_s"]})
                print(f"{driver:16s} rep {rep}: {info['spp_per_s']:.2f} spp/s, pipeline "
                      f"{info.get('pipeline_ms')} ms, {info['wall_s']:.2f} s", file=sys.stderr)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    med = {d: {k: statistics.median(r[k] for r in rows if r["driver"] == d and r[k] is not None)
               for k in ("spp_per_s", "pipeline_ms", "wall_s")} for d in drivers}
    print(f"{os.path.basename(args.scene)} {args.size}, {args.spp} spp, {args.reps} reps each, interleaved, medians:")
    first = med[drivers[0]]
    for d in drivers:
        m = med[d]
        print(f"  {d:16s} {m['spp_per_s']:.2f} spp/s  pipeline {m['pipeline_ms']:.0f} ms  "
              f"process {m['wall_s']:.2f} s  | vs {drivers[0]}: spp/s "
              f"{m['spp_per_s'] / first['spp_per_s']:.2f}x, process {first['wall_s'] / m['wall_s']:.2f}x")


if __name__ == "__main__":
    main()
