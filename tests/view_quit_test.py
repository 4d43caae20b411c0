#!/usr/bin/env python3
"""`sdfc view` obeys Q while a slow kernel is being built (issue 29), under Xvfb
(run by tests/view_quit_test.sh).

A small scene is shown; then a save brings a scene of two instance groups, whose
kernel lavapipe compiles with LLVM for seconds at its first draw (Mesa's shader
cache off). While that compile runs on the viewer's worker thread, an X
screenshot of the window still equals the last image, and a real Q key press
sent through the X server (XTEST) ends the process within 0.5 s, exit 0, with
validation layers silent.
"""
import ctypes
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time

import matplotlib.image as mpimg
import numpy as np

SDFC = sys.argv[1]
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def read_png(path):
    return np.round(mpimg.imread(path)[:, :, :3] * 255).astype(np.int16)


def read_xwd(path):
    """RGB of an XWD file (as tests/view_test.py reads it)."""
    data = open(path, "rb").read()
    h = struct.unpack(">25I", data[:100])
    header_size, width, height = h[0], h[4], h[5]
    byte_order, bits_per_pixel, bytes_per_line = h[7], h[11], h[12]
    red_mask, green_mask, blue_mask, ncolors = h[14], h[15], h[16], h[19]
    assert bits_per_pixel == 32, "expected a 24/32-bit visual"
    pixels = np.frombuffer(data, dtype="<u4" if byte_order == 0 else ">u4",
                           count=height * bytes_per_line // 4, offset=header_size + 12 * ncolors)
    pixels = pixels.reshape(height, bytes_per_line // 4)[:, :width].astype(np.int64)

    def channel(mask):
        shift = (mask & -mask).bit_length() - 1
        return ((pixels & mask) >> shift).astype(np.int16)
    return np.stack([channel(red_mask), channel(green_mask), channel(blue_mask)], axis=-1)


def press_key(window, name):
    """A key press and release through the X server (XTEST), to `window` focused."""
    x11 = ctypes.CDLL("libX11.so.6")
    xtst = ctypes.CDLL("libXtst.so.6")
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XStringToKeysym.restype = ctypes.c_ulong
    x11.XStringToKeysym.argtypes = [ctypes.c_char_p]
    x11.XKeysymToKeycode.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
    x11.XSetInputFocus.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int, ctypes.c_ulong]
    x11.XFlush.argtypes = [ctypes.c_void_p]
    x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    xtst.XTestFakeKeyEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
    display = x11.XOpenDisplay(None)
    if not display:
        raise RuntimeError("cannot open the X display")
    x11.XSetInputFocus(display, window, 2, 0)  # RevertToParent, CurrentTime
    x11.XSync(display, 0)
    code = x11.XKeysymToKeycode(display, x11.XStringToKeysym(name.encode()))
    xtst.XTestFakeKeyEvent(display, code, 1, 0)
    xtst.XTestFakeKeyEvent(display, code, 0, 0)
    x11.XFlush(display)
    x11.XCloseDisplay(display)


FAST = """render(size: [160, 120], spp: 2, bounces: 1)
camera(position: [0, 1.2, 4.5], target: [0, 0.6, 0], fov: 40)
scene {
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.7, 0.7, 0.7]))
  translate([0, 0.7, 0]) { sphere(radius: 0.7, material: diffuse(albedo: [0.8, 0.3, 0.25])) }
}
"""


def slow_scene():
    # Two instance groups (each becomes data + a hierarchy with its own traversal
    # code), glass and metal: a kernel that takes lavapipe seconds to compile.
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


def main():
    check(bool(os.environ.get("DISPLAY")), "a display is set (run under xvfb-run)")
    with tempfile.TemporaryDirectory(prefix="sdfc_quit_") as d:
        j = lambda name: os.path.join(d, name)
        scene = j("scene.sdf")
        open(scene, "w").write(FAST)
        open(j("slow.sdf"), "w").write(slow_scene())
        open(j("events.txt"), "w").write(f"""wait-spp 2
save {j('first.png')}
run echo ${{WINDOW}} > '{j('window.txt')}'
write-file {j('slow.sdf')}
wait-reload
quit
""")
        env = dict(os.environ, SDFC_VALIDATION="1", LP_NUM_THREADS="2", MESA_SHADER_CACHE_DISABLE="true",
                   XDG_CACHE_HOME=j("cache"))
        proc = subprocess.Popen([SDFC, "view", scene, "--script", j("events.txt"), "--frame-log", j("frames.log")],
                                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        lines = []
        compiling = threading.Event()

        def read_stderr():
            for line in proc.stderr:
                lines.append(line)
                # The first is the first scene's; the second is the slow one's.
                if sum("compiling the kernel (first draw)" in l for l in lines) == 2:
                    compiling.set()
        reader = threading.Thread(target=read_stderr, daemon=True)
        reader.start()
        # The worker says when the driver's compile starts; a binary that does it
        # in the frame loop instead says nothing, and is in it 3 s after the save.
        started = time.monotonic()
        written = None
        while not compiling.is_set() and time.monotonic() - started < 300:
            if written is None and open(scene).read() == open(j("slow.sdf")).read():
                written = time.monotonic()  # the script's write-file has happened
            if written is not None and time.monotonic() - written > 3:
                break
            time.sleep(0.02)
        check(compiling.is_set(), "the worker reports the slow kernel's compile")
        time.sleep(0.3)  # well inside the compile
        shot_ok = subprocess.run(["xwd", "-id", open(j("window.txt")).read().strip(), "-silent",
                                  "-out", j("shot.xwd")], timeout=30).returncode == 0
        check(shot_ok, "a screenshot during the compile")
        if shot_ok:
            shot, first = read_xwd(j("shot.xwd")), read_png(j("first.png"))
            check(shot.shape == first.shape and np.abs(shot - first).max() == 0,
                  "during the compile the window still shows the last image")
        building = not any("reloaded:" in l for l in lines)
        t0 = time.monotonic()
        press_key(int(open(j("window.txt")).read().strip()), "q")
        try:
            code = proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = None
        elapsed = time.monotonic() - t0
        reader.join(timeout=5)
        sys.stderr.write("".join(lines))
        check(building, "Q was pressed while the kernel was still being compiled")
        check(code == 0, f"Q exits 0 (got {code})")
        check(elapsed <= 0.5, f"Q quits within 0.5 s during the compile ({elapsed * 1000:.0f} ms)")
        check(not any("reloaded:" in l for l in lines), "the process ended before the compile finished")
        check(not any("[vulkan" in l for l in lines), "validation layers silent")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
