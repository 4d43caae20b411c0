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
  boxbash    kitbash with every part a box (an ablation: the cost of mixing kinds)
  chess      32 parametric pieces (pawns, rooks, knights, bishops, queens,
             kings) from revolved profiles and parametric definitions; n is
             ignored beyond 32 (a board of n squares' worth of pieces)

Framing (`framing`): "sphere" (the default) puts the camera where the
family's bounding sphere (the parts' own bounding balls, not the clump's
centres) spans the same share of the view at every count, so a count's cost
is not a coverage's: at 10 parts the legacy camera stood back from a small
clump and most pixels were sky. "legacy" is the camera of the pages before
(position extent * [1.6, 1.2, 2.4] + [0, 1, 2]), kept for their history.

    bench/many_parts_scenes.py kitbash 1000 --smooth 0.05 > kit.sdf
"""
import argparse
import math
import random


def _num(x):
    return f"{x:.6g}"


def _vec(v):
    return "[" + ", ".join(_num(x) for x in v) + "]"


FOV = 40  # vertical, degrees
# The bounding sphere's angular radius as a share of the half field of view
# ("sphere" framing): about what the legacy camera gave at 1,000 parts.
SPHERE_SHARE = 0.9
HEADER = """render(size: [320, 180])
camera(position: {pos}, target: {target}, fov: {fov})
sun(direction: [0.5, 1, 0.3])
let a = diffuse(albedo: [0.8, 0.4, 0.3])
"""


def _rot(rng):
    axis = [rng.uniform(-1, 1) for _ in range(3)]
    if max(abs(x) for x in axis) < 0.1:
        axis = [0, 1, 0]
    return f"rotate(axis: {_vec(axis)}, degrees: {_num(rng.uniform(0, 180))})"


def _primitive(rng, kind, s):
    """A primitive's text and the radius of a ball about its origin holding it."""
    if kind == "box":
        size = [s * rng.uniform(0.5, 1.5) for _ in range(3)]
        return f"box(size: {_vec(size)})", 0.5 * math.sqrt(sum(x * x for x in size))
    if kind == "capsule":
        h = s * rng.uniform(0.8, 2)
        return f"capsule(radius: {_num(0.3 * s)}, height: {_num(h)})", 0.5 * h + 0.3 * s
    if kind == "cylinder":
        h = s * rng.uniform(0.8, 2)
        return f"cylinder(radius: {_num(0.4 * s)}, height: {_num(h)})", math.hypot(0.5 * h, 0.4 * s)
    if kind == "torus":
        return f"torus(major: {_num(0.5 * s)}, minor: {_num(0.15 * s)})", 0.65 * s
    return f"sphere(radius: {_num(0.5 * s)})", 0.5 * s


def _clump(rng, n, spread):
    """n points in a ball whose volume grows with n (constant density)."""
    r = spread * n ** (1 / 3)
    pts = []
    while len(pts) < n:
        p = [rng.uniform(-r, r) for _ in range(3)]
        if sum(x * x for x in p) <= r * r:
            pts.append(p)
    return pts, r


# Each family returns (extent, body lines, balls): extent places the legacy
# camera, balls (centre, radius) hold every part and frame the "sphere" camera.
def molecule(n, smooth, rng):
    pts, r = _clump(rng, n, 0.5)
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    balls = []
    for p in pts:
        radius = rng.uniform(0.25, 0.45)
        body.append(f"    translate({_vec(p)}) {{ sphere(radius: {_num(radius)}) }}")
        balls.append((p, radius))
    body.append("  }")
    return r, body, balls


def kitbash(n, smooth, rng, kinds=("box", "capsule", "cylinder", "torus", "sphere")):
    pts, r = _clump(rng, n, 0.6)
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    balls = []
    for i, p in enumerate(pts):
        s = rng.uniform(0.3, 0.7)
        rot = _rot(rng)
        text, radius = _primitive(rng, kinds[i % 5], s)
        body.append(f"    translate({_vec(p)}) {{ {rot} {{ {text} }} }}")
        balls.append((p, radius))
    body.append("  }")
    return r, body, balls


def tree(n, smooth, rng):
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    balls = []
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
        balls.append((mid, 0.5 * math.sqrt(2 * w * w + length * length)))
        extent = max(extent, max(abs(x) for x in tip))
        count += 1
        for _ in range(2):
            nd = [d[i] + rng.uniform(-0.7, 0.7) for i in range(3)]
            nd[1] = abs(nd[1]) + 0.2
            norm = math.sqrt(sum(x * x for x in nd))
            todo.append((tip, [x / norm for x in nd], length * 0.8, depth + 1))
    body.append("  }")
    return extent, body, balls


def holes(n, smooth, rng):
    side = 1.0 + 0.4 * n ** (1 / 2)
    body = [f"  subtract(smooth: {_num(smooth)}, material: a) {{",
            f"    box(size: {_vec([side, side, 0.6 * side])})"]
    for _ in range(n):
        p = [rng.uniform(-side / 2, side / 2), rng.uniform(-side / 2, side / 2), 0.3 * side]
        body.append(f"    translate({_vec(p)}) {{ sphere(radius: {_num(rng.uniform(0.1, 0.3))}) }}")
    body.append("  }")
    # The holes only take away: the block holds the shape.
    return side, body, [([0.0, 0.0, 0.0], 0.5 * side * math.sqrt(2.36))]


def city(n, smooth, rng):
    side = 1.5 * math.ceil(math.sqrt(n))
    body = [f"  union(smooth: {_num(smooth)}, material: a) {{"]
    balls = []
    k = math.ceil(math.sqrt(n))
    for i in range(n):
        x, z = (i % k) * 1.5 - side / 2, (i // k) * 1.5 - side / 2
        h = rng.uniform(0.5, 3.0)
        fx, fz = rng.uniform(0.6, 1.2), rng.uniform(0.6, 1.2)
        body.append(f"    translate({_vec([x, h / 2, z])}) {{ box(size: {_vec([fx, h, fz])}, rounding: 0.03) }}")
        balls.append(([x, h / 2, z], 0.5 * math.sqrt(fx * fx + h * h + fz * fz)))
        if rng.random() < 0.3:
            body.append(f"    translate({_vec([x, h, z])}) {{ pyramid(size: {_num(min(fx, fz))}, height: {_num(0.5)}) }}")
            balls.append(([x, h, z], math.hypot(min(fx, fz) / math.sqrt(2), 0.5)))
    body.append("  }")
    return side / 2, body, balls

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
    balls = []
    count = 0
    for row, z in ((0, -3.5), (1, -2.5), (6, 2.5), (7, 3.5)):
        for col in range(8):
            if count >= max(n, 1):
                break
            piece = order[col] if row in (0, 7) else "pawn"
            s = rng.uniform(0.95, 1.05)  # hand-made: no two pieces quite alike
            body.append(f"    translate({_vec([col - 3.5, 0, z])}) {{ {piece}({_num(s)}) }}")
            # The tallest piece (the king) reaches 1.79 s, the widest 0.45 s.
            balls.append(([col - 3.5, 0.9 * s, z], math.hypot(0.9 * s, 0.45 * s)))
            count += 1
    body.append("  }")
    return 5.0, body, balls


def boxbash(n, smooth, rng):
    """kitbash with every part a box: what mixing kinds costs (an ablation)."""
    return kitbash(n, smooth, rng, kinds=("box",) * 5)


FAMILIES = dict(molecule=molecule, kitbash=kitbash, tree=tree, holes=holes, city=city, chess=chess,
                boxbash=boxbash)
FRAMINGS = ("sphere", "legacy")


def bounding_sphere(balls):
    """A sphere holding every ball: its centre the middle of their box."""
    lo = [min(c[i] - r for c, r in balls) for i in range(3)]
    hi = [max(c[i] + r for c, r in balls) for i in range(3)]
    centre = [(lo[i] + hi[i]) / 2 for i in range(3)]
    radius = max(math.dist(c, centre) + r for c, r in balls)
    return centre, radius


def camera(family, extent, balls, framing):
    """(position, target) of the camera."""
    if framing == "legacy":
        target = [0, extent * 0.3 if family in ("tree", "city", "chess") else 0, 0]
        return [extent * 1.6, extent * 1.2 + 1, extent * 2.4 + 2], target
    centre, radius = bounding_sphere(balls)
    # The legacy camera's direction; the distance at which the sphere's
    # angular radius is SPHERE_SHARE of the half field of view.
    d = [1.6, 1.2, 2.4]
    norm = math.sqrt(sum(x * x for x in d))
    dist = radius / math.sin(math.radians(SPHERE_SHARE * FOV / 2))
    return [centre[i] + d[i] / norm * dist for i in range(3)], centre


def scene(family, n, smooth=0.0, seed=1, framing="sphere"):
    rng = random.Random(f"{family}-{n}-{seed}")
    extent, body, balls = FAMILIES[family](n, smooth, rng)
    pos, target = camera(family, extent, balls, framing)
    text = HEADER.format(pos=_vec(pos), target=_vec(target), fov=FOV)
    if family == "chess":
        text += CHESS_DEFS
    return text + "scene {\n" + "\n".join(body) + "\n}\n"



def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("family", choices=sorted(FAMILIES))
    ap.add_argument("n", type=int)
    ap.add_argument("--smooth", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--framing", choices=FRAMINGS, default="sphere")
    args = ap.parse_args()
    print(scene(args.family, args.n, args.smooth, args.seed, args.framing), end="")


if __name__ == "__main__":
    main()
