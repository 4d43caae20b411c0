#!/usr/bin/env python3
"""Menger sponge of level 5: sdfc against Mitsuba 3 with the sponge as a mesh.

The benchmark target: "On a Menger sponge of level 5 (3.2 million cubes as a
mesh for Mitsuba): memory at most 1/100 of Mitsuba's, time at most
Mitsuba's." sdfc draws the sponge from its distance function (`menger`, a few
dozen lines of GLSL); Mitsuba 3 (PyPI `mitsuba`, variant scalar_rgb) gets the
naive mesh the target describes: 20^level cubes, each an independent closed
box of 12 triangles (8 vertices), in a binary PLY.

Scene (both renderers): a diffuse sponge of side 1 resting on a diffuse
ground under a uniform white sky, a pinhole camera, the same image size, spp
and path length, set up as in bench/mitsuba_check.py. Each renderer runs in
its own process under /usr/bin/time, so peak resident memory is its own.

Measured: scene load/build (sdfc: SPIR-V compile + pipeline creation;
Mitsuba: PLY load + acceleration structure), render time, wall time to one
image, peak RSS, the scene's own size (SPIR-V bytes; PLY bytes and
triangles), and mean radiance of two seeds per renderer against the
standard error from their difference. Before rendering, the mesh is checked
against sdfc's own float64 distance (`sdfc eval`) at random points.

    /usr/bin/python3 bench/mitsuba_menger.py [--sdfc build/cli/sdfc] [--level 5] [--spp 16]

Writes bench/results/MENGER_MITSUBA.md (unless --no-report). The full run takes
about 6-8 minutes on the 2-CPU lavapipe machine, most of it Mitsuba's
acceleration structure build over 38.4 M triangles.
"""
import argparse
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sdfbench as sb  # noqa: E402
from mitsuba_check import mean_and_error, read_pfm  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))

# Camera, materials and sky shared by both renderers.
CAMERA = {"origin": [1.55, 1.25, 2.1], "target": [0.0, 0.45, 0.0], "fov": 40.0}
GROUND_ALBEDO = [0.5, 0.5, 0.5]
SPONGE_ALBEDO = [0.8, 0.3, 0.25]
SPONGE_SIZE = 1.0  # side of the sponge's cube; it rests on y = 0, centred on the y axis

SCENE = """render(size: [{w}, {h}], spp: {spp}, bounces: {bounces})
camera(position: [{cam[0]}, {cam[1]}, {cam[2]}], target: [{tgt[0]}, {tgt[1]}, {tgt[2]}], fov: {fov})
sky(color: [1, 1, 1])
scene {{
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [{g[0]}, {g[1]}, {g[2]}]))
  translate([0, {half}, 0]) {{
    menger(level: {level}, size: {size}, material: diffuse(albedo: [{s[0]}, {s[1]}, {s[2]}]))
  }}
}}
"""


def scene_text(level, w, h, spp, bounces, sponge=True, ground=True):
    text = SCENE.format(w=w, h=h, spp=spp, bounces=bounces, cam=CAMERA["origin"],
                        tgt=CAMERA["target"], fov=CAMERA["fov"], g=GROUND_ALBEDO,
                        s=SPONGE_ALBEDO, half=SPONGE_SIZE / 2, size=SPONGE_SIZE, level=level)
    if not sponge:
        text = re.sub(r"  translate\(.*?\n  }\n", "", text, flags=re.S)
    if not ground:
        text = re.sub(r"  plane\(.*?\n", "", text)
    return text


# --------------------------------------------------------------------------
# The sponge as cubes. sdfc's `menger(level, size)` (compiler/shapes/
# primitives.cpp) is the cube [-size/2, size/2]^3 minus, for k = 0..level-1,
# the infinite cross of square bars centred in every cell of side size/3^k
# (cells aligned with the cube's corner), each bar a third of the cell wide.
# A point is in a bar of level k when at least two of its three base-3 digits
# number k are 1, so the solid is the union of the cells of side size/3^level
# whose index triples have, at every digit position, at most one digit 1:
# 20^level cubes.

def sponge_cells(level):
    """Integer indices (n, 3) of the kept cells of side size/3^level."""
    digits = np.array([(i, j, k) for i in range(3) for j in range(3) for k in range(3)], np.int32)
    keep = digits[(digits == 1).sum(axis=1) < 2]  # the 20 sub-cubes of one step
    cells = np.zeros((1, 3), np.int32)
    for _ in range(level):
        cells = (cells[:, None, :] * 3 + keep[None, :, :]).reshape(-1, 3)
    return cells


def occupancy(level):
    """Boolean grid 3^level per axis: True where a kept cell is."""
    n = 3 ** level
    grid = np.zeros((n, n, n), bool)
    c = sponge_cells(level)
    grid[c[:, 0], c[:, 1], c[:, 2]] = True
    return grid


# Corner k of a unit cube is (k>>2 & 1, k>>1 & 1, k & 1); two triangles per
# face, counter-clockwise seen from outside (Mitsuba's face normal is
# cross(p1 - p0, p2 - p0), and its diffuse BSDF is black from behind).
CORNERS = np.array([((k >> 2) & 1, (k >> 1) & 1, k & 1) for k in range(8)], np.int64)
QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
CUBE_TRIANGLES = np.array([t for a, b, c, d in QUADS for t in ((a, b, c), (a, c, d))], np.uint32)


def check_winding():
    """Every triangle's normal points away from the unit cube's centre."""
    p = CORNERS[CUBE_TRIANGLES].astype(float)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return bool(np.all(np.einsum("ij,ij->i", n, p.mean(axis=1) - 0.5) > 0))


def write_ply(path, level):
    """Writes the sponge as 20^level independent boxes; returns (bytes, vertices, triangles)."""
    cells = sponge_cells(level).astype(np.int64)
    n = len(cells)
    cell = SPONGE_SIZE / 3 ** level
    # Vertices from integer grid coordinates, so that neighbouring boxes
    # share bit-identical corner positions (no cracks between them).
    grid = (cells[:, None, :] + CORNERS[None, :, :]).reshape(-1, 3)
    verts = (grid * cell - SPONGE_SIZE / 2).astype("<f4")
    verts[:, 1] += np.float32(SPONGE_SIZE / 2)
    # Indices as `uint`: Mitsuba 3.9.1's PLY loader converts `int` indices
    # through float32, so above 2^24 (16.8 M vertices; level 5 has 25.6 M)
    # they are rounded and the boxes' triangles join the wrong corners.
    faces = np.empty(n * 12, dtype=[("n", "u1"), ("i", "<u4", (3,))])
    faces["n"] = 3
    faces["i"] = (CUBE_TRIANGLES[None] + 8 * np.arange(n, dtype=np.uint32)[:, None, None]).reshape(-1, 3)
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"comment Menger sponge level {level}: {n} boxes of 12 triangles\n"
              f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar uint vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        verts.tofile(f)
        faces.tofile(f)
    return os.path.getsize(path), len(verts), len(faces)


def check_against_sdfc(sdfc, scene_path, level, points=20000, seed=7):
    """Signs of sdfc's float64 distance (`sdfc eval`) against the mesh's
    occupancy: at the centres of random cells of side size/3^level (kept and
    removed alike), and at random points in a box 4% larger than the sponge,
    away from cell faces. Returns (points tested, disagreements, kept
    cell centres among them)."""
    rng = np.random.default_rng(seed)
    grid = occupancy(level)
    n = 3 ** level
    cell = SPONGE_SIZE / n
    centres_idx = rng.integers(0, n, size=(points, 3))
    centres = (centres_idx + 0.5) * cell - SPONGE_SIZE / 2
    inside_c = grid[centres_idx[:, 0], centres_idx[:, 1], centres_idx[:, 2]]
    p = rng.uniform(-0.52, 0.52, size=(points, 3)) * SPONGE_SIZE
    u = (p + SPONGE_SIZE / 2) / cell
    away = np.all(np.abs(u - np.round(u)) > 1e-3, axis=1)
    p = p[away]
    idx = np.floor((p + SPONGE_SIZE / 2) / cell).astype(int)
    in_box = np.all((idx >= 0) & (idx < n), axis=1)
    inside_p = np.zeros(len(p), bool)
    ib = idx[in_box]
    inside_p[in_box] = grid[ib[:, 0], ib[:, 1], ib[:, 2]]
    pts = np.concatenate([centres, p])
    inside = np.concatenate([inside_c, inside_p])
    pts[:, 1] += SPONGE_SIZE / 2  # the scene's translate (the scene here has no ground)
    text = "\n".join(f"{x!r} {y!r} {z!r}" for x, y, z in pts) + "\n"
    out = subprocess.run([sdfc, "eval", scene_path], input=text, capture_output=True, text=True,
                         check=True).stdout.split()
    d = np.array([float(v) for v in out])
    wrong = int(np.sum((d < 0) != inside))
    return len(pts), wrong, int(inside_c.sum())


# --------------------------------------------------------------------------
# Workers, each run in its own process.

def worker_mesh(args):
    t0 = time.perf_counter()
    size, nv, nt = write_ply(args.ply, args.level)
    t1 = time.perf_counter()
    tested, wrong, kept = check_against_sdfc(args.sdfc, args.scene, args.level)
    print(json.dumps({"ply_bytes": size, "vertices": nv, "triangles": nt, "write_s": t1 - t0,
                      "winding_ok": check_winding(), "eval_points": tested,
                      "eval_wrong": wrong, "eval_kept_centres": kept,
                      "eval_s": time.perf_counter() - t1}))


def mitsuba_scene(mi, w, h, spp, ply):
    from mitsuba import ScalarTransform4f as T
    scene = {
        "type": "scene",
        "sensor": {
            "type": "perspective", "fov": CAMERA["fov"], "fov_axis": "y", "far_clip": 1e9,
            "to_world": T().look_at(origin=CAMERA["origin"], target=CAMERA["target"], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}},
        "ground": {
            "type": "rectangle",
            # 2e5 on a side, as in bench/mitsuba_check.py. Its edge leaves a
            # sliver of sky in the horizon row (at 256 spp, bounces 0: the
            # whole sky-share gap, -6 s.e., is that row; 0 elsewhere). At 2e7
            # the horizon agrees (0.9 s.e.) but the 3-bounce mean drops 1.7%
            # (float32 precision of the huge rectangle's hit points).
            "to_world": T().rotate([1, 0, 0], -90).scale(1e5),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": GROUND_ALBEDO}},
        },
    }
    if ply:
        # face_normals: flat boxes (without it Mitsuba would smooth the
        # normals over each box's 8 shared corners).
        scene["sponge"] = {"type": "ply", "filename": ply, "face_normals": True,
                           "bsdf": {"type": "diffuse",
                                    "reflectance": {"type": "rgb", "value": SPONGE_ALBEDO}}}
    return scene


def worker_mitsuba(args):
    t0 = time.perf_counter()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    t1 = time.perf_counter()
    w, h = map(int, args.size.split("x"))
    scene = mi.load_dict(mitsuba_scene(mi, w, h, args.spp, args.ply))
    t2 = time.perf_counter()
    result = {"import_s": t1 - t0, "load_s": t2 - t1, "renders": []}
    for bounces in args.bounce_list:
        # sdfc's `bounces` counts scattering events, Mitsuba's max_depth path segments.
        integrator = mi.load_dict({"type": "path", "max_depth": bounces + 1})
        for seed in args.seeds:
            start = time.perf_counter()
            image = np.array(mi.render(scene, integrator=integrator, spp=args.spp, seed=seed))[:, :, :3]
            dt = time.perf_counter() - start
            out = os.path.join(args.out_dir, f"mitsuba_b{bounces}_s{seed}.npy")
            np.save(out, image)
            result["renders"].append({"bounces": bounces, "seed": seed, "render_s": dt, "image": out})
    result["process_s"] = time.perf_counter() - t0
    print(json.dumps(result))


# --------------------------------------------------------------------------
# Driver.

def timed(cmd, **kw):
    """Runs cmd under /usr/bin/time; returns (CompletedProcess, wall s, peak RSS bytes)."""
    fd, tfile = tempfile.mkstemp(suffix=".time")
    os.close(fd)
    start = time.perf_counter()
    proc = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", tfile, *cmd], capture_output=True,
                          text=True, **kw)
    wall = time.perf_counter() - start
    with open(tfile) as f:
        lines = [line for line in f.read().split() if line.isdigit()]
    os.unlink(tfile)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout + proc.stderr)
        raise SystemExit(f"failed ({proc.returncode}): {' '.join(cmd)}")
    return proc, wall, int(lines[-1]) * 1024 if lines else 0


def sdfc_render(sdfc, scene_path, out, seed, spp, bounces):
    proc, wall, rss = timed([sdfc, "render", scene_path, "-o", out, "--seed", str(seed),
                             "--spp", str(spp), "--bounces", str(bounces), "--denoise", "none"])
    err = proc.stderr
    m = re.search(r"compiled in (\d+) ms.*?pipeline in (\d+) ms", err)
    r = re.search(r"\((\d+) spp in ([0-9.]+)s", err)
    return {"seed": seed, "bounces": bounces, "wall_s": wall, "rss": rss,
            "compile_s": int(m.group(1)) / 1000 if m else float("nan"),
            "pipeline_s": int(m.group(2)) / 1000 if m else float("nan"),
            "render_s": float(r.group(2)) if r else float("nan"), "image": read_pfm(out)}


def machine_info():
    """sdfbench's machine line plus the RAM."""
    info = sb.machine_info()
    info["mem"] = "?"
    try:
        with open("/proc/meminfo") as f:
            kb = int(f.readline().split()[1])
        info["mem"] = f"{kb / 2**20:.0f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    return info


def gib(b):
    return f"{b / 2**30:.2f} GiB" if b >= 2**30 else f"{b / 2**20:.0f} MiB"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sdfc", default=os.path.join(HERE, "..", "build", "cli", "sdfc"))
    ap.add_argument("--level", type=int, default=5)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=3)
    ap.add_argument("--no-visibility", action="store_true",
                    help="skip the 0-bounce (pure visibility) comparison")
    ap.add_argument("--keep", metavar="DIR", help="keep the PLY, scenes and images in DIR")
    ap.add_argument("--no-report", action="store_true", help="do not write bench/results/MENGER_MITSUBA.md")
    ap.add_argument("--report", default=os.path.join(HERE, "results", "MENGER_MITSUBA.md"))
    # Internal: the worker processes.
    ap.add_argument("--worker", choices=["mesh", "mitsuba"], help=argparse.SUPPRESS)
    ap.add_argument("--ply", help=argparse.SUPPRESS)
    ap.add_argument("--scene", help=argparse.SUPPRESS)
    ap.add_argument("--out-dir", help=argparse.SUPPRESS)
    ap.add_argument("--seeds", type=int, nargs="*", default=[1, 2], help=argparse.SUPPRESS)
    ap.add_argument("--bounce-list", type=int, nargs="*", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker == "mesh":
        return worker_mesh(args)
    if args.worker == "mitsuba":
        return worker_mitsuba(args)

    t_start = time.perf_counter()
    sdfc = os.path.abspath(args.sdfc)
    w, h = map(int, args.size.split("x"))
    bounce_list = [args.bounces] + ([] if args.no_visibility or args.bounces == 0 else [0])
    tmp = args.keep or tempfile.mkdtemp(prefix="menger_")
    os.makedirs(tmp, exist_ok=True)
    need = 0.3 * 20 ** args.level * 8 * 12 + 13 * 20 ** args.level * 12  # PLY bytes, roughly
    free = shutil.disk_usage(tmp).free
    if free < 2 * need:
        raise SystemExit(f"{tmp}: {gib(free)} free, the PLY needs about {gib(need)}")
    try:
        scene_path = os.path.join(tmp, "menger.sdf")
        with open(scene_path, "w") as f:
            f.write(scene_text(args.level, w, h, args.spp, args.bounces))
        ply = os.path.join(tmp, "menger.ply")
        me = sys.executable
        script = os.path.abspath(__file__)

        # The mesh, checked against sdfc's distance function (of the sponge alone).
        check_scene = os.path.join(tmp, "sponge_only.sdf")
        with open(check_scene, "w") as f:
            f.write(scene_text(args.level, w, h, args.spp, args.bounces, ground=False))
        print(f"writing the level-{args.level} sponge as {20 ** args.level} boxes ...", flush=True)
        proc, _, _ = timed([me, script, "--worker", "mesh", "--level", str(args.level), "--ply", ply,
                            "--scene", check_scene, "--sdfc", sdfc])
        mesh = json.loads(proc.stdout.strip().splitlines()[-1])
        print(f"  {mesh['triangles']} triangles, {gib(mesh['ply_bytes'])} PLY in {mesh['write_s']:.1f} s; "
              f"sdfc eval at {mesh['eval_points']} points: {mesh['eval_wrong']} disagree, "
              f"winding {'outward' if mesh['winding_ok'] else 'WRONG'}", flush=True)

        # sdfc: the SPIR-V, then renders (compile + pipeline are in each render).
        spv = os.path.join(tmp, "menger.spv")
        proc, _, _ = timed([sdfc, "compile", scene_path, "--emit", "spv", "-o", spv, "--timings", "3"])
        spv_bytes = os.path.getsize(spv)
        tm = re.search(r"total ([0-9.]+) ms", proc.stdout + proc.stderr)
        compile_median_s = float(tm.group(1)) / 1000 if tm else float("nan")
        print(f"sdfc: SPIR-V {spv_bytes} bytes, compile {compile_median_s * 1000:.0f} ms (median)", flush=True)
        sd = {}
        for b in bounce_list:
            for seed in (1, 2):
                sd[b, seed] = sdfc_render(sdfc, scene_path, os.path.join(tmp, f"sdfc_b{b}_s{seed}.pfm"),
                                          seed, args.spp, b)
                r = sd[b, seed]
                print(f"  bounces {b} seed {seed}: compile {r['compile_s']:.2f} s, pipeline "
                      f"{r['pipeline_s']:.2f} s, render {r['render_s']:.2f} s, wall {r['wall_s']:.2f} s, "
                      f"peak RSS {gib(r['rss'])}", flush=True)

        # Mitsuba: one process loads the mesh once and renders every image.
        print(f"Mitsuba: loading {mesh['triangles']} triangles and rendering ...", flush=True)
        proc, mi_wall, mi_rss = timed([me, script, "--worker", "mitsuba", "--ply", ply, "--size", args.size,
                                       "--spp", str(args.spp), "--out-dir", tmp, "--seeds", "1", "2",
                                       "--bounce-list", *map(str, bounce_list)])
        mires = json.loads(proc.stdout.strip().splitlines()[-1])
        mi_img = {(r["bounces"], r["seed"]): np.load(r["image"]) for r in mires["renders"]}
        mi_render = {(r["bounces"], r["seed"]): r["render_s"] for r in mires["renders"]}
        # Wall time to one image: the process minus the renders it did after the first.
        mi_one = mi_wall - (sum(mi_render.values()) - mi_render[args.bounces, 1])
        print(f"  import {mires['import_s']:.1f} s, load + build {mires['load_s']:.1f} s, render "
              + ", ".join(f"b{b}/s{s} {t:.1f} s" for (b, s), t in mi_render.items())
              + f", peak RSS {gib(mi_rss)}", flush=True)

        # Fixed costs: the same scene without the sponge, 1 spp.
        base_scene = os.path.join(tmp, "ground.sdf")
        with open(base_scene, "w") as f:
            f.write(scene_text(args.level, w, h, 1, args.bounces, sponge=False))
        sd_base = sdfc_render(sdfc, base_scene, os.path.join(tmp, "ground.pfm"), 1, 1, args.bounces)
        base_dir = os.path.join(tmp, "ground_only")
        os.makedirs(base_dir, exist_ok=True)
        _, _, mi_base_rss = timed([me, script, "--worker", "mitsuba", "--size", args.size, "--spp", "1",
                                   "--out-dir", base_dir, "--seeds", "1", "--bounce-list", str(args.bounces)])
    finally:
        if not args.keep:
            shutil.rmtree(tmp, ignore_errors=True)

    # Agreement.
    agree = {}
    for b in bounce_list:
        ms, ses = mean_and_error(sd[b, 1]["image"], sd[b, 2]["image"])
        mm, sem = mean_and_error(mi_img[b, 1], mi_img[b, 2])
        z = (ms - mm) / np.sqrt(ses ** 2 + sem ** 2)
        agree[b] = (ms, ses, mm, sem, z)

    s1 = sd[args.bounces, 1]
    sd_rss = max(r["rss"] for r in sd.values())
    sd_load = s1["compile_s"] + s1["pipeline_s"]
    sd_render = min(sd[args.bounces, s]["render_s"] for s in (1, 2))
    sd_wall = s1["wall_s"]
    mi_render_min = min(mi_render[args.bounces, s] for s in (1, 2))
    total = time.perf_counter() - t_start

    rows = [
        ("scene load/build", f"{sd_load:.2f} s (compile {s1['compile_s']:.2f} + pipeline {s1['pipeline_s']:.2f})",
         f"{mires['load_s']:.1f} s (PLY + acceleration structure)", f"{mires['load_s'] / sd_load:.0f}x"),
        (f"render ({args.spp} spp, {args.bounces} bounces)", f"{sd_render:.2f} s", f"{mi_render_min:.2f} s",
         f"{mi_render_min / sd_render:.2f}x"),
        ("wall time to one image", f"{sd_wall:.2f} s", f"{mi_one:.1f} s", f"{mi_one / sd_wall:.1f}x"),
        ("peak resident memory", gib(sd_rss), gib(mi_rss), f"{mi_rss / sd_rss:.0f}x"),
        ("  same scene without sponge (1 spp)", gib(sd_base["rss"]), gib(mi_base_rss), ""),
        ("  sponge's share (difference)", gib(max(sd_rss - sd_base["rss"], 0)),
         gib(mi_rss - mi_base_rss), ""),
        ("scene size", f"{spv_bytes / 1024:.1f} KiB SPIR-V",
         f"{gib(mesh['ply_bytes'])} PLY, {mesh['triangles'] / 1e6:.1f} M triangles",
         f"{mesh['ply_bytes'] / spv_bytes:.0f}x"),
    ]
    mem_ok = sd_rss * 100 <= mi_rss
    time_ok = sd_wall <= mi_one
    verdict = [
        f"memory: sdfc {gib(sd_rss)} = 1/{mi_rss / sd_rss:.0f} of Mitsuba's {gib(mi_rss)}; "
        f"target at most 1/100: {'met' if mem_ok else 'NOT met'}",
        f"time: sdfc {sd_wall:.2f} s against Mitsuba's {mi_one:.1f} s to one image; "
        f"target at most Mitsuba's: {'met' if time_ok else 'NOT met'}",
    ]
    agree_lines = []
    for b, (ms, ses, mm, sem, z) in agree.items():
        agree_lines.append(
            f"| {b} | {np.array2string(ms, precision=5)} ± {np.array2string(ses, precision=5)} "
            f"| {np.array2string(mm, precision=5)} ± {np.array2string(sem, precision=5)} "
            f"| {np.array2string(z, precision=2)} |")
    ok = all(np.all(np.abs(a[4]) < 4) for a in agree.values()) and mesh["eval_wrong"] == 0

    print()
    print(f"{'':40s} {'sdfc':32s} {'Mitsuba 3 scalar_rgb':40s} Mitsuba/sdfc")
    for r in rows:
        print(f"{r[0]:40s} {r[1]:32s} {r[2]:40s} {r[3]}")
    for v in verdict:
        print(v)
    print("mean radiance (two seeds each), difference in standard errors:")
    for line in agree_lines:
        print("  " + line)
    print("agree within 4 standard errors" if ok else "DISAGREE beyond 4 standard errors (or mesh check failed)")
    print(f"total {total:.0f} s")

    if not args.no_report:
        info = machine_info()
        git = subprocess.run(["git", "-C", HERE, "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True).stdout.strip() or "?"
        md = [
            "# Menger sponge: sdfc against Mitsuba 3 with the sponge as a mesh",
            "",
            f"Generated by `bench/mitsuba_menger.py --level {args.level} --size {args.size} --spp {args.spp} "
            f"--bounces {args.bounces}` in {total / 60:.1f} min on "
            f"{datetime.date.today().isoformat()}. Do not edit by hand.",
            "",
            "Target: *on a Menger sponge of level 5 (3.2 million cubes as a mesh for Mitsuba): memory at "
            "most 1/100 of Mitsuba's, time at most Mitsuba's.*",
            "",
            "## Machine",
            "",
            f"- CPU: {info['cpu']}, {info['cores']} CPUs, {info['mem']} RAM",
            f"- Vulkan device: {info['device']}; driver: {info['driver']}",
            f"- LP_NUM_THREADS: {os.environ.get('LP_NUM_THREADS', 'unset (llvmpipe uses all CPUs)')}",
            f"- sdfc: `{args.sdfc}` (git {git}); Mitsuba 3 scalar_rgb (its own thread pool, all CPUs)",
            "",
            "## Scene",
            "",
            f"A diffuse Menger sponge of level {args.level} and side {SPONGE_SIZE} resting on a diffuse "
            f"ground under a uniform white sky; camera at {CAMERA['origin']} looking at "
            f"{CAMERA['target']}, vertical field of view {CAMERA['fov']:g} degrees; {w}x{h}, "
            f"{args.spp} spp, {args.bounces} bounces (Mitsuba `path`, `max_depth` {args.bounces + 1}), "
            "box pixel filter. sdfc gets `menger(level, size)`; Mitsuba gets "
            f"{20 ** args.level} independent boxes of 12 triangles in a binary PLY (`ply` plugin, "
            "`face_normals`; face indices as `uint`, since Mitsuba 3.9.1 rounds `int` "
            "indices above 2^24 through float32 and the level-5 boxes then join wrong corners), the "
            "ground as a rectangle 2e5 on a side (its far edge puts a sliver of sky into the horizon "
            "row: at bounces 0 that row is the whole difference).",
            "",
            f"Same solid: the boxes are the cells of side 1/3^{args.level} with at most one middle "
            "digit per base-3 digit position, which is how `menger` subtracts its crosses "
            "(compiler/shapes/primitives.cpp). Checked against sdfc's float64 distance "
            f"(`sdfc eval`) at {mesh['eval_points']} points (random cell centres, "
            f"{mesh['eval_kept_centres']} of them kept, and random points in a box 4% larger than "
            f"the sponge): {mesh['eval_wrong']} disagree in sign.",
            "",
            "## Figures",
            "",
            "| | sdfc | Mitsuba 3 | Mitsuba / sdfc |",
            "|---|---|---|---|",
            *[f"| {r[0].strip()} | {r[1]} | {r[2]} | {r[3]} |" for r in rows],
            "",
            *[f"- {v}" for v in verdict],
            "",
            "sdfc's load is SPIR-V compilation and pipeline creation (lavapipe compiles the shader "
            f"with LLVM); the median of 3 compiles alone is {compile_median_s * 1000:.0f} ms. "
            "Mitsuba's is `load_dict` of the PLY including its acceleration structure; its wall time "
            f"to one image is its process time ({mires['import_s']:.1f} s of it importing mitsuba) "
            "without the later renders. Peak resident memory is `/usr/bin/time`'s maximum RSS of each "
            "renderer's own process; for sdfc, the largest of its render processes. The rows "
            "without the sponge show each renderer's fixed cost (libraries, LLVM, thread pool).",
            "",
            "## Do they see the same sponge?",
            "",
            "Mean radiance over the image (RGB) of two seeds per renderer, ± the standard error from "
            "the seeds' difference (as in `bench/mitsuba_check.py`), and (sdfc - Mitsuba) in "
            "standard errors. Bounces 0 is pure visibility: a pixel is 1 where it sees the sky, 0 where it "
            "hits the sponge or the ground, so its mean is the sky's share of the image.",
            "",
            "| bounces | sdfc | Mitsuba 3 | difference (s.e.) |",
            "|---|---|---|---|",
            *agree_lines,
            "",
            "Within 4 standard errors: " + ("yes." if ok else "**no**."),
            "",
        ]
        with open(args.report, "w") as f:
            f.write("\n".join(md))
        print(f"wrote {args.report}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
