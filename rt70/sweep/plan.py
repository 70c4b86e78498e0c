"""The plan of a sweep, checked before any work: its grid, chunks, quantities and size.

What :mod:`rt70.sweep.run` computes and stores: the axes and their values
(:func:`parse_values`, :func:`make_grid`), the chunks a grid is cut into
(:meth:`Grid.chunks`), the scene a chunk is computed on (:class:`SceneSource`,
:func:`build_scene`), one chunk's computation (:func:`compute_chunk`) and the sweep as a
whole with its key (:class:`Sweep`, :func:`plan`), and the memory it will hold against
what this machine has (:func:`peak_bytes`, :func:`check_size`). docs/sweeps.md.
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
from rt70.sweep.quantities import (
    PARAMETERS,
    QUANTITIES,
    Quantity,
    SweepPoint,
    check_factors,
    scaled_scene,
)
from rt70.urdf.text import read_source

#: The fixed axes of every grid, in order, with units and defaults (one value each).
AXES = (("elevation", "deg", 90.0), ("azimuth", "deg", 0.0), ("wind", "m/s", 0.0))
AXES += (("direction", "deg", 0.0),)

#: Quantities computed when none is named.
DEFAULT_QUANTITIES = ("first_frequency", "sag")

#: Default number of points per chunk (a run along elevation).
DEFAULT_CHUNK = 8

#: Version of the partial-results layout (part of the key): 2 has the chunk files of
#: :mod:`rt70.sweep.store` (their key and checksum inside).
FORMAT = 2

#: Largest magnitude of an azimuth or a wind direction, degrees: one turn either way
#: holds every pointing; beyond it a float's spacing grows until the angle means nothing.
MAX_TURN_DEG = 360.0

#: Memory a sweep holds per number of its results, bytes: the grid's float64 arrays,
#: filled as the chunks arrive. The four constants below are rounded up from
#: ``python validation/sweep_memory.py --points 9000`` (tracemalloc, output written):
#: 7.8 B per number, 2645 B per error record, 662 B per chunk, 90 B per axis value.
BYTES_PER_NUMBER = 10

#: Memory per failed point and quantity, bytes: its error record and its share of the
#: JSON sidecar — counted for every point, as if every point failed.
BYTES_PER_ERROR = 3_000

#: Memory per chunk, bytes: its :class:`Chunk` and its share of the bookkeeping.
BYTES_PER_CHUNK = 1_000

#: Memory per value of an axis, bytes: the Python float, the tuple slot, the grid's
#: JSON (key, metadata) and numpy's transient ``linspace``.
BYTES_PER_AXIS_VALUE = 150


class SweepError(Rt70Error):
    """A sweep that cannot run as asked (bad grid, a foreign partial directory, no cluster)."""


class ClusterError(SweepError):
    """The Dask cluster cannot finish the sweep: its scheduler or its workers are gone."""


# --- the grid ------------------------------------------------------------------------


def parse_values(text: str) -> tuple[float, ...]:
    """Values of an axis: ``A:B:N`` (N equally spaced, ends included), ``A,B,…`` or ``A``.

    Raises
    ------
    SweepError
        For anything else (``1:2``, N < 2 with A ≠ B, a non-finite number).
    ResourceError
        More values than this machine can hold (checked before they are made).
    """

    def number(s: str) -> float:
        try:
            v = float(s)
        except ValueError:
            raise SweepError(f"'{s}' is not a number (in '{text}')") from None
        if not math.isfinite(v):
            raise SweepError(f"'{s}' is not a finite number (in '{text}')")
        return v

    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise SweepError(f"'{text}': a range is START:STOP:COUNT, e.g. 0:90:91")
        a, b = number(parts[0]), number(parts[1])
        try:
            n = int(parts[2])
        except ValueError:
            raise SweepError(f"'{text}': COUNT '{parts[2]}' is not an integer") from None
        if n < 1 or (n == 1 and a != b):
            raise SweepError(f"'{text}': COUNT must be at least 2 (1 only when START = STOP)")
        check_memory(n * BYTES_PER_AXIS_VALUE, f"{n} values of an axis", f"'{text}'")
        return tuple(float(v) for v in np.linspace(a, b, n))
    return tuple(number(s) for s in text.split(","))


@dataclass(frozen=True)
class Axis:
    """One axis of a grid: its name (``scale:NAME`` for a scene parameter), unit, values."""

    name: str
    unit: str
    values: tuple[float, ...]


@dataclass(frozen=True)
class Chunk:
    """Points ``start … stop − 1`` along elevation at the indices ``rest`` of the other axes."""

    number: int
    rest: tuple[int, ...]
    start: int
    stop: int

    def indices(self) -> list[tuple[int, ...]]:
        """Grid indices of the chunk's points, in order of increasing elevation index."""
        return [(i, *self.rest) for i in range(self.start, self.stop)]


@dataclass(frozen=True)
class Grid:
    """The Cartesian product of :attr:`axes` (elevation first: the chunks run along it)."""

    axes: tuple[Axis, ...]

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values per axis."""
        return tuple(len(a.values) for a in self.axes)

    @property
    def size(self) -> int:
        """Number of points."""
        return math.prod(self.shape)

    def point(self, index: Sequence[int]) -> SweepPoint:
        """The point at a grid index."""
        values = {a.name: a.values[i] for a, i in zip(self.axes, index, strict=True)}
        scales = {k.removeprefix("scale:"): v for k, v in values.items() if k.startswith("scale:")}
        return SweepPoint(
            values["elevation"], values["azimuth"], values["wind"], values["direction"], scales
        )

    def chunks(self, size: int) -> list[Chunk]:
        """The grid cut into runs of at most ``size`` consecutive elevations, numbered."""
        out = []
        for rest in np.ndindex(*self.shape[1:]):
            for start in range(0, self.shape[0], size):
                stop = min(start + size, self.shape[0])
                out.append(Chunk(len(out), tuple(int(i) for i in rest), start, stop))
        return out

    def chunk(self, size: int, number: int) -> Chunk:
        """Chunk ``number`` of :meth:`chunks` (``size``), without listing the others."""
        per_run = math.ceil(self.shape[0] / size)
        run, k = divmod(number, per_run)
        rest = (
            tuple(int(i) for i in np.unravel_index(run, self.shape[1:])) if self.shape[1:] else ()
        )
        start = k * size
        return Chunk(number, rest, start, min(start + size, self.shape[0]))

    def as_dict(self) -> dict[str, Any]:
        """The axes as JSON: ``{name: {"unit": …, "values": […]}}``, in order."""
        return {a.name: {"unit": a.unit, "values": list(a.values)} for a in self.axes}


def make_grid(
    values: Mapping[str, Sequence[float]] | None = None,
    scales: Mapping[str, Sequence[float]] | None = None,
) -> Grid:
    """A grid from axis values (missing axes take their default) and parameter factors.

    Raises
    ------
    SweepError
        An elevation outside 0…90°, an azimuth or direction beyond one turn, a
        negative wind speed, an unknown axis or scene parameter, a factor ≤ 0, an empty
        or repeated axis.
    """
    from rt70.scenes.rt70_state import ELEVATION_RANGE

    values = dict(values or {})
    unknown = [k for k in values if k not in {name for name, _, _ in AXES}]
    if unknown:
        raise SweepError(f"unknown sweep axis {', '.join(unknown)}")
    axes = []
    for name, unit, default in AXES:
        axes.append(Axis(name, unit, tuple(float(v) for v in values.get(name, (default,)))))
    for name, factors in (scales or {}).items():
        if name not in PARAMETERS:
            raise SweepError(
                f"--scale {name}: unknown scene parameter (known: {', '.join(PARAMETERS)})"
            )
        if any(not f > 0.0 for f in factors):
            raise SweepError(f"--scale {name}: factors must be greater than 0")
        axes.append(Axis(f"scale:{name}", "1", tuple(float(f) for f in factors)))
    low, high = ELEVATION_RANGE
    for axis in axes:
        if not axis.values:
            raise SweepError(f"--{axis.name}: no values")
        if len(set(axis.values)) != len(axis.values):
            raise SweepError(f"--{axis.name}: a value is repeated")
    if any(not low <= e <= high for e in axes[0].values):
        raise SweepError(f"--elevation: the RT-70 points from {low:g}° to {high:g}°")
    if any(w < 0.0 for w in axes[2].values):
        raise SweepError("--wind: speeds must be at least 0 m/s")
    for axis in (axes[1], axes[3]):
        if any(abs(v) > MAX_TURN_DEG for v in axis.values):
            raise SweepError(
                f"--{axis.name}: angles from {-MAX_TURN_DEG:g}° to {MAX_TURN_DEG:g}° "
                "(one turn either way holds every pointing)"
            )
    return Grid(tuple(axes))


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
    from rt70.scenes.rt70_state import missing_axes

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
    names = scene.textbook.coordinate_names
    missing = missing_axes(names)
    if missing:
        raise SweepError(f"{source.name}: no RT-70 pointing axis {', '.join(missing)} to sweep")
    for axis in grid.axes:
        if axis.name.startswith("scale:"):
            check_factors(scene, axis.name.removeprefix("scale:"), axis.values)
    for q in chosen:
        if q.check is not None:
            q.check(scene)
    return Sweep(source, grid, chosen, chunk)


def peak_bytes(grid: Grid, quantities: Sequence[Quantity], chunk: int) -> int:
    """Memory a sweep holds at its end, bytes: results, error records, chunk bookkeeping.

    ``points × (BYTES_PER_NUMBER × numbers + BYTES_PER_ERROR × quantities) + chunks ×
    BYTES_PER_CHUNK``, every point counted as failed (the most it can hold).
    """
    numbers = sum(math.prod(f.shape) for q in quantities for f in q.fields)
    chunks = math.ceil(grid.shape[0] / chunk) * math.prod(grid.shape[1:])
    per_point = BYTES_PER_NUMBER * numbers + BYTES_PER_ERROR * len(quantities)
    return grid.size * per_point + chunks * BYTES_PER_CHUNK


def check_size(grid: Grid, quantities: Sequence[Quantity], chunk: int) -> None:
    """Refuse a sweep whose results this machine cannot hold (:func:`peak_bytes`).

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
