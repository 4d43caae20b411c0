#!/usr/bin/env python3
"""What instance groups cost before the first sample (issue 29): scenes of 1, 2
and 4 groups of 400 instances each (boxes, spheres, tori, cylinders: one shape
per group, positions from a fixed seed), Mesa's shader cache off.

Per round, the group counts in alternating order (so each shares the machine's
load with the others):
  - the kernel `sdfc view` builds, drawn by build/bench/first_draw/sdfc_first_draw
    at 1x1: lavapipe's LLVM compile at the first draw, in process CPU ms (robust
    to load) and wall ms;
  - `sdfc render --size 64x36 --spp 1 --no-cache --timings`: the whole process
    and its "first draw (driver's kernel compile)" stage, wall ms.
Medians over the rounds, and each figure over one group's. Writes the table
of bench/results/instance_groups.md (and prints it), keeping its notes.

Usage: /usr/bin/python3 bench/instance_groups.py [--sdfc build/cli/sdfc]
           [--first-draw build/bench/first_draw/sdfc_first_draw] [--rounds 3]
           [--groups 1 2 4] [--out bench/results/instance_groups.md]
"""
import argparse
import json
import os
import random
import re
import statistics
import subprocess
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SHAPES = ["box(size: [0.3, 0.3, 0.3])", "sphere(radius: 0.2)", "torus(major: 0.2, minor: 0.06)",
          "cylinder(radius: 0.12, height: 0.4)"]


def scene_text(groups):
    rng = random.Random(1)
    lines = ["camera(position: [0, 6, 14], target: [0, 0, 0])", "scene {",
             "  plane(normal: [0, 1, 0], offset: 0)"]
    for g in range(groups):
        points = ", ".join(f"[{rng.uniform(-6, 6):.2f}, {rng.uniform(0.2, 3):.2f}, {rng.uniform(-6, 6):.2f}]"
                           for _ in range(400))
        lines.append(f"  instances(positions: [{points}]) {{ {SHAPES[g % len(SHAPES)]} }}")
    lines.append("}")
    return "\n".join(lines) + "\n"


def env():
    e = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true")
    e.pop("SDFC_VALIDATION", None)
    return e


def first_draw(tool, scene):
    r = subprocess.run([tool, scene, "--reps", "1", "--size", "1x1"], capture_output=True, text=True,
                       env=env(), timeout=900)
    if r.returncode != 0:
        # Its draws wait at most 60 s (the renderer's pass timeout): a big
        # kernel on a loaded machine can take longer. `render` waits 600 s.
        print(f"sdfc_first_draw failed: {r.stderr.strip()}")
        return float("nan"), float("nan")
    j = json.loads(r.stdout)["sizes"][0]
    return j["draw1_cpu_ms"][0], j["draw1_ms"][0]


def render(sdfc, scene, out):
    r = subprocess.run([sdfc, "render", scene, "-o", out, "--size", "64x36", "--spp", "1", "--no-cache",
                        "--timings"], capture_output=True, text=True, env=env(), timeout=900)
    if r.returncode != 0:
        raise SystemExit(f"sdfc render failed: {r.stderr}")
    stage = float(re.search(r"first draw \(driver's kernel compile\)\s+([0-9.]+)", r.stderr).group(1))
    total = float(re.search(r"total \(process start to exit\)\s+([0-9.]+)", r.stderr).group(1))
    return stage, total


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build/cli/sdfc"))
    ap.add_argument("--first-draw", default=os.path.join(ROOT, "build/bench/first_draw/sdfc_first_draw"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--groups", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--out", default=os.path.join(HERE, "results/instance_groups.md"))
    a = ap.parse_args()
    figures = {g: {"jit_cpu": [], "jit_wall": [], "stage": [], "total": []} for g in a.groups}
    loads = [os.getloadavg()[0]]
    start = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    with tempfile.TemporaryDirectory() as d:
        scenes = {}
        for g in a.groups:
            scenes[g] = os.path.join(d, f"groups{g}.sdf")
            open(scenes[g], "w").write(scene_text(g))
        for rnd in range(a.rounds):
            order = a.groups if rnd % 2 == 0 else list(reversed(a.groups))
            for g in order:
                cpu, wall = first_draw(a.first_draw, scenes[g])
                stage, total = render(a.sdfc, scenes[g], os.path.join(d, "out.png"))
                f = figures[g]
                f["jit_cpu"].append(cpu)
                f["jit_wall"].append(wall)
                f["stage"].append(stage)
                f["total"].append(total)
                print(f"round {rnd + 1} groups {g}: first draw {cpu:.0f} CPU ms ({wall:.0f} wall), "
                      f"render first-draw stage {stage:.0f} ms, whole process {total:.0f} ms", flush=True)
            loads.append(os.getloadavg()[0])
    def median(values):
        ok = [v for v in values if v == v]  # the timed-out runs left out
        return statistics.median(ok) if ok else float("nan")
    med = {g: {k: median(v) for k, v in f.items()} for g, f in figures.items()}
    base = med[a.groups[0]]
    rows = [f"# Instance groups before the first sample (bench/instance_groups.py)", "",
            f"{start}; {a.rounds} rounds, group counts alternating; load average "
            f"{min(loads):.1f}-{max(loads):.1f}; Mesa's shader cache off; each group 400 instances of "
            "one shape (box, sphere, torus, cylinder). Medians; x = over one group's; nan: every "
            "sdfc_first_draw run of it timed out (60 s).", "",
            "| groups | first draw, CPU ms | x | first draw, wall ms | `render` first-draw stage, ms | x | "
            "`render` 64x36 1 spp, whole process ms | x |",
            "|---|---|---|---|---|---|---|---|"]
    for g in a.groups:
        m = med[g]
        rows.append(f"| {g} | {m['jit_cpu']:.0f} | {m['jit_cpu'] / base['jit_cpu']:.2f} | {m['jit_wall']:.0f} | "
                    f"{m['stage']:.0f} | {m['stage'] / base['stage']:.2f} | {m['total']:.0f} | "
                    f"{m['total'] / base['total']:.2f} |")
    text = "\n".join(rows) + "\n"
    print(text)
    # The hand-written notes below the table (from "## Notes" on) are kept.
    notes = ""
    if os.path.exists(a.out):
        old = open(a.out).read()
        if "\n## Notes" in old:
            notes = "\n" + old[old.index("\n## Notes") + 1:]
    with open(a.out, "w") as out:
        out.write(text + notes)


if __name__ == "__main__":
    main()
