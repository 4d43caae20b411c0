#!/usr/bin/env python3
"""Ctrl-C in every phase of `sdfc render` (issue 47 item 6): acted on within half
a second, and an image without samples never replaces a file.

  - During the driver's kernel compile (a scene of instance groups that lavapipe
    compiles for seconds, with Mesa's and sdfc's caches off): the process ends at
    once, exit 130, and the file already at the output path is left as it was.
    Before, the compile ran on, then a 0-sample black PNG replaced the file.
  - During the samples: exit 130 within the pass, the samples so far written.
  - During the denoise (a large image, so that nlr and svgf take a second or
    more): exit 130 at once, the samples' raw mean written. Before, the denoise
    ran to its end.

The limit checked is 1.5 s (the target is 0.5 s, met on an idle machine: the
test machine is shared and may be loaded); the times are printed.

    render_interrupt_test.py SDFC
"""
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

SDFC = sys.argv[1]
HERE = os.path.dirname(os.path.abspath(__file__))
HELLO = os.path.join(os.path.dirname(HERE), "bench", "scenes", "hello.sdf")
LIMIT_S = 1.5
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def slow_scene():
    # As tests/view_quit_test.py: two instance groups, glass and metal.
    a = ", ".join(f"[{x * 0.5 - 2:.2f}, 0.2, {z * 0.5 - 2:.2f}]" for x in range(8) for z in range(8))
    b = ", ".join(f"[{x * 0.5 - 2:.2f}, 1.0, {z * 0.5 - 2:.2f}]" for x in range(8) for z in range(8))
    return f"""render(size: [160, 120], spp: 2, bounces: 2)
camera(position: [0, 3, 7], target: [0, 0.6, 0], fov: 40)
scene {{
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.7, 0.7, 0.7]))
  instances(positions: [{a}]) {{ box(size: [0.3, 0.3, 0.3], rounding: 0.05, material: glass(ior: 1.5)) }}
  instances(positions: [{b}]) {{ torus(major: 0.15, minor: 0.05, material: metal(albedo: [0.9, 0.8, 0.5], roughness: 0.2)) }}
}}
"""


def interrupt_when(args, marker, work, delay=0.0):
    """Runs `sdfc render ARGS`, sends SIGINT `delay` s after `marker` appears on
    its stderr; returns (exit code, seconds from the signal to the exit, stderr,
    stderr up to the signal, or None when the marker never came)."""
    env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true", XDG_CACHE_HOME=os.path.join(work, "cache"))
    proc = subprocess.Popen([SDFC, "render"] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            env=env)
    text = bytearray()
    seen = threading.Event()

    def read():
        while True:
            chunk = proc.stderr.read1(4096)
            if not chunk:
                break
            text.extend(chunk)
            if marker.encode() in text:
                seen.set()
    reader = threading.Thread(target=read)
    reader.start()
    sent, before = None, None
    while proc.poll() is None:
        if seen.wait(0.01):
            time.sleep(delay)
            sent = time.monotonic()
            before = text.decode(errors="replace")
            proc.send_signal(signal.SIGINT)
            break
    try:
        proc.wait(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
    took = time.monotonic() - sent if sent else float("nan")
    reader.join()
    return proc.returncode, took, text.decode(errors="replace"), before


def main():
    with tempfile.TemporaryDirectory(prefix="sdfc_interrupt_") as work:
        j = lambda name: os.path.join(work, name)
        before = b"an image that must survive\n"

        # 1. The driver's kernel compile.
        open(j("slow.sdf"), "w").write(slow_scene())
        open(j("kept.png"), "wb").write(before)
        code, took, err, sent = interrupt_when([j("slow.sdf"), "-o", j("kept.png"), "--no-cache"],
                                               "compiling the kernel (first draw)...", work, delay=0.3)
        print(f"  compile: signal to exit {took:.3f} s; stderr tail: {err.strip().splitlines()[-1:]}")
        check(sent is not None, "the kernel compile started")
        check(sent is None or "done in" not in sent.split("compiling the kernel")[-1],
              "the signal came before the compile's end")
        check(code == 130, f"compile: exit 130 ({code})")
        check(took < LIMIT_S, f"compile: ended {took:.3f} s after the signal (< {LIMIT_S} s)")
        check(open(j("kept.png"), "rb").read() == before, "compile: the file at -o is untouched")

        # 2. The samples: the first progress line comes after the first pass.
        code, took, err, sent = interrupt_when([HELLO, "-o", j("samples.png"), "--size", "640x360",
                                                "--spp", "256", "--denoise", "none"], "render: ", work)
        print(f"  samples: signal to exit {took:.3f} s")
        check(code == 130, f"samples: exit 130 ({code})")
        check(took < LIMIT_S, f"samples: ended {took:.3f} s after the signal (< {LIMIT_S} s)")
        check(os.path.exists(j("samples.png")) and "interrupted; wrote the" in err,
              "samples: the samples so far written")

        # 3. The denoise of a large image: nlr (the default) and svgf.
        for denoiser in ("nlr", "svgf"):
            out = j(f"denoise_{denoiser}.pfm")
            code, took, err, sent = interrupt_when([HELLO, "-o", out, "--size", "1280x720", "--spp", "4",
                                                    "--denoise", denoiser], "denoising", work, delay=0.1)
            print(f"  denoise ({denoiser}): signal to exit {took:.3f} s")
            check(sent is not None, f"denoise ({denoiser}): its progress line was printed")
            check(code == 130, f"denoise ({denoiser}): exit 130 ({code})")
            check(took < LIMIT_S, f"denoise ({denoiser}): ended {took:.3f} s after the signal (< {LIMIT_S} s)")
            check(os.path.exists(out) and "in the denoise" in err,
                  f"denoise ({denoiser}): the raw mean written, and said so")

    print("FAILED: " + "; ".join(failures) if failures else "all passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
