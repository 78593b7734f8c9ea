"""Portals from Python (DESIGN.md §8 P2): ``portal_mode="mask"`` gives bitwise the command line's
``--portal-mode mask`` on the window stage, hint mode (the default) the unmasked dome, and a
bad value is refused naming the argument; the dask wrappers pass the option through."""

from __future__ import annotations

import numpy as np
import pytest

import luxeval
from helpers import REPO, cli_query, floor_points, sphere_dirs

WINDOW = REPO / "tests" / "data" / "usd" / "portal" / "window.usda"


def test_portal_mode_mask_equals_the_cli(cli, tmp_path):
    stage = luxeval.Stage(WINDOW)
    points = floor_points(64, half=1.0)
    normals = sphere_dirs(64, seed=3)
    inputs = {"points": points, "normals": normals}
    for mode in ("hint", "mask"):
        want = cli_query(cli, tmp_path, "irradiance", WINDOW, inputs,
                         "--device", "cpu", "--portal-mode", mode)
        got = stage.irradiance(points, normals, device="cpu", portal_mode=mode)
        assert np.array_equal(got, want), mode
    dirs = sphere_dirs(64, seed=4)
    want = cli_query(cli, tmp_path, "radiance", WINDOW, {"points": points, "dirs": dirs},
                     "--device", "cpu", "--portal-mode", "mask")
    got = stage.radiance(points, dirs, device="cpu", portal_mode="mask")
    assert np.array_equal(got, want)
    # Mask mode changes the values (the window is a small part of the sky).
    hint = stage.irradiance(points, normals, device="cpu")
    mask = stage.irradiance(points, normals, device="cpu", portal_mode="mask")
    assert not np.array_equal(hint, mask)


def test_bad_portal_mode_names_the_argument():
    stage = luxeval.Stage(WINDOW)
    with pytest.raises(luxeval.InputError, match="portal_mode"):
        stage.emission(sphere_dirs(4), device="cpu", portal_mode="bogus")


def test_dask_passes_portal_mode():
    dask = pytest.importorskip("luxeval.dask")
    da = pytest.importorskip("dask.array")
    stage = luxeval.Stage(WINDOW)
    points = floor_points(32, half=1.0)
    normals = sphere_dirs(32, seed=5)
    lazy = dask.irradiance(WINDOW, da.from_array(points, chunks=8), da.from_array(normals, chunks=8),
                           device="cpu", portal_mode="mask")
    want = stage.irradiance(points, normals, device="cpu", portal_mode="mask")
    assert np.array_equal(lazy.compute(), want)
