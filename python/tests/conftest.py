"""Shared fixtures: the repository's files, the luxeval command line to compare with, and
which devices exist.

The comparisons with the command line need the ``luxeval`` binary built from the same
checkout: ``LUXEVAL_CLI`` when set, else ``target/debug/luxeval`` (built by
``cargo test --ignore-rust-version`` or ``cargo build --ignore-rust-version``), else
``target/release/luxeval``. GPU tests run on any Vulkan adapter (lavapipe on CI); without one
they skip, except under ``CI=true``, where they fail, as the Rust tests do.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import luxeval
from helpers import REPO, on_ci


@pytest.fixture(scope="session")
def cli() -> Path:
    env = os.environ.get("LUXEVAL_CLI")
    candidates = [Path(env)] if env else [REPO / "target" / p / "luxeval" for p in ("debug", "release")]
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    pytest.fail(
        "the luxeval command line is needed to compare with: build it with "
        "`cargo build --ignore-rust-version` or set LUXEVAL_CLI (looked at "
        + ", ".join(str(c) for c in candidates)
        + ")"
    )


@pytest.fixture(scope="session")
def has_gpu() -> bool:
    try:
        luxeval.device_name("gpu")
        return True
    except luxeval.DeviceError as e:
        if on_ci():
            pytest.fail(f"no GPU adapter under CI=true: {e}")
        return False


@pytest.fixture(params=["cpu", "gpu"])
def device(request, has_gpu) -> str:
    """Each test that takes it runs on the CPU reference and on the GPU."""
    if request.param == "gpu" and not has_gpu:
        pytest.skip("no GPU adapter (install Mesa's lavapipe: mesa-vulkan-drivers)")
    return request.param
