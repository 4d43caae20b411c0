#!/usr/bin/env python3
"""One table of option limits (api/option_limits.h), every front end (issue 47 item 14).

    PYTHONPATH=build/python /usr/bin/python3 tests/option_limits_test.py [--sdfc build/cli/sdfc]

Walks the table the module exports (sdfc._sdfc.option_limits()): for each option, values
just outside its range, a fraction for a whole number, NaN and infinity are refused by
every command whose --help lists its flag (exit 2, `sdfc: error:`), by every Python call
that takes it (ValueError naming it), and for spp by the viewer's script (`file:line:
error:`). Python took light_samples=-1 as 4294967295, bounces=1000, time=nan and
voxel_size=nan while the command line refused them. A new option in the table with no
front end here fails this test, as does a Python keyword the table lacks.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

import sdfc

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COMMANDS = ("render", "view", "export", "mesh", "eval")
SCENE = "camera(position: [0, 1, 4], target: [0, 0, 0])\nscene {\n  sphere(radius: 1)\n}\n"

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def bad_values(limit):
    lo, hi, whole = limit["lo"], limit["hi"], limit["whole"]
    if whole:
        out = [lo - 1, hi + 1, lo + 0.5]
    else:
        out = [lo if limit["open_low"] else (lo * 10 if lo < 0 else lo - 1), hi * 10 if hi > 0 else hi + 1]
    return out + [float("nan"), float("inf")]


def text(v):
    """As typed on a command line: 65, -1, 1.5, 3.4028234663852886e+39, nan, inf."""
    if np.isfinite(v) and v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return repr(float(v))


def python_calls(scene):
    pts = np.zeros((2, 3))
    box = [[-2, -2, -2], [2, 2, 2]]
    r = dict(size=(4, 4), spp=1)
    return {
        "spp": [("render", lambda v: scene.render(size=(4, 4), spp=v))],
        "bounces": [("render", lambda v: scene.render(**r, bounces=v))],
        "light_samples": [("render", lambda v: scene.render(**r, light_samples=v))],
        "size": [("render width", lambda v: scene.render(size=(v, 4), spp=1)),
                 ("render height", lambda v: scene.render(size=(4, v), spp=1))],
        "time": [("render", lambda v: scene.render(**r, time=v)), ("eval", lambda v: scene.eval(pts, time=v)),
                 ("gradient", lambda v: scene.gradient(pts, time=v)),
                 ("material", lambda v: scene.material(pts, time=v)),
                 ("mesh", lambda v: scene.mesh(resolution=8, box=box, time=v))],
        "seed": [("render", lambda v: scene.render(**r, seed=v))],
        "resolution": [("mesh", lambda v: scene.mesh(resolution=v, box=box))],
        "voxel_size": [("mesh", lambda v: scene.mesh(voxel_size=v, box=box))],
        "threads": [("eval", lambda v: scene.eval(pts, threads=v)),
                    ("mesh", lambda v: scene.mesh(resolution=8, box=box, threads=v))],
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    a = p.parse_args()
    table = sdfc._sdfc.option_limits()
    check(len(table) >= 10, "the table has its %d options" % len(table))
    with tempfile.TemporaryDirectory(prefix="sdfc limits ") as tmp:
        path = os.path.join(tmp, "s.sdf")
        with open(path, "w") as f:
            f.write(SCENE)
        helps = {c: subprocess.run([a.sdfc, c, "--help"], capture_output=True, text=True).stdout for c in COMMANDS}
        args = {"render": [path, "-o", os.path.join(tmp, "x.png"), "-q"], "view": [path],
                "export": [path, "-o", os.path.join(tmp, "x.html"), "-q"],
                "mesh": [path, "-o", os.path.join(tmp, "x.stl"), "-q"], "eval": [path]}
        for limit in table:
            flag = limit["flag"]
            if not flag:
                continue
            users = [c for c in COMMANDS if (flag + " ") in helps[c]]
            check(bool(users), "%s is a flag of some command (%s)" % (flag, ", ".join(users)))
            for command in users:
                for v in bad_values(limit):
                    value = text(v)
                    if flag == "--size":
                        value = value + "x8"
                    r = subprocess.run([a.sdfc, command, *args[command], flag, value], capture_output=True,
                                       text=True, input="", timeout=60)
                    check(r.returncode == 2 and r.stderr.startswith("sdfc: error:") and flag in r.stderr,
                          "sdfc %s %s %s: exit 2 (%d: %s)" % (command, flag, value, r.returncode,
                                                             r.stderr.strip()[:100]))
        scene = sdfc.load(path)
        calls = python_calls(scene)
        python_names = {l["name"] for l in table if l["python"]}
        check(set(calls) == python_names, "every Python keyword in the table is tried here, and only those "
              "(%s)" % sorted(set(calls) ^ python_names))
        for limit in table:
            for where, call in calls.get(limit["name"], []):
                for v in bad_values(limit):
                    try:
                        call(v)
                        check(False, "Python %s(%s=%r) is refused (it was accepted)" % (where, limit["name"], v))
                    except ValueError as e:
                        check(str(e).startswith(limit["name"] + " must be"),
                              "Python %s(%s=%r): ValueError (%s)" % (where, limit["name"], v, e))
        # The ends themselves are taken.
        scene.eval(np.zeros((1, 3)), time=3.4028234663852886e38, threads=1)
        check(len(scene.mesh(resolution=4, box=[[-2, -2, -2], [2, 2, 2]])[0]) > 0, "resolution=4 meshes")
        # The viewer's script takes spp as --spp does, refused at its line before any window.
        script = os.path.join(tmp, "script.txt")
        for v in ("0", "1048577", "1.5"):
            with open(script, "w") as f:
                f.write("# a comment\nspp %s\n" % v)
            r = subprocess.run([a.sdfc, "view", path, "--script", script], capture_output=True, text=True,
                               timeout=60)
            check(r.returncode == 2 and (script + ":2: error: 'spp' must be a whole number from 1 to 1048576")
                  in r.stderr, "view script 'spp %s' refused at its line (%d: %s)"
                  % (v, r.returncode, r.stderr.strip()[:120]))
    if failures:
        print("%d failed" % len(failures))
        return 1
    print("all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
