"""luxeval: evaluate USD lights (UsdLux) on the GPU or on an f64 CPU reference.

Open a stage, then ask for emission, radiance, irradiance or a falloff map with NumPy arrays::

    import numpy as np
    import luxeval

    stage = luxeval.Stage("assets/studio.usda")
    dirs = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
    rgb = stage.emission(dirs)               # float32 (2, 3): the sum over lights
    per = stage.emission(dirs, per_light=True)  # float32 (L, 2, 3), rows as stage.light_paths()

This package mirrors the Rust library (``luxeval::Stage``, ``Evaluator``, ``PreparedScene``):

- :class:`Stage` reads a stage's lights once; its queries prepare the selected lights once per
  (``lights``, device, ``temperature_mode``, ``texture_filter``, ``portal_mode``) and reuse them, with the GPU pipelines and buffers.
- :class:`InputError` (a ``ValueError``): bad input, naming the file, prim and attribute or the
  argument. :class:`DeviceError` (a ``RuntimeError``): no GPU with ``device="gpu"``, a device
  failure. :class:`DeviceWarning`: ``device="auto"`` found no hardware GPU and uses the CPU reference.
- :func:`device_name`: which device a ``device=`` argument selects.
- :mod:`luxeval.dask` (needs ``dask`` and ``distributed``): the same queries over chunked dask
  arrays, one opened stage per worker process.
"""

import os as _os

# Mesa's Vulkan device-select layer prints "error: XDG_RUNTIME_DIR is invalid or not set" on
# headless machines (render-farm nodes, CI runners, containers) when it probes for a display;
# luxeval never presents to one, so the layer is switched off there before the first device is
# enumerated, unless the user chose otherwise (the command line does the same).
if "NODEVICE_SELECT" not in _os.environ and not _os.path.isdir(_os.environ.get("XDG_RUNTIME_DIR") or "/nonexistent"):
    _os.environ["NODEVICE_SELECT"] = "1"

from ._luxeval import (  # noqa: E402
    DeviceError,
    DeviceWarning,
    InputError,
    Stage,
    __version__,
    device_name,
)

__all__ = [
    "DeviceError",
    "DeviceWarning",
    "InputError",
    "Stage",
    "__version__",
    "device_name",
]
