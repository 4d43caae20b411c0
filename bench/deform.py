#!/usr/bin/env python3
"""bench/DEFORM.md: the examples that use displace / morph / bend / twist, and
bench/deform/displace_octaves.sdf, rendered by two sdfc binaries (before,
after) interleaved in the same run: primary steps (the mean and max a beauty
render prints), spp/s of a beauty render (median of rounds), and the depth view
compared pixel by pixel (hit/miss agreement, depth difference).

usage: deform.py BEFORE_SDFC AFTER_SDFC [--rounds N] [--size WxH] [--spp N]
"""
import argparse, os, re, statistics, subprocess, sys, tempfile
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["examples/deformations.sdf", "bench/deform/displace_octaves.sdf", "bench/deform/bend_off_axis.sdf",
          "examples/morph.sdf",
          "examples/profiles_and_twist.sdf"]


def run(sdfc, scene, out, *args):
    r = subprocess.run([sdfc, "render", os.path.join(ROOT, scene), "-o", out, *args],
                       capture_output=True, text=True, timeout=600)
    if r.returncode:
        sys.exit(f"{sdfc} {scene}: {r.stderr}")
    return r.stderr + r.stdout


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3 if kind == b"PF" else 1)[..., 0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--size", default="480x270")
    ap.add_argument("--spp", default="8")
    ap.add_argument("--time", default="0.7")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp()
    rows = []
    for scene in SCENES:
        steps, rate, depth = {}, {"before": [], "after": []}, {}
        for name, exe in (("before", a.before), ("after", a.after)):
            run(exe, scene, f"{tmp}/{name}_depth.pfm", "--view", "depth", "--size", a.size, "--time", a.time, "-q")
            depth[name] = read_pfm(f"{tmp}/{name}_depth.pfm")
        for _ in range(a.rounds):
            for name, exe in (("before", a.before), ("after", a.after)):
                text = run(exe, scene, f"{tmp}/{name}.png", "--size", a.size, "--spp", a.spp, "--time", a.time, "--denoise", "none")
                m = re.search(r"([0-9.]+) spp/s", text)
                rate[name].append(float(m.group(1)))
                m = re.search(r"primary ray steps: mean ([0-9.]+), max ([0-9.]+)", text)
                steps[name] = (float(m.group(1)), float(m.group(2)))
        b, f = depth["before"], depth["after"]
        hit_b, hit_f = np.isfinite(b) & (b > 0) & (b < 1e9), np.isfinite(f) & (f > 0) & (f < 1e9)
        both = hit_b & hit_f
        diff = float(np.max(np.abs(b[both] - f[both]))) if both.any() else 0.0
        rows.append((scene, steps["before"], steps["after"], statistics.median(rate["before"]),
                     statistics.median(rate["after"]), int(np.sum(hit_b != hit_f)), int(hit_b.sum()), diff))
    print(f"size {a.size}, {a.spp} spp, time {a.time}, {a.rounds} interleaved rounds, medians")
    print("| scene | primary steps mean (max) before | after | spp/s before | after | x | hit/miss differ | hits | max depth diff |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s, sb, sa, rb, ra, off, hits, diff in rows:
        print(f"| {s} | {sb[0]:.2f} ({sb[1]:g}) | {sa[0]:.2f} ({sa[1]:g}) | {rb:.3f} | {ra:.3f} | {ra / rb:.2f} | {off} | {hits} | {diff:.2e} |")


if __name__ == "__main__":
    main()
