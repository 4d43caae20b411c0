#!/usr/bin/python3
"""Where a march step's time goes in the many-parts families (issue 46): per
family and count, the kernel's event counts per pixel (`--view iterations
--count-event all.QUANTITY`, 1 spp) and the set's grid line from `--emit ir`,
beside the sampling's CPU ms per sample (bench/many_parts.py's measure).

  bench/many_parts_steps.py [--sdfc build/cli/sdfc] [--families kitbash,boxbash]
                            [--counts 10,100,1000,10000] [--smooth 0.05]
                            [--size 320x180] [--spp 8] [--repeats 3]
                            [--out bench/results/many_parts_steps.md]
                            [--flags "--instance-threshold 2"]

--flags go to every compile and render: `--instance-threshold 2` puts even
10 parts in a set (data, a blend grid), `--instance-threshold 0` keeps every
count inline code, which separates the data path's cost from the count's.

Columns: march segments (all rays: primary, shadow, bounce) per pixel; grid
lookups per segment; list entries per lookup (the length of the lists the
rays reach, which a blend grid evaluates whole); CPU ms per sample; and that
over the segments: ns per segment, the per-step cost the part count changes.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import many_parts_scenes as mps  # noqa: E402
import sdfbench as sb  # noqa: E402

QUANTITIES = ("segments", "lookups", "entries")


def count(sdfc, scene, out, size, event, flags):
    proc = subprocess.run([sdfc, "render", scene, "-o", out, "--size", size, "--spp", "1", "--view", "iterations",
                           "--count-event", event, "-Wno-bound"] + flags, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-2000:])
    m = re.search(r"%s per pixel: mean ([0-9.eE+-]+)" % re.escape(event), proc.stderr)
    return float(m.group(1)) if m else float("nan")


def sampling(sdfc, scene, out, size, spp, flags):
    """CPU ms per sample: the process's at spp less a 1 spp run's (bench/many_parts.py)."""
    full = sb.render(sdfc, scene, out, ["--size", size, "--spp", str(spp), "-Wno-bound"] + flags)
    one = sb.render(sdfc, scene, out, ["--size", size, "--spp", "1", "-Wno-bound"] + flags)
    return 1000 * (full["cpu_s"] - one["cpu_s"]) / (spp - 1)


def grid_line(sdfc, scene, flags):
    ir = sb.compile_text(sdfc, scene, "ir", flags)
    m = re.search(r"grid [0-9x]+ cells of [^;)]*", ir)
    return m.group(0) if m else "no grid (inline code)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--families", default="kitbash,boxbash")
    ap.add_argument("--counts", default="10,100,1000,10000")
    ap.add_argument("--smooth", type=float, default=0.05)
    ap.add_argument("--size", default="320x180")
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--framing", choices=mps.FRAMINGS, default="sphere")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "many_parts_steps.md"))
    ap.add_argument("--flags", default="", help="more sdfc flags for every compile and render")
    args = ap.parse_args()
    flags = args.flags.split()
    w, h = (int(x) for x in args.size.split("x"))
    lines = ["# Where a step's time goes (bench/many_parts_steps.py)", "",
             f"{args.size}, {args.framing} framing, smooth {args.smooth}; event counts from a 1 spp "
             f"`--view iterations --count-event all.*` render, CPU ms per sample as bench/many_parts.py "
             f"({args.spp} spp less 1 spp, median of {args.repeats}, after a warm-up render)"
             + (f"; flags `{args.flags}`" if flags else "") + ".", "",
             "| family | parts | grid | segments / px | lookups / segment | entries / lookup | "
             "CPU ms / sample | ns / segment |",
             "|---|---:|---|---:|---:|---:|---:|---:|"]
    print("\n".join(lines), flush=True)
    with tempfile.TemporaryDirectory(prefix="many_parts_steps_") as dir_:
        for fam in args.families.split(","):
            for n in (int(c) for c in args.counts.split(",")):
                scene = os.path.join(dir_, f"{fam}_{n}.sdf")
                with open(scene, "w") as f:
                    f.write(mps.scene(fam, n, args.smooth, framing=args.framing))
                out = os.path.join(dir_, "c.pfm")
                g = {q: count(args.sdfc, scene, out, args.size, "all." + q, flags) for q in QUANTITIES}
                # The warm-up: both runs of a repeat then hit Mesa's shader cache.
                sb.render(args.sdfc, scene, out, ["--size", args.size, "--spp", "1", "-Wno-bound"] + flags)
                ms = statistics.median(sampling(args.sdfc, scene, out, args.size, args.spp, flags)
                                       for _ in range(args.repeats))
                seg = g["segments"]
                line = (f"| {fam} | {n} | {grid_line(args.sdfc, scene, flags)} | {seg:.2f} | "
                        f"{g['lookups'] / seg:.2f} | {g['entries'] / max(g['lookups'], 1e-30):.2f} | {ms:.1f} | "
                        f"{1e6 * ms / (seg * w * h):.0f} |")
                print(line, flush=True)
                lines.append(line)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
