"""Issue 17 hard cases against exact float64 ray-primitive intersection.

Each scene in examples/hard/i17_*.sdf is a union of spheres and axis-aligned
boxes, restated here; the first hit of every pixel-centre ray is solved in
float64 in closed form (ray-sphere quadratic, slab test) and compared with
sdfc's depth, normal and albedo AOVs. Rules (docs/accuracy.md):
  - a ray starting on a surface counts a hit at t = 0 only if it enters the solid;
  - a ray starting inside a solid hits where it leaves it;
  - where two solids touch (coplanar faces), the surface is that of the solid
    the ray enters, else of the one it leaves.

Usage: python3 bench/exact_hits.py [--sdfc build/cli/sdfc] [--json out.json] [scenes...]
       python3 bench/exact_hits.py --table before.json after.json   (markdown rows)
"""
import argparse
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sdfbench as sb  # noqa: E402
from geometry import steps_from_heatmap  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def sphere(c, r, albedo):
    return ("sphere", np.array(c, float), float(r), np.array(albedo, float))


def box(c, size, albedo):
    return ("box", np.array(c, float), np.array(size, float) / 2, np.array(albedo, float))


CLAY = [0.8, 0.3, 0.25]
SCENES = {
    "i17_small_on_huge.sdf": [box([0, -0.5, 0], [2000, 1, 2000], [0.6] * 3),
                              sphere([0, 0.1, 0], 0.1, CLAY)],
    "i17_far_pair.sdf": [sphere([0, 0, 0], 1, CLAY), sphere([1e5, 0, 0], 1, CLAY)],
    "i17_far_narrow.sdf": [sphere([0.3, -0.2, -1e6], 1, CLAY)],
    "i17_grazing_box.sdf": [box([0, -1, -500], [400, 2, 1000], [0.6] * 3),
                            box([1.5, 0.25, -8], [2, 0.1, 6], [0.3, 0.5, 0.7])],
    "i17_camera_on_box.sdf": [box([0, -0.5, 0], [4, 1, 4], [0.6] * 3),
                              sphere([0.4, 1, -3], 0.5, CLAY)],
    "i17_camera_on_sphere.sdf": [sphere([0, 0, 0], 1, CLAY),
                                 box([0.5, 2.5, -3], [1, 1, 1], [0.2, 0.3, 0.8])],
    "i17_glass_on_ground.sdf": [box([0, -0.5, 0], [8, 1, 8], [0.6, 0.55, 0.5]),
                                box([0, 0.25, 0], [1, 0.5, 1], [1, 1, 1])],
    "i17_mirror_slab.sdf": [box([0, 0, 0], [1.6, 1.2, 0.02], [0.95] * 3),
                            box([0, 0, 6], [20, 20, 0.2], [0.7] * 3)],
}


def events(prim, ro, rd):
    """(t_enter, n_enter, t_exit, n_exit) per ray for one primitive; nan = none.
    t_enter < 0 <= t_exit means the ray starts inside."""
    kind, c = prim[0], prim[1]
    n = len(rd)
    if kind == "sphere":
        r = prim[2]
        oc = ro - c
        b = rd @ oc
        h = b * b - (oc @ oc - r * r)
        ok = h >= 0
        s = np.sqrt(np.where(ok, h, 0))
        t0 = np.where(ok, -b - s, np.nan)
        t1 = np.where(ok, -b + s, np.nan)
        # On the surface (oc.oc == r^2 exactly): roots 0 and -2b; the ray enters iff b < 0.
        n0 = (ro + t0[:, None] * rd - c) / r
        n1 = (ro + t1[:, None] * rd - c) / r
        return t0, n0, t1, n1
    half = prim[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / rd
        ta = (c - half - ro) * inv
        tb = (c + half - ro) * inv
    near = np.minimum(ta, tb)
    far = np.maximum(ta, tb)
    t0 = near.max(axis=1)
    t1 = far.min(axis=1)
    ok = t0 <= t1
    a0 = near.argmax(axis=1)
    a1 = far.argmin(axis=1)
    n0 = np.zeros((n, 3))
    n1 = np.zeros((n, 3))
    n0[np.arange(n), a0] = -np.sign(rd[np.arange(n), a0])
    n1[np.arange(n), a1] = np.sign(rd[np.arange(n), a1])
    return np.where(ok, t0, np.nan), n0, np.where(ok, t1, np.nan), n1


def exact_first_hits(prims, ro, rd):
    """Nearest event per ray: depth (inf = miss), normal (outward of the solid
    whose surface it is), albedo. Entering beats leaving at equal t (contact)."""
    n = len(rd)
    best_t = np.full(n, np.inf)
    best_enter = np.zeros(n, bool)
    normal = np.zeros((n, 3))
    albedo = np.zeros((n, 3))
    for p in prims:
        t0, n0, t1, n1 = events(p, ro, rd)
        # Entering at t0 >= 0 (t0 == 0: the ray starts on the surface and goes in,
        # which needs t1 > 0); leaving at t1 > 0 when starting inside (t0 < 0).
        enter = (t0 >= 0) & (t1 > t0)
        leave = (t0 < 0) & (t1 > 0)
        for cand, t, nn, is_enter in ((enter, t0, n0, True), (leave, t1, n1, False)):
            tt = np.where(cand, t, np.inf)
            better = (tt < best_t) | ((tt == best_t) & is_enter & ~best_enter & np.isfinite(tt))
            best_t = np.where(better, tt, best_t)
            best_enter = np.where(better, is_enter, best_enter)
            normal[better] = nn[better]
            albedo[better] = p[3]
    return best_t, normal, albedo


def f32_bound(ro, rd, t):
    """What float32 can resolve of a hit, as a distance to the surface: 16 ulps
    of the largest of t, |p|, |ro| and 1 (p = ro + rd t and the scene's
    unit-sized terms are rounded; docs/accuracy.md)."""
    p = ro + rd * t[:, None]
    mag = np.maximum.reduce([np.abs(p).max(axis=1), t, np.full(len(t), np.abs(ro).max()),
                             np.ones(len(t))])
    return 16 * mag * 2.0 ** -23


def measure(sdfc, scene_path, width=160, height=120, workdir=None):
    name = os.path.basename(scene_path)
    prims = SCENES[name]
    workdir = workdir or tempfile.mkdtemp(prefix="exact_hits_")
    base = os.path.join(workdir, name.replace(".sdf", ""))
    common = ["--size", f"{width}x{height}", "--spp", "1"]
    info = sb.render(sdfc, scene_path, base + "_depth.pfm", common + ["--view", "depth"])
    for view in ("normal", "albedo", "steps"):
        sb.render(sdfc, scene_path, f"{base}_{view}.pfm", common + ["--view", view, "-q"])
    depth = sb.read_pfm(base + "_depth.pfm")[..., 0].reshape(-1)
    normal = (sb.read_pfm(base + "_normal.pfm") * 2 - 1).reshape(-1, 3)
    albedo = sb.read_pfm(base + "_albedo.pfm").reshape(-1, 3)
    budget = info["step_budget"] or 1
    steps = steps_from_heatmap(sb.read_pfm(base + "_steps.pfm"), budget).reshape(-1)

    cam = sb.parse_camera(sb.compile_text(sdfc, scene_path, "ir"))
    ro, rd = sb.camera_rays(cam, width, height)
    rd = rd.reshape(-1, 3)
    t_ref, n_ref, a_ref = exact_first_hits(prims, ro, rd)
    ref_hit = np.isfinite(t_ref)
    gpu_hit = depth >= 0
    both = ref_hit & gpu_hit
    err = np.abs(depth[both] - t_ref[both])
    rel = err / np.maximum(t_ref[both], 1e-300)
    bound = f32_bound(ro, rd[both], t_ref[both])
    surf = err * np.abs(np.sum(rd[both] * n_ref[both], axis=1))  # distance to the surface
    cos = np.sum(normal[both] * n_ref[both], axis=1)
    ang = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    alb_err = np.abs(albedo[both] - a_ref[both]).max(axis=1)
    frac = lambda m: float(np.mean(m)) if m.size else float("nan")
    return {
        "scene": name,
        "pixels": int(len(depth)),
        "ref_hits": int(ref_hit.sum()),
        "sdfc_hits": int(gpu_hit.sum()),
        "hit_miss_disagree": int(np.sum(ref_hit != gpu_hit)),
        "missed": int(np.sum(ref_hit & ~gpu_hit)),
        "false_hits": int(np.sum(gpu_hit & ~ref_hit)),
        "depth_off_1e-3": frac(err > 1e-3),
        "depth_rel_off_1e-3": frac(rel > 1e-3),
        "depth_rel_median": float(np.median(rel)) if rel.size else float("nan"),
        "depth_rel_max": float(rel.max()) if rel.size else float("nan"),
        "surface_off_f32_bound": frac(surf > bound),
        "normal_off_1deg": frac(ang > 1.0),
        "normal_err_max_deg": float(ang.max()) if ang.size else float("nan"),
        "albedo_wrong": frac(alb_err > 1e-3),
        "out_of_steps": int(np.sum(steps >= budget)),
        "step_budget": int(budget),
    }


def table(before_path, after_path):
    """Markdown rows: each figure as before -> after."""
    load = lambda p: {r["scene"]: r for r in json.load(open(p))}
    before, after = load(before_path), load(after_path)
    pct = lambda v: f"{100 * v:.2f}%"
    cols = [("hit px (exact)", lambda r: f"{r['sdfc_hits']} ({r['ref_hits']})"),
            ("hit/miss wrong", lambda r: str(r["hit_miss_disagree"])),
            ("depth off >1e-3", lambda r: pct(r["depth_off_1e-3"])),
            ("surface dist >16 ulp", lambda r: pct(r["surface_off_f32_bound"])),
            ("normal off >1 deg", lambda r: pct(r["normal_off_1deg"])),
            ("albedo wrong", lambda r: pct(r["albedo_wrong"])),
            ("out of steps (budget)", lambda r: f"{r['out_of_steps']} ({r['step_budget']})")]
    lines = ["| scene | " + " | ".join(c for c, _ in cols) + " |",
             "|---" * (len(cols) + 1) + "|"]
    for name, a in after.items():
        b = before.get(name)
        cells = [(f(b) + " -> " if b else "") + f(a) for _, f in cols]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--table":
        print(table(sys.argv[2], sys.argv[3]))
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--json", help="write the rows here")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args()
    scenes = args.scenes or [os.path.join(ROOT, "examples", "hard", s) for s in SCENES]
    w, h = map(int, args.size.split("x"))
    rows = []
    for s in scenes:
        row = measure(args.sdfc, s, w, h)
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
