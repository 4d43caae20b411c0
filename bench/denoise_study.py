#!/usr/bin/env python3
"""Where the denoisers' error lives, and what a denoise costs.

    /usr/bin/python3 bench/denoise_study.py --mesa25 --reuse-refs   # ~12 min on an idle machine

For each scene at --size: the undenoised image at --low-spp and --high-spp, and
each denoiser at --low-spp, against the cached converged reference of
`bench/run.py --converge` (made there if missing: castle 2048 spp, the others
1024 spp, two white-noise halves). relMSE (mean (x - ref)^2 / (ref^2 + 0.01)),
mean LDR-FLIP, and each region's share of the relMSE: sky (primary ray missed),
edges (a neighbour across a depth, normal or albedo discontinuity, or the sky),
the rest, and the top 1% of pixels. Regions come from the renderer's own depth,
normal and albedo views. Then the filter's own time (`sdfc: denoised ... in N
ms`, median of --reps) at each of --timing-sizes on the first scene.
Writes results/DENOISE_<size>.md and results/denoise_<size>.csv under --out.
"""
import argparse
import csv
import os
import statistics
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import converge  # noqa: E402
import flip  # noqa: E402
import run  # noqa: E402
import sdfbench as sb  # noqa: E402

SEED = 7
REF_SPP = {"castle.sdf": 2048}  # others: 1024 (the references bench/results/CONVERGE_640x360.md used)


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def regions(sdfc, scene, size, work, env):
    """Boolean masks (sky, edge) from the depth, normal and albedo views."""
    views = {}
    for view in ("depth", "normal", "albedo"):
        out = os.path.join(work, f"view_{view}.pfm")
        sb.render(sdfc, scene, out, ["--size", size, "--spp", "1", "--view", view, "-q"], env=env)
        views[view] = sb.read_pfm(out)
    z = views["depth"][..., 0]
    hit = z >= 0
    n = views["normal"] * 2 - 1
    alb = views["albedo"]
    edge = np.zeros(hit.shape, bool)
    h, w = hit.shape
    for dy, dx in ((0, 1), (1, 0)):
        a = (slice(0, h - dy), slice(0, w - dx))
        b = (slice(dy, h), slice(dx, w))
        both = hit[a] & hit[b]
        # A depth step well beyond what the slope one pixel further predicts.
        far = (slice(0, h - 2 * dy), slice(0, w - 2 * dx))
        jump = np.zeros_like(both)
        jump[far] = np.abs(z[a][far] - z[b][far]) > 0.02 * np.maximum(z[a][far], 1e-6)
        bad = (hit[a] != hit[b]) | (both & (jump | ((n[a] * n[b]).sum(-1) < 0.9)
                                            | (np.abs(alb[a] - alb[b]).sum(-1) > 0.05)))
        edge[a] |= bad
        edge[b] |= bad
    return ~hit, edge & hit


def denoise_args(spec):
    """`nlr` -> --denoise nlr; `nlr:0.7,1.25,2.5` also --denoise-select 0.7,1.25,2.5
    (per-pixel choice among those last-pass strengths, docs/denoise.md); a `/aovs`
    suffix picks the features: `nlr/specular` -> --denoise-aovs specular; a
    trailing `+a` adds --adaptive (docs/adaptive.md, its default options)."""
    spec, adaptive, _ = spec.partition("+a")
    spec, _, aovs = spec.partition("/")
    name, _, select = spec.partition(":")
    return (["--denoise", name] + (["--denoise-select", select] if select else [])
            + (["--denoise-aovs", aovs] if aovs else []) + (["--adaptive"] if adaptive else []))


def breakdown(img, ref, sky, edge):
    per = ((img - ref) ** 2 / (ref ** 2 + 0.01)).mean(-1)
    total = per.sum()
    top = np.sort(per.ravel())[::-1][:max(1, per.size // 100)].sum()
    return {"share_sky": per[sky].sum() / total, "share_edge": per[edge].sum() / total,
            "share_rest": per[~sky & ~edge].sum() / total, "share_top1pct": top / total}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--size", default="640x360")
    p.add_argument("--scenes", nargs="+", default=[os.path.join(ROOT, "examples", s) for s in
                                                   ("castle.sdf", "colonnade.sdf", "glass_menger.sdf")])
    p.add_argument("--low-spp", type=int, default=16)
    p.add_argument("--high-spp", type=int, default=256)
    p.add_argument("--denoisers", nargs="+", default=["svgf", "nlm", "nlr", "nlr:0.7,1.25,2.5"],
                   help="names for --denoise; name:K,K,K adds --denoise-select K,K,K, "
                        "name+a --adaptive")
    p.add_argument("--timing-sizes", nargs="*", default=["640x360", "1280x720"])
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--mesa25", action="store_true",
                   help="the bundled Mesa 25 lavapipe (default: the system's 22.3.6)")
    p.add_argument("--cache", default=os.path.join(HERE, "cache"))
    p.add_argument("--reuse-refs", action="store_true",
                   help="use a cached reference of the scene made by an earlier kernel")
    p.add_argument("--out", default=HERE)
    args = p.parse_args()
    start = time.time()
    load_start = os.getloadavg()[0]
    env = converge.driver_env("bundled" if args.mesa25 else "system", args.sdfc)
    os.makedirs(os.path.join(args.out, "results"), exist_ok=True)
    work = tempfile.mkdtemp(prefix="denoise_study_")
    rows = []
    for scene in args.scenes:
        name = os.path.basename(scene)
        ref_args = argparse.Namespace(converge=True, cache=args.cache, work=work, sdfc=args.sdfc,
                                      ref_spp=REF_SPP.get(name, 1024), reuse_refs=args.reuse_refs)
        ref, ref_var = run.reference(ref_args, scene, args.size)
        sky, edge = regions(args.sdfc, scene, args.size, work, env)
        configs = [("none", args.low_spp), ("none", args.high_spp)] + \
                  [(d, args.low_spp) for d in args.denoisers]
        for denoiser, spp in configs:
            out = os.path.join(work, f"{denoiser.replace(':', '_')}_{spp}.pfm")
            info = sb.render(args.sdfc, scene, out, ["--size", args.size, "--spp", str(spp),
                                                     "--seed", str(SEED)] + denoise_args(denoiser), env=env)
            img = sb.read_pfm(out)
            row = {"scene": name, "denoiser": denoiser, "spp": spp, "size": args.size,
                   "relmse": sb.relmse(img, ref), "flip": flip.mean_flip(img, ref),
                   "relmse_ref_floor": float(np.mean(ref_var / (ref ** 2 + 0.01))),
                   "wall_s": info["wall_s"], "cpu_s": info["cpu_s"], "denoise_ms": info["denoise_ms"],
                   **breakdown(img, ref, sky, edge)}
            rows.append(row)
            log(f"{name:18s} {denoiser:5s} {spp:4d} spp relMSE {row['relmse']:.3g} FLIP "
                f"{row['flip']:.4f} edge share {row['share_edge']:.2f}")
    timing = []
    for size in args.timing_sizes:
        # Interleaved (rep by rep, every denoiser), so load changes hit them alike;
        # the CPU time is the filter's own whatever the load.
        ms = {d: [] for d in args.denoisers}
        cpu = {d: [] for d in args.denoisers}
        for _ in range(args.reps):
            for denoiser in args.denoisers:
                info = sb.render(args.sdfc, args.scenes[0], os.path.join(work, "t.pfm"),
                                 ["--size", size, "--spp", str(args.low_spp), "--seed", str(SEED),
                                  ] + denoise_args(denoiser), env=env)
                ms[denoiser].append(info["denoise_ms"])
                cpu[denoiser].append(info["denoise_cpu_ms"])
        for denoiser in args.denoisers:
            timing.append((size, denoiser, statistics.median(ms[denoiser]), ms[denoiser],
                           statistics.median(cpu[denoiser])))
            log(f"{size} {denoiser}: {statistics.median(ms[denoiser]):.0f} ms per denoise "
                f"(runs {ms[denoiser]}), CPU {statistics.median(cpu[denoiser]):.0f} ms")

    csv_path = os.path.join(args.out, "results", f"denoise_{args.size}.csv")
    with open(csv_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    load = os.getloadavg()[0]
    lines = [f"# Denoisers at {args.size}: error by region, and cost", "",
             f"Generated by `bench/denoise_study.py "
             f"{' '.join(a.replace(ROOT + os.sep, '') for a in sys.argv[1:])}` in {(time.time() - start) / 60:.1f} min "
             f"(load average {load_start:.1f} at the start, {load:.1f} at the end); data results/denoise_{args.size}.csv. "
             f"Seed {SEED}; references as bench/results/CONVERGE_640x360.md (castle 2048 spp, others 1024; "
             "`relMSE floor` is the reference's own noise, included in every relMSE).", "",
             "| scene | image | relMSE | FLIP | relMSE share: edges | rest | sky | top 1% of pixels |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        label = f"{r['spp']} spp, " + ("no denoiser" if r["denoiser"] == "none" else
                                       r["denoiser"].replace(":", ", select ")
                                       .replace("+a", " + adaptive"))
        lines.append(f"| {r['scene']} | {label} | {r['relmse']:.2g} | {r['flip']:.4f} | "
                     f"{r['share_edge']:.2f} | {r['share_rest']:.2f} | {r['share_sky']:.2f} | "
                     f"{r['share_top1pct']:.2f} |")
    floors = {r["scene"]: r["relmse_ref_floor"] for r in rows}
    lines += ["", "relMSE floor of the references: " +
              ", ".join(f"{k} {v:.2g}" for k, v in floors.items()) + ".", "",
              f"Filter time alone ({args.scenes[0] and os.path.basename(args.scenes[0])}, "
              f"{args.low_spp} spp, median of {args.reps}, denoisers interleaved; wall time on "
              "the machine's cores as it was loaded, and the process's CPU time, the filter's own):", "",
              "| size | denoiser | ms per denoise | runs | CPU ms (median) |", "|---|---|---|---|---|"]
    lines += [f"| {s} | {d} | {m:.0f} | {', '.join(str(int(x)) for x in ms)} | {c:.0f} |"
              for s, d, m, ms, c in timing]
    report = os.path.join(args.out, "results", f"DENOISE_{args.size}.md")
    with open(report, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
