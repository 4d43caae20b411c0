"""Geometric error of the primary rays: the depth AOV of `sdfc render` against
the first root of the scene's float64 distance along the same camera ray."""
import os

import numpy as np

import sdfbench as sb

TARGET_REL = 1e-4     # the target for the relative hit-distance error
WRONG_SURFACE = 1e-2  # a relative error above this is another surface, not imprecision


def steps_from_heatmap(img, budget):
    """The steps view's march steps per pixel: its PFM holds the raw count in
    every channel (the heat map is drawn for PNGs only; runtime/debug_view.h).
    `budget` is kept for the callers; the count needs no inverting."""
    return np.rint(img[..., 0])


def reference_roots(sdfc, scene, width, height, cache_dir):
    """Exact roots for every pixel-centre ray, cached by scene and size."""
    key = sb.file_hash([scene, sdfc], f"roots{width}x{height}")  # sdfc: its evaluator
    path = os.path.join(cache_dir, f"roots_{os.path.basename(scene)}_{key}.npz")
    if os.path.exists(path):
        d = np.load(path)
        return d["roots"], d["sign0"], d["normals"], int(d["evals"])
    cam = sb.parse_camera(sb.compile_text(sdfc, scene, "ir"))
    limits = sb.scene_limits(sdfc, scene)
    ro, rd = sb.camera_rays(cam, width, height)
    rd = rd.reshape(-1, 3)
    sdf = sb.Evaluator(sdfc, scene)
    # 0.8: margin below the compiler's 1 / Lipschitz for bounds it may misjudge.
    roots, sign0 = sb.exact_roots(sdf, ro, rd, limits["kSceneMaxDist"],
                                  0.8 * limits.get("kSceneStepScale", 1.0))
    evals = sdf.count
    sdf.close()
    # Float64 gradient at the root: the normal the AOV should report.
    grad = sb.Evaluator(sdfc, scene, gradient=True)
    normals = np.full((len(rd), 3), np.nan)
    ok = np.isfinite(roots)
    if ok.any():
        g = grad(ro + rd[ok] * roots[ok][:, None])[:, 1:4]
        normals[ok] = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)
    grad.close()
    np.savez(path, roots=roots, sign0=sign0, normals=normals, evals=evals)
    return roots, sign0, normals, evals


def measure(sdfc, scene, flags, width, height, workdir, cache_dir):
    """One scene under one compiler configuration: a row of statistics."""
    base = os.path.join(workdir, os.path.basename(scene).replace(".sdf", ""))
    common = ["--size", f"{width}x{height}", "--spp", "1"] + list(flags)
    # Not quiet: stderr carries the step budget.
    info = sb.render(sdfc, scene, base + "_depth.pfm", common + ["--view", "depth"])
    sb.render(sdfc, scene, base + "_steps.pfm", common + ["--view", "steps", "-q"])
    sb.render(sdfc, scene, base + "_normal.pfm", common + ["--view", "normal", "-q"])
    budget = info["step_budget"]
    depth = sb.read_pfm(base + "_depth.pfm")[..., 0].reshape(-1)
    steps = steps_from_heatmap(sb.read_pfm(base + "_steps.pfm"), budget).reshape(-1)
    normal = (sb.read_pfm(base + "_normal.pfm") * 2 - 1).reshape(-1, 3)
    roots, sign0, ref_n, evals = reference_roots(sdfc, scene, width, height, cache_dir)

    ref_hit = np.isfinite(roots)
    gpu_hit = depth >= 0
    both = ref_hit & gpu_hit
    t_ref, t_gpu = roots[both], depth[both]
    rel = np.abs(t_gpu - t_ref) / np.maximum(t_ref, 1e-300)
    same = rel <= WRONG_SURFACE
    # Distance of the reported hit point from the surface, in pixels: a pixel-cone
    # epsilon stops up to ~half a pixel from the surface, which along a grazing
    # ray is a large hit-distance error but an invisible one on screen.
    cam = sb.parse_camera(sb.compile_text(sdfc, scene, "ir"))
    ro, rd = sb.camera_rays(cam, width, height)
    sdf = sb.Evaluator(sdfc, scene)
    f_gpu = np.abs(sdf(ro + rd.reshape(-1, 3)[both] * t_gpu[:, None]))
    sdf.close()
    pixel_angle = 2 * np.tan(np.radians(cam["fov"]) / 2) / height
    # t = 0 (a ray that "hits" at its origin) has no meaningful screen error.
    px = np.where(t_gpu > 0, f_gpu / np.maximum(t_gpu, 1e-30) / pixel_angle, np.nan)[t_gpu > 0]
    n = len(depth)
    nref = max(int(ref_hit.sum()), 1)
    stat = lambda fn, a: float(fn(a)) if len(a) else float("nan")
    row = {
        "rays": n,
        "ref_hit_share": float(ref_hit.sum() / n),
        "start_inside": float(np.mean(sign0 < 0)),
        "steps_mean": float(steps.mean()),
        "steps_max": int(steps.max()),
        "step_budget": int(budget),
        "out_of_steps": float(np.mean(steps >= budget)),
        # Share of rays with an exact hit that the renderer reports as a miss.
        "missed_hits": float(np.sum(ref_hit & ~gpu_hit) / nref),
        "missed_by_budget": float(np.sum(ref_hit & ~gpu_hit & (steps >= budget)) / nref),
        "false_hits": float(np.sum(gpu_hit & ~ref_hit) / n),
        # Passed through the first surface (tunnelling) / stopped well before it.
        "overshoot": float(np.sum(t_gpu > t_ref * (1 + WRONG_SURFACE)) / nref),
        "early_stop": float(np.sum(t_gpu < t_ref * (1 - WRONG_SURFACE)) / nref),
        "rel_err_median": stat(np.median, rel),
        "rel_err_p95": stat(lambda a: np.percentile(a, 95), rel),
        "rel_err_max": stat(np.max, rel),
        "within_target": stat(lambda a: np.mean(a <= TARGET_REL), rel),
        "surf_px_median": stat(np.median, px),
        "surf_px_max": stat(np.max, px),
        "ref_evals_per_ray": evals / n,
    }
    # Normal error in degrees where both found the same surface.
    if same.any():
        gn = normal[both][same]
        rn = ref_n[both][same]
        cos = np.clip(np.sum(gn * rn, axis=1) / np.maximum(np.linalg.norm(gn, axis=1), 1e-30), -1, 1)
        ang = np.degrees(np.arccos(cos))
        row["normal_err_median_deg"] = float(np.median(ang))
        row["normal_err_p99_deg"] = float(np.percentile(ang, 99))
    else:
        row["normal_err_median_deg"] = row["normal_err_p99_deg"] = float("nan")
    return row
