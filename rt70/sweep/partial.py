"""``FILE.partial/``: the finished chunks of a sweep, kept so that a rerun resumes.

Where a sweep's chunks wait for the end (docs/sweeps.md, "Resuming"): the output paths
checked before any work (:func:`check_output`), one directory per output file locked by
one process at a time (:class:`PartialResults`), each chunk written atomically with the
sweep's key and a checksum (:mod:`rt70.sweep.store`) and verified when it is read back
or comes back from a worker (:func:`check_result`): what cannot be trusted is recomputed.
"""

from __future__ import annotations

import json
import os
import shutil
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from rt70.errors import OutputError, Rt70Warning
from rt70.guards.atomic import atomic_write
from rt70.sweep import store as sweep_store
from rt70.sweep.errors import SweepError
from rt70.sweep.grid import Chunk
from rt70.sweep.plan import ChunkResult, Sweep


def sidecar(out: Path) -> Path:
    """The JSON sidecar of a sweep file: ``out`` with the suffix ``.json``."""
    return Path(out).with_suffix(".json")


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

        A chunk file that cannot be trusted (:func:`rt70.sweep.store.read_chunk`,
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
    value finite (NaN only where :attr:`~rt70.sweep.quantities.Field.nan` allows it).

    Parameters
    ----------
    sweep : Sweep
        The sweep the result must belong to (its quantities and their fields).
    chunk : Chunk
        The chunk the result claims to be: its points ``start … stop − 1``.
    result : ChunkResult
        What came back from a worker or was read back from a chunk file.

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
