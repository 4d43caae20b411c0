"""The Python package against the command line: every function, its error paths,
and the bit-for-bit equalities (eval, render, glsl, spirv). SDFC names the
command-line binary (CTest sets it; default build/cli/sdfc)."""
import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import sdfc

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SDFC = os.environ.get("SDFC", os.path.join(ROOT, "build", "cli", "sdfc"))

SCENE = textwrap.dedent("""\
    render(size: [64, 36], spp: 4)
    camera(position: [0, 2, 6], target: [0, 0.8, 0])
    sun(direction: [0.5, 1, 0.3])
    let clay = diffuse(albedo: [0.8, 0.3, 0.2])
    let r = 1
    scene {
      plane(normal: [0, 1, 0], offset: 0)
      translate([0, 1, 0]) {
        subtract(material: clay) {
          box(size: [1.6, 1.6, 1.6], rounding: 0.1)
          sphere(radius: r)
        }
      }
    }
    """)

BROKEN = "scene {\n  sphere(radus: 1)\n  box(size: [1, 2])\n}\n"


def run(*args, stdin=None):
    return subprocess.run([SDFC, *args], input=stdin, capture_output=True, text=stdin is not None or None)


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory):
    # A folder with a space, as a user's might be.
    path = tmp_path_factory.mktemp("py scenes") / "hello scene.sdf"
    path.write_text(SCENE)
    return str(path)


@pytest.fixture(scope="module")
def scene(scene_file):
    return sdfc.load(scene_file)


@pytest.fixture(scope="module")
def points():
    rng = np.random.default_rng(7)
    return rng.uniform(-2.5, 2.5, size=(200, 3))


# -- load, parse, errors

def test_load_and_parse(scene, scene_file):
    assert scene.path == scene_file
    assert scene.text == SCENE
    assert scene.size == (64, 36)
    assert "clay" in scene.materials
    parsed = sdfc.parse(SCENE)
    assert parsed.path == "<string>"
    assert parsed.diagnostics == []


def test_scene_error_prints_as_check(tmp_path):
    path = tmp_path / "broken.sdf"
    path.write_text(BROKEN)
    with pytest.raises(sdfc.SceneError) as e:
        sdfc.load(str(path))
    check = run("check", str(path))
    assert check.returncode == 1
    assert str(e.value) == check.stderr.decode()
    first = e.value.diagnostics[0]
    assert (first.severity, first.file, first.line, first.column) == ("error", str(path), 2, 10)
    assert "radus" in first.message
    assert all(d.severity == "error" for d in e.value.diagnostics)


def test_parse_error_names_its_source():
    with pytest.raises(sdfc.SceneError) as e:
        sdfc.parse(BROKEN, name="mine.sdf")
    assert str(e.value).startswith("mine.sdf:2:10: error:")


def test_unreadable_file(tmp_path):
    with pytest.raises(sdfc.SceneError, match="cannot read .*missing.sdf"):
        sdfc.load(str(tmp_path / "missing.sdf"))
    with pytest.raises(sdfc.SceneError, match="it is a directory"):
        sdfc.load(str(tmp_path))


def test_defines_as_dash_d(scene_file, points):
    bigger = sdfc.load(scene_file, defines={"r": 0.5})
    cli = run("eval", scene_file, "-D", "r=0.5", stdin="0 1 0\n")
    assert float(cli.stdout.split()[0]) == bigger.eval(np.array([[0.0, 1.0, 0.0]]))[0]
    with pytest.raises(TypeError):
        sdfc.load(scene_file, defines={"r": "big"})


def test_warnings_and_werror(tmp_path):
    path = tmp_path / "warn.sdf"
    path.write_text("scene {\n  scale(factor: [1, 2, 1]) { sphere(radius: 1) }\n}\n")
    s = sdfc.load(str(path))
    assert [d.severity for d in s.diagnostics] == ["warning"]
    name = s.diagnostics[0].name
    with pytest.raises(sdfc.SceneError):
        sdfc.load(str(path), werror=True)
    assert sdfc.load(str(path), disabled_warnings=[name], werror=True).diagnostics == []


# -- the float64 field

def test_eval_bit_equal_to_cli(scene, scene_file, points):
    text = "".join("%.17g %.17g %.17g\n" % tuple(p) for p in points)
    out = run("eval", scene_file, "--gradient", "--material", stdin=text)
    assert out.returncode == 0, out.stderr
    rows = [line.split() for line in out.stdout.splitlines()]
    d = scene.eval(points)
    g = scene.gradient(points)
    m = scene.material(points)
    assert d.dtype == np.float64 and d.shape == (len(points),)
    assert g.dtype == np.float64 and g.shape == (len(points), 3)
    names = scene.materials
    for i, row in enumerate(rows):
        assert float(row[0]) == d[i]  # %.17g round-trips a double exactly
        assert row[1:4] == ["%.12g" % v for v in g[i]]
        assert row[4] == (names[m[i]] if m[i] >= 0 else "-")


def test_material_of_a_shape_without_one_is_the_first(tmp_path):
    # As the renderer shades it (it was -1 here while the image used the first).
    path = tmp_path / "mat.sdf"
    path.write_text("let red = diffuse(albedo: [1, 0, 0])\nlet blue = diffuse(albedo: [0, 0, 1])\n"
                    "scene { translate([-5, 0, 0]) { sphere(radius: 1, material: blue) } sphere(radius: 1) translate([5, 0, 0]) { sphere(radius: 1, material: blue) } }\n")
    s = sdfc.load(str(path))
    m = s.material(np.array([[0.0, 0, 0], [5, 0, 0]]))
    assert [s.materials[i] for i in m] == ["red", "blue"]
    bare = tmp_path / "bare.sdf"
    bare.write_text("scene { sphere(radius: 1) }\n")
    assert list(sdfc.load(str(bare)).material(np.zeros((1, 3)))) == [-1]


def test_eval_threads_agree(scene, points):
    many = np.repeat(points, 100, axis=0)
    assert np.array_equal(scene.eval(many, threads=1), scene.eval(many, threads=2))
    assert np.array_equal(scene.eval(np.asfortranarray(many)), scene.eval(many))
    assert scene.eval(np.zeros((0, 3))).shape == (0,)


def test_eval_releases_the_gil(scene):
    many = np.random.default_rng(1).uniform(-3, 3, size=(400_000, 3))
    ticks = []
    done = threading.Event()

    def work():  # several calls: one is a few milliseconds now
        for _ in range(20):
            scene.eval(many)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(1)
        time.sleep(0.001)
    t.join()
    assert len(ticks) > 3  # the main thread ran Python while eval worked


@pytest.mark.parametrize("bad, error", [
    (np.zeros((4, 2)), ValueError),
    (np.zeros(3), ValueError),
    (np.zeros((2, 3, 1)), ValueError),
    (np.zeros((4, 3), dtype=np.float32), TypeError),
    (np.zeros((4, 3), dtype=np.int64), TypeError),
    ([[0.0, 0.0, 0.0]], TypeError),
])
def test_bad_points(scene, bad, error):
    with pytest.raises(error, match="points"):
        scene.eval(bad)
    with pytest.raises(error, match="points"):
        scene.gradient(bad)


# -- the kernel

def test_glsl_and_spirv_as_compile(scene, scene_file, tmp_path):
    out = run("compile", scene_file, "--emit", "glsl")
    assert scene.glsl() == out.stdout.decode()
    normal = run("compile", scene_file, "--emit", "glsl", "--view", "normal")
    assert scene.glsl(view="normal") == normal.stdout.decode()
    spv = tmp_path / "k.spv"
    assert run("compile", scene_file, "--emit", "spv", "-o", str(spv)).returncode == 0
    words = scene.spirv()
    assert words[:4] == b"\x03\x02\x23\x07" and words == spv.read_bytes()
    with pytest.raises(ValueError, match="view"):
        scene.glsl(view="sideways")


# -- rendering

@pytest.mark.parametrize("args, kwargs", [
    ([], {}),
    (["--spp", "2", "--seed", "3", "--denoise", "none"], dict(spp=2, seed=3, denoise="none")),
    (["--size", "40x20", "--view", "normal"], dict(size=(40, 20), view="normal")),
])
def test_render_bit_equal_to_cli(scene, scene_file, tmp_path, args, kwargs):
    exr = tmp_path / "x.exr"
    out = run("render", scene_file, "-o", str(exr), "--quiet", *args)
    assert out.returncode == 0, out.stderr
    image = scene.render(**kwargs)
    reference = sdfc.read_image(str(exr))
    assert image.dtype == np.float32 and image.shape == reference.shape
    assert np.array_equal(image.view(np.uint32), reference.view(np.uint32))


def test_render_progress_and_time(scene):
    calls = []
    image = scene.render(size=(16, 8), spp=4, progress=lambda done, total: calls.append((done, total)))
    assert image.shape == (8, 16, 3) and np.isfinite(image).all()
    assert calls and calls[-1] == (4, 4)
    with pytest.raises(ZeroDivisionError):
        scene.render(size=(16, 8), spp=4, progress=lambda d, t: 1 / 0)


def test_render_bad_settings(scene):
    with pytest.raises(ValueError, match="denoise"):
        scene.render(size=(8, 8), denoise="magic")
    with pytest.raises(ValueError, match="size"):
        scene.render(size=(0, 8))
    with pytest.raises(ValueError, match="spp"):
        scene.render(size=(8, 8), spp=0)


def test_device_that_cannot_be_created(scene):
    with pytest.raises(sdfc.DeviceError):
        scene.render(size=(8, 8), spp=1, device=99)
    assert isinstance(sdfc.DeviceError("x"), RuntimeError)


def cli_driver():
    """`sdfc devices`' driver line and its devices' driver texts (e.g. "Mesa 25.0.7"),
    in the environment this process started with (os.environ: not the loader's
    variables the module's driver selection set in the C environment since)."""
    out = subprocess.run([SDFC, "devices"], capture_output=True, text=True, env=dict(os.environ))
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("driver: "), out.stdout
    return lines[0][len("driver: "):], [line.rsplit(", ", 1)[1].rstrip(")") for line in lines[1:]]


def python_driver(**env):
    """sdfc.driver() in a fresh process with `env` added (None removes a variable)."""
    child_env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    for key, value in env.items():
        child_env.pop(key, None) if value is None else child_env.__setitem__(key, value)
    out = subprocess.run([sys.executable, "-c", "import sdfc, json; print(json.dumps(sdfc.driver()))"],
                         capture_output=True, text=True, env=child_env)
    return out


def test_driver_is_the_command_lines():
    # The package renders on the driver `sdfc render` uses, so their images are the
    # same bits (test_render_bit_equal_to_cli): an installed wheel carries the
    # bundled lavapipe when it was built beside one (docs/python.md).
    info = sdfc.driver()
    assert info["choice"] in ("auto", "system", "bundled") and info["reason"]
    reason, drivers = cli_driver()
    assert info["bundled"] == reason.startswith("bundled lavapipe"), (info, reason)
    assert [d["driver"] for d in info["devices"]] == drivers, (info, drivers)
    if info["bundled"]:
        assert info["manifest"].endswith("lvp_icd.x86_64.json") and os.path.isfile(info["manifest"])
        assert any(d.startswith("Mesa 25.") for d in drivers), drivers
        if os.environ.get("SDFC_EXPECT_WHEEL_DRIVER") == "1":  # tools/python_wheel_check.sh
            package = os.path.dirname(os.path.realpath(sdfc.__file__))
            assert info["manifest"] == os.path.join(package, "lavapipe-25", "lvp_icd.x86_64.json"), info
    else:
        assert info["manifest"] == ""


def test_driver_chosen_by_the_environment():
    system = python_driver(SDFC_DRIVER="system", SDFC_LAVAPIPE=None)
    assert system.returncode == 0, system.stderr
    assert '"bundled": false' in system.stdout and "--driver system" in system.stdout
    missing = python_driver(SDFC_DRIVER=None, SDFC_LAVAPIPE="/nonexistent/lavapipe")
    assert missing.returncode != 0
    assert "DeviceError" in missing.stderr and "SDFC_LAVAPIPE=/nonexistent/lavapipe" in missing.stderr
    info = sdfc.driver()
    if info["bundled"]:
        # SDFC_LAVAPIPE names a folder (the one in use here) or its manifest.
        folder = os.path.dirname(info["manifest"])
        for named in (folder, info["manifest"]):
            chosen = python_driver(SDFC_DRIVER=None, SDFC_LAVAPIPE=named, VK_DRIVER_FILES=None,
                                   VK_ICD_FILENAMES=None)
            assert chosen.returncode == 0, chosen.stderr
            assert '"bundled": true' in chosen.stdout and "SDFC_LAVAPIPE" in chosen.stdout
            assert "Mesa 25." in chosen.stdout


def test_package_renders_with_the_lavapipe_beside_it(scene_file, tmp_path):
    # The layout a wheel installs (python/CMakeLists.txt): sdfc/lavapipe-25/ with the
    # driver, its libdrm and a manifest naming "./libvulkan_lvp.so". A copy of this
    # package laid out so, in a fresh process, must render with that copy of the
    # driver (not the build tree's) and give the command line's bits.
    info = sdfc.driver()
    if not info["bundled"]:
        pytest.skip("no bundled lavapipe")
    with open(info["manifest"]) as f:
        manifest = json.load(f)
    library = os.path.join(os.path.dirname(info["manifest"]), manifest["ICD"]["library_path"])
    package = tmp_path / "site" / "sdfc"
    shutil.copytree(os.path.dirname(os.path.realpath(sdfc.__file__)), package,
                    ignore=shutil.ignore_patterns("lavapipe-25", "__pycache__"))
    lvp = package / "lavapipe-25"
    lvp.mkdir()
    shutil.copy(library, lvp / "libvulkan_lvp.so")
    shutil.copy(os.path.realpath(os.path.join(os.path.dirname(library), "libdrm.so.2")), lvp / "libdrm.so.2")
    manifest["ICD"]["library_path"] = "./libvulkan_lvp.so"
    (lvp / "lvp_icd.x86_64.json").write_text(json.dumps(manifest))
    child = textwrap.dedent(f"""\
        import json, sys, numpy as np, sdfc
        image = sdfc.load({scene_file!r}).render()
        np.save(sys.argv[1], image)
        mapped = sorted({{l.split()[-1] for l in open("/proc/self/maps") if "libvulkan_lvp" in l}})
        print(json.dumps(dict(sdfc.driver(), mapped=mapped)))
        """)
    env = {k: v for k, v in os.environ.items()
           if k not in ("SDFC_DRIVER", "SDFC_LAVAPIPE", "VK_DRIVER_FILES", "VK_ICD_FILENAMES")}
    env["PYTHONPATH"] = str(tmp_path / "site")
    out = subprocess.run([sys.executable, "-c", child, str(tmp_path / "image.npy")],
                         capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout.splitlines()[-1])
    assert got["bundled"] and got["manifest"] == str(lvp / "lvp_icd.x86_64.json"), got
    assert got["mapped"] == [str(lvp / "libvulkan_lvp.so")], got
    exr = tmp_path / "cli.exr"
    cli = subprocess.run([SDFC, "render", scene_file, "-o", str(exr), "--quiet"], capture_output=True, env=env)
    assert cli.returncode == 0, cli.stderr
    image = np.load(tmp_path / "image.npy")
    assert np.array_equal(image.view(np.uint32), sdfc.read_image(str(exr)).view(np.uint32))


def test_ctrl_c_raises_keyboard_interrupt(scene_file):
    # A render of many passes in a child; SIGINT after its first pass must end it
    # with KeyboardInterrupt within about a pass. The render is long (about 100 s
    # uninterrupted, passes of tens of ms): at 4000 spp it took 2 s, and on a
    # loaded machine it once ended before the signal arrived.
    child = textwrap.dedent(f"""\
        import signal, sys, time, sdfc
        # A job started in the background inherits SIGINT ignored: a terminal's Ctrl-C is not.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        s = sdfc.load({scene_file!r})
        def progress(done, total):
            print("pass", done, flush=True)
        try:
            s.render(size=(64, 36), spp=200000, denoise="none", progress=progress)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(7)
        """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    p = subprocess.Popen([sys.executable, "-c", child], stdout=subprocess.PIPE, text=True, env=env)
    first = p.stdout.readline()
    assert first.startswith("pass"), first
    start = time.monotonic()
    p.send_signal(signal.SIGINT)
    rest = p.stdout.read()
    p.wait(timeout=60)
    assert p.returncode == 7 and "interrupted" in rest, (p.returncode, rest[-500:])
    assert time.monotonic() - start < 20


def test_repr_png(scene):
    png = scene._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 100


# -- meshing

def test_mesh(scene, tmp_path):
    shape = sdfc.parse("let m = diffuse(albedo: [1, 0, 0])\nscene {\n  sphere(radius: 1, material: m)\n}\n")
    v, f, m = shape.mesh(resolution=24)
    assert v.dtype == np.float64 and v.shape[1] == 3
    assert f.dtype == np.uint32 and f.shape[1] == 3 and f.max() < len(v)
    assert m.shape == (len(f),) and set(m.tolist()) == {0}
    assert np.abs(shape.eval(v)).max() < 1e-3
    with pytest.raises(ValueError, match="unbounded|box"):
        scene.mesh(resolution=16)
    v2, f2, _ = scene.mesh(resolution=16, box=[[-2, -0.5, -2], [2, 2.5, 2]])
    assert len(f2) > 0


def test_mesh_errors_name_python_arguments(scene):
    # A Python user was told to "give --box" (the command line's flag).
    with pytest.raises(ValueError, match=r"give box=\[x0, y0, z0, x1, y1, z1\]") as e:
        scene.mesh(resolution=16)
    assert "--" not in str(e.value)
    with pytest.raises(ValueError, match=r"^box must have x0 < x1") as e:
        scene.mesh(resolution=16, box=[[1, 0, 0], [0, 1, 1]])
    with pytest.raises(ValueError, match=r"raise voxel_size or lower resolution") as e:
        scene.mesh(voxel_size=1e-4, box=[[-2, -0.5, -2], [2, 2.5, 2]])
    assert "--" not in str(e.value)


# -- the builder

def test_builder_text_checks(tmp_path):
    s = (sdfc.sphere(1) | sdfc.box([2, 1, 1]).translate([1, 0, 0])).smooth(0.2)
    s = (s - sdfc.cylinder(0.3, 4).rotate_x(90)) & sdfc.box(3)
    s = s.material(sdfc.diffuse([0.8, 0.3, 0.2])) | sdfc.torus(1.5, 0.1).rotate([0, 0, 1], 30).scale(1.2)
    text = str(s)
    path = tmp_path / "built.sdf"
    path.write_text(text)
    check = run("check", str(path))
    assert check.returncode == 0, check.stderr
    assert run("fmt", "--check", str(path)).returncode == 0, text
    scene = s.scene()
    d = scene.eval(np.array([[0.0, 0.6, 0.0], [0.0, 0.0, 0.0]]))
    assert d[0] < 0 and abs(d[1] - 0.3) < 1e-12  # in the solid; on the hole's axis


def test_builder_sky(tmp_path):
    # scene_text and Shape.scene take the language's sky(...) as they take
    # camera and sun (there was no way to give one).
    s = sdfc.sphere(1)
    text = sdfc.scene_text(s, sky={"top": [0.45, 0.6, 0.9], "bottom": [0.9, 0.9, 0.9]})
    assert "sky(top: [0.45, 0.6, 0.9], bottom: [0.9, 0.9, 0.9])" in text
    path = tmp_path / "sky.sdf"
    path.write_text(text)
    assert run("check", str(path)).returncode == 0, text
    dark = s.scene(sky={"color": [0, 0, 0]}, size=(16, 16)).render(spp=1)
    bright = s.scene(sky={"color": [1, 1, 1]}, size=(16, 16)).render(spp=1)
    assert dark[0, 0].max() < 0.05 and bright[0, 0].min() > 0.5  # a corner sees the sky
    assert 'sky(map: "studio.exr", rotation: 30)' in sdfc.scene_text(s, sky={"map": "studio.exr", "rotation": 30})
    with pytest.raises(ValueError, match="quote"):
        sdfc.scene_text(s, sky={"map": 'a"b.exr'})
    with pytest.raises(TypeError, match="dict"):
        sdfc.scene_text(s, sky=[0, 0, 0])


def test_builder_distances():
    s = sdfc.sphere(1).translate([1, 0, 0]).scene()
    p = np.array([[3.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert np.allclose(s.eval(p), [1.0, -1.0])
    with pytest.raises(ValueError):
        sdfc.sphere(1).smooth(0.1)
    with pytest.raises(TypeError):
        sdfc.sphere(1) | 3
