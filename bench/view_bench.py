#!/usr/bin/env python3
"""Benchmark of `sdfc view` on the castle (lavapipe), under its own Xvfb.

Figures (issue 12 targets in brackets), written to bench/results/view.json and
printed as a table:
  - normal view, 640x360, full resolution every frame, the camera orbiting:
    ms per frame (render + tone map + present)            [<= 31 ms]
  - path traced, 1 spp a frame, 640x360, still camera: frames per second  [>= 5]
  - the same while orbiting with dynamic resolution (preview frames)
  - save-to-new-image latency: the file written -> first frame of the new
    scene presented, median of --edits edits (5)           [<= 250 ms]
  - input to presented frame, in frames                    [<= 2]
  - issue 36: the per-frame split of the normal view at 640x360 (sphere and castle,
    full resolution every frame while orbiting), medians over the frames of the
    frame log: pass, the CPU's part of the display, copy, acquire, present, wait,
    and the frame interval; CPU seconds of the whole run (sdfc and Xvfb)
    [interval at most 1.5 ms above the pass; sphere <= 6.4 ms, castle <= 16.7 ms].
    --figures split; --page writes bench/results/VIEW_FRAME.md from it.
The machine is shared (load average recorded): compare within one run.

Each figure is measured for every (binary, driver) pair in one run, the pairs
interleaved figure by figure, so before/after ratios share the machine's load:
--baseline names an older sdfc binary (e.g. one built from the commit before a
change) and --drivers picks the system lavapipe (22) and/or Mesa 25's
(tools/lavapipe25.sh, fetched first). Mesa's on-disk shader cache is disabled,
so every run compiles its shaders as a person's fresh edit would.
Usage: bench/view_bench.py [--sdfc build/cli/sdfc] [--baseline OLD_SDFC]
                           [--drivers 22,25] [--edits 5] [--out bench/results/view.json]
                           [--figures normal,beauty,save,input] [--rounds 1]
--rounds R repeats the interleaved (binary, driver) measurements R times (A/B/A/B...),
pooling the saves of all rounds into one median.
"""
import argparse
import json
import os
import re
import resource
import shlex
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


# Driver name -> extra environment ("25" filled in main). sdfc picks the bundled
# Mesa 25 on its own where it is fetched, so "22" must ask for the system driver.
DRIVER_ENV = {"22": {"SDFC_DRIVER": "system"}}


def driver_env(driver):
    env = dict(os.environ, LP_NUM_THREADS="2", MESA_SHADER_CACHE_DISABLE="true")
    env.pop("SDFC_VALIDATION", None)
    env.update(DRIVER_ENV.get(driver, {}))
    return env


def run_view(sdfc, scene, script_text, flags, workdir, driver="22", cpu=None):
    script = os.path.join(workdir, "events.txt")
    log = os.path.join(workdir, "frames.log")
    open(script, "w").write(script_text)
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24 -nolisten tcp",
           sdfc, "view", scene, "--script", script, "--frame-log", log] + flags
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True, env=driver_env(driver), timeout=1800)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if cpu is not None:
        cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        raise SystemExit(f"sdfc view exited {r.returncode}")
    lines = open(log).read().splitlines()
    frames = []
    for l in lines:
        if l.startswith("frame "):
            w = l.split()
            frames.append({w[i]: w[i + 1] for i in range(0, len(w) - 1, 2)})
    return lines, frames, r.stderr


def interval_ms(frames):
    t = [float(f["t_ms"]) for f in frames]
    return [b - a for a, b in zip(t, t[1:])]


def measure(sdfc, driver, scene, text, d, n, n_edits=5, figures=("normal", "beauty", "save", "input")):
    """The four figures (and their parts) for one binary under one driver."""
    result = {}
    run = lambda script, flags: run_view(sdfc, scene, script, flags, d, driver)
    if "normal" in figures:
        measure_normal(result, run, n)
    if "beauty" in figures:
        measure_beauty(result, run, n)
    if "save" in figures:
        measure_save(result, run, text, d, n_edits)
    if "input" in figures:
        measure_input(result, run)
    if "split" in figures:
        for name, path in (("sphere", os.path.join(ROOT, "examples", "diffuse_sphere.sdf")),
                           ("castle", scene)):
            measure_split(result, name, lambda script, flags, cpu: run_view(
                sdfc, path, script, flags, d, driver, cpu), n)
    return result


SPLIT = [("pass", "render_ms"), ("display (CPU)", "display_ms"), ("copy", "copy_ms"),
         ("acquire", "acquire_ms"), ("present", "queue_present_ms"), ("wait", "wait_ms")]


def measure_split(result, name, run, n):
    # Issue 36: the normal view at 640x360, full resolution while orbiting: each
    # part's median over the frames, the interval's, and the run's CPU seconds.
    cpu = []
    _, frames, _ = run(f"wait-idle\nlog orbit\ndrag left {4 * n} 0 {n}\nwait 2\nquit\n",
                       ["--view", "normal", "--no-dynamic-resolution", "--size", "640x360"], cpu)
    orbit = [f for f in frames if f["res"] == "640x360"][1:]  # the first frame pays LLVM's compile
    key = f"split_{name}"
    for label, field in SPLIT:
        result[f"{key}_{field}"] = statistics.median(float(f[field]) for f in orbit)
    result[f"{key}_interval_ms"] = statistics.median(interval_ms(orbit))
    result[f"{key}_above_pass_ms"] = result[f"{key}_interval_ms"] - result[f"{key}_render_ms"]
    result[f"{key}_cpu_s"] = cpu[0]
    result[f"{key}_frames"] = len(orbit)


def measure_normal(result, run, n):
    # 1. Normal view, full resolution each frame while orbiting.
    _, frames, _ = run(f"wait-idle\nlog orbit\ndrag left {4 * n} 0 {n}\nwait 2\nquit\n",
                       ["--view", "normal", "--no-dynamic-resolution", "--size", "640x360"])
    orbit = [f for f in frames if f["res"] == "640x360"][1:]  # the first frame pays LLVM's compile
    result["normal_640x360_ms_per_frame"] = statistics.median(float(f["ms"]) for f in orbit)
    result["normal_640x360_frame_interval_ms"] = statistics.median(interval_ms(orbit))
    result["normal_640x360_render_ms"] = statistics.median(float(f["render_ms"]) for f in orbit)
    result["normal_640x360_outside_pass_ms"] = statistics.median(
        float(f["ms"]) - float(f["render_ms"]) for f in orbit)



def measure_beauty(result, run, n):
    # 2. Path traced, 1 spp a frame, still camera; then orbiting with dynamic resolution.
    _, frames, _ = run(f"wait-spp {n + 1}\nlog orbit\ndrag left {4 * n} 0 {n}\nwait-spp 2\nquit\n",
                       ["--spp", "100000", "--size", "640x360"])
    still = [f for f in frames if f["res"] == "640x360" and f["moving"] == "0"]
    still = still[1:n + 1]
    result["beauty_640x360_1spp_ms_per_frame"] = statistics.median(float(f["ms"]) for f in still)
    result["beauty_640x360_1spp_fps"] = 1000.0 / statistics.median(interval_ms(still))
    result["beauty_640x360_1spp_render_ms"] = statistics.median(float(f["render_ms"]) for f in still)
    moving = [f for f in frames if f["moving"] == "1"]
    if len(moving) > 2:
        result["beauty_orbit_preview_fps"] = 1000.0 / statistics.median(interval_ms(moving))
        result["beauty_orbit_preview_resolutions"] = sorted({f["res"] for f in moving})



def measure_save(result, run, text, d, n_edits):
    # 3. Save-to-new-image latency: edits of a `let` number, each new to the
    # driver (no shader cache), timed from the write to the new scene's first
    # presented frame.
    edits = []
    for i, h in enumerate(3.2 - 0.1 * k for k in range(n_edits)):
        path = os.path.join(d, f"edit{i}.sdf")
        open(path, "w").write(re.sub(r"let wall_height = [0-9.]+", f"let wall_height = {h}", text))
        edits.append(path)
    script = "wait-idle\n" + "".join(f"write-file {p}\nwait-reload\nwait-idle\n" for p in edits) + "quit\n"
    lines, frames, stderr = run(script, ["--spp", "1", "--size", "640x360"])
    reloads = [l for l in lines if "reload ok" in l][1:]  # the first is the initial load
    parse = lambda key, l: float(re.search(key + r" (\d+) ms", l).group(1))
    result["save_to_image_ms"] = [parse("save-to-image", l) for l in reloads]
    result["save_to_image_ms_median"] = statistics.median(result["save_to_image_ms"])
    result["reload_compile_ms"] = [parse(r"\(compile", l) for l in reloads]
    result["reload_pipeline_ms"] = [parse("pipeline", l) for l in reloads]
    result["reload_first_frame_ms"] = [parse("first frame", l) for l in reloads]
    # sdfc view validates SPIR-V beside pipeline creation; the wait after it (0 for
    # binaries that validate inside the compile and do not print it).
    waited = [re.search(r"waited (\d+) ms", l) for l in reloads]
    result["reload_validation_wait_ms"] = [float(m.group(1)) if m else 0.0 for m in waited]
    result["reload_other_ms"] = [s - c - p - f - w for s, c, p, f, w in zip(
        result["save_to_image_ms"], result["reload_compile_ms"], result["reload_pipeline_ms"],
        result["reload_first_frame_ms"], result["reload_validation_wait_ms"])]
    for k in ("reload_compile_ms", "reload_pipeline_ms", "reload_first_frame_ms",
              "reload_validation_wait_ms", "reload_other_ms"):
        result[k + "_median"] = statistics.median(result[k])
    result["reload_first_frame_resolution"] = [re.search(r"at (\d+x\d+)", l).group(1) for l in reloads]
    full = [parse("save-to-full-resolution", l) for l in lines if "reload full" in l][1:]
    result["save_to_full_resolution_ms"] = full
    result["save_to_full_resolution_ms_median"] = statistics.median(full)



def measure_input(result, run):
    # 4. Input to presented frame (frames).
    lines, frames, _ = run("wait-idle\ndrag left 40 0 10\nwait 3\nquit\n", ["--spp", "1", "--size", "640x360"])
    by_index = {int(f["frame"]): f for f in frames}
    waits = []
    for l in lines:
        if l.startswith("event ") and "input drag" in l:
            k = int(l.split()[1])
            before = by_index.get(k, {}).get("camera")
            later = [i for i in sorted(by_index) if i > k and by_index[i]["camera"] != before]
            if later:
                waits.append(later[0] - k)
    result["input_to_frame_frames_max"] = max(waits)
    result["input_to_frame_frames"] = waits


ROWS = [
    ("castle normal view 640x360, ms/frame (<= 31)", "normal_640x360_ms_per_frame"),
    ("  of which the render pass, ms", "normal_640x360_render_ms"),
    ("  outside the pass, ms", "normal_640x360_outside_pass_ms"),
    ("  frame interval incl. event loop, ms", "normal_640x360_frame_interval_ms"),
    ("castle path traced 1 spp/frame 640x360, fps (>= 5)", "beauty_640x360_1spp_fps"),
    ("  ms/frame", "beauty_640x360_1spp_ms_per_frame"),
    ("  of which the render pass, ms", "beauty_640x360_1spp_render_ms"),
    ("castle orbiting, dynamic resolution, fps", "beauty_orbit_preview_fps"),
    ("save-to-new-image latency, ms, median (<= 250)", "save_to_image_ms_median"),
    ("  compile, ms", "reload_compile_ms_median"),
    ("  pipeline, ms", "reload_pipeline_ms_median"),
    ("  first frame, ms", "reload_first_frame_ms_median"),
    ("  waiting for SPIR-V validation, ms", "reload_validation_wait_ms_median"),
    ("  the rest (watcher, hand-off), ms", "reload_other_ms_median"),
    ("  to the first full-resolution frame, ms", "save_to_full_resolution_ms_median"),
    ("input to presented frame, frames, max (<= 2)", "input_to_frame_frames_max"),
] + [row for name, target in (("sphere", 6.4), ("castle", 16.7)) for row in [
    (f"{name} normal 640x360 frame interval, ms (<= {target})", f"split_{name}_interval_ms"),
    ("  above the pass, ms (<= 1.5)", f"split_{name}_above_pass_ms")] +
    [(f"  {label}, ms", f"split_{name}_{field}") for label, field in SPLIT] +
    [("  CPU seconds of the run (sdfc + Xvfb)", f"split_{name}_cpu_s")]]


def pool(rounds):
    """One result from several rounds: lists joined (medians taken again), numbers the median."""
    out = {}
    for k in rounds[0]:
        values = [r[k] for r in rounds if k in r]
        if isinstance(values[0], list):
            out[k] = [x for v in values for x in v]
        elif isinstance(values[0], (int, float)):
            out[k] = statistics.median(values)
        else:
            out[k] = values[0]
    for k in list(out):
        if k.endswith("_median") and isinstance(out.get(k[:-len("_median")]), list):
            out[k] = statistics.median(out[k[:-len("_median")]])
    out["rounds"] = len(rounds)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--baseline", help="an older sdfc binary to compare with (before/after ratios)")
    ap.add_argument("--drivers", default="22,25", help="22 (system lavapipe), 25 (tools/lavapipe25.sh)")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "view.json"))
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--edits", type=int, default=5, help="saves timed for the save-to-image median")
    ap.add_argument("--figures", default="normal,beauty,save,input",
                    help="which figures: normal, beauty, save (save-to-image), input")
    ap.add_argument("--page", help="also write the split as a markdown page (bench/results/VIEW_FRAME.md)")
    ap.add_argument("--rounds", type=int, default=1,
                    help="repeat the interleaved measurements; lists are pooled, figures are medians of rounds")
    args = ap.parse_args()
    figures = [x for x in args.figures.split(",") if x]
    castle = os.path.join(ROOT, "examples", "castle.sdf")
    drivers = [x for x in args.drivers.split(",") if x]
    if "25" in drivers:
        tool = os.path.join(ROOT, "tools", "lavapipe25.sh")
        subprocess.run([tool, "fetch"], check=True)
        env = subprocess.run([tool, "env"], capture_output=True, text=True, check=True).stdout
        words = shlex.split(env.strip().removeprefix("export "))
        DRIVER_ENV["25"] = dict(w.split("=", 1) for w in words)
    binaries = [("after", args.sdfc)] + ([("before", args.baseline)] if args.baseline else [])
    result = {"machine": {"cpus": os.cpu_count(), "load_average_start": os.getloadavg()},
              "binaries": dict(binaries), "drivers": drivers, "runs": {}}
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "castle.sdf")
        text = open(castle).read()
        open(scene, "w").write(text)
        rounds = {}
        for r in range(args.rounds):
            for driver in drivers:
                for name, sdfc in binaries:  # interleaved: before and after share the load
                    key = f"{name}_mesa{driver}"
                    print("measuring", key, "round", r + 1, "load", os.getloadavg()[0], file=sys.stderr, flush=True)
                    rounds.setdefault(key, []).append(
                        measure(sdfc, driver, scene, text, d, args.frames, args.edits, figures))
        result["runs"] = {key: pool(rs) for key, rs in rounds.items()}
    result["machine"]["load_average_end"] = os.getloadavg()
    # The headline figures: the new binary on sdfc's default driver (the bundled
    # Mesa 25 where tools/setup.sh fetched it, else the system's).
    runs = result["runs"]
    result.update(runs.get("after_mesa25", runs.get("after_mesa22", next(iter(runs.values())))))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)

    keys = list(result["runs"])
    print(f"{'figure':52s} " + " ".join(f"{k:>18s}" for k in keys))
    for label, k in ROWS:
        cells = []
        for run in keys:
            v = result["runs"][run].get(k, float("nan"))
            cells.append(f"{v:18.1f}")
        print(f"{label:52s} " + " ".join(cells))
    for driver in drivers:
        a, b = result["runs"].get(f"after_mesa{driver}"), result["runs"].get(f"before_mesa{driver}")
        if a and b:
            print(f"after / before, Mesa {driver}: " + ", ".join(
                f"{k} {a[k] / b[k]:.2f}" for k in ("normal_640x360_ms_per_frame", "normal_640x360_render_ms",
                                                 "beauty_640x360_1spp_fps", "save_to_image_ms_median") if b.get(k) and k in a))
    print("load average:", result["machine"]["load_average_start"], "->", result["machine"]["load_average_end"])
    print("wrote", args.out)
    if args.page:
        write_page(args.page, result, keys, args)
        print("wrote", args.page)


def write_page(path, result, keys, args):
    """The split figures as a results page: one column per (binary, driver)."""
    m = result["machine"]
    lines = ["# The viewer's frame: issue 36's split (bench/view_bench.py --figures split)", "",
             f"Generated by `bench/view_bench.py --figures {args.figures} --rounds {args.rounds} "
             f"--frames {args.frames} --drivers {','.join(result['drivers'])}"
             f"{' --baseline ' + os.path.basename(args.baseline) if args.baseline else ''}`. "
             f"{m['cpus']} CPUs, load average {m['load_average_start'][0]:.1f} at the start and "
             f"{m['load_average_end'][0]:.1f} at the end (a shared, loaded machine: the binaries "
             "alternate run by run, each figure is the median over the frames of a run and then over "
             "the rounds). `after` is this branch, `before` the binary named by --baseline.", "",
             "Normal view, 640x360, full resolution every frame while the camera orbits. The parts "
             "are the frame log's (`render_ms`, `display_ms`, `copy_ms`, `acquire_ms`, "
             "`queue_present_ms`, `wait_ms`); `interval` is the median time between presented frames.",
             "", "| figure | " + " | ".join(keys) + " |", "|---|" + "---:|" * len(keys)]
    for label, k in ROWS:
        if not k.startswith("split_"):
            continue
        cells = [f"{result['runs'][run].get(k, float('nan')):.2f}" for run in keys]
        lines.append(f"| {label.strip()} | " + " | ".join(cells) + " |")
    lines.append("")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    open(path, "w").write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
