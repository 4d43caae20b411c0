#!/usr/bin/env python3
"""`sdfc export` (issue 34): pages and Shadertoy code for every example, limits refused,
and the page's WebGL2 image against `sdfc render`'s in headless Chromium.

    /usr/bin/python3 tests/export_test.py [--sdfc build/cli/sdfc] [--part files|browser]

files: every example exports as a page and as Shadertoy code (sdfc checks both with
glslang as GLSL ES 3.00), nothing in a page reaches the network, an instance scene
exports, a scene whose data is over the texture's rows is refused (exit 1, nothing
written), and Shadertoy refuses data. browser: the castle's page and an instance
scene's, 64x36, in Chromium with SwiftShader's WebGL2: no console message, the normal
view within a few codes of `sdfc render --view normal`, the beauty within noise of
`sdfc render --denoise none` at the same spp (the same sampler: pass k is sample k).
The browser part does not use the Vulkan driver (the system-driver run may skip it).
"""
import argparse
import base64
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

import matplotlib.image as mpimg
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = sorted(os.path.join(ROOT, "examples", f) for f in os.listdir(os.path.join(ROOT, "examples"))
                  if f.endswith(".sdf"))
SIZE = (64, 36)
SPP = 16

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, **kw)


def instance_scene(path, count, seed=1):
    rng = np.random.default_rng(seed)
    pts = np.round(np.column_stack([rng.uniform(-4, 4, count), rng.uniform(0.3, 1.5, count),
                                    rng.uniform(-4, 4, count)]), 3)
    points = ", ".join("[%g, %g, %g]" % tuple(p) for p in pts)
    with open(path, "w") as f:
        f.write("camera(position: [0, 5, 12], target: [0, 0.5, 0])\nsun(direction: [0.5, 1, 0.3])\n"
                "scene {\n  plane(normal: [0, 1, 0], offset: 0)\n"
                "  instances(positions: [%s]) {\n"
                "    sphere(radius: 0.25, material: diffuse(albedo: [0.8, 0.4, 0.2]))\n  }\n}\n" % points)


def castle_sdf():
    return os.path.join(ROOT, "examples", "castle.sdf")


def files_part(sdfc, tmp):
    for scene in EXAMPLES:
        name = os.path.basename(scene)[:-4]
        page = os.path.join(tmp, name + " page.html")
        r = run([sdfc, "export", scene, "-o", page, "-q"])
        check(r.returncode == 0 and os.path.exists(page) and os.path.getsize(page) > 0, "%s exports as a page (%s)" % (name, r.stderr.strip()))
        if os.path.exists(page):
            text = open(page).read()
            # No other file or host: no src/href attribute in a tag, no CSS url(),
            # fetch, XHR or import.
            outside = re.findall(r"<[^>]*\b(?:src|href)\s*=|url\(|fetch\(|XMLHttpRequest|import\(", text)
            check(not outside, "%s's page loads nothing else %s" % (name, outside[:3]))
        toy = os.path.join(tmp, name + ".shadertoy.glsl")
        r = run([sdfc, "export", scene, "-o", toy, "--target", "shadertoy", "-q"])
        check(r.returncode == 0 and os.path.exists(toy) and "void mainImage(" in open(toy).read(),
              "%s exports for Shadertoy (%s)" % (name, r.stderr.strip()))

    castle = os.path.join(tmp, "castle page.html")
    size = os.path.getsize(castle) if os.path.exists(castle) else 1 << 30
    check(size < 200_000, "the castle's page is under 200 KB (%d bytes)" % size)

    inst = os.path.join(tmp, "instances.sdf")
    instance_scene(inst, 300)
    r = run([sdfc, "export", inst, "-o", os.path.join(tmp, "instances.html"), "-q"])
    check(r.returncode == 0, "a scene with instances exports (%s)" % r.stderr.strip())
    html = os.path.join(tmp, "instances.html")
    check(os.path.exists(html) and '"data": "' in open(html).read(), "its data is in the page")
    r = run([sdfc, "export", inst, "-o", os.path.join(tmp, "instances.glsl"), "--target", "shadertoy"])
    check(r.returncode == 1 and "sdfc: error:" in r.stderr and "Shadertoy" in r.stderr
          and not os.path.exists(os.path.join(tmp, "instances.glsl")),
          "Shadertoy refuses instance data, exit 1 (%d: %s)" % (r.returncode, r.stderr.strip()[:90]))

    big = os.path.join(tmp, "big.sdf")
    instance_scene(big, 3000)
    out = os.path.join(tmp, "big.html")
    r = run([sdfc, "export", big, "-o", out, "--max-data-rows", "1"])
    check(r.returncode == 1 and r.stderr.startswith("sdfc: error: the scene's instance data is")
          and "nothing was written" in r.stderr and not os.path.exists(out),
          "a scene over the data texture is refused, exit 1 (%d: %s)" % (r.returncode, r.stderr.strip()[:120]))
    r = run([sdfc, "export", big, "-o", out, "-q"])
    check(r.returncode == 0, "the same scene fits the default 2048 rows")

    # A file name is data in both outputs (issue 47 item 17): in the page's JSON block no
    # '<', '>' or '&' (a name holding "<!--<script>" kept the block open and the page blank);
    # in Shadertoy's // comment no control character (a newline made the rest of the name code).
    small = "camera(position: [0, 1, 4], target: [0, 0, 0])\nscene {\n  sphere(radius: 1)\n}\n"
    hostile = os.path.join(tmp, "a<!--<script>&>b.sdf")
    with open(hostile, "w") as f:
        f.write(small)
    page = os.path.join(tmp, "hostile.html")
    r = run([sdfc, "export", hostile, "-o", page, "-q"])
    html = open(page).read() if r.returncode == 0 else ""
    m = re.search(r'<script type="application/json" id="sdfc-scene">(.*?)</script>', html, re.S)
    block = m.group(1) if m else ""
    check(m is not None and not any(c in block for c in "<>&") and
          json.loads(block)["name"] == "a<!--<script>&>b",
          "a name holding <!--<script> stays inside the page's JSON block, read back whole (%d)" % r.returncode)
    check(html.count("<script") == 2, "the page has its two script elements and no other")
    toy = os.path.join(tmp, "hostile.glsl")
    hostile = os.path.join(tmp, "x\nvoid main() {}\n\\.sdf")
    with open(hostile, "w") as f:
        f.write(small)
    r = run([sdfc, "export", hostile, "-o", toy, "--target", "shadertoy", "-q"])
    code = open(toy).read() if r.returncode == 0 else ""
    check(r.returncode == 0 and code.startswith("// x\\nvoid main() {}\\n\\x5c: written by") and
          "\nvoid main() {}" not in code,
          "Shadertoy: a newline in the name stays in the first comment line (%d: %s)"
          % (r.returncode, code.split("\n")[0][:60]))

    bad = os.path.join(tmp, "bad scene.sdf")
    with open(bad, "w") as f:
        f.write("scene {\n  sphere(radus: 1)\n}\n")
    r = run([sdfc, "export", bad, "-o", os.path.join(tmp, "bad.html")])
    check(r.returncode == 1 and "bad scene.sdf:2:10: error:" in r.stderr and "^" in r.stderr
          and not os.path.exists(os.path.join(tmp, "bad.html")),
          "a scene with a mistake: file:line:col, caret, exit 1 (%d)" % r.returncode)
    r = run([sdfc, "export", castle_sdf(), "-o", os.path.join(tmp, "x.html"), "--target", "webgpu"])
    check(r.returncode == 2 and r.stderr.startswith("sdfc: error: --target"),
          "an unknown target is a usage error, exit 2 (%d)" % r.returncode)


def chromium():
    for name in ("chromium", "chromium-browser"):
        if shutil.which(name):
            return shutil.which(name)
    return None


# What Shadertoy wraps an image tab's code in: its uniforms before, a main after.
SHADERTOY_HARNESS = """<!DOCTYPE html><html><body><canvas id="c" width="@W@" height="@H@"></canvas>
<pre id="sdfc-result" hidden></pre><script>
const code = @CODE@;
const gl = document.getElementById("c").getContext("webgl2", { preserveDrawingBuffer: true });
const fs = "#version 300 es\\nprecision highp float;\\nprecision highp int;\\nprecision highp sampler2D;\\n" +
  "uniform vec3 iResolution;\\nuniform float iTime;\\nuniform float iTimeDelta;\\nuniform int iFrame;\\n" +
  "uniform vec4 iMouse;\\nuniform vec4 iDate;\\nuniform sampler2D iChannel0;\\n" + code +
  "\\nout vec4 shadertoy_out;\\nvoid main() { mainImage(shadertoy_out, gl_FragCoord.xy); }\\n";
const p = gl.createProgram();
for (const [type, text] of [[gl.VERTEX_SHADER, "#version 300 es\\nvoid main() { vec2 p = vec2(gl_VertexID & 1, " +
    "gl_VertexID >> 1) * 4.0 - 1.0; gl_Position = vec4(p, 0.0, 1.0); }\\n"], [gl.FRAGMENT_SHADER, fs]]) {
  const s = gl.createShader(type); gl.shaderSource(s, text); gl.compileShader(s); gl.attachShader(p, s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) console.error(gl.getShaderInfoLog(s));
}
gl.linkProgram(p);
gl.useProgram(p);
gl.uniform3f(gl.getUniformLocation(p, "iResolution"), @W@, @H@, 1);
gl.bindVertexArray(gl.createVertexArray());
gl.drawArrays(gl.TRIANGLES, 0, 3);
const rgba = new Uint8Array(@W@ * @H@ * 4);
gl.readPixels(0, 0, @W@, @H@, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
let binary = "";
for (let i = 0; i < rgba.length; i += 0x8000) binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
document.getElementById("sdfc-result").textContent = JSON.stringify({ width: @W@, height: @H@,
  views: { normal: { rgba: btoa(binary) } } });
</script></body></html>
"""


def browse(page, views, spp, tmp, url=None):
    """The page's #test result and Chromium's console lines."""
    # preview: the first beauty image at half size first, as a user's page draws it.
    url = url or "file://" + page.replace(" ", "%20") + "#test&preview&views=%s&spp=%d" % (",".join(views), spp)
    r = run([chromium(), "--headless", "--no-sandbox", "--no-first-run",
             "--user-data-dir=" + os.path.join(tmp, "profile"), "--use-gl=angle", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--enable-logging=stderr", "--v=0", "--dump-dom", url],
            timeout=120)
    # ANGLE's note that the test's own readPixels waits for the GPU is no error.
    console = [l for l in r.stderr.splitlines()
               if ":CONSOLE" in l and "GL Driver Message (OpenGL, Performance" not in l]
    m = re.search(r'<pre id="sdfc-result" hidden="">(.*?)</pre>', r.stdout, re.S)
    result = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&")) if m else None
    return result, console


def image(result, view):
    v = result["views"][view]
    rgba = np.frombuffer(base64.b64decode(v["rgba"]), np.uint8).reshape(result["height"], result["width"], 4)
    return rgba[::-1, :, :3].astype(np.int16)  # readPixels is bottom-up


def rendered(sdfc, scene, tmp, *flags):
    out = os.path.join(tmp, "render.png")
    r = run([sdfc, "render", scene, "-o", out, "--size", "%dx%d" % SIZE, "-q", *flags])
    if r.returncode != 0:
        raise SystemExit("render failed: " + r.stderr)
    return np.round(mpimg.imread(out)[:, :, :3] * 255).astype(np.int16)


def browser_part(sdfc, tmp):
    if not chromium():
        raise SystemExit("chromium is not installed (tools/setup.sh installs it)")
    castle = os.path.join(ROOT, "examples", "castle.sdf")
    inst = os.path.join(tmp, "instances.sdf")
    instance_scene(inst, 300)
    for scene, views in ((castle, ("normal", "beauty")), (inst, ("normal",))):
        name = os.path.basename(scene)
        page = os.path.join(tmp, name + " page.html")
        r = run([sdfc, "export", scene, "-o", page, "--size", "%dx%d" % SIZE, "-q"])
        check(r.returncode == 0, "%s exports at 64x36" % name)
        result, console = browse(page, views, SPP, tmp)
        check(result is not None, "%s: the page rendered" % name)
        check(not console, "%s: no console message %s" % (name, console[:2]))
        if result is None:
            continue
        print("      first image %.0f ms after navigation" % result["first_image_ms"])
        web = image(result, "normal")
        ref = rendered(sdfc, scene, tmp, "--view", "normal")
        diff = np.abs(web - ref).max(axis=-1)
        share = float((diff > 3).mean())
        check(share <= 0.01, "%s normal view: %.2f%% of pixels more than 3 codes from render's (max %d)"
              % (name, share * 100, diff.max()))
        if "beauty" in views:
            web = image(result, "beauty").astype(float)
            ref = rendered(sdfc, scene, tmp, "--denoise", "none", "--spp", str(SPP)).astype(float)
            # The same samples on two drivers: most pixels agree; a path whose
            # float rounding differs is noise. Means within 1 code, few pixels off.
            mean = abs(web.mean() - ref.mean())
            far = float((np.abs(web - ref).max(axis=-1) > 24).mean())
            check(mean < 1.0 and far < 0.05, "%s beauty (%d spp): mean differs by %.2f codes, %.1f%% of "
                  "pixels by more than 24" % (name, SPP, mean, far * 100))


def shadertoy_part(sdfc, tmp):
    """The castle's Shadertoy code in Shadertoy's wrapper: the normal view of render."""
    castle = castle_sdf()
    toy = os.path.join(tmp, "castle.shadertoy.glsl")
    # --size: the kernel's pixel cone (march stopping band) is that of render's size.
    r = run([sdfc, "export", castle, "-o", toy, "--target", "shadertoy", "--size", "%dx%d" % SIZE, "-q"])
    check(r.returncode == 0, "the castle exports for Shadertoy")
    w, h = SIZE
    harness = os.path.join(tmp, "shadertoy harness.html")
    code = json.dumps(open(toy).read()).replace("</", "<\\/")
    with open(harness, "w") as f:
        f.write(SHADERTOY_HARNESS.replace("@W@", str(w)).replace("@H@", str(h)).replace("@CODE@", code))
    result, console = browse(None, None, 0, tmp, url="file://" + harness.replace(" ", "%20"))
    check(result is not None and not console, "the Shadertoy code runs in its wrapper %s" % console[:2])
    if result is None:
        return
    # The scene's camera at the render's aspect: the same rays as render --view normal.
    diff = np.abs(image(result, "normal") - rendered(sdfc, castle, tmp, "--view", "normal")).max(axis=-1)
    share = float((diff > 3).mean())
    check(share <= 0.01, "Shadertoy normal view: %.2f%% of pixels more than 3 codes from render's (max %d)"
          % (share * 100, diff.max()))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sdfc", default=os.path.join(ROOT, "build", "cli", "sdfc"))
    p.add_argument("--part", choices=("files", "browser"), default=None)
    a = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="sdfc export ") as tmp:
        if a.part in (None, "files"):
            files_part(a.sdfc, tmp)
        if a.part in (None, "browser"):
            browser_part(a.sdfc, tmp)
            shadertoy_part(a.sdfc, tmp)
    if failures:
        print("%d failed" % len(failures))
        return 1
    print("all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
