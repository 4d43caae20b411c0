#!/usr/bin/env python3
"""Generated scenes of many *distinct* parts (issue 46), deterministic per
(family, n, seed). Written the way people model, not as copies of one shape:

  molecule   n spheres of varied radii in a clump, smooth-blended
  kitbash    n rotated boxes, capsules, cylinders, tori and spheres of varied
             sizes, hard union (smooth: 0) or smooth union
  tree       a branching tree of n rounded boxes, each rotated and sized by
             its depth, hard union
  holes      a block with n holes of varied radius subtracted from it
  city       n buildings of distinct footprints and heights, some with roofs
  chess      32 parametric pieces (pawns, rooks, knights, bishops, queens,
             kings) from revolved profiles and parametric definitions; n is
             ignored beyond 32 (a board of n squares' worth of pieces)

    bench/many_parts_scenes.py kitbash 1000 --smooth 0.05 > kit.sdf
"""
import argparse
import math
import random


def _num(x):
    return f"{x:.6g}"


def _vec(v):
    return "[" + ", ".join(_num(x) for x in v) + "]"


HEADER = """render(size: [320, 180])
camera(position: {pos}, target: {target}, fov: 40)
sun(direction: [0.5, 1, 0.3])
let a = diffuse(albedo: [0.8, 0.4, 0.3])
"""


def _rot(rng):
    axis = [rng.uniform(-1, 1) for _ in range(3)]
    if max(abs(x) for x in axis) < 0.1:
        axis = [0, 1, 0]
    return f"rotate(axis: {_vec(axis)}, degrees: {_num(rng.uniform(0, 180))})"


def _primitive(rng, kind, s):
    if kind == "box":
        return f"box(size: {_vec([s * rng.uniform(0.5, 1.5) for _ in range(3)])})"
    if kind == "capsule":
        return f"capsule(radius: {_num(0.3 * s)}, height: {_num(s * rng.uniform(0.8, 2))})"
    if kind == "cylinder":
        return f"cylinder(radius: {_num(0.4 * s)}, height: {_num(s * rng.uniform(0.8, 2))})"
    if kind == "torus":
        return f"torus(major: {_num(0.5 * s)}, minor: {_num(0.15 * s)})"
    return f"sphere(radius: {_num(0.5 * s)})"


def _clump(rng, n, spread):
    """n points in a ball whose volume grows with n (constant density)."""
    r = spread * n ** (1 / 3)
    pts = []
    while len(pts) < n:
        p = [rng.uniform(-r, r) for _ in range(3)]
        if sum(x * x for x in p) <= r * r:
            pts.append(p)
    return pts, r


def molecule(n, smooth, rng):
    pts, r = _clump(rng, n, 0.5)
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    for p in pts:
        body.append(f"    translate({_vec(p)}) {{ sphere(radius: {_num(rng.uniform(0.25, 0.45))}) }}")
    body.append("  }")
    return r, body


def kitbash(n, smooth, rng):
    pts, r = _clump(rng, n, 0.6)
    kinds = ["box", "capsule", "cylinder", "torus", "sphere"]
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    for i, p in enumerate(pts):
        s = rng.uniform(0.3, 0.7)
        body.append(f"    translate({_vec(p)}) {{ {_rot(rng)} {{ {_primitive(rng, kinds[i % 5], s)} }} }}")
    body.append("  }")
    return r, body


def tree(n, smooth, rng):
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    # Breadth-first branching: each branch spawns two shorter ones at its tip.
    todo = [([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.5, 0)]
    count = 0
    extent = 1.0
    while todo and count < n:
        base, d, length, depth = todo.pop(0)
        mid = [base[i] + d[i] * length / 2 for i in range(3)]
        tip = [base[i] + d[i] * length for i in range(3)]
        # Rotate y onto d: axis y x d, angle acos(d.y).
        axis = [d[2], 0.0, -d[0]]
        angle = math.degrees(math.acos(max(-1.0, min(1.0, d[1]))))
        w = max(0.04, 0.25 * 0.8 ** depth)
        shape = f"box(size: {_vec([w, length, w])}, rounding: {_num(w * 0.3)})"
        if abs(angle) > 1e-6 and max(abs(axis[0]), abs(axis[2])) > 1e-9:
            shape = f"rotate(axis: {_vec(axis)}, degrees: {_num(angle)}) {{ {shape} }}"
        body.append(f"    translate({_vec(mid)}) {{ {shape} }}")
        extent = max(extent, max(abs(x) for x in tip))
        count += 1
        for _ in range(2):
            nd = [d[i] + rng.uniform(-0.7, 0.7) for i in range(3)]
            nd[1] = abs(nd[1]) + 0.2
            norm = math.sqrt(sum(x * x for x in nd))
            todo.append((tip, [x / norm for x in nd], length * 0.8, depth + 1))
    body.append("  }")
    return extent, body


def holes(n, smooth, rng):
    side = 1.0 + 0.4 * n ** (1 / 2)
    body = [f"  subtract(smooth: {_num(smooth)}, material: a) {{",
            f"    box(size: {_vec([side, side, 0.6 * side])})"]
    for _ in range(n):
        p = [rng.uniform(-side / 2, side / 2), rng.uniform(-side / 2, side / 2), 0.3 * side]
        body.append(f"    translate({_vec(p)}) {{ sphere(radius: {_num(rng.uniform(0.1, 0.3))}) }}")
    body.append("  }")
    return side, body


def city(n, smooth, rng):
    side = 1.5 * math.ceil(math.sqrt(n))
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    k = math.ceil(math.sqrt(n))
    for i in range(n):
        x, z = (i % k) * 1.5 - side / 2, (i // k) * 1.5 - side / 2
        h = rng.uniform(0.5, 3.0)
        fx, fz = rng.uniform(0.6, 1.2), rng.uniform(0.6, 1.2)
        body.append(f"    translate({_vec([x, h / 2, z])}) {{ box(size: {_vec([fx, h, fz])}, rounding: 0.03) }}")
        if rng.random() < 0.3:
            body.append(f"    translate({_vec([x, h, z])}) {{ pyramid(size: {_num(min(fx, fz))}, height: {_num(0.5)}) }}")
    body.append("  }")
    return side / 2, body


CHESS_DEFS = """let pawn(s) = union {
  translate([0, 0.15 * s, 0]) { cylinder(radius: 0.35 * s, height: 0.3 * s) }
  translate([0, 0.45 * s, 0]) { cone(radius: 0.22 * s, height: 0.6 * s) }
  translate([0, 0.95 * s, 0]) { sphere(radius: 0.2 * s) }
}
let rook(s) = subtract {
  union {
    translate([0, 0.15 * s, 0]) { cylinder(radius: 0.4 * s, height: 0.3 * s) }
    translate([0, 0.7 * s, 0]) { cylinder(radius: 0.28 * s, height: 1.0 * s) }
  }
  translate([0, 1.15 * s, 0]) { box(size: [0.9 * s, 0.2 * s, 0.12 * s]) }
}
let bishop(s) = union {
  translate([0, 0.15 * s, 0]) { cylinder(radius: 0.38 * s, height: 0.3 * s) }
  translate([0, 0.3 * s, 0]) { round_cone(bottom: 0.25 * s, top: 0.1 * s, height: 0.8 * s) }
  translate([0, 1.2 * s, 0]) { ellipsoid(radii: [0.17 * s, 0.25 * s, 0.17 * s]) }
}
let knight(s) = union {
  translate([0, 0.15 * s, 0]) { cylinder(radius: 0.38 * s, height: 0.3 * s) }
  translate([0, 0.7 * s, 0]) { rotate(axis: [0, 0, 1], degrees: 20) { box(size: [0.3 * s, 0.9 * s, 0.3 * s], rounding: 0.05 * s) } }
  translate([0.15 * s, 1.05 * s, 0]) { box(size: [0.5 * s, 0.25 * s, 0.25 * s], rounding: 0.06 * s) }
}
let queen(s) = union(smooth: 0.05 * s) {
  translate([0, 0.15 * s, 0]) { cylinder(radius: 0.42 * s, height: 0.3 * s) }
  translate([0, 0.3 * s, 0]) { round_cone(bottom: 0.28 * s, top: 0.15 * s, height: 1.1 * s) }
  translate([0, 1.5 * s, 0]) { torus(major: 0.18 * s, minor: 0.06 * s) }
  translate([0, 1.62 * s, 0]) { sphere(radius: 0.09 * s) }
}
let king(s) = union {
  translate([0, 0.15 * s, 0]) { cylinder(radius: 0.42 * s, height: 0.3 * s) }
  translate([0, 0.3 * s, 0]) { round_cone(bottom: 0.28 * s, top: 0.16 * s, height: 1.2 * s) }
  translate([0, 1.7 * s, 0]) { box(size: [0.08 * s, 0.35 * s, 0.08 * s]) }
  translate([0, 1.75 * s, 0]) { box(size: [0.25 * s, 0.08 * s, 0.08 * s]) }
}
"""


def chess(n, smooth, rng):
    order = ["rook", "knight", "bishop", "queen", "king", "bishop", "knight", "rook"]
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    count = 0
    for row, z in ((0, -3.5), (1, -2.5), (6, 2.5), (7, 3.5)):
        for col in range(8):
            if count >= max(n, 1):
                break
            piece = order[col] if row in (0, 7) else "pawn"
            s = rng.uniform(0.95, 1.05)  # hand-made: no two pieces quite alike
            body.append(f"    translate({_vec([col - 3.5, 0, z])}) {{ {piece}({_num(s)}) }}")
            count += 1
    body.append("  }")
    return 5.0, body


FAMILIES = dict(molecule=molecule, kitbash=kitbash, tree=tree, holes=holes, city=city, chess=chess)


def scene(family, n, smooth=0.0, seed=1):
    rng = random.Random(f"{family}-{n}-{seed}")
    extent, body = FAMILIES[family](n, smooth, rng)
    target = [0, extent * 0.3 if family in ("tree", "city", "chess") else 0, 0]
    pos = [extent * 1.6, extent * 1.2 + 1, extent * 2.4 + 2]
    text = HEADER.format(pos=_vec(pos), target=_vec(target))
    if family == "chess":
        text += CHESS_DEFS
    return text + "scene {\n" + "\n".join(body) + "\n}\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("family", choices=sorted(FAMILIES))
    ap.add_argument("n", type=int)
    ap.add_argument("--smooth", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    print(scene(args.family, args.n, args.smooth, args.seed), end="")


if __name__ == "__main__":
    main()
