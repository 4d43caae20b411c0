#!/usr/bin/env python3
"""Render-farm figures for docs/farm.md, written to bench/results/FARM.md:

1. Per-shard overhead (process start, Vulkan context, compile, pipeline creation,
   shard write) against render time, for shards of a few samples of a 1080p castle
   job, and the shard size at which overhead stays under 2%.
2. `sdfc merge` time and peak memory for 64 shards at 1920x1080 (synthetic sums
   written by the real shard writer, build/farm/farm_synthetic_shards).
3. A projection, from those figures, of a 240-frame 1080p 256-spp animation on
   1, 10 and 100 nodes like this machine, with the arithmetic.

    /usr/bin/python3 bench/farm_bench.py [--sdfc build/cli/sdfc] [--reps 3]

About 5 minutes on the 2-CPU lavapipe machine (most of it 1080p rendering).
"""
import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sdfbench import machine_info  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARD_LINE = re.compile(r"compile (\d+) ms, pipeline (\d+) ms, render (\d+) ms, write (\d+) ms")


def run_shard(sdfc, scene, size, job_spp, samples, out_dir):
    """One real shard (index 0) of a job cut into job_spp/samples shards; seconds."""
    shards = job_spp // samples
    start = time.perf_counter()
    proc = subprocess.run([sdfc, "render", scene, "--size", size, "--spp", str(job_spp),
                           "--shards", str(shards), "--shard-index", "0", "-o", out_dir],
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    m = SHARD_LINE.search(proc.stderr)
    if proc.returncode != 0 or not m:
        sys.exit(f"shard failed ({proc.returncode}): {proc.stderr}")
    compile_s, pipeline_s, render_s, write_s = (int(x) / 1000 for x in m.groups())
    for name in os.listdir(out_dir):
        os.remove(os.path.join(out_dir, name))
    return {"wall": wall, "compile": compile_s, "pipeline": pipeline_s, "render": render_s,
            "write": write_s, "start": wall - compile_s - pipeline_s - render_s - write_s}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build/cli/sdfc"))
    ap.add_argument("--synth", default=os.path.join(ROOT, "build/farm/farm_synthetic_shards"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples/castle.sdf"))
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--job-spp", type=int, default=256)
    ap.add_argument("--samples", type=int, nargs="+", default=[1, 2, 4],
                    help="shard sizes (samples per pixel per shard) to time")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--merge-shards", type=int, default=64)
    ap.add_argument("--out", default=os.path.join(ROOT, "bench/results/FARM.md"))
    args = ap.parse_args()
    machine = machine_info(args.sdfc)
    lines = []

    def say(text=""):
        print(text, flush=True)
        lines.append(text)

    # ------------------------------------------------------------ 1. overhead
    runs = {s: [] for s in args.samples}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.reps):
            for s in args.samples:  # interleaved, so machine load hits every size alike
                runs[s].append(run_shard(args.sdfc, args.scene, args.size, args.job_spp, s, tmp))
    med = {s: {k: statistics.median(r[k] for r in runs[s]) for k in runs[s][0]} for s in args.samples}
    every = [r for s in args.samples for r in runs[s]]
    overhead = statistics.median(r["wall"] - r["render"] for r in every)
    parts = {k: statistics.median(r[k] for r in every) for k in ("start", "compile", "pipeline", "write")}
    per_sample = statistics.median(r["render"] / s for s in args.samples for r in runs[s])
    # overhead / (overhead + n * per_sample) < 0.02  <=>  n > 49 * overhead / per_sample
    n_2pct = math.floor(49 * overhead / per_sample) + 1

    say("# Render farm figures")
    say()
    say(f"Written by `bench/farm_bench.py` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}. "
        f"Machine: {machine['cpu']}, {machine['cores']} CPUs, {machine['device']} ({machine['driver']}); "
        f"LP_NUM_THREADS {machine['lp_num_threads']}. The machine is shared with other jobs, so "
        f"figures are medians of {args.reps} interleaved runs.")
    say()
    say(f"## 1. Per-shard overhead against render time")
    say()
    say(f"Shard 0 of `{os.path.relpath(args.scene, ROOT)}` at {args.size}, a {args.job_spp}-spp job "
        f"(at 1920x1080 a pass is 1 sample, so any sample count is a valid shard). Overhead = process wall "
        f"time - render time: process start and Vulkan context, compile, pipeline creation, "
        f"shard write (EXR with 128-bit sums, ZIP).")
    say()
    say("| spp per shard | wall s | render s | start+context s | compile s | pipeline s | write s | overhead share |")
    say("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for s in args.samples:
        m = med[s]
        say(f"| {s} | {m['wall']:.2f} | {m['render']:.2f} | {m['start']:.2f} | {m['compile']:.2f} | "
            f"{m['pipeline']:.2f} | {m['write']:.2f} | {100 * (m['wall'] - m['render']) / m['wall']:.0f}% |")
    say()
    say(f"Median over all runs: overhead **{overhead:.2f} s** per shard (start+context {parts['start']:.2f}, "
        f"compile {parts['compile']:.2f}, pipeline {parts['pipeline']:.2f}, write {parts['write']:.2f}); "
        f"render **{per_sample:.2f} s per spp** at {args.size}.")
    say(f"Overhead stays under 2% when overhead / (overhead + n x {per_sample:.2f} s) < 0.02, i.e. "
        f"n > 49 x {overhead:.2f} / {per_sample:.2f} = {49 * overhead / per_sample:.1f}: "
        f"**shards of at least {n_2pct} spp** ({n_2pct * per_sample / 60:.1f} min of rendering each) "
        f"at {args.size} on this machine. The threshold scales with image size only through the "
        f"write (compile and pipeline creation do not depend on it).")
    say()

    # ------------------------------------------------------------ 2. merge
    with tempfile.TemporaryDirectory() as tmp:
        shard_dir = os.path.join(tmp, "shards")
        width, height = args.size.split("x")
        synth = subprocess.run([args.synth, shard_dir, width, height, str(args.merge_shards)],
                               capture_output=True, text=True, check=True)
        write_ms = float(synth.stdout.strip())
        total_bytes = sum(os.path.getsize(os.path.join(shard_dir, f)) for f in os.listdir(shard_dir))
        merges = []
        for _ in range(max(1, min(args.reps, 2))):
            proc = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M", args.sdfc, "merge", shard_dir,
                                   "-o", os.path.join(tmp, "merged.exr")], capture_output=True, text=True)
            m = re.search(r"TIME ([0-9.]+) (\d+)", proc.stderr)
            if proc.returncode != 0 or not m:
                sys.exit(f"merge failed: {proc.stderr}")
            merges.append((float(m.group(1)), int(m.group(2)) / 1024))
    merge_s = statistics.median(x[0] for x in merges)
    merge_mib = max(x[1] for x in merges)
    per_shard_merge = merge_s / args.merge_shards
    say(f"## 2. Merge: {args.merge_shards} shards at {args.size}")
    say()
    say(f"Synthetic shards (pseudo-random radiance in [0, 2), one sample each) written by the real shard "
        f"writer: {total_bytes / args.merge_shards / 2**20:.1f} MiB per shard, "
        f"{total_bytes / 2**30:.2f} GiB in all; median write {write_ms / 1000:.2f} s per shard. "
        f"`sdfc merge` (checks every header, then adds one shard at a time): "
        f"**{merge_s:.1f} s** wall ({per_shard_merge:.2f} s per shard), **{merge_mib:.0f} MiB** peak "
        f"resident memory (`/usr/bin/time` max RSS; the sums of one frame take "
        f"{int(width) * int(height) * 48 / 2**20:.0f} MiB, one decoded shard about "
        f"{int(width) * int(height) * 60 / 2**20:.0f} MiB).")
    say()

    # ------------------------------------------------------------ 3. projection
    frames, spp = 240, 256
    frame_render = spp * per_sample
    say(f"## 3. Projection: {frames} frames, {args.size}, {spp} spp, castle")
    say()
    say(f"From the figures above: one frame is {spp} x {per_sample:.2f} s = {frame_render:.0f} s of "
        f"rendering on one node like this one (2 CPUs; lavapipe uses both, so one shard at a time per "
        f"node); every shard adds {overhead:.2f} s of overhead and {per_shard_merge:.2f} s to the merge "
        f"job, which runs on one node after the last shard. With k shards per frame and N nodes, the "
        f"{frames} x k shards run in ceil({frames} k / N) waves of ({frame_render:.0f} / k + "
        f"{overhead:.2f}) s. For each N, the k from 1, 2, 4, ..., 256 (a shard is at least one 1-sample "
        f"pass) with the shortest total:")
    say()
    say("| nodes | shards per frame k | waves | shard s | render phase | merge phase | total | node-hours | efficiency |")
    say("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    ideal = frames * frame_render
    for nodes in (1, 10, 100):
        best = None
        k = 1
        while k <= spp:
            waves = math.ceil(frames * k / nodes)
            shard = frame_render / k + overhead
            render_phase = waves * shard
            merge_phase = frames * k * per_shard_merge
            total = render_phase + merge_phase
            if best is None or total < best[-1]:
                best = (k, waves, shard, render_phase, merge_phase, total)
            k *= 2
        k, waves, shard, render_phase, merge_phase, total = best
        node_hours = (frames * k * shard) / 3600 + merge_phase / 3600
        say(f"| {nodes} | {k} | {waves} | {shard:.0f} | {render_phase / 3600:.2f} h | "
            f"{merge_phase / 60:.1f} min | **{total / 3600:.2f} h** ({total / 86400:.2f} d) | "
            f"{node_hours:.1f} | {100 * ideal / nodes / total:.0f}% |")
    say()
    say(f"Efficiency = ideal time ({frames} x {frame_render:.0f} s / N, no overhead, no merge) / total. "
        f"Arithmetic for one row, N = 10 with k = 1: ceil(240 x 1 / 10) = 24 waves of "
        f"({frame_render:.0f} + {overhead:.2f}) s = {24 * (frame_render + overhead) / 3600:.2f} h, plus a "
        f"merge of 240 x {per_shard_merge:.2f} s = {240 * per_shard_merge / 60:.1f} min. The merge is "
        f"serial in one job; at 100 nodes it is the part to split (one merge job per frame range) "
        f"before adding nodes.")
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
