"""luxeval queries over chunked dask arrays, one opened stage per worker process.

Each function takes a stage (a path, or a :class:`luxeval.Stage`) and dask arrays of shape
(N, 3), and returns a lazy ``dask.array.Array`` of float32, (N, 3) or (L, N, 3) with
``per_light=True``, chunked along N like the input (:func:`sample` returns a dict of (N, K, ...) arrays,
:func:`pdf` float32 (N,) or (L, N)). Nothing runs until ``.compute()``; then every
chunk is evaluated by whichever scheduler computes it: the local threaded scheduler, a
``dask.distributed`` ``LocalCluster``, or any real cluster, the same way::

    from dask.distributed import Client, LocalCluster
    import dask.array as da
    import luxeval.dask

    client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
    dirs = da.random.normal(size=(10_000_000, 3), chunks=(1_000_000, 3))
    rgb = luxeval.dask.emission("assets/studio.usda", dirs).compute()

A worker process opens the stage once, on its first chunk, and keeps it (a per-process cache
keyed by the stage's absolute path and requested time); the stage keeps its prepared lights per
(``lights``, device, ``temperature_mode``, ``texture_filter``, ``portal_mode``), so the GPU pipelines and buffers are built once per
worker, not per chunk. The path must name the same file on every worker (a shared file system).

Devices: each worker picks its own. With ``device="auto"`` (the default) a worker without a hardware GPU
adapter evaluates on the f64 CPU reference and issues one ``luxeval.DeviceWarning`` (in that
worker's log); its chunks then agree with GPU chunks to the usual 1e-4 relative tolerance, not
bitwise. With ``device="gpu"`` such a worker raises ``luxeval.DeviceError``, which
``compute()`` re-raises. Bad input (a NaN row, an unknown light) raises ``luxeval.InputError``
at ``compute()``; what can be checked without the data (the stage, the shapes, the options) is
checked when the graph is built.
"""

from __future__ import annotations

import functools
import os
import threading
from typing import Any, Optional, Sequence, Union

import dask.array as da
import numpy as np

from ._luxeval import InputError, Stage

__all__ = [
    "emission",
    "intensity",
    "radiance",
    "irradiance",
    "sample",
    "pdf",
    "cache_info",
    "clear_cache",
]

StageLike = Union[str, "os.PathLike[str]", Stage]

_LOCK = threading.Lock()
_STAGES: dict[tuple[str, Optional[float]], Stage] = {}
_OPENED = 0


def _stage(path: str, time: Optional[float]) -> Stage:
    """This process's stage for (absolute path, time), opened on first use."""
    global _OPENED
    key = (path, time)
    with _LOCK:
        stage = _STAGES.get(key)
        if stage is None:
            stage = Stage(path, time)
            _STAGES[key] = stage
            _OPENED += 1
        return stage


def cache_info() -> dict[str, Any]:
    """What this process has opened: ``{"pid", "opened", "stages"}``, where ``opened`` counts
    the stages opened since the process started (or since :func:`clear_cache`) and ``stages``
    lists each cached stage's ``path``, ``time`` and ``prepared`` light sets. Run it on the
    workers with ``client.run(luxeval.dask.cache_info)``."""
    with _LOCK:
        return {
            "pid": os.getpid(),
            "opened": _OPENED,
            "stages": [
                {"path": path, "time": time, "prepared": stage.prepared}
                for (path, time), stage in _STAGES.items()
            ],
        }


def clear_cache() -> None:
    """Forgets this process's stages (and their prepared lights); the next chunk opens the stage
    again. Use ``client.run(luxeval.dask.clear_cache)`` after the file changed."""
    global _OPENED
    with _LOCK:
        _STAGES.clear()
        _OPENED = 0


def _block(
    query: str,
    path: str,
    time: Optional[float],
    options: dict[str, Any],
    *blocks: np.ndarray,
    block_info: Optional[dict] = None,
) -> np.ndarray:
    try:
        return getattr(_stage(path, time), query)(*blocks, **options)
    except InputError as e:
        # Row numbers in the message count from the chunk's first row: say which chunk.
        if block_info and 0 in block_info:
            start, stop = block_info[0]["array-location"][0]
            raise InputError(f"{e} (rows counted within the chunk of rows {start}:{stop})") from None
        raise


def _locate(stage: StageLike, time: Optional[float]) -> tuple[str, Optional[float]]:
    """(absolute path, requested time) of a stage argument."""
    if isinstance(stage, Stage):
        if time is not None:
            raise InputError("time: give it to luxeval.Stage, not with a Stage object")
        path, requested = stage.__reduce__()[1]
        return path, requested
    if not isinstance(stage, (str, os.PathLike)):
        raise TypeError(f"stage: expected a path or a luxeval.Stage, got {type(stage).__name__}")
    return os.path.abspath(os.fspath(stage)), time


def _rows(x: Any, name: str, chunks: int) -> da.Array:
    """`x` as a dask array of shape (N, 3), one chunk along the columns."""
    if not isinstance(x, da.Array):
        x = np.asarray(x)
        if x.ndim == 2:
            x = da.from_array(x, chunks=(chunks, 3))
        else:
            x = da.from_array(x)
    if x.dtype.kind not in "fiu":
        raise InputError(
            f"{name}: dtype {x.dtype} is not a real number type; expected an (N, 3) array of floats"
        )
    if x.ndim != 2 or x.shape[1] != 3:
        raise InputError(f"{name}: shape {x.shape}; expected (N, 3)")
    if any(np.isnan(c) for c in x.chunks[0]):
        raise InputError(f"{name}: unknown chunk sizes; call compute_chunk_sizes() first")
    return x.rechunk({1: 3})


def _check_options(
    device: str, temperature_mode: str, texture_filter: str, portal_mode: str = "hint"
) -> None:
    if device not in ("auto", "gpu", "cpu"):
        raise InputError(f'device: {device!r} is not one of "auto", "gpu", "cpu"')
    if temperature_mode not in ("spec", "usd", "planckian"):
        raise InputError(
            f'temperature_mode: {temperature_mode!r} is not one of "spec", "usd", "planckian"'
        )
    if texture_filter not in ("bilinear", "nearest"):
        raise InputError(
            f'texture_filter: {texture_filter!r} is not one of "bilinear", "nearest"'
        )
    if portal_mode not in ("hint", "mask"):
        raise InputError(f'portal_mode: {portal_mode!r} is not one of "hint", "mask"')


def _paired(arrays: Sequence[tuple[Any, str]], chunks: int) -> list[da.Array]:
    """The (N, 3) inputs as dask arrays, every one chunked like the first so that blocks pair
    up row by row."""
    xs = [_rows(x, name, chunks) for x, name in arrays]
    first, first_name = xs[0], arrays[0][1]
    for x, (_, name) in zip(xs[1:], arrays[1:]):
        if x.shape[0] != first.shape[0]:
            raise InputError(
                f"{first_name}/{name}: {first.shape[0]} {first_name} but {x.shape[0]} {name}; "
                "they pair up row by row"
            )
    return [first] + [x.rechunk((first.chunks[0], (3,))) for x in xs[1:]]


def _map(
    query: str,
    stage: StageLike,
    arrays: Sequence[tuple[Any, str]],
    *,
    time: Optional[float],
    per_light: bool,
    lights: Union[None, str, Sequence[str]],
    device: str,
    temperature_mode: str,
    texture_filter: str,
    chunks: int,
    portal_mode: str = "hint",
    extra: Optional[dict[str, Any]] = None,
) -> da.Array:
    path, requested = _locate(stage, time)
    # Opened here too (no device: reading the lights only): a bad stage, selection or option is
    # reported now, and the number of lights gives the shape of per-light results.
    local = _stage(path, requested)
    n_lights = len(local.light_paths(lights))
    _check_options(device, temperature_mode, texture_filter, portal_mode)
    if isinstance(lights, str):
        lights = [lights]
    options = {
        "per_light": per_light,
        "lights": None if lights is None else list(lights),
        "device": device,
        "temperature_mode": temperature_mode,
        "texture_filter": texture_filter,
        "portal_mode": portal_mode,
        **(extra or {}),
    }
    xs = _paired(arrays, chunks)
    first = xs[0]
    func = functools.partial(_block, query, path, requested, options)
    if per_light:
        return da.map_blocks(
            func,
            *xs,
            new_axis=0,
            chunks=((n_lights,), first.chunks[0], (3,)),
            dtype=np.float32,
            meta=np.empty((0, 0, 0), dtype=np.float32),
        )
    return da.map_blocks(
        func,
        *xs,
        chunks=(first.chunks[0], (3,)),
        dtype=np.float32,
        meta=np.empty((0, 0), dtype=np.float32),
    )


def emission(
    stage: StageLike,
    dirs: Any,
    *,
    time: Optional[float] = None,
    per_light: bool = False,
    lights: Union[None, str, Sequence[str]] = None,
    device: str = "auto",
    temperature_mode: str = "spec",
    texture_filter: str = "bilinear",
    portal_mode: str = "hint",
    chunks: int = 1_000_000,
) -> da.Array:
    """:meth:`luxeval.Stage.emission` over a dask array of directions (N, 3), lazily.

    ``stage``: a path (read at ``time``) or a :class:`luxeval.Stage` (its path and time).
    ``dirs``: a dask array, or anything NumPy reads, split into ``chunks`` rows per chunk.
    Returns float32 (N, 3), or (L, N, 3) with ``per_light=True``, chunked like ``dirs``.
    """
    return _map(
        "emission",
        stage,
        [(dirs, "dirs")],
        time=time,
        per_light=per_light,
        lights=lights,
        device=device,
        temperature_mode=temperature_mode,
        texture_filter=texture_filter,
        portal_mode=portal_mode,
        chunks=chunks,
    )


def intensity(
    stage: StageLike,
    dirs: Any,
    *,
    time: Optional[float] = None,
    per_light: bool = False,
    lights: Union[None, str, Sequence[str]] = None,
    device: str = "auto",
    temperature_mode: str = "spec",
    texture_filter: str = "bilinear",
    portal_mode: str = "hint",
    chunks: int = 1_000_000,
) -> da.Array:
    """:meth:`luxeval.Stage.intensity` over a dask array of directions (N, 3), lazily.
    Arguments as :func:`emission`."""
    return _map(
        "intensity",
        stage,
        [(dirs, "dirs")],
        time=time,
        per_light=per_light,
        lights=lights,
        device=device,
        temperature_mode=temperature_mode,
        texture_filter=texture_filter,
        portal_mode=portal_mode,
        chunks=chunks,
    )


def radiance(
    stage: StageLike,
    points: Any,
    dirs: Any,
    *,
    time: Optional[float] = None,
    per_light: bool = False,
    lights: Union[None, str, Sequence[str]] = None,
    device: str = "auto",
    temperature_mode: str = "spec",
    texture_filter: str = "bilinear",
    portal_mode: str = "hint",
    chunks: int = 1_000_000,
) -> da.Array:
    """:meth:`luxeval.Stage.radiance` over dask arrays of points and directions (N, 3) each,
    lazily; ``dirs`` is rechunked like ``points``. Arguments as :func:`emission`."""
    return _map(
        "radiance",
        stage,
        [(points, "points"), (dirs, "dirs")],
        time=time,
        per_light=per_light,
        lights=lights,
        device=device,
        temperature_mode=temperature_mode,
        texture_filter=texture_filter,
        portal_mode=portal_mode,
        chunks=chunks,
    )


def irradiance(
    stage: StageLike,
    points: Any,
    normals: Any,
    *,
    time: Optional[float] = None,
    per_light: bool = False,
    lights: Union[None, str, Sequence[str]] = None,
    device: str = "auto",
    temperature_mode: str = "spec",
    texture_filter: str = "bilinear",
    portal_mode: str = "hint",
    tolerance: float = 1e-4,
    chunks: int = 1_000_000,
) -> da.Array:
    """:meth:`luxeval.Stage.irradiance` over dask arrays of points and receiver normals (N, 3)
    each, lazily; ``normals`` is rechunked like ``points``. Arguments as :func:`emission`;
    ``tolerance`` as :meth:`luxeval.Stage.irradiance`."""
    return _map(
        "irradiance",
        stage,
        [(points, "points"), (normals, "normals")],
        time=time,
        per_light=per_light,
        lights=lights,
        device=device,
        temperature_mode=temperature_mode,
        texture_filter=texture_filter,
        portal_mode=portal_mode,
        chunks=chunks,
        extra={"tolerance": float(tolerance)},
    )


# One record per (point, sample): what Stage.sample returns, in one array per chunk, so that a
# chunk is sampled once however many of the five results are computed.
_SAMPLE_DTYPE = np.dtype(
    [
        ("dirs", np.float32, (3,)),
        ("pdf", np.float32),
        ("radiance", np.float32, (3,)),
        ("light_pdf", np.float32),
        ("light", np.int32),
    ]
)

MAX_COUNT = 1 << 20


def _sample_block(
    path: str,
    time: Optional[float],
    options: dict[str, Any],
    *blocks: np.ndarray,
    block_info: Optional[dict] = None,
) -> np.ndarray:
    # The chunk's first row in the whole input: the generator is keyed by the row, so every
    # chunk draws what one call on the whole input draws for its rows.
    start, stop = block_info[0]["array-location"][0]
    try:
        s = _stage(path, time).sample(*blocks, first_point=start, **options)
    except InputError as e:
        raise InputError(f"{e} (rows counted within the chunk of rows {start}:{stop})") from None
    out = np.empty(s["pdf"].shape, dtype=_SAMPLE_DTYPE)
    for name in _SAMPLE_DTYPE.names:
        out[name] = s[name]
    return out


def _integer(value: Any, name: str, low: int, high: int, what: str) -> int:
    if isinstance(value, (bool, np.bool_, float, np.floating)) or not hasattr(value, "__index__"):
        ok = False
    else:
        value = value.__index__()
        ok = low <= value <= high
    if not ok:
        raise InputError(f"{name}: {value!r} is not {what}")
    return value


def _check_selection(selection: str, normals: Any) -> None:
    if selection not in ("power", "bound", "exact"):
        raise InputError(f'selection: "{selection}" is not one of "power", "bound", "exact"')
    if selection == "exact" and normals is None:
        raise InputError(
            'normals: selection="exact" needs a receiver normal per point (it weighs each '
            "light by its irradiance on the receiver)"
        )


def sample(
    stage: StageLike,
    points: Any,
    normals: Any = None,
    *,
    count: int = 1,
    seed: int = 0,
    selection: str = "bound",
    time: Optional[float] = None,
    lights: Union[None, str, Sequence[str]] = None,
    device: str = "auto",
    temperature_mode: str = "spec",
    texture_filter: str = "bilinear",
    portal_mode: str = "hint",
    chunks: int = 1_000_000,
) -> dict[str, da.Array]:
    """:meth:`luxeval.Stage.sample` over dask arrays of points (and receiver normals) (N, 3),
    lazily; ``normals`` is rechunked like ``points``.

    Returns a dict of lazy dask arrays chunked along N like ``points``: ``"dirs"`` float32
    (N, K, 3), ``"pdf"`` (N, K), ``"radiance"`` (N, K, 3), ``"light_pdf"`` (N, K) and int32
    ``"light"`` (N, K), K = ``count``. Each chunk is sampled with its first row's offset as
    ``first_point``, so the result is bitwise :meth:`luxeval.Stage.sample` on the whole input,
    however it is chunked. The five arrays share one sampling task per chunk: compute them
    together (``dask.compute(result)[0]``) to sample each chunk once. Each worker samples where
    ``device`` says, as the eager call does. ``count``,
    ``seed``, ``selection`` as :meth:`luxeval.Stage.sample`; other arguments as
    :func:`emission` (``chunks`` counts points).
    """
    path, requested = _locate(stage, time)
    local = _stage(path, requested)
    local.light_paths(lights)  # a bad selection is reported now
    _check_options(device, temperature_mode, texture_filter, portal_mode)
    count = _integer(
        count, "count", 1, MAX_COUNT,
        f"from 1 to {MAX_COUNT} samples per point (use more seeds for more)",
    )
    seed = _integer(seed, "seed", 0, 2**32 - 1, f"an integer from 0 to {2**32 - 1}")
    _check_selection(selection, normals)
    if isinstance(lights, str):
        lights = [lights]
    options = {
        "count": count,
        "seed": seed,
        "selection": selection,
        "lights": None if lights is None else list(lights),
        "device": device,
        "temperature_mode": temperature_mode,
        "texture_filter": texture_filter,
        "portal_mode": portal_mode,
    }
    arrays = [(points, "points")] + ([] if normals is None else [(normals, "normals")])
    xs = _paired(arrays, chunks)
    func = functools.partial(_sample_block, path, requested, options)
    records = da.map_blocks(
        func,
        *xs,
        chunks=(xs[0].chunks[0], (count,)),
        dtype=_SAMPLE_DTYPE,
        meta=np.empty((0, 0), dtype=_SAMPLE_DTYPE),
    )
    return {
        name: records[name].map_blocks(np.ascontiguousarray, dtype=_SAMPLE_DTYPE[name].base)
        for name in _SAMPLE_DTYPE.names
    }


def pdf(
    stage: StageLike,
    points: Any,
    dirs: Any,
    normals: Any = None,
    *,
    per_light: bool = False,
    selection: str = "bound",
    time: Optional[float] = None,
    lights: Union[None, str, Sequence[str]] = None,
    device: str = "auto",
    temperature_mode: str = "spec",
    texture_filter: str = "bilinear",
    portal_mode: str = "hint",
    chunks: int = 1_000_000,
) -> da.Array:
    """:meth:`luxeval.Stage.pdf` over dask arrays of points, directions (and receiver normals)
    (M, 3) each, lazily; ``dirs`` and ``normals`` are rechunked like ``points``. Returns float32
    (M,), or (L, M) with ``per_light=True``, chunked along M like ``points``. ``selection`` as
    :meth:`luxeval.Stage.pdf`; other arguments as :func:`emission`."""
    path, requested = _locate(stage, time)
    local = _stage(path, requested)
    n_lights = len(local.light_paths(lights))
    _check_options(device, temperature_mode, texture_filter, portal_mode)
    _check_selection(selection, normals)
    if isinstance(lights, str):
        lights = [lights]
    options = {
        "per_light": per_light,
        "selection": selection,
        "lights": None if lights is None else list(lights),
        "device": device,
        "temperature_mode": temperature_mode,
        "texture_filter": texture_filter,
        "portal_mode": portal_mode,
    }
    arrays = [(points, "points"), (dirs, "dirs")]
    arrays += [] if normals is None else [(normals, "normals")]
    xs = _paired(arrays, chunks)
    func = functools.partial(_block, "pdf", path, requested, options)
    if per_light:
        return da.map_blocks(
            func,
            *xs,
            drop_axis=1,
            new_axis=0,
            chunks=((n_lights,), xs[0].chunks[0]),
            dtype=np.float32,
            meta=np.empty((0, 0), dtype=np.float32),
        )
    return da.map_blocks(
        func,
        *xs,
        drop_axis=1,
        chunks=(xs[0].chunks[0],),
        dtype=np.float32,
        meta=np.empty((0,), dtype=np.float32),
    )
