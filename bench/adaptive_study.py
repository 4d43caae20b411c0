#!/usr/bin/env python3
"""Adaptive sampling at equal mean spp against uniform sampling (docs/adaptive.md).

    /usr/bin/python3 bench/adaptive_study.py --mesa25 --reuse-refs            # 3 scenes
    /usr/bin/python3 bench/adaptive_study.py --mesa25 --reuse-refs --scenes examples/castle.sdf \
        --configs nlr nlr+a                                                     # one scene, fast

Each config is a denoiser spec (bench/denoise_study.py: `nlr`, `nlr:0.7,1.25,2.5`,
`none`) with an optional `+a` (--adaptive) and `+a:key=value,...` for its options
(est=denoised|variance|uniform, share=0.5, cap=8, block=8, power=0.5), at --spp
samples per pixel (the mean, for adaptive ones); `none@256` renders 256 spp. Against
the cached references of `bench/run.py --converge` (as denoise_study.py): relMSE,
mean LDR-FLIP, and the wall seconds of the whole `sdfc render` process and its
render alone. With --reps > 1 the configs run interleaved rep by rep (so load
changes hit them alike) and the seconds are medians; errors are from the first rep
(the same seed gives the same image). --cpu-time adds the process's CPU seconds
(user + sys) and the filter's own CPU ms (sdfc's `denoised ... (N CPU ms)`),
medians too. Writes results/ADAPTIVE_<size>.md and results/adaptive_<size>.csv under --out.
"""
import argparse
import csv
import os
import statistics
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import converge  # noqa: E402
import denoise_study  # noqa: E402
import flip  # noqa: E402
import run  # noqa: E402
import sdfbench as sb  # noqa: E402

SEED = 7
DEFAULT_CONFIGS = ["none", "none@256", "nlr", "nlr+a", "nlr+a:est=variance",
                   "nlr:0.7,1.25,2.5", "nlr:0.7,1.25,2.5+a"]
OPTION_FLAGS = {"est": "--adaptive-estimate", "share": "--adaptive-share", "cap": "--adaptive-cap",
                "block": "--adaptive-block", "power": "--adaptive-power",
                "budget": "--adaptive-budget", "offset": "--adaptive-cost-offset",
                "cost": "--adaptive-cost"}


def config_args(spec, spp):
    """`nlr:0.7,1.25,2.5+a:share=0.25,cap=4` -> sdfc flags; `none@256` -> 256 spp."""
    spec, _, at = spec.partition("@")
    spp = int(at) if at else spp
    denoiser, plus, adaptive = spec.partition("+a")
    flags = ["--spp", str(spp)]
    if denoiser != "none":
        flags += denoise_study.denoise_args(denoiser)
    if plus:
        flags.append("--adaptive")
        for item in filter(None, adaptive.lstrip(":").split(",")):
            key, _, value = item.partition("=")
            flags += [OPTION_FLAGS[key], value]
    return flags, spp


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--size", default="640x360")
    p.add_argument("--scenes", nargs="+", default=[os.path.join(ROOT, "examples", s) for s in
                                                   ("castle.sdf", "colonnade.sdf", "glass_menger.sdf")])
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--configs", nargs="+", default=DEFAULT_CONFIGS)
    p.add_argument("--reps", type=int, default=1)
    p.add_argument("--seed", type=int, default=SEED)
    p.add_argument("--mesa25", action="store_true",
                   help="the bundled Mesa 25 lavapipe (default: the system's 22.3.6)")
    p.add_argument("--cache", default=os.path.join(HERE, "cache"))
    p.add_argument("--reuse-refs", action="store_true",
                   help="use a cached reference of the scene made by an earlier kernel")
    p.add_argument("--out", default=HERE)
    p.add_argument("--tag", default="", help="suffix of the output file names")
    p.add_argument("--cpu-time", action="store_true",
                   help="also the process's and the filter's CPU time")
    args = p.parse_args()
    start = time.time()
    load_start = os.getloadavg()[0]
    env = converge.driver_env("bundled" if args.mesa25 else "system", args.sdfc)
    os.makedirs(os.path.join(args.out, "results"), exist_ok=True)
    work = tempfile.mkdtemp(prefix="adaptive_study_")
    rows = []
    for scene in args.scenes:
        name = os.path.basename(scene)
        ref_args = argparse.Namespace(converge=True, cache=args.cache, work=work, sdfc=args.sdfc,
                                      ref_spp=denoise_study.REF_SPP.get(name, 1024),
                                      reuse_refs=args.reuse_refs)
        ref, _ = run.reference(ref_args, scene, args.size)
        wall = {c: [] for c in args.configs}
        render_s = {c: [] for c in args.configs}
        cpu_s = {c: [] for c in args.configs}
        filter_cpu_ms = {c: [] for c in args.configs}
        errors = {}
        for rep in range(args.reps):
            for config in args.configs:
                flags, spp = config_args(config, args.spp)
                out = os.path.join(work, "img.pfm")
                info = sb.render(args.sdfc, scene, out,
                                 ["--size", args.size, "--seed", str(args.seed)] + flags, env=env)
                wall[config].append(info["wall_s"])
                render_s[config].append(info["render_s"] or 0.0)
                cpu_s[config].append(info["cpu_s"])
                filter_cpu_ms[config].append(info["denoise_cpu_ms"] or 0.0)
                if rep == 0:
                    img = sb.read_pfm(out)
                    errors[config] = (spp, sb.relmse(img, ref), flip.mean_flip(img, ref))
                    print(f"{name:18s} {config:28s} {spp:4d} spp relMSE {errors[config][1]:.3g} "
                          f"FLIP {errors[config][2]:.4f} wall {info['wall_s']:.1f} s",
                          file=sys.stderr, flush=True)
        for config in args.configs:
            spp, rel, fl = errors[config]
            rows.append({"scene": name, "config": config, "spp": spp, "size": args.size,
                         "relmse": rel, "flip": fl, "wall_s": statistics.median(wall[config]),
                         "render_s": statistics.median(render_s[config]),
                         "wall_runs": " ".join(f"{x:.1f}" for x in wall[config])})
            if args.cpu_time:
                rows[-1].update({"cpu_s": statistics.median(cpu_s[config]),
                                 "filter_cpu_ms": statistics.median(filter_cpu_ms[config]),
                                 "cpu_runs": " ".join(f"{x:.1f}" for x in cpu_s[config])})

    tag = f"_{args.tag}" if args.tag else ""
    csv_path = os.path.join(args.out, "results", f"adaptive_{args.size}{tag}.csv")
    with open(csv_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    load = os.getloadavg()[0]
    lines = [f"# Adaptive sampling at {args.size}, {args.spp} spp mean", "",
             f"Generated by `bench/adaptive_study.py --size {args.size}"
             f"{' --mesa25' if args.mesa25 else ''}{' --reuse-refs' if args.reuse_refs else ''}"
             f" --reps {args.reps} --seed {args.seed}"
             f"{' --configs ' + ' '.join(args.configs) if args.configs != DEFAULT_CONFIGS else ''}"
             f"{' --cpu-time' if args.cpu_time else ''}` in {(time.time() - start) / 60:.1f} min "
             f"(load average {f'{load_start:.1f} at the start, ' if args.cpu_time else ''}"
             f"{load:.1f} at the end); data results/adaptive_{args.size}{tag}.csv. Seed {args.seed}; "
             "references as bench/results/DENOISE_640x360.md. `+a` = --adaptive (options after the "
             "colon); seconds: whole process / render() alone, medians over the reps, interleaved.",
             "", "| scene | config | spp | relMSE | FLIP | wall s | render s | runs |" +
             (" CPU s | filter CPU ms | CPU runs |" if args.cpu_time else ""),
             "|---|---|---|---|---|---|---|---|" + ("---|---|---|" if args.cpu_time else "")]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['config']} | {r['spp']} | {r['relmse']:.3g} | "
                     f"{r['flip']:.4f} | {r['wall_s']:.1f} | {r['render_s']:.1f} | {r['wall_runs']} |" +
                     (f" {r['cpu_s']:.1f} | {r['filter_cpu_ms']:.0f} | {r['cpu_runs']} |"
                      if args.cpu_time else ""))
    report = os.path.join(args.out, "results", f"ADAPTIVE_{args.size}{tag}.md")
    with open(report, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
