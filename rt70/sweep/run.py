"""Parameter sweeps over a grid of pointings, winds and scene parameters, on Dask.

One job: compute registered quantities (:mod:`rt70.sweep.quantities`) at every point
of a Cartesian grid — elevation × azimuth × wind speed × wind direction × scene
parameter factors — in chunks, either in this process (:func:`serial`) or on a
``dask.distributed`` cluster (:func:`rt70.sweep.cluster.on_dask`), and store them so an
interrupted sweep resumes (docs/sweeps.md):

- the grid, the quantities and the memory the sweep will hold are checked before any
  work (:func:`plan`, :func:`check_size`); so are the output paths (:func:`check_output`);
- a **chunk** is a run of consecutive elevations at fixed values of the other axes
  (:meth:`Grid.chunks`); it is the unit of work and of resumption;
- each finished chunk is written atomically to ``FILE.partial/chunk-NNNNN.npz`` by the
  client as it arrives, with the sweep's key and a checksum (:mod:`rt70.sweep.store`);
  ``FILE.partial/key.json`` holds the sweep's key, a hash of the scene file's content,
  the grid, the quantities and the chunk size. A rerun with the same key verifies the
  chunks there, keeps those it can trust and computes the others (saying how many and
  why); a different key is refused (:class:`SweepError`): nothing is mixed and nothing
  is deleted. One process at a time writes a partial directory (a lock, :class:`
  rt70.sweep.store.DirectoryLock`);
- at the end ``FILE`` (NPZ: the axes and one array per quantity field, shaped
  ``grid.shape + field.shape``) and ``FILE``'s JSON sidecar (metadata, per-point
  errors) are written together atomically and ``FILE.partial/`` is removed.

A point whose quantity raises :class:`~rt70.errors.Rt70Error` (no equilibrium, an
unstable mode, …) or returns a value that is not finite is stored as NaN and its
message recorded: a NaN in the output always has its error record (a field may
declare a NaN that means something else, :attr:`rt70.sweep.quantities.Field.nan`).
Any other exception is a bug and stops the sweep (finished chunks kept).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Generator
from contextlib import closing, nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import rt70
from rt70.errors import OutputError
from rt70.guards.atomic import atomic_write_all
from rt70.sweep.errors import ClusterError, SweepError
from rt70.sweep.grid import AXES, Axis, Chunk, Grid, make_grid, parse_values
from rt70.sweep.partial import PartialResults, _cannot_write, check_output, check_result, sidecar
from rt70.sweep.plan import (
    DEFAULT_CHUNK,
    DEFAULT_QUANTITIES,
    SCENES_KEPT,
    ChunkResult,
    SceneSource,
    Sweep,
    build_scene,
    check_size,
    compute_chunk,
    option_name,
    peak_bytes,
    plan,
)

__all__ = [
    "AXES",
    "DEFAULT_CHUNK",
    "DEFAULT_QUANTITIES",
    "SCENES_KEPT",
    "Axis",
    "Chunk",
    "ChunkResult",
    "ClusterError",
    "Executor",
    "Grid",
    "PartialResults",
    "SceneSource",
    "Sweep",
    "SweepError",
    "SweepResult",
    "axis_key",
    "build_scene",
    "check_output",
    "check_result",
    "check_size",
    "compute_chunk",
    "make_grid",
    "option_name",
    "parse_values",
    "peak_bytes",
    "plan",
    "run",
    "serial",
    "sidecar",
    "write",
]


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
        :func:`serial` or :func:`rt70.sweep.cluster.on_dask` of a client.
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
        Another process writes ``out.partial/`` (:class:`rt70.sweep.store.DirectoryLock`).
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
