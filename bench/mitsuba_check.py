#!/usr/bin/env python3
"""Independent reference: the shared scenes in Mitsuba 3 (PyPI `mitsuba`,
variant scalar_rgb; its LLVM variants crash against Debian 12's LLVM 15) and in
sdfc, compared by mean radiance within the Monte Carlo noise, and by the wall
time each needs to reach the same noise.

The shared scenes use only what both renderers express identically: spheres,
boxes, capped cylinders, an infinite ground, the paper's three materials
(diffuse, mirror, glass without tint) under a uniform sky, a pinhole camera
with a vertical field of view, and a fixed path length. Boxes and cylinders
float 0.05 above the ground: where a cylinder stands on it, Mitsuba 3.9.1
renders the pixels along the contact line up to 20% darker than a float64
integration of the same pixels (which sdfc matches within 1%).

    /usr/bin/python3 bench/mitsuba_check.py [--sdfc build/cli/sdfc]
        check          sdfc against Mitsuba, both rendered now
        reference      render Mitsuba at high spp, write tests/mitsuba_reference.json
        test           sdfc against the stored reference (CTest; no Mitsuba needed)
        efficiency     equal-error wall time, sdfc against Mitsuba
        envmap         an environment-lit scene (sky(map:) / Mitsuba's envmap, the
                       same EXR, rotated): the map seen directly (0 bounces), then
                       the lit scene; mean within 1%, every block within 3%
"""
import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import sdfbench as sb  # noqa: E402
REFERENCE_JSON = os.path.join(HERE, "..", "tests", "mitsuba_reference.json")

CAMERA = {"position": [0, 1.2, 4.5], "target": [0, 0.6, 0], "fov": 40}

# Each scene: the sdfc source (size/spp/bounces filled in) and the same scene
# for Mitsuba as load_dict entries besides sensor, integrator and sky.
SCENES = {
    "diffuse_sphere": {
        "sdf": """
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([0, 0.7, 0]) { sphere(radius: 0.7, material: diffuse(albedo: [0.8, 0.3, 0.25])) }
""",
        "shapes": lambda T: {
            "ball": {"type": "sphere", "center": [0, 0.7, 0], "radius": 0.7,
                     "bsdf": diffuse([0.8, 0.3, 0.25])},
        },
    },
    "mirror_box_cylinder": {
        "sdf": """
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([-0.6, 0.55, 0]) {
    rotate(axis: [0, 1, 0], degrees: 30) { box(size: [0.9, 1, 0.9], material: mirror(tint: [0.9, 0.9, 0.9])) }
  }
  translate([0.7, 0.45, 0.3]) { cylinder(radius: 0.35, height: 0.8, material: diffuse(albedo: [0.2, 0.5, 0.8])) }
""",
        "shapes": lambda T: {
            "box": {"type": "cube",
                    "to_world": T().translate([-0.6, 0.55, 0]).rotate([0, 1, 0], 30).scale([0.45, 0.5, 0.45]),
                    "bsdf": {"type": "conductor", "material": "none",
                             "specular_reflectance": rgb([0.9, 0.9, 0.9])}},
            **capped_cylinder("can", [0.7, 0.45, 0.3], 0.35, 0.8, T, diffuse([0.2, 0.5, 0.8])),
        },
    },
    "glass_sphere": {
        "sdf": """
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([0.2, 0.6, 0.4]) { sphere(radius: 0.6, material: glass(ior: 1.5)) }
  translate([-0.7, 0.5, -0.8]) { box(size: 0.9, material: diffuse(albedo: [0.8, 0.6, 0.2])) }
""",
        "shapes": lambda T: {
            "ball": {"type": "sphere", "center": [0.2, 0.6, 0.4], "radius": 0.6,
                     "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}},
            "box": {"type": "cube", "to_world": T().translate([-0.7, 0.5, -0.8]).scale(0.45),
                    "bsdf": diffuse([0.8, 0.6, 0.2])},
        },
    },
    # Glass resting on a surface (docs/design/glass_contact.md): a glass block on
    # a diffuse table (a marched box floating 0.05 above the ground) and one on
    # the ground plane. sdfc's blocks touch; Mitsuba's float above (a thin air
    # gap: with coincident faces it would pick either face at random): 1e-4 on
    # the table, 3e-3 on the ground, as with 1e-4 Mitsuba 3.9.1's rays cross the
    # 2e5-wide ground rectangle (float precision) and see the sky below it
    # (measured on the block's top rows: 0.589 at 1e-4, 0.535 at 3e-3; sdfc 0.534).
    "glass_resting": {
        "sdf": """
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([-0.55, 0.25, 0]) { box(size: [1.5, 0.4, 1.2], material: diffuse(albedo: [0.7, 0.55, 0.35])) }
  translate([-0.55, 0.8, 0]) {
    rotate(axis: [0, 1, 0], degrees: 25) { box(size: 0.7, material: glass(ior: 1.5)) }
  }
  translate([0.95, 0.3, 0.2]) {
    rotate(axis: [0, 1, 0], degrees: -20) { box(size: 0.6, material: glass(ior: 1.5)) }
  }
""",
        "shapes": lambda T: {
            "table": {"type": "cube", "to_world": T().translate([-0.55, 0.25, 0]).scale([0.75, 0.2, 0.6]),
                      "bsdf": diffuse([0.7, 0.55, 0.35])},
            "on_table": {"type": "cube",
                         "to_world": T().translate([-0.55, 0.8 + 1e-4, 0]).rotate([0, 1, 0], 25).scale(0.35),
                         "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}},
            "on_ground": {"type": "cube",
                          "to_world": T().translate([0.95, 0.3 + 3e-3, 0.2]).rotate([0, 1, 0], -20).scale(0.3),
                          "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}},
        },
    },
}


def rgb(v):
    return {"type": "rgb", "value": v}


def diffuse(albedo):
    return {"type": "diffuse", "reflectance": rgb(albedo)}


def capped_cylinder(name, center, radius, height, T, bsdf):
    """sdfc's cylinder (axis y, full height, centred) as Mitsuba's open tube
    plus two disks facing outward (Mitsuba's diffuse is one-sided)."""
    x, y, z = center
    h = height / 2
    return {
        name: {"type": "cylinder", "p0": [x, y - h, z], "p1": [x, y + h, z], "radius": radius, "bsdf": bsdf},
        name + "_top": {"type": "disk", "to_world": T().translate([x, y + h, z]).rotate([1, 0, 0], -90).scale(radius),
                        "bsdf": bsdf},
        name + "_bottom": {"type": "disk", "to_world": T().translate([x, y - h, z]).rotate([1, 0, 0], 90).scale(radius),
                           "bsdf": bsdf},
    }


def sdf_source(name, w, h, spp, bounces):
    c = CAMERA
    return (f"render(size: [{w}, {h}], spp: {spp}, bounces: {bounces})\n"
            f"camera(position: {c['position']}, target: {c['target']}, fov: {c['fov']})\n"
            "sky(color: [1, 1, 1])\nscene {" + SCENES[name]["sdf"] + "}\n")


def read_pfm(path):
    with open(path, "rb") as f:
        f.readline()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1]


def render_sdfc(sdfc, scene_path, seed, out, flags=()):
    """Image, wall time of the whole process, and the render loop's own time."""
    start = time.perf_counter()
    # Undenoised: the mean radiance of the samples themselves.
    run = subprocess.run([sdfc, "render", scene_path, "-o", out, "--seed", str(seed), "--denoise", "none", *flags],
                         check=True, capture_output=True, text=True)
    wall = time.perf_counter() - start
    # "(N spp in X s, R spp/s)": N / R has more digits than X.
    m = re.search(r"\(([0-9]+) spp in [0-9.]+s, ([0-9.e+-]+) spp/s\)", run.stderr)
    return read_pfm(out), wall, int(m.group(1)) / float(m.group(2)) if m else wall


def render_mitsuba(name, w, h, spp, bounces, seed, sampler="independent"):
    """Image, wall time of scene build + render, and the render's own time."""
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    from mitsuba import ScalarTransform4f as T
    c = CAMERA
    start = time.perf_counter()
    scene = mi.load_dict({
        "type": "scene",
        # Path length: sdfc's `bounces` counts scattering events; Mitsuba's
        # max_depth counts segments, so B bounces = max_depth B + 1.
        "integrator": {"type": "path", "max_depth": bounces + 1},
        "sensor": {
            "type": "perspective", "fov": c["fov"], "fov_axis": "y",
            # The default far clip (1e4) drops the ground within 0.02 pixel of
            # the horizon: measured as 1.6% more sky in the horizon row.
            "far_clip": 1e9,
            "to_world": T().look_at(origin=c["position"], target=c["target"], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}},
            "sampler": {"type": sampler, "sample_count": spp, "seed": seed},
        },
        "sky": {"type": "constant", "radiance": rgb([1, 1, 1])},
        # The infinite plane as a rectangle 2e5 on a side.
        "ground": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90).scale(1e5),
                   "bsdf": diffuse([0.5, 0.5, 0.5])},
        **SCENES[name]["shapes"](T),
    })
    render_start = time.perf_counter()
    image = np.array(mi.render(scene, spp=spp, seed=seed))[:, :, :3]
    end = time.perf_counter()
    return image, end - start, end - render_start


def mean_and_error(a, b):
    """Mean radiance of two independent renders and the standard error of
    that mean, from their difference (pixels are independent estimates)."""
    mean = 0.5 * (a.mean(axis=(0, 1)) + b.mean(axis=(0, 1)))
    diff = (a - b).reshape(-1, 3)
    # std(a - b) / sqrt(2): one render's per-pixel noise; / sqrt(2): two renders;
    # / sqrt(pixels): the image mean.
    se = diff.std(axis=0) / np.sqrt(2) / np.sqrt(2) / np.sqrt(diff.shape[0])
    return mean, se


def noise_rmse(a, b):
    """RMSE of one render against the converged image, from two independent
    renders (valid for unbiased estimators: `check` shows both are)."""
    return float(np.sqrt(np.mean((a - b) ** 2) / 2))


def sdfc_pair(sdfc, name, w, h, spp, bounces, tmp, flags=()):
    path = os.path.join(tmp, f"{name}.sdf")
    with open(path, "w") as f:
        f.write(sdf_source(name, w, h, spp, bounces))
    r1 = render_sdfc(sdfc, path, 1, os.path.join(tmp, "s1.pfm"), flags)
    r2 = render_sdfc(sdfc, path, 2, os.path.join(tmp, "s2.pfm"), flags)
    return r1, r2


def z_scores(ms, ses, mm, sem):
    return np.abs(ms - mm) / np.sqrt(ses ** 2 + sem ** 2)


def report_agreement(name, ms, ses, mm, sem, what="Mitsuba"):
    z = z_scores(ms, ses, mm, sem)
    fmt = lambda v: np.array2string(np.asarray(v), precision=6)
    print(f"{name}: sdfc {fmt(ms)} +- {fmt(ses)}")
    print(f"{' ' * len(name)}  {what} {fmt(mm)} +- {fmt(sem)}")
    print(f"{' ' * len(name)}  difference {fmt((ms - mm) / mm * 100)} %, {fmt(z)} standard errors")
    return z


def cmd_check(args):
    w, h = args.width, args.height
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            (s1, ts, _), (s2, _, _) = sdfc_pair(args.sdfc, name, w, h, args.spp, args.bounces, tmp)
            m1, tm, _ = render_mitsuba(name, w, h, args.spp, args.bounces, 1)
            m2, _, _ = render_mitsuba(name, w, h, args.spp, args.bounces, 2)
            ms, ses = mean_and_error(s1, s2)
            mm, sem = mean_and_error(m1, m2)
            z = report_agreement(name, ms, ses, mm, sem)
            print(f"{' ' * len(name)}  wall time per render at {args.spp} spp: sdfc {ts:.2f} s, Mitsuba {tm:.2f} s")
            worst = max(worst, float(z.max()))
    ok = worst < 4
    print("agree within 4 standard errors" if ok else "DISAGREE: a bug to find")
    return 0 if ok else 1


def scene_key(name, w, h, bounces):
    text = sdf_source(name, w, h, 0, bounces)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def cmd_reference(args):
    """Mitsuba's mean radiance at high spp, stored for `test`."""
    import mitsuba as mi
    data = {"mitsuba": mi.__version__, "variant": "scalar_rgb", "spp": args.spp,
            "width": args.width, "height": args.height, "bounces": args.bounces, "scenes": {}}
    for name in args.scenes:
        m1, t1, _ = render_mitsuba(name, args.width, args.height, args.spp, args.bounces, 1)
        m2, _, _ = render_mitsuba(name, args.width, args.height, args.spp, args.bounces, 2)
        mean, se = mean_and_error(m1, m2)
        data["scenes"][name] = {"key": scene_key(name, args.width, args.height, args.bounces),
                                "mean": mean.tolist(), "standard_error": se.tolist()}
        print(f"{name}: {mean} +- {se} ({t1:.1f} s per render)")
    with open(args.reference, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    print("wrote", args.reference)
    return 0


def cmd_test(args):
    """sdfc against the stored Mitsuba reference: within 4 combined s.e."""
    with open(args.reference) as f:
        ref = json.load(f)
    w, h, bounces = ref["width"], ref["height"], ref["bounces"]
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name, r in ref["scenes"].items():
            if r["key"] != scene_key(name, w, h, bounces):
                print(f"{name}: the scene changed since the reference was rendered; "
                      f"run `{sys.argv[0]} reference`")
                failures += 1
                continue
            (s1, _, _), (s2, _, _) = sdfc_pair(args.sdfc, name, w, h, args.spp, bounces, tmp)
            ms, ses = mean_and_error(s1, s2)
            z = report_agreement(name, ms, ses, np.array(r["mean"]), np.array(r["standard_error"]),
                                 f"Mitsuba {ref['mitsuba']} ({ref['spp']} spp)")
            # A bias shows as a shift in every channel; 4 s.e. in one of 9
            # channel tests happens by chance about 5e-4 of the time.
            if z.max() >= 4:
                failures += 1
    print("agree within 4 standard errors" if not failures else f"DISAGREE on {failures} scene(s)")
    return 1 if failures else 0


def cmd_efficiency(args):
    """Equal-error wall time: both renderers at several spp, noise RMSE from two
    seeds, time to reach the error Mitsuba reaches at its largest spp."""
    w, h = args.width, args.height
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            pts = {"sdfc": [], "sdfc render": [], "Mitsuba": [], "Mitsuba render": []}
            for spp in args.spp_list:
                (s1, ws1, rs1), (s2, ws2, rs2) = sdfc_pair(args.sdfc, name, w, h, spp, args.bounces, tmp)
                e = noise_rmse(s1, s2)
                pts["sdfc"].append((min(ws1, ws2), e))
                pts["sdfc render"].append((min(rs1, rs2), e))
                m1, wm1, rm1 = render_mitsuba(name, w, h, spp, args.bounces, 1, args.mitsuba_sampler)
                m2, wm2, rm2 = render_mitsuba(name, w, h, spp, args.bounces, 2, args.mitsuba_sampler)
                e = noise_rmse(m1, m2)
                pts["Mitsuba"].append((min(wm1, wm2), e))
                pts["Mitsuba render"].append((min(rm1, rm2), e))
                print(f"{name} {spp:5d} spp: sdfc RMSE {pts['sdfc'][-1][1]:.4f} in {pts['sdfc'][-1][0]:.2f} s "
                      f"(render {pts['sdfc render'][-1][0]:.2f} s); Mitsuba RMSE {e:.4f} in "
                      f"{pts['Mitsuba'][-1][0]:.2f} s (render {pts['Mitsuba render'][-1][0]:.2f} s)", flush=True)
            # Agreement at the largest spp, from the same four renders.
            ms, ses = mean_and_error(s1, s2)
            mm, sem = mean_and_error(m1, m2)
            z = z_scores(ms, ses, mm, sem)
            target = pts["Mitsuba"][-1][1]
            t = {k: sb.time_to_error(v, target)[0] or float("nan") for k, v in pts.items()}
            rows.append({"scene": name, "target_rmse": target, **{f"time {k}": v for k, v in t.items()},
                         "ratio": t["sdfc"] / t["Mitsuba"],
                         "mean_diff_percent": float(np.max(np.abs(ms - mm) / mm) * 100),
                         "z_max": float(z.max()),
                         "ratio render": t["sdfc render"] / t["Mitsuba render"]})
    print(f"\nequal-error wall time, {w}x{h}, {args.bounces} bounces, Mitsuba sampler {args.mitsuba_sampler}, "
          f"target = Mitsuba's RMSE at {args.spp_list[-1]} spp (sdfc / Mitsuba; below 1 = sdfc faster)")
    print(f"{'scene':22s} {'target':>8s} {'sdfc s':>8s} {'Mitsuba s':>10s} {'ratio':>6s} {'render only':>12s} "
          f"{'mean diff':>10s} {'s.e.':>5s}")
    for r in rows:
        print(f"{r['scene']:22s} {r['target_rmse']:8.4f} {r['time sdfc']:8.2f} {r['time Mitsuba']:10.2f} "
              f"{r['ratio']:6.2f} {r['ratio render']:12.2f} {r['mean_diff_percent']:9.4f}% {r['z_max']:5.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"width": w, "height": h, "bounces": args.bounces, "spp": args.spp_list,
                       "mitsuba_sampler": args.mitsuba_sampler, "threads": os.cpu_count(),
                       "rows": rows}, f, indent=1)
    return 0


# The environment-lit scene: a diffuse sphere, a rough metal box and the
# ground under the procedural studio map (tools/envmap.py), turned 30 degrees.
ENV_SDF = """
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([-0.55, 0.5, 0]) { sphere(radius: 0.5, material: diffuse(albedo: [0.8, 0.3, 0.25])) }
  translate([0.6, 0.4, -0.2]) { sphere(radius: 0.4, material: diffuse(albedo: [0.3, 0.6, 0.8])) }
"""
ENV_ROTATION = 30
ENV_WIDTH = 128


def render_mitsuba_env(map_path, w, h, spp, bounces, seed, with_shapes):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    from mitsuba import ScalarTransform4f as T
    c = CAMERA
    shapes = {}
    if with_shapes:
        shapes = {"ground": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90).scale(1e5),
                             "bsdf": diffuse([0.5, 0.5, 0.5])},
                  "a": {"type": "sphere", "center": [-0.55, 0.5, 0], "radius": 0.5, "bsdf": diffuse([0.8, 0.3, 0.25])},
                  "b": {"type": "sphere", "center": [0.6, 0.4, -0.2], "radius": 0.4, "bsdf": diffuse([0.3, 0.6, 0.8])}}
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": bounces + 1},
        "sensor": {"type": "perspective", "fov": c["fov"], "fov_axis": "y", "far_clip": 1e9,
                   "to_world": T().look_at(origin=c["position"], target=c["target"], up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": spp, "seed": seed}},
        "sky": {"type": "envmap", "filename": map_path, "to_world": T().rotate([0, 1, 0], ENV_ROTATION)},
        **shapes,
    })
    return np.array(mi.render(scene, spp=spp, seed=seed))[:, :, :3]


def cmd_envmap(args):
    sys.path.insert(0, os.path.join(HERE, "..", "tools"))
    import envmap
    w, h = args.width, args.height
    c = CAMERA
    ok = True
    with tempfile.TemporaryDirectory(prefix="sdfc envmap check ") as tmp:
        map_path = os.path.join(tmp, "studio.exr")
        envmap.write_exr(map_path, envmap.studio(ENV_WIDTH))
        for label, shapes, bounces in [("the map seen directly", "translate([0, -1000, 0]) { sphere(radius: 0.01) }", 0),
                                       ("the lit scene", ENV_SDF, args.bounces)]:
            path = os.path.join(tmp, "scene.sdf")
            with open(path, "w") as f:
                f.write(f"render(size: [{w}, {h}], spp: {args.spp}, bounces: {bounces})\n"
                        f"camera(position: {c['position']}, target: {c['target']}, fov: {c['fov']})\n"
                        f'sky(map: "studio.exr", rotation: {ENV_ROTATION})\nscene {{' + shapes + "}\n")
            s, ts, _ = render_sdfc(args.sdfc, path, 1, os.path.join(tmp, "s.pfm"))
            start = time.perf_counter()
            m = render_mitsuba_env(map_path, w, h, args.mitsuba_spp, bounces, 1, bounces > 0)
            tm = time.perf_counter() - start
            mean = float(s.mean() / m.mean() - 1)
            by, bx = h // 4, w // 4  # 16 blocks
            bs = s[:by * 4, :bx * 4].reshape(4, by, 4, bx, 3).mean(axis=(1, 3, 4))
            bm = m[:by * 4, :bx * 4].reshape(4, by, 4, bx, 3).mean(axis=(1, 3, 4))
            block = float(np.abs(bs / bm - 1).max())
            good = abs(mean) < 0.01 and block < 0.03
            ok = ok and good
            print(f"{label}: sdfc ({args.spp} spp, {ts:.1f} s) / Mitsuba ({args.mitsuba_spp} spp, {tm:.1f} s): "
                  f"mean {100 * mean:+.2f}% (within 1%), worst of 16 blocks {100 * block:.2f}% (within 3%) "
                  f"{'ok' if good else 'FAIL'}")
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", nargs="?", default="check", choices=["check", "reference", "test", "efficiency", "envmap"])
    ap.add_argument("--sdfc", default=os.path.join(HERE, "..", "build", "cli", "sdfc"))
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=None,
                    help="check: 256; reference: 8192 (Mitsuba); test: 512 (sdfc)")
    ap.add_argument("--spp-list", default="16,64,256", help="efficiency: sample counts")
    ap.add_argument("--bounces", type=int, default=3)
    ap.add_argument("--mitsuba-spp", type=int, default=1024, help="envmap: Mitsuba's samples per pixel")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--reference", default=REFERENCE_JSON)
    ap.add_argument("--json", default=None, help="efficiency: write the table here")
    ap.add_argument("--mitsuba-sampler", default="independent",
                    help="efficiency: Mitsuba's sampler (independent, multijitter, ldsampler, ...)")
    args = ap.parse_args()
    args.width, args.height = map(int, args.size.split("x"))
    args.scenes = args.scenes.split(",")
    args.spp_list = [int(s) for s in args.spp_list.split(",")]
    if args.spp is None:
        args.spp = {"check": 256, "reference": 8192, "test": 512}.get(args.command, 256)
    return {"check": cmd_check, "reference": cmd_reference, "test": cmd_test,
            "efficiency": cmd_efficiency, "envmap": cmd_envmap}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
