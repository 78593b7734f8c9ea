"""Light sampling from Python: ``Stage.sample`` and ``Stage.pdf`` (DESIGN.md §9 S4).

The draws are checked against NumPy arithmetic on their own outputs (the Monte Carlo estimate
of the irradiance equals ``Stage.irradiance`` within 5 standard errors), chunking and dask give
the one-call result bit for bit, ``pdf`` is the density the draws claim, ``luxeval sample`` and
``luxeval pdf`` give the same bits, and bad arguments are refused naming the argument."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

import luxeval
from helpers import LUXTEST, STUDIO, floor_points, run_cli

Y = np.array([0.2126, 0.7152, 0.0722])
FIELDS = {
    "dirs": (np.float32, 3),
    "pdf": (np.float32, 2),
    "radiance": (np.float32, 3),
    "light_pdf": (np.float32, 2),
    "light": (np.int32, 2),
}

# A few floor points (y = 0) facing up, inside and outside the spot sphere's cone.
FLOOR = np.array([[0, 0, 0], [0.4, 0, -0.3], [1, 0, 1], [-2, 0, 0.5], [3, 0, -3]], np.float32)
UP = np.tile(np.float32([0, 1, 0]), (len(FLOOR), 1))


def _stage(name: str, time: float) -> luxeval.Stage:
    return luxeval.Stage(LUXTEST / f"{name}.usda", time=time)


def _same(a: dict, b: dict) -> None:
    """Bit for bit (inf and any NaN included)."""
    assert a.keys() == b.keys() == FIELDS.keys()
    for k in FIELDS:
        assert a[k].dtype == b[k].dtype and a[k].shape == b[k].shape, k
        assert np.array_equal(a[k].view(np.uint8), b[k].view(np.uint8)), k


def test_sample_returns_the_arrays_it_says():
    stage = _stage("sphere", 31)
    s = stage.sample(FLOOR, UP, count=7, seed=3)
    n = len(FLOOR)
    for k, (dtype, ndim) in FIELDS.items():
        assert s[k].dtype == dtype, k
        assert s[k].shape == ((n, 7, 3) if ndim == 3 else (n, 7)), k
        assert s[k].flags.c_contiguous, k
    assert set(np.unique(s["light"])) <= {-1, 0}
    ok = s["light"] >= 0
    assert np.allclose(np.linalg.norm(s["dirs"][ok], axis=-1), 1, atol=1e-5)
    # Defaults: one sample, seed 0, the "bound" selection.
    one = stage.sample(FLOOR)
    assert one["dirs"].shape == (n, 1, 3)
    _same(one, stage.sample(FLOOR, None, count=1, seed=0, selection="bound"))
    # Another seed draws other directions.
    assert not np.array_equal(s["dirs"], stage.sample(FLOOR, UP, count=7, seed=4)["dirs"])


@pytest.mark.parametrize(
    "name,time,selection",
    [("sphere", 31, "bound"), ("sphere", 31, "power"), ("sphere", 31, "exact"), ("dome", 1, "bound")],
)
def test_the_estimate_converges_to_the_irradiance(name, time, selection):
    # NumPy, independent of the library's own Monte Carlo test: the mean of
    # Y(radiance) · max(0, n·ω) / pdf (/ light_pdf for a delta light) is Y(irradiance)
    # (each luxtest light's diffuse is 1) within 5 standard errors.
    stage = _stage(name, time)
    assert all(
        i["value"] == 1.0 for l in stage.lights for i in l["inputs"] if i["name"] == "inputs:diffuse"
    )
    k = 20_000
    s = stage.sample(FLOOR, UP, count=k, seed=17, selection=selection)
    f = (s["radiance"].astype(np.float64) @ Y) * np.maximum(s["dirs"][..., 1].astype(np.float64), 0)
    pdf = s["pdf"].astype(np.float64)
    pdf = np.where(np.isinf(pdf), s["light_pdf"], pdf)
    assert np.all(f[pdf == 0] == 0), "light drawn at density 0"
    v = np.where(pdf > 0, f / np.where(pdf > 0, pdf, 1), 0)
    mean = v.mean(axis=1)
    se = v.std(axis=1) / np.sqrt(k)
    exact = stage.irradiance(FLOOR, UP, device="cpu", tolerance=1e-6).astype(np.float64) @ Y
    assert exact.max() > 0
    assert np.all(np.abs(mean - exact) <= 5 * se + 1e-5 * np.abs(exact)), (mean, se, exact)


def test_chunks_and_slices_draw_what_one_call_draws():
    stage = luxeval.Stage(STUDIO)
    n, k = 6000, 3  # several of the extension's chunks (4096 / K points at first)
    points = floor_points(n, seed=5) + np.float32([0, 0.1, 0])
    up = np.tile(np.float32([0, 1, 0]), (n, 1))
    whole = stage.sample(points, up, count=k, seed=9)
    cuts = [0, 1, 999, 2500, 2501, n]
    parts = [
        stage.sample(points[a:b], up[a:b], count=k, seed=9, first_point=a)
        for a, b in zip(cuts, cuts[1:])
    ]
    _same(whole, {key: np.concatenate([p[key] for p in parts]) for key in FIELDS})
    # float64 and Fortran-order inputs give the float32 bits.
    _same(whole, stage.sample(np.asfortranarray(points.astype(np.float64)), up, count=k, seed=9))


def test_dask_sample_and_pdf_are_the_eager_result():
    da = pytest.importorskip("dask.array")
    import dask
    import luxeval.dask as ldask

    stage = luxeval.Stage(STUDIO)
    n, k = 2000, 5
    points = floor_points(n, seed=6) + np.float32([0, 0.2, 0])
    up = np.tile(np.float32([0, 1, 0]), (n, 1))
    eager = stage.sample(points, up, count=k, seed=11)
    lazy = ldask.sample(
        STUDIO, da.from_array(points, chunks=(333, 3)), da.from_array(up, chunks=(500, 3)),
        count=k, seed=11,
    )
    assert lazy["dirs"].shape == (n, k, 3) and lazy["light"].dtype == np.int32
    assert lazy["pdf"].chunks[0] == da.from_array(points, chunks=(333, 3)).chunks[0]
    _same(eager, dask.compute(lazy, scheduler="threads")[0])
    # Without normals, from a NumPy array split by `chunks`, with a Stage object.
    _same(
        stage.sample(points, count=2, seed=1, selection="power"),
        dask.compute(ldask.sample(stage, points, count=2, seed=1, selection="power", chunks=700))[0],
    )
    dirs = eager["dirs"][:, 0]
    for per_light in (False, True):
        want = stage.pdf(points, dirs, up, per_light=per_light)
        got = ldask.pdf(STUDIO, points, dirs, up, per_light=per_light, chunks=300)
        assert got.shape == want.shape
        assert np.array_equal(want, got.compute())


def _rows(points, normals, k):
    rows_p = np.repeat(points, k, axis=0)
    return rows_p, None if normals is None else np.repeat(normals, k, axis=0)


def _mostly_equal(got, want):
    """Equal to 1e-4 relative but for at most 1 % of the rows (the float32 rounding of a
    direction can carry it across a light's silhouette)."""
    rel = np.abs(got.astype(np.float64) - want) / want
    assert (rel > 1e-4).mean() <= 0.01, np.sort(rel)[-20:]


@pytest.mark.parametrize("name,time", [("sphere", 31), ("dome", 1)])
@pytest.mark.parametrize("with_normals", [True, False], ids=["normals", "no-normals"])
def test_pdf_is_the_density_of_the_draws(name, time, with_normals):
    # One light: the density of the direction is the drawn one.
    stage = _stage(name, time)
    n, k = 40, 64
    points = floor_points(n, half=2.0, seed=7)
    normals = np.tile(np.float32([0, 1, 0]), (n, 1)) if with_normals else None
    s = stage.sample(points, normals, count=k, seed=2)
    rows_p, rows_n = _rows(points, normals, k)
    drawn = s["pdf"].reshape(-1)
    dirs = s["dirs"].reshape(-1, 3)
    mask = drawn > 0
    assert np.isfinite(drawn).all() and mask.mean() > 0.3
    got = stage.pdf(rows_p[mask], dirs[mask], None if rows_n is None else rows_n[mask])
    assert got.shape == (mask.sum(),) and got.dtype == np.float32
    _mostly_equal(got, drawn[mask])


def test_per_light_pdf_is_the_chosen_lights_share():
    # Several lights whose directions overlap (the sky dome covers every direction): the drawn
    # pdf is P(l | x) · pdf_l(ω) of the chosen light l, the row l of pdf(per_light=True); the
    # summed pdf (the density of ω whichever light drew it) is the sum of the rows.
    stage = luxeval.Stage(STUDIO)
    n, k = 300, 16
    points = floor_points(n, seed=7) + np.float32([0, 0.05, 0])
    up = np.tile(np.float32([0, 1, 0]), (n, 1))
    for normals in (up, None):
        s = stage.sample(points, normals, count=k, seed=2)
        rows_p, rows_n = _rows(points, normals, k)
        drawn = s["pdf"].reshape(-1)
        dirs = s["dirs"].reshape(-1, 3)
        chosen = s["light"].reshape(-1)
        finite = np.isfinite(drawn) & (drawn > 0)  # not the sun: a delta light has no density
        assert finite.mean() > 0.5
        assert np.all(chosen[~np.isfinite(drawn)] == stage.light_paths().index("/lights/sun"))
        per = stage.pdf(rows_p, dirs, rows_n, per_light=True)
        total = stage.pdf(rows_p, dirs, rows_n)
        assert per.shape == (len(stage.light_paths()), n * k) and per.dtype == np.float32
        assert total.shape == (n * k,) and total.dtype == np.float32
        rows = np.flatnonzero(finite)
        _mostly_equal(per[chosen[rows], rows], drawn[rows])
        assert np.allclose(per.astype(np.float64).sum(axis=0), total, rtol=1e-5, atol=0)
        assert np.all(total[rows] >= per[chosen[rows], rows])


@pytest.mark.parametrize(
    "scene,time,flags",
    [
        (LUXTEST / "sphere.usda", 31, ["--count", 64, "--seed", 5]),
        (LUXTEST / "dome.usda", 1, ["--count", 16, "--seed", 1, "--selection", "exact"]),
        (STUDIO, None, ["--count", 8, "--selection", "power"]),
    ],
    ids=["sphere", "dome-exact", "studio-power-no-normals"],
)
def test_the_command_line_gives_the_same_bits(cli, tmp_path, scene, time, flags):
    n = 257
    points = floor_points(n, seed=8) + np.float32([0, 0.01, 0])
    normals = None if "power" in flags else np.tile(np.float32([0, 1, 0]), (n, 1))
    np.save(tmp_path / "P.npy", points)
    args = ["sample", scene, "--points", tmp_path / "P.npy", "-o", tmp_path / "S.npz", *flags]
    if normals is not None:
        np.save(tmp_path / "N.npy", normals)
        args += ["--normals", tmp_path / "N.npy"]
    if time is not None:
        args += ["--time", time]
    run_cli(cli, *args)
    opts = dict(zip([f.lstrip("-") for f in flags[::2]], flags[1::2]))
    stage = luxeval.Stage(scene, time=time)
    py = stage.sample(
        points, normals, count=int(opts["count"]), seed=int(opts.get("seed", 0)),
        selection=opts.get("selection", "bound"),
    )
    with np.load(tmp_path / "S.npz") as z:
        _same({k: z[k] for k in FIELDS}, py)
    # luxeval pdf of the first draws, summed and per light.
    dirs = py["dirs"][:, 0]
    np.save(tmp_path / "D.npy", dirs)
    for per_light in (False, True):
        pargs = ["pdf", scene, "--points", tmp_path / "P.npy", "--dirs", tmp_path / "D.npy",
                 "-o", tmp_path / "pdf.npy"]
        pargs += ["--normals", tmp_path / "N.npy"] if normals is not None else []
        pargs += ["--time", time] if time is not None else []
        pargs += ["--selection", opts["selection"]] if "selection" in opts else []
        pargs += ["--per-light"] if per_light else []
        run_cli(cli, *pargs)
        want = np.load(tmp_path / "pdf.npy")
        got = stage.pdf(points, dirs, normals, per_light=per_light,
                        selection=opts.get("selection", "bound"))
        assert want.dtype == got.dtype and want.shape == got.shape
        assert np.array_equal(want, got)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"count": 0}, r"count: 0 is not from 1 to 1048576"),
        ({"count": 2**20 + 1}, r"count: 1048577 is not from 1 to 1048576"),
        ({"count": -1}, r"count: -1"),
        ({"count": 2.0}, r"count: 2.0"),
        ({"seed": -1}, r"seed: -1 is not an integer from 0 to 4294967295"),
        ({"seed": 2**32}, r"seed: 4294967296"),
        ({"selection": "bogus"}, r"selection: \"bogus\" is not one of \"power\", \"bound\", \"exact\""),
        ({"normals": None, "selection": "exact"}, r"normals: selection=\"exact\" needs a receiver normal"),
        ({"device": "tpu"}, r"device: "),
    ],
)
def test_bad_sample_arguments_are_refused_naming_them(kwargs, match):
    stage = _stage("sphere", 31)
    kw = {"normals": UP, **kwargs}
    with pytest.raises(luxeval.InputError, match=match):
        stage.sample(FLOOR, **kw)
    assert issubclass(luxeval.InputError, ValueError)


def test_bad_rows_are_named_by_row():
    stage = _stage("sphere", 31)
    bad = FLOOR.astype(np.float64)
    bad[3, 1] = np.nan
    with pytest.raises(luxeval.InputError, match=r"points: row 3 = \[-2.0, nan, 0.5\] is not finite"):
        stage.sample(bad, UP, count=4)
    with pytest.raises(luxeval.InputError, match=r"points: row 3 .* is not finite"):
        stage.pdf(bad, UP, UP)
    zero = UP.copy()
    zero[2] = 0
    with pytest.raises(luxeval.InputError, match=r"normals: row 2 .* zero vector"):
        stage.sample(FLOOR, zero)
    with pytest.raises(luxeval.InputError, match=r"dirs: row 2 .* zero vector"):
        stage.pdf(FLOOR, zero)
    with pytest.raises(luxeval.InputError, match=r"points/normals: 5 points but 4 normals"):
        stage.sample(FLOOR, UP[:4])
    with pytest.raises(luxeval.InputError, match=r"points/dirs: 5 points but 4 dirs"):
        stage.pdf(FLOOR, UP[:4])
    with pytest.raises(luxeval.InputError, match=r"selection: \"bogus\" is not one of"):
        stage.pdf(FLOOR, UP, selection="bogus")
    with pytest.raises(luxeval.InputError, match=r"normals: selection=\"exact\""):
        stage.pdf(FLOOR, UP, selection="exact")


def test_device_gpu_draws_what_the_cpu_draws():
    """device="gpu" samples with the WGSL twins: the same lights chosen, directions within 1e-3
    rad and densities within 1e-4 of the CPU reference for all but a few rows on the samplers'
    seams (tests/sample_conformance.rs bounds them); without a GPU adapter, DeviceError (a skip
    outside CI)."""
    stage = _stage("sphere", 31)
    try:
        g = stage.sample(FLOOR, UP, count=64, device="gpu")
    except luxeval.DeviceError:
        if os.environ.get("CI") in ("true", "1"):
            raise
        pytest.skip("no GPU adapter")
    c = stage.sample(FLOOR, UP, count=64, device="cpu")
    assert np.array_equal(g["light"], c["light"])
    assert np.array_equal(g["light_pdf"], c["light_pdf"])
    lit = c["pdf"] > 0
    cos = np.clip(np.sum(g["dirs"].astype(np.float64) * c["dirs"], axis=-1), -1.0, 1.0)
    assert np.mean(np.arccos(cos[lit]) < 1e-3) > 0.98
    rel = np.abs(g["pdf"][lit] - c["pdf"][lit]) / c["pdf"][lit]
    assert np.mean(rel < 1e-4) > 0.98
    p = stage.pdf(FLOOR, c["dirs"][:, 0], UP, device="gpu")
    q = stage.pdf(FLOOR, c["dirs"][:, 0], UP, device="cpu")
    ok = (q == 0) | (np.abs(p - q) <= 1e-4 * np.abs(q))
    assert np.mean(ok) > 0.9


def test_dask_refuses_bad_arguments_when_the_graph_is_built():
    pytest.importorskip("dask.array")
    import luxeval.dask as ldask

    scene = LUXTEST / "sphere.usda"
    with pytest.raises(luxeval.InputError, match="count: 0"):
        ldask.sample(scene, FLOOR, UP, count=0)
    with pytest.raises(luxeval.InputError, match="seed: -1"):
        ldask.sample(scene, FLOOR, UP, seed=-1)
    with pytest.raises(luxeval.InputError, match='selection: "bogus" is not one of'):
        ldask.sample(scene, FLOOR, UP, selection="bogus")
    with pytest.raises(luxeval.InputError, match="normals: selection=\"exact\""):
        ldask.pdf(scene, FLOOR, UP, selection="exact")
    bad = FLOOR.copy()
    bad[3, 0] = np.nan
    with pytest.raises(luxeval.InputError, match=r"points: row 1 .* \(rows counted within the chunk of rows 2:4\)"):
        ldask.sample(scene, bad, UP, time=31, chunks=2)["pdf"].compute()
