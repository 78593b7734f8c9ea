"""maturin's PEP 517 backend, with ``--ignore-rust-version`` added to every build.

The USD reader luxeval uses (openusd 0.8) declares Rust 1.96 while luxeval builds on 1.95, so
cargo must be told to ignore declared rust-versions (it compiles and passes its tests on 1.95;
see the README). maturin has a command-line flag for that but no pyproject setting, and pip
passes no flags to a backend unless asked with ``--config-settings``; this wrapper adds the flag
so that ``pip install ./python`` works as it is. Other arguments given with
``--config-settings build-args=...`` or ``MATURIN_PEP517_ARGS`` are kept.
"""

from __future__ import annotations

import os
import shlex
from typing import Any, Mapping

import maturin as _maturin
from maturin import (  # noqa: F401  (the rest of the PEP 517 interface, as maturin has it)
    get_requires_for_build_editable,
    get_requires_for_build_sdist,
    get_requires_for_build_wheel,
)

_FLAG = "--ignore-rust-version"


def _settings(config_settings: Mapping[str, Any] | None) -> dict[str, Any]:
    settings = dict(config_settings or {})
    key = "maturin.build-args" if "maturin.build-args" in settings else "build-args"
    args = settings.get(key)
    if args is None:
        args = shlex.split(os.getenv("MATURIN_PEP517_ARGS", ""))
    elif isinstance(args, str):
        args = shlex.split(args)
    else:
        args = list(args)
    if _FLAG not in args:
        args.append(_FLAG)
    settings[key] = args
    return settings


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    return _maturin.build_wheel(wheel_directory, _settings(config_settings), metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    return _maturin.build_editable(wheel_directory, _settings(config_settings), metadata_directory)


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return _maturin.prepare_metadata_for_build_wheel(metadata_directory, _settings(config_settings))


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return _maturin.prepare_metadata_for_build_editable(
        metadata_directory, _settings(config_settings)
    )


def build_sdist(sdist_directory, config_settings=None):
    return _maturin.build_sdist(sdist_directory, config_settings)
