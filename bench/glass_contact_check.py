#!/usr/bin/env python3
"""Glass resting on a surface against Mitsuba 3 (docs/design/glass_contact.md).

mitsuba_check.py's scene `glass_resting` (a glass block on a diffuse table and
one on the ground plane) in sdfc and in Mitsuba 3 (scalar_rgb), compared over
the lower half of each block's pixels, where light inside the glass meets the
face it rests on: the mean there and the worst of its four column strips, each
with its difference in standard errors. The blocks' pixels are those whose
primary hit is glass (`--view albedo` is 1, 1, 1 there: untinted glass).

    /tmp/venv/bin/python bench/glass_contact_check.py [check|reference|test] [--sdfc build/cli/sdfc]
        [--size 160x120] [--spp 256] [--mitsuba-spp 1024] [--bounces 6]
        [--cache DIR]   keep Mitsuba's renders there (keyed by scene and settings)
    check       both renderers now, the figures in bench/RESULTS.md
    reference   Mitsuba's block means at 64x36 -> tests/glass_contact_reference.json
    test        sdfc at 64x36 against that file (CTest; no Mitsuba needed)
"""
import json
import argparse
import hashlib
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import mitsuba_check as mc  # noqa: E402

SCENE = "glass_resting"
MITSUBA_GAPS = (1e-4, 3e-3)  # the blocks' gaps in mitsuba_check.py (the cache key)
REFERENCE_JSON = os.path.join(HERE, "..", "tests", "glass_contact_reference.json")
TEST_SIZE = (64, 36)


def mitsuba_pair(w, h, spp, bounces, cache):
    key = hashlib.sha256(repr((mc.SCENES[SCENE]["sdf"], w, h, spp, bounces, mc.CAMERA, MITSUBA_GAPS)).encode()).hexdigest()[:12]
    path = os.path.join(cache, f"mitsuba_{SCENE}_{key}.npz") if cache else None
    if path and os.path.exists(path):
        d = np.load(path)
        return d["a"], d["b"]
    a, _, _ = mc.render_mitsuba(SCENE, w, h, spp, bounces, 1)
    b, _, _ = mc.render_mitsuba(SCENE, w, h, spp, bounces, 2)
    if path:
        os.makedirs(cache, exist_ok=True)
        np.savez(path, a=a, b=b)
    return a, b


def block_masks(sdfc, scene_path, tmp):
    out = os.path.join(tmp, "albedo.pfm")
    subprocess.run([sdfc, "render", scene_path, "--view", "albedo", "-o", out], check=True, capture_output=True)
    albedo = mc.read_pfm(out)
    glass = np.all(np.abs(albedo - 1.0) < 1e-6, axis=2)
    w = glass.shape[1]
    masks = {}
    for name, cols in (("on the table", slice(0, w // 2)), ("on the ground", slice(w // 2, w))):
        m = np.zeros_like(glass)
        m[:, cols] = glass[:, cols]
        rows = np.nonzero(m.any(axis=1))[0]
        lower = np.zeros_like(m)
        mid = (rows.min() + rows.max() + 1) // 2
        lower[mid:] = m[mid:]
        masks[name] = lower
        if name == "on the ground":
            # Its top face, seen at a grazing angle, shows the ground under it.
            upper = m.copy()
            upper[mid:] = False
            masks[name + ", upper half"] = upper
    return masks


def region(a1, a2, mask):
    """Mean over the masked pixels of two independent renders and its standard error."""
    x1, x2 = a1[mask], a2[mask]
    mean = 0.5 * (x1.mean(axis=0) + x2.mean(axis=0))
    se = (x1 - x2).std(axis=0) / 2 / np.sqrt(max(len(x1), 1))
    return mean, se


def sdfc_blocks(sdfc, w, h, spp, bounces):
    """sdfc's pair of renders and the blocks' lower-half masks."""
    with tempfile.TemporaryDirectory() as tmp:
        (s1, _, _), (s2, _, _) = mc.sdfc_pair(sdfc, SCENE, w, h, spp, bounces, tmp)
        masks = block_masks(sdfc, os.path.join(tmp, f"{SCENE}.sdf"), tmp)
    return s1, s2, masks


def cmd_reference(args):
    w, h = TEST_SIZE
    m1, m2 = mitsuba_pair(w, h, args.mitsuba_spp, args.bounces, args.cache)
    _, _, masks = sdfc_blocks(args.sdfc, w, h, 1, args.bounces)
    import mitsuba as mi
    data = {"mitsuba": mi.__version__, "variant": "scalar_rgb", "spp": args.mitsuba_spp, "width": w,
            "height": h, "bounces": args.bounces, "scene": mc.sdf_source(SCENE, w, h, 0, args.bounces),
            "blocks": {}}
    for name, mask in masks.items():
        mean, se = region(m1, m2, mask)
        data["blocks"][name] = {"mask": np.flatnonzero(mask).tolist(), "mean": mean.tolist(),
                                "standard_error": se.tolist()}
        print(f"{name}: {mean} +- {se}")
    with open(REFERENCE_JSON, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    print("wrote", REFERENCE_JSON)
    return 0


def cmd_test(args):
    """sdfc's block means against the stored Mitsuba ones: within 4 combined
    standard errors and 2% (the old floor-shaded contact was 16-26% dark)."""
    with open(REFERENCE_JSON) as f:
        ref = json.load(f)
    w, h, bounces = ref["width"], ref["height"], ref["bounces"]
    if ref["scene"] != mc.sdf_source(SCENE, w, h, 0, bounces):
        print(f"the scene changed since the reference was rendered; run `{sys.argv[0]} reference`")
        return 1
    s1, s2, _ = sdfc_blocks(args.sdfc, w, h, args.spp, bounces)
    failures = 0
    for name, r in ref["blocks"].items():
        mask = np.zeros(w * h, dtype=bool)
        mask[r["mask"]] = True
        mask = mask.reshape(h, w)
        a, ea = region(s1, s2, mask)
        b, eb = np.array(r["mean"]), np.array(r["standard_error"])
        d = (a - b) / b * 100
        z = mc.z_scores(a, ea, b, eb)
        ok = bool(np.all((z < 4) | (np.abs(d) < 2)))
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} block {name}: sdfc {np.array2string(a, precision=4)} Mitsuba "
              f"{np.array2string(b, precision=4)}: {np.array2string(d, precision=2)} % "
              f"({np.array2string(z, precision=1)} s.e.)")
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", nargs="?", default="check", choices=["check", "reference", "test"])
    ap.add_argument("--sdfc", default=os.path.join(HERE, "..", "build", "cli", "sdfc"))
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--mitsuba-spp", type=int, default=1024)
    ap.add_argument("--bounces", type=int, default=6)
    ap.add_argument("--cache", default=None)
    args = ap.parse_args()
    if args.command == "reference":
        return cmd_reference(args)
    if args.command == "test":
        return cmd_test(args)
    w, h = map(int, args.size.split("x"))
    s1, s2, masks = sdfc_blocks(args.sdfc, w, h, args.spp, args.bounces)
    m1, m2 = mitsuba_pair(w, h, args.mitsuba_spp, args.bounces, args.cache)
    ms, ses = mc.mean_and_error(s1, s2)
    mm, sem = mc.mean_and_error(m1, m2)
    print(f"{SCENE} {w}x{h}, {args.bounces} bounces; sdfc {args.spp} spp, Mitsuba {args.mitsuba_spp} spp")
    print(f"whole image: difference {np.array2string((ms - mm) / mm * 100, precision=2)} %, "
          f"{np.array2string(mc.z_scores(ms, ses, mm, sem), precision=1)} s.e.")
    worst = 0.0
    for name, mask in masks.items():
        a, ea = region(s1, s2, mask)
        b, eb = region(m1, m2, mask)
        d = (a - b) / b * 100
        z = mc.z_scores(a, ea, b, eb)
        cols = np.nonzero(mask.any(axis=0))[0]
        strips = np.array_split(cols, 4)
        strip_d = []
        for c in strips:
            sm = np.zeros_like(mask)
            sm[:, c] = mask[:, c]
            sa, _ = region(s1, s2, sm)
            sb, _ = region(m1, m2, sm)
            strip_d.append(float(np.max(np.abs((sa - sb) / sb)) * 100))
        worst = max(worst, max(strip_d))
        print(f"block {name}, lower half ({int(mask.sum())} px): sdfc {np.array2string(a, precision=4)} "
              f"Mitsuba {np.array2string(b, precision=4)}: {np.array2string(d, precision=2)} % "
              f"({np.array2string(z, precision=1)} s.e.); worst column strip {max(strip_d):.2f} %")
    print(f"worst strip over the blocks' lower halves: {worst:.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
