#!/usr/bin/env python3
"""`sdfc view` draws a failed save's first error on the image (issue 29), under
Xvfb (CTest runs it with xvfb-run), through paths with spaces in the script.

One session in a folder with a space in its name, on "my scene.sdf": a clean
frame; a save with an error (its X screenshot's bottom band differs from the
clean one's and holds white text, the rest of the image stays; the frame log's
title names the file, line, column and message; `save` writes the render without
the band); the scene fixed again (the band is gone: the screenshot equals the
clean one). `save` and `write-file` take paths with spaces.
"""
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from view_test import read_png, read_xwd  # noqa: E402

SDFC = sys.argv[1]
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


SCENE = """render(size: [160, 120], spp: 2, bounces: 1)
camera(position: [0, 1.2, 4.5], target: [0, 0.6, 0], fov: 40)
scene {
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.7, 0.7, 0.7]))
  translate([0, 0.7, 0]) { SHAPE }
}
"""
CLEAN = SCENE.replace("SHAPE", "sphere(radius: 0.7, material: diffuse(albedo: [0.8, 0.3, 0.25]))")
BROKEN = SCENE.replace("SHAPE", "sphere(radus: 0.7)")
# Where BROKEN's error is (1-based line and column of `radus`).
ERROR_LINE = 5
ERROR_COL = BROKEN.splitlines()[ERROR_LINE - 1].index("radus") + 1


def main():
    env = dict(os.environ, SDFC_VALIDATION="1", LP_NUM_THREADS="2")
    with tempfile.TemporaryDirectory() as top:
        d = os.path.join(top, "a folder")
        os.makedirs(d)
        j = lambda name: os.path.join(d, name)
        scene = j("my scene.sdf")
        open(scene, "w").write(CLEAN)
        open(j("broken scene.sdf"), "w").write(BROKEN)
        open(j("clean scene.sdf"), "w").write(CLEAN)
        shot = lambda name: f"run sleep 0.3; xwd -id ${{WINDOW}} -silent -out '{j(name)}'"
        script = f"""wait-spp 2
save {j('clean frame.png')}
{shot('clean.xwd')}
write-file {j('broken scene.sdf')}
wait-reload
wait 3
{shot('broken.xwd')}
save "{j('after broken.png')}"
write-file '{j('clean scene.sdf')}'
wait-reload
wait-spp 2
{shot('fixed.xwd')}
quit
"""
        open(j("events.txt"), "w").write(script)
        log = j("frames.log")
        r = subprocess.run([SDFC, "view", scene, "--script", j("events.txt"), "--frame-log", log],
                           env=env, capture_output=True, text=True, timeout=300)
        sys.stderr.write(r.stderr)
        check(r.returncode == 0, f"quit exits 0 (got {r.returncode})")
        check("[vulkan" not in r.stderr, "validation layers silent")
        for name in ("clean frame.png", "after broken.png", "clean.xwd", "broken.xwd", "fixed.xwd"):
            check(os.path.exists(j(name)), f"'{name}' written (a path with spaces)")
        if failures:
            return 1
        events = [l for l in open(log).read().splitlines() if l.startswith("event ")]
        check(sum("reload ok" in e for e in events) == 2, "write-file with spaces: two good loads")
        want = f"my scene.sdf:{ERROR_LINE}:{ERROR_COL}: 'sphere' has no parameter 'radus'"
        titles = [e for e in events if "reload error" in e]
        check(any(want in e for e in titles), f"the title names the first error ({want!r} in {titles})")

        clean, broken, fixed = (read_xwd(j(n)) for n in ("clean.xwd", "broken.xwd", "fixed.xwd"))
        h = clean.shape[0]
        # The band at scale 1: one line of text is 9 rows plus 2 above and below;
        # 13 rows from the bottom hold it for any message.
        band = slice(h - 13, h)
        differs = (np.abs(broken[band].astype(int) - clean[band]).max(axis=-1) > 16).mean()
        check(differs > 0.5, f"the error band differs from the clean frame ({differs:.0%} of its pixels)")
        white = (broken[band] == 255).all(axis=-1).sum()
        check(white > 40, f"the band holds white text ({white} pixels)")
        above = slice(0, h - 4 * 9 - 4)  # above the tallest band (4 lines)
        check(np.array_equal(broken[above], clean[above]), "above the band the last image stays")
        check(np.array_equal(fixed, clean), "the band goes when the scene compiles again")
        check(np.array_equal(read_png(j("after broken.png")), read_png(j("clean frame.png"))),
              "save writes the render without the band")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
