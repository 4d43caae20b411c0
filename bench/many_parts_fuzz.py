#!/usr/bin/env python3
"""Random scenes of many distinct parts in every composition a set can sit in,
each rendered and checked against the float64 evaluator (issue 46: nothing
silently wrong).

A scene (deterministic per seed) is 40 to 1,000 parts of 1 to 15 primitive
kinds (rotated, scaled, some with materials of their own given as
`union(material: m) { part }`), of varied sizes, in a ball, combined by one
form: a hard or smooth union, holes cut from a box, an intersection with a
ball, nested unions, and the union under twist, bend, round, shell, displace,
elongate, morph, a transform, a smooth ground plane, or moving with time.

Two checks per scene:
  - geometry: a 160x90 depth render through bench/many_parts.py's
    pixels_off (a hit within a pixel's footprint of the surface, no surface
    clearly before it); "off" must be 0;
  - materials (hard unions with materials of their own): the albedo view of
    the default render against `--instance-threshold 0` (the parts as inline
    code); a handful of silhouette pixels may differ.

    /usr/bin/python3 bench/many_parts_fuzz.py --seeds 0-100
    /usr/bin/python3 bench/many_parts_fuzz.py --seeds 57 --form round_twist --keep /tmp/fuzz

Prints one line a scene and a summary; exit status 1 when a scene has a pixel
off the surface (or more than --albedo-pixels albedo pixels differ).
Needs numpy (Debian's python3-numpy: run with /usr/bin/python3).
"""
import argparse
import math
import os
import random
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import many_parts as mp  # noqa: E402
import sdfbench as sb  # noqa: E402

KINDS = ["sphere", "box", "rbox", "torus", "cylinder", "cone", "capsule", "prism", "hexprism",
         "octahedron", "pyramid", "round_cone", "ellipsoid", "extrude", "revolve"]
FORMS = ["union", "union", "holes", "intersect", "nested", "twist", "transformed", "round", "shell",
         "setminus", "subtract_set", "ground", "displace", "round_twist", "bend", "elongate", "moving",
         "morph"]


def num(x):
    return f"{x:.5g}"


def vec(a):
    return "[" + ", ".join(num(x) for x in a) + "]"


def primitive(r, kind, s):
    """One primitive of size about s."""
    if kind == "sphere":
        return f"sphere(radius: {num(s)})"
    if kind == "box":
        return f"box(size: {vec([s * r.uniform(0.5, 2) for _ in range(3)])})"
    if kind == "rbox":
        a = [s * r.uniform(0.6, 2) for _ in range(3)]
        return f"box(size: {vec(a)}, rounding: {num(min(a) * 0.3)})"
    if kind == "torus":
        return f"torus(major: {num(s)}, minor: {num(s * r.uniform(0.1, 0.5))})"
    if kind == "cylinder":
        return f"cylinder(radius: {num(s * 0.6)}, height: {num(s * r.uniform(0.5, 3))})"
    if kind == "cone":
        return f"cone(radius: {num(s * 0.7)}, height: {num(s * r.uniform(0.5, 2))})"
    if kind == "capsule":
        return f"capsule(radius: {num(s * 0.4)}, height: {num(s * r.uniform(0.5, 3))})"
    if kind == "prism":
        return f"prism(size: {num(s * 1.2)}, depth: {num(s * r.uniform(0.3, 2))})"
    if kind == "hexprism":
        return f"hexprism(radius: {num(s * 0.6)}, depth: {num(s * r.uniform(0.3, 2))})"
    if kind == "octahedron":
        return f"octahedron(radius: {num(s)})"
    if kind == "pyramid":
        return f"pyramid(size: {num(s * 1.2)}, height: {num(s * r.uniform(0.5, 2))})"
    if kind == "round_cone":
        return f"round_cone(bottom: {num(s * 0.5)}, top: {num(s * 0.2)}, height: {num(s * 1.5)})"
    if kind == "ellipsoid":
        return f"ellipsoid(radii: {vec([s * r.uniform(0.4, 1.2) for _ in range(3)])})"
    if kind == "extrude":
        return f"extrude(depth: {num(s * r.uniform(0.3, 1.5))}) {{ circle(radius: {num(s * 0.6)}) }}"
    return f"revolve(offset: {num(s * 0.6)}) {{ rect(size: [{num(s * 0.3)}, {num(s * 0.8)}]) }}"


def parts(r, n, radius, kinds, materials, rotated, scaled, sizes):
    out = []
    for _ in range(n):
        s = math.exp(r.uniform(math.log(sizes[0]), math.log(sizes[1])))
        p = primitive(r, r.choice(kinds), s)
        material = r.choice(materials) if materials and r.random() < 0.6 else None
        if rotated and r.random() < 0.8:
            p = f"rotate(axis: {vec([r.gauss(0, 1) for _ in range(3)])}, degrees: {num(r.uniform(0, 180))}) {{ {p} }}"
        if scaled and r.random() < 0.5:
            p = f"scale({num(r.uniform(0.5, 1.8))}) {{ {p} }}"
        while True:
            c = [r.uniform(-radius, radius) for _ in range(3)]
            if sum(x * x for x in c) <= radius * radius:
                break
        p = f"translate({vec(c)}) {{ {p} }}"
        if material:
            p = f"union(material: {material}) {{ {p} }}"
        out.append("    " + p)
    return "\n".join(out)


def scene(seed, form=None):
    """(text, description, hard union with materials of their own) of scene `seed`."""
    r = random.Random(seed)
    n = r.choice([40, 80, 150, 400, 1000])
    radius = r.choice([1.0, 3.0, 10.0])
    kinds = r.sample(KINDS, r.choice([1, 1, 2, 3, 6, 15]))
    materials = ["m1", "m2", "m3"] if r.random() < 0.35 else []
    rotated, scaled = r.random() < 0.7, r.random() < 0.3
    spacing = radius / n ** (1 / 3)
    sizes = (spacing * r.choice([0.2, 0.5]), spacing * r.choice([0.8, 1.5, 3.0]))
    k = r.choice([0.0, 0.0, 0.01, 0.05, 0.2]) * spacing
    body = parts(r, n, radius, kinds, materials, rotated, scaled, sizes)
    form = form or r.choice(FORMS)
    sm = f"smooth: {num(k)}, " if k > 0 else ""
    u = f"union({sm}material: base) {{\n{body}\n  }}"
    R = radius
    shapes = {
        "union": lambda: u,
        "holes": lambda: f"subtract({sm}material: base) {{\n    box(size: {vec([1.6 * R] * 3)})\n    union {{\n{body}\n    }}\n  }}",
        "intersect": lambda: f"intersect(material: base) {{\n    sphere(radius: {num(0.8 * R)})\n    {u}\n  }}",
        "nested": lambda: (f"union(material: base) {{\n    {u}\n    union(smooth: {num(0.1 * spacing)}) {{\n"
                           f"{parts(r, n // 2, R, r.sample(KINDS, 2), materials, rotated, scaled, sizes)}\n    }}\n  }}"),
        "twist": lambda: f"twist(rate: {num(r.uniform(5, 30) / R)}) {{\n    {u}\n  }}",
        "transformed": lambda: (f"translate([0.3, -0.2, 0.1]) {{ rotate(axis: [1, 2, 0.5], degrees: 33) {{ "
                                f"scale({num(r.uniform(0.5, 2))}) {{\n    {u}\n  }} }} }}"),
        "round": lambda: f"round(radius: {num(0.1 * spacing)}) {{\n    {u}\n  }}",
        "shell": lambda: (f"intersect {{ box(size: [{num(3 * R)}, {num(3 * R)}, {num(R)}]) "
                          f"shell(thickness: {num(0.05 * spacing)}) {{\n    {u}\n  }} }}"),
        "setminus": lambda: f"subtract(material: base) {{\n    {u}\n    sphere(radius: {num(0.5 * R)})\n  }}",
        "subtract_set": lambda: f"subtract(material: base) {{\n    sphere(radius: {num(R)})\n    {u}\n  }}",
        "ground": lambda: f"union(smooth: {num(0.3 * spacing)}) {{\n    plane(offset: {num(-0.7 * R)})\n    {u}\n  }}",
        "displace": lambda: f"displace(amplitude: {num(0.1 * spacing)}, scale: {num(3 / spacing)}) {{\n    {u}\n  }}",
        "round_twist": lambda: (f"round(radius: {num(0.1 * spacing)}) {{ twist(rate: {num(r.uniform(5, 30) / R)}) {{\n"
                                f"    {u}\n  }} }}"),
        "bend": lambda: f"bend(rate: {num(r.uniform(2, 10) / R)}) {{\n    {u}\n  }}",
        "elongate": lambda: f"elongate(amount: [{num(0.3 * R)}, 0, 0]) {{\n    {u}\n  }}",
        "moving": lambda: f"translate([0, sin(time), 0]) {{\n    {u}\n  }}",
        "morph": lambda: f"morph(t: 0.4) {{\n    sphere(radius: {num(R)})\n    {u}\n  }}",
    }
    shape = shapes[form]()
    cam = [2.2 * R, 1.4 * R, 2.6 * R]
    if form == "transformed":
        cam = [2 * x for x in cam]
    head = (f"render(size: [160, 90])\ncamera(position: {vec(cam)}, target: [0, 0, 0], fov: 40)\n"
            "sun(direction: [0.5, 1, 0.3])\nlet base = diffuse(albedo: [0.7, 0.7, 0.7])\n"
            "let m1 = diffuse(albedo: [0.8, 0.2, 0.2])\nlet m2 = metal(albedo: [0.8, 0.8, 0.2], roughness: 0.3)\n"
            "let m3 = diffuse(albedo: [0.2, 0.3, 0.8])\n")
    desc = (f"seed {seed}: {form}, {n} parts of {len(kinds)} kinds, radius {R:g}, smooth {k:.3g}"
            f"{', own materials' if materials else ''}{', rotated' if rotated else ''}{', scaled' if scaled else ''}")
    hard_materials = k == 0 and bool(materials) and form in ("union", "holes", "intersect", "setminus")
    return head + "scene {\n  " + shape + "\n}\n", desc, hard_materials


def albedo_differences(sdfc, path, dir_):
    images = []
    for extra in ([], ["--instance-threshold", "0"]):
        out = os.path.join(dir_, f"albedo{len(images)}.pfm")
        sb.render(sdfc, path, out, ["--size", "160x90", "--spp", "1", "--view", "albedo", "-q"] + extra)
        images.append(sb.read_pfm(out)[..., :3])
    return int((np.abs(images[0] - images[1]).max(axis=-1) > 1e-3).sum())


def seed_range(text):
    lo, _, hi = text.partition("-")
    return range(int(lo), int(hi) + 1 if hi else int(lo) + 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    ap.add_argument("--seeds", default="0-40", help="A-B (both included) or one seed")
    ap.add_argument("--form", choices=sorted(set(FORMS)), help="only this form (default: each seed's own)")
    ap.add_argument("--albedo-pixels", type=int, default=20, help="albedo pixels that may differ (silhouettes)")
    ap.add_argument("--keep", help="write each scene and its images under this folder")
    args = ap.parse_args()
    failed = 0
    seeds = seed_range(args.seeds)
    for seed in seeds:
        text, desc, check_albedo = scene(seed, args.form)
        with tempfile.TemporaryDirectory(prefix="sdfc_fuzz_") as scratch:
            dir_ = os.path.join(args.keep, f"seed{seed}") if args.keep else scratch
            os.makedirs(dir_, exist_ok=True)
            path = os.path.join(dir_, "scene.sdf")
            with open(path, "w") as f:
                f.write(text)
            hits, off, early, missed = mp.pixels_off(args.sdfc, path, dir_, 160, 90)
            line = f"{desc}: {hits} hit pixels, {off} off, {early} with a surface before, {missed} missed"
            bad = off > 0
            if check_albedo:
                differ = albedo_differences(args.sdfc, path, dir_)
                line += f"; albedo: {differ} pixels differ from inline code"
                bad = bad or differ > args.albedo_pixels
        print(("FAIL " if bad else "ok   ") + line, flush=True)
        failed += bad
    print(f"{failed} of {len(seeds)} scenes failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
