"""Helpers of the tests: the repository's files, running the command line, sample arrays."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
ASSETS = REPO / "assets"
STUDIO = ASSETS / "studio.usda"
LUXTEST = REPO / "tests" / "data" / "luxtest" / "usd"


def on_ci() -> bool:
    return os.environ.get("CI") == "true"


def run_cli(cli: Path, *args: object) -> subprocess.CompletedProcess:
    """Runs the command line; fails the test with its stderr when it fails."""
    p = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
    if p.returncode != 0:
        pytest.fail(f"luxeval {' '.join(map(str, args))} exited {p.returncode}:\n{p.stderr}")
    return p


def cli_query(cli: Path, tmp_path: Path, query: str, scene: Path, inputs: dict, *flags) -> np.ndarray:
    """`luxeval QUERY SCENE --NAME FILE.npy ... -o OUT.npy FLAGS...`, the output read back."""
    args: list[object] = [query, scene]
    for name, array in inputs.items():
        f = tmp_path / f"{query}_{name}.npy"
        np.save(f, array)
        args += [f"--{name}", f]
    out = tmp_path / f"{query}_out.npy"
    args += ["-o", out, *flags]
    run_cli(cli, *args)
    return np.load(out)


def sphere_dirs(n: int, seed: int = 1) -> np.ndarray:
    """Unit directions, float32 (n, 3)."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    return (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)


def floor_points(n: int, half: float = 4.0, y: float = 0.0, seed: int = 2) -> np.ndarray:
    """Points on the floor y = `y`, float32 (n, 3)."""
    rng = np.random.default_rng(seed)
    p = np.zeros((n, 3))
    p[:, 0] = rng.uniform(-half, half, n)
    p[:, 1] = y
    p[:, 2] = rng.uniform(-half, half, n)
    return p.astype(np.float32)
