#!/usr/bin/env python3
"""sdfc speed-against-error benchmark and numerical hard-case suite.

One command:  /usr/bin/python3 bench/run.py  [--sdfc build/cli/sdfc]
It renders every example scene under each ablation at several sample counts,
times the renders, measures their error against a cached converged reference,
measures primary-ray hit distances against float64 roots on every scene and
every hard case, and writes bench/results/*.csv, bench/plots/*.png and
bench/RESULTS.md. `--smoke` runs a reduced version and checks bounds (CI).
`--converge --size 640x360` measures seconds to a visually converged image
instead (bench/converge.py; writes bench/results/CONVERGE_<size>.md).
"""
import argparse
import csv
import glob
import json
import os
import shutil
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import converge  # noqa: E402
import flip  # noqa: E402
import geometry  # noqa: E402
import sdfbench as sb  # noqa: E402

ROOT = os.path.dirname(HERE)

# Ablations. Each differs from "derived" (the compiler's defaults: bounds on,
# epsilon and step budget derived from the scene, Owen-scrambled Sobol, no
# denoiser) in one respect, except "baseline", the paper-style tracer.
CONFIGS = {
    # `render` leaves bounding volumes out on CPU devices (lavapipe masks
    # branches instead of jumping); "bounds" forces them in to measure that.
    "derived": [],
    "bounds": ["--bounds"],
    "paper-eps": ["--paper-baseline"],
    "white-noise": ["--white-noise"],
    "bilateral": ["--denoise", "bilateral"],
    "atrous": ["--denoise", "atrous"],
    "baseline": ["--paper-baseline", "--no-bounds", "--white-noise", "--denoise", "bilateral"],
}
# The reference avoids every shortcut: no bounds, no fusion, an independent
# sampler (so it shares no sample pattern with the Sobol runs), no denoiser.
REFERENCE_FLAGS = ["--no-bounds", "--no-fuse", "--white-noise", "--denoise", "none"]
GEOMETRY_CONFIGS = ["derived", "paper-eps"]
SEED = 7


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---------------------------------------------------------------- references

def reference(args, scene, size):
    """Converged image and its own noise (per-pixel variance of the mean),
    from two independent halves; cached by scene text and settings."""
    # The binary embeds the kernel: a reference from another build is stale.
    # --converge keys on the emitted shader instead (the kernel is all of the
    # binary an image depends on), so rebuilding the denoiser keeps its
    # expensive references.
    settings = f"ref{size}:{args.ref_spp}:{' '.join(REFERENCE_FLAGS)}"
    if getattr(args, "converge", False):
        glsl = sb.compile_text(args.sdfc, scene, "glsl", [f for f in REFERENCE_FLAGS
                                                           if f not in ("--denoise", "none")])
        key = sb.file_hash([scene], settings + glsl)
    else:
        key = sb.file_hash([scene, args.sdfc], settings)
    path = os.path.join(args.cache, f"ref_{os.path.basename(scene)}_{key}.npz")
    if not os.path.exists(path) and getattr(args, "reuse_refs", False):
        # --reuse-refs: a reference made by an earlier kernel (same scene file
        # name); the caller's report must say so.
        import glob
        older = sorted(glob.glob(os.path.join(args.cache, f"ref_{os.path.basename(scene)}_*.npz")),
                       key=os.path.getmtime)
        if older:
            log(f"  reference {os.path.basename(scene)}: reusing {os.path.basename(older[-1])} "
                "(made by an earlier kernel)")
            path = older[-1]
    if os.path.exists(path):
        d = np.load(path)
        return d["mean"], d["var"]
    halves = []
    for seed in (1001, 1002):
        out = os.path.join(args.work, f"ref_{seed}.pfm")
        log(f"  reference {os.path.basename(scene)}: {args.ref_spp // 2} spp, seed {seed}")
        # The reference's driver does not change its expectation: --converge renders
        # it with the faster Mesa 25 lavapipe when tools/lavapipe25.sh has it.
        env = converge.driver_env("bundled", args.sdfc) if getattr(args, "converge", False) else None
        sb.render(args.sdfc, scene, out, ["--size", size, "--spp", str(args.ref_spp // 2),
                                          "--seed", str(seed), "-q"] + REFERENCE_FLAGS, env=env)
        halves.append(sb.read_pfm(out))
    mean = 0.5 * (halves[0] + halves[1])
    var = (halves[0] - halves[1]) ** 2 / 4  # variance of the mean of two halves
    np.savez(path, mean=mean, var=var)
    return mean, var


# ---------------------------------------------------------------- convergence

def errors(img, ref, ref_var):
    """Raw metrics and ones with the reference's own noise subtracted (the
    expected squared error against a noisy reference is the true one plus the
    reference's variance). `flip`: mean LDR-FLIP (bench/flip.py) of the
    displayed images (clamped, sRGB) at 67 pixels per degree, against the
    reference as it is (FLIP is not additive, so not debiased)."""
    mse = np.mean((img - ref) ** 2)
    rel = sb.relmse(img, ref)
    mse_floor = np.mean(ref_var)
    rel_floor = np.mean(ref_var / (ref ** 2 + 0.01))
    return {"rmse": float(np.sqrt(mse)), "relmse": rel,
            "rmse_debiased": float(np.sqrt(max(mse - mse_floor, 1e-3 * mse))),
            "relmse_debiased": float(max(rel - rel_floor, 1e-3 * rel)),
            "rmse_floor": float(np.sqrt(mse_floor)), "relmse_floor": float(rel_floor),
            "flip": flip.mean_flip(img, ref)}


def logical_work(args, scene, size, flags):
    """Mean loop iterations per pixel at 1 spp (--view iterations): each march
    or normal iteration is one sdScene evaluation, so this counts the logical
    work that lavapipe's masked execution hides from the wall clock."""
    out = os.path.join(args.work, "iter.pfm")
    sb.render(args.sdfc, scene, out, ["--size", size, "--spp", "1", "--view", "iterations",
                                      "-q"] + [f for f in flags if f not in ("bilateral", "atrous")])
    return float(np.mean(sb.read_pfm(out)[..., 0]))


def convergence(args, scene, size, configs, writer):
    ref, ref_var = reference(args, scene, size)
    rows = []
    for name in configs:
        flags = [f for f in CONFIGS[name]]
        render_flags = [f for i, f in enumerate(flags)
                        if not (f == "--denoise" or (i > 0 and flags[i - 1] == "--denoise"))]
        work = logical_work(args, scene, size, render_flags)
        for spp in args.spp:
            runs = []
            for rep in range(args.reps):
                out = os.path.join(args.work, f"{name}_{spp}.pfm")
                runs.append(sb.render(args.sdfc, scene, out, ["--size", size, "--spp", str(spp),
                                                              "--seed", str(SEED)] + flags))
                if rep == 0:
                    err = errors(sb.read_pfm(out), ref, ref_var)
            med = lambda k: statistics.median(r[k] for r in runs)
            row = {"scene": os.path.basename(scene), "config": name, "spp": spp,
                   "render_s": med("render_s"), "wall_s": med("wall_s"),
                   "compile_ms": med("compile_ms"), "pipeline_ms": med("pipeline_ms"),
                   # Process time that is neither compile, pipeline nor sampling:
                   # Vulkan setup, readback, the denoiser, the file.
                   "other_s": med("wall_s") - med("compile_ms") / 1e3 - med("pipeline_ms") / 1e3
                   - med("render_s"),
                   "steps_mean": runs[0]["steps_mean"], "steps_max": runs[0]["steps_max"],
                   "step_budget": runs[0]["step_budget"], "iterations_per_pixel_1spp": work,
                   **err}
            rows.append(row)
            log(f"  {name:12s} {spp:4d} spp  {row['render_s']:.3f} s  relMSE {row['relmse']:.4g}  FLIP {row['flip']:.4f}")
    # Denoising happens after the timed sampling: charge each denoised config
    # its extra process time over "derived" (which differs only in that).
    other = {c: statistics.median(r["other_s"] for r in rows if r["config"] == c) for c in configs}
    for r in rows:
        extra = max(0.0, other[r["config"]] - other.get("derived", other[r["config"]]))
        r["denoise_s"] = extra if "--denoise" in CONFIGS[r["config"]] else 0.0
        r["time_s"] = r["render_s"] + r["denoise_s"]
        writer.writerow(r)
    return rows


def equal_error(rows, metric, at=max):
    """Per config: time to reach the baseline's error at its largest spp
    (at=max) or smallest (at=min). The paper-style baseline is biased, so its
    error levels off and other configurations may reach it below 1 spp
    (extrapolated); its 1-spp error is a target they reach by interpolation."""
    base = [r for r in rows if r["config"] == "baseline"]
    if not base:
        return {}
    top = at(base, key=lambda r: r["spp"])
    target, t_base = top[metric], top["time_s"]
    out = {}
    for c in dict.fromkeys(r["config"] for r in rows):
        t, how = sb.time_to_error([(r["time_s"], r[metric]) for r in rows if r["config"] == c], target)
        out[c] = {"time": t, "how": how, "speedup": t_base / t if t else None,
                  "target": target, "t_base": t_base}
    return out


# ---------------------------------------------------------------- plots

def plot_convergence(rows, scene, plots_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    paths = []
    labels = {"relmse_debiased": "relmse (reference noise removed)",
              "rmse_debiased": "rmse (reference noise removed)",
              "flip": "mean LDR-FLIP (67 ppd, against the reference)"}
    for metric in ("relmse_debiased", "rmse_debiased", "flip"):
        fig, ax = plt.subplots(figsize=(6, 4.2))
        for c in dict.fromkeys(r["config"] for r in rows):
            pts = sorted((r["time_s"], r[metric], r["spp"]) for r in rows if r["config"] == c)
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=c,
                    lw=2.2 if c in ("baseline", "derived") else 1.2)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("render time [s] (sampling + denoiser; median of runs)")
        ax.set_ylabel(labels[metric])
        ax.set_title(f"{scene}: error vs time")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = os.path.join(plots_dir, f"{scene.replace('.sdf', '')}_{metric.split('_')[0]}.png")
        fig.savefig(path, dpi=100)
        plt.close(fig)
        paths.append(path)
    return paths


def plot_steps(geo_rows, plots_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = list(dict.fromkeys(r["scene"] for r in geo_rows))
    configs = list(dict.fromkeys(r["config"] for r in geo_rows))
    fig, ax = plt.subplots(figsize=(8, 4))
    w = 0.8 / len(configs)
    for j, c in enumerate(configs):
        vals = [next((r["steps_mean"] for r in geo_rows if r["scene"] == s and r["config"] == c), 0)
                for s in scenes]
        ax.bar(np.arange(len(scenes)) + j * w, vals, w, label=c)
    ax.set_xticks(np.arange(len(scenes)) + 0.4 - w / 2)
    ax.set_xticklabels([s.replace(".sdf", "") for s in scenes], rotation=40, ha="right", fontsize=8)
    ax.set_ylabel("primary-ray steps (mean)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(plots_dir, "steps_per_ray.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


# ---------------------------------------------------------------- report

def fmt(x, spec=".3g"):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–"
    return format(x, spec)


def many_parts_headline():
    """The headline of bench/many_parts.py's last run (results/many_parts.json),
    which has its own page: cost growth with the part count, and pixels off
    the float64 surface, per family."""
    path = os.path.join(HERE, "results", "many_parts.json")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        rows = [r for r in json.load(f) if r.get("binary") == "after" and "cpu_ms_per_sample" in r]
    lines = ["## Many distinct parts (headline of results/many_parts.md)", "",
             "CPU ms per sample at 320x180 (the sampling alone: a render's CPU less a 1 spp render's) "
             "relative to the family's smallest count, each count framed alike; in brackets the same per "
             "hit pixel; and hit pixels off the float64 surface (all counts); run `bench/many_parts.py` "
             "to refresh.", "",
             "| family | parts: cost relative to the first (per hit pixel) | pixels off |", "|---|---|---|"]
    for fam in dict.fromkeys(r["family"] for r in rows):
        fr = sorted((r for r in rows if r["family"] == fam), key=lambda r: r["parts"])
        per_hit = [r["cpu_ms_per_sample"] / r["hits"] if r.get("hits") else float("nan") for r in fr]
        growth = ", ".join(f"{r['parts']}: {r['cpu_ms_per_sample'] / fr[0]['cpu_ms_per_sample']:.1f}x "
                           f"({h / per_hit[0]:.1f}x)" for r, h in zip(fr, per_hit))
        lines.append(f"| {fam} | {growth} | {sum(int(r.get('off', 0)) for r in fr)} |")
    # Families last measured the old way (whole-process CPU, legacy framing).
    legacy = os.path.join(HERE, "results", "many_parts_legacy_framing.json")
    if os.path.exists(legacy):
        with open(legacy) as f:
            old = [fam for fam in dict.fromkeys(r["family"] for r in json.load(f) if "mesh_s" not in r) if fam not in {r["family"] for r in rows}]
        if old:
            lines += ["", f"Not in this run: {', '.join(old)}; their last figures, measured the old way (whole-process "
                      "CPU, legacy framing), are in results/many_parts_legacy_framing.md."]
    return lines + [""]


def bounds_plan_headline():
    """The headline of bench/bounds_plan.py's last run (results/bounds_plan.csv):
    the planned bounding-volume checks against none and all, per scene."""
    path = os.path.join(HERE, "results", "bounds_plan.csv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        rows = list(csv.DictReader(f))
    lines = ["## Bounding-volume checks on lavapipe (headline of results/bounds_plan.md)", "",
             "CPU seconds of a render with no checks over those of the compiler's plan (the default) "
             "and of every check (`--bounds`); run `bench/bounds_plan.py` to refresh.", "",
             "| scene | checks kept | planned | all |", "|---|---|---|---|"]
    for r in rows:
        none = float(r["none_cpu_s"])
        lines.append(f"| {r['scene']} | {r['checks_planned']} of {r['checks_all']} | "
                     f"{none / float(r['planned_cpu_s']):.2f}x | {none / float(r['all_cpu_s']):.2f}x |")
    return lines + [""]


def anim_denoise_headline():
    """The headline of bench/anim_denoise.py's last run (results/anim_denoise.csv):
    an animation's denoise share of the frame time, per denoiser, medians."""
    path = os.path.join(HERE, "results", "anim_denoise.csv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        rows = [r for r in csv.DictReader(f) if r["spp"] == "8"]
    lines = ["## An animation's denoise (headline of results/ANIM_DENOISE.md)", "",
             "morph.sdf, 320x180, 8 spp, 24 frames: per frame, the samples and the denoise in wall ms "
             "(medians over the runs) and the denoise's share of the frame; run `bench/anim_denoise.py` "
             "to refresh.", "",
             "| --denoise | chose | frame ms | samples ms | denoise ms (CPU ms) | share |", "|---|---|---|---|---|---|"]
    for name in dict.fromkeys(r["denoiser"] for r in rows):
        rs = [r for r in rows if r["denoiser"] == name]
        med = lambda k: statistics.median(float(r[k]) for r in rs)
        lines.append(f"| {name} | {rs[0]['chosen']} | {med('frame_ms'):.0f} | {med('samples_ms'):.0f} | "
                     f"{med('denoise_ms'):.0f} ({med('denoise_cpu_ms'):.0f}) | {100 * med('share'):.0f}% |")
    return lines + [""]


def write_report(args, info, conv_rows, speedups, geo_rows, plots, elapsed, mitsuba=None):
    rel = lambda p: os.path.relpath(p, os.path.dirname(args.report))
    lines = ["# sdfc benchmark results", "",
             f"Generated by `bench/run.py` ({'smoke' if args.smoke else 'full'} run, "
             f"{elapsed / 60:.1f} min). Do not edit by hand.", "",
             "## Machine", "",
             f"- CPU: {info['cpu']}, {info['cores']} CPUs",
             f"- Vulkan device: {info['device']}; driver: {info['driver']}",
             f"- LP_NUM_THREADS: {info['lp_num_threads']}",
             f"- sdfc: `{args.sdfc}` (git {info.get('git', '?')})",
             f"- convergence: {args.size}, spp {args.spp}, median of {args.reps} runs, "
             f"reference {args.ref_spp} spp ({' '.join(REFERENCE_FLAGS)}); geometry: {args.geo_size}",
             "",
             "The machine is shared and loaded: only ratios measured in the same run are "
             "meaningful. Times are sdfc's own sampling time (`N spp / spp/s` from stderr) plus, "
             "for denoised configurations, their extra process time over `derived`; compile and "
             "pipeline creation are timed separately (columns `compile_ms`, `pipeline_ms`).",
             "",
             "**lavapipe executes both sides of every `if` under a lane mask** unless all 8 lanes "
             "agree: skipping a subtree by its bounding volume pays only where whole groups skip "
             "(results/bounds_plan.md), and loops exit early only when all 8 lanes are done. "
             "So besides time we report logical work: primary-ray "
             "steps and loop iterations per pixel (`--view iterations`: one sdScene evaluation per "
             "march or normal iteration). Neither counts the nodes a bound skips inside one "
             "evaluation, so the benefit of bounds is not visible in these numbers either.", ""]
    if speedups:
        lines += ["## Headline: equal-error speedup over the paper-style baseline", "",
                  "Baseline = `--paper-baseline --no-bounds --white-noise --denoise bilateral`. "
                  "For each configuration, the time its log-log error/time curve needs to reach "
                  "the baseline's error at the baseline's largest spp; speedup = baseline time / "
                  "that time. 'extrapolated' = outside the measured range (less certain).", ""]
        for scene, by_metric in speedups.items():
            for metric, sp in by_metric.items():
                any_sp = next(iter(sp.values()))
                lines += [f"**{scene}**, metric {metric} (target {any_sp['target']:.4g} reached by "
                          f"the baseline in {any_sp['t_base']:.3f} s):", "",
                          "| config | time to target [s] | speedup | how |", "|---|---|---|---|"]
                for c, v in sp.items():
                    lines.append(f"| {c} | {fmt(v['time'])} | {fmt(v['speedup'], '.2f')} | "
                                 f"{v['how'] or 'not reached'} |")
                lines.append("")
    if conv_rows:
        lines += ["## Error against time", "",
                  "`relmse` = mean((a-b)^2/(b^2+0.01)); `_db` = with the reference's own noise "
                  "(estimated from its two independent halves) subtracted. `flip` = mean LDR-FLIP "
                  "(`bench/flip.py`, Andersson et al. 2020) of the displayed images (clamped to "
                  "[0, 1], sRGB) at 67 pixels per degree, against the reference as it is (not "
                  "debiased, so it includes the reference's own noise). Full data: "
                  "`results/convergence.csv`.", "",
                  "| scene | config | spp | time [s] | compile [ms] | pipeline [ms] | steps mean/max "
                  "| iter/px | rmse | relmse | relmse_db | flip |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in conv_rows:
            lines.append(f"| {r['scene']} | {r['config']} | {r['spp']} | {r['time_s']:.3f} | "
                         f"{r['compile_ms']:.0f} | {r['pipeline_ms']:.0f} | "
                         f"{fmt(r['steps_mean'], '.1f')}/{fmt(r['steps_max'], '.0f')} | "
                         f"{r['iterations_per_pixel_1spp']:.0f} | {r['rmse']:.4g} | "
                         f"{r['relmse']:.4g} | {r['relmse_debiased']:.4g} | {r['flip']:.4f} |")
        lines.append("")
        for p in plots:
            lines.append(f"![{os.path.basename(p)}]({rel(p)})")
        lines.append("")
    lines += many_parts_headline()
    lines += bounds_plan_headline()
    lines += anim_denoise_headline()
    if geo_rows:
        lines += ["## Primary-ray geometry (hit distance against float64 roots)", "",
                  "Depth AOV (1 spp, unjittered pixel-centre ray) against the first sign change "
                  "of the float64 distance (`sdfc eval`) along the same ray, found by marching "
                  "with a safe step and bisecting to 1e-14. `rel err` = |t - t*| / t*, over rays "
                  "where both hit; target 1e-4. `surf px` = |f(hit point)| in pixels (the "
                  "screen-space error: a pixel-cone epsilon stops within a fraction of a pixel, "
                  "which along grazing rays is a large relative hit-distance error). missed = "
                  "exact hit reported as a miss (share of exact hits; of which by running out of "
                  "steps); overshoot = reported hit >1% beyond the first root (tunnelling); early "
                  "= >1% before it. Normal error against the float64 gradient at the root. Full "
                  "data: `results/geometry.csv`.", "",
                  "| scene | config | steps mean/max (budget) | out of steps | missed (budget) "
                  "| false hits | overshoot | early | rel err median / p95 | ≤1e-4 | surf px median/max "
                  "| normal err median/p99 [°] |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        pct = lambda x: fmt(100 * x, ".2f") + "%"
        for r in geo_rows:
            lines.append(
                f"| {r['scene']} | {r['config']} | {r['steps_mean']:.1f}/{r['steps_max']} "
                f"({r['step_budget']}) | {pct(r['out_of_steps'])} | {pct(r['missed_hits'])} "
                f"({pct(r['missed_by_budget'])}) | {pct(r['false_hits'])} | {pct(r['overshoot'])} | "
                f"{pct(r['early_stop'])} | {fmt(r['rel_err_median'], '.2e')} / "
                f"{fmt(r['rel_err_p95'], '.2e')} | {pct(r['within_target'])} | "
                f"{fmt(r['surf_px_median'], '.3f')}/{fmt(r['surf_px_max'], '.3f')} | "
                f"{fmt(r['normal_err_median_deg'], '.2f')}/{fmt(r['normal_err_p99_deg'], '.1f')} |")
        lines += ["", f"![steps per ray]({rel(os.path.join(args.plots, 'steps_per_ray.png'))})", ""]
    if mitsuba:
        lines += ["## Against Mitsuba 3 (independent renderer)", "",
                  f"`bench/mitsuba_check.py efficiency`: the three shared scenes (spheres, boxes, "
                  f"capped cylinders, a ground plane; diffuse, mirror and glass; uniform sky) in "
                  f"sdfc and in Mitsuba {mitsuba.get('mitsuba', '3')} `scalar_rgb` (path tracer, "
                  f"{mitsuba['mitsuba_sampler']} sampler, box filter), both on the same "
                  f"{mitsuba['threads']} CPUs, {mitsuba['width']}x{mitsuba['height']}, "
                  f"{mitsuba['bounces']} bounces, spp {mitsuba['spp']}. Error = per-pixel RMSE of "
                  "one render against the converged image, from the difference of two seeds (both "
                  "renderers are unbiased against each other: last columns). Target = Mitsuba's "
                  "error at its largest spp; times are whole-process wall times for sdfc (start-up, "
                  "compile, pipeline creation, render, image write) and scene load plus render for "
                  "Mitsuba (in process, after import); 'render only' excludes both set-ups. "
                  "Ratio below 1: sdfc reaches the error sooner. The stored-reference test "
                  "(`tests/mitsuba_reference.json`, 4096 Mitsuba spp) runs in CTest.", "",
                  "| scene | target RMSE | sdfc [s] | Mitsuba [s] | ratio | render only | mean diff | s.e. |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in mitsuba["rows"]:
            lines.append(f"| {r['scene']} | {r['target_rmse']:.4f} | {r['time sdfc']:.2f} | "
                         f"{r['time Mitsuba']:.2f} | {r['ratio']:.2f} | {r['ratio render']:.2f} | "
                         f"{r['mean_diff_percent']:.4f}% | {r['z_max']:.2f} |")
        lines.append("")
    menger = os.path.join(HERE, "results", "MENGER_MITSUBA.md")
    if os.path.exists(menger):
        lines += ["Menger sponge of level 5 against Mitsuba 3 with 3.2 million cubes as a mesh: "
                  f"[{os.path.basename(menger)}]({rel(menger)}) (`bench/mitsuba_menger.py`, "
                  "run separately: it takes several minutes and gigabytes).", ""]
    lines += ["## Not done", "",
              "- HDR-FLIP (exposure brackets over the linear radiance): only LDR-FLIP of the "
              "clamped display image is reported.",
              "- Skipped for the time budget (`--budget-min`, `--total-min`): "
              + (", ".join(args.skipped) or "nothing"), ""]
    with open(args.report, "w") as f:
        f.write("\n".join(lines))


# ---------------------------------------------------------------- main

def parse_args():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--size", default="160x90", help="convergence renders")
    p.add_argument("--geo-size", default="160x90", help="geometry (depth) renders")
    p.add_argument("--spp", type=int, nargs="+", default=[1, 4, 16])
    p.add_argument("--reps", type=int, default=3, help="timed runs per point (median)")
    p.add_argument("--ref-spp", type=int, default=256)
    p.add_argument("--scenes", nargs="*", help="convergence scenes (default examples/*.sdf)")
    p.add_argument("--hard", nargs="*", help="geometry-only scenes (default examples/hard/*.sdf)")
    p.add_argument("--configs", nargs="+", default=list(CONFIGS))
    p.add_argument("--budget-min", type=float, default=6,
                   help="skip further convergence scenes (after the castle) past this time")
    p.add_argument("--total-min", type=float, default=11,
                   help="skip geometry of further example scenes (hard cases and the castle "
                        "always run) past this time")
    p.add_argument("--cache", default=os.path.join(HERE, "cache"))
    p.add_argument("--reuse-refs", action="store_true",
                   help="use a cached reference of the scene made by an earlier kernel")
    p.add_argument("--out", default=HERE, help="where results/, plots/ and RESULTS.md go")
    p.add_argument("--smoke", action="store_true", help="reduced run with checks (CI)")
    p.add_argument("--converge", action="store_true",
                   help="seconds to a visually converged image (bench/converge.py)")
    p.add_argument("--converge-configs", nargs="+", default=list(converge.CONVERGE_CONFIGS))
    p.add_argument("--flip-target", type=float, default=0.05)
    p.add_argument("--relmse-target", type=float, default=0.001)
    p.add_argument("--converge-min-spp", type=int, default=1)
    p.add_argument("--converge-max-spp", type=int, default=1024)
    p.add_argument("--converge-budget-s", type=float, default=240,
                   help="per scene and configuration: stop the ladder past this wall time")
    p.add_argument("--cpu-time", action="store_true",
                   help="--converge: also process CPU seconds and spp to each target")
    args = p.parse_args()
    if args.converge:
        args.scenes = args.scenes or [os.path.join(ROOT, "examples", s) for s in
                                      ("castle.sdf", "colonnade.sdf", "glass_menger.sdf")]
    if args.smoke:
        args.size, args.geo_size, args.spp, args.reps, args.ref_spp = "64x36", "64x36", [1, 4], 1, 32
        args.configs = ["derived", "baseline"]
        args.scenes = args.scenes or [os.path.join(ROOT, "examples", "diffuse_sphere.sdf")]
    args.scenes = args.scenes if args.scenes is not None else sorted(
        glob.glob(os.path.join(ROOT, "examples", "*.sdf")))
    # The castle first: it carries the headline and must not fall to the budget.
    args.scenes.sort(key=lambda s: (os.path.basename(s) != "castle.sdf", s))
    args.hard = args.hard if args.hard is not None else sorted(
        glob.glob(os.path.join(ROOT, "examples", "hard", "*.sdf")))
    args.results = os.path.join(args.out, "results")
    args.plots = os.path.join(args.out, "plots")
    args.report = os.path.join(args.out, "RESULTS.md")
    args.work = os.path.join(args.cache, "work")
    args.skipped = []
    for d in (args.cache, args.results, args.plots, args.work):
        os.makedirs(d, exist_ok=True)
    return args


def main_converge(args, start):
    load_start = os.getloadavg()[0]
    rows, summary, csv_path = converge.run(args, reference, errors)
    plots = converge.plot(rows, args.plots, args.size)
    report = os.path.join(args.out, "results", f"CONVERGE_{args.size}.md")
    command = " ".join(a.replace(ROOT + os.sep, "") for a in sys.argv[1:])
    lines = [f"# sdfc: seconds to a visually converged image, {args.size}", "",
             f"Generated by `bench/run.py {command}` in {(time.time() - start) / 60:.1f} min "
             f"(load average {load_start:.1f} at the start, {os.getloadavg()[0]:.1f} at the end); "
             f"data {os.path.relpath(csv_path, args.out)}.", ""]
    lines += converge.report_lines(args, summary, args.ref_spp) + [""]
    lines += [f"![{os.path.basename(p)}](../plots/{os.path.basename(p)})" for p in plots]
    with open(report, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(converge.report_lines(args, summary, args.ref_spp)))
    return 0


def main():
    args = parse_args()
    start = time.time()
    if args.converge:
        return main_converge(args, start)
    info = sb.machine_info(args.sdfc)
    try:
        import subprocess
        info["git"] = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                     capture_output=True, text=True).stdout.strip()
    except OSError:
        pass
    log(f"machine: {info}")

    conv_rows, speedups, plots = [], {}, []
    with open(os.path.join(args.results, "convergence.csv"), "w", newline="") as f:
        writer = None
        for scene in args.scenes:
            if os.path.basename(scene) != "castle.sdf" and time.time() - start > args.budget_min * 60:
                log(f"budget spent: skipping convergence of {scene}")
                args.skipped.append(f"convergence of {os.path.basename(scene)}")
                continue
            log(f"convergence: {scene}")
            if writer is None:
                fields = ["scene", "config", "spp", "time_s", "render_s", "denoise_s", "wall_s",
                          "other_s", "compile_ms", "pipeline_ms", "steps_mean", "steps_max",
                          "step_budget", "iterations_per_pixel_1spp", "rmse", "relmse",
                          "rmse_debiased", "relmse_debiased", "rmse_floor", "relmse_floor", "flip"]
                writer = csv.DictWriter(f, fieldnames=fields)
                writer.writeheader()
            rows = convergence(args, scene, args.size, args.configs, writer)
            f.flush()
            conv_rows += rows
            name = os.path.basename(scene)
            speedups[name] = {m: equal_error(rows, m) for m in ("relmse_debiased", "rmse_debiased")}
            speedups[name]["relmse_debiased, baseline at its smallest spp"] = equal_error(
                rows, "relmse_debiased", at=min)
            speedups[name] = {m: v for m, v in speedups[name].items() if v}
            if not speedups[name]:
                del speedups[name]
            plots += plot_convergence(rows, name, args.plots)

    geo_rows = []
    gw, gh = map(int, args.geo_size.split("x"))
    geo_configs = [c for c in GEOMETRY_CONFIGS if c in args.configs or args.smoke]
    if args.smoke:
        geo_configs = ["derived"]
    # Hard cases and the castle always; other examples while time remains. The
    # smoke run measures only the hard cases whose bounds it asserts.
    must = args.hard + [s for s in args.scenes if os.path.basename(s) == "castle.sdf"]
    geo_scenes = must + [s for s in args.scenes if s not in must]
    if args.smoke:
        geo_scenes = [s for s in args.hard
                      if SMOKE_BOUNDS.get(os.path.relpath(s, os.path.join(ROOT, "examples")), {}) is not None]
    for scene in geo_scenes:
        if scene not in must and time.time() - start > args.total_min * 60:
            log(f"time spent: skipping geometry of {scene}")
            args.skipped.append(f"geometry of {os.path.basename(scene)}")
            continue
        log(f"geometry: {scene}")
        for c in geo_configs:
            row = geometry.measure(args.sdfc, scene, CONFIGS[c], gw, gh, args.work, args.cache)
            geo_rows.append({"scene": os.path.relpath(scene, os.path.join(ROOT, "examples")),
                             "config": c, **row})
    if geo_rows:
        with open(os.path.join(args.results, "geometry.csv"), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(geo_rows[0]))
            w.writeheader()
            w.writerows(geo_rows)
        plot_steps(geo_rows, args.plots)

    mitsuba = None if args.smoke else mitsuba_efficiency(args)
    write_report(args, info, conv_rows, speedups, geo_rows, plots, time.time() - start, mitsuba)
    print_summary(speedups, geo_rows)
    log(f"done in {(time.time() - start) / 60:.1f} min; report: {args.report}")
    if args.smoke:
        return smoke_checks(conv_rows, geo_rows)
    return 0


def mitsuba_efficiency(args):
    """Equal-error time against Mitsuba 3 on the shared scenes, when the
    `mitsuba` module is importable (pip; not a build dependency)."""
    import json
    import subprocess
    py = sys.executable
    if subprocess.run([py, "-c", "import mitsuba"], capture_output=True).returncode != 0:
        args.skipped.append("Mitsuba 3 comparison (`pip install mitsuba` to enable)")
        return None
    out = os.path.join(args.results, "mitsuba_efficiency.json")
    log("Mitsuba 3: equal-error time on the shared scenes")
    subprocess.run([py, os.path.join(HERE, "mitsuba_check.py"), "efficiency", "--sdfc", args.sdfc,
                    "--json", out], check=True)
    with open(out) as f:
        data = json.load(f)
    try:
        import importlib.metadata
        data["mitsuba"] = importlib.metadata.version("mitsuba")
    except Exception:  # metadata missing: the report says "Mitsuba 3"
        pass
    return data


def print_summary(speedups, geo_rows):
    for scene, by_metric in speedups.items():
        for metric, sp in by_metric.items():
            cells = ", ".join(f"{c} {fmt(v['speedup'], '.2f')}x" for c, v in sp.items())
            print(f"{scene} equal-{metric} speedup over baseline: {cells}")
    print(f"{'scene':28s} {'config':10s} {'steps':>11s} {'outOfSteps':>10s} {'missed':>8s} "
          f"{'relErrMed':>10s} {'relErrP95':>10s}")
    for r in geo_rows:
        print(f"{r['scene']:28s} {r['config']:10s} {r['steps_mean']:6.1f}/{r['steps_max']:<4d} "
              f"{100 * r['out_of_steps']:9.2f}% {100 * r['missed_hits']:7.2f}% "
              f"{r['rel_err_median']:10.2e} {r['rel_err_p95']:10.2e}")


# Geometry bounds the smoke test asserts (derived configuration, smoke size),
# from the measured results in RESULTS.md with margin. The derived epsilon is a
# quarter-pixel cone, so the hit point lies within ~0.25 px of the surface but
# the relative hit distance is only ~pixel_angle / 4 / cos(incidence): ~1e-3
# and more, never the issue's 1e-4 (no hard case meets 1e-4 today, so none is
# asserted at 1e-4; see RESULTS.md). These bounds catch tunnelling, lost hits
# and a broken epsilon policy.
DEFAULT_BOUNDS = {"overshoot": 0.005, "missed_hits": 0.005, "surf_px_max": 0.3,
                  "rel_err_median": 0.03}
SMOKE_BOUNDS = {
    # float32 positions near 1e4 are rounded to ~1e-3: up to ~0.6 px measured.
    "hard/far_origin.sdf": {"surf_px_max": 1.0},
    # Grazing rays run out of steps at the horizon (~1-3% measured).
    "hard/grazing.sdf": {"surf_px_max": 1.0, "missed_hits": 0.04},
    # Known failure, not asserted: primary rays starting inside a solid stop at t = 0.
    "hard/camera_inside.sdf": None,
    # Not judged by geometry.py's roots of the union field, which count a camera on a
    # surface as a hit at t = 0 and see no root where two solids touch; the issue 17
    # rules (docs/accuracy.md) are checked by bench/exact_hits.py and
    # tests/accuracy_test.cpp against exact ray-box / ray-sphere hits.
    "hard/i17_camera_on_box.sdf": None,
    "hard/i17_camera_on_sphere.sdf": None,
    "hard/i17_glass_on_ground.sdf": None,
}


def smoke_checks(conv_rows, geo_rows):
    failures = []
    for r in conv_rows:
        if not (np.isfinite(r["relmse"]) and r["render_s"] and r["render_s"] > 0
                and 0 <= r["flip"] <= 1):
            failures.append(f"{r['scene']} {r['config']} {r['spp']}: bad row {r}")
    # More samples must reduce the error (a broken accumulator or reference would not).
    for c in dict.fromkeys(r["config"] for r in conv_rows):
        rs = sorted((r for r in conv_rows if r["config"] == c), key=lambda r: r["spp"])
        if len(rs) >= 2 and not rs[-1]["relmse"] < rs[0]["relmse"]:
            failures.append(f"{c}: relMSE does not fall with spp ({rs[0]['relmse']} -> {rs[-1]['relmse']})")
    for r in geo_rows:
        if not r["scene"].startswith("hard/") or SMOKE_BOUNDS.get(r["scene"], {}) is None:
            continue
        bounds = {**DEFAULT_BOUNDS, **SMOKE_BOUNDS.get(r["scene"], {})}
        for key, limit in bounds.items():
            if not r[key] <= limit:
                failures.append(f"{r['scene']} {r['config']}: {key} = {r[key]:.3g} > {limit:.3g}")
    if not any(r["scene"].startswith("hard/") for r in geo_rows):
        failures.append("no hard case was measured")
    for msg in failures:
        print("FAIL:", msg)
    print("smoke:", "FAILED" if failures else "ok", f"({len(geo_rows)} geometry rows checked)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
