#!/usr/bin/env python3
"""Where a reload's first frame goes, and what the kernel's shape costs (issue 12).

For each (binary, driver) pair, interleaved round by round so before/after
share the machine's load:
  - the kernel `sdfc view` builds for the castle's beauty view (the binary's
    own emitter: `sdfc compile --no-bounds`, as the view compiles on a CPU
    device), drawn by build/bench/first_draw/sdfc_first_draw: pipeline creation,
    the first draw at 1x1 (lavapipe's LLVM compile of the fragment shader,
    nearly all of it) and at 160x90 (the reload's first frame), and the second
    draw of the same pipeline; process CPU ms (robust to load) and wall ms;
  - steady-state path tracing: `sdfc render` at 640x360, samples per second
    from the difference of two renders (--spp 4 and --spp 20), so pipeline
    creation and the compile at the first draw cancel out.
Mesa's on-disk shader cache is off (every build is new to the driver).
Writes bench/results/view_jit.json; medians are printed.

Usage: bench/view_jit_bench.py --baseline OLD_SDFC [--sdfc build/cli/sdfc]
                               [--drivers 22,25] [--rounds 5] [--no-render]
"""
import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DRIVER_ENV = {"22": {"SDFC_DRIVER": "system"}}


def env_for(driver):
    env = dict(os.environ, LP_NUM_THREADS="2", MESA_SHADER_CACHE_DISABLE="true")
    env.pop("SDFC_VALIDATION", None)
    env.update(DRIVER_ENV.get(driver, {}))
    return env


def first_draw(tool, scene, glsl, driver):
    r = subprocess.run([tool, scene, "--glsl", glsl, "--reps", "1", "--size", "1x1", "--size", "160x90"],
                       capture_output=True, text=True, env=env_for(driver), timeout=600)
    if r.returncode != 0:
        raise SystemExit(f"sdfc_first_draw failed: {r.stderr}")
    j = json.loads(r.stdout)
    one, small = j["sizes"]
    return {"spirv_bytes": j["spirv_bytes"],
            "pipeline_cpu_ms": one["pipeline_cpu_ms"][0], "pipeline_ms": one["pipeline_ms"][0],
            "jit_1x1_cpu_ms": one["draw1_cpu_ms"][0], "jit_1x1_ms": one["draw1_ms"][0],
            "first_draw_160x90_ms": small["draw1_ms"][0], "second_draw_160x90_ms": small["draw2_ms"][0]}


def render_seconds(sdfc, scene, spp, driver, out):
    r = subprocess.run([sdfc, "render", scene, "--size", "640x360", "--spp", str(spp), "-o", out,
                        "--denoise", "none"],
                       capture_output=True, text=True, env=env_for(driver), timeout=1800)
    m = re.search(r"\((\d+) spp in ([0-9.eE+-]+)s", r.stderr)
    if r.returncode != 0 or not m:
        raise SystemExit(f"sdfc render failed: {r.stderr}")
    return float(m.group(2))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--baseline", required=True, help="an sdfc binary built from the commit before")
    ap.add_argument("--first-draw", default=os.path.join(ROOT, "build", "bench", "first_draw", "sdfc_first_draw"))
    ap.add_argument("--drivers", default="22,25")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "castle.sdf"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "view_jit.json"))
    ap.add_argument("--no-render", action="store_true", help="only the first-draw figures (no spp/s)")
    args = ap.parse_args()
    drivers = [d for d in args.drivers.split(",") if d]
    if "25" in drivers:
        tool = os.path.join(ROOT, "tools", "lavapipe25.sh")
        subprocess.run([tool, "fetch"], check=True)
        words = shlex.split(subprocess.run([tool, "env"], capture_output=True, text=True,
                                           check=True).stdout.strip().removeprefix("export "))
        DRIVER_ENV["25"] = dict(w.split("=", 1) for w in words)
    binaries = {"after": args.sdfc, "before": args.baseline}
    samples = {}
    load_start = os.getloadavg()
    with tempfile.TemporaryDirectory() as d:
        glsl = {}
        for name, sdfc in binaries.items():
            glsl[name] = os.path.join(d, name + ".glsl")
            subprocess.run([sdfc, "compile", args.scene, "--emit", "glsl", "--no-bounds", "-o", glsl[name]],
                           check=True, capture_output=True)
        out = os.path.join(d, "x.pfm")
        for r in range(args.rounds):
            for driver in drivers:
                for name, sdfc in binaries.items():
                    key = f"{name}_mesa{driver}"
                    print(f"round {r + 1}/{args.rounds} {key}", file=sys.stderr, flush=True)
                    s = first_draw(args.first_draw, args.scene, glsl[name], driver)
                    if not args.no_render:
                        t4 = render_seconds(sdfc, args.scene, 4, driver, out)
                        t20 = render_seconds(sdfc, args.scene, 20, driver, out)
                        s["steady_spp_per_s"] = 16 / max(t20 - t4, 1e-9)
                    for k, v in s.items():
                        samples.setdefault(key, {}).setdefault(k, []).append(v)
    result = {"machine": {"cpus": os.cpu_count(), "load_average_start": load_start,
                          "load_average_end": os.getloadavg()},
              "binaries": binaries, "scene": args.scene, "rounds": args.rounds, "samples": samples,
              "medians": {key: {k: statistics.median(v) for k, v in s.items()} for key, s in samples.items()}}
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    med = result["medians"]
    keys = list(med)
    print(f"{'median':28s} " + " ".join(f"{k:>15s}" for k in keys))
    for k in next(iter(med.values())):
        print(f"{k:28s} " + " ".join(f"{med[run][k]:15.1f}" for run in keys))
    for driver in drivers:
        a, b = med.get(f"after_mesa{driver}"), med.get(f"before_mesa{driver}")
        if a and b:
            print(f"after / before, Mesa {driver}: " + ", ".join(
                f"{k} {a[k] / b[k]:.2f}" for k in ("pipeline_cpu_ms", "jit_1x1_cpu_ms", "first_draw_160x90_ms",
                                                 "second_draw_160x90_ms", "steady_spp_per_s") if k in a))
    print("load average:", result["machine"]["load_average_start"], "->", result["machine"]["load_average_end"])
    print("wrote", args.out)


if __name__ == "__main__":
    main()
