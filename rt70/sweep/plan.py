"""The plan of a sweep, checked before any work: its scene, quantities, chunks and size.

What :mod:`rt70.sweep.run` computes and stores, on a grid of :mod:`rt70.sweep.grid`: the
scene a chunk is computed on (:class:`SceneSource`, :func:`build_scene`), one chunk's
computation (:func:`compute_chunk`) and the sweep as a whole with its key
(:class:`Sweep`, :func:`plan`), and the memory it will hold against what this machine
has (:func:`peak_bytes`, :func:`check_size`). docs/sweeps.md.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.resources import check_memory
from rt70.model.scene import Scene, scene_from_text, scene_path
from rt70.sweep import surface_quantity  # noqa: F401  (registers 'surface')
from rt70.sweep.errors import SweepError
from rt70.sweep.grid import Chunk, Grid
from rt70.sweep.quantities import QUANTITIES, Quantity, check_factors, scaled_scene
from rt70.urdf.text import read_source

#: Quantities computed when none is named.
DEFAULT_QUANTITIES = ("first_frequency", "sag")

#: Default number of points per chunk (a run along elevation).
DEFAULT_CHUNK = 8

#: Version of the partial-results layout (part of the key): 2 has the chunk files of
#: :mod:`rt70.sweep.store` (their key and checksum inside).
FORMAT = 2

#: Memory a sweep holds per number of its results, bytes: the grid's float64 arrays,
#: filled as the chunks arrive. The three constants below (and
#: :data:`rt70.sweep.grid.BYTES_PER_AXIS_VALUE`) are rounded up from
#: ``python validation/sweep_memory.py --points 9000`` (tracemalloc, output written):
#: 7.8 B per number, 2645 B per error record, 662 B per chunk, 90 B per axis value.
BYTES_PER_NUMBER = 10

#: Memory per failed point and quantity, bytes: its error record and its share of the
#: JSON sidecar — counted for every point, as if every point failed.
BYTES_PER_ERROR = 3_000

#: Memory per chunk, bytes: its :class:`Chunk` and its share of the bookkeeping.
BYTES_PER_CHUNK = 1_000


# --- the scene, as sent to the workers -----------------------------------------------


@dataclass(frozen=True)
class SceneSource:
    """A scene's file content (what the workers build it from) and its SHA-256.

    ``origin`` is the file it was read from, the name messages about its content give
    (the scene's name where it came from no file).
    """

    name: str
    text: str
    sha256: str
    origin: str = ""

    @classmethod
    def read(cls, target: str | Path) -> SceneSource:
        """Read a scene by name or path (:func:`rt70.model.scene.scene_path`)."""
        path = scene_path(target)
        text = read_source(path)
        return cls(path.stem, text, hashlib.sha256(text.encode()).hexdigest(), str(path))


#: Scenes built in this process, most recently used last: (sha256, scales) → Scene.
_SCENES: OrderedDict[tuple[str, tuple[tuple[str, float], ...]], Scene] = OrderedDict()

#: Scenes a process keeps built (the base scene and the latest scaled ones): a chunk
#: runs at one set of factors, so a worker needs one at a time; a sweep over many
#: factors does not pile up scenes.
SCENES_KEPT = 4


def build_scene(source: SceneSource, scales: Mapping[str, float] | None = None) -> Scene:
    """The scene of ``source`` with the parameters scaled, built once per process.

    The :data:`SCENES_KEPT` most recently used scenes are kept.
    """
    scales = dict(scales or {})
    key = (source.sha256, tuple(sorted(scales.items())))
    if key in _SCENES:
        _SCENES.move_to_end(key)
        return _SCENES[key]
    if scales:
        scene = scaled_scene(build_scene(source), scales)
    else:
        scene = scene_from_text(source.text, source.name, source=source.origin or None)
    _SCENES[key] = scene
    while len(_SCENES) > SCENES_KEPT:
        _SCENES.popitem(last=False)
    return scene


# --- one chunk -----------------------------------------------------------------------


@dataclass
class ChunkResult:
    """What one chunk computed: ``arrays[field]`` (one row per point) and its errors."""

    number: int
    arrays: dict[str, np.ndarray]
    errors: list[dict[str, Any]] = field(default_factory=list)


def compute_chunk(
    source: SceneSource, grid: Grid, chunk: Chunk, quantities: Sequence[Quantity]
) -> ChunkResult:
    """Every quantity at every point of ``chunk`` (the task a Dask worker runs).

    A quantity that raises :class:`~rt70.errors.Rt70Error` or
    :class:`numpy.linalg.LinAlgError`, or returns a value that is not finite (a NaN
    its field does not declare, :attr:`~rt70.sweep.quantities.Field.nan`), leaves its
    fields NaN at that point with an error record.

    Parameters
    ----------
    source : SceneSource
        The scene's file content; each point's scene is built from it with the point's
        scale factors (:func:`build_scene`, kept per process).
    grid : Grid
        The sweep's grid.
    chunk : Chunk
        The points computed.
    quantities : sequence of Quantity
        The quantities computed at each point.

    Returns
    -------
    ChunkResult
        ``arrays[field]`` shaped ``(stop − start, *field.shape)``, and the error records
        (``index``, ``point``, ``quantity``, ``error``).
    """
    n = chunk.stop - chunk.start
    arrays = {f.name: np.full((n, *f.shape), np.nan) for q in quantities for f in q.fields}
    errors = []
    for row, index in enumerate(chunk.indices()):
        point = grid.point(index)
        scene = build_scene(source, point.scales)
        for q in quantities:
            try:
                with np.errstate(all="ignore"):  # what overflows is reported, not warned
                    values = finite_values(q, q.compute(scene, point))
            except (Rt70Error, np.linalg.LinAlgError) as exc:
                errors.append(
                    {"index": list(index), "point": point.as_dict(), "quantity": q.name}
                    | {"error": str(exc)}
                )
                continue
            for f in q.fields:
                arrays[f.name][row] = values[f.name]
    return ChunkResult(chunk.number, arrays, errors)


def finite_values(quantity: Quantity, values: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """A quantity's values at one point as arrays of its fields' shapes, checked finite.

    Raises
    ------
    Rt70Error
        A value is infinite, or NaN where its field declares no meaning for a NaN.
    ValueError
        A value of the wrong shape (a bug in the quantity).
    """
    out = {}
    for f in quantity.fields:
        v = np.asarray(values[f.name], dtype=float)
        if v.shape != f.shape:
            raise ValueError(
                f"quantity {quantity.name}: {f.name} has shape {v.shape}, not {f.shape}"
            )
        bad = np.isinf(v) if f.nan else ~np.isfinite(v)
        if bad.any():
            first = v.ravel()[bad.ravel()][0]
            raise Rt70Error(f"{quantity.name}: {f.name} is not finite at this point ({first})")
        out[f.name] = v
    return out


# --- the plan and its key --------------------------------------------------------------


@dataclass(frozen=True)
class Sweep:
    """What to compute: a scene, a grid, the quantities, the chunk size."""

    source: SceneSource
    grid: Grid
    quantities: tuple[Quantity, ...]
    chunk: int = DEFAULT_CHUNK

    @property
    def key(self) -> str:
        """Hash of the scene's content, the grid, the quantities and the chunk size."""
        fields = {q.name: [[f.name, list(f.shape)] for f in q.fields] for q in self.quantities}
        blob = json.dumps(
            [FORMAT, self.source.sha256, self.grid.as_dict(), fields, self.chunk], sort_keys=True
        )
        return hashlib.sha256(blob.encode()).hexdigest()

    def chunks(self) -> list[Chunk]:
        """The sweep's chunks (:meth:`Grid.chunks`)."""
        return self.grid.chunks(self.chunk)


def plan(
    target: str | Path,
    grid: Grid,
    quantities: Sequence[str],
    chunk: int = DEFAULT_CHUNK,
) -> Sweep:
    """Check the sweep can run and read its scene, before any work.

    Parameters
    ----------
    target : str or Path
        A scene name (``rt70_servo``) or the path of a URDF file.
    grid : Grid
        The points: elevation first, then azimuth, wind, direction and scale axes.
    quantities : sequence of str
        Names of registered quantities (:data:`rt70.sweep.quantities.QUANTITIES`).
    chunk : int, optional
        Points per chunk along elevation (≥ 1).

    Returns
    -------
    Sweep
        The scene's content, the grid, the quantities and the chunk size.

    Raises
    ------
    Rt70Error
        A scene that does not load, has no RT-70 pointing axes or cannot give a
        quantity (:attr:`Quantity.check`); an unknown quantity; chunk < 1; a scale
        factor taking a number of the scene beyond what rt70 reads in a model.
    ResourceError
        A sweep larger than this machine can hold (:func:`check_size`), checked before
        the scene is read.
    """
    if chunk < 1:
        raise SweepError(f"--chunk must be at least 1, got {chunk}")
    unknown = [q for q in quantities if q not in QUANTITIES]
    if unknown or not quantities:
        known = ", ".join(sorted(QUANTITIES))
        raise SweepError(f"unknown quantity {', '.join(unknown) or '(none)'} (known: {known})")
    chosen = tuple(QUANTITIES[q] for q in quantities)
    check_size(grid, chosen, chunk)
    source = SceneSource.read(target)
    scene = build_scene(source)
    _check_pointings(source.name, scene, grid)
    for axis in grid.axes:
        if axis.name.startswith("scale:"):
            check_factors(scene, axis.name.removeprefix("scale:"), axis.values)
    for q in chosen:
        if q.check is not None:
            q.check(scene)
    return Sweep(source, grid, chosen, chunk)


def _check_pointings(name: str, scene, grid: Grid) -> None:
    """Refuse a scene without a mount, or a grid elevation or azimuth outside its ranges."""
    from rt70.model.antenna import mount_of, range_deg, within_range

    try:
        mount = mount_of(scene)
    except Rt70Error as exc:
        raise SweepError(f"no pointing axes to sweep: {exc}") from None
    for axis_name in ("elevation", "azimuth"):
        axis = mount.axis(axis_name)
        values = next(a.values for a in grid.axes if a.name == axis_name)
        outside = [v for v in values if not within_range(axis, v)]
        if outside:
            low, high = range_deg(axis)
            raise SweepError(
                f"--{axis_name} {outside[0]:g}: {name} points its {axis_name} axis from "
                f"{low:g}° to {high:g}° (<rt70:axis name='{axis_name}'>)"
            )


def peak_bytes(grid: Grid, quantities: Sequence[Quantity], chunk: int) -> int:
    """Memory a sweep holds at its end, bytes: results, error records, chunk bookkeeping.

    ``points × (BYTES_PER_NUMBER × numbers + BYTES_PER_ERROR × quantities) + chunks ×
    BYTES_PER_CHUNK``, every point counted as failed (the most it can hold).

    Parameters
    ----------
    grid : Grid
        The sweep's grid.
    quantities : sequence of Quantity
        The quantities computed at each point (their fields' numbers).
    chunk : int
        Points per chunk along elevation.
    """
    numbers = sum(math.prod(f.shape) for q in quantities for f in q.fields)
    chunks = math.ceil(grid.shape[0] / chunk) * math.prod(grid.shape[1:])
    per_point = BYTES_PER_NUMBER * numbers + BYTES_PER_ERROR * len(quantities)
    return grid.size * per_point + chunks * BYTES_PER_CHUNK


def check_size(grid: Grid, quantities: Sequence[Quantity], chunk: int) -> None:
    """Refuse a sweep whose results this machine cannot hold (:func:`peak_bytes`).

    Parameters
    ----------
    grid : Grid
        The sweep's grid.
    quantities : sequence of Quantity
        The quantities computed at each point.
    chunk : int
        Points per chunk along elevation.

    Raises
    ------
    ResourceError
        Naming the axes' options and their sizes, the estimate and the memory available.
    """
    swept = [a for a in grid.axes if len(a.values) > 1] or list(grid.axes[:1])
    options = " × ".join(option_name(a.name) for a in swept)
    sizes = " × ".join(str(len(a.values)) for a in swept)
    numbers = sum(math.prod(f.shape) for q in quantities for f in q.fields)
    check_memory(
        peak_bytes(grid, quantities, chunk),
        f"a grid of {grid.size} points ({sizes}) of {numbers} numbers each, with an error "
        "record per point and quantity at most,",
        options,
    )


def option_name(axis: str) -> str:
    """The command-line option of an axis: ``--elevation``, ``--scale NAME``."""
    return f"--scale {axis.removeprefix('scale:')}" if axis.startswith("scale:") else f"--{axis}"
