"""Bad input raises InputError (a ValueError) naming the file, prim and attribute or the
argument; no GPU raises DeviceError with device="gpu" and falls back with one DeviceWarning with
device="auto"."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import luxeval
from helpers import STUDIO, sphere_dirs


@pytest.fixture(scope="module")
def stage():
    return luxeval.Stage(STUDIO)


def test_missing_file(tmp_path):
    missing = tmp_path / "nope.usda"
    with pytest.raises(luxeval.InputError, match=re.escape(str(missing))):
        luxeval.Stage(missing)


def test_malformed_stage_names_the_file_and_line(tmp_path):
    bad = tmp_path / "bad.usda"
    bad.write_text('#usda 1.0\n\ndef SphereLight "l"\n{\n    float inputs:radius = \n}\n')
    with pytest.raises(luxeval.InputError, match=re.escape(str(bad))) as e:
        luxeval.Stage(bad)
    assert isinstance(e.value, ValueError)


def test_not_a_usd_file(tmp_path):
    bad = tmp_path / "notes.usda"
    bad.write_text("these are not the lights you are looking for\n")
    with pytest.raises(luxeval.InputError, match=re.escape(str(bad))):
        luxeval.Stage(bad)


def test_bad_attribute_names_file_prim_and_attribute(tmp_path):
    f = tmp_path / "negative.usda"
    f.write_text(textwrap.dedent("""\
        #usda 1.0
        def SphereLight "ok"
        {
        }
        def SphereLight "bad"
        {
            float inputs:radius = -1
        }
        """))
    stage = luxeval.Stage(f)  # reading is fine: the lights are listed as authored
    assert stage.light_paths() == ["/ok", "/bad"]
    for call in (lambda: stage.emission(sphere_dirs(4)),
                 lambda: stage.falloff([0, 0, 0], [1, 0, 0], [0, 0, -1], (2, 2))):
        with pytest.raises(luxeval.InputError) as e:
            call()
        msg = str(e.value)
        assert str(f) in msg and "/bad" in msg and "inputs:radius" in msg, msg
    # The other light alone is fine.
    assert stage.emission(sphere_dirs(4), lights="/ok").shape == (4, 3)


def test_bad_time(tmp_path):
    with pytest.raises(luxeval.InputError, match="time: NaN is not a finite time code"):
        luxeval.Stage(STUDIO, time=float("nan"))
    with pytest.raises(TypeError):
        luxeval.Stage(STUDIO, time="five")
    with pytest.raises(TypeError):
        luxeval.Stage(42)


@pytest.mark.parametrize(
    "dirs, message",
    [
        (np.zeros((4, 2)), r"dirs: shape \(4, 2\); expected \(N, 3\)"),
        (np.zeros(3), r"dirs: shape \(3,\); expected \(N, 3\)"),
        (np.zeros((2, 4, 3)), r"dirs: shape \(2, 4, 3\); expected \(N, 3\)"),
        (np.array([[0, 1, 0], [np.nan, 0, 1]]), r"dirs: row 1 = \[nan, 0.0, 1.0\] is not finite"),
        (np.array([[0, 1, 0], [0, np.inf, 1]], np.float32), r"dirs: row 1 .* is not finite"),
        (np.array([[0, 1, 0], [1e300, 0, 0]]), r"dirs: row 1 = \[1e\+300, 0.0, 0.0\] is outside float32's range"),
        (np.array([[0, 1, 0], [0, 0, 0]]), r"dirs: row 1 = \[0, 0, 0\] is the zero vector"),
        (np.array([["a", "b", "c"]]), r"dirs: dtype <U1 is not a real number type"),
        (np.zeros((2, 3), np.complex64), r"dirs: dtype complex64 is not a real number type"),
        ([[1, 2, 3], [4, 5]], r"dirs: cannot be read as an array"),
        (None, r"dirs: dtype object is not a real number type"),
    ],
)
def test_bad_directions(stage, dirs, message):
    with pytest.raises(luxeval.InputError, match=message):
        stage.emission(dirs, device="cpu")


def test_bad_pairs(stage):
    p = np.zeros((5, 3))
    with pytest.raises(luxeval.InputError, match="points/dirs: 5 points but 4 dirs"):
        stage.radiance(p, sphere_dirs(4))
    with pytest.raises(luxeval.InputError, match="points: row 2 .* not finite"):
        stage.irradiance(np.array([[0, 0, 0], [0, 0, 0], [0, np.nan, 0]]), sphere_dirs(3))
    # A point may be zero, a normal may not.
    with pytest.raises(luxeval.InputError, match="normals: row 0 .* zero vector"):
        stage.irradiance(np.zeros((1, 3)), np.zeros((1, 3)))


def test_bad_options(stage):
    dirs = sphere_dirs(3)
    with pytest.raises(luxeval.InputError, match=r'device: "tpu" is not one of'):
        stage.emission(dirs, device="tpu")
    with pytest.raises(luxeval.InputError, match=r'temperature_mode: "kelvin" is not one of'):
        stage.emission(dirs, temperature_mode="kelvin")
    with pytest.raises(luxeval.InputError, match=r'texture_filter: "cubic" is not one of'):
        stage.emission(dirs, texture_filter="cubic")
    with pytest.raises(luxeval.InputError, match=r"lights: /lights/nope is not a light of .*studio.usda"):
        stage.emission(dirs, lights=["/lights/key", "/lights/nope"])
    with pytest.raises(luxeval.InputError, match="lights: an empty list selects no light"):
        stage.emission(dirs, lights=[])
    with pytest.raises(luxeval.InputError, match="lights: expected None, a prim path or a list"):
        stage.emission(dirs, lights=[1, 2])
    with pytest.raises(TypeError):
        stage.emission(dirs, per_light="yes")


def test_bad_falloff_arguments(stage):
    o, u, v = [0, 0, 0], [1, 0, 0], [0, 0, -1]
    with pytest.raises(luxeval.InputError, match=r"u/v: .* are parallel or zero"):
        stage.falloff(o, u, [2, 0, 0], (4, 4))
    with pytest.raises(luxeval.InputError, match=r"res: expected \(width, height\)"):
        stage.falloff(o, u, v, (0, 4))
    with pytest.raises(luxeval.InputError, match=r"res: expected \(width, height\)"):
        stage.falloff(o, u, v, 16)
    with pytest.raises(luxeval.InputError, match=r"res: 100000×100000 is more than"):
        stage.falloff(o, u, v, (100_000, 100_000))
    with pytest.raises(luxeval.InputError, match=r"origin: \[nan, 0.0, 0.0\] is not finite"):
        stage.falloff([np.nan, 0, 0], u, v, (4, 4))
    with pytest.raises(luxeval.InputError, match=r"v: shape \(2,\)"):
        stage.falloff(o, u, [0, 1], (4, 4))


def test_a_stage_without_lights_warns_and_returns_zeros(tmp_path):
    f = tmp_path / "empty.usda"
    f.write_text('#usda 1.0\ndef Xform "world"\n{\n}\n')
    stage = luxeval.Stage(f)
    assert stage.lights == [] and stage.light_paths() == []
    with pytest.warns(UserWarning, match="no light to evaluate"):
        out = stage.emission(sphere_dirs(5), device="cpu")
    np.testing.assert_array_equal(out, np.zeros((5, 3), np.float32))
    assert stage.emission(sphere_dirs(5), per_light=True, device="cpu").shape == (0, 5, 3)


NO_GPU_CHILD = textwrap.dedent(
    """
    import sys, warnings
    import numpy as np
    import luxeval
    stage = luxeval.Stage(sys.argv[1])
    dirs = np.load(sys.argv[2])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        a = stage.emission(dirs)
        b = stage.emission(dirs, per_light=True)
        name = luxeval.device_name()
    assert [w.category for w in caught] == [luxeval.DeviceWarning], caught
    print("warning:", caught[0].message)
    assert name == "cpu (f64 reference)", name
    assert np.array_equal(a, stage.emission(dirs, device="cpu"))
    assert np.array_equal(b, stage.emission(dirs, per_light=True, device="cpu"))
    assert stage.prepared == [(None, "cpu", "spec", "bilinear")], stage.prepared
    try:
        stage.emission(dirs, device="gpu")
    except luxeval.DeviceError as e:
        print("DeviceError:", e)
    else:
        sys.exit("no DeviceError")
    """
)


def test_without_a_gpu_auto_falls_back_and_gpu_raises(tmp_path):
    env = dict(os.environ, VK_DRIVER_FILES=str(tmp_path / "no_such_icd.json"),
               VK_ICD_FILENAMES=str(tmp_path / "no_such_icd.json"))
    dirs = tmp_path / "dirs.npy"
    np.save(dirs, sphere_dirs(64))
    p = subprocess.run([sys.executable, "-c", NO_GPU_CHILD, str(STUDIO), str(dirs)],
                       env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    assert 'warning: device="auto": the CPU reference: no GPU adapter' in p.stdout, p.stdout
    assert 'DeviceError: no GPU adapter found' in p.stdout and 'device="cpu"' in p.stdout


def test_a_headless_machine_hears_only_luxeval():
    """Without XDG_RUNTIME_DIR (render-farm nodes, CI runners, containers) Mesa's device-select
    layer prints "error: XDG_RUNTIME_DIR is invalid or not set" when devices are enumerated;
    importing luxeval and asking for a device prints nothing."""
    env = {k: v for k, v in os.environ.items() if k not in ("XDG_RUNTIME_DIR", "NODEVICE_SELECT")}
    code = "import luxeval; luxeval.device_name('auto')"
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "XDG_RUNTIME_DIR" not in p.stderr, p.stderr
