#!/usr/bin/env python3
"""The castle's default render in 5 s (issue 48): time against error of the candidates.

    /usr/bin/python3 bench/castle_5s.py filter --spp 24 32 --seeds 7 8 --variants VARIANT...
    /usr/bin/python3 bench/castle_5s.py render --configs nlr@32 nlr+a@20 ... --seeds 7 8 --reps 3

`filter`: one render of the halves per spp and seed (build/bench/nlr_tune/sdfc_nlr_tune),
then nlr with each parameter VARIANT (`name:key=value,...`, see nlr_tune.cpp) on it:
relMSE against the converged reference and the filter's CPU ms. `render`: `sdfc render`
per config (`DENOISER[+a[:flag=value...]][+s]@SPP`, e.g. `nlr+a:budget=time@24`; `+s`:
--denoise-select 0.7,1.25,2.5), the configs
interleaved rep by rep, CPU seconds of the process (user + sys, os.wait4) as medians over
--reps, relMSE and mean LDR-FLIP (bench/flip.py) per seed. References: bench/run.py --converge's (castle 2048 spp, the others
1024), made and cached in bench/cache if missing. Prints a table and appends it to --log.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import flip  # noqa: E402
import run  # noqa: E402
import sdfbench as sb  # noqa: E402

REF_SPP = {"castle.sdf": 2048}
ADAPTIVE_FLAGS = {"est": "--adaptive-estimate", "share": "--adaptive-share", "cap": "--adaptive-cap",
                  "block": "--adaptive-block", "power": "--adaptive-power", "budget": "--adaptive-budget",
                  "cost": "--adaptive-cost"}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def reference(args, scene, work):
    ref_args = argparse.Namespace(converge=True, cache=args.cache, work=work, sdfc=args.sdfc,
                                  ref_spp=REF_SPP.get(os.path.basename(scene), 1024), reuse_refs=False)
    mean, _ = run.reference(ref_args, scene, args.size)
    return mean


def config_flags(spec):
    """`nlr+a:budget=time+s@24` -> flags for sdfc render."""
    body, _, spp = spec.rpartition("@")
    denoiser, *extras = body.split("+")
    flags = ["--spp", spp, "--denoise", denoiser]
    for extra in extras:
        if extra == "s":
            flags += ["--denoise-select", "0.7,1.25,2.5"]
            continue
        flags.append("--adaptive")
        _, _, options = extra.partition(":")
        for item in filter(None, options.split(",")):
            key, _, value = item.partition("=")
            flags += [ADAPTIVE_FLAGS[key], value]
    return flags


def render_once(args, scene, out, flags, seed):
    start = time.perf_counter()
    proc = subprocess.Popen([args.sdfc, "render", scene, "-o", out, "--size", args.size, "--seed", str(seed)]
                            + flags, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    err = proc.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"render {scene} {flags} failed:\n{err}")
    return wall, usage.ru_utime + usage.ru_stime


def cmd_filter(args, scene, ref, work):
    ref_path = os.path.join(work, "ref.f32")
    ref.astype("<f4").tofile(ref_path)
    rows = []
    for spp in args.spp:
        for seed in args.seeds:
            out = subprocess.run([args.tool, scene, "--ref", ref_path, "--size", args.size, "--spp", str(spp),
                                  "--seed", str(seed)] + args.variants, capture_output=True, text=True, check=True)
            for line in out.stdout.splitlines():
                row = json.loads(line)
                rows.append(row)
                log(f"{spp:3d} spp seed {seed}: {row['variant']:14s} relMSE {row['relmse']:.4g}  {row['cpu_ms']:.0f} CPU ms")
    names = list(dict.fromkeys(r["variant"] for r in rows))
    specs = {r["variant"]: r.get("spec", "") for r in rows}
    lines = [f"| variant | {' | '.join(f'relMSE {s} spp' for s in args.spp)} | filter CPU ms (median) | parameters |",
             "|---|" + "---|" * len(args.spp) + "---|---|"]
    for name in names:
        cells = []
        for spp in args.spp:
            vals = [r["relmse"] for r in rows if r["variant"] == name and r["spp"] == spp]
            cells.append(f"{np.mean(vals):.3g} ({', '.join(f'{v:.3g}' for v in vals)})")
        cpu = statistics.median(r["cpu_ms"] for r in rows if r["variant"] == name)
        spec = specs[name].partition(":")[2] if ":" in specs[name] else ("nlrParams()" if name != "raw" else "no filter")
        lines.append(f"| {name} | {' | '.join(cells)} | {cpu:.0f} | {spec} |")
    return lines, f"seeds {', '.join(map(str, args.seeds))} (mean, then each seed)"


def cmd_render(args, scene, ref, work):
    errors, flips, cpu, wall = {}, {}, {c: [] for c in args.configs}, {c: [] for c in args.configs}
    out = os.path.join(work, "x.pfm")
    for rep in range(args.reps):
        for seed in args.seeds:
            for config in args.configs:
                w, c = render_once(args, scene, out, config_flags(config), seed)
                cpu[config].append(c)
                wall[config].append(w)
                if rep == 0:
                    image = sb.read_pfm(out)
                    errors.setdefault(config, []).append(sb.relmse(image, ref))
                    flips.setdefault(config, []).append(flip.mean_flip(image, ref))
                log(f"rep {rep} seed {seed} {config:28s} {w:.2f} s wall {c:.2f} CPU s"
                    + (f" relMSE {errors[config][-1]:.4g} FLIP {flips[config][-1]:.4f}" if rep == 0 else ""))
    lines = ["| config | CPU s (median) | wall s (median, loaded) | relMSE (mean of seeds) | relMSE per seed | FLIP (mean) |",
             "|---|---|---|---|---|---|"]
    for config in args.configs:
        lines.append(f"| {config} | {statistics.median(cpu[config]):.2f} | {statistics.median(wall[config]):.2f} | "
                     f"{np.mean(errors[config]):.3g} | {', '.join(f'{e:.3g}' for e in errors[config])} | "
                     f"{np.mean(flips[config]):.4f} |")
    return lines, f"seeds {', '.join(map(str, args.seeds))}, {args.reps} reps interleaved"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("mode", choices=["filter", "render"])
    p.add_argument("--variants", nargs="+", default=["base"], help="filter: nlr parameter variants")
    p.add_argument("--scene", default=os.path.join(ROOT, "examples", "castle.sdf"))
    p.add_argument("--configs", nargs="+", default=["nlr@48", "nlr@32"])
    p.add_argument("--spp", nargs="+", type=int, default=[32])
    p.add_argument("--seeds", nargs="+", type=int, default=[7, 8])
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--size", default="640x360")
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--tool", default=os.path.join(ROOT, "build", "bench", "nlr_tune", "sdfc_nlr_tune"))
    p.add_argument("--cache", default=os.path.join(HERE, "cache"))
    p.add_argument("--log", help="append the table here (markdown)")
    p.add_argument("--title", default="")
    args = p.parse_args()
    work = tempfile.mkdtemp(prefix="castle_5s_")
    start, load = time.time(), os.getloadavg()[0]
    ref = reference(args, args.scene, work)
    lines, how = (cmd_filter if args.mode == "filter" else cmd_render)(args, args.scene, ref, work)
    cmd = " ".join(a.replace(ROOT + os.sep, "") for a in sys.argv[1:])
    head = [f"### {args.title or args.mode}", "",
            f"`bench/castle_5s.py {cmd}`: {os.path.basename(args.scene)} at {args.size}, {how}; "
            f"{(time.time() - start) / 60:.1f} min, load average {load:.1f} at the start, "
            f"{os.getloadavg()[0]:.1f} at the end.", ""]
    text = "\n".join(head + lines) + "\n"
    print(text)
    if args.log:
        with open(args.log, "a") as f:
            f.write("\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
