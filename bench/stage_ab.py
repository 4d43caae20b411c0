#!/usr/bin/python3
"""Paired A/B of sdfc binaries on one scene: whole-process CPU and wall, and --timings stages.

    bench/stage_ab.py REPS SCENE SDFC_A SDFC_B [...]   (env: AB_SIZE=640x360, AB_SPP=1,
                                                       AB_FLAGS="...", SDFC_DRIVER)

Runs `sdfc render SCENE --size AB_SIZE --spp AB_SPP --timings` with Mesa's shader
cache off, alternating the binaries run by run (the order reversed every other
repetition), after one unrecorded run each that fills a shared sdfc cache (so the
figures are "warm"). Prints medians: CPU seconds (user + system, the firmer figure
on a loaded machine), wall seconds and the main stages in ms. Used for the levers in
bench/results/fixed_costs.md.
"""
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

STAGES = ("device", "pipeline", "first", "passes", "readback", "encoding", "total")


def main():
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    reps, scene, bins = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
    extra = os.environ.get("AB_FLAGS", "").split()
    with tempfile.TemporaryDirectory() as work:
        env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true", XDG_CACHE_HOME=os.path.join(work, "cache"))
        res = {b: {"cpu": [], "wall": [], "stages": {}} for b in bins}
        for rep in range(reps + 1):
            for b in (bins if rep % 2 == 0 else bins[::-1]):
                cmd = [b, "render", scene, "-o", os.path.join(work, "x.png"), "--size",
                       os.environ.get("AB_SIZE", "640x360"), "--spp", os.environ.get("AB_SPP", "1"),
                       "--timings"] + extra
                used = resource.getrusage(resource.RUSAGE_CHILDREN)
                start = time.perf_counter()
                r = subprocess.run(cmd, env=env, capture_output=True, text=True)
                wall = time.perf_counter() - start
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                if r.returncode:
                    sys.stderr.write(r.stderr)
                    raise SystemExit(f"{' '.join(cmd)} exited {r.returncode}")
                if rep == 0:
                    continue  # fills the cache
                res[b]["cpu"].append(after.ru_utime - used.ru_utime + after.ru_stime - used.ru_stime)
                res[b]["wall"].append(wall)
                for m in re.finditer(r"^  (.+?)\s+(-?[0-9.]+)\s", r.stderr, re.M):
                    res[b]["stages"].setdefault(m.group(1).strip(), []).append(float(m.group(2)))
    print(f"load average {os.getloadavg()[0]:.1f}, {reps} alternating runs, medians")
    for b in bins:
        stages = "  ".join(f"{k.split(' (')[0]} {statistics.median(v):.1f}"
                           for k, v in res[b]["stages"].items() if k.split()[0] in STAGES)
        print(f"{b}: CPU {statistics.median(res[b]['cpu']):.3f} s, wall {statistics.median(res[b]['wall']):.3f} s; ms: {stages}")


if __name__ == "__main__":
    main()
