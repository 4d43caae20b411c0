#!/usr/bin/env python3
"""What the default denoiser costs and what it is worth, before and after issue 48.

    /usr/bin/python3 bench/denoise_speed.py [--old-sdfc PATH] [--reps 5]   # ~15 min on an idle machine

Part 1, the filter alone (build/bench/denoise_speed/sdfc_denoise_speed): per
scene of the corpus, one render of two halves at --size and --spp (nlr's
features), then, interleaved rep by rep in one process, nlr as it was at
ab4eac1 (its code kept in bench/denoise_speed/legacy_nlm.cpp), the runtime's
nlr and svgf; wall and CPU milliseconds (medians), the largest difference
between the two nlr images, and the relMSE (mean (x - ref)^2 / (ref^2 + 0.01))
and mean LDR-FLIP (bench/flip.py) of each image against the converged
reference of bench/run.py --converge (castle 2048 spp, the others 1024; made
and cached in bench/cache if missing).

Part 2, start to PNG (--old-sdfc, a build of ab4eac1, against --sdfc): the
README's hello scene and the castle with default settings, runs of the two
binaries interleaved (--e2e-reps, after one warm-up each: caches warm, as on a
second run), wall seconds (median) and the image's relMSE against the reference.

Writes results/DENOISE_SPEED.md and results/denoise_speed.csv under --out.
"""
import argparse
import csv
import json
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
import run  # noqa: E402
import sdfbench as sb  # noqa: E402

CORPUS = ["examples/castle.sdf", "bench/scenes/hello.sdf", "examples/colonnade.sdf",
          "examples/glass_menger.sdf", "bench/scenes/textured_env.sdf"]
REF_SPP = {"castle.sdf": 2048}  # the others 1024, as bench/denoise_study.py


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def reference(args, scene, work):
    ref_args = argparse.Namespace(converge=True, cache=args.cache, work=work, sdfc=args.sdfc,
                                  ref_spp=REF_SPP.get(os.path.basename(scene), 1024), reuse_refs=False)
    return run.reference(ref_args, scene, args.size)


def errors(img, ref):
    return sb.relmse(img, ref), flip.mean_flip(img, ref)


def end_to_end(binary, scene, out, env):
    start = time.perf_counter()
    proc = subprocess.run([binary, "render", scene, "-o", out], stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True, env=env)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"{binary} render {scene} failed:\n{proc.stderr}")
    return wall, proc.stderr


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--tool", default=os.path.join(ROOT, "build", "bench", "denoise_speed", "sdfc_denoise_speed"))
    p.add_argument("--old-sdfc", help="sdfc built at ab4eac1, for part 2 (skipped without)")
    p.add_argument("--scenes", nargs="+", default=[os.path.join(ROOT, s) for s in CORPUS])
    p.add_argument("--size", default="640x360")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--e2e-reps", type=int, default=5)
    p.add_argument("--no-warmup", action="store_true", help="part 2 without the warm-up runs")
    p.add_argument("--e2e-scenes", nargs="+", default=[os.path.join(ROOT, s) for s in
                                                       ("bench/scenes/hello.sdf", "examples/castle.sdf")])
    p.add_argument("--cache", default=os.path.join(HERE, "cache"))
    p.add_argument("--out", default=HERE)
    args = p.parse_args()
    start = time.time()
    load_start = os.getloadavg()[0]
    work = tempfile.mkdtemp(prefix="denoise_speed_")
    rows = []
    for scene in args.scenes:
        name = os.path.basename(scene)
        ref, _ = reference(args, scene, work)
        out = os.path.join(work, name)
        os.makedirs(out, exist_ok=True)
        proc = subprocess.run([args.tool, scene, "--size", args.size, "--spp", str(args.spp),
                               "--reps", str(args.reps), "--out", out], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"{args.tool} {scene} failed:\n{proc.stderr}")
        t = json.loads(proc.stdout.strip().splitlines()[-1])
        row = {"scene": name, "size": args.size, "spp": t["spp"], "threads": t["threads"]}
        for image in ("raw", "legacy", "nlr", "svgf"):
            rel, fl = errors(sb.read_pfm(os.path.join(out, image + ".pfm")), ref)
            row[f"{image}_relmse"], row[f"{image}_flip"] = rel, fl
        for d in ("legacy", "nlr", "svgf"):
            row[f"{d}_ms"] = t[f"median_{d}_ms"]
            row[f"{d}_cpu_ms"] = t[f"median_{d}_cpu_ms"]
            row[f"{d}_runs_ms"] = t[f"{d}_ms"]
        row["max_rel_diff"] = t["max_rel_diff"]
        rows.append(row)
        log(f"{name:20s} nlr {row['legacy_ms']:.0f} -> {row['nlr_ms']:.0f} ms wall, "
            f"{row['legacy_cpu_ms']:.0f} -> {row['nlr_cpu_ms']:.0f} CPU ms; relMSE "
            f"{row['legacy_relmse']:.4g} -> {row['nlr_relmse']:.4g}, FLIP {row['legacy_flip']:.4f} -> "
            f"{row['nlr_flip']:.4f}")

    e2e = []
    if args.old_sdfc:
        env = dict(os.environ)
        for scene in args.e2e_scenes:
            name = os.path.basename(scene)
            ref, _ = reference(args, scene, work)
            walls = {"ab4eac1": [], "now": []}
            rel = {}
            binaries = {"ab4eac1": args.old_sdfc, "now": args.sdfc}
            for label, binary in binaries.items():  # warm-up: caches, page cache
                if not args.no_warmup:
                    end_to_end(binary, scene, os.path.join(work, "warm.png"), env)
            for _ in range(args.e2e_reps):
                for label, binary in binaries.items():
                    wall, _ = end_to_end(binary, scene, os.path.join(work, f"e2e_{label}.png"), env)
                    walls[label].append(wall)
            for label, binary in binaries.items():  # the same image, as floats
                end_to_end(binary, scene, os.path.join(work, f"e2e_{label}.pfm"), env)
                rel[label] = sb.relmse(sb.read_pfm(os.path.join(work, f"e2e_{label}.pfm")), ref)
            for label in binaries:
                e2e.append({"scene": name, "binary": label, "median_wall_s": statistics.median(walls[label]),
                            "runs_s": walls[label], "relmse": rel[label]})
                log(f"{name:20s} default render, {label}: {statistics.median(walls[label]):.2f} s "
                    f"(runs {', '.join(f'{w:.2f}' for w in walls[label])}), relMSE {rel[label]:.3g}")

    os.makedirs(os.path.join(args.out, "results"), exist_ok=True)
    with open(os.path.join(args.out, "results", "denoise_speed.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    load = os.getloadavg()[0]
    cmd = " ".join(a.replace(ROOT + os.sep, "") for a in sys.argv[1:])
    lines = [f"# The denoiser's cost and error at {args.size}, {args.spp} spp: nlr before and after issue 48", "",
             f"Generated by `bench/denoise_speed.py {cmd}` in {(time.time() - start) / 60:.1f} min, "
             f"{rows[0]['threads']} hardware threads, load average {load_start:.1f} at the start and "
             f"{load:.1f} at the end (the machine is shared: wall times are inflated by the load; CPU "
             "times are the filter's own). Data: results/denoise_speed.csv.", "",
             "## The filter alone, on the same input in one process", "",
             "`legacy` is nlr as it was at ab4eac1 (bench/denoise_speed/legacy_nlm.cpp), `nlr` the "
             f"runtime's; medians of {args.reps} interleaved runs. relMSE and FLIP against the converged "
             "reference (castle 2048 spp, the others 1024); `raw` is the samples' mean.", "",
             "| scene | legacy nlr ms (CPU ms) | nlr ms (CPU ms) | svgf ms (CPU ms) | largest difference legacy/nlr (relative) | "
             "relMSE raw | legacy | nlr | svgf | FLIP raw | legacy | nlr | svgf |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['legacy_ms']:.0f} ({r['legacy_cpu_ms']:.0f}) | {r['nlr_ms']:.0f} "
                     f"({r['nlr_cpu_ms']:.0f}) | {r['svgf_ms']:.0f} ({r['svgf_cpu_ms']:.0f}) | "
                     f"{r['max_rel_diff']:.2g} | {r['raw_relmse']:.3g} | {r['legacy_relmse']:.4g} | "
                     f"{r['nlr_relmse']:.4g} | {r['svgf_relmse']:.3g} | {r['raw_flip']:.4f} | "
                     f"{r['legacy_flip']:.5f} | {r['nlr_flip']:.5f} | {r['svgf_flip']:.4f} |")
    if e2e:
        lines += ["", "## Start to PNG, default settings", "",
                  f"`sdfc render SCENE -o x` (the scene's own size and spp, nlr), {args.e2e_reps} runs of each "
                  "binary interleaved" + (" (the caches warm from earlier runs)" if args.no_warmup else
                                         " after a warm-up each (caches warm)") +
                  ", writing the PNG; relMSE of one more run's image written as PFM.", "",
                  "| scene | binary | wall s (median) | runs | relMSE |", "|---|---|---|---|---|"]
        lines += [f"| {e['scene']} | {e['binary']} | {e['median_wall_s']:.2f} | "
                  f"{', '.join(f'{w:.2f}' for w in e['runs_s'])} | {e['relmse']:.3g} |" for e in e2e]
    with open(os.path.join(args.out, "results", "DENOISE_SPEED.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
