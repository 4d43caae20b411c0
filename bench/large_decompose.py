#!/usr/bin/python3
"""Where a point cloud's render time goes (docs/design/large_scenes.md, "Decomposition"):
per pixel and sample, how many ray segments of each kind (primary, bounce,
shadow), how many shading events (hits on the cloud that compute a normal), and
per segment the march loop iterations, grid lookups, list entries and hierarchy
visits, counted by the kernel itself (`sdfc render --view iterations
--count-event KIND.QUANTITY`, 640x360, 1 spp, 3 bounces, 1 light sample).

  bench/large_decompose.py [--sdfc build/cli/sdfc] [--before OLD_SDFC] [--counts 100,100000]
                           [--out bench/results/large_decompose.md] [--cpu-repeats 3]

The scenes are bench/large_scenes.py's (same points, radii and camera). With
--cpu-repeats N it also takes the median CPU ms per sample of each scene (user +
sys, (9 spp - 1 spp) / 8, counts interleaved) for the cost per march iteration.
With --before OLD_SDFC (a build with --count-event) the same tables for it,
CPU times interleaved with this binary's.
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import large_scenes as ls  # noqa: E402

KINDS = ("primary", "bounce", "shadow", "normal")
QUANTITIES = ("segments", "iterations", "lookups", "entries", "visits", "hits")


def count(sdfc, scene, dir_, event):
    png = os.path.join(dir_, "count.pfm")
    proc = subprocess.run([sdfc, "render", scene, "-o", png, "--size", "640x360", "--spp", "1", "--view",
                           "iterations", "--count-event", event], capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-2000:])
    return (ls.field(r"%s per pixel: mean ([0-9.eE+-]+)" % event.replace(".", r"\."), proc.stderr),
            ls.field(r"loop iterations per pixel: mean ([0-9.eE+-]+)", proc.stderr))


def tables(label, figures, total_iterations, cpu, counts):
    lines = ["## " + label, "",
             "| instances | ray kind | segments / pixel | hits / segment | loop iterations / segment | "
             "lookups / segment | list entries / lookup | hierarchy visits / segment |",
             "|---:|---|---:|---:|---:|---:|---:|---:|"]
    for c in counts:
        for k in KINDS:
            g = {q: figures.get((c, k, q), float("nan")) for q in QUANTITIES}
            seg = g["segments"] or float("nan")
            lines.append("| %d | %s | %.3f | %s | %.2f | %.2f | %.2f | %.3f |" % (
                c, k + (" (shading events)" if k == "normal" else ""), g["segments"],
                "%.3f" % (g["hits"] / seg) if k != "normal" else "", g["iterations"] / seg, g["lookups"] / seg,
                g["entries"] / max(g["lookups"], 1e-30), g["visits"] / seg))
    lines.append("")
    lines.append("| instances | segments / pixel (all kinds) | shading events / pixel | march + normal iterations "
                 "/ pixel | lookups / pixel | list entries / pixel | visits / pixel | loop iterations / pixel "
                 "(all loops) | CPU ms / sample (median) | runs |")
    lines.append("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for c in counts:
        s = lambda q, ks=KINDS: sum(figures.get((c, k, q), 0.0) for k in ks)  # noqa: E731
        lines.append("| %d | %.3f | %.3f | %.2f | %.2f | %.2f | %.2f | %.2f | %s | %s |" % (
            c, s("segments", KINDS[:3]), figures[(c, "normal", "segments")], s("iterations"), s("lookups"),
            s("entries"), s("visits"), total_iterations[c],
            "%.0f" % statistics.median(cpu[c]) if cpu[c] else "", ", ".join("%.0f" % x for x in cpu[c])))
    lines.append("")
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(os.path.dirname(__file__), "..", "build", "cli", "sdfc"))
    ap.add_argument("--before", help="an older sdfc (with --count-event) for the same tables, CPU interleaved")
    ap.add_argument("--counts", default="100,100000")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "results", "large_decompose.md"))
    ap.add_argument("--cpu-repeats", type=int, default=3)
    ap.add_argument("--dir", default="/tmp/sdfc_large_scenes")
    args = ap.parse_args()
    os.makedirs(args.dir, exist_ok=True)
    counts = [int(c) for c in args.counts.split(",")]
    scenes = {c: ls.write_instanced(args.dir, c) for c in counts}
    binaries = [os.path.normpath(b) for b in ([args.before] if args.before else []) + [args.sdfc]]
    figures = {b: {} for b in binaries}
    total_iterations = {b: {} for b in binaries}
    for b in binaries:
        for c in counts:
            for k in KINDS:
                for q in QUANTITIES:
                    if k == "normal" and q == "hits":
                        continue
                    figures[b][(c, k, q)], total_iterations[b][c] = count(b, scenes[c], args.dir, "%s.%s" % (k, q))
            print("counted %d with %s" % (c, b), file=sys.stderr)
    cpu = {b: {c: [] for c in counts} for b in binaries}
    for r in range(args.cpu_repeats):
        for c in counts:
            for b in (binaries if r % 2 == 0 else binaries[::-1]):
                cpu[b][c].append(ls.cpu_ms_per_sample(b, scenes[c], args.dir))
    lines = ["# Where a point cloud's time goes", "",
             "Generated by `bench/large_decompose.py` on %s: kernel event counts (`--count-event`), "
             "640x360, 1 spp, 3 bounces, 1 light sample; per pixel (one path each). Load (uptime) at the end: %.1f." %
             (time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), os.getloadavg()[0]), ""]
    for b in binaries:
        lines += tables(("before: " if b == binaries[0] and len(binaries) > 1 else "") + b, figures[b],
                        total_iterations[b], cpu[b], counts)
    text = "\n".join(lines)
    with open(args.out, "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
