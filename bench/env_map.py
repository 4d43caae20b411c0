#!/usr/bin/python3
"""What an environment map costs, and how fast it converges (issue 33's
targets: at most 15% of the sun-and-sky castle's samples per second for any
map up to 4096 x 2048; faster than uniform sampling in relMSE at equal time).

    bench/env_map.py [--sdfc build/cli/sdfc] [--against other/sdfc] [--reps 5] [--size 320x180] [--spp 16]
                     [--out bench/results/ENV_MAP.md]

1. Cost: examples/castle.sdf as it is (gradient sky and sun) and with its sky
   replaced by the procedural studio map (tools/envmap.py) at 64 x 32,
   1024 x 512 and 4096 x 2048, the sun kept; the cases alternate run by run,
   and the figure is the median of the per-repetition ratios of sdfc's
   samples per second (passes only). The compile's wall time and the
   process's peak memory give the map's load, build and upload cost.
2. Convergence: examples/envmap/studio.sdf at 96 x 54, 2 bounces, against a
   1024-spp reference: the map importance-sampled (default), sampled
   uniformly over the sphere (SDFC_ENVMAP_SAMPLING=uniform, the same MIS), and
   BSDF sampling alone (--light-samples 0). relMSE x render seconds is the
   inverse efficiency: at equal time, relMSE is proportional to it.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
import envmap  # noqa: E402
import sdfbench as sb  # noqa: E402

CASTLE = os.path.join(ROOT, "examples", "castle.sdf")
STUDIO = os.path.join(ROOT, "examples", "envmap", "studio.sdf")
SKY = "sky(top: [0.32, 0.52, 0.92], bottom: [0.85, 0.88, 0.92])"


def run_measured(cmd, env=None):
    """Wall seconds, CPU seconds and ru_maxrss (MiB; not the process's own peak: Linux
    counts the forking parent's) of one sdfc process, and its stderr."""
    env = dict(os.environ if env is None else env, SDFC_NO_CACHE="1")
    env.setdefault("GALLIVM_PERF", "")
    with tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err, env=env)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        err.seek(0)
        text = err.read()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{text}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024, text


def cost(args, tmp, lines):
    with open(CASTLE) as f:
        castle = f.read()
    assert SKY in castle
    scenes = {"castle (gradient sky + sun)": CASTLE}
    for w in (64, 1024, 4096):
        path = os.path.join(tmp, f"studio {w}.exr")
        envmap.write_exr(path, envmap.studio(w))
        scene = os.path.join(tmp, f"castle map {w}.sdf")
        with open(scene, "w") as f:
            f.write(castle.replace(SKY, f'sky(map: "studio {w}.exr")'))
        scenes[f"castle, map {w} x {w // 2} + sun"] = scene
    # With --against, each scene is run by both binaries, alternated: a
    # paired A/B in one run (A the other binary, B --sdfc).
    binaries = [("", args.sdfc)] if not args.against else [(" (A)", args.against), (" (B)", args.sdfc)]
    castles = {tag: "castle (gradient sky + sun)" + tag for tag, _ in binaries}
    sdfc_of = {name + tag: sdfc for name in scenes for tag, sdfc in binaries}
    castle_of = {name + tag: castles[tag] for name in scenes for tag, _ in binaries}
    scenes = {name + tag: path for name, path in scenes.items() for tag, _ in binaries}
    speeds = {k: [] for k in scenes}
    cpus = {k: [] for k in scenes}
    loads = {k: [] for k in scenes}
    out = os.path.join(tmp, "out.pfm")
    flags = ["--size", args.size, "--spp", str(args.spp), "--denoise", "none"]
    for rep in range(args.reps):
        order = list(scenes) if rep % 2 == 0 else list(scenes)[::-1]
        for name in order:
            sdfc = sdfc_of[name]
            info = sb.render(sdfc, scenes[name], out, flags)
            # The same render at 1 spp: its CPU seconds are the fixed costs
            # (compile, JIT, map load); the difference is the N - 1 samples'.
            one = sb.render(sdfc, scenes[name], out, ["--size", args.size, "--spp", "1", "--denoise", "none"])
            speeds[name].append(info["spp_per_s"])
            cpus[name].append(info["cpu_s"] - one["cpu_s"])
            # The map's fixed cost: `--emit ir` reads and checks it; `--emit glsl`
            # also builds its distribution and the scene data (no glslang).
            _, ir_cpu, ir_rss, _ = run_measured([sdfc, "compile", scenes[name], "--emit", "ir", "-o",
                                                 os.path.join(tmp, "k.txt")])
            _, gl_cpu, gl_rss, _ = run_measured([sdfc, "compile", scenes[name], "--emit", "glsl", "-o",
                                                 os.path.join(tmp, "k.glsl")])
            loads[name].append((ir_cpu, gl_cpu, gl_rss))
            print(f"rep {rep} {name}: {info['spp_per_s']:.3f} spp/s, {info['cpu_s']:.2f} CPU s; check {ir_cpu:.2f} "
                  f"CPU s, check + emit {gl_cpu:.2f} CPU s, {gl_rss:.0f} MiB", flush=True)
    against = f" --against {args.against}" if args.against else ""
    lines += ["## Cost against the castle", "",
              f"`bench/env_map.py --reps {args.reps} --size {args.size} --spp {args.spp}{against}`, cases alternated run "
              "by run. The machine is shared (load ~15 on 2 CPUs): wall-clock samples per second swing 3x "
              "between runs, so the cost is the CPU seconds of the samples (lavapipe's threads included): a "
              "render's CPU seconds less those of the same render at 1 spp (the fixed costs: compile, JIT, "
              "map load), paired run by run. `sdfc compile --emit ir` reads and checks the map; `--emit glsl` also builds "
              "its distribution and the scene data.", "",
              "| scene | median CPU s of N - 1 samples | paired samples per CPU s vs the castle | median spp/s (wall) | "
              "check CPU s | check + emit CPU s |",
              "|---|---|---|---|---|---|"]
    for name in scenes:
        ratio = statistics.median(b / a for a, b in zip(cpus[name], cpus[castle_of[name]]))
        lines.append(f"| {name} | {statistics.median(cpus[name]):.2f} | {ratio:.3f} | "
                     f"{statistics.median(speeds[name]):.3f} | "
                     f"{statistics.median(l[0] for l in loads[name]):.2f} | "
                     f"{statistics.median(l[1] for l in loads[name]):.2f} |")
    lines += ["", "CPU s per run: " + "; ".join(f"{k}: {', '.join(f'{v:.2f}' for v in s)}" for k, s in cpus.items()), ""]


def converge(args, tmp, lines):
    out = os.path.join(tmp, "c.pfm")
    base = ["--size", "96x54", "--bounces", "2", "--denoise", "none"]
    ref_path = os.path.join(tmp, "ref.pfm")
    sb.render(args.sdfc, STUDIO, ref_path, base + ["--spp", str(args.ref_spp), "--seed", "99"])
    ref = sb.read_pfm(ref_path)
    modes = {"importance (default)": ({}, []), "uniform over the sphere": ({"SDFC_ENVMAP_SAMPLING": "uniform"}, []),
             "BSDF sampling alone": ({}, ["--light-samples", "0"])}
    rows = {k: [] for k in modes}
    for rep in range(args.reps):
        order = list(modes) if rep % 2 == 0 else list(modes)[::-1]
        for name in order:
            extra_env, extra = modes[name]
            env = dict(os.environ, **extra_env)
            info = sb.render(args.sdfc, STUDIO, out, base + ["--spp", "32", "--seed", str(rep)] + extra, env=env)
            err = sb.relmse(sb.read_pfm(out), ref)
            rows[name].append((err, info["render_s"]))
            print(f"rep {rep} {name}: relMSE {err:.5f} in {info['render_s']:.2f} s", flush=True)
    first = list(modes)[0]
    eff0 = statistics.median(e * t for e, t in rows[first])
    lines += ["## Convergence against uniform sampling", "",
              f"examples/envmap/studio.sdf at 96 x 54, 2 bounces, 32 spp, {args.reps} seeds a mode, alternated; "
              f"reference {args.ref_spp} spp (importance sampled, another seed). relMSE x render seconds is "
              "the inverse efficiency (equal-time relMSE is proportional to it).", "",
              "| NEE of the map | median relMSE | median render s | median relMSE x s | vs importance |",
              "|---|---|---|---|---|"]
    for name in modes:
        eff = statistics.median(e * t for e, t in rows[name])
        lines.append(f"| {name} | {statistics.median(e for e, _ in rows[name]):.5f} | "
                     f"{statistics.median(t for _, t in rows[name]):.2f} | {eff:.5f} | {eff / eff0:.2f}x |")
    lines.append("")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--against", help="a second sdfc binary (A) to run the cost part against --sdfc (B), paired")
    p.add_argument("--size", default="320x180")
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--ref-spp", type=int, default=1024)
    p.add_argument("--part", choices=["all", "cost", "converge"], default="all")
    p.add_argument("--out", default=os.path.join(HERE, "results", "ENV_MAP.md"))
    args = p.parse_args()
    lines = ["# Environment maps: cost and convergence (issue 33)", ""]
    with tempfile.TemporaryDirectory(prefix="sdfc env map bench ") as tmp:
        if args.part in ("all", "cost"):
            cost(args, tmp, lines)
        if args.part in ("all", "converge"):
            converge(args, tmp, lines)
    load = os.getloadavg()
    lines += [f"Load average at the end: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} (2 CPUs shared, lavapipe).", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
