"""Scenes built in Python: shapes combined with | (union), & (intersect) and
- (subtract), moved with .translate / .rotate / .scale, given materials. str()
of a shape is .sdf text in sdfc fmt's layout that `sdfc check` accepts.

    s = sphere(1) | box([2, 1, 1]).translate([1, 0, 0])
    scene = s.smooth(0.2).material(diffuse([0.8, 0.3, 0.2])).scene()
"""
from __future__ import annotations

import math
from collections.abc import Sequence


def _number(x) -> str:
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"a scene's numbers must be finite, got {x}")
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


def _vector(v, n: int = 3) -> str:
    values = [v] * n if isinstance(v, (int, float)) else list(v)
    if len(values) != n:
        raise ValueError(f"expected {n} numbers, got {len(values)}")
    return "[" + ", ".join(_number(x) for x in values) + "]"


class Material:
    """diffuse(albedo), mirror(), glass(ior), metal(albedo, roughness), emissive(color, strength)."""

    def __init__(self, kind: str, args: dict):
        self.kind, self.args = kind, args

    def __str__(self) -> str:
        return self.kind + "(" + ", ".join(f"{k}: {v}" for k, v in self.args.items()) + ")"


def diffuse(albedo=(0.8, 0.8, 0.8)) -> Material:
    return Material("diffuse", {"albedo": _vector(albedo)})


def mirror() -> Material:
    return Material("mirror", {})


def glass(ior: float = 1.5) -> Material:
    return Material("glass", {"ior": _number(ior)})


def metal(albedo=(0.9, 0.9, 0.9), roughness: float = 0.2) -> Material:
    return Material("metal", {"albedo": _vector(albedo), "roughness": _number(roughness)})


def emissive(color=(1, 1, 1), strength: float = 1) -> Material:
    return Material("emissive", {"color": _vector(color), "strength": _number(strength)})


class Shape:
    """A node of the scene tree: a call with arguments and children."""

    def __init__(self, name: str, args: dict | None = None, children: Sequence["Shape"] = (),
                 positional: str | None = None):
        self.name = name
        self.args = dict(args or {})
        self.children = list(children)
        self.positional = positional  # translate's offset, written without its name

    def _with(self, **args) -> "Shape":
        return Shape(self.name, {**self.args, **args}, self.children, self.positional)

    # -- CSG
    def __or__(self, other: "Shape") -> "Shape":
        return _combine("union", self, other)

    def __and__(self, other: "Shape") -> "Shape":
        return _combine("intersect", self, other)

    def __sub__(self, other: "Shape") -> "Shape":
        return Shape("subtract", {}, [self, _shape(other)])

    def smooth(self, k: float) -> "Shape":
        """A smooth blend of width k for a union, intersection or difference."""
        if self.name not in ("union", "intersect", "subtract"):
            raise ValueError(".smooth() applies to a union, intersection or difference, not " + self.name)
        return self._with(smooth=_number(k))

    # -- placement
    def translate(self, offset) -> "Shape":
        return Shape("translate", {}, [self], positional=_vector(offset))

    def rotate(self, axis, degrees: float) -> "Shape":
        """Right-handed rotation by `degrees` about `axis`."""
        return Shape("rotate", {"axis": _vector(axis), "degrees": _number(degrees)}, [self])

    def rotate_x(self, degrees: float) -> "Shape":
        return self.rotate([1, 0, 0], degrees)

    def rotate_y(self, degrees: float) -> "Shape":
        return self.rotate([0, 1, 0], degrees)

    def rotate_z(self, degrees: float) -> "Shape":
        return self.rotate([0, 0, 1], degrees)

    def euler(self, degrees) -> "Shape":
        """Euler angles in degrees, about x, then y, then z."""
        return Shape("rotate", {"euler": _vector(degrees)}, [self])

    def scale(self, factor: float) -> "Shape":
        return Shape("scale", {"factor": _number(factor)}, [self])

    def round(self, radius: float) -> "Shape":
        return Shape("round", {"radius": _number(radius)}, [self])

    def shell(self, thickness: float) -> "Shape":
        return Shape("shell", {"thickness": _number(thickness)}, [self])

    def material(self, material: Material) -> "Shape":
        if not isinstance(material, Material):
            raise TypeError("material() takes sdfc.diffuse(...), mirror(), glass(...), metal(...) or emissive(...)")
        return self._with(material=str(material))

    # -- text and scenes
    def sdf(self, indent: int = 0) -> str:
        """This shape as .sdf lines (no scene block)."""
        pad = "  " * indent
        args = ([self.positional] if self.positional else []) + [f"{k}: {v}" for k, v in self.args.items()]
        head = pad + self.name + ("(" + ", ".join(args) + ")" if args or not self.children else "")
        if not self.children:
            return head
        inner = "\n".join(c.sdf(indent + 1) for c in self.children)
        return head + " {\n" + inner + "\n" + pad + "}"

    def __str__(self) -> str:
        return scene_text(self)

    def __repr__(self) -> str:
        return f"<sdfc.Shape {self.name}>"

    def scene(self, **settings):
        """A checked sdfc.Scene of this shape (settings as in scene_text)."""
        from . import parse
        return parse(scene_text(self, **settings), name="<builder>")

    def _repr_png_(self) -> bytes:
        return self.scene()._repr_png_()


def _shape(x) -> Shape:
    if not isinstance(x, Shape):
        raise TypeError(f"expected an sdfc shape, got {type(x).__name__}")
    return x


def _combine(kind: str, a: Shape, b: Shape) -> Shape:
    b = _shape(b)
    # a | b | c is one union of three (unless a blend is set on it).
    children = (a.children if a.name == kind and not a.args else [a]) + \
               (b.children if b.name == kind and not b.args else [b])
    return Shape(kind, {}, children)


def union(*shapes: Shape) -> Shape:
    return Shape("union", {}, [_shape(s) for s in shapes])


def intersect(*shapes: Shape) -> Shape:
    return Shape("intersect", {}, [_shape(s) for s in shapes])


def subtract(*shapes: Shape) -> Shape:
    return Shape("subtract", {}, [_shape(s) for s in shapes])


def sphere(radius: float = 1) -> Shape:
    return Shape("sphere", {"radius": _number(radius)})


def box(size=1, rounding: float = 0) -> Shape:
    args = {"size": _number(size) if isinstance(size, (int, float)) else _vector(size)}
    if rounding:
        args["rounding"] = _number(rounding)
    return Shape("box", args)


def torus(major: float = 1, minor: float = 0.25) -> Shape:
    return Shape("torus", {"major": _number(major), "minor": _number(minor)})


def cylinder(radius: float = 0.5, height: float = 1) -> Shape:
    return Shape("cylinder", {"radius": _number(radius), "height": _number(height)})


def cone(radius: float = 0.5, height: float = 1) -> Shape:
    return Shape("cone", {"radius": _number(radius), "height": _number(height)})


def capsule(radius: float = 0.25, height: float = 1) -> Shape:
    return Shape("capsule", {"radius": _number(radius), "height": _number(height)})


def plane(normal=(0, 1, 0), offset: float = 0) -> Shape:
    return Shape("plane", {"normal": _vector(normal), "offset": _number(offset)})


def _setting_value(name: str, key: str, v) -> str:
    if isinstance(v, str):
        # A file name (sky's map): one line, no quotes, as the language's strings.
        if '"' in v or "\n" in v or "\r" in v:
            raise ValueError(f"{name}[{key!r}]: a file name cannot hold a quote or a line break: {v!r}")
        return '"' + v + '"'
    if isinstance(v, (int, float)):
        return _number(v)
    return _vector(v)


def scene_text(shape: Shape, camera: dict | None = None, sun: dict | None = None,
               size: Sequence[int] | None = None, spp: int | None = None,
               sky: dict | None = None) -> str:
    """A whole .sdf file: optional render, camera, sun and sky settings, then the scene block.
    camera={"position": [...], "target": [...]}, sun={"direction": [...]},
    sky={"color": [...]} or {"top": [...], "bottom": [...]} or
    {"map": "studio.exr", "rotation": 30, "strength": 1} (the parameters of the
    language's camera(...), sun(...) and sky(...), docs/language.md)."""
    lines = []
    render = []
    if size is not None:
        render.append(f"size: [{int(size[0])}, {int(size[1])}]")
    if spp is not None:
        render.append(f"spp: {int(spp)}")
    if render:
        lines.append("render(" + ", ".join(render) + ")")
    for name, values in (("camera", camera), ("sun", sun), ("sky", sky)):
        if values:
            if not isinstance(values, dict):
                raise TypeError(f"{name} must be a dict of {name}(...)'s parameters, got {type(values).__name__}")
            lines.append(name + "(" + ", ".join(
                f"{k}: {_setting_value(name, k, v)}" for k, v in values.items()) + ")")
    lines.append("scene {\n" + _shape(shape).sdf(1) + "\n}")
    return "\n".join(lines) + "\n"
