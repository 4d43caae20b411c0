#!/usr/bin/python3
"""Large scenes as data (docs/design/large_scenes.md): how compile time, pipeline
creation, shader size, render speed and memory grow with the instance count.

  bench/large_scenes.py [--sdfc build/cli/sdfc] [--out bench/results/large_scenes.md]
                        [--counts 100,1000,10000,100000,1000000] [--spp 2] [--repeats 3]
                        [--before OLD_SDFC] [--quick]

Scenes: spheres at uniform random positions in a fixed box (40 x 8 x 40 above
a ground plane), written as instances(positions: file("points.csv")); the
radius shrinks as count^(-1/3) so every scene covers the same extent with the
same filled volume. Figures:
  1. per count: `sdfc compile --emit spv` (wall s, SPIR-V bytes), `sdfc render`
     at 64x36 1 spp with lavapipe's shader cache off (pipeline creation ms, wall s
     with the first draw's LLVM compile, peak RSS via /usr/bin/time); every timed
     render below runs after an untimed one, so the cache holds its kernel;
  2. the same 1,000 spheres as 1,000 inline union children (--instance-threshold 0):
     the shader that grows with the scene;
  3. per count at 640x360: loop iterations per pixel (kernel + grid lists +
     hierarchy visits, `--view iterations`), primary march steps, and ms per
     sample (median of --repeats runs, counts interleaved); the ratio 100 vs
     100,000 against the target (100k at >= 1/3 the speed of 100);
  3b. with --before OLD_SDFC: the same 100 and 100,000 scenes rendered by an
     older binary and this one, interleaved, in the same run (before/after);
     CPU ms per sample too ((9 spp - 1 spp) / 8, user + sys), steadier on a shared machine;
  4. peak RSS of one 640x360 1 spp render of 1,000,000 instances (target < 1 GiB);
  5. `sdfc check` of 200,000 spheres written as union children vs instances(file).
Needs numpy (Debian python3-numpy: run with /usr/bin/python3) and /usr/bin/time (package `time`).
"""
import argparse
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sdfbench as sb  # noqa: E402  (read_pfm; numpy: Debian's python3-numpy, /usr/bin/python3)

HEADER = """camera(position: [0, 26, 48], target: [0, 2, 0], fov: 45)
sun(direction: [-0.4, 0.8, 0.5], angle: 2, strength: 3)
sky(top: [0.35, 0.55, 0.9], bottom: [0.85, 0.88, 0.92])
let clay = diffuse(albedo: [0.75, 0.6, 0.5])
"""


def radius_for(count):
    # 100 spheres of radius 1.0: N r^3 constant.
    return 1.0 * (100.0 / count) ** (1.0 / 3.0)


def write_points(path, count, seed=1):
    rng = random.Random(seed)
    with open(path, "w") as f:
        f.write("x,y,z\n")
        for _ in range(count):
            f.write("%.5f,%.5f,%.5f\n" % (rng.uniform(-20, 20), rng.uniform(0.5, 8), rng.uniform(-20, 20)))


def write_instanced(dir_, count):
    points = os.path.join(dir_, "points_%d.csv" % count)
    if not os.path.exists(points):
        write_points(points, count)
    path = os.path.join(dir_, "instances_%d.sdf" % count)
    with open(path, "w") as f:
        f.write(HEADER)
        f.write("scene {\n  plane(offset: 0)\n")
        f.write('  instances(positions: file("%s"), material: clay) { sphere(radius: %.6g) }\n}\n'
                % (os.path.basename(points), radius_for(count)))
    return path


def write_union(dir_, count):
    rng = random.Random(1)
    path = os.path.join(dir_, "union_%d.sdf" % count)
    r = radius_for(count)
    with open(path, "w") as f:
        f.write(HEADER)
        f.write("scene {\n  plane(offset: 0)\n  union(material: clay) {\n")
        rng.random()
        for _ in range(count):
            f.write("    translate([%.5f, %.5f, %.5f]) { sphere(radius: %.6g) }\n"
                    % (rng.uniform(-20, 20), rng.uniform(0.5, 8), rng.uniform(-20, 20), r))
        f.write("  }\n}\n")
    return path


def timed(cmd, env=None):
    """Runs cmd under /usr/bin/time; returns (wall s, peak RSS MiB, stderr)."""
    full = ["/usr/bin/time", "-f", "SDFC_BENCH_RSS_KB %M"] + cmd
    start = time.perf_counter()
    proc = subprocess.run(full, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError("%s failed (%d):\n%s" % (" ".join(cmd), proc.returncode, proc.stderr[-2000:]))
    m = re.search(r"SDFC_BENCH_RSS_KB (\d+)", proc.stderr)
    return wall, int(m.group(1)) / 1024.0 if m else float("nan"), proc.stderr


def field(pattern, text, default=float("nan")):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else default


def shader_figures(sdfc, scene, dir_, flags=()):
    spv = os.path.join(dir_, "out.spv")
    compile_s, compile_rss, _ = timed([sdfc, "compile", scene, "--emit", "spv", "-o", spv] + list(flags))
    size = os.path.getsize(spv)
    png = os.path.join(dir_, "small.png")
    # A first render of a new scene: lavapipe's shader cache off, so the wall time
    # always holds its LLVM compile at the first draw (a cached kernel skips it).
    env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true")
    wall, rss, err = timed([sdfc, "render", scene, "-o", png, "--size", "64x36", "--spp", "1"] + list(flags), env)
    return {"compile_s": compile_s, "spirv_bytes": size, "pipeline_ms": field(r"pipeline in (\d+) ms", err),
            "render_wall_s": wall, "rss_mib": rss}


def ms_once(sdfc, scene, dir_, spp):
    warm(sdfc, scene, dir_)
    png = os.path.join(dir_, "big.png")
    _, _, err = timed([sdfc, "render", scene, "-o", png, "--size", "640x360", "--spp", str(spp),
                       "--denoise", "none"])
    return 1000.0 / field(r"spp in [^,]*, ([0-9.eE+-]+) spp/s", err)


_warm = set()


def warm(sdfc, scene, dir_, size="640x360"):
    """Render once, untimed, so that lavapipe's shader cache holds this binary's kernel
    for the scene: the first render of a new shader spends seconds in LLVM."""
    if (sdfc, scene, size) in _warm:
        return
    _warm.add((sdfc, scene, size))
    subprocess.run([sdfc, "render", scene, "-q", "-o", os.path.join(dir_, "warm.png"), "--size", size,
                    "--spp", "1"], capture_output=True)


def cpu_ms_per_sample(sdfc, scene, dir_):
    """CPU time (user + sys, all threads) per sample at 640x360: (9 spp - 1 spp) / 8. Less
    disturbed by other processes on a shared machine than wall time, and free of the
    per-process costs (startup, compile, pipeline, the first pass's overheads)."""
    warm(sdfc, scene, dir_)
    png = os.path.join(dir_, "cpu.png")
    cpu = []
    for spp in (1, 9):
        proc = subprocess.run(["/usr/bin/time", "-f", "SDFC_BENCH_CPU %U %S", sdfc, "render", scene, "-o", png,
                               "--size", "640x360", "--spp", str(spp), "--denoise", "none"],
                              capture_output=True, text=True)
        m = re.search(r"SDFC_BENCH_CPU ([0-9.]+) ([0-9.]+)", proc.stderr)
        if proc.returncode != 0 or not m:
            raise RuntimeError("render failed:\n" + proc.stderr[-2000:])
        cpu.append(float(m.group(1)) + float(m.group(2)))
    return 1000.0 * (cpu[1] - cpu[0]) / 8


def iterations(sdfc, scene, dir_):
    """Mean loop iterations and primary march steps per pixel at 640x360, 1 spp."""
    png = os.path.join(dir_, "it.png")
    _, _, err = timed([sdfc, "render", scene, "-o", png, "--size", "640x360", "--spp", "1", "--view", "iterations"])
    return field(r"loop iterations per pixel: mean ([0-9.eE+-]+)", err), field(r"primary ray steps: mean ([0-9.eE+-]+)", err)


def depth_disagreement(before, after, scene, dir_, flags_before=(), any_side=False):
    """Share of 640x360 pixels whose primary depth from `before` is over 1% nearer than from
    `after` (any_side: differs by over 1% either way)."""
    maps = []
    for i, (sdfc, flags) in enumerate(((before, flags_before), (after, ()))):
        path = os.path.join(dir_, "depth%d.pfm" % i)
        timed([sdfc, "render", scene, "-o", path, "--size", "640x360", "--spp", "1", "--view", "depth"] + list(flags))
        maps.append(sb.read_pfm(path)[..., 0].reshape(-1))
    a, b = maps
    if any_side:
        return float((abs(a - b) > 0.01 * abs(a)).mean())
    return float((a < 0.99 * b).mean())


def grid_summary(sdfc, scene):
    proc = subprocess.run([sdfc, "compile", scene, "--emit", "ir"], capture_output=True, text=True)
    m = re.search(r"grid (\S+) cells of [^,]*, lists of ([0-9.]+) on average, (?:(\d+) split, )?(\d+) crowded",
                  proc.stdout)
    return "%s, lists %s, %s split, %s crowded" % (m.group(1), m.group(2), m.group(3) or 0, m.group(4)) if m else "none"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap.add_argument("--sdfc", default=os.path.join(root, "build", "cli", "sdfc"))
    ap.add_argument("--out", default=os.path.join(root, "bench", "results", "large_scenes.md"))
    ap.add_argument("--counts", default="100,1000,10000,100000,1000000")
    ap.add_argument("--spp", type=int, default=2)
    ap.add_argument("--before", help="an older sdfc binary for a before/after comparison in the same run")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="small counts, for a smoke run")
    args = ap.parse_args()
    counts = [int(c) for c in args.counts.split(",")]
    big = 100000
    if args.quick:
        counts, big, args.spp, args.repeats = [100, 1000], 1000, 1, 1

    lines = ["# Large scenes as data", "",
             "Generated by `bench/large_scenes.py` on %s (%s CPUs, lavapipe; LP_NUM_THREADS=%s)."
             % (time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), os.cpu_count(),
                os.environ.get("LP_NUM_THREADS", "unset")), ""]

    def emit(line=""):
        print(line, flush=True)
        lines.append(line)

    with tempfile.TemporaryDirectory(prefix="sdfc_large_") as dir_:
        emit("## Shader size and pipeline creation against the instance count")
        emit("")
        emit("| instances | form | compile (s) | SPIR-V (bytes) | pipeline (ms) | 64x36 1 spp render, no shader cache, wall (s) | peak RSS (MiB) |")
        emit("|---:|---|---:|---:|---:|---:|---:|")
        for n in counts:
            f = shader_figures(args.sdfc, write_instanced(dir_, n), dir_)
            emit("| %d | data | %.2f | %d | %.0f | %.2f | %.0f |" % (n, f["compile_s"], f["spirv_bytes"],
                                                                  f["pipeline_ms"], f["render_wall_s"], f["rss_mib"]))
        n_inline = 1000 if not args.quick else 100
        f = shader_figures(args.sdfc, write_union(dir_, n_inline), dir_, ["--instance-threshold", "0"])
        emit("| %d | inline code (--instance-threshold 0) | %.2f | %d | %.0f | %.2f | %.0f |"
             % (n_inline, f["compile_s"], f["spirv_bytes"], f["pipeline_ms"], f["render_wall_s"], f["rss_mib"]))
        emit("")

        emit("## Render speed at 640x360, same extent, %d spp, median of %d interleaved runs" % (args.spp, args.repeats))
        emit("")
        speed_counts = sorted(set(counts + [100, big]))
        scenes = {n: write_instanced(dir_, n) for n in speed_counts}
        runs = {n: [] for n in speed_counts}
        for _ in range(args.repeats):
            for n in speed_counts:
                runs[n].append(ms_once(args.sdfc, scenes[n], dir_, args.spp))
        emit("| instances | sphere radius | grid (cells, mean list, split and crowded cells) | loop iterations / pixel | primary steps / pixel | ms per sample (median) | runs |")
        emit("|---:|---:|---|---:|---:|---:|---|")
        med = {}
        for n in speed_counts:
            it, steps = iterations(args.sdfc, scenes[n], dir_)
            med[n] = statistics.median(runs[n])
            emit("| %d | %.3g | %s | %.0f | %.1f | %.0f | %s |" % (n, radius_for(n), grid_summary(args.sdfc, scenes[n]), it,
                                                             steps, med[n], ", ".join("%.0f" % x for x in runs[n])))
        emit("")
        emit("Speed of %d instances relative to 100, wall ms per sample at %d spp: %.2f (target >= 0.33). "
             "Each render's fixed costs (its first pass, the AOV ray) are in the figure: at few spp they "
             "dilute the ratio toward 1; the steady state is the CPU figure below, or --spp 16."
             % (big, args.spp, med[100] / med[big]))
        emit("")
        # The grid's bound against exact distances: the same 1,000 spheres as inline code.
        it_g, st_g = iterations(args.sdfc, scenes[1000] if 1000 in scenes else write_instanced(dir_, 1000), dir_)
        png = os.path.join(dir_, "it.png")
        _, _, err = timed([args.sdfc, "render", write_instanced(dir_, 1000), "-o", png, "--size", "640x360",
                           "--spp", "1", "--view", "iterations", "--instance-threshold", "0"])
        emit("Primary steps per pixel for 1000 spheres: %.2f through the grid, %.2f with exact distances"
             " (inline code; its loop iterations per pixel: %.0f vs %.0f through the grid)."
             % (st_g, field(r"primary ray steps: mean ([0-9.eE+-]+)", err),
                field(r"loop iterations per pixel: mean ([0-9.eE+-]+)", err), it_g))
        emit("")
        emit("Pixels whose primary depth differs by over 1%% between the grid and the inline code (1000"
             " spheres, 640x360): %.2f%%." % (100 * depth_disagreement(
                 args.sdfc, args.sdfc, write_instanced(dir_, 1000), dir_, ["--instance-threshold", "0"], True)))
        emit("")
        if args.before:
            emit("## Before/after, same run (%s vs %s), %d spp, median of %d interleaved"
                 % (args.before, args.sdfc, args.spp, args.repeats))
            emit("")
            ab = {(b, n): [] for b in ("before", "after") for n in speed_counts}
            cpu = {(b, n): [] for b in ("before", "after") for n in speed_counts}
            for _ in range(args.repeats):
                for n in speed_counts:
                    ab[("before", n)].append(ms_once(args.before, scenes[n], dir_, args.spp))
                    ab[("after", n)].append(ms_once(args.sdfc, scenes[n], dir_, args.spp))
                    cpu[("before", n)].append(cpu_ms_per_sample(args.before, scenes[n], dir_))
                    cpu[("after", n)].append(cpu_ms_per_sample(args.sdfc, scenes[n], dir_))
            emit("Wall ms per sample at %d spp (as above), and CPU ms per sample (user + sys, (9 spp - 1 spp) / 8),"
                 " medians:" % args.spp)
            emit("")
            emit("| instances | before ms/sample | after ms/sample | before/after | before CPU ms/sample | after |"
                 " before/after | before iterations / pixel | after |")
            emit("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
            for n in speed_counts:
                b, a = statistics.median(ab[("before", n)]), statistics.median(ab[("after", n)])
                cb, ca = statistics.median(cpu[("before", n)]), statistics.median(cpu[("after", n)])
                emit("| %d | %.0f | %.0f | %.2f | %.0f | %.0f | %.2f | %.0f | %.0f |"
                     % (n, b, a, b / a, cb, ca, cb / ca, iterations(args.before, scenes[n], dir_)[0],
                        iterations(args.sdfc, scenes[n], dir_)[0]))
            emit("")

            def ratio(d, b):
                return statistics.median(d[(b, 100)]) / statistics.median(d[(b, big)])
            emit("Ratio %d vs 100, wall: before %.2f, after %.2f; CPU: before %.2f, after %.2f." % (
                big, ratio(ab, "before"), ratio(ab, "after"), ratio(cpu, "before"), ratio(cpu, "after")))
            emit("")
            emit("Primary rays of %d instances whose depth differs by over 1%% between the before binary and"
                 " this one (`--view depth`, 640x360): %.2f%% of pixels." % (big, 100 * depth_disagreement(
                     args.before, args.sdfc, scenes[big], dir_, any_side=True)))
            emit("")
            # No regression on a scene without instances: the castle, before/after interleaved.
            castle = os.path.join(root, "examples", "castle.sdf")
            cr = {"before": [], "after": []}
            cc = {"before": [], "after": []}
            for _ in range(args.repeats):
                cr["before"].append(ms_once(args.before, castle, dir_, args.spp))
                cr["after"].append(ms_once(args.sdfc, castle, dir_, args.spp))
                cc["before"].append(cpu_ms_per_sample(args.before, castle, dir_))
                cc["after"].append(cpu_ms_per_sample(args.sdfc, castle, dir_))
            b, a = statistics.median(cr["before"]), statistics.median(cr["after"])
            cb, ca = statistics.median(cc["before"]), statistics.median(cc["after"])
            emit("examples/castle.sdf, 640x360 %d spp, median of %d interleaved: before %.0f ms/sample (%.2f spp/s),"
                 " after %.0f ms/sample (%.2f spp/s), before/after %.2f; CPU ms/sample %.0f -> %.0f;"
                 " loop iterations / pixel %.1f -> %.1f."
                 % (args.spp, args.repeats, b, 1000 / b, a, 1000 / a, b / a, cb, ca,
                    iterations(args.before, castle, dir_)[0], iterations(args.sdfc, castle, dir_)[0]))
            emit("")

        n_rss = max(counts)
        scene = write_instanced(dir_, n_rss)
        wall, rss, _ = timed([args.sdfc, "render", scene, "-o", os.path.join(dir_, "rss.png"),
                              "--size", "640x360", "--spp", "1"])
        emit("## Peak memory end to end")
        emit("")
        emit("`sdfc render` of %d instances at 640x360, 1 spp: peak RSS %.0f MiB, wall %.1f s (target < 1024 MiB)."
             % (n_rss, rss, wall))
        emit("")

        n_check = 200000 if not args.quick else 2000
        union = write_union(dir_, n_check)
        inst = write_instanced(dir_, n_check)
        cu, ru, _ = timed([args.sdfc, "check", union])
        ci, ri, _ = timed([args.sdfc, "check", inst])
        emit("## `sdfc check` of %d spheres" % n_check)
        emit("")
        emit("| written as | wall (s) | peak RSS (MiB) |")
        emit("|---|---:|---:|")
        emit("| %d union children (translate { sphere }) | %.2f | %.0f |" % (n_check, cu, ru))
        emit("| instances(positions: file(...)) | %.2f | %.0f |" % (ci, ri))
        emit("")

    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote", args.out)


if __name__ == "__main__":
    main()
