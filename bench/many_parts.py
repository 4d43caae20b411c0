#!/usr/bin/python3
"""Scenes of many distinct parts (issue 46): cost and exactness per family and
part count, written to bench/results/many_parts.md (and .json).

  bench/many_parts.py [--sdfc build/cli/sdfc] [--before OLD_SDFC]
                      [--families molecule,kitbash,tree,holes,city,chess]
                      [--counts 10,100,1000] [--smooth 0.05] [--repeats 3]
                      [--size 320x180] [--spp 8] [--min-sampling-s 1.0] [--mesh-counts 1000]
                      [--framing sphere|legacy]
  bench/many_parts.py --first-image [--before OLD_SDFC] [--counts 10000] [--repeats 3]

Families come from bench/many_parts_scenes.py, framed (--framing sphere, the
default) so that the family's bounding sphere spans the same share of the view
at every count; --framing legacy is the camera of the pages before 2026-12-06,
which stood back from a small clump (kitbash: 853 hit pixels of 14,400 at 10
parts, 3,775 at 1,000), so part of their cost growth was coverage.
Per family and count:
  - compile: `sdfc compile --emit spv` wall seconds (SPIR-V cache off);
  - first image: `sdfc render` at 64x36, 1 spp, lavapipe's shader cache off:
    pipeline creation and the whole process (its first draw compiles the
    kernel with LLVM); peak RSS of that process (/usr/bin/time);
  - spp/s at --size and --spp with no denoiser (median of --repeats, the
    binaries interleaved when --before is given), and CPU ms per sample: the
    process's CPU seconds at --spp (more where --spp samples for less than
    --min-sampling-s of CPU) less those of a 1 spp render of the same
    scene (run beside it, both after a warm-up render fills Mesa's shader
    cache), over --spp - 1, so compiles, pipeline creation and the first
    draw's kernel compile are not counted; "process CPU ms/spp" is
    the whole process's CPU over --spp, the figure of the pages before
    2026-12-06 (at 10 parts it was mostly start-up);
  - primary steps per pixel (`--view steps`' mean);
  - hit pixels of a 160x90 depth render, and the CPU time per sample divided
    by them (us per hit pixel, scaled to --size) and by the primary steps (ns
    per primary step): how much of the growth is coverage, how much a step's;
  - pixels off: a 160x90 depth render checked against `sdfc eval` (float64):
    a hit must lie within a pixel's footprint of the surface and no surface
    may lie clearly before it on the ray (the check of tests/many_parts_test.cpp);
  - with --mesh-counts: `sdfc mesh` at resolution 128 of the smooth molecule.
With --first-image, only the first image (issue 46's "compile + pipeline +
first sample"): --repeats runs per binary, interleaved, medians of the whole
process's wall and CPU seconds (os.wait4: user + system of every thread) and
of `--timings`' front end, pipeline creation and first draw (the driver's LLVM
compile), to bench/results/many_parts_first_image.md (and .json).
Needs numpy (Debian's python3-numpy: run with /usr/bin/python3) and /usr/bin/time.
"""
import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import many_parts_scenes as mps  # noqa: E402
import sdfbench as sb  # noqa: E402


def timed(cmd, env=None):
    """Wall seconds, peak RSS (MiB) and stderr of a whole process."""
    full = ["/usr/bin/time", "-f", "MAXRSS %M"] + cmd
    start = time.perf_counter()
    p = subprocess.run(full, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr[-2000:]}")
    m = re.search(r"MAXRSS (\d+)", p.stderr)
    return wall, (int(m.group(1)) / 1024 if m else float("nan")), p.stderr


def cold_env():
    env = dict(os.environ, SDFC_NO_CACHE="1", MESA_SHADER_CACHE_DISABLE="true")
    env.setdefault("GALLIVM_PERF", "")
    return env


def first_image(sdfc, scene, out):
    wall, rss, err = timed([sdfc, "render", scene, "-o", out, "--size", "64x36", "--spp", "1",
                            "--denoise", "none", "--timings"], cold_env())
    m = re.search(r"pipeline[^0-9]*([0-9.]+) ?ms", err)
    return wall, rss, float(m.group(1)) if m else float("nan")


def first_image_stages(sdfc, scene, out):
    """One cold first image: wall s, CPU s (the process and its threads) and --timings' stages (ms)."""
    start = time.perf_counter()
    p = subprocess.Popen([sdfc, "render", scene, "-o", out, "--size", "64x36", "--spp", "1",
                          "--denoise", "none", "--timings", "-q"], env=cold_env(),
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - start
    if status != 0:
        raise RuntimeError(f"{sdfc} render {scene} failed:\n{err[-2000:]}")
    stages = {}
    for key, label in (("front_ms", "front end"), ("pipeline_ms", "pipeline creation"),
                       ("first_draw_ms", "first draw")):
        m = re.search(re.escape(label) + r"[^\n]*?\s([0-9.]+)\s+[0-9.]+%", err)
        stages[key] = float(m.group(1)) if m else float("nan")
    return dict(wall_s=wall, cpu_s=usage.ru_utime + usage.ru_stime, **stages)


def family_scenes(args, families, counts, dir_):
    """(family, parts, smooth, path) of each scene to measure, written to dir_:
    the chess set is 32 pieces whatever the count; only molecules and
    kit-bashes blend."""
    for fam in families:
        for n in ([32] if fam == "chess" else counts):
            smooth = args.smooth if fam in ("molecule", "kitbash") else 0.0
            scene = os.path.join(dir_, f"{fam}_{n}.sdf")
            with open(scene, "w") as f:
                f.write(mps.scene(fam, n, smooth, framing=args.framing))
            yield fam, n, smooth, scene


def first_image_mode(args, binaries, families, counts):
    """The first image per family and count, binaries interleaved (--first-image)."""
    out = os.path.join(HERE, "results", "many_parts_first_image.md") if args.out is None else args.out
    machine = sb.machine_info(args.sdfc)
    keys = ("wall_s", "cpu_s", "front_ms", "pipeline_ms", "first_draw_ms")
    lines = ["# First image of many distinct parts (bench/many_parts.py --first-image)", "",
             f"Machine: {machine['cpu']}, {machine['cores']} cores, {machine['device']}, {machine['driver']}; "
             f"load average at the start {os.getloadavg()[0]:.1f}. `sdfc render` at 64x36, 1 spp, no denoiser, "
             f"Mesa's shader cache and sdfc's SPIR-V cache off, LLVM optimised (GALLIVM_PERF empty); "
             f"smooth {args.smooth} where the family blends; medians of {args.repeats}, binaries interleaved.", "",
             "| family | parts | binary | whole process s | CPU s | front end ms | pipeline ms | first draw ms |",
             "|---|---|---|---|---|---|---|---|"]
    for line in lines:
        print(line, flush=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="many_parts_") as dir_:
        for fam, n, smooth, scene in family_scenes(args, families, counts, dir_):
            runs = {name: [] for name, _ in binaries}
            for _ in range(args.repeats):
                for name, exe in binaries:
                    runs[name].append(first_image_stages(exe, scene, os.path.join(dir_, "f.png")))
            for name, _ in binaries:
                row = dict(family=fam, parts=n, binary=name, smooth=smooth, runs=runs[name])
                row.update({k: statistics.median(r[k] for r in runs[name]) for k in keys})
                rows.append(row)
                line = (f"| {fam} | {n} | {name} | {row['wall_s']:.2f} | {row['cpu_s']:.2f} | {row['front_ms']:.0f} | "
                        f"{row['pipeline_ms']:.0f} | {row['first_draw_ms']:.0f} |")
                print(line, flush=True)
                lines.append(line)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.splitext(out)[0] + ".json", "w") as f:
        json.dump(rows, f, indent=1)
    print(f"wrote {out}")


def compile_s(sdfc, scene):
    start = time.perf_counter()
    subprocess.run([sdfc, "compile", scene, "--emit", "spv", "-o", os.devnull], check=True,
                   capture_output=True, env=cold_env())
    return time.perf_counter() - start


def sampling(sdfc, scene, out, size, spp):
    """spp/s, the process's CPU seconds, and those of a 1 spp render."""
    info = sb.render(sdfc, scene, out, ["--size", size, "--spp", str(spp), "-Wno-bound"])
    one = sb.render(sdfc, scene, out, ["--size", size, "--spp", "1", "-Wno-bound"])
    return info["spp_per_s"], info["cpu_s"], one["cpu_s"]


def family_order(family):
    """A family's place on the page: bench/many_parts_scenes.py's order, whichever were measured."""
    order = list(mps.FAMILIES)
    return order.index(family) if family in order else len(order)


# The most samples a row's timed renders take (sampled_spp).
MAX_SAMPLED_SPP = 512


def sampled_spp(todo, scene, out, args):
    """The spp of a row's timed renders: --spp, or more where --spp samples
    for less than --min-sampling-s of CPU (a 10-twig tree samples in 1-8 ms,
    so at 8 spp its CPU difference was mostly the two processes' noise and
    every ratio to it moved by 2-8x between runs). From the first binary's
    one render, the same for every binary of the row."""
    try:
        _, cpu, cpu_one = sampling(todo[0][1], scene, out, args.size, args.spp)
    except (RuntimeError, IndexError):
        return args.spp
    took = max(cpu - cpu_one, 1e-3)
    if took >= args.min_sampling_s:
        return args.spp
    return min(MAX_SAMPLED_SPP, max(args.spp, math.ceil(args.spp * args.min_sampling_s / took)))


def primary_steps(sdfc, scene, dir_, size):
    path = os.path.join(dir_, "steps.pfm")
    info = sb.render(sdfc, scene, path, ["--size", size, "--spp", "1", "--view", "steps", "-Wno-bound"])
    # The steps view's PFM holds the raw count (bench/geometry.py).
    return float(np.mean(np.rint(sb.read_pfm(path)[..., 0])))


CHECK_W, CHECK_H = 160, 90


def hit_pixels(sdfc, scene, dir_, width=CHECK_W, height=CHECK_H):
    """Pixels of a primary depth render that hit a surface."""
    path = os.path.join(dir_, "depth.pfm")
    sb.render(sdfc, scene, path, ["--size", f"{width}x{height}", "--spp", "1", "--view", "depth", "-q"])
    return int((sb.read_pfm(path)[..., 0] >= 0).sum())


def per_work(row, size):
    """CPU us per sample per hit pixel (hits scaled to --size), ns per primary step."""
    w, h = (int(x) for x in size.split("x"))
    hits = row.get("hits", 0) * (w * h) / (CHECK_W * CHECK_H)
    us_hit = 1000 * row["cpu_ms_per_sample"] / hits if hits else float("nan")
    steps = row["primary_steps"] * w * h
    ns_step = 1e6 * row["cpu_ms_per_sample"] / steps if steps else float("nan")
    return us_hit, ns_step


def pixels_off(sdfc, scene, dir_, width=CHECK_W, height=CHECK_H):
    """(hit pixels, off the surface, a surface clearly before, missed) against float64."""
    path = os.path.join(dir_, "depth.pfm")
    sb.render(sdfc, scene, path, ["--size", f"{width}x{height}", "--spp", "1", "--view", "depth", "-q"])
    depth = sb.read_pfm(path)[..., 0].reshape(-1)
    cam = sb.parse_camera(sb.compile_text(sdfc, scene, "ir"))
    ro, rd = sb.camera_rays(cam, width, height)
    rd = rd.reshape(-1, 3)
    tan_half = math.tan(math.radians(cam["fov"]) / 2)
    fp = lambda t: np.maximum(t, 1e-3) * 2 * tan_half / height
    ev = sb.Evaluator(sdfc, scene)
    try:
        n = len(rd)
        hit = depth >= 0
        field = np.full(n, np.nan)
        field[hit] = ev(ro + rd[hit] * depth[hit, None])
        off = hit & (np.abs(field) > fp(depth))
        # The float64 march, all rays at once (tests/many_parts_test.cpp's rule).
        t = np.zeros(n)
        found = np.zeros(n, bool)
        active = np.ones(n, bool)
        reach = 4 * np.linalg.norm(ro)
        for _ in range(600):
            idx = np.nonzero(active)[0]
            if len(idx) == 0:
                break
            d = ev(ro + rd[idx] * t[idx, None])
            f = fp(t[idx])
            near = d < 0.25 * f
            far = idx[~near]
            t[far] += d[~near]
            cand = idx[near]
            if len(cand):
                inside = np.zeros(len(cand), bool)
                for j in range(9):
                    pts = ro + rd[cand] * (t[cand] + 0.5 * j * fp(t[cand]))[:, None]
                    inside |= ev(pts) < -0.5 * fp(t[cand])
                found[cand[inside]] = True
                active[cand[inside]] = False
                rest = cand[~inside]
                t[rest] += np.maximum(d[near][~inside], 0.5 * fp(t[rest]))
            active &= t < reach
        early = hit & found & (t < depth - 2 * fp(depth))
        missed = ~hit & found
        return int(hit.sum()), int(off.sum()), int(early.sum()), int(missed.sum())
    finally:
        ev.close()


def mesh_s(sdfc, scene, dir_):
    out = os.path.join(dir_, "m.stl")
    wall, rss, _ = timed([sdfc, "mesh", scene, "-o", out, "--resolution", "128"])
    return wall, rss


def row_line(r, size):
    if "refused" in r:
        return f"| {r['family']} | {r['parts']} | {r['binary']} | refused: {r['refused']} |"
    us_hit, ns_step = per_work(r, size)
    return (f"| {r['family']} | {r['parts']} | {r['binary']} | {r['compile_s']:.2f} | {r['first_image_s']:.2f} | "
            f"{r['pipeline_ms']:.0f} | {r['peak_mib']:.0f} | {r['spp_per_s']:.2f} | "
            f"{r.get('process_cpu_ms_per_spp', r['cpu_ms_per_sample']):.0f} | "
            f"{r['cpu_ms_per_sample'] if 'process_cpu_ms_per_spp' in r else float('nan'):.0f} | {r['primary_steps']:.1f} | {r.get('hits', '-')} | "
            f"{us_hit:.1f} | {ns_step:.0f} | {r.get('off', '-')} | {r.get('early', '-')} | {r.get('missed', '-')} |")


def resumed_repeats(rows, repeats):
    """" (of 3: tree, holes)" for resumed rows measured with another --repeats."""
    other = {}
    for r in rows:
        if r.get("repeats", repeats) != repeats:
            other.setdefault(r["repeats"], []).append(r["family"])
    return "".join(f" (of {k}: {', '.join(dict.fromkeys(v))}, resumed from an earlier run)" for k, v in sorted(other.items()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--before", help="an older sdfc, timed interleaved with --sdfc")
    ap.add_argument("--families", default="molecule,kitbash,tree,holes,city,chess")
    ap.add_argument("--counts", default="10,100,1000")
    ap.add_argument("--smooth", type=float, default=0.05)
    ap.add_argument("--framing", choices=mps.FRAMINGS, default="sphere",
                    help="sphere: the same share of the view at every count; legacy: the old camera")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--size", default="320x180")
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--min-sampling-s", type=float, default=1.0,
                    help="render more than --spp where --spp samples for less CPU time than this")
    ap.add_argument("--mesh-counts", default="")
    ap.add_argument("--no-check", action="store_true", help="skip the float64 pixel check")
    ap.add_argument("--out", default=None, help="the page (default bench/results/many_parts.md, "
                    "or many_parts_first_image.md with --first-image)")
    ap.add_argument("--first-image", action="store_true",
                    help="only the first image's cost, with its stages (issue 46's 2 s goal at 10k parts)")
    ap.add_argument("--resume", action="store_true", help="keep the rows of --out's .json and measure the rest")
    args = ap.parse_args()
    binaries = [("after", args.sdfc)] + ([("before", args.before)] if args.before else [])
    families = args.families.split(",")
    counts = [int(c) for c in args.counts.split(",")]
    if args.first_image:
        first_image_mode(args, binaries, families, counts)
        return
    if args.out is None:
        args.out = os.path.join(HERE, "results", "many_parts.md")
    rows = []
    lines = []
    json_path = os.path.splitext(args.out)[0] + ".json"
    if args.resume and os.path.exists(json_path):
        with open(json_path) as f:
            # Rows of another framing are another benchmark, and rows from
            # before 2026-12-06 (no framing recorded) timed the whole process.
            rows = [r for r in json.load(f) if r.get("framing") == args.framing]
    done = {(r["family"], r["parts"], r["binary"]) for r in rows}

    def emit(line=""):
        print(line, flush=True)
        lines.append(line)

    emit("# Scenes of many distinct parts (bench/many_parts.py)")
    emit()
    machine = sb.machine_info(args.sdfc)
    emit(f"Machine: {machine['cpu']}, {machine['cores']} cores, {machine['device']}, {machine['driver']}. Size {args.size}, {args.spp} spp, no denoiser, "
         f"smooth {args.smooth} where the family blends; medians of {args.repeats}{resumed_repeats(rows, args.repeats)}.")
    emit()
    emit("CPU ms/sample is the sampling's alone (the process's CPU at the given spp less a 1 spp run's, over "
         "spp - 1; since 2026-12-06); process CPU ms/spp, the figure before, also counts the compile, the "
         "pipeline and the first draw's kernel compile, which at 10 parts were most of it.")
    emit("The last page of the old measure (legacy framing, whole-process CPU, 2026-12-05) is "
         "bench/results/many_parts_legacy_framing.md.")
    emit()
    if args.framing == "sphere":
        emit("Framing: each family's bounding sphere spans the same share of the view at every count "
             "(`--framing sphere`, since 2026-12-06). Before, the camera stood back from small clumps "
             "(`--framing legacy`), so most of a small count's pixels were sky and part of the growth "
             "was coverage; the per hit pixel and per primary step columns separate the two.")
    else:
        emit("Framing: legacy (the camera of the pages before 2026-12-06: small clumps seen from farther "
             "away, so coverage grows with the count).")
    emit()
    head = ("| family | parts | binary | compile s | first image s | pipeline ms | peak MiB | spp/s "
            "| process CPU ms/spp | CPU ms/sample | primary steps | hit px | CPU us/hit px | CPU ns/primary step | off | before | missed |")
    emit(head)
    emit("|" + "|".join(["---"] * (head.count("|") - 1)) + "|")
    with tempfile.TemporaryDirectory(prefix="many_parts_") as dir_:
        for fam, n, smooth, scene in family_scenes(args, families, counts, dir_):
            per = {name: {"spp": [], "cpu": [], "process": []} for name, _ in binaries}
            refused = {}
            todo = [(name, exe) for name, exe in binaries if (fam, n, name) not in done]
            # Warm Mesa's shader cache, so that neither of a repeat's two
            # renders pays the kernel's LLVM compile the other does not.
            for name, exe in todo:
                try:
                    sb.render(exe, scene, os.path.join(dir_, "w.pfm"), ["--size", args.size, "--spp", "1", "-Wno-bound"])
                except RuntimeError:
                    pass  # refused: the repeats below say why
            spp = sampled_spp(todo, scene, os.path.join(dir_, "b.pfm"), args)
            for _ in range(args.repeats):
                for name, exe in todo:
                    if name in refused:
                        continue
                    try:
                        spp_s, cpu, cpu_one = sampling(exe, scene, os.path.join(dir_, "b.pfm"), args.size, spp)
                    except RuntimeError as e:  # e.g. an older binary's limit
                        refused[name] = str(e).splitlines()[1][:160] if len(str(e).splitlines()) > 1 else str(e)
                        continue
                    per[name]["spp"].append(spp_s)
                    per[name]["cpu"].append(1000 * (cpu - cpu_one) / (spp - 1))
                    per[name]["process"].append(1000 * cpu / spp)
            for name, exe in todo:
                row = dict(family=fam, parts=n, binary=name, smooth=smooth, framing=args.framing,
                           repeats=args.repeats, spp=spp)
                if name in refused:
                    row["refused"] = refused[name]
                    rows.append(row)
                    emit(f"| {fam} | {n} | {name} | refused: {refused[name]} |")
                    continue
                row["compile_s"] = compile_s(exe, scene)
                row["first_image_s"], row["peak_mib"], row["pipeline_ms"] = first_image(
                    exe, scene, os.path.join(dir_, "f.png"))
                row["spp_per_s"] = statistics.median(per[name]["spp"])
                row["cpu_ms_per_sample"] = statistics.median(per[name]["cpu"])
                row["process_cpu_ms_per_spp"] = statistics.median(per[name]["process"])
                row["primary_steps"] = primary_steps(exe, scene, dir_, args.size)
                if not args.no_check:
                    row["hits"], row["off"], row["early"], row["missed"] = pixels_off(exe, scene, dir_)
                else:
                    row["hits"] = hit_pixels(exe, scene, dir_)
                rows.append(row)
                emit(row_line(row, args.size))
        if args.mesh_counts:
            emit()
            emit("| mesh: molecule parts | binary | `sdfc mesh --resolution 128` s | peak MiB |")
            emit("|---|---|---|---|")
            for n in [int(c) for c in args.mesh_counts.split(",")]:
                scene = os.path.join(dir_, f"mesh_{n}.sdf")
                with open(scene, "w") as f:
                    f.write(mps.scene("molecule", n, args.smooth))
                for name, exe in binaries:
                    wall, rss = mesh_s(exe, scene, dir_)
                    rows.append(dict(family="molecule-mesh", parts=n, binary=name, mesh_s=wall, peak_mib=rss))
                    emit(f"| {n} | {name} | {wall:.2f} | {rss:.0f} |")
    # The page holds every row, resumed ones too, in family order.
    head_at = lines.index(head)
    body = []
    for r in sorted((r for r in rows if "mesh_s" not in r),
                    key=lambda r: (family_order(r["family"]), r["parts"], r["binary"] != "after")):
        body.append(row_line(r, args.size))
    end = head_at + 2
    while end < len(lines) and lines[end].startswith("| ") and "mesh" not in lines[end]:
        end += 1
    lines[head_at + 2:end] = body
    # Cost growth per family: spp/s of the smallest count over each count's.
    emit()
    more = [f"{r['family']} {r['parts']}: {r['spp']}" for r in rows if r.get("spp", args.spp) > args.spp]
    if more:
        emit(f"Rows timed at more than {args.spp} spp (their {args.spp} spp sampled for less than "
             f"{args.min_sampling_s:g} s of CPU; since 2026-12-07): " + ", ".join(dict.fromkeys(more)) + ".")
        emit()
    emit("All rows (this run's and earlier resumed ones, each measured with the binaries of its own run) are in the .json beside this page.")
    emit()
    emit("Cost relative to the family's smallest count: CPU ms per sample; in brackets per hit pixel, "
         "then per primary step (coverage and march length taken out):")
    emit()
    for name, _ in binaries:
        # Every family on the page, resumed ones too.
        for fam in sorted(dict.fromkeys(r["family"] for r in rows), key=family_order):
            base = sorted((r for r in rows if r["family"] == fam and r["binary"] == name and "cpu_ms_per_sample" in r),
                          key=lambda r: r["parts"])
            if not base:
                continue
            b_hit, b_step = per_work(base[0], args.size)
            parts = []
            for r in base:
                hit, step = per_work(r, args.size)
                parts.append(f"{r['parts']}: {r['cpu_ms_per_sample'] / base[0]['cpu_ms_per_sample']:.2f}x "
                             f"({hit / b_hit:.2f}x, {step / b_step:.2f}x)")
            emit(f"- {name} {fam}: " + ", ".join(parts))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    # In family order, resumed rows among them (the headline keeps this order).
    rows.sort(key=lambda r: family_order(r["family"]))
    with open(os.path.splitext(args.out)[0] + ".json", "w") as f:
        json.dump(rows, f, indent=1)
    print(f"wrote {args.out}")
    if os.path.abspath(args.out) == os.path.join(HERE, "results", "many_parts.md"):
        update_headline()


def update_headline():
    """Replaces bench/RESULTS.md's many-parts section with the headline of the
    page just written (bench/run.py writes the same section when it runs)."""
    import run  # noqa: E402  (bench/run.py: the headline's one definition)
    report = os.path.join(HERE, "RESULTS.md")
    title = "## Many distinct parts (headline of results/many_parts.md)"
    if not os.path.exists(report):
        return
    with open(report) as f:
        text = f.read()
    start = text.find(title)
    if start < 0:
        return
    end = text.find("\n## ", start + len(title))
    end = len(text) if end < 0 else end + 1
    with open(report, "w") as f:
        f.write(text[:start] + "\n".join(run.many_parts_headline()) + "\n" + text[end:])
    print(f"updated {report}")


if __name__ == "__main__":
    main()
