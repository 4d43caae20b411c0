#!/usr/bin/python3
"""What one evaluation of each kind of part costs the kernel, in boxes: the
units of the analysis's cost model (compiler/passes/analyze.cpp), which the
bounding-volume plan weighs against a check's cost.

    /usr/bin/python3 bench/primitive_cost.py [--sdfc build/cli/sdfc] [--reps 5]
        [--size 640x360] [--out bench/results/primitive_cost.md]

Each scene is the same sphere on a plane with 24 copies of one part placed
60 units below the plane, where no ray goes: they lengthen no step and
shorten none (every scene marches the same iterations, checked), yet every
step evaluates all 24 (--no-bounds, and no instancing). A 96-box scene less
the 24-box one gives the cost of 72 boxes; a part's cost is its scene's
sampling CPU less what the 24-box scene spends besides its boxes, over 24 boxes'. Sampling CPU per sample = (process CPU at 9 spp -
at 1 spp) / 8, the scenes interleaved rep by rep, medians.
"""
import argparse
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

HEAD = """render(size: [320, 180], spp: 8, bounces: 3)
camera(position: [0, 1, 5], target: [0, 0, 0], fov: 40)
sun(direction: [-0.5, 1, 0.4], angle: 3, strength: 2.5)
scene {
  sphere(radius: 1)
  plane(offset: -1)
"""
BASE7 = "[0, 0], [0.34, 0], [0.34, 0.06], [0.28, 0.1], [0.3, 0.14], [0.2, 0.18], [0, 0.18]"
BASE13 = BASE7[:-len(", [0, 0.18]")] + \
    ", [0.22, 0.2], [0.18, 0.24], [0.2, 0.26], [0.15, 0.3], [0.17, 0.33], [0.1, 0.36], [0, 0.36]"
# name: (part, what the model counts it, from analyze.cpp)
PARTS = {
    "box": ("box(size: [0.3, 0.3, 0.3])", "1"),
    "sphere": ("sphere(radius: 0.2)", "1"),
    "ellipsoid": ("ellipsoid(radii: [0.13, 0.2, 0.13])", "1"),
    "cylinder": ("cylinder(radius: 0.15, height: 0.1)", "1"),
    "torus": ("torus(major: 0.2, minor: 0.05)", "1"),
    "capsule": ("capsule(radius: 0.05, height: 0.3)", "1"),
    "revolved polygon, 7 points": ("revolve { polygon(points: [%s]) }" % BASE7, "cost per point x 7 + 0.2"),
    "revolved polygon, 13 points": ("revolve { polygon(points: [%s]) }" % BASE13, "cost per point x 13 + 0.2"),
    "menger level 1": ("menger(level: 1, size: 0.3)", "4"),
    "menger level 2": ("menger(level: 2, size: 0.3)", "6"),
}


def scene_text(part, copies=24, rows=1):
    body = ""
    for r in range(rows):
        for i in range(copies):
            # Distinct places, so no two copies share arithmetic.
            body += "  translate([%g, %g, %g]) { %s }\n" % ((i % 6) * 0.9, -60 - r, (i // 6) * 0.9, part)
    return HEAD + body + "}\n"


def cpu_ms(sdfc, scene, size, spp):
    out = tempfile.mktemp(suffix=".pfm")
    cmd = [sdfc, "render", scene, "-o", out, "--size", size, "--spp", str(spp), "--denoise", "none",
           "--no-bounds", "--instance-threshold", "100000"]
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         env=dict(os.environ, GALLIVM_PERF=""))
    _, status, usage = os.wait4(p.pid, 0)
    err = p.stderr.read().decode()
    if status != 0:
        sys.exit("render failed: %s\n%s" % (" ".join(cmd), err[-2000:]))
    if os.path.exists(out):
        os.unlink(out)
    return (usage.ru_utime + usage.ru_stime) * 1000


def iterations(sdfc, scene):
    out = tempfile.mktemp(suffix=".pfm")
    proc = subprocess.run([sdfc, "render", scene, "-o", out, "--size", "160x90", "--spp", "1", "--view",
                           "iterations", "--no-bounds", "--instance-threshold", "100000"],
                          capture_output=True, text=True)
    if os.path.exists(out):
        os.unlink(out)
    m = re.search(r"loop iterations per pixel: mean ([0-9.]+)", proc.stderr)
    return float(m.group(1)) if m else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "primitive_cost.md"))
    args = ap.parse_args()
    start = time.time()
    work = tempfile.mkdtemp(prefix="primitive_cost_")
    scenes = {"96 boxes": os.path.join(work, "boxes96.sdf")}
    with open(scenes["96 boxes"], "w") as f:
        f.write(scene_text(PARTS["box"][0], rows=4))
    for name, (part, _) in PARTS.items():
        scenes[name] = os.path.join(work, re.sub(r"[^a-z0-9]+", "_", name) + ".sdf")
        with open(scenes[name], "w") as f:
            f.write(scene_text(part))
    its = {name: iterations(args.sdfc, path) for name, path in scenes.items()}
    if len(set(its.values())) != 1:
        sys.exit("the scenes march different iterations (%s): the parts are not out of reach" % its)
    for path in scenes.values():  # warm the SPIR-V and shader caches
        cpu_ms(args.sdfc, path, args.size, 1)
    samples = {name: [] for name in scenes}
    for rep in range(args.reps):
        for name, path in scenes.items():
            hi = cpu_ms(args.sdfc, path, args.size, 9)
            lo = cpu_ms(args.sdfc, path, args.size, 1)
            samples[name].append((hi - lo) / 8)
        print("rep %d/%d done" % (rep + 1, args.reps), file=sys.stderr, flush=True)
    med = {name: statistics.median(v) for name, v in samples.items()}
    box = (med["96 boxes"] - med["box"]) / 72
    lines = ["# What a part costs the kernel, in boxes (bench/primitive_cost.py)", "",
             "Generated by `bench/primitive_cost.py` in %.1f min on %s. %s, %d reps interleaved, medians; "
             "every scene marches %.2f loop iterations a pixel." % (
                 (time.time() - start) / 60, sb.machine_info(args.sdfc).get("cpu", "?"), args.size, args.reps,
                 next(iter(its.values()))), "",
             "24 copies of the part sit where no ray reaches, and every step evaluates them all. "
             "24 boxes cost %.2f CPU ms a sample (a third of the 96-box scene less the 24-box one)." % (24 * box),
             "", "| part | CPU ms a sample (24 copies and the rest) | cost in boxes | the model counts |",
             "|---|---|---|---|"]
    rest = med["box"] - 24 * box
    for name, (_, model) in PARTS.items():
        cost = (med[name] - rest) / 24 / box if box > 0 else float("nan")
        lines.append("| %s | %.1f (%s) | %.2f | %s |" % (name, med[name], ", ".join("%.0f" % x for x in samples[name]),
                                                   cost, model))
    lines.append("| 96 boxes | %.1f (%s) | | |" % (med["96 boxes"], ", ".join("%.0f" % x for x in samples["96 boxes"])))
    text = "\n".join(lines) + "\n"
    print(text)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
