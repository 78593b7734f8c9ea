"""luxeval.dask on a dask.distributed LocalCluster with two worker processes gives the
single-process result, bitwise, opening the stage once per worker."""

from __future__ import annotations

import numpy as np
import pytest

da = pytest.importorskip("dask.array")
distributed = pytest.importorskip("distributed")

import luxeval
import luxeval.dask as ldask
from helpers import LUXTEST, STUDIO, floor_points, sphere_dirs


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


def test_two_workers_give_the_single_process_result(client):
    dirs = sphere_dirs(4000, seed=21)
    points = floor_points(4000, seed=22) + np.float32([0, 0.3, 0])
    up = np.abs(sphere_dirs(4000, seed=23))
    lazy = {
        "emission": ldask.emission(STUDIO, da.from_array(dirs, chunks=(500, 3))),
        "intensity": ldask.intensity(STUDIO, da.from_array(dirs, chunks=(1000, 3)), per_light=True),
        "radiance": ldask.radiance(
            str(STUDIO), da.from_array(points, chunks=(500, 3)), da.from_array(up, chunks=(700, 3)),
            per_light=True,
        ),
        "irradiance": ldask.irradiance(
            luxeval.Stage(STUDIO), da.from_array(points[:800], chunks=(200, 3)),
            np.tile([0.0, 1.0, 0.0], (800, 1)), lights=["/lights/key", "/lights/sky"],
        ),
    }
    assert lazy["emission"].shape == (4000, 3) and lazy["emission"].dtype == np.float32
    assert lazy["emission"].chunks == ((500,) * 8, (3,))
    assert lazy["radiance"].shape == (6, 4000, 3)
    got = dict(zip(lazy, client.compute(list(lazy.values()), sync=True)))

    stage = luxeval.Stage(STUDIO)
    np.testing.assert_array_equal(got["emission"], stage.emission(dirs))
    np.testing.assert_array_equal(got["intensity"], stage.intensity(dirs, per_light=True))
    assert got["intensity"].shape == (6, 4000, 3) and np.count_nonzero(got["intensity"]) > 0
    np.testing.assert_array_equal(got["radiance"], stage.radiance(points, up, per_light=True))
    np.testing.assert_array_equal(
        got["irradiance"],
        stage.irradiance(points[:800], np.tile([0.0, 1.0, 0.0], (800, 1)),
                         lights=["/lights/key", "/lights/sky"]),
    )
    assert np.count_nonzero(got["emission"]) > 0 and np.count_nonzero(got["radiance"]) > 0

    # 24 chunks over two workers: each worker opened the stage at most once and prepared each
    # light selection once.
    info = client.run(ldask.cache_info)
    assert len(info) == 2
    assert sum(i["opened"] for i in info.values()) >= 1
    for i in info.values():
        assert i["opened"] <= 1, info
        for s in i["stages"]:
            assert s["path"] == str(STUDIO) and s["time"] is None
            assert len(s["prepared"]) == len(set(s["prepared"])) <= 2


def test_a_stage_at_a_time_on_the_workers(client):
    rect = LUXTEST / "rect.usda"
    dirs = sphere_dirs(600, seed=24)
    got = ldask.emission(luxeval.Stage(rect, time=5), dirs, chunks=200, device="cpu").compute()
    np.testing.assert_array_equal(got, luxeval.Stage(rect, time=5).emission(dirs, device="cpu"))
    assert not np.array_equal(got, luxeval.Stage(rect).emission(dirs, device="cpu"))


def test_bad_input_is_reported(client):
    with pytest.raises(luxeval.InputError, match="dirs: shape"):
        ldask.emission(STUDIO, da.zeros((10, 2), chunks=5))
    with pytest.raises(luxeval.InputError, match="lights: /nope is not a light"):
        ldask.emission(STUDIO, da.ones((10, 3), chunks=5), lights=["/nope"])
    with pytest.raises(luxeval.InputError, match="points/dirs: 10 points but 8 dirs"):
        ldask.radiance(STUDIO, da.zeros((10, 3), chunks=5), da.ones((8, 3), chunks=4))
    with pytest.raises(luxeval.InputError):
        ldask.emission(STUDIO / "missing.usda", da.ones((10, 3), chunks=5))
    # Found only in the data, on a worker: re-raised by compute() with its type and message.
    bad = np.ones((10, 3))
    bad[7, 0] = np.nan
    with pytest.raises(luxeval.InputError, match=r"dirs: row 2 = \[nan, 1.0, 1.0\] is not finite \(rows counted within the chunk of rows 5:10\)"):
        ldask.emission(STUDIO, da.from_array(bad, chunks=5), device="cpu").compute()
