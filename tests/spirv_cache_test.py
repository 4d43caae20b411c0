#!/usr/bin/env python3
"""The on-disk SPIR-V cache through the real command (compiler/spirv/spirv_cache.h).

Every run points XDG_CACHE_HOME at a fresh temporary directory, so no user's
cache is read or written. Asserts: the first render stores one entry and the
second is a hit with the same SPIR-V (`compile --emit spv`) and the same image;
a corrupt entry (garbage, truncated, a flipped word) is ignored, the image is the
same and the entry is replaced by a valid one; `--no-cache` neither reads nor
writes the cache; four renders started at once on an empty cache all succeed
with one image, leaving one valid entry and no temporaries; HOME is used
when XDG_CACHE_HOME is unset; `render --timings` lists the stages.
"""
import filecmp
import glob
import os
import subprocess
import sys
import tempfile

SDFC = sys.argv[1]
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


SCENE = """render(size: [32, 18], spp: 1, bounces: 1)
camera(position: [0, 1, 4], target: [0, 0.5, 0], fov: 40)
scene {
  plane(normal: [0, 1, 0], offset: 0)
  translate([0, 0.6, 0]) { sphere(radius: 0.6) }
}
"""


def run(args, cache, extra_env=None):
    env = dict(os.environ, XDG_CACHE_HOME=cache, SDFC_VALIDATION="1", LP_NUM_THREADS="1")
    if extra_env:
        env.update(extra_env)
    return subprocess.run([SDFC] + args, env=env, capture_output=True, text=True, timeout=120)


def entries(cache):
    return sorted(glob.glob(os.path.join(cache, "sdfc", "spirv", "*.spv")))


def kernel_entry(cache):
    """The scene's kernel: the largest entry (the other is the full-screen vertex shader's)."""
    return max(entries(cache), key=os.path.getsize)


def leftovers(cache):
    return [p for p in glob.glob(os.path.join(cache, "sdfc", "spirv", "*")) if not p.endswith(".spv")]


def main():
    with tempfile.TemporaryDirectory(prefix="sdfc cache ") as d:  # a path with a space
        scene = os.path.join(d, "my scene.sdf")
        open(scene, "w").write(SCENE)
        cache = os.path.join(d, "cache")
        j = lambda name: os.path.join(d, name)

        # Miss, then hit: the same SPIR-V and the same image.
        r = run(["render", scene, "-o", j("miss.png")], cache)
        check(r.returncode == 0, f"first render exits 0 ({r.returncode}) {r.stderr[-300:]}")
        check("from the cache" not in r.stderr, "first render compiles (an empty cache)")
        check(len(entries(cache)) == 2, f"first render stores the kernel and the vertex shader ({entries(cache)})")
        r = run(["render", scene, "-o", j("hit.png")], cache)
        check(r.returncode == 0 and "from the cache" in r.stderr, "second render is a cache hit")
        check(filecmp.cmp(j("miss.png"), j("hit.png"), shallow=False), "a hit gives the same image")
        r1 = run(["compile", scene, "--emit", "spv", "-o", j("hit.spv")], cache)
        r2 = run(["compile", scene, "--emit", "spv", "--no-cache", "-o", j("fresh.spv")], cache)
        check(r1.returncode == 0 and r2.returncode == 0 and
              filecmp.cmp(j("hit.spv"), j("fresh.spv"), shallow=False),
              "a hit gives the same SPIR-V as a fresh compile")

        # A corrupt entry is ignored and replaced.
        entry = kernel_entry(cache)
        good = open(entry, "rb").read()
        for name, bad in (("garbage", b"not an entry at all"), ("truncated", good[: len(good) // 2]),
                          ("flipped word", good[:-8] + bytes([good[-8] ^ 0xFF]) + good[-7:]),
                          ("empty", b"")):
            open(entry, "wb").write(bad)
            r = run(["render", scene, "-o", j("corrupt.png")], cache)
            check(r.returncode == 0 and "from the cache" not in r.stderr,
                  f"a {name} entry is ignored (exit {r.returncode})")
            check(filecmp.cmp(j("miss.png"), j("corrupt.png"), shallow=False),
                  f"a {name} entry: the same image")
            check(open(entry, "rb").read() == good, f"a {name} entry is replaced by a valid one")

        # --no-cache neither reads nor writes.
        empty = os.path.join(d, "empty cache")
        r = run(["render", scene, "-o", j("nocache.png"), "--no-cache"], empty)
        check(r.returncode == 0 and not entries(empty), "--no-cache writes nothing")
        r = run(["render", scene, "-o", j("nocache.png"), "--no-cache"], cache)
        check(r.returncode == 0 and "from the cache" not in r.stderr, "--no-cache reads nothing")

        # Concurrent runs on an empty cache.
        shared = os.path.join(d, "shared cache")
        env = dict(os.environ, XDG_CACHE_HOME=shared, LP_NUM_THREADS="1")
        procs = [subprocess.Popen([SDFC, "render", scene, "-q", "-o", j(f"c{i}.png")], env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                 for i in range(4)]
        codes = [p.wait(timeout=300) for p in procs]
        check(codes == [0, 0, 0, 0], f"four concurrent renders succeed ({codes})")
        check(all(filecmp.cmp(j("miss.png"), j(f"c{i}.png"), shallow=False) for i in range(4)),
              "four concurrent renders: the same image")
        check(len(entries(shared)) == 2 and open(kernel_entry(shared), "rb").read() == good,
              "four concurrent renders leave the two entries, valid")
        check(not leftovers(shared), f"no temporaries left ({leftovers(shared)})")

        # Without XDG_CACHE_HOME: $HOME/.cache/sdfc.
        home = os.path.join(d, "home")
        os.makedirs(home)
        env = {k: v for k, v in os.environ.items() if k != "XDG_CACHE_HOME"}
        env.update(HOME=home, LP_NUM_THREADS="1")
        r = subprocess.run([SDFC, "render", scene, "-q", "-o", j("home.png")], env=env,
                           capture_output=True, text=True, timeout=120)
        check(r.returncode == 0 and len(glob.glob(os.path.join(home, ".cache/sdfc/spirv/*.spv"))) == 2,
              "HOME/.cache/sdfc without XDG_CACHE_HOME")

        # --timings names every fixed stage.
        r = run(["render", scene, "-o", j("timed.png"), "--timings"], cache)
        for stage in ("process start to main", "device creation", "front end", "SPIR-V from the cache",
                      "pipeline creation", "first draw", "passes", "readback", "encoding",
                      "device destruction", "total"):
            check(stage in r.stderr, f"--timings lists '{stage}'")
        r = run(["render", scene, "-o", j("timed.png"), "--timings", "--no-cache"], cache)
        check("glslang" in r.stderr and "SPIR-V validation" in r.stderr,
              "--timings --no-cache lists glslang and validation")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
