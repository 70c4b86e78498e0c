"""Parameter sweeps over a grid of pointings, winds and scene parameters, on Dask.

One job: compute registered quantities (:mod:`rt70.sweep_quantities`) at every point
of a Cartesian grid — elevation × azimuth × wind speed × wind direction × scene
parameter factors — in chunks, either in this process (:func:`serial`) or on a
``dask.distributed`` cluster (:func:`rt70.sweep_dask.on_dask`), and store them so an
interrupted sweep resumes (docs/sweeps.md):

- the grid, the quantities and the memory the sweep will hold are checked before any
  work (:func:`plan`, :func:`check_size`); so are the output paths (:func:`check_output`);
- a **chunk** is a run of consecutive elevations at fixed values of the other axes
  (:meth:`Grid.chunks`); it is the unit of work and of resumption;
- each finished chunk is written atomically to ``FILE.partial/chunk-NNNNN.npz`` by the
  client as it arrives, with the sweep's key and a checksum (:mod:`rt70.sweep_store`);
  ``FILE.partial/key.json`` holds the sweep's key, a hash of the scene file's content,
  the grid, the quantities and the chunk size. A rerun with the same key verifies the
  chunks there, keeps those it can trust and computes the others (saying how many and
  why); a different key is refused (:class:`SweepError`): nothing is mixed and nothing
  is deleted. One process at a time writes a partial directory (a lock, :class:`
  rt70.sweep_store.DirectoryLock`);
- at the end ``FILE`` (NPZ: the axes and one array per quantity field, shaped
  ``grid.shape + field.shape``) and ``FILE``'s JSON sidecar (metadata, per-point
  errors) are written together atomically and ``FILE.partial/`` is removed.

A point whose quantity raises :class:`~rt70.errors.Rt70Error` (no equilibrium, an
unstable mode, …) or returns a value that is not finite is stored as NaN and its
message recorded: a NaN in the output always has its error record (a field may
declare a NaN that means something else, :attr:`rt70.sweep_quantities.Field.nan`).
Any other exception is a bug and stops the sweep (finished chunks kept).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import time
import warnings
from collections import OrderedDict
from collections.abc import Callable, Generator, Iterator, Mapping, Sequence
from contextlib import closing, contextmanager, nullcontext
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import rt70
from rt70 import sweep_store
from rt70.atomic import atomic_write, atomic_write_all
from rt70.errors import OutputError, Rt70Error, Rt70Warning
from rt70.resources import check_memory
from rt70.scene import Scene, scene_from_text, scene_path
from rt70.sweep_quantities import (
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
#: :mod:`rt70.sweep_store` (their key and checksum inside).
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
    from rt70.options import ELEVATION_RANGE

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
    """A scene's file content (what the workers build it from) and its SHA-256."""

    name: str
    text: str
    sha256: str

    @classmethod
    def read(cls, target: str | Path) -> SceneSource:
        """Read a scene by name or path (:func:`rt70.scene.scene_path`)."""
        path = scene_path(target)
        text = read_source(path)
        return cls(path.stem, text, hashlib.sha256(text.encode()).hexdigest())


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
        scene = scene_from_text(source.text, source.name)
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
    its field does not declare, :attr:`~rt70.sweep_quantities.Field.nan`), leaves its
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


# --- where chunks are kept -------------------------------------------------------------


def check_output(out: str | Path) -> None:
    """Refuse output paths a sweep could not use, before any work (nothing created).

    ``out`` (a ``.npz`` file), its JSON sidecar, ``out.partial/`` and the key and lock
    files in it: each must be absent or of the right kind, so that a sweep does not
    fail on them after its work is done.

    Raises
    ------
    OutputError
        Naming the path and what it is.
    """
    out = Path(out)
    directory = PartialResults.directory_of(out)
    for path in (out, sidecar(out), directory / "key.json", directory / "lock"):
        if not sweep_store.is_regular_or_missing(path):
            raise OutputError(f"{path}: exists and is not a regular file (a directory?)")
    if directory.exists() and not directory.is_dir():
        raise OutputError(
            f"{directory}: exists and is not a directory (where {out.name}'s finished "
            "chunks are kept); remove it, or write to another --out"
        )


class PartialResults:
    """``FILE.partial/``: the finished chunks of one sweep, keyed by :attr:`Sweep.key`.

    Use :meth:`locked` around everything that reads or writes it; :meth:`open` checks
    the directory and loads the chunks it can trust.
    """

    def __init__(self, out: str | Path, sweep: Sweep):
        self.out = Path(out)
        self.directory = self.directory_of(self.out)
        self.sweep = sweep
        self.recomputed: dict[str, str] = {}  # chunk file → why it is recomputed
        self._lock = sweep_store.DirectoryLock(self.directory)

    @staticmethod
    def directory_of(out: Path) -> Path:
        """The partial directory of an output file: ``FILE.partial``."""
        return out.with_name(out.name + ".partial")

    @contextmanager
    def locked(self) -> Iterator[PartialResults]:
        """Hold the directory's lock inside the block (re-entrant in a process).

        Raises
        ------
        LockedError
            Another process writes this directory (another sweep on the same ``--out``).
        OutputError
            The directory or its lock file cannot be created.
        """
        check_output(self.out)
        try:
            self._lock.acquire()
        except OSError as exc:
            raise OutputError(f"{self._lock.path}: cannot create ({exc.strerror})") from None
        try:
            yield self
        finally:
            self._lock.release()

    def check(self) -> None:
        """Refuse a directory that holds the chunks of a different sweep (nothing created).

        Raises
        ------
        SweepError
            If the directory holds chunk files and its key file is missing, unreadable or
            not this sweep's.
        OutputError
            If a path of it is of the wrong kind (:func:`check_output`).
        """
        check_output(self.out)
        key_file = self.directory / "key.json"
        if not self.directory.is_dir():
            return
        chunk_files = list(self.directory.glob("chunk-*.npz"))
        if not key_file.exists() and not chunk_files:
            return  # a directory left by a stop before its key: a fresh start
        try:
            if key_file.stat().st_size > sweep_store.MAX_META_BYTES:
                raise ValueError("too large")
            key = json.loads(key_file.read_text(encoding="utf-8"))["key"]
        except (OSError, ValueError, KeyError, TypeError) as exc:
            reason = "missing" if isinstance(exc, FileNotFoundError) else "unreadable"
            raise SweepError(
                f"{key_file}: {reason}, so the {len(chunk_files)} chunk file(s) beside it "
                "cannot be told apart from another sweep's; remove "
                f"{self.directory}, or write to another --out"
            ) from None
        if key != self.sweep.key:
            raise SweepError(
                f"{self.directory}: holds the unfinished results of a different sweep "
                "(scene file, grid, quantities or --chunk differ); remove it, or write to "
                "another --out"
            )

    def open(self) -> dict[int, ChunkResult]:
        """Check the directory (:meth:`check`), create its key, load its trusted chunks.

        A chunk file that cannot be trusted (:func:`rt70.sweep_store.read_chunk`,
        :func:`check_result`) is left to be recomputed: :attr:`recomputed` says which
        and why, and one :class:`~rt70.errors.Rt70Warning` says how many.
        """
        self.check()
        key_file = self.directory / "key.json"
        if key_file.is_file():
            return self._load()
        record = {"key": self.sweep.key, "scene": self.sweep.source.name}
        self._write(key_file, lambda tmp: tmp.write_text(json.dumps(record), encoding="utf-8"))
        return self._load()

    def _path(self, number: int) -> Path:
        return self.directory / f"chunk-{number:05d}.npz"

    def _load(self) -> dict[int, ChunkResult]:
        fields = {f.name: f.shape for q in self.sweep.quantities for f in q.fields}
        done = {}
        for chunk in self.sweep.chunks():
            path = self._path(chunk.number)
            if not os.path.lexists(path):
                continue
            if path.is_dir():
                raise OutputError(f"{path}: a directory where a chunk file belongs; remove it")
            try:
                if not path.is_file():
                    raise sweep_store.UntrustedChunk("not a regular file")
                arrays, errors = sweep_store.read_chunk(path, self._meta(chunk), fields)
                result = ChunkResult(chunk.number, arrays, errors)
                check_result(self.sweep, chunk, result)
            except (sweep_store.UntrustedChunk, SweepError) as exc:
                self.recomputed[path.name] = str(exc)
                continue
            done[chunk.number] = result
        if self.recomputed:
            warnings.warn(self._recompute_message(), Rt70Warning, stacklevel=3)
        return done

    def _recompute_message(self) -> str:
        shown = [f"{name}: {why}" for name, why in list(self.recomputed.items())[:3]]
        more = len(self.recomputed) - len(shown)
        return (
            f"{self.directory}: {len(self.recomputed)} chunk file(s) cannot be trusted and "
            f"are recomputed: {'; '.join(shown)}{f'; and {more} more' if more else ''}"
        )

    def _meta(self, chunk: Chunk) -> dict[str, Any]:
        return {
            "key": self.sweep.key,
            "chunk": chunk.number,
            "rest": list(chunk.rest),
            "start": chunk.start,
            "stop": chunk.stop,
        }

    def save(self, result: ChunkResult) -> None:
        """Write one finished chunk atomically, with the sweep's key and a checksum.

        Raises
        ------
        OutputError
            The file system refused it (a full disk): the chunks saved so far are kept.
        """
        meta = self._meta(self.sweep.grid.chunk(self.sweep.chunk, result.number))
        self._write(
            self._path(result.number),
            lambda tmp: sweep_store.write_chunk(tmp, meta, result.arrays, result.errors),
        )

    def _write(self, path: Path, write: Callable[[Path], None]) -> None:
        try:
            atomic_write(path, write)
        except (OSError, OutputError) as exc:
            raise OutputError(f"{_cannot_write(path, exc)}; {self.kept()}") from None

    def kept(self) -> str:
        """Where the finished chunks are, for a message: ``N finished chunk(s) kept in …``."""
        n = len(list(self.directory.glob("chunk-*.npz"))) if self.directory.is_dir() else 0
        return f"{n} finished chunk(s) kept in {self.directory}: rerun to resume"

    def remove(self) -> None:
        """Delete the directory (the sweep's files are written)."""
        shutil.rmtree(self.directory, ignore_errors=True)


def check_result(sweep: Sweep, chunk: Chunk, result: ChunkResult) -> None:
    """Refuse a chunk's result that is not what ``sweep`` computes there.

    Its fields (names, shapes), its error records (points of the chunk, quantities of
    the sweep) and the rule that a NaN has its error record: for each point and
    quantity, either an error record and every field NaN, or no record and every
    value finite (NaN only where :attr:`~rt70.sweep_quantities.Field.nan` allows it).

    Raises
    ------
    SweepError
        Naming what is wrong.
    """
    rows = chunk.stop - chunk.start
    expected = {f.name: (rows, *f.shape) for q in sweep.quantities for f in q.fields}
    got = {k: np.shape(v) for k, v in result.arrays.items()}
    if got != expected:
        raise SweepError(f"fields {got}, not the chunk's {expected}")
    indices = {tuple(i): row for row, i in enumerate(chunk.indices())}
    names = {q.name for q in sweep.quantities}
    failed = set()
    for e in result.errors:
        try:
            where = (indices[tuple(e["index"])], e["quantity"])
            ok = where[1] in names and isinstance(e["error"], str) and isinstance(e["point"], dict)
        except (KeyError, TypeError):
            ok = False
        if not ok or where in failed:
            raise SweepError("an error record that is not one of its points' or is repeated")
        failed.add(where)
    for q in sweep.quantities:
        for row in range(rows):
            values = [(f, np.asarray(result.arrays[f.name][row])) for f in q.fields]
            where = f"{q.name} at grid index {list(chunk.indices()[row])}"
            if (row, q.name) in failed:
                if not all(np.isnan(v).all() for _, v in values):
                    raise SweepError(f"{where} has an error record and values")
            elif not all(
                not np.isinf(v).any() and (f.nan or not np.isnan(v).any()) for f, v in values
            ):
                raise SweepError(f"{where} is not finite and has no error record")


def _cannot_write(path: Path, exc: BaseException) -> str:
    """``<path>: cannot write (<reason>)`` for an ``OSError`` or rt70's ``OutputError``."""
    if isinstance(exc, OSError):
        return f"{path}: cannot write ({exc.strerror or exc})"
    return str(exc)


# --- executors: where the chunks are computed ------------------------------------------

#: An executor: (sweep, chunks to compute) → results as they finish.
Executor = Callable[[Sweep, list[Chunk]], Generator[ChunkResult, None, None]]


def serial(sweep: Sweep, chunks: list[Chunk]) -> Generator[ChunkResult, None, None]:
    """Compute the chunks one after the other in this process (BLAS pinned to 1 thread)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        for chunk in chunks:
            yield compute_chunk(sweep.source, sweep.grid, chunk, sweep.quantities)


# --- running -------------------------------------------------------------------------


@dataclass
class SweepResult:
    """A finished sweep: its arrays (axes and fields) and its metadata (the JSON sidecar)."""

    arrays: dict[str, np.ndarray]
    metadata: dict[str, Any]

    @property
    def errors(self) -> list[dict[str, Any]]:
        """The points that failed, one record per point and quantity."""
        return self.metadata["errors"]


def run(
    sweep: Sweep,
    executor: Executor,
    out: str | Path | None = None,
    workers: int = 0,
    progress: bool = False,
    on_chunk: Callable[[ChunkResult], None] | None = None,
) -> SweepResult:
    """Compute the sweep (resuming from ``out``'s partial results) and write ``out``.

    Parameters
    ----------
    sweep : Sweep
        From :func:`plan`.
    executor : callable
        :func:`serial` or :func:`rt70.sweep_dask.on_dask` of a client.
    out : path, optional
        The ``.npz`` file; its JSON sidecar is ``out.with_suffix(".json")`` and its
        partial results ``out.partial/``, locked while the sweep runs. None: nothing is
        stored (no resume).
    workers : int
        Recorded in the metadata (0 for in-process).
    progress : bool
        A tqdm bar over the chunks on stderr.
    on_chunk : callable, optional
        Called with each chunk computed here (not the resumed ones) after it is saved.

    Raises
    ------
    ResourceError
        The sweep is larger than this machine can hold (:func:`check_size`).
    SweepError
        ``out.partial/`` holds another sweep's chunks; a chunk from the executor is not what
        the sweep computes (:func:`check_result`); the cluster fails
        (:class:`ClusterError`, the finished chunks kept).
    LockedError
        Another process writes ``out.partial/`` (:class:`rt70.sweep_store.DirectoryLock`).
    OutputError
        A file cannot be written (a full disk): the previous output files and the
        finished chunks are kept.
    """
    check_size(sweep.grid, sweep.quantities, sweep.chunk)
    store = PartialResults(out, sweep) if out is not None else None
    with store.locked() if store is not None else nullcontext():
        result = _compute(sweep, executor, store, workers, progress, on_chunk)
        if store is not None:
            try:
                write(result, store.out)
            except (OSError, OutputError) as exc:
                raise OutputError(
                    f"{_cannot_write(store.out, exc)}; the previous {store.out.name} and "
                    f"{sidecar(store.out).name} are unchanged, {store.kept()}"
                ) from None
            store.remove()
    return result


def _compute(
    sweep: Sweep,
    executor: Executor,
    store: PartialResults | None,
    workers: int,
    progress: bool,
    on_chunk: Callable[[ChunkResult], None] | None,
) -> SweepResult:
    """The sweep's arrays and metadata: resumed chunks and the others from ``executor``."""
    from tqdm import tqdm

    start = time.perf_counter()
    chunks = sweep.chunks()
    done = store.open() if store is not None else {}
    pending = [c for c in chunks if c.number not in done]
    arrays = _empty_arrays(sweep)
    errors: dict[int, list[dict[str, Any]]] = {}
    for number, got in done.items():
        errors[number] = _place(arrays, chunks[number], got)
    with tqdm(
        total=len(chunks), initial=len(done), disable=not progress, unit="chunk", leave=False
    ) as bar:
        with closing(executor(sweep, pending)) as finished:  # closed at once on Ctrl-C
            try:
                for got in finished:
                    chunk = chunks[got.number] if 0 <= got.number < len(chunks) else None
                    if chunk is None or got.number in errors:
                        raise SweepError(
                            f"the executor returned chunk {got.number} twice or unasked"
                        )
                    try:
                        check_result(sweep, chunk, got)
                    except SweepError as exc:
                        raise SweepError(f"chunk {got.number} as computed: {exc}") from None
                    if store is not None:
                        store.save(got)
                    errors[got.number] = _place(arrays, chunk, got)
                    if on_chunk is not None:
                        on_chunk(got)
                    bar.update(1)
            except ClusterError as exc:
                if store is None:
                    raise
                raise ClusterError(f"{exc}; {store.kept()}") from None
    metadata = {
        "scene": {"name": sweep.source.name, "sha256": sweep.source.sha256},
        "grid": sweep.grid.as_dict(),
        "shape": list(sweep.grid.shape),
        "quantities": {
            q.name: {
                "description": q.description,
                "fields": {
                    f.name: {"shape": list(f.shape), "unit": f.unit, "description": f.description}
                    | {"nan": f.nan or "a failed point (see errors)"}
                    for f in q.fields
                },
            }
            for q in sweep.quantities
        },
        "rt70_version": rt70.__version__,
        "key": sweep.key,
        "chunk": sweep.chunk,
        "chunks": {
            "total": len(chunks),
            "resumed": len(done),
            "computed": len(pending),
            "recomputed": len(store.recomputed) if store is not None else 0,
        },
        "workers": workers,
        "wall_time_s": time.perf_counter() - start,
        "errors": [e for c in chunks for e in errors[c.number]],
    }
    return SweepResult(arrays, metadata)


def _empty_arrays(sweep: Sweep) -> dict[str, np.ndarray]:
    """The axes (``elevation``, …, ``scale_NAME``) and each field, NaN, shaped by the grid."""
    shape = sweep.grid.shape
    arrays: dict[str, np.ndarray] = {axis_key(a.name): np.array(a.values) for a in sweep.grid.axes}
    for q in sweep.quantities:
        for f in q.fields:
            arrays[f.name] = np.full((*shape, *f.shape), np.nan)
    return arrays


def _place(arrays: dict[str, np.ndarray], chunk: Chunk, result: ChunkResult) -> list:
    """Copy a chunk's rows into the grid's arrays; its error records."""
    for name, rows in result.arrays.items():
        arrays[name][(slice(chunk.start, chunk.stop), *chunk.rest)] = rows
    return result.errors


def axis_key(name: str) -> str:
    """The NPZ key of an axis: its name, ``scale:NAME`` as ``scale_NAME``."""
    return name.replace(":", "_")


def sidecar(out: Path) -> Path:
    """The JSON sidecar of a sweep file: ``out`` with the suffix ``.json``."""
    return Path(out).with_suffix(".json")


def write(result: SweepResult, out: Path) -> list[Path]:
    """Write the NPZ file and its JSON sidecar together, atomically.

    Raises
    ------
    OSError or OutputError
        The file system refused a file: neither target changed, no temporary file left.
    """
    text = json.dumps(result.metadata, indent=2, allow_nan=False)
    return atomic_write_all(
        {
            out: lambda tmp: np.savez(tmp, **result.arrays),
            sidecar(out): lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"),
        }
    )
