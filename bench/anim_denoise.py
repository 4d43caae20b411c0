#!/usr/bin/env python3
"""An animation's denoise: its share of the frame time, and its error (issue 48's last target).

    /usr/bin/python3 bench/anim_denoise.py [--reps 3] [--frames 0-23] [--spp 8]

Part 1, the share: `sdfc render examples/morph.sdf --size 320x180 --spp 8 --frames 0-23 --timings`
with the animation's default (nlr-fast), with --denoise nlr (the default before) and with
--denoise none, interleaved rep by rep. Per run: the process's wall and CPU seconds (wait4),
and per frame (--timings) the passes, readback, denoise and PNG writing; the share is the
denoise over their sum, the median over the frames; also the wall the filter adds to the
whole run against --denoise none.

Part 2, the error: stills of morph at times 0, 0.75 and 1.5 s (320x180, seed 7) at 8, 12
and 16 spp with nlr and nlr-fast, relMSE and FLIP against 1024-spp references (rendered once,
cached in bench/cache); with the CPU ms a frame costs (the samples' CPU per spp measured in
part 1 from --denoise none at --spp and 2x --spp, plus the filter's), so that the two filters
compare by time to an error.

Writes results/ANIM_DENOISE.md and results/anim_denoise.csv under --out.
"""
import argparse
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import flip  # noqa: E402
import sdfbench as sb  # noqa: E402

SCENE = os.path.join(ROOT, "examples", "morph.sdf")
TIMES = ["0", "0.75", "1.5"]


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def render(sdfc, args):
    start = time.perf_counter()
    proc = subprocess.Popen([sdfc, "render", SCENE] + args, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"sdfc render {args} failed:\n{err}")
    return wall, usage.ru_utime + usage.ru_stime, err


def median(xs):
    return statistics.median(xs) if xs else 0.0


def animation_run(sdfc, work, spp, frames, denoise):
    flags = ["-o", os.path.join(work, "f.png"), "--size", "320x180", "--spp", str(spp), "--frames", frames,
             "--fps", "24", "--seed", "7", "--timings"] + (["--denoise", denoise] if denoise else [])
    wall, cpu, err = render(sdfc, flags)
    chosen = re.search(r"settings: .*? \+ (no|[\w-]+) denoiser", err)
    den_cpu = [int(b) for b in re.findall(r"denoised \([\w-]+\) in \d+ ms \((\d+) CPU ms\)", err)]
    # --timings: each frame's stages in ms; the frame is their sum.
    stages = {}
    for stage, frame, ms in re.findall(r"^\s+(passes|readback|denoise|encoding and writing) \(frame (\d+)\)\s+([0-9.]+)",
                                       err, re.M):
        stages.setdefault(int(frame), {})[stage] = float(ms)
    samples = [f.get("passes", 0) + f.get("readback", 0) for f in stages.values()]
    den = [f.get("denoise", 0) for f in stages.values()]
    frame = [sum(f.values()) for f in stages.values()]
    share = [d / t for d, t in zip(den, frame) if t > 0]
    return {"denoiser": denoise or "default", "chosen": {"no": "none"}.get(chosen.group(1), chosen.group(1))
            if chosen else "?", "spp": spp, "wall_s": wall, "cpu_s": cpu, "frames": len(stages),
            "samples_ms": median(samples), "denoise_ms": median(den), "denoise_cpu_ms": median(den_cpu),
            "frame_ms": median(frame), "share": median(share)}


def reference(sdfc, cache, t, ref_spp):
    path = os.path.join(cache, f"ref_morph_t{t}_320x180_{ref_spp}spp.pfm")
    if not os.path.exists(path):
        log(f"rendering the reference at t={t} ({ref_spp} spp)")
        render(sdfc, ["-o", path, "--size", "320x180", "--spp", str(ref_spp), "--denoise", "none",
                      "--time", t, "--quiet"])
    return sb.read_pfm(path)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--frames", default="0-23")
    p.add_argument("--spp", type=int, default=8)
    p.add_argument("--error-spp", nargs="+", type=int, default=[8, 12, 16])
    p.add_argument("--ref-spp", type=int, default=1024)
    p.add_argument("--cache", default=os.path.join(HERE, "cache"))
    p.add_argument("--out", default=HERE)
    args = p.parse_args()
    start, load_start = time.time(), os.getloadavg()[0]
    work = tempfile.mkdtemp(prefix="anim_denoise_")
    os.makedirs(args.cache, exist_ok=True)

    # Part 1: interleaved, rep by rep.
    runs = []
    configs = [("", args.spp), ("nlr", args.spp), ("none", args.spp), ("none", 2 * args.spp)]
    for rep in range(args.reps):
        for denoise, spp in configs:
            r = animation_run(args.sdfc, work, spp, args.frames, denoise)
            r["rep"] = rep
            runs.append(r)
            log(f"rep {rep} {r['denoiser']:8s} ({r['chosen']}) {spp:3d} spp: {r['wall_s']:.2f} s wall, "
                f"{r['cpu_s']:.2f} CPU s; per frame {r['frame_ms']:.0f} ms: samples {r['samples_ms']:.0f} ms, denoise "
                f"{r['denoise_ms']:.0f} ms ({r['denoise_cpu_ms']:.0f} CPU ms), share {100 * r['share']:.0f}%")

    def med(denoise, spp, key):
        return median([r[key] for r in runs if r["denoiser"] == (denoise or "default") and r["spp"] == spp])

    frames = max(r["frames"] for r in runs)
    # The samples' CPU per spp and frame: --denoise none at 2x --spp against --spp.
    cpu_per_spp_ms = 1000 * (med("none", 2 * args.spp, "cpu_s") - med("none", args.spp, "cpu_s")) / frames / args.spp
    samples_cpu_ms = lambda spp: cpu_per_spp_ms * spp  # noqa: E731

    # Part 2: the error of the two filters at a few spp.
    refs = {t: reference(args.sdfc, args.cache, t, args.ref_spp) for t in TIMES}
    errors = []
    for denoise in ("nlr", "nlr-fast"):
        for spp in args.error_spp:
            rel, fl, cpu = [], [], []
            for t in TIMES:
                out = os.path.join(work, "x.pfm")
                _, _, err = render(args.sdfc, ["-o", out, "--size", "320x180", "--spp", str(spp), "--denoise",
                                               denoise, "--time", t, "--seed", "7"])
                m = re.search(r"denoised \([\w-]+\) in \d+ ms \((\d+) CPU ms\)", err)
                cpu.append(int(m.group(1)) if m else 0)
                img = sb.read_pfm(out)
                rel.append(sb.relmse(img, refs[t]))
                fl.append(flip.mean_flip(img, refs[t]))
            row = {"denoiser": denoise, "spp": spp, "relmse": statistics.mean(rel), "flip": statistics.mean(fl),
                   "denoise_cpu_ms": median(cpu)}
            row["frame_cpu_ms"] = samples_cpu_ms(spp) + row["denoise_cpu_ms"]
            errors.append(row)
            log(f"{denoise:8s} {spp:3d} spp: relMSE {row['relmse']:.3g}, FLIP {row['flip']:.4f}, "
                f"filter {row['denoise_cpu_ms']:.0f} CPU ms, frame ~{row['frame_cpu_ms']:.0f} CPU ms")

    os.makedirs(os.path.join(args.out, "results"), exist_ok=True)
    with open(os.path.join(args.out, "results", "anim_denoise.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(runs[0]))
        writer.writeheader()
        writer.writerows(runs)
    cmd = " ".join(a.replace(ROOT + os.sep, "") for a in sys.argv[1:])
    # Above the cores' count, other work shared them: the filter's threads waited.
    machine = ("an otherwise idle machine: the wall figures hold" if max(load_start, os.getloadavg()[0]) < os.cpu_count()
               else "a shared machine: the CPU figures hold, the wall figures are inflated")
    lines = ["# An animation's denoise: share of the frame time, and error", "",
             f"Generated by `bench/anim_denoise.py {cmd}` in {(time.time() - start) / 60:.1f} min, load average "
             f"{load_start:.1f} at the start and {os.getloadavg()[0]:.1f} at the end ({machine}). "
             f"morph.sdf, 320x180, {args.spp} spp, frames {args.frames} at 24 fps, seed 7; "
             f"medians of {args.reps} interleaved runs. Data: results/anim_denoise.csv.", "",
             "| --denoise | chose | run wall s | run CPU s | frame ms | samples ms | denoise ms | "
             "denoise CPU ms | denoise share of the frame | run wall added against none |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    none_wall = med("none", args.spp, "wall_s")
    for denoise in ("", "nlr", "none"):
        chosen = next(r["chosen"] for r in runs if r["denoiser"] == (denoise or "default"))
        wall = med(denoise, args.spp, "wall_s")
        lines.append(f"| {denoise or '(default)'} | {chosen} | {wall:.2f} | {med(denoise, args.spp, 'cpu_s'):.2f} | "
                     f"{med(denoise, args.spp, 'frame_ms'):.0f} | {med(denoise, args.spp, 'samples_ms'):.0f} | "
                     f"{med(denoise, args.spp, 'denoise_ms'):.0f} | {med(denoise, args.spp, 'denoise_cpu_ms'):.0f} | "
                     f"{100 * med(denoise, args.spp, 'share'):.0f}% | "
                     f"{100 * (wall - none_wall) / wall if denoise != 'none' else 0:.0f}% |")
    lines += ["", "Per frame, medians over the frames of a run, then over the runs (sdfc --timings): the frame "
              "is its passes, readback, denoise and PNG writing; samples = passes + readback; the share is "
              "denoise over the frame. The last column: the whole run's wall against --denoise none's "
              "(startup included).", "",
              f"Error against {args.ref_spp}-spp references (mean over t = {', '.join(TIMES)} s), and the "
              f"CPU ms a frame costs: the samples' {cpu_per_spp_ms:.1f} CPU ms per spp (part 1's none runs) "
              "plus the filter's CPU ms:", "",
              "| denoiser | spp | relMSE | FLIP | filter CPU ms | frame CPU ms |", "|---|---|---|---|---|---|"]
    lines += [f"| {r['denoiser']} | {r['spp']} | {r['relmse']:.3g} | {r['flip']:.4f} | {r['denoise_cpu_ms']:.0f} | "
              f"{r['frame_cpu_ms']:.0f} |" for r in errors]
    with open(os.path.join(args.out, "results", "ANIM_DENOISE.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
