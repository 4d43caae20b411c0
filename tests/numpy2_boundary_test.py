#!/usr/bin/env python3
"""The build tree's module under numpy 2 (issue 47 item 8): every array out is right.

    /usr/bin/python3 tests/numpy2_boundary_test.py --module-dir build/python --venv build/numpy2-venv

The module links the system's pybind11 (2.10 on Debian 12), which reads a dtype's item size
from numpy 1's struct layout: under numpy 2 from pip, eval([[0,0,0],[2,0,0],[0,5,0]]) gave
-1, -1, -1 (a 1-D result with a stride of 0). This makes a virtual environment with numpy 2
from PyPI (once; skipped, exit 77, where it cannot be made) and checks there that eval,
gradient, material, mesh, render, read_image and to_srgb8 give C-contiguous arrays of the
right values, and that a strided input is read point by point.
"""
import argparse
import os
import subprocess
import sys
import tempfile

CHILD = r'''
import sys
import numpy as np
import sdfc
assert int(np.__version__.split(".")[0]) >= 2, np.__version__
failures = []
def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)
scene = sdfc.parse(
    "let red = diffuse(albedo: [1, 0, 0])\nlet blue = diffuse(albedo: [0, 0, 1])\n"
    "scene {\n  sphere(radius: 1, material: red)\n  translate([0, 5, 0]) { sphere(radius: 1, material: blue) }\n}\n",
    name="two.sdf")
pts = np.array([[0.0, 0, 0], [2, 0, 0], [0, 5, 0], [0, 7, 0]])
d = scene.eval(pts)
check(np.allclose(d, [-1, 1, -1, 1]) and d.strides == (8,), "eval point by point %s %s" % (d, d.strides))
wide = np.zeros((4, 5))
wide[:, :3] = pts
check(np.allclose(scene.eval(wide[:, :3]), [-1, 1, -1, 1]), "eval of a strided view")
m = scene.material(pts)
check(m.tolist() == [0, 0, 1, 1] and m.strides == (4,), "material point by point %s" % m)
g = scene.gradient(pts[1:2])
check(np.allclose(g, [[1, 0, 0]], atol=1e-6) and g.strides == (24, 8), "gradient %s" % g)
v, f, mat = scene.mesh(resolution=16)
check(v.strides == (24, 8) and f.strides == (12, 4) and mat.strides == (4,) and set(mat.tolist()) == {0, 1},
      "mesh arrays %s %s %s" % (v.strides, f.strides, sorted(set(mat.tolist()))))
check(np.abs(scene.eval(v)).max() < 1e-2, "mesh vertices on the surface")
image = scene.render(size=(8, 4), spp=1, denoise="none")
check(image.shape == (4, 8, 3) and image.strides == (96, 12, 4), "render %s" % (image.strides,))
rgb = sdfc._sdfc.to_srgb8(image)
check(rgb.strides == (24, 3, 1), "to_srgb8 %s" % (rgb.strides,))
sys.exit(1 if failures else 0)
'''


def numpy2_python(venv):
    python = os.path.join(venv, "bin", "python")
    probe = [python, "-c", "import numpy, sys; sys.exit(int(numpy.__version__.split('.')[0]) < 2)"]
    if os.path.exists(python) and subprocess.run(probe, capture_output=True).returncode == 0:
        return python
    r = subprocess.run([sys.executable, "-m", "venv", venv], capture_output=True, text=True)
    if r.returncode == 0:
        r = subprocess.run([python, "-m", "pip", "install", "-q", "numpy>=2"], capture_output=True, text=True,
                           timeout=240)
    if r.returncode != 0 or subprocess.run(probe, capture_output=True).returncode != 0:
        print("skipped: no numpy 2 environment could be made (%s)" % r.stderr.strip()[-200:])
        return None
    return python


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--module-dir", required=True)
    p.add_argument("--venv", required=True)
    a = p.parse_args()
    python = numpy2_python(a.venv)
    if python is None:
        return 77
    with tempfile.TemporaryDirectory(prefix="sdfc numpy2 ") as tmp:
        env = dict(os.environ, PYTHONPATH=a.module_dir)
        r = subprocess.run([python, "-c", CHILD], cwd=tmp, env=env, capture_output=True, text=True, timeout=240)
    print(r.stdout + r.stderr)
    return r.returncode


if __name__ == "__main__":
    sys.exit(main())
