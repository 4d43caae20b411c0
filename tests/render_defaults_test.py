#!/usr/bin/env python3
"""The render defaults decided once (api/render_defaults.h), the same in every front end (issue 48).

    PYTHONPATH=build/python /usr/bin/python3 tests/render_defaults_test.py --sdfc build/cli/sdfc

For combinations of the scene's render(spp: ...) set or not, --spp given or not, --denoise
given or not, --layers, --adaptive and views other than beauty, `sdfc render` prints one
line "sdfc: settings: ..." saying what it chose and why; it must be the line the module's
Scene.render_settings() returns for the same options (the function both call), its spp the
spp of the "wrote" line, and its denoiser the one the "wrote" line names. --quiet prints
none of it.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import sdfc

SCENE = "camera(position: [0, 1, 4], target: [0, 0, 0])\n{render}scene {{\n  sphere(radius: 1)\n}}\n"

failures = []


def check(ok, what, detail=""):
    print(("ok    " if ok else "FAIL  ") + what + ("" if ok else "\n      " + detail))
    if not ok:
        failures.append(what)


def settings_line(stderr):
    lines = [l for l in stderr.splitlines() if l.startswith("sdfc: settings: ")]
    return lines[0][len("sdfc: settings: "):] if len(lines) == 1 else None


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", required=True)
    args = p.parse_args()
    env = dict(os.environ, LP_NUM_THREADS=os.environ.get("LP_NUM_THREADS", "2"))
    with tempfile.TemporaryDirectory() as tmp:
        scenes = {}
        for name, render in (("set", "render(spp: 4)\n"), ("unset", "")):
            scenes[name] = os.path.join(tmp, name + ".sdf")
            with open(scenes[name], "w") as f:
                f.write(SCENE.format(render=render))
        # (scene, --spp, --denoise, view, --layers, --adaptive)
        cases = [
            ("set", None, None, "beauty", False, False),
            ("unset", None, None, "beauty", False, False),
            ("set", 2, None, "beauty", False, False),
            ("unset", 1, None, "beauty", False, False),
            ("set", None, "svgf", "beauty", False, False),
            ("unset", 2, "none", "beauty", False, False),
            ("set", None, "atrous", "beauty", False, False),
            ("set", None, None, "normal", False, False),
            ("unset", 2, "svgf", "depth", False, False),
            ("set", None, None, "beauty", True, False),
            ("unset", 2, None, "beauty", True, False),
            ("set", None, None, "beauty", False, True),
            ("unset", 4, "svgf", "beauty", False, True),
        ]
        for scene, spp, denoise, view, layers, adaptive in cases:
            out = os.path.join(tmp, "x.exr" if layers else "x.pfm")
            cmd = [args.sdfc, "render", scenes[scene], "-o", out, "--size", "8x8"]
            if spp is not None:
                cmd += ["--spp", str(spp)]
            if denoise is not None:
                cmd += ["--denoise", denoise]
            if view != "beauty":
                cmd += ["--view", view]
            if layers:
                cmd += ["--layers"]
            if adaptive:
                cmd += ["--adaptive"]
            what = " ".join(cmd[2:]).replace(tmp + os.sep, "")
            r = subprocess.run(cmd, capture_output=True, text=True, env=env)
            if r.returncode != 0:
                check(False, what, r.stderr)
                continue
            line = settings_line(r.stderr)
            check(line is not None, what + ": one settings line", r.stderr)
            if line is None:
                continue
            print("      " + line)
            if not layers and not adaptive:
                py = sdfc.load(scenes[scene]).render_settings(spp=spp, view=view, denoise=denoise)
                check(py["reason"] == line, what + ": Python's render_settings() says the same",
                      "python: " + py["reason"])
            wrote = re.search(r"sdfc: wrote .* \((\d+) spp in", r.stderr)
            if view == "beauty" and wrote and not adaptive:
                expected = spp if spp is not None else (4 if scene == "set" else 16)
                check(line.startswith(f"{expected} spp") and int(wrote.group(1)) in (expected, expected - 1),
                      what + f": {expected} spp chosen and rendered", r.stderr)
                denoised = re.search(r"denoised \((\w+);", r.stderr)
                chosen = re.search(r"\+ (\w+) denoiser", line)
                named = denoised.group(1) if denoised else None
                applies = chosen is not None and chosen.group(1) != "no" and "leaves a 1-spp image" not in line
                check(named == (chosen.group(1) if applies else None),
                      what + ": the denoiser chosen is the one applied", r.stderr)
            check(("adaptive" in line) == (adaptive and view == "beauty"), what + ": adaptive as asked", line)
        q = subprocess.run([args.sdfc, "render", scenes["set"], "-o", os.path.join(tmp, "q.pfm"), "--size",
                            "8x8", "--quiet"], capture_output=True, text=True, env=env)
        check(q.returncode == 0 and settings_line(q.stderr) is None and "settings" not in q.stderr,
              "--quiet prints no settings line", q.stderr)
        # An animation (--frames with more than one frame) takes nlr-fast unless --denoise
        # says otherwise, and each frame is the still rendered at its time with it.
        anim = os.path.join(tmp, "anim.sdf")
        with open(anim, "w") as f:
            f.write(SCENE.replace("sphere(radius: 1)", "sphere(radius: 0.8 + 0.2 * sin(time))")
                    .format(render="render(spp: 4)\n"))
        for denoise, expected in ((None, "nlr-fast"), ("nlr", "nlr")):
            cmd = [args.sdfc, "render", anim, "-o", os.path.join(tmp, "f.pfm"), "--size", "24x16",
                   "--frames", "0-1", "--fps", "4"] + (["--denoise", denoise] if denoise else [])
            what = " ".join(cmd[2:]).replace(tmp + os.sep, "")
            r = subprocess.run(cmd, capture_output=True, text=True, env=env)
            line = settings_line(r.stderr) if r.returncode == 0 else None
            check(line is not None and f"+ {expected} denoiser" in line, what + f": {expected} chosen", r.stderr)
            check(r.stderr.count(f"denoised ({expected};") == 2, what + f": both frames denoised with {expected}",
                  r.stderr)
        still = os.path.join(tmp, "still.pfm")
        r = subprocess.run([args.sdfc, "render", anim, "-o", still, "--size", "24x16", "--time", "0.25",
                            "--denoise", "nlr-fast"], capture_output=True, text=True, env=env)
        check(r.returncode == 0 and "denoised (nlr-fast;" in r.stderr, "a still with --denoise nlr-fast", r.stderr)
        subprocess.run([args.sdfc, "render", anim, "-o", os.path.join(tmp, "f.pfm"), "--size", "24x16",
                        "--frames", "0-1", "--fps", "4", "--quiet"], capture_output=True, env=env)
        frame1 = os.path.join(tmp, "f_0001.pfm")
        same = os.path.exists(frame1) and open(frame1, "rb").read() == open(still, "rb").read()
        check(same, "an animation's frame 1 is the still at its time with nlr-fast, byte for byte")
        # Python's render uses the chosen denoiser: its default equals denoise="nlr".
        s = sdfc.load(scenes["set"])
        a = s.render(size=(8, 8), spp=2)
        b = s.render(size=(8, 8), spp=2, denoise="nlr")
        check((a == b).all(), "Python's render: the default denoiser is the chosen one (nlr)")
    if failures:
        print(f"{len(failures)} failed")
        return 1
    print("all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
