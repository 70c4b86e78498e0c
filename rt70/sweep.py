"""Parameter sweeps over a grid of pointings, winds and scene parameters, on Dask.

One job: compute registered quantities (:mod:`rt70.sweep_quantities`) at every point
of a Cartesian grid — elevation × azimuth × wind speed × wind direction × scene
parameter factors — in chunks, either in this process (:func:`serial`) or on a
``dask.distributed`` cluster (:func:`rt70.sweep_dask.on_dask`), and store them so an
interrupted sweep resumes (docs/sweeps.md):

- a **chunk** is a run of consecutive elevations at fixed values of the other axes
  (:meth:`Grid.chunks`); it is the unit of work and of resumption;
- each finished chunk is written atomically to ``FILE.partial/chunk-NNNNN.npz`` by the
  client as it arrives; ``FILE.partial/key.json`` holds the sweep's key, a hash of the
  scene file's content, the grid, the quantities and the chunk size. A rerun with the
  same key computes only the chunks not yet there; a different key is refused
  (:class:`SweepError`): nothing is mixed and nothing is deleted;
- at the end ``FILE`` (NPZ: the axes and one array per quantity field, shaped
  ``grid.shape + field.shape``) and ``FILE``'s JSON sidecar (metadata, per-point
  errors) are written together atomically and ``FILE.partial/`` is removed.

A point whose quantity raises :class:`~rt70.errors.Rt70Error` (no equilibrium, an
unstable mode, …) is stored as NaN and its message recorded; any other exception is a
bug and stops the sweep (finished chunks kept).
"""

from __future__ import annotations

import hashlib
import json
import math
import shutil
import time
from collections.abc import Callable, Generator, Iterable, Mapping, Sequence
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import rt70
from rt70.atomic import atomic_write, atomic_write_all
from rt70.errors import Rt70Error
from rt70.scene import Scene, scene_from_text, scene_path
from rt70.sweep_quantities import (
    PARAMETERS,
    QUANTITIES,
    Quantity,
    SweepPoint,
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

#: Version of the partial-results layout (part of the key).
FORMAT = 1


class SweepError(Rt70Error):
    """A sweep that cannot run as asked (bad grid, a foreign partial directory, no cluster)."""


# --- the grid ------------------------------------------------------------------------


def parse_values(text: str) -> tuple[float, ...]:
    """Values of an axis: ``A:B:N`` (N equally spaced, ends included), ``A,B,…`` or ``A``.

    Raises
    ------
    SweepError
        For anything else (``1:2``, N < 2 with A ≠ B, a non-finite number).
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
        An elevation outside 0…90°, a negative wind speed, an unknown axis or scene
        parameter, a factor ≤ 0, an empty or repeated axis.
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


#: Scenes built in this process: (sha256, scales) → Scene (a worker builds each once).
_SCENES: dict[tuple[str, tuple[tuple[str, float], ...]], Scene] = {}


def build_scene(source: SceneSource, scales: Mapping[str, float] | None = None) -> Scene:
    """The scene of ``source`` with the parameters scaled, built once per process."""
    scales = dict(scales or {})
    key = (source.sha256, tuple(sorted(scales.items())))
    if key not in _SCENES:
        if scales:
            base = build_scene(source)
            _SCENES[key] = scaled_scene(base, scales)
        else:
            _SCENES[key] = scene_from_text(source.text, source.name)
    return _SCENES[key]


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
    """Every quantity at every point of ``chunk`` (the task a Dask worker runs)."""
    n = chunk.stop - chunk.start
    arrays = {f.name: np.full((n, *f.shape), np.nan) for q in quantities for f in q.fields}
    errors = []
    for row, index in enumerate(chunk.indices()):
        point = grid.point(index)
        scene = build_scene(source, point.scales)
        for q in quantities:
            try:
                values = q.compute(scene, point)
            except (Rt70Error, np.linalg.LinAlgError) as exc:
                errors.append(
                    {"index": list(index), "point": point.as_dict(), "quantity": q.name}
                    | {"error": str(exc)}
                )
                continue
            for f in q.fields:
                arrays[f.name][row] = values[f.name]
    return ChunkResult(chunk.number, arrays, errors)


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
    """Read the scene and check the sweep can run, before any work.

    Raises
    ------
    Rt70Error
        A scene that does not load, has no RT-70 pointing axes or cannot give a
        quantity (:attr:`Quantity.check`); an unknown quantity; chunk < 1.
    """
    from rt70.scenes.rt70_state import missing_axes

    if chunk < 1:
        raise SweepError(f"--chunk must be at least 1, got {chunk}")
    unknown = [q for q in quantities if q not in QUANTITIES]
    if unknown or not quantities:
        known = ", ".join(sorted(QUANTITIES))
        raise SweepError(f"unknown quantity {', '.join(unknown) or '(none)'} (known: {known})")
    source = SceneSource.read(target)
    scene = build_scene(source)
    names = scene.textbook.coordinate_names
    missing = missing_axes(names)
    if missing:
        raise SweepError(f"{source.name}: no RT-70 pointing axis {', '.join(missing)} to sweep")
    chosen = tuple(QUANTITIES[q] for q in quantities)
    for q in chosen:
        if q.check is not None:
            q.check(scene)
    return Sweep(source, grid, chosen, chunk)


# --- where chunks are kept -------------------------------------------------------------


class PartialResults:
    """``FILE.partial/``: the finished chunks of one sweep, keyed by :attr:`Sweep.key`."""

    def __init__(self, out: Path, sweep: Sweep):
        self.directory = out.with_name(out.name + ".partial")
        self.sweep = sweep

    def check(self) -> None:
        """Refuse a directory that holds the chunks of a different sweep (nothing created).

        Raises
        ------
        SweepError
            If the directory exists and its key is not this sweep's (or is unreadable).
        """
        if not self.directory.exists() or not any(self.directory.iterdir()):
            return  # nothing there (or a directory left empty by a stop before its key)
        try:
            key = json.loads((self.directory / "key.json").read_text(encoding="utf-8"))["key"]
        except (OSError, ValueError, KeyError, TypeError):
            key = None
        if key != self.sweep.key:
            raise SweepError(
                f"{self.directory}: holds the unfinished results of a different sweep "
                "(scene file, grid, quantities or --chunk differ); remove it, or write to "
                "another --out"
            )

    def open(self) -> dict[int, ChunkResult]:
        """Create the directory, or check its key (:meth:`check`) and load its chunks."""
        self.check()
        key_file = self.directory / "key.json"
        if key_file.is_file():
            return self._load()
        self.directory.mkdir(parents=True, exist_ok=True)
        record = {"key": self.sweep.key, "scene": self.sweep.source.name}
        atomic_write(key_file, lambda tmp: tmp.write_text(json.dumps(record), encoding="utf-8"))
        return {}

    def _path(self, number: int) -> Path:
        return self.directory / f"chunk-{number:05d}.npz"

    def _load(self) -> dict[int, ChunkResult]:
        done = {}
        for chunk in self.sweep.chunks():
            path = self._path(chunk.number)
            if path.is_file():
                with np.load(path, allow_pickle=False) as data:
                    arrays = {k: data[k] for k in data.files if k != "errors"}
                    errors = json.loads(str(data["errors"]))
                done[chunk.number] = ChunkResult(chunk.number, arrays, errors)
        return done

    def save(self, result: ChunkResult) -> None:
        """Write one finished chunk atomically."""
        errors = np.array(json.dumps(result.errors))
        atomic_write(
            self._path(result.number),
            lambda tmp: np.savez(tmp, errors=errors, **result.arrays),
        )

    def remove(self) -> None:
        """Delete the directory (the sweep's files are written)."""
        shutil.rmtree(self.directory, ignore_errors=True)


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
        partial results ``out.partial/``. None: nothing is stored (no resume).
    workers : int
        Recorded in the metadata (0 for in-process).
    progress : bool
        A tqdm bar over the chunks on stderr.
    on_chunk : callable, optional
        Called with each chunk computed here (not the resumed ones) after it is saved.
    """
    from tqdm import tqdm

    start = time.perf_counter()
    chunks = sweep.chunks()
    store = PartialResults(Path(out), sweep) if out is not None else None
    done = store.open() if store is not None else {}
    pending = [c for c in chunks if c.number not in done]
    results = dict(done)
    with tqdm(
        total=len(chunks), initial=len(done), disable=not progress, unit="chunk", leave=False
    ) as bar:
        with closing(executor(sweep, pending)) as finished:  # closed at once on Ctrl-C
            for result in finished:
                if store is not None:
                    store.save(result)
                results[result.number] = result
                if on_chunk is not None:
                    on_chunk(result)
                bar.update(1)
    wall = time.perf_counter() - start
    assembled = _assemble(sweep, chunks, results)
    metadata = {
        "scene": {"name": sweep.source.name, "sha256": sweep.source.sha256},
        "grid": sweep.grid.as_dict(),
        "shape": list(sweep.grid.shape),
        "quantities": {
            q.name: {
                "description": q.description,
                "fields": {
                    f.name: {"shape": list(f.shape), "unit": f.unit, "description": f.description}
                    for f in q.fields
                },
            }
            for q in sweep.quantities
        },
        "rt70_version": rt70.__version__,
        "key": sweep.key,
        "chunk": sweep.chunk,
        "chunks": {"total": len(chunks), "resumed": len(done), "computed": len(pending)},
        "workers": workers,
        "wall_time_s": wall,
        "errors": [e for c in chunks for e in results[c.number].errors],
    }
    result = SweepResult(assembled, metadata)
    if out is not None:
        write(result, Path(out))
        store.remove()
    return result


def _assemble(sweep: Sweep, chunks: Iterable[Chunk], results: Mapping[int, ChunkResult]):
    """The axes (``elevation``, …, ``scale_NAME``) and each field shaped by the grid."""
    shape = sweep.grid.shape
    arrays: dict[str, np.ndarray] = {axis_key(a.name): np.array(a.values) for a in sweep.grid.axes}
    for q in sweep.quantities:
        for f in q.fields:
            arrays[f.name] = np.full((*shape, *f.shape), np.nan)
    for chunk in chunks:
        got = results[chunk.number]
        for name, rows in got.arrays.items():
            arrays[name][(slice(chunk.start, chunk.stop), *chunk.rest)] = rows
    return arrays


def axis_key(name: str) -> str:
    """The NPZ key of an axis: its name, ``scale:NAME`` as ``scale_NAME``."""
    return name.replace(":", "_")


def sidecar(out: Path) -> Path:
    """The JSON sidecar of a sweep file: ``out`` with the suffix ``.json``."""
    return Path(out).with_suffix(".json")


def write(result: SweepResult, out: Path) -> list[Path]:
    """Write the NPZ file and its JSON sidecar together, atomically."""
    text = json.dumps(result.metadata, indent=2, allow_nan=False)
    return atomic_write_all(
        {
            out: lambda tmp: np.savez(tmp, **result.arrays),
            sidecar(out): lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"),
        }
    )
