#!/usr/bin/python3
"""What a colour field costs (issue 33's target: at most 10% of the castle's
samples per second).

    bench/field_cost.py [--sdfc build/cli/sdfc] [--reps 5] [--size 320x180] [--spp 32]
                        [--out bench/results/FIELD_COST.md]

Renders examples/castle.sdf as it is and with its materials' colours made
fields (the stone of the walls and towers 5-octave noise, the lawn a checker,
the slate roofs stripes, the gold a gradient: the most expensive field on most
of the image), alternating the cases run by run so both see the same machine
load, and reports the median samples per second of each (sdfc's own figure:
the passes alone, not the compile).
"""
import argparse
import os
import statistics
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import sdfbench as sb  # noqa: E402

CASTLE = os.path.join(ROOT, "examples", "castle.sdf")
FIELDS = {
    "let stone = diffuse(albedo: [0.72, 0.68, 0.6])":
        "let stone = diffuse(albedo: noise([0.55, 0.52, 0.46], [0.8, 0.76, 0.68], scale: 2, octaves: 5))",
    "let slate = diffuse(albedo: [0.3, 0.34, 0.46])":
        "let slate = diffuse(albedo: stripes([0.3, 0.34, 0.46], [0.24, 0.27, 0.38], axis: [0, 1, 0], period: 0.2))",
    "let lawn = diffuse(albedo: [0.33, 0.48, 0.22])":
        "let lawn = diffuse(albedo: checker([0.33, 0.48, 0.22], [0.28, 0.42, 0.18], size: 1))",
    "let gold = metal(albedo: [1.0, 0.78, 0.34], roughness: 0.3)":
        "let gold = metal(albedo: gradient([1.0, 0.78, 0.34], [0.9, 0.6, 0.3], from: 0, to: 6), roughness: 0.3)",
}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--size", default="320x180")
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--out", default=os.path.join(HERE, "results", "FIELD_COST.md"))
    args = p.parse_args()
    with open(CASTLE) as f:
        text = f.read()
    fielded = text
    for old, new in FIELDS.items():
        assert old in fielded, old
        fielded = fielded.replace(old, new)
    speeds = {"castle": [], "castle with fields": []}
    with tempfile.TemporaryDirectory(prefix="sdfc field cost ") as tmp:
        scenes = {"castle": CASTLE, "castle with fields": os.path.join(tmp, "castle fields.sdf")}
        with open(scenes["castle with fields"], "w") as f:
            f.write(fielded)
        out = os.path.join(tmp, "out.pfm")
        flags = ["--size", args.size, "--spp", str(args.spp)]
        for rep in range(args.reps):
            order = list(scenes) if rep % 2 == 0 else list(scenes)[::-1]
            for name in order:
                info = sb.render(args.sdfc, scenes[name], out, flags)
                speeds[name].append(info["spp_per_s"])
                print(f"rep {rep} {name}: {info['spp_per_s']:.3f} spp/s", flush=True)
    base = statistics.median(speeds["castle"])
    with_fields = statistics.median(speeds["castle with fields"])
    cost = 1 - with_fields / base
    # Each repetition ran both cases back to back: their ratio sees one load.
    paired = statistics.median(f / c for f, c in zip(speeds["castle with fields"], speeds["castle"]))
    load = os.getloadavg()
    lines = [
        "# What a colour field costs (issue 33)",
        "",
        f"`bench/field_cost.py --reps {args.reps} --size {args.size} --spp {args.spp}`: the castle as it is",
        "and with its four materials' colours made fields (stone 5-octave noise, slate stripes, lawn",
        "a checker, gold a gradient), alternated run by run; sdfc's samples per second (passes only).",
        f"Load average at the end: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} (2 CPUs, lavapipe).",
        "",
        "| scene | median spp/s | runs |",
        "|---|---|---|",
        f"| castle | {base:.3f} | {', '.join(f'{v:.3f}' for v in speeds['castle'])} |",
        f"| castle with fields | {with_fields:.3f} | {', '.join(f'{v:.3f}' for v in speeds['castle with fields'])} |",
        "",
        f"Cost of the fields: {100 * cost:.1f}% of the castle's samples per second from the medians, "
        f"{100 * (1 - paired):.1f}% from the median of the per-repetition ratios (target: at most 10%).",
        "",
    ]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
