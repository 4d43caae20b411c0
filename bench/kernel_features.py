#!/usr/bin/python3
"""A render nothing denoises: the kernel without AOV features and the readback of
only what is read (issue 36), against another binary (main's), stage by stage.

    bench/kernel_features.py --base MAIN_SDFC [--sdfc build/cli/sdfc] [--reps 5]
                             [--drivers bundled system] [--check-examples]
                             [--out bench/results/kernel_features.md]

Runs `sdfc render SCENE -o x.png --size 640x360 --spp 1 --timings` (nlr, the
default, does nothing at 1 spp, so this binary emits the featureless kernel) with
Mesa's shader cache off and sdfc's SPIR-V cache warm, alternating the two
binaries run by run (the order reversed every other repetition). Reports medians
of the stages the levers touch: the first draw (lavapipe's LLVM compile of the
kernel), the passes, the readback, and the process's CPU seconds.

The first draw by itself: bench/first_draw's sdfc_first_draw at 1x1 (nearly all
of it lavapipe's compile), the full and the featureless kernel (--no-aovs)
alternating, CPU ms, with LLVM unoptimised (GALLIVM_PERF=nopt, as `render` of
few samples) and optimised.

--check-examples: every example at 64x36, 2 spp, --denoise none, written as EXR
by both binaries on each driver, compared byte for byte.
"""
import argparse
import glob
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENES = {"sphere": os.path.join(ROOT, "examples", "diffuse_sphere.sdf"),
          "castle": os.path.join(ROOT, "examples", "castle.sdf")}
NOTES_MARK = "<!-- Below this line: kept as written when the script regenerates the tables. -->"
STAGES = ["first draw (driver's kernel compile)", "passes", "readback"]


def env_for(driver, cache):
    env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true", SDFC_DRIVER=driver, XDG_CACHE_HOME=cache)
    env.pop("SDFC_VALIDATION", None)
    env.pop("GALLIVM_PERF", None)
    return env


def timed_run(sdfc, scene, out, env):
    cmd = [sdfc, "render", scene, "-o", out, "--size", "640x360", "--spp", "1", "--timings"]
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        raise SystemExit(f"{' '.join(cmd)} exited {r.returncode}")
    stages = {}
    for m in re.finditer(r"^  (.+?)\s+(-?[0-9.]+)\s+(?:-?[0-9.]+%)?", r.stderr, re.M):
        stages[m.group(1).strip()] = float(m.group(2))
    stages["CPU s"] = (after.ru_utime - used.ru_utime) + (after.ru_stime - used.ru_stime)
    stages["wall s"] = wall
    return stages


def first_draw_cpu(tool, scene, driver, aovs, nopt, reps):
    env = env_for(driver, "/nonexistent")
    if nopt:
        env["GALLIVM_PERF"] = "nopt"
    cmd = [tool, scene, "--size", "1x1", "--reps", str(reps)] + ([] if aovs else ["--no-aovs"])
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        raise SystemExit(f"{' '.join(cmd)} exited {r.returncode}")
    import json
    j = json.loads(r.stdout)
    return j["sizes"][0]["draw1_cpu_ms"], j["spirv_bytes"]


def check_examples(binaries, drivers, work):
    """Byte-compares each example's EXR from every binary; returns (compared, differing names)."""
    compared, differing = 0, []
    for driver in drivers:
        env = env_for(driver, os.path.join(work, "cache-check"))
        for scene in sorted(glob.glob(os.path.join(ROOT, "examples", "*.sdf"))):
            outs = []
            for i, sdfc in enumerate(binaries):
                out = os.path.join(work, f"check {i}.exr")
                cmd = [sdfc, "render", scene, "-o", out, "--size", "64x36", "--spp", "2", "--denoise", "none", "-q"]
                r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
                if r.returncode != 0:
                    sys.stderr.write(r.stderr)
                    raise SystemExit(f"{' '.join(cmd)} exited {r.returncode}")
                with open(out, "rb") as f:
                    outs.append(f.read())
            compared += 1
            if any(o != outs[0] for o in outs[1:]):
                differing.append(f"{os.path.basename(scene)} ({driver})")
    return compared, differing


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--base", required=True, help="the binary before the change (main's)")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--drivers", nargs="+", default=["bundled", "system"])
    ap.add_argument("--check-examples", action="store_true")
    ap.add_argument("--first-draw", default=os.path.join(ROOT, "build", "bench", "first_draw", "sdfc_first_draw"))
    ap.add_argument("--first-draw-rounds", type=int, default=3)
    ap.add_argument("--skip-render", action="store_true", help="only the first-draw and image sections")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "kernel_features.md"))
    args = ap.parse_args()
    binaries = {"base": args.base, "this": args.sdfc}
    load_start = os.getloadavg()[0]
    lines = ["# A render nothing denoises: the kernel without features (bench/kernel_features.py)", "",
             f"`sdfc render SCENE --size 640x360 --spp 1 --timings` (nlr does nothing at 1 spp), Mesa's shader "
             f"cache off, sdfc's SPIR-V cache warm; medians of {args.reps} runs, the two binaries alternating "
             f"(base: `{args.base}`). Load average at the start {load_start:.1f} on {os.cpu_count()} cores.", ""]
    with tempfile.TemporaryDirectory(prefix="sdfc kernel features ") as work:
        for driver in args.drivers if not args.skip_render else []:
            results = {(s, b): [] for s in SCENES for b in binaries}
            for rep in range(args.reps + 1):  # the first: warms the SPIR-V caches, not counted
                order = [(s, b) for s in SCENES for b in binaries]
                if rep % 2:
                    order.reverse()
                for scene, binary in order:
                    env = env_for(driver, os.path.join(work, f"cache {binary}"))
                    stages = timed_run(binaries[binary], SCENES[scene], os.path.join(work, "x.png"), env)
                    if rep > 0:
                        results[(scene, binary)].append(stages)
            lines += [f"## Driver: {driver}", "",
                      "| case | " + " | ".join(s + ", ms" for s in STAGES) + " | CPU s | wall s |",
                      "|---|" + "---|" * (len(STAGES) + 2)]
            for (scene, binary), runs in results.items():
                med = lambda k: statistics.median(r.get(k, float("nan")) for r in runs)
                lines.append(f"| {scene} {binary} | " + " | ".join(f"{med(s):.1f}" for s in STAGES) +
                             f" | {med('CPU s'):.3f} | {med('wall s'):.3f} |")
            lines.append("")
        if args.first_draw_rounds > 0:
            lines += ["## The first draw by itself (sdfc_first_draw, 1x1, CPU ms)", "",
                      f"{args.first_draw_rounds} rounds of 2 draws each, full and featureless alternating; medians.", "",
                      "| driver | scene | LLVM | full kernel, CPU ms | featureless, CPU ms | ratio | SPIR-V bytes full / featureless |",
                      "|---|---|---|---|---|---|---|"]
            for driver in args.drivers:
                for scene in SCENES:
                    for nopt in (True, False):
                        got = {True: [], False: []}
                        size = {}
                        for rnd in range(args.first_draw_rounds):
                            for aovs in ((True, False) if rnd % 2 == 0 else (False, True)):
                                cpu, size[aovs] = first_draw_cpu(args.first_draw, SCENES[scene], driver, aovs, nopt, 2)
                                got[aovs] += cpu
                        full, bare = statistics.median(got[True]), statistics.median(got[False])
                        lines.append(f"| {driver} | {scene} | {'unoptimised' if nopt else 'optimised'} | {full:.0f} | "
                                     f"{bare:.0f} | {bare / full:.2f} | {size[True]} / {size[False]} |")
            lines.append("")
        if args.check_examples:
            compared, differing = check_examples([args.base, args.sdfc], args.drivers, work)
            lines += ["## Images", "",
                      f"Every example at 64x36, 2 spp, `--denoise none`, EXR, both binaries: {compared} "
                      f"renders compared byte for byte, {len(differing)} differ" +
                      (": " + ", ".join(differing) if differing else "."), ""]
    lines.append(f"Load average at the end {os.getloadavg()[0]:.1f}.")
    text = "\n".join(lines) + "\n"
    print(text)
    notes = ""
    if os.path.exists(args.out):
        with open(args.out) as f:
            old = f.read()
        if NOTES_MARK in old:
            notes = "\n" + NOTES_MARK + old.split(NOTES_MARK, 1)[1]
    with open(args.out, "w") as f:
        f.write(text + notes)


if __name__ == "__main__":
    main()
