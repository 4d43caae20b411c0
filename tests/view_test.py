#!/usr/bin/env python3
"""End-to-end test of `sdfc view` under Xvfb (run by tests/view_test.sh).

One scripted session on a copy of a small scene asserts: frames are presented;
an orbit changes the image and orbiting back restores it; a real X screenshot
(xwd) of the window equals the renderer's own frame; a save on disk shows the new
scene (latency printed); a broken save keeps the last image, prints the errors
exactly as `sdfc check` and says so in the title, and the next good save
recovers; the camera key prints a pasteable camera line; input reaches the
screen within two frames; a scripted resize makes a new swapchain and starts the
accumulation again at the new size, and the screenshot still equals the frame;
quit exits 0 with validation layers silent. Also: no
display -> exit 3 with a pointer to `sdfc render`.
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

import matplotlib.image as mpimg
import numpy as np

SDFC = sys.argv[1]
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)
    return condition


def read_png(path):
    return np.round(mpimg.imread(path)[:, :, :3] * 255).astype(np.int16)


def read_xwd(path):
    """RGB of an XWD (X Window Dump) file: 25 big-endian CARD32 header fields."""
    data = open(path, "rb").read()
    h = struct.unpack(">25I", data[:100])
    header_size, width, height = h[0], h[4], h[5]
    byte_order, bits_per_pixel, bytes_per_line = h[7], h[11], h[12]
    red_mask, green_mask, blue_mask, ncolors = h[14], h[15], h[16], h[19]
    assert bits_per_pixel == 32, "expected a 24/32-bit visual"
    pixels = np.frombuffer(data, dtype="<u4" if byte_order == 0 else ">u4",
                           count=height * bytes_per_line // 4,
                           offset=header_size + 12 * ncolors)
    pixels = pixels.reshape(height, bytes_per_line // 4)[:, :width].astype(np.int64)

    def channel(mask):
        shift = (mask & -mask).bit_length() - 1
        return ((pixels & mask) >> shift).astype(np.int16)
    return np.stack([channel(red_mask), channel(green_mask), channel(blue_mask)], axis=-1)


SCENE = """render(size: [160, 120], spp: 4, bounces: 2)
camera(position: [0, 1.2, 4.5], target: [0, 0.6, 0], fov: 40)
sky(top: [0.45, 0.6, 0.9], bottom: [0.7, 0.7, 0.72])
sun(direction: [0.5, 1, 0.4], angle: 3, strength: 1.2)
scene {
  plane(normal: [0, 1, 0], offset: 0, material: diffuse(albedo: [0.7, 0.7, 0.7]))
  translate([0, 0.7, 0]) { SHAPE }
}
"""
FIRST = SCENE.replace("SHAPE", "sphere(radius: 0.7, material: diffuse(albedo: [0.8, 0.3, 0.25]))")
EDITED = SCENE.replace("SHAPE", "box(size: [1.2, 1.2, 1.2], material: diffuse(albedo: [0.2, 0.4, 0.9]))")
BROKEN = SCENE.replace("SHAPE", "sphere(radus: 0.7)\n  torus(major: 1)")
RECOVERED = SCENE.replace("translate([0, 0.7, 0]) { SHAPE }",
                          "translate([0.8 * sin(4 * time), 0.7, 0]) { torus(major: 0.6, minor: 0.2, "
                          "material: diffuse(albedo: [0.9, 0.8, 0.2])) }")


def main():
    env = dict(os.environ, SDFC_VALIDATION="1", LP_NUM_THREADS="2")
    # Without a display: exit 3 and a pointer to `sdfc render`.
    bare = {k: v for k, v in env.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "s.sdf")
        open(path, "w").write(FIRST)
        r = subprocess.run([SDFC, "view", path], env=bare, capture_output=True, text=True, timeout=60)
        check(r.returncode == 3, f"no display: exit 3 (got {r.returncode})")
        check("sdfc render" in r.stderr, "no display: the message points to `sdfc render`")

    check(bool(os.environ.get("DISPLAY")), "a display is set (run under xvfb-run)")
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "scene.sdf")
        open(scene, "w").write(FIRST)
        for name, text in (("edited", EDITED), ("broken", BROKEN), ("recovered", RECOVERED)):
            open(os.path.join(d, name + ".sdf"), "w").write(text)
        j = lambda name: os.path.join(d, name)
        script = f"""# the session
wait-spp 4
save {j('first.png')}
run sleep 0.5; xwd -id ${{WINDOW}} -silent -out {j('shot.xwd')}
log orbit
drag left 120 0 3
wait-spp 4
save {j('moved.png')}
drag left -120 0 3
wait-spp 4
save {j('back.png')}
key c
write-file {j('edited.sdf')}
wait-reload
wait-spp 4
save {j('edited.png')}
write-file {j('broken.sdf')}
wait-reload
wait 5
save {j('after_broken.png')}
write-file {j('recovered.sdf')}
wait-reload
wait-spp 4
save {j('recovered.png')}
key 2
wait-idle
save {j('normal.png')}
key 1
key period
key period
key period
wait-spp 4
save {j('stepped.png')}
key d
wait 2
save {j('denoised.png')}
key f
wait-spp 4
save {j('framed.png')}
resize 200 150
wait-spp 4
save {j('resized.png')}
run sleep 0.5; xwd -id ${{WINDOW}} -silent -out {j('shot_resized.xwd')}
quit
"""
        open(j("events.txt"), "w").write(script)
        log = j("frames.log")
        r = subprocess.run([SDFC, "view", scene, "--script", j("events.txt"), "--frame-log", log],
                           env=env, capture_output=True, text=True, timeout=600)
        sys.stderr.write(r.stderr)
        check(r.returncode == 0, f"quit exits 0 (got {r.returncode})")
        check("[vulkan" not in r.stderr, "validation layers silent")
        lines = open(log).read().splitlines()
        frames = [l.split() for l in lines if l.startswith("frame ")]
        check(len(frames) >= 10, f"frames presented ({len(frames)})")

        first, moved, back = read_png(j("first.png")), read_png(j("moved.png")), read_png(j("back.png"))
        moved_diff = np.abs(first - moved).max(axis=-1)
        back_diff = np.abs(first - back).max(axis=-1)
        check((moved_diff > 8).mean() > 0.05,
              f"orbit changes the image ({(moved_diff > 8).mean():.1%} of pixels)")
        # The camera comes back through float arithmetic: a silhouette pixel
        # whose centre is within rounding of an edge may flip, nothing more.
        check((back_diff > 2).mean() < 0.005 and (back_diff > 32).mean() < 0.001,
              f"orbiting back restores it ({(back_diff > 2).mean():.3%} pixels off by > 2/255, "
              f"{(back_diff > 32).mean():.3%} by > 32/255)")

        shot = read_xwd(j("shot.xwd"))
        check(shot.shape == first.shape, f"screenshot size {shot.shape} = frame size {first.shape}")
        if shot.shape == first.shape:
            d8 = np.abs(shot - first)
            check(d8.max() == 0, f"X screenshot equals the renderer's frame (max diff {d8.max()})")

        edited, after, recovered = (read_png(j(n)) for n in ("edited.png", "after_broken.png", "recovered.png"))
        check((np.abs(edited - back).max(axis=-1) > 8).mean() > 0.02, "a save shows the new scene")
        check(np.array_equal(after, edited), "a broken save keeps the last image")
        check((np.abs(recovered - edited).max(axis=-1) > 8).mean() > 0.02, "the next good save recovers")
        normal, stepped, denoised, framed = (read_png(j(n)) for n in ("normal.png", "stepped.png", "denoised.png", "framed.png"))
        differs = lambda a, b: (np.abs(a - b).max(axis=-1) > 8).mean()
        check(differs(normal, recovered) > 0.2, f"key 2 shows the normal view ({differs(normal, recovered):.0%} differs)")
        check(differs(stepped, recovered) > 0.01, f"the step key advances time ({differs(stepped, recovered):.1%} differs)")
        noise = lambda im: np.abs(np.diff(im.astype(float), axis=1)).mean()
        check(noise(denoised) < noise(stepped), f"key d denoises (pixel-to-pixel change {noise(stepped):.2f} -> {noise(denoised):.2f})")
        check(differs(framed, stepped) > 0.05, f"key f frames the scene's bounds ({differs(framed, stepped):.0%} differs)")
        # A resize: a new swapchain at the window's size, the accumulation started
        # again at it, and the X screenshot still equals the frame.
        resized = read_png(j("resized.png"))
        check(resized.shape == (150, 200, 3), f"after a resize the frame is the window's size {resized.shape}")
        check(any(f[f.index("res") + 1] == "200x150" and f[f.index("spp") + 1] == "1" for f in frames),
              "the resize starts the accumulation again at the new size")
        shot = read_xwd(j("shot_resized.xwd"))
        check(shot.shape == resized.shape and np.abs(shot - resized).max() == 0,
              f"after a resize the X screenshot equals the frame ({shot.shape})")
        events = [l for l in lines if l.startswith("event ")]
        check(any(e.endswith("resize 200x150") for e in events), "the view follows the window's new size")
        check(any("reload error" in e and "ERROR" in e for e in events), "the title shows the error")
        check(sum("reload ok" in e for e in events) == 3, "three good loads (first, edited, recovered)")
        latencies = [float(m.group(1)) for m in (re.search(r"save-to-image (\d+) ms", e) for e in events) if m]
        print("save-to-image latencies (ms):", latencies)

        # The broken save's diagnostics, exactly as `sdfc check` prints them for that file.
        open(scene, "w").write(BROKEN)
        c = subprocess.run([SDFC, "check", scene], capture_output=True, text=True, timeout=60)
        check(c.returncode == 1 and re.search(r"scene\.sdf:\d+:\d+: error:", c.stderr) is not None,
              "sdfc check reports file:line:col")
        check(c.stderr in r.stderr, "the view prints the errors exactly as sdfc check")

        check(re.search(r"^camera\(position: \[[^]]+\], target: \[[^]]+\], fov: [0-9.]+\)$",
                        r.stdout, re.M) is not None, "the camera key prints a camera(...) line")

        # Input to presented frame: frames from an input event to the first frame showing it.
        waits = []
        for i, l in enumerate(lines):
            if l.startswith("event ") and "input drag" in l:
                n = int(l.split()[1])
                cam = None
                for f in frames:
                    if int(f[1]) == n:
                        cam = f[f.index("camera") + 1]
                for f in frames:
                    if int(f[1]) > n and f[f.index("camera") + 1] != cam:
                        waits.append(int(f[1]) - n)
                        break
        check(bool(waits) and max(waits) <= 2, f"input reaches the screen within 2 frames ({waits})")
    # Space plays time at the wall clock's rate, rendering included (the clock
    # once added only the idle gap between frames: about 1/30 of real time).
    with tempfile.TemporaryDirectory() as d:
        scene = os.path.join(d, "play.sdf")
        open(scene, "w").write(RECOVERED)
        open(os.path.join(d, "play.txt"), "w").write("wait-spp 1\nkey space\nwait 40\nkey space\nwait 5\nquit\n")
        log = os.path.join(d, "play.log")
        r = subprocess.run([SDFC, "view", scene, "--script", os.path.join(d, "play.txt"), "--frame-log", log],
                           env=env, capture_output=True, text=True, timeout=300)
        check(r.returncode == 0, f"play session exits 0 (got {r.returncode})")
        frames = [l.split() for l in open(log).read().splitlines() if l.startswith("frame ")]
        field = lambda f, name: float(f[f.index(name) + 1])
        played = [f for f in frames if field(f, "time") > 0]
        if len(played) >= 10:
            scene_s = field(played[-1], "time") - field(played[0], "time")
            wall_s = (field(played[-1], "t_ms") - field(played[0], "t_ms")) / 1000
            check(0.8 * wall_s <= scene_s <= 1.2 * wall_s,
                  f"play advances scene time with the wall clock ({scene_s:.3f} s in {wall_s:.3f} s, "
                  f"{len(played)} frames)")
            check(field(frames[-1], "time") == field(played[-1], "time"), "a second Space pauses time")
        else:
            check(False, f"frames presented while playing ({len(played)})")


    def reload_session(d, replacement, source, what):
        """Runs the viewer on d/main.sdf, replaces `source` by `replacement`
        while it runs (renamed over it, as editors save: a copy in place can be
        seen half written, a failed reload, then a second one), and checks that
        the scene reloads and shows the change."""
        j = lambda name: os.path.join(d, name)
        script = f"""wait-spp 2
save {j('before.png')}
run sleep 0.2; cp '{replacement}' '{source}.new'; mv '{source}.new' '{source}'
wait-reload
wait-spp 2
save {j('after.png')}
quit
"""
        open(j("events.txt"), "w").write(script)
        log = j("frames.log")
        r = subprocess.run([SDFC, "view", j("main.sdf"), "--script", j("events.txt"), "--frame-log", log,
                            "--size", "96x64"], env=env, capture_output=True, text=True, timeout=300)
        sys.stderr.write(r.stderr)
        check(r.returncode == 0, f"{what} session: quit exits 0 (got {r.returncode})")
        events = [l for l in open(log).read().splitlines() if l.startswith("event ")]
        if not check(sum("reload ok" in e for e in events) == 2, f"saving the {what} reloads the scene"):
            sys.stderr.write("events:\n" + "\n".join(events) + "\n")
        before, after = read_png(j("before.png")), read_png(j("after.png"))
        check((np.abs(before - after).max(axis=-1) > 8).mean() > 0.02, f"the reload shows the {what}'s change")

    # A save of an imported file reloads the scene that imports it.
    with tempfile.TemporaryDirectory() as d:
        j = lambda name: os.path.join(d, name)
        os.makedirs(j("lib dir"))
        part = "let part(r) = sphere(radius: r, material: diffuse(albedo: COLOUR))\n"
        open(j("lib dir/parts.sdf"), "w").write(part.replace("COLOUR", "[0.8, 0.3, 0.25]"))
        open(j("lib dir/parts2.sdf"), "w").write(part.replace("COLOUR", "[0.2, 0.4, 0.9]"))
        open(j("main.sdf"), "w").write('import "lib dir/parts.sdf" as lib\n' +
                                       SCENE.replace("SHAPE", "lib.part(0.7)"))
        reload_session(d, j("lib dir/parts2.sdf"), j("lib dir/parts.sdf"), "imported file")

    # A save of a texture the scene reads reloads it too (as an import does).
    with tempfile.TemporaryDirectory() as d:
        j = lambda name: os.path.join(d, name)
        os.makedirs(j("tex dir"))
        for name, colour in (("red.png", (0.9, 0.2, 0.15)), ("blue.png", (0.15, 0.3, 0.9))):
            mpimg.imsave(j("tex dir/" + name), np.tile(np.array(colour, np.float32), (8, 8, 1)))
        shutil.copy(j("tex dir/red.png"), j("tex dir/wood.png"))
        open(j("main.sdf"), "w").write(SCENE.replace(
            "SHAPE", 'sphere(radius: 0.7, material: diffuse(albedo: texture(file: "tex dir/wood.png")))'))
        reload_session(d, j("tex dir/blue.png"), j("tex dir/wood.png"), "texture")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
