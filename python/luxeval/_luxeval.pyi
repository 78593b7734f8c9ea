"""Type stubs of the extension module luxeval._luxeval (re-exported by ``luxeval``)."""

from __future__ import annotations

import os
from typing import Any, Callable, Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Device = Literal["auto", "gpu", "cpu"]
TemperatureMode = Literal["spec", "usd", "planckian"]
TextureFilter = Literal["bilinear", "nearest"]
# DESIGN.md §8 P2: hint (portals change no value) or mask (a dome reaches a point only through them).
PortalMode = Literal["hint", "mask"]
Lights = Optional[Union[str, Sequence[str]]]
Vec3 = Union[Sequence[float], npt.ArrayLike]
Selection = Literal["power", "bound", "exact"]

class InputError(ValueError):
    """Bad input: an unreadable or malformed stage, an attribute luxeval cannot evaluate, an
    array of the wrong shape or with non-finite values, a bad argument. The message names the
    file, the prim and the attribute, or the argument."""

class DeviceError(RuntimeError):
    """A run-time failure: no GPU adapter with device="gpu", a device that could not be opened
    or was lost, a failed GPU computation."""

class DeviceWarning(RuntimeWarning):
    """Issued once per process when device="auto" finds no GPU adapter and falls back to the CPU
    reference."""

def device_name(device: Device = "auto") -> str:
    """The device a query with this ``device=`` argument runs on: the GPU adapter's name and
    backend, or ``"cpu (f64 reference)"``. Opens the GPU if it is not open yet."""

class Stage:
    """A USD stage (.usda, .usdc, .usdz) and its lights, read once at one time.

    ``Stage(path, time=None, progress=None)`` reads the lights at ``time`` (a USD time code);
    without one, at the stage's ``startTimeCode`` when authored, else at each attribute's
    earliest time sample. ``progress(step, done, total)``, when given, is called while the stage
    is read (``step``: ``"opening"``, ``"checking"``, ``"composing"``, ``"finding"``,
    ``"reading"``; ``done``/``total`` item counts or ``None``), at each step's ends, every 1,024
    items and every quarter second; an exception it raises stops the reading and propagates.
    Ctrl-C stops a long read with ``KeyboardInterrupt``.
    Raises ``InputError`` when the file is missing, unreadable or malformed (naming the file and
    line or prim). Queries take any real dtype in C or Fortran order (C-contiguous float32 is
    used without a copy) and return ``numpy.float32`` arrays (``sample``: a dict of arrays); the lights are prepared once per
    (lights, device, temperature_mode, texture_filter, portal_mode) and reused. Picklable: unpickling opens the stage again.
    """

    def __init__(
        self,
        path: Union[str, os.PathLike[str]],
        time: Optional[float] = None,
        progress: Optional[
            Callable[[Literal["opening", "checking", "composing", "finding", "reading"], Optional[int], Optional[int]], object]
        ] = None,
    ) -> None: ...
    @property
    def path(self) -> str:
        """The stage's path, as given."""
    @property
    def time(self) -> Optional[float]:
        """The time code the lights were read at; ``None`` for USD's EarliestTime."""
    @property
    def time_rule(self) -> Literal["given", "start_time_code", "earliest"]:
        """Why the lights were read at ``time``."""
    @property
    def up_axis(self) -> str:
        """``"Y"`` or ``"Z"`` (``"Y"`` when not authored)."""
    @property
    def meters_per_unit(self) -> float:
        """The stage's metersPerUnit (0.01 when not authored)."""
    @property
    def lights(self) -> list[dict[str, Any]]:
        """Every light of the stage in traversal order, as the records of
        ``luxeval lights --json`` (with ``light_filters``, ``link_collections`` and
        ``shaping_without_api``: read, not applied; a mesh light's ``mesh`` summary, a portal's
        ``portal`` and a dome's ``portals``, ``portals_evaluated`` and ``masked``). A new list
        on each access."""
    @property
    def light_lists(self) -> list[dict[str, Any]]:
        """The stage's light lists (ListAPI / LightListAPI; not read by luxeval): ``path``,
        ``api``, ``targets``, ``cache_behavior``."""
    @property
    def unapplied(self) -> Optional[str]:
        """One line on the light filters, link collections, shaping inputs without ShapingAPI
        and light lists luxeval does not apply, or ``None``: the query commands' warning."""
    @property
    def warnings(self) -> list[str]:
        """What reading the stage said (layers left out, values read differently; each naming its
        layer), then one message per light the queries skip (unsupported, invisible), naming its
        prim."""
    @property
    def prepared(
        self,
    ) -> list[tuple[Optional[tuple[str, ...]], Literal["gpu", "cpu"], TemperatureMode, TextureFilter]]:
        """The prepared light sets cached on this stage: (selection or None, device, mode,
        texture filter)."""
    def light_paths(self, lights: Lights = None) -> list[str]:
        """The prim paths a query with this ``lights=`` evaluates, in ``per_light`` row order."""
    def emission(
        self,
        dirs: npt.ArrayLike,
        *,
        per_light: bool = False,
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
    ) -> npt.NDArray[np.float32]:
        """Radiance leaving each light along each direction (N, 3) → float32 (N, 3), or
        (L, N, 3) with ``per_light=True``."""
    def intensity(
        self,
        dirs: npt.ArrayLike,
        *,
        per_light: bool = False,
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
    ) -> npt.NDArray[np.float32]:
        """Far-field intensity of each light along each direction (N, 3) → float32 (N, 3), or
        (L, N, 3) with ``per_light=True``: emission × projected area (a mesh light's visible
        emitting area); 0 for distant and dome lights."""
    def radiance(
        self,
        points: npt.ArrayLike,
        dirs: npt.ArrayLike,
        *,
        per_light: bool = False,
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
    ) -> npt.NDArray[np.float32]:
        """Radiance arriving at each point from each direction (pairs of (N, 3)) → float32
        (N, 3), or (L, N, 3) with ``per_light=True``."""
    def irradiance(
        self,
        points: npt.ArrayLike,
        normals: npt.ArrayLike,
        *,
        per_light: bool = False,
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
        tolerance: float = 1e-4,
    ) -> npt.NDArray[np.float32]:
        """Diffuse-weighted irradiance at each point on a receiver with the given normal →
        float32 (N, 3), or (L, N, 3) with ``per_light=True``."""
    def falloff(
        self,
        origin: Vec3,
        u: Vec3,
        v: Vec3,
        res: tuple[int, int],
        *,
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
        tolerance: float = 1e-4,
    ) -> npt.NDArray[np.float32]:
        """The summed irradiance at the pixel centres of ``origin + s·u + t·v``, res = (W, H)
        → float32 (H, W, 3), row 0 at the top (the ``origin + v`` side)."""
    def sample(
        self,
        points: npt.ArrayLike,
        normals: Optional[npt.ArrayLike] = None,
        *,
        count: int = 1,
        seed: int = 0,
        selection: Selection = "bound",
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
        first_point: int = 0,
    ) -> dict[str, npt.NDArray[Any]]:
        """``count`` (K, 1 to 2**20) directions per point (N, 3) toward the lights, as
        ``luxeval sample``: ``{"dirs": float32 (N, K, 3), "pdf": float32 (N, K) (inf for a
        delta light), "radiance": float32 (N, K, 3), "light_pdf": float32 (N, K), "light":
        int32 (N, K) (row of light_paths(lights), -1 where no light reaches the point)}``.
        ``normals`` (N, 3) or None (needed by ``selection="exact"``); ``seed`` 0 to 2**32 - 1;
        ``first_point``: the row of ``points[0]`` in a larger input (a slice draws what the
        whole would). ``device`` as ``emission`` (on a GPU the light is chosen on the host, the
        direction drawn by the WGSL samplers, textured domes' included)."""
    def pdf(
        self,
        points: npt.ArrayLike,
        dirs: npt.ArrayLike,
        normals: Optional[npt.ArrayLike] = None,
        *,
        per_light: bool = False,
        selection: Selection = "bound",
        lights: Lights = None,
        device: Device = "auto",
        temperature_mode: TemperatureMode = "spec",
        texture_filter: TextureFilter = "bilinear",
        portal_mode: PortalMode = "hint",
    ) -> npt.NDArray[np.float32]:
        """The density ``sample`` draws each direction with (pairs of (M, 3); ``normals`` as
        given to ``sample``) → float32 (M,), or (L, M) with ``per_light=True`` (rows sum to the
        total). ``device`` as ``sample``."""
    def __reduce__(self) -> tuple[type[Stage], tuple[str, Optional[float]]]: ...
