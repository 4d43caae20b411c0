"""Helpers for the sdfc benchmark: running sdfc, reading PFM, error metrics,
camera rays and exact float64 ray roots through `sdfc eval`.

Only the standard library and numpy: CI installs python3-numpy from apt.
"""
import hashlib
import os
import re
import statistics
import subprocess
import tempfile
import threading
import time

import numpy as np

# ---------------------------------------------------------------- running sdfc

STDERR_PATTERNS = {
    "compile_ms": r"compiled in (\d+) ms",
    "pipeline_ms": r"pipeline in (\d+) ms",
    "steps_mean": r"primary ray steps: mean ([0-9.eE+-]+)",
    "steps_max": r"primary ray steps: mean [0-9.eE+-]+, max ([0-9.eE+-]+)",
    "step_budget": r"\(budget (\d+)\)",
    "spp_done": r"wrote .* \((\d+) spp in",
    "spp_per_s": r"spp in [^,]*, ([0-9.eE+-]+) spp/s",
    "denoise_ms": r"denoised \(\w+\) in (\d+) ms",
    "denoise_cpu_ms": r"denoised \(\w+\) in \d+ ms \((\d+) CPU ms\)",
}


def parse_stderr(text):
    """Numbers sdfc prints on stderr; missing ones are None."""
    out = {}
    for key, pattern in STDERR_PATTERNS.items():
        m = re.search(pattern, text)
        out[key] = float(m.group(1)) if m else None
    # "N spp in 1.9s" is rounded for people; N / (spp/s) keeps 6 digits.
    if out["spp_done"] and out["spp_per_s"]:
        out["render_s"] = out["spp_done"] / out["spp_per_s"]
    else:
        out["render_s"] = None
    return out


def render(sdfc, scene, output, flags, env=None):
    """Run `sdfc render`; returns parsed stderr plus the process's wall seconds
    (wall_s) and CPU seconds, user + sys of all its threads (cpu_s: steadier
    than wall time on a machine other people load)."""
    # sdfc denoises beauty renders by default; a benchmark says so when it wants it.
    flags = list(flags) + ([] if "--denoise" in flags else ["--denoise", "none"])
    cmd = [sdfc, "render", scene, "-o", output] + flags
    # Compile figures are glslang's, not a SPIR-V cache hit (docs/caches.md).
    env = dict(os.environ if env is None else env, SDFC_NO_CACHE="1")
    # Sampling figures are the optimised kernel's: an empty GALLIVM_PERF stops
    # small renders compiling unoptimised (docs/caches.md, "The first draw").
    env.setdefault("GALLIVM_PERF", "")
    with tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err, env=env)
        # wait4, not wait: it returns this child's own resource usage.
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        stderr = err.read()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{stderr}")
    info = parse_stderr(stderr)
    info["wall_s"] = wall
    info["cpu_s"] = usage.ru_utime + usage.ru_stime
    return info


def interleaved_medians(sdfc, scene, work, configs, reps, flags, keys=("cpu_s", "spp_per_s")):
    """Renders `scene` once per (name, extra flags) in `configs` per rep, the order
    turned every other rep; the medians of `keys` per name."""
    got = {name: [] for name, _ in configs}
    for rep in range(reps):
        for name, extra in configs if rep % 2 == 0 else configs[::-1]:
            got[name].append(render(sdfc, scene, os.path.join(work, "x.pfm"), list(flags) + list(extra)))
    return {name: {k: statistics.median(i[k] for i in runs) for k in keys} for name, runs in got.items()}


def compile_text(sdfc, scene, emit, flags=()):
    proc = subprocess.run([sdfc, "compile", scene, "--emit", emit] + list(flags),
                          capture_output=True, text=True, check=True)
    return proc.stdout


def scene_limits(sdfc, scene, flags=()):
    """The march constants the compiler derived (kSceneMaxDist, ...) for these flags."""
    glsl = compile_text(sdfc, scene, "glsl", flags)
    limits = {}
    for name, value in re.findall(r"const (?:float|int) (kScene\w+) = ([0-9.eE+-]+);", glsl):
        limits[name] = float(value)
    return limits


def file_hash(paths, extra=""):
    """Cache key: scene text, the sdfc binary and the settings that shape the image."""
    h = hashlib.sha256(extra.encode())
    for p in paths:
        with open(p, "rb") as f:
            h.update(f.read())
    return h.hexdigest()[:16]


# ---------------------------------------------------------------- images

def read_pfm(path):
    """PFM as float64 array (H, W, C), top row first."""
    with open(path, "rb") as f:
        magic = f.readline().strip()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        channels = 3 if magic == b"PF" else 1
        dtype = "<f4" if scale < 0 else ">f4"
        data = np.frombuffer(f.read(width * height * channels * 4), dtype=dtype)
    img = data.reshape(height, width, channels).astype(np.float64)
    return img[::-1]  # PFM rows run bottom to top


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def relmse(a, b):
    """Relative MSE as in the issue: mean((a-b)^2 / (b^2 + 0.01))."""
    return float(np.mean((a - b) ** 2 / (b ** 2 + 0.01)))


# ---------------------------------------------------------------- camera rays

def parse_camera(ir_text):
    """Camera line of `sdfc compile --emit ir`."""
    line = next(l for l in ir_text.splitlines() if l.startswith("camera "))
    vec = lambda name: np.array([float(x) for x in
                                 re.search(name + r"=\[([^\]]*)\]", line).group(1).split(",")])
    fov = float(re.search(r"fov=([0-9.eE+-]+)", line).group(1))
    aperture = float(re.search(r"aperture=([0-9.eE+-]+)", line).group(1))
    # A far scene is compiled in its camera's frame ("origin [x, y, z]", world
    # minus origin): back to world coordinates, which `sdfc eval` uses.
    origin = np.zeros(3)
    m = re.search(r"^origin \[([^\]]*)\]", ir_text, re.M)
    if m:
        origin = np.array([float(x) for x in m.group(1).split(",")])
    return {"position": vec("position") + origin, "target": vec("target") + origin, "up": vec("up"),
            "fov": fov, "aperture": aperture}


def camera_rays(cam, width, height):
    """Float64 version of runtime/camera.cpp makeFrameParams + pathtrace.glsl
    cameraRay at the pixel centres (the unjittered AOV ray). Returns ro (3,),
    rd (H, W, 3) with unit directions, rows top first."""
    offset = cam["target"] - cam["position"]
    forward = offset / np.linalg.norm(offset)
    up = cam["up"]
    right = np.cross(forward, up)
    if np.linalg.norm(right) < 1e-6 * max(np.linalg.norm(up), 1e-30):
        up = np.array([0, 1, 0.0]) if abs(forward[1]) < 0.9 else np.array([0, 0, 1.0])
        right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_half = np.tan(np.radians(cam["fov"]) * 0.5)
    aspect = width / height
    fx = (np.arange(width) + 0.5)
    fy = (np.arange(height) + 0.5)
    ndc_x = 2.0 * fx / width - 1.0
    ndc_y = 1.0 - 2.0 * fy / height
    nx, ny = np.meshgrid(ndc_x, ndc_y)
    rd = (forward[None, None, :] + (nx * aspect * tan_half)[..., None] * right
          + (ny * tan_half)[..., None] * up)
    rd /= np.linalg.norm(rd, axis=-1, keepdims=True)
    return cam["position"].copy(), rd


# ---------------------------------------------------------------- float64 SDF

class Evaluator:
    """A persistent `sdfc eval` process: float64 distances (and gradients) at
    batches of points. stdbuf makes its printf output line-buffered so a batch
    can be answered without closing stdin; a writer thread avoids the pipe
    deadlock of writing a large batch while the answers pile up."""

    def __init__(self, sdfc, scene, gradient=False):
        cmd = ["stdbuf", "-oL", sdfc, "eval", scene] + (["--gradient"] if gradient else [])
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1 << 16)
        self.gradient = gradient
        self.count = 0  # points evaluated: the reference's own logical work

    def __call__(self, points):
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        n = len(points)
        if n == 0:
            return np.zeros((0, 4)) if self.gradient else np.zeros(0)
        text = "\n".join(f"{x!r} {y!r} {z!r}" for x, y, z in points.tolist()) + "\n"

        def write():
            self.proc.stdin.write(text)
            self.proc.stdin.flush()

        writer = threading.Thread(target=write)
        writer.start()
        lines = [self.proc.stdout.readline() for _ in range(n)]
        writer.join()
        self.count += n
        values = np.array([[float(v) for v in l.split()] for l in lines])
        return values if self.gradient else values[:, 0]

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()


def exact_roots(sdf, ro, rd, t_max, step_scale, min_step_rel=2e-6, max_iter=20000):
    """First sign change of f(t) = sdf(ro + t rd) for every ray, in float64.

    March by |f| * step_scale (safe for a distance bound with the compiler's
    1 / Lipschitz scale), but at least min_step_rel * max(t, scale): near a
    grazing surface pure sphere tracing needs ~1/angle steps, and a feature
    thinner than that minimum step along the ray is far below the 1e-4 target.
    Once the sign flips, bisect the last interval to float64 precision.
    Rays that start inside a solid (f(0) < 0) look for the exit (sign flip to
    positive). Returns t (nan = no root before t_max) and the start sign."""
    n = len(rd)
    scale = max(np.max(np.abs(ro)), 1.0)
    t = np.zeros(n)
    f = sdf(np.repeat(ro[None], n, 0))
    sign0 = np.where(f < 0, -1.0, 1.0)
    lo = np.zeros(n)
    hi = np.full(n, np.nan)
    active = np.ones(n, bool)
    # A ray exactly on the surface at t = 0: treat as root 0.
    on = f == 0
    hi[on] = 0
    active[on] = False
    for _ in range(max_iter):
        idx = np.nonzero(active)[0]
        if len(idx) == 0:
            break
        fa = f[idx] * sign0[idx]
        step = np.maximum(fa * step_scale, min_step_rel * np.maximum(t[idx], scale))
        tn = t[idx] + step
        fn = sdf(ro + rd[idx] * tn[:, None])
        flipped = fn * sign0[idx] <= 0
        lo[idx] = t[idx]
        t[idx] = tn
        f[idx] = fn
        hi[idx[flipped]] = tn[flipped]
        done = flipped | (tn > t_max)
        active[idx[done]] = False
    # Bisection: lo has the start sign, hi does not.
    idx = np.nonzero(np.isfinite(hi) & (hi > 0))[0]
    a, b = lo[idx], hi[idx]
    for _ in range(60):
        m = 0.5 * (a + b)
        fm = sdf(ro + rd[idx] * m[:, None]) * sign0[idx]
        inside = fm <= 0
        b = np.where(inside, m, b)
        a = np.where(inside, a, m)
        if np.all(b - a <= 1e-14 * np.maximum(b, 1e-300)):
            break
    roots = hi.copy()
    roots[idx] = 0.5 * (a + b)
    return roots, sign0


# ---------------------------------------------------------------- machine

def machine_info(sdfc=None):
    """CPU model and cores (lscpu); the Vulkan device and driver: with `sdfc`,
    the first device `sdfc devices` lists (the one it renders on, which may be
    its bundled lavapipe), else vulkaninfo --summary's (the system's)."""
    info = {"cpu": "?", "cores": str(os.cpu_count()), "device": "?", "driver": "?"}
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        for line in out.splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "Model name":
                info["cpu"] = value.strip()
            if key.strip() == "CPU(s)":
                info["cores"] = value.strip()
    except OSError:
        pass
    try:
        if sdfc:
            # "driver: bundled lavapipe ... (/path/lvp_icd.json)", then
            # "0: llvmpipe (LLVM 15.0.6, 256 bits) (CPU, Mesa 25.0.7)"
            out = subprocess.run([sdfc, "devices"], capture_output=True, text=True).stdout
            drivers = [l.partition(": ")[2] for l in out.splitlines() if l.startswith("driver: ")]
            devices = [l.partition(": ")[2] for l in out.splitlines() if l[:1].isdigit()]
            if devices:
                info["device"] = devices[0]
            if drivers:  # without the manifest's path
                info["driver"] = re.sub(r"\s*\(/[^()]*\)$", "", drivers[0])
        else:
            out = subprocess.run(["vulkaninfo", "--summary"], capture_output=True, text=True).stdout
            m = re.search(r"deviceName\s*=\s*(.*)", out)
            if m:
                info["device"] = m.group(1).strip()
            m = re.search(r"driverInfo\s*=\s*(.*)", out)
            if m:
                info["driver"] = m.group(1).strip()
    except OSError:
        pass
    info["lp_num_threads"] = os.environ.get("LP_NUM_THREADS",
                                            f"unset (llvmpipe uses all {info['cores']} CPUs)")
    return info


def time_to_error(points, target):
    """Time at which a log-log piecewise-linear error(time) curve reaches
    `target`; (time, how) with how = interpolated / extrapolated / None."""
    pts = sorted((t, e) for t, e in points if t > 0 and e > 0)
    if len(pts) < 2:
        return None, None  # too few finite measurements to place a curve
    lt = np.log([p[0] for p in pts])
    le = np.log([p[1] for p in pts])
    lg = np.log(target)
    for i in range(len(pts) - 1):
        if (le[i] - lg) * (le[i + 1] - lg) <= 0 and le[i] != le[i + 1]:
            f = (lg - le[i]) / (le[i + 1] - le[i])
            return float(np.exp(lt[i] + f * (lt[i + 1] - lt[i]))), "interpolated"
    # Outside the measured range: extend the nearest segment if it descends.
    i = 0 if le[0] < lg else len(pts) - 2
    if len(pts) >= 2 and le[i + 1] < le[i]:
        slope = (lt[i + 1] - lt[i]) / (le[i + 1] - le[i])
        return float(np.exp(lt[i] + (lg - le[i]) * slope)), "extrapolated"
    return None, None
