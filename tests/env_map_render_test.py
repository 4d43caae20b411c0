#!/usr/bin/env python3
"""The environment light sky(map: ...) in the image (issue 33):

- white furnace: a white diffuse sphere (albedo 1) inside a constant map of
  radiance 1 renders 1 everywhere within noise (EXR and .hdr maps, rotated);
- the map seen directly (0 bounces) is the map, bilinear with texel (i, j)
  at u = i / (W - 1), v = j / (H - 1), y up, u = atan2(x, -z) / 2 pi,
  turned by rotation about +y (Mitsuba 3's layout);
- next-event estimation with MIS and BSDF sampling alone (--light-samples 0)
  agree in the mean on a studio map with a sharp key light, and on a map
  large enough to be sampled on a coarser grid than its texels.

    /usr/bin/python3 tests/env_map_render_test.py [--sdfc build/cli/sdfc]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import envmap  # noqa: E402
import sdfbench as sb  # noqa: E402

W, H = 64, 36
failures = 0


def check(ok, what):
    global failures
    print(("ok    " if ok else "FAIL  ") + what)
    failures += not ok


def render(sdfc, scene, out, *flags):
    subprocess.run([sdfc, "render", scene, "-o", out, "--denoise", "none", "-q"] + list(flags), check=True)
    return sb.read_pfm(out)


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def furnace(sdfc, tmp):
    envmap.write_exr(os.path.join(tmp, "white map.exr"), np.ones((4, 8, 3), np.float32))
    envmap.write_hdr(os.path.join(tmp, "white map.hdr"), np.ones((4, 8, 3), np.float32))
    for name, sky in [("exr", 'sky(map: "white map.exr")'), ("hdr rotated", 'sky(map: "white map.hdr", rotation: 40)')]:
        scene = os.path.join(tmp, f"furnace {name}.sdf")
        write(scene, f"""render(size: [{W}, {H}], spp: 16, bounces: 3)
camera(position: [0, 0, 4], target: [0, 0, 0], fov: 35)
{sky}
scene {{ sphere(radius: 1, material: diffuse(albedo: [1, 1, 1])) }}
""")
        img = render(sdfc, scene, os.path.join(tmp, f"furnace {name}.pfm"))
        mean, worst = float(img.mean()), float(np.abs(img - 1).max())
        rms = float(np.sqrt(np.mean((img - 1) ** 2)))
        # 16 spp of NEE + MIS: per-pixel noise about 0.03, no pixel biased.
        check(abs(mean - 1) < 0.005 and rms < 0.05 and worst < 0.25,
              f"furnace ({name}): mean {mean:.4f} (1 within 0.5%), RMS {rms:.4f} (< 0.05), "
              f"worst pixel off by {worst:.3f} (< 0.25)")


def seen_directly(sdfc, tmp, w=64):
    rgb = envmap.studio(w)
    name = "studio.exr" if w == 64 else f"studio {w}.exr"
    envmap.write_exr(os.path.join(tmp, name), rgb)
    cam = {"position": np.array([0.0, 0.3, 0.0]), "target": np.array([1.0, 0.5, -0.4]),
           "up": np.array([0, 1, 0.0]), "fov": 60.0, "aperture": 0.0}
    scene = os.path.join(tmp, "direct.sdf")
    write(scene, f"""render(size: [{W}, {H}], spp: 32, bounces: 0)
camera(position: [0, 0.3, 0], target: [1, 0.5, -0.4], fov: 60)
sky(map: "{name}", rotation: 90, strength: 0.5)
scene {{ translate([0, -50, 0]) {{ sphere(radius: 0.1) }} }}
""")
    img = render(sdfc, scene, os.path.join(tmp, "direct.pfm"))
    _, rd = sb.camera_rays(cam, W, H)
    a = np.radians(90)
    # World to the map's frame: the inverse of a turn by a about +y.
    x = np.cos(a) * rd[..., 0] - np.sin(a) * rd[..., 2]
    z = np.sin(a) * rd[..., 0] + np.cos(a) * rd[..., 2]
    u = np.mod(np.arctan2(x, -z) / (2 * np.pi), 1.0)
    v = np.arccos(np.clip(rd[..., 1], -1, 1)) / np.pi
    # Texel (i, j) at u = i / (w - 1), v = j / (h - 1), as Mitsuba 3.
    s, t = u * (w - 1), v * (w // 2 - 1)
    x0, y0 = np.minimum(s.astype(int), w - 2), np.minimum(t.astype(int), w // 2 - 2)
    fs, ft = (s - x0)[..., None], (t - y0)[..., None]
    x1, y1 = x0 + 1, y0 + 1
    want = 0.5 * ((rgb[y0, x0] * (1 - fs) + rgb[y0, x1] * fs) * (1 - ft) + (rgb[y1, x0] * (1 - fs) + rgb[y1, x1] * fs) * ft)
    rel = np.abs(img - want) / np.maximum(want, 1e-3)
    check(float(np.median(rel)) < 0.01 and float(img.max()) > 1.0,
          f"map seen directly ({w} x {w // 2}): median relative error {np.median(rel):.4f} (< 1%), brightest {img.max():.2f} "
          "(the key light is in view)")


def mis_against_bsdf(sdfc, tmp, map_name="studio.exr", what=""):
    scene = os.path.join(tmp, f"studio scene {map_name}.sdf")
    write(scene, f"""render(size: [{W}, {H}], spp: 64, bounces: 2)
camera(position: [0, 1.2, 4.5], target: [0, 0.6, 0], fov: 40)
sky(map: "{map_name}", rotation: 30)
scene {{
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.5, 0.5, 0.5]))
  translate([0, 0.7, 0]) {{ sphere(radius: 0.7, material: diffuse(albedo: [0.8, 0.3, 0.25])) }}
}}
""")
    nee = render(sdfc, scene, os.path.join(tmp, "nee.pfm"))
    bsdf = render(sdfc, scene, os.path.join(tmp, "bsdf.pfm"), "--light-samples", "0", "--spp", "256")
    ratio = float(nee.mean() / bsdf.mean())
    # Blocks of 16 x 12 pixels: the two strategies agree in each.
    bn = nee.reshape(3, 12, 4, 16, 3).mean(axis=(1, 3))
    bb = bsdf.reshape(3, 12, 4, 16, 3).mean(axis=(1, 3))
    block = float(np.abs(bn / bb - 1).max())
    check(abs(ratio - 1) < 0.02 and block < 0.08,
          f"NEE + MIS against BSDF sampling alone{what}: mean ratio {ratio:.4f} (1 within 2%), worst block {block:.3f}")


def coarse_grid(sdfc, tmp):
    # 1039 x 519 texel cells sampled on a 512 x 256 grid whose cells cover
    # parts of texel cells (eval/env_map.h): the kernel's draws and pdf agree.
    envmap.write_exr(os.path.join(tmp, "studio 1040.exr"), envmap.studio(1040))
    mis_against_bsdf(sdfc, tmp, "studio 1040.exr", " (a 1040 x 520 map, coarse sampling grid)")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="sdfc env map ") as tmp:
        furnace(args.sdfc, tmp)
        seen_directly(args.sdfc, tmp)
        seen_directly(args.sdfc, tmp, 10)  # a small map of odd size
        mis_against_bsdf(args.sdfc, tmp)
        coarse_grid(args.sdfc, tmp)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
