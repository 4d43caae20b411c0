"""Seconds to a visually converged image (`bench/run.py --converge`).

For each scene at a user's resolution, each configuration renders a doubling
ladder of sample counts (one process per render, as a user runs it) until its
image is within --flip-target mean LDR-FLIP and --relmse-target relMSE of the
converged reference, or its time budget is spent. The time to each target is
read off the log-log error-against-time curve (interpolated between ladder
points; extrapolated, and marked so, past the last one). The time charged is
the whole process's wall time: compile, pipeline creation, sampling, denoising
and writing the file, i.e. what a user waits for. The paper-style baseline
runs in the same run, so ratios are measured under the same machine load.

Levers are configurations that add one thing at a time:
  baseline     the paper-style tracer (run.py's "baseline")
  derived      sdfc's defaults, no denoiser          (kernel lever)
  svgf         + the variance-guided denoiser        (denoiser lever, round 1)
  nlm          + the dual-buffer NL-means denoiser   (denoiser lever; docs/denoise.md)
  nlm-mesa25   + lavapipe of Mesa 25.0.7             (driver lever; sdfc's default
               when tools/setup.sh fetched it into build/lavapipe-25)
  nlr          nlm + jittered features and a first-order regression (denoiser
               lever, round 3; system driver)
  nlr-mesa25   the same on Mesa 25.0.7
  baseline-mesa25, derived-mesa25, svgf-mesa25: those on Mesa 25.0.7, so each
               lever can be compared on one driver
All but the -mesa25 ones are pinned to the system's Mesa 22.3.6 (--driver system) so
the driver's share stays separate.
"""
import csv
import os
import statistics
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import sdfbench as sb  # noqa: E402

CONVERGE_CONFIGS = {
    "baseline": (["--paper-baseline", "--no-bounds", "--white-noise", "--denoise", "bilateral"], "system"),
    "derived": ([], "system"),
    "svgf": (["--denoise", "svgf"], "system"),
    "nlm": (["--denoise", "nlm"], "system"),
    "nlm-mesa25": (["--denoise", "nlm"], "bundled"),
    "nlr": (["--denoise", "nlr"], "system"),
    "nlr-mesa25": (["--denoise", "nlr"], "bundled"),
    "baseline-mesa25": (["--paper-baseline", "--no-bounds", "--white-noise", "--denoise", "bilateral"],
                        "bundled"),
    "derived-mesa25": ([], "bundled"),
    "svgf-mesa25": (["--denoise", "svgf"], "bundled"),
}
SEED = 7


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def driver_env(driver, sdfc):
    """Environment pinning sdfc's Vulkan driver (SDFC_DRIVER = --driver,
    runtime/driver_select.h), or None when `bundled` is asked for and the build
    tree next to `sdfc` has no build/lavapipe-25 (tools/lavapipe25.sh fetch)."""
    manifest = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(sdfc))),
                            "lavapipe-25", "lvp_icd.x86_64.json")
    if driver == "bundled" and not os.path.exists(manifest):
        log(f"  bundled lavapipe unavailable: no {manifest}")
        return None
    env = dict(os.environ)
    env["SDFC_DRIVER"] = driver
    return env


def ladder(args, scene, name, flags, env, ref, ref_var, errors, writer):
    rows, spent, spp = [], 0.0, args.converge_min_spp
    while spp <= args.converge_max_spp:
        runs, err = [], None
        for rep in range(args.reps):
            out = os.path.join(args.work, f"conv_{name}_{spp}.pfm")
            runs.append(sb.render(args.sdfc, scene, out,
                                  ["--size", args.size, "--spp", str(spp), "--seed", str(SEED)]
                                  + flags, env=env))
            if rep == 0:
                err = errors(sb.read_pfm(out), ref, ref_var)
        med = lambda k: statistics.median(r[k] for r in runs)
        row = {"scene": os.path.basename(scene), "config": name, "spp": spp, "size": args.size,
               "wall_s": med("wall_s"), "cpu_s": med("cpu_s"), "render_s": med("render_s"),
               "pipeline_ms": med("pipeline_ms"), "compile_ms": med("compile_ms"), **err}
        rows.append(row)
        writer.writerow(row)
        spent += sum(r["wall_s"] for r in runs)
        log(f"  {name:12s} {spp:5d} spp  {row['wall_s']:7.2f} s  relMSE {row['relmse']:.4g}  "
            f"FLIP {row['flip']:.4f}")
        done = row["flip"] <= args.flip_target and row["relmse"] <= args.relmse_target
        if done or spent > args.converge_budget_s:
            break
        spp *= 2
    return rows


def time_to(rows, metric, target, x="wall_s"):
    """Where the log-log error(x) curve reaches target; x is a row's wall_s,
    cpu_s or spp."""
    pts = [(r[x], r[metric]) for r in rows]
    # A point already under the target at the first rung: that rung's x.
    first = min(rows, key=lambda r: r["spp"])
    if first[metric] <= target:
        return first[x], "at first rung"
    t, how = sb.time_to_error(pts, target)
    # Past two more doublings of the last rung the curve is a plateau (a biased
    # filter), not a trend: an extrapolated figure would mean nothing.
    last_s = max(r[x] for r in rows)
    if t is not None and how == "extrapolated" and t > 4 * last_s:
        return None, f"never (levels off at {min(r[metric] for r in rows):.2g})"
    return t, how


def run(args, reference, errors):
    """Returns the rows and a per-scene summary {scene: {config: {...}}}."""
    path = os.path.join(args.results, f"converge_{args.size}.csv")
    summary, all_rows = {}, []
    fields = ["scene", "config", "spp", "size", "wall_s"] + \
        (["cpu_s"] if getattr(args, "cpu_time", False) else []) + ["render_s", "pipeline_ms", "compile_ms",
              "rmse", "relmse", "rmse_debiased", "relmse_debiased", "rmse_floor", "relmse_floor",
              "flip"]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        for scene in args.scenes:
            log(f"converge: {scene} at {args.size}")
            ref, ref_var = reference(args, scene, args.size)
            name = os.path.basename(scene)
            summary[name] = {}
            for config in args.converge_configs:
                flags, driver = CONVERGE_CONFIGS[config]
                env = driver_env(driver, args.sdfc)
                if env is None:
                    continue
                rows = ladder(args, scene, config, flags, env, ref, ref_var, errors, writer)
                f.flush()
                all_rows += rows
                t_flip, how_flip = time_to(rows, "flip", args.flip_target)
                t_rel, how_rel = time_to(rows, "relmse", args.relmse_target)
                t = max(t_flip, t_rel) if t_flip and t_rel else None
                summary[name][config] = {"flip_s": t_flip, "flip_how": how_flip,
                                         "relmse_s": t_rel, "relmse_how": how_rel, "both_s": t,
                                         "driver": driver}
                # The same read-offs in process CPU seconds and in samples per pixel.
                for x in ("cpu_s", "spp"):
                    got = [time_to(rows, m, target, x) for m, target in
                           (("flip", args.flip_target), ("relmse", args.relmse_target))]
                    summary[name][config][x] = got
                    summary[name][config][x + "_both"] = \
                        max(got[0][0], got[1][0]) if got[0][0] and got[1][0] else None
    return all_rows, summary, path


def report_lines(args, summary, ref_spp):
    lines = [f"## Seconds to a visually converged image ({args.size})", "",
             f"Whole-process wall time (compile, pipeline, sampling, denoiser, file) until mean "
             f"LDR-FLIP <= {args.flip_target} and relMSE <= {args.relmse_target} against a "
             f"{ref_spp}-spp reference; one process per ladder rung (spp doubling), time read off "
             f"the log-log error curve (x = extrapolated past the last rung). Same run, same load.",
             "", "| scene | config | s to FLIP target | s to relMSE target | s to both | "
             "speedup over baseline (FLIP) |", "|---|---|---|---|---|---|"]
    for scene, configs in summary.items():
        base = configs.get("baseline", {}).get("flip_s")
        for config, s in configs.items():
            mark = lambda t, how: (how if how and how.startswith("never") else "-") if t is None else \
                f"{t:.1f}{' x' if how == 'extrapolated' else ''}"
            speed = f"{base / s['flip_s']:.2f}x" if base and s["flip_s"] else "-"
            never = any(str(s[k]).startswith("never") for k in ("flip_how", "relmse_how"))
            both = ("never" if never else "-") if s["both_s"] is None else f"{s['both_s']:.1f}"
            lines.append(f"| {scene} | {config} | {mark(s['flip_s'], s['flip_how'])} | "
                         f"{mark(s['relmse_s'], s['relmse_how'])} | {both} | {speed} |")
    if getattr(args, "cpu_time", False):
        lines += cpu_lines(args, summary)
    return lines


def cpu_lines(args, summary):
    """--cpu-time: the same read-offs in process CPU seconds (user + sys of all
    the process's threads; less sensitive to other people's load than wall time)
    and in samples per pixel, with each configuration's driver."""
    def cell(value, how, fmt):
        if value is None:
            return how if how and how.startswith("never") else "-"
        return fmt.format(value) + (" x" if how == "extrapolated" else "")
    lines = ["", f"The same in process CPU seconds (user + sys) and in samples per pixel (the spp "
             "read off the log-log error(spp) curve between rungs); speedup = the same driver's "
             "baseline CPU s over this one's, to the FLIP target.", "",
             "| scene | config | driver | CPU s to FLIP | CPU s to relMSE | CPU s to both | "
             "spp to FLIP | spp to relMSE | CPU speedup over same-driver baseline (FLIP) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for scene, configs in summary.items():
        for config, s in configs.items():
            (c_flip, h_flip), (c_rel, h_rel) = s["cpu_s"]
            (n_flip, hn_flip), (n_rel, hn_rel) = s["spp"]
            base_name = "baseline-mesa25" if s["driver"] == "bundled" else "baseline"
            base = configs.get(base_name, {}).get("cpu_s", [(None, None)])[0][0]
            speed = f"{base / c_flip:.2f}x" if base and c_flip else "-"
            never = any(str(h).startswith("never") for h in (h_flip, h_rel))
            both = ("never" if never else "-") if s["cpu_s_both"] is None else f"{s['cpu_s_both']:.1f}"
            driver = "Mesa 25.0.7" if s["driver"] == "bundled" else "Mesa 22.3.6"
            lines.append(f"| {scene} | {config} | {driver} | {cell(c_flip, h_flip, '{:.1f}')} | "
                         f"{cell(c_rel, h_rel, '{:.1f}')} | {both} | {cell(n_flip, hn_flip, '{:.1f}')} | "
                         f"{cell(n_rel, hn_rel, '{:.1f}')} | {speed} |")
    return lines


def plot(rows, plots_dir, size):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    out = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        for ax, metric in zip(axes, ("relmse", "flip")):
            for config in dict.fromkeys(r["config"] for r in rows if r["scene"] == scene):
                pts = sorted((r["wall_s"], r[metric]) for r in rows
                             if r["scene"] == scene and r["config"] == config)
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=config)
            ax.set_xlabel("process wall time [s]")
            ax.set_ylabel(metric)
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend()
        fig.suptitle(f"{scene} {size}")
        path = os.path.join(plots_dir, f"converge_{scene.replace('.sdf', '')}_{size}.png")
        fig.tight_layout()
        fig.savefig(path, dpi=90)
        plt.close(fig)
        out.append(path)
    return out
