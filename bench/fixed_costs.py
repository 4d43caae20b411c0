#!/usr/bin/python3
"""Fixed costs of one small render, whole process, each lever by itself (issue 36).

    bench/fixed_costs.py [--sdfc build/cli/sdfc] [--base OTHER_SDFC] [--reps 7]
                         [--drivers bundled system] [--out bench/results/fixed_costs.md]

Runs `sdfc render SCENE -o x.png --size 640x360 --spp 1` with Mesa's shader
cache off (MESA_SHADER_CACHE_DISABLE=true), timing the whole process from the
outside, in these cases, alternated run by run (the order reversed every other
repetition) so every case sees the same machine load:

  sphere cold     an empty sdfc cache (a fresh XDG_CACHE_HOME per run)
  sphere warm     the sdfc cache holding the sphere's SPIR-V
  sphere no-cache --no-cache (glslang and validation every run)
  castle cold     an empty sdfc cache
  castle warm     the sdfc cache holding the castle's SPIR-V
  sphere/castle optimised  warm, GALLIVM_PERF set empty: lavapipe's LLVM
                  optimisation kept (the quick-compile lever off;
                  runtime/driver_compile_level.h)
  (--base BIN)    the same scenes with another binary (e.g. main's), no cache

and, from one extra `--timings` run per case, the stage split. Prints medians and
writes them, with the machine's load average, to --out (Markdown).
"""
import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENES = {"sphere": os.path.join(ROOT, "examples", "diffuse_sphere.sdf"),
          "castle": os.path.join(ROOT, "examples", "castle.sdf")}


def env_for(driver, cache, extra=None):
    env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true", SDFC_DRIVER=driver, XDG_CACHE_HOME=cache)
    env.pop("SDFC_VALIDATION", None)
    env.pop("GALLIVM_PERF", None)
    env.update(extra or {})
    return env


NOTES_MARK = "<!-- Below this line: kept as written when the script regenerates the tables. -->"


def run_once(sdfc, scene, out, env, flags=()):
    cmd = [sdfc, "render", scene, "-o", out, "--size", "640x360", "--spp", "1", "-q"] + list(flags)
    start = time.perf_counter()
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    elapsed = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        raise SystemExit(f"{' '.join(cmd)} exited {r.returncode}")
    # CPU seconds (user + system) of the process: on a loaded machine the wall
    # time is mostly waiting for a core, its CPU time much less so.
    cpu = (after.ru_utime - used.ru_utime) + (after.ru_stime - used.ru_stime)
    return elapsed, cpu


def stage_split(sdfc, scene, out, env, flags=()):
    cmd = [sdfc, "render", scene, "-o", out, "--size", "640x360", "--spp", "1", "--timings"] + list(flags)
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    stages = {}
    for m in re.finditer(r"^  (.+?)\s+(-?[0-9.]+)\s+(?:-?[0-9.]+%)?", r.stderr, re.M):
        stages[m.group(1).strip()] = float(m.group(2))
    return stages


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--base", help="another sdfc binary to time alongside (no cache)")
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--drivers", nargs="+", default=["bundled", "system"])
    ap.add_argument("--out", default=os.path.join(HERE, "results", "fixed_costs.md"))
    args = ap.parse_args()

    lines = ["# Fixed costs (bench/fixed_costs.py)", "",
             f"Whole process to a 640x360 PNG at 1 spp, Mesa's shader cache off, medians of {args.reps} "
             f"alternating runs; load average at the start {os.getloadavg()[0]:.1f} "
             f"(on {os.cpu_count()} cores).", ""]
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "x.png")
        for driver in args.drivers:
            warm = os.path.join(work, f"warm-{driver}")
            # Fill the warm cache once per scene.
            for scene in SCENES.values():
                run_once(args.sdfc, scene, out, env_for(driver, warm))
            cases = []
            for name, scene in SCENES.items():
                cases.append((f"{name} cold", args.sdfc, scene, None, ()))
                cases.append((f"{name} warm", args.sdfc, scene, warm, ()))
            cases.insert(2, ("sphere no-cache", args.sdfc, SCENES["sphere"], warm, ("--no-cache",)))
            cases.append(("sphere optimised", args.sdfc, SCENES["sphere"], warm, (), {"GALLIVM_PERF": ""}))
            cases.append(("castle optimised", args.sdfc, SCENES["castle"], warm, (), {"GALLIVM_PERF": ""}))
            if args.base:
                for name, scene in SCENES.items():
                    cases.append((f"{name} base", args.base, scene, os.path.join(work, "base"), ()))
            times = {c[0]: [] for c in cases}
            cpus = {c[0]: [] for c in cases}
            for rep in range(args.reps):
                order = cases if rep % 2 == 0 else cases[::-1]
                for label, binary, scene, cache, flags, *extra in order:
                    if cache is None:  # cold: a cache directory of its own, empty
                        cache = tempfile.mkdtemp(dir=work)
                    env = env_for(driver, cache, extra[0] if extra else None)
                    elapsed, cpu = run_once(binary, scene, out, env, flags)
                    times[label].append(elapsed)
                    cpus[label].append(cpu)
                    if label.endswith("cold"):
                        shutil.rmtree(cache, ignore_errors=True)
            lines += [f"## Driver: {driver}", "", "| case | median s | min s | max s | median CPU s |",
                      "|---|---|---|---|---|"]
            for label in times:
                t = times[label]
                lines.append(f"| {label} | {statistics.median(t):.3f} | {min(t):.3f} | {max(t):.3f} | "
                             f"{statistics.median(cpus[label]):.3f} |")
                print(f"{driver:8s} {label:16s} median {statistics.median(t):.3f} s  "
                      f"(min {min(t):.3f}, max {max(t):.3f}), CPU {statistics.median(cpus[label]):.3f} s")
            lines += ["", "Stage split of one `--timings` run (ms):", ""]
            split_cases = [("sphere cold", SCENES["sphere"], None), ("sphere warm", SCENES["sphere"], warm),
                           ("castle warm", SCENES["castle"], warm)]
            splits = {}
            for label, scene, cache in split_cases:
                splits[label] = stage_split(args.sdfc, scene, out,
                                            env_for(driver, cache or tempfile.mkdtemp(dir=work)))
            names = []
            for s in splits.values():
                names += [n for n in s if n not in names]
            lines.append("| stage | " + " | ".join(splits) + " |")
            lines.append("|---|" + "---|" * len(splits))
            for n in names:
                lines.append(f"| {n} | " + " | ".join(f"{s[n]:.1f}" if n in s else "" for s in splits.values()) + " |")
            lines.append("")
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    notes = ""
    if os.path.exists(args.out):
        old = open(args.out).read()
        if NOTES_MARK in old:
            notes = old[old.index(NOTES_MARK):]
    open(args.out, "w").write("\n".join(lines) + "\n" + (notes or NOTES_MARK + "\n"))
    print("wrote", args.out)


if __name__ == "__main__":
    main()
