#!/usr/bin/env python3
"""Benchmark of `sdfc view` on the castle (lavapipe), under its own Xvfb.

Figures (issue 12 targets in brackets), written to bench/results/view.json and
printed as a table:
  - normal view, 640x360, full resolution every frame, the camera orbiting:
    ms per frame (render + tone map + present)            [<= 31 ms]
  - path traced, 1 spp a frame, 640x360, still camera: frames per second  [>= 5]
  - the same while orbiting with dynamic resolution (preview frames)
  - save-to-new-image latency: the file written -> first frame of the new
    scene presented, median of 3 edits                     [<= 250 ms]
  - input to presented frame, in frames                    [<= 2]
The machine is shared (load average recorded): compare within one run.
Usage: bench/view_bench.py [--sdfc build/cli/sdfc] [--out bench/results/view.json]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run_view(sdfc, scene, script_text, flags, workdir):
    script = os.path.join(workdir, "events.txt")
    log = os.path.join(workdir, "frames.log")
    open(script, "w").write(script_text)
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24 -nolisten tcp",
           sdfc, "view", scene, "--script", script, "--frame-log", log] + flags
    env = dict(os.environ, LP_NUM_THREADS="2")
    env.pop("SDFC_VALIDATION", None)
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=1800)
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "view.json"))
    ap.add_argument("--frames", type=int, default=30)
    args = ap.parse_args()
    castle = os.path.join(ROOT, "examples", "castle.sdf")
    n = args.frames
    result = {"machine": {"cpus": os.cpu_count(), "load_average_start": os.getloadavg()}}

    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "castle.sdf")
        text = open(castle).read()
        open(scene, "w").write(text)

        # 1. Normal view, full resolution each frame while orbiting.
        _, frames, _ = run_view(args.sdfc, scene, f"wait-idle\nlog orbit\ndrag left {4 * n} 0 {n}\nwait 2\nquit\n",
                                ["--view", "normal", "--no-dynamic-resolution", "--size", "640x360"], d)
        orbit = [f for f in frames if f["res"] == "640x360"][1:]  # the first frame pays LLVM's compile
        result["normal_640x360_ms_per_frame"] = statistics.median(float(f["ms"]) for f in orbit)
        result["normal_640x360_frame_interval_ms"] = statistics.median(interval_ms(orbit))
        result["normal_640x360_render_ms"] = statistics.median(float(f["render_ms"]) for f in orbit)

        # 2. Path traced, 1 spp a frame, still camera; then orbiting with dynamic resolution.
        _, frames, _ = run_view(args.sdfc, scene,
                                f"wait-spp {n + 1}\nlog orbit\ndrag left {4 * n} 0 {n}\nwait-spp 2\nquit\n",
                                ["--spp", "100000", "--size", "640x360"], d)
        still = [f for f in frames if f["res"] == "640x360" and f["moving"] == "0"]
        still = still[1:n + 1]
        result["beauty_640x360_1spp_ms_per_frame"] = statistics.median(float(f["ms"]) for f in still)
        result["beauty_640x360_1spp_fps"] = 1000.0 / statistics.median(interval_ms(still))
        result["beauty_640x360_1spp_render_ms"] = statistics.median(float(f["render_ms"]) for f in still)
        moving = [f for f in frames if f["moving"] == "1"]
        if len(moving) > 2:
            result["beauty_orbit_preview_fps"] = 1000.0 / statistics.median(interval_ms(moving))
            result["beauty_orbit_preview_resolutions"] = sorted({f["res"] for f in moving})

        # 3. Save-to-new-image latency: three edits of a `let` number.
        edits = []
        for i, h in enumerate((3.2, 2.6, 3.0)):
            path = os.path.join(d, f"edit{i}.sdf")
            open(path, "w").write(re.sub(r"let wall_height = [0-9.]+", f"let wall_height = {h}", text))
            edits.append(path)
        script = "wait-idle\n" + "".join(f"write-file {p}\nwait-reload\nwait-idle\n" for p in edits) + "quit\n"
        lines, frames, stderr = run_view(args.sdfc, scene, script, ["--spp", "1", "--size", "640x360"], d)
        reloads = [l for l in lines if "reload ok" in l][1:]  # the first is the initial load
        parse = lambda key, l: float(re.search(key + r" (\d+) ms", l).group(1))
        result["save_to_image_ms"] = [parse("save-to-image", l) for l in reloads]
        result["save_to_image_ms_median"] = statistics.median(result["save_to_image_ms"])
        result["reload_compile_ms_median"] = statistics.median(parse(r"\(compile", l) for l in reloads)
        result["reload_pipeline_ms_median"] = statistics.median(parse("pipeline", l) for l in reloads)
        result["reload_first_frame_ms_median"] = statistics.median(parse("first frame", l) for l in reloads)
        full = [parse("save-to-full-resolution", l) for l in lines if "reload full" in l][1:]
        result["save_to_full_resolution_ms"] = full
        result["save_to_full_resolution_ms_median"] = statistics.median(full)

        # 4. Input to presented frame (frames), from the orbit of run 1's log format.
        lines, frames, _ = run_view(args.sdfc, scene, "wait-idle\ndrag left 40 0 10\nwait 3\nquit\n",
                                    ["--spp", "1", "--size", "640x360"], d)
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
        # Reference in the same conditions: `sdfc render` (no window) of a 4-frame sequence
        # with one renderer; frames 2-4 are past LLVM's first-draw compile.
        for view, key in (("normal", "render_normal_640x360_ms"), ("beauty", "render_beauty_1spp_640x360_ms")):
            r = subprocess.run([args.sdfc, "render", scene, "-o", os.path.join(d, "ref.png"), "--size", "640x360",
                                "--spp", "1", "--view", view, "--frames", "0-0.3:0.1"], capture_output=True,
                               text=True, env=dict(os.environ, LP_NUM_THREADS="2"), timeout=600)
            times = [float(v) for v in re.findall(r"1 spp in ([0-9.]+)s", r.stderr)]
            if len(times) > 1:
                result[key] = statistics.median(times[1:]) * 1000
    result["machine"]["load_average_end"] = os.getloadavg()

    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    rows = [
        ("castle normal view 640x360, ms/frame (<= 31)", result["normal_640x360_ms_per_frame"]),
        ("  of which the render pass, ms", result["normal_640x360_render_ms"]),
        ("  frame interval incl. event loop, ms", result["normal_640x360_frame_interval_ms"]),
        ("castle path traced 1 spp/frame 640x360, fps (>= 5)", result["beauty_640x360_1spp_fps"]),
        ("  ms/frame", result["beauty_640x360_1spp_ms_per_frame"]),
        ("  of which the render pass, ms", result["beauty_640x360_1spp_render_ms"]),
        ("castle orbiting, dynamic resolution, fps", result.get("beauty_orbit_preview_fps", 0)),
        ("save-to-new-image latency, ms, median (<= 250)", result["save_to_image_ms_median"]),
        ("  to the first full-resolution frame, ms, median", result["save_to_full_resolution_ms_median"]),
        ("  compile / pipeline / first frame, ms", "%.0f / %.0f / %.0f" % (
            result["reload_compile_ms_median"], result["reload_pipeline_ms_median"],
            result["reload_first_frame_ms_median"])),
        ("input to presented frame, frames, max (<= 2)", result["input_to_frame_frames_max"]),
        ("reference: sdfc render --view normal, 1 pass, ms", result.get("render_normal_640x360_ms", 0)),
        ("reference: sdfc render beauty 1 spp, ms", result.get("render_beauty_1spp_640x360_ms", 0)),
    ]
    for name, value in rows:
        print(f"{name:52s} {value if isinstance(value, str) else round(value, 1)}")
    print("load average:", result["machine"]["load_average_start"], "->", result["machine"]["load_average_end"])
    print("wrote", args.out)


if __name__ == "__main__":
    main()
