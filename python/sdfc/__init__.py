"""sdfc from Python: load or build a scene of signed distance functions, evaluate
its float64 field, path-trace it on the Vulkan device and mesh it.

    import sdfc
    scene = sdfc.load("examples/castle.sdf")
    d = scene.eval(points)               # (N, 3) float64 -> (N,) float64
    image = scene.render(size=(64, 36))  # (36, 64, 3) float32, linear

See docs/python.md.
"""
from __future__ import annotations

import os
import struct
import zlib
from collections.abc import Callable, Mapping, Sequence  # not typing: its import is a tenth of `import sdfc`

from . import _sdfc
from ._sdfc import DeviceError, read_image
from .builder import (Material, Shape, box, capsule, cone, cylinder, diffuse, emissive, glass,
                      intersect, metal, mirror, plane, scene_text, sphere, subtract, torus, union)

__version__ = _sdfc.__version__

__all__ = [
    "load", "parse", "driver", "Scene", "SceneError", "Diagnostic", "DeviceError", "read_image",
    "Shape", "Material", "sphere", "box", "torus", "cylinder", "cone", "capsule", "plane",
    "union", "intersect", "subtract", "diffuse", "mirror", "glass", "metal", "emissive", "scene_text",
]


class Diagnostic:
    """One diagnostic of a scene: severity is "error", "warning" or "note"; name is a
    warning's name (for disabled_warnings / -Wno-NAME); notes are Diagnostics too.
    Immutable, compared and hashed by value. (A plain class: dataclasses' import and
    class generation were a quarter of `import sdfc`.)"""
    __slots__ = ("severity", "file", "line", "column", "message", "name", "notes")

    def __init__(self, severity: str, file: str, line: int, column: int, message: str,
                 name: str = "", notes: tuple = ()):
        for key, value in zip(self.__slots__, (severity, file, line, column, message, name, tuple(notes))):
            object.__setattr__(self, key, value)

    def __setattr__(self, key, value):
        raise AttributeError("Diagnostic is immutable")

    def _fields(self) -> tuple:
        return tuple(getattr(self, key) for key in self.__slots__)

    def __eq__(self, other):
        return self._fields() == other._fields() if isinstance(other, Diagnostic) else NotImplemented

    def __hash__(self):
        return hash(self._fields())

    def __repr__(self) -> str:
        return "Diagnostic(" + ", ".join(f"{k}={getattr(self, k)!r}" for k in self.__slots__) + ")"

    @staticmethod
    def _from(d: dict) -> "Diagnostic":
        return Diagnostic(d["severity"], d["file"], d["line"], d["column"], d["message"], d["name"],
                          tuple(Diagnostic._from(n) for n in d["notes"]))


class SceneError(Exception):
    """A scene that cannot be read or has errors. str() is what `sdfc check` prints."""

    def __init__(self, text: str, diagnostics: Sequence[Diagnostic] = ()):
        super().__init__(text)
        self.text = text
        self.diagnostics = list(diagnostics)

    def __str__(self) -> str:
        return self.text


class Scene:
    """A checked scene. Made by load(), parse() or a builder shape's .scene()."""

    def __init__(self, native):
        self._native = native

    # -- what was loaded
    @property
    def path(self) -> str:
        return self._native.path

    @property
    def text(self) -> str:
        """The .sdf source."""
        return self._native.text

    @property
    def diagnostics(self) -> list:
        """Warnings (a scene with errors raises SceneError instead)."""
        return [Diagnostic._from(d) for d in self._native.diagnostics]

    @property
    def materials(self) -> list:
        """Material names, indexed by the ids material() and mesh() return."""
        return self._native.materials

    @property
    def size(self) -> tuple:
        """The scene's render size (width, height)."""
        return self._native.size

    # -- the float64 field (bit for bit `sdfc eval`), on every core, the GIL released
    def eval(self, points, time: float = 0.0, threads: int = 0):
        """Signed distance at each of the (N, 3) float64 points: (N,) float64."""
        return self._native.field(points, time, threads, "distance")

    def gradient(self, points, time: float = 0.0, threads: int = 0):
        """The field's gradient (central differences, as `sdfc eval --gradient`): (N, 3) float64."""
        return self._native.field(points, time, threads, "gradient")

    def material(self, points, time: float = 0.0, threads: int = 0):
        """The material id at each point: (N,) int32 into .materials, -1 for none."""
        return self._native.field(points, time, threads, "material")

    # -- the kernel
    def glsl(self, view: str = "beauty") -> str:
        """The fragment shader `sdfc compile --emit glsl --view VIEW` writes."""
        return self._native.glsl(view)

    def spirv(self, view: str = "beauty") -> bytes:
        """The validated SPIR-V module of that shader."""
        return self._native.spirv(view)

    # -- pictures and meshes
    def render(self, size: Sequence[int] | None = None, spp: int | None = None,
               view: str = "beauty", denoise: str | None = None, time: float = 0.0,
               seed: int = 0, bounces: int | None = None, light_samples: int | None = None,
               device: int = -1, progress: Callable[[int, int], None] | None = None):
        """Path-traces the scene: a linear float32 (H, W, 3) image, equal bit for bit to
        `sdfc render -o x.exr` with the same settings (unset ones are the scene's; denoise
        None is nlr for the beauty view, "none" turns it off). progress(done, total) is
        called after every pass; Ctrl-C raises KeyboardInterrupt after the pass under way."""
        # Numbers go to the module as given: it checks each against the table of option
        # limits the command line uses (api/option_limits.h), so 1.5 or -1 is refused,
        # not rounded or wrapped.
        return self._native.render(size, spp, view, denoise, time, seed, bounces,
                                   light_samples, int(device), progress)

    def render_settings(self, spp: int | None = None, view: str = "beauty", denoise: str | None = None) -> dict:
        """What render() with these options would use, as `sdfc render` decides it
        (api/render_defaults.h): {"spp", "denoiser", "denoises", "adaptive", "reason"};
        "reason" is the line `sdfc render` prints after "sdfc: settings: "."""
        return self._native.render_settings(spp, view, denoise)

    def mesh(self, resolution: int = 128, voxel_size: float | None = None, box=None, time: float = 0.0,
             threads: int = 0):
        """Dual-contoured mesh as `sdfc mesh` makes it: (vertices (V, 3) float64,
        faces (F, 3) uint32, material ids (F,) int32). voxel_size, when given, overrides
        resolution (as --voxel-size)."""
        if box is not None:
            box = [float(v) for pair in box for v in pair] if len(box) == 2 else [float(v) for v in box]
        return self._native.mesh(resolution, voxel_size, box, time, threads)

    def save(self, path: str) -> None:
        """Writes the .sdf source to `path`."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.text)

    def _repr_png_(self) -> bytes:
        """Jupyter's preview: a small, quick render."""
        w, h = self.size
        scale = min(1.0, 320.0 / max(w, 1))
        image = self.render(size=(max(1, round(w * scale)), max(1, round(h * scale))), spp=16)
        return png_bytes(image)

    def __repr__(self) -> str:
        return f"<sdfc.Scene {self.path!r}>"


def _checked(native, defines_given: bool = False) -> Scene:
    if native.io_error:
        raise SceneError("sdfc: error: " + native.io_error)
    if not native.ok:
        raise SceneError(native.diagnostics_text, [Diagnostic._from(d) for d in native.diagnostics])
    return Scene(native)


def _defines(defines: Mapping[str, float] | None) -> dict:
    out = {}
    for name, value in (defines or {}).items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise TypeError(f"define {name!r} must be a number, got {type(value).__name__}")
        out[str(name)] = float(value)
    return out


def load(path, defines: Mapping[str, float] | None = None,
         disabled_warnings: Sequence[str] = (), werror: bool = False) -> Scene:
    """Reads and checks the .sdf file at `path`; `defines` as `-D name=value`.
    Raises SceneError (an unreadable file, or errors) with the diagnostics."""
    return _checked(_sdfc.load(os.fspath(path), _defines(defines), list(disabled_warnings), werror))


def parse(text: str, name: str = "<string>", defines: Mapping[str, float] | None = None,
          disabled_warnings: Sequence[str] = (), werror: bool = False) -> Scene:
    """Checks .sdf `text`; `name` is what diagnostics call it (imports resolve from
    its folder). Raises SceneError with the diagnostics."""
    return _checked(_sdfc.parse(str(text), name, _defines(defines), list(disabled_warnings), werror))


def driver() -> dict:
    """The Vulkan driver this process renders with, chosen once per process as
    `sdfc render` chooses it (docs/python.md): `bundled` is True for the Mesa 25
    lavapipe a wheel carries (or SDFC_LAVAPIPE names), `manifest` its ICD file,
    `reason` the line `sdfc devices` prints after "driver: ", `choice` SDFC_DRIVER's
    value (auto, system, bundled), `devices` the devices it lists (index, name,
    type, driver: e.g. "Mesa 25.0.7"). Set SDFC_DRIVER or SDFC_LAVAPIPE in the
    environment before the first render or call of this function to choose."""
    return _sdfc.driver()


def png_bytes(image) -> bytes:
    """A linear (H, W, 3) image as PNG bytes, tone-mapped and encoded as `sdfc render -o x.png`."""
    rgb = _sdfc.to_srgb8(image)
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
