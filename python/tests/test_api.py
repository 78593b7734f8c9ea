"""The Python API's own behaviour: input dtypes and orders, no copy of float32 input, falloff
maps, prepared scenes reused, pickling, the GIL released, Ctrl-C, type stubs and docstrings."""

from __future__ import annotations

import ast
import inspect
import json
import os
import pickle
import signal
import subprocess
import sys
import textwrap
import threading
import time
import warnings
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import luxeval
import luxeval._luxeval as native
from helpers import LUXTEST, STUDIO, cli_query, floor_points, run_cli, sphere_dirs


@pytest.fixture(scope="module")
def stage():
    return luxeval.Stage(STUDIO)


def test_any_real_dtype_and_order_gives_the_float32_result(stage, device):
    base = sphere_dirs(500, seed=11) * np.float32(2.5)  # any non-zero length is fine
    want = stage.emission(base, device=device)
    f64 = base.astype(np.float64)
    variants = {
        "float64": f64,
        "float32 fortran": np.asfortranarray(base),
        "float64 fortran": np.asfortranarray(f64),
        "strided": np.repeat(base, 2, axis=0)[::2],
        "big-endian": base.astype(">f4"),
        "misaligned": np.frombuffer(b"\0" + base.tobytes(), np.float32, offset=1).reshape(-1, 3),
        "list": base.tolist(),
    }
    for name, x in variants.items():
        np.testing.assert_array_equal(stage.emission(x, device=device), want, err_msg=name)
    # Other dtypes: the same as their values converted to float32.
    for x in [base.astype(np.float16), np.array([[0, -1, 0], [3, 0, 0], [0, 0, -2]], dtype=np.int64),
              np.array([[1, 1, 1]], dtype=np.uint8), base.astype(np.longdouble)]:
        got = stage.emission(x, device=device)
        np.testing.assert_array_equal(got, stage.emission(x.astype(np.float32), device=device))
        assert got.dtype == np.float32 and got.shape == (len(x), 3)


def test_contiguous_float32_input_is_not_copied(stage):
    n = 1 << 20  # 12 MiB of float32 input
    dirs = np.tile(sphere_dirs(1024, seed=12), (n // 1024, 1))
    assert dirs.flags.c_contiguous and dirs.dtype == np.float32
    stage.emission(dirs[:10], device="cpu")  # prepare outside the measurement

    def peak(x):
        tracemalloc.start()
        try:
            out = stage.emission(x, device="cpu")
            return tracemalloc.get_traced_memory()[1], out
        finally:
            tracemalloc.stop()

    in_place, a = peak(dirs)
    copied, b = peak(np.asfortranarray(dirs))
    np.testing.assert_array_equal(a, b)
    # NumPy reports its allocations to tracemalloc; the result buffer is Rust's and is not
    # counted. A Fortran-order input is copied once (12 MiB), C-contiguous float32 not at all.
    assert copied >= dirs.nbytes
    assert in_place < dirs.nbytes // 8, (in_place, copied)


def test_empty_input_gives_empty_output(stage, device):
    assert stage.emission(np.zeros((0, 3)), device=device).shape == (0, 3)
    assert stage.irradiance(np.zeros((0, 3)), np.zeros((0, 3)), per_light=True, device=device).shape == (6, 0, 3)


def test_per_light_rows_follow_light_paths_and_sum(stage, device):
    dirs = sphere_dirs(400, seed=13)
    per = stage.emission(dirs, per_light=True, device=device)
    assert per.shape == (6, 400, 3)
    for i, path in enumerate(stage.light_paths()):
        np.testing.assert_array_equal(per[i], stage.emission(dirs, lights=[path], device=device))
    # Lights do not occlude each other: the sum is the sum of the per-light rows.
    np.testing.assert_allclose(per.sum(axis=0), stage.emission(dirs, device=device), rtol=1e-5, atol=1e-6)


def _pixel_centres(origin, u, v, w, h):
    """Pixel (row j, column i) at origin + (i + 1/2)/W u + (1 - (j + 1/2)/H) v, row 0 at the top,
    in f64 (the order of operations of falloff::Plane::pixel_centre), then float32."""
    s = (np.arange(w) + 0.5) / w
    t = 1.0 - (np.arange(h) + 0.5) / h
    p = (origin + s[None, :, None] * u) + t[:, None, None] * v
    return p.astype(np.float32)


def test_falloff_is_irradiance_at_the_pixel_centres(stage, device):
    origin, u, v = np.array([-5.0, 0, 5]), np.array([10.0, 0, 0]), np.array([0, 0, -10.0])
    m = stage.falloff(origin, u, v, (24, 16), device=device)
    assert m.shape == (16, 24, 3) and m.dtype == np.float32
    pts = _pixel_centres(origin, u, v, 24, 16).reshape(-1, 3)
    normals = np.tile(np.float32([0, 1, 0]), (len(pts), 1))  # normalize(u × v)
    np.testing.assert_array_equal(m.reshape(-1, 3), stage.irradiance(pts, normals, device=device))


def test_falloff_image_orientation(tmp_path, device):
    """A small sphere light 1 m above (-4, 0, 4), at s = t = 0.1 of the plane: the brightest
    pixels are near the image's bottom-left (row 0 is the top, the origin + v edge)."""
    f = tmp_path / "spot.usda"
    f.write_text('#usda 1.0\ndef SphereLight "l"\n{\n    float inputs:radius = 0.1\n'
                 '    double3 xformOp:translate = (-4, 1, 4)\n'
                 '    uniform token[] xformOpOrder = ["xformOp:translate"]\n}\n')
    m = luxeval.Stage(f).falloff([-5, 0, 5], [10, 0, 0], [0, 0, -10], (20, 10), device=device)
    lum = m.sum(axis=2)
    # Pixel centres s = (i + 1/2)/20 and t = 1 - (j + 1/2)/10 are nearest 0.1 at i in {1, 2},
    # j in {8, 9}, which are equidistant from the light.
    row, col = np.unravel_index(np.argmax(lum), lum.shape)
    assert row in (8, 9) and col in (1, 2), (row, col)
    assert lum[8:10, 1:3].min() > 0.999 * lum.max()
    assert lum[0, 19] < 0.05 * lum.max()


def _read_exr(path: Path) -> np.ndarray:
    """A scanline EXR of float R, G, B (ZIP, ZIPS or no compression) as (H, W, 3): enough to
    read what `luxeval falloff` writes, written from the OpenEXR file layout."""
    import struct
    import zlib

    b = path.read_bytes()
    assert struct.unpack_from("<I", b, 0)[0] == 20000630, "not an EXR file"
    pos, attrs = 8, {}
    while b[pos] != 0:
        name_end = b.index(b"\0", pos)
        type_end = b.index(b"\0", name_end + 1)
        size = struct.unpack_from("<i", b, type_end + 1)[0]
        start = type_end + 5
        attrs[b[pos:name_end].decode()] = b[start:start + size]
        pos = start + size
    pos += 1
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attrs["dataWindow"])
    w, h = xmax - xmin + 1, ymax - ymin + 1
    compression = attrs["compression"][0]
    lines = {0: 1, 2: 1, 3: 16}[compression]  # none, ZIPS, ZIP
    channels, c = [], attrs["channels"]
    while c[0] != 0:
        end = c.index(b"\0")
        channels.append((c[:end].decode(), struct.unpack_from("<i", c, end + 1)[0]))
        c = c[end + 1 + 16:]
    assert [t for _, t in channels] == [2] * len(channels), "float channels only"
    names = [n for n, _ in channels]
    blocks = (h + lines - 1) // lines
    offsets = struct.unpack_from(f"<{blocks}Q", b, pos)
    img = np.zeros((h, w, len(names)), np.float32)
    for off in offsets:
        y, size = struct.unpack_from("<ii", b, off)
        data = b[off + 8: off + 8 + size]
        n_lines = min(lines, ymax + 1 - y)
        raw_size = n_lines * w * 4 * len(names)
        if compression != 0 and size < raw_size:
            t = np.frombuffer(zlib.decompress(data), np.uint8).astype(np.int32)
            t = (np.cumsum(np.concatenate([t[:1], t[1:] - 128])) & 0xFF).astype(np.uint8)
            half = (len(t) + 1) // 2
            raw = np.empty_like(t)
            raw[0::2], raw[1::2] = t[:half], t[half:]
            data = raw.tobytes()
        rows = np.frombuffer(data, "<f4").reshape(n_lines, len(names), w)
        img[y - ymin: y - ymin + n_lines] = rows.transpose(0, 2, 1)
    return img[:, :, [names.index(ch) for ch in "RGB"]]


def test_falloff_equals_the_cli_exr(cli, tmp_path, device):
    stage = luxeval.Stage(STUDIO)
    m = stage.falloff([-4, 0, 4], [8, 0, 0], [0, 0, -8], (40, 20), device=device)
    out = tmp_path / "map.exr"
    run_cli(cli, "falloff", STUDIO, "--origin", "-4,0,4", "--u", "8,0,0", "--v", "0,0,-8",
            "--res", "40,20", "-o", out, "--device", device)
    np.testing.assert_array_equal(m, _read_exr(out))


def test_falloff_equals_cli_irradiance_on_a_tilted_plane(cli, tmp_path, device):
    """A plane whose normal is not axis-aligned: the same pixel centres through the CLI."""
    origin, u, v = np.array([-3.0, 0.2, 2]), np.array([6.0, 1.0, 0]), np.array([0, 0.5, -5.0])
    stage = luxeval.Stage(STUDIO)
    m = stage.falloff(origin, u, v, (12, 10), device=device)
    pts = _pixel_centres(origin, u, v, 12, 10).reshape(-1, 3)
    n = np.cross(u, v)
    # glam normalises by multiplying with the reciprocal length.
    normals = np.tile((n * (1.0 / np.linalg.norm(n))).astype(np.float32), (len(pts), 1))
    want = cli_query(cli, tmp_path, "irradiance", STUDIO, {"points": pts, "normals": normals},
                     "--device", device)
    np.testing.assert_array_equal(m.reshape(-1, 3), want)


def test_tolerance_equals_the_cli(cli, tmp_path):
    """``tolerance=`` is the CLI's ``--tolerance`` (default 1e-4 on both), and the reference's
    1e-9 on the CPU moves the shaped spot's floor by less than 1e-4."""
    scene = LUXTEST / "sphere.usda"
    stage = luxeval.Stage(scene, time=31)
    pts = floor_points(6)
    normals = np.tile(np.array([0, 1, 0], np.float32), (len(pts), 1))
    for tol in (1e-4, 1e-9):
        got = stage.irradiance(pts, normals, device="cpu", tolerance=tol)
        flags = ["--device", "cpu", "--time", "31"]
        if tol != 1e-4:
            flags += ["--tolerance", str(tol)]
        want = cli_query(cli, tmp_path, "irradiance", scene, {"points": pts, "normals": normals},
                         *flags)
        np.testing.assert_array_equal(got, want)
    loose = stage.irradiance(pts, normals, device="cpu")
    exact = stage.irradiance(pts, normals, device="cpu", tolerance=1e-9)
    assert exact.max() > 0
    np.testing.assert_allclose(loose, exact, rtol=1e-4, atol=0)
    with pytest.raises(luxeval.InputError, match="tolerance"):
        stage.irradiance(pts, normals, device="cpu", tolerance=0.5)
    with pytest.raises(luxeval.InputError, match="tolerance"):
        stage.falloff([-1, 0, 1], [2, 0, 0], [0, 0, -2], (2, 2), device="cpu", tolerance=0.0)


def test_prepared_lights_are_reused(device):
    stage = luxeval.Stage(STUDIO)
    assert stage.prepared == []
    dirs = sphere_dirs(100)
    stage.emission(dirs, device=device)
    stage.radiance(floor_points(100), dirs, device=device)
    stage.irradiance(floor_points(100), np.tile([0, 1.0, 0], (100, 1)), device=device)
    assert stage.prepared == [(None, device, "spec", "bilinear")]
    stage.emission(dirs, device=device, lights=["/lights/sun", "/lights/key"])
    stage.emission(dirs, device=device, lights=["/lights/key", "/lights/sun"])
    stage.emission(dirs, device=device, temperature_mode="usd")
    stage.emission(dirs, device=device, texture_filter="nearest")
    assert stage.prepared == [
        (None, device, "spec", "bilinear"),
        (None, device, "spec", "nearest"),
        (None, device, "usd", "bilinear"),
        (("/lights/key", "/lights/sun"), device, "spec", "bilinear"),
    ]


def test_auto_is_a_hardware_gpu_else_the_cpu(cli):
    """DESIGN.md §4: ``device="auto"`` picks a hardware adapter when the machine has one, and
    never a software one (lavapipe, on CI: ``device="gpu"`` opens that)."""
    info = json.loads(subprocess.run([str(cli), "info", "--json"], capture_output=True,
                                     text=True, check=True).stdout)
    hardware = any(a["device_type"] != "Cpu" for a in info["adapters"])
    stage = luxeval.Stage(STUDIO)
    stage.emission(sphere_dirs(10))
    assert stage.prepared == [(None, "gpu" if hardware else "cpu", "spec", "bilinear")]
    assert (luxeval.device_name() != "cpu (f64 reference)") == hardware


def test_time_is_read_as_given():
    rect = STUDIO.parents[1] / "tests" / "data" / "luxtest" / "usd" / "rect.usda"
    default = luxeval.Stage(rect)
    assert (default.time_rule, default.time) == ("start_time_code", 1.0)
    at5 = luxeval.Stage(rect, time=5)
    assert (at5.time_rule, at5.time) == ("given", 5.0)
    assert default.lights != at5.lights  # the luxtest rect light is animated


def test_a_stage_pickles_by_path_and_time(tmp_path):
    stage = luxeval.Stage(STUDIO.parents[1] / "tests" / "data" / "luxtest" / "usd" / "rect.usda", time=5)
    again = pickle.loads(pickle.dumps(stage))
    assert isinstance(again, luxeval.Stage)
    assert again.lights == stage.lights and again.time == 5.0
    dirs = sphere_dirs(50)
    np.testing.assert_array_equal(again.emission(dirs, device="cpu"), stage.emission(dirs, device="cpu"))
    assert again.prepared == [(None, "cpu", "spec", "bilinear")]  # prepared lights are not pickled


def test_the_gil_is_released_while_the_device_works(stage):
    pts = floor_points(40000, seed=14)
    normals = np.tile(np.float32([0, 1, 0]), (len(pts), 1))
    stage.irradiance(pts[:10], normals[:10], device="cpu")  # prepares (not timed: under load
    # the preparation would make the rows look slower than they are, and the call too short)
    t0 = time.perf_counter()
    stage.irradiance(pts[:1000], normals[:1000], device="cpu")  # times 1000 rows
    n = min(len(pts), max(200, int(1000 * 1.5 / (time.perf_counter() - t0))))  # about 1.5 s

    def run(n):
        done = threading.Event()
        window = []

        def work():
            t0 = time.perf_counter()
            stage.irradiance(pts[:n], normals[:n], device="cpu")
            window.append(time.perf_counter() - t0)
            done.set()

        t = threading.Thread(target=work)
        ticks = 0
        t.start()
        while not done.is_set():
            time.sleep(0.002)  # needs the GIL to wake up
            ticks += 1
        t.join()
        return window[0], ticks

    window, ticks = run(n)
    # A machine that sped up since the timing: once more with four times the rows.
    if window <= 0.3 and n < len(pts):
        window, ticks = run(min(len(pts), 4 * n))
    # Holding the GIL, the call would let this thread wake up only between its chunks (about
    # four per second); released, it wakes up every few milliseconds.
    assert window > 0.3, "the call must last long enough to tell"
    assert ticks >= 20 * window, (ticks, window)


CHILD = textwrap.dedent(
    """
    import signal, sys, time
    import numpy as np
    import luxeval
    # A process started in the background by a shell without job control (as a CI runner may
    # start the tests) inherits SIGINT ignored, and Python then installs no KeyboardInterrupt
    # handler: install Python's own, as an interactive session has it.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    stage = luxeval.Stage(sys.argv[1])
    rng = np.random.default_rng(0)
    pts = np.zeros((300, 3), np.float32)
    pts[:, 0] = rng.uniform(-4, 4, 300)
    pts[:, 2] = rng.uniform(-4, 4, 300)
    up = np.tile(np.float32([0, 1, 0]), (300, 1))
    stage.irradiance(pts[:10], up[:10], device="cpu")  # prepare
    t0 = time.perf_counter()
    stage.irradiance(pts, up, device="cpu")
    per_row = (time.perf_counter() - t0) / 300
    n = int(60.0 / per_row)  # a call of about a minute
    reps = -(-n // 300)
    big_p, big_n = np.tile(pts, (reps, 1)), np.tile(up, (reps, 1))
    print("start", flush=True)
    t0 = time.perf_counter()
    try:
        stage.irradiance(big_p, big_n, device="cpu")
        print("finished", time.perf_counter() - t0, flush=True)
        sys.exit(1)
    except KeyboardInterrupt:
        print("interrupted", time.perf_counter() - t0, flush=True)
    out = stage.irradiance(pts[:10], up[:10], device="cpu")
    print("usable", out.shape, flush=True)
    """
)


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
def test_ctrl_c_stops_a_long_call_cleanly():
    p = subprocess.Popen([sys.executable, "-c", CHILD, str(STUDIO)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(1.0)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    lines = out.splitlines()
    assert p.returncode == 0, (out, err)
    assert lines[0].startswith("interrupted"), (out, err)
    # Interrupted within a chunk or two of the signal (chunks last about 0.25 s), not after the
    # minute the call would take.
    assert float(lines[0].split()[1]) < 10.0, lines
    assert lines[1] == "usable (10, 3)"


STUB = Path(native.__file__).with_name("_luxeval.pyi")


def _stub_names():
    tree = ast.parse(STUB.read_text())
    top, members = {}, {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            top[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            top[node.target.id] = node
    for node in top["Stage"].body:
        if isinstance(node, ast.FunctionDef):
            members[node.name] = node
    return top, members


def test_the_stubs_name_every_public_name_with_its_signature():
    assert STUB.is_file(), "the stubs are installed next to the extension"
    top, members = _stub_names()
    public = {n for n in dir(native) if not n.startswith("_")} | {"__version__"}
    assert public == set(top), public ^ set(top)
    assert set(luxeval.__all__) == public
    stage_public = {n for n in dir(luxeval.Stage) if not n.startswith("_")}
    assert stage_public == {n for n in members if not n.startswith("_")}, stage_public ^ set(members)
    for name in ("emission", "radiance", "irradiance", "falloff", "sample", "pdf", "light_paths"):
        runtime = inspect.signature(getattr(luxeval.Stage, name))
        stub_args = members[name].args
        stub = [a.arg for a in stub_args.args + stub_args.kwonlyargs]
        assert list(runtime.parameters) == stub, (name, list(runtime.parameters), stub)
        stub_defaults = [ast.literal_eval(d) for d in stub_args.kw_defaults + stub_args.defaults]
        runtime_defaults = [p.default for p in runtime.parameters.values() if p.default is not p.empty]
        assert sorted(map(repr, runtime_defaults)) == sorted(map(repr, stub_defaults)), name
    assert list(inspect.signature(luxeval.device_name).parameters) == ["device"]


def test_every_public_name_has_a_docstring():
    import luxeval.dask

    objects = [luxeval, luxeval.dask, luxeval.Stage, luxeval.InputError, luxeval.DeviceError,
               luxeval.DeviceWarning, luxeval.device_name]
    objects += [getattr(luxeval.Stage, n) for n in dir(luxeval.Stage) if not n.startswith("_")]
    objects += [getattr(luxeval.dask, n) for n in luxeval.dask.__all__]
    for o in objects:
        assert (o.__doc__ or "").strip(), o
    top, members = _stub_names()
    for name, node in list(top.items()) + list(members.items()):
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and not name.startswith("_") and name != "__init__":
            assert ast.get_docstring(node), f"stub of {name} has no docstring"
    assert issubclass(luxeval.InputError, ValueError)
    assert issubclass(luxeval.DeviceError, RuntimeError)
    assert issubclass(luxeval.DeviceWarning, RuntimeWarning)


def dense_ies() -> str:
    """The 1°-by-5° type C profile of ``luxeval::testkit::ies::dense_profile``: near a large
    light shaped by it, a receiver's quadrature crosses more grid surfaces than lavapipe's loop
    budget allows."""
    v = list(range(181))
    h = [5 * k for k in range(73)]
    out = "IESNA:LM-63-2002\r\n[TEST] dense\r\nTILT=NONE\r\n"
    out += f"1 -1 1 {len(v)} {len(h)} 1 2 0.1 0.1 0\r\n1 1 0\r\n"
    out += " ".join(map(str, v)) + "\r\n" + " ".join(map(str, h)) + "\r\n"
    for hh in h:
        row = [100 + 50 * np.cos(np.radians(vv) * 3) * np.sin(np.radians(hh) * 2) for vv in v]
        out += " ".join(repr(float(x)) for x in row) + "\r\n"
    return out


def test_the_host_recomputed_rows_are_announced(tmp_path, cli):
    """Irradiance rows the device cannot finish (on lavapipe: its loop budget) are recomputed on
    the CPU reference, and the call says how many with a UserWarning, as ``luxeval`` prints a
    ``note:``; the values are the CPU path's within the tolerance of each."""
    (tmp_path / "dense.ies").write_text(dense_ies())
    stage_path = tmp_path / "dense.usda"
    stage_path.write_text('#usda 1.0\ndef RectLight "L" (\n    prepend apiSchemas = ["ShapingAPI"]\n)\n'
                          '{\n    float inputs:width = 2\n    float inputs:height = 2\n'
                          '    asset inputs:shaping:ies:file = @dense.ies@\n}\n')
    info = json.loads(subprocess.run([str(cli), "info", "--json"], capture_output=True,
                                     text=True, check=True).stdout)
    software = all("llvmpipe" in a["name"] for a in info["adapters"]) and info["adapters"]
    stage = luxeval.Stage(stage_path)
    args = ([-0.5, -0.5, -0.1], [1, 0, 0], [0, 1, 0], (4, 2))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gpu = stage.falloff(*args, device="gpu")
    said = [str(w.message) for w in caught if "recomputed on the CPU reference" in str(w.message)]
    if software:
        assert len(said) == 1 and "of 8 irradiance rows" in said[0] and "dense.usda" in said[0], said
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cpu = stage.falloff(*args, device="cpu")
    assert not [w for w in caught if "recomputed" in str(w.message)]
    assert (cpu > 0).all()
    np.testing.assert_allclose(gpu, cpu, rtol=2e-4)


def _many_lights(tmp_path: Path, n: int) -> Path:
    """A stage of ``n`` SphereLights, four to an Xform under /World: n + n/4 + 1 prims."""
    groups = []
    for g in range(n // 4):
        lights = "".join(
            f'        def SphereLight "L{l}"\n        {{\n            float inputs:intensity = {l + 1}\n'
            f"            double3 xformOp:translate = ({g}, {l}, 0)\n"
            '            uniform token[] xformOpOrder = ["xformOp:translate"]\n        }\n'
            for l in range(4)
        )
        groups.append(f'    def Xform "G{g}"\n    {{\n{lights}    }}\n')
    path = tmp_path / "many.usda"
    path.write_text('#usda 1.0\n\ndef Xform "World"\n{\n' + "".join(groups) + "}\n")
    return path


def test_progress_reports_each_step_of_reading_a_stage(tmp_path):
    n = 2048
    prims = n + n // 4 + 1
    path = _many_lights(tmp_path, n)
    seen = []

    def progress(step, done, total):
        # The last report comes again while the reader is silent: kept once.
        if not seen or seen[-1] != (step, done, total):
            seen.append((step, done, total))

    stage = luxeval.Stage(path, progress=progress)
    assert len(stage.lights) == n
    assert seen[:2] == [("opening", None, None), ("checking", None, None)]
    order = ["opening", "checking", "composing", "finding", "reading"]
    assert [order.index(s) for s, _, _ in seen] == sorted(order.index(s) for s, _, _ in seen)
    assert [d for s, d, _ in seen if s == "composing"] == [0, 1024, 2048, prims]
    assert [(d, t) for s, d, t in seen if s == "finding"] == [(d, prims) for d in (0, 1024, 2048, prims)]
    assert [(d, t) for s, d, t in seen if s == "reading"] == [(d, n) for d in (0, 1024, 2048)]
    # The same lights as without progress.
    assert stage.lights == luxeval.Stage(path).lights


def test_an_exception_in_progress_stops_reading_and_propagates(tmp_path):
    path = _many_lights(tmp_path, 16)

    class Enough(Exception):
        pass

    calls = []

    def progress(step, done, total):
        calls.append(step)
        if step == "composing":
            raise Enough(step)

    with pytest.raises(Enough, match="composing"):
        luxeval.Stage(path, progress=progress)
    # Not called again once it raised.
    assert calls == ["opening", "checking", "composing"]
    with pytest.raises(TypeError, match="progress: must be callable"):
        luxeval.Stage(path, progress=3)


CHILD_LOAD = textwrap.dedent(
    """
    import signal, sys, time
    import luxeval
    signal.signal(signal.SIGINT, signal.default_int_handler)
    print("start", flush=True)
    t0 = time.perf_counter()
    try:
        luxeval.Stage(sys.argv[1])
        print("finished", time.perf_counter() - t0, flush=True)
    except KeyboardInterrupt:
        print("interrupted", time.perf_counter() - t0, flush=True)
    """
)


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
def test_ctrl_c_stops_reading_a_big_stage(tmp_path):
    # 40,000 lights: tens of seconds to read with the tests' unoptimised build, most of it in
    # openusd's parse and composition, which report nothing: the caller's quarter-second
    # heartbeat is what runs the signal handlers meanwhile.
    path = _many_lights(tmp_path, 40_000)
    p = subprocess.Popen([sys.executable, "-c", CHILD_LOAD, str(path)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(1.0)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 0, (out, err)
    word, seconds = out.split()
    assert word == "interrupted", (out, err)
    assert float(seconds) < 5.0, out
