#!/usr/bin/env python3
"""`sdfc view` shows what `sdfc render` writes (run under xvfb-run by CTest).

The window is tone-mapped on the device (runtime/display_pass.h); the PNG writer
on the CPU. For the beauty view (the default curve, and ACES with an exposure),
the normal view and the depth view (mapped for display on the CPU, then the
device's linear curve) of a small scene, an `xwd` screenshot of the window after
the samples are in equals `sdfc render`'s PNG of the same view and samples byte
for byte, and so does the view's own `save`. Paths have spaces in them.
Usage: view_matches_render_test.py path/to/sdfc
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from view_test import read_png, read_xwd  # noqa: E402

SDFC = sys.argv[1]
SCENE = """render(size: [64, 36], spp: 3, bounces: 2)
camera(position: [0, 1.2, 4.5], target: [0, 0.6, 0], fov: 40)
sky(top: [0.9, 1.2, 1.8], bottom: [0.7, 0.7, 0.72])
sun(direction: [0.5, 1, 0.4], angle: 3, strength: 3.5)
scene {
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.7, 0.7, 0.7]))
  translate([0, 0.7, 0]) { sphere(radius: 0.7, material: diffuse(albedo: [0.95, 0.35, 0.25])) }
}
"""
CASES = [  # name, flags for both commands
    ("beauty", []),
    ("beauty aces", ["--tonemap", "aces", "--exposure", "-0.75"]),
    ("normal", ["--view", "normal"]),
    ("depth", ["--view", "depth"]),
]
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def main():
    env = dict(os.environ, SDFC_VALIDATION="1", LP_NUM_THREADS="2")
    with tempfile.TemporaryDirectory() as top:
        d = os.path.join(top, "view and render")
        os.mkdir(d)
        scene = os.path.join(d, "the scene.sdf")
        open(scene, "w").write(SCENE)
        for name, flags in CASES:
            j = lambda f: os.path.join(d, name + " " + f)
            script = (f"wait-idle\nrun sleep 0.3; xwd -id ${{WINDOW}} -silent -out '{j('shot.xwd')}'\n"
                      f"save {j('saved.png')}\nquit\n")
            open(j("events.txt"), "w").write(script)
            r = subprocess.run([SDFC, "view", scene, "--script", j("events.txt")] + flags,
                               env=env, capture_output=True, text=True, timeout=300)
            check(r.returncode == 0 and "[vulkan" not in r.stderr,
                  f"{name}: view exits 0, validation silent (got {r.returncode}){r.stderr[-400:] if r.returncode else ''}")
            # The view shows the raw mean (its denoiser is a key); render denoises by default.
            r = subprocess.run([SDFC, "render", scene, "-o", j("render.png"), "--denoise", "none"] + flags,
                               env=env, capture_output=True, text=True, timeout=300)
            check(r.returncode == 0, f"{name}: render exits 0 {r.stderr[-400:]}")
            if not all(os.path.exists(j(f)) for f in ("shot.xwd", "saved.png", "render.png")):
                check(False, f"{name}: the screenshot, the save and the render exist")
                continue
            ref = read_png(j("render.png"))
            shot = read_xwd(j("shot.xwd"))[:ref.shape[0], :ref.shape[1]]
            saved = read_png(j("saved.png"))
            check(shot.shape == ref.shape, f"{name}: the window is the render's size {shot.shape} {ref.shape}")
            if shot.shape == ref.shape:
                diff = np.abs(shot - ref)
                check(diff.max() == 0, f"{name}: the window equals `sdfc render`'s PNG byte for byte "
                                       f"({(diff.max(axis=-1) > 0).sum()} pixels differ, by at most {diff.max()})")
            check(saved.shape == ref.shape and np.array_equal(saved, ref),
                  f"{name}: the view's save equals `sdfc render`'s PNG")
            check(ref.std() > 1, f"{name}: the image is not flat (std {ref.std():.1f})")
    if failures:
        print(f"{len(failures)} failure(s)")
        sys.exit(1)


if __name__ == "__main__":
    main()
