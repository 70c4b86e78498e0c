"""Where a sweep keeps its finished chunks: the chunk files, their checks, the lock.

:class:`rt70.sweep.run.PartialResults` keeps a sweep's finished chunks in ``FILE.partial/``
(docs/sweeps.md, "Chunks, resume"); this module holds what it stands on:

- a **chunk file** ``chunk-NNNNN.npz`` is a ZIP archive (``numpy.load`` opens it) of
  ``meta.json`` — the layout version, the sweep's key, the chunk's number and place in
  the grid, and the SHA-256 of everything else (:func:`checksum`) — ``errors.json``
  (the chunk's failed points) and one ``FIELD.npy`` per quantity field (little-endian
  float64, one row per point): :func:`write_chunk`;
- :func:`read_chunk` reads one back and raises :class:`UntrustedChunk`, with the reason,
  for anything it cannot vouch for: not a ZIP of exactly those members; a member larger
  than the chunk can hold (checked before it is read, so a forged header cannot make
  it allocate); another layout, sweep or chunk; a field of the wrong shape or type; a
  checksum that does not match;
- :class:`DirectoryLock`: one writer per directory, an exclusive ``fcntl.flock`` on its
  ``lock`` file. The kernel releases it when the owning process ends, however it ends
  (SIGKILL included), so a lock is never stale; the file holds the owner's pid and host
  for the message a second writer gets.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import os
import socket
import threading
import zipfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rt70.errors import Rt70Error

#: Version of the chunk files' layout (written in each file's ``meta.json``).
CHUNK_FORMAT = 2

#: The dtype of every field array in a chunk file.
FIELD_DTYPE = np.dtype("<f8")

#: Largest ``meta.json`` read back, bytes (it holds a few numbers and two hashes).
MAX_META_BYTES = 4096

#: Largest ``errors.json`` read back per point of the chunk and quantity, bytes (an
#: error record is its point's values and one message: a few hundred bytes).
MAX_ERROR_BYTES_PER_POINT = 64 * 1024

#: Largest ``.npy`` header read back, bytes (numpy writes 128).
MAX_NPY_HEADER_BYTES = 4096


class UntrustedChunk(Exception):
    """A chunk file this sweep cannot use; ``str()`` is the reason (recomputed)."""


class LockedError(Rt70Error):
    """Another process holds a directory's lock (another sweep writes there)."""


# --- the chunk files ---------------------------------------------------------------------


def checksum(meta: Mapping[str, Any], errors_json: bytes, arrays: Mapping[str, np.ndarray]) -> str:
    """SHA-256 of a chunk's content: its ``meta`` (without ``sha256``), errors and fields.

    The fields enter by name (sorted), shape and little-endian float64 bytes, so the sum
    does not depend on the order of the ZIP members.

    Parameters
    ----------
    meta : mapping
        The chunk's ``meta.json`` record; a ``sha256`` entry in it is left out.
    errors_json : bytes
        The chunk's ``errors.json``, as written.
    arrays : mapping of str to ndarray
        The chunk's fields, ``(stop − start, *shape)`` each.

    Returns
    -------
    str
        The hexadecimal digest.
    """
    h = hashlib.sha256()
    fixed = {k: v for k, v in meta.items() if k != "sha256"}
    h.update(json.dumps(fixed, sort_keys=True).encode())
    h.update(b"\0errors\0" + errors_json)
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name], dtype=FIELD_DTYPE)
        h.update(f"\0{name}\0{list(a.shape)}\0".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def write_chunk(
    path: Path, meta: Mapping[str, Any], arrays: Mapping[str, np.ndarray], errors: list
) -> None:
    """Write a chunk file to ``path`` (a temporary file of :func:`rt70.guards.atomic.atomic_write`).

    Parameters
    ----------
    path : Path
        The file written (a ZIP of ``meta.json``, ``errors.json`` and one ``.npy`` per
        field, stored uncompressed).
    meta : mapping
        The sweep's ``key`` and the chunk's ``chunk`` number, ``rest``, ``start``,
        ``stop``; the layout version and the checksum are added.
    arrays : mapping of str to ndarray
        The chunk's fields, ``(stop − start, *shape)`` each, written as float64.
    errors : list of dict
        The chunk's error records (JSON, no NaN).
    """
    errors_json = json.dumps(errors, allow_nan=False).encode()
    record = {"format": CHUNK_FORMAT, **meta}
    record["sha256"] = checksum(record, errors_json, arrays)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as z:
        z.writestr("meta.json", json.dumps(record, sort_keys=True))
        z.writestr("errors.json", errors_json)
        for name, a in arrays.items():
            with z.open(f"{name}.npy", "w") as f:
                data = np.ascontiguousarray(a, dtype=FIELD_DTYPE)
                np.lib.format.write_array(f, data, allow_pickle=False)


def read_chunk(
    path: Path, meta: Mapping[str, Any], fields: Mapping[str, tuple[int, ...]]
) -> tuple[dict[str, np.ndarray], list]:
    """The fields and error records of the chunk file at ``path``, checked.

    Parameters
    ----------
    path : Path
        A regular file.
    meta : mapping
        What its ``meta.json`` must say besides the layout and the checksum: the
        sweep's ``key``, the chunk's ``chunk`` number, ``rest``, ``start``, ``stop``.
    fields : mapping of str to shape
        Every field the chunk must hold, with its shape per point.

    Returns
    -------
    arrays : dict of str to array
        ``arrays[field]`` shaped ``(stop − start, *shape)``.
    errors : list
        The decoded ``errors.json`` (its structure is the caller's to check).

    Raises
    ------
    UntrustedChunk
        Naming what is wrong.
    """
    rows = meta["stop"] - meta["start"]
    try:
        with zipfile.ZipFile(path) as z:
            members = {"meta.json", "errors.json"} | {f"{name}.npy" for name in fields}
            found = set(z.namelist())
            if found != members:
                odd = sorted(found ^ members)
                raise UntrustedChunk(f"not this sweep's fields ({', '.join(odd[:4])} differ)")
            record = json.loads(_member(z, "meta.json", MAX_META_BYTES))
            _check_meta(record, meta)
            limit = MAX_ERROR_BYTES_PER_POINT * max(rows, 1) * max(len(fields), 1)
            errors_json = _member(z, "errors.json", limit)
            errors = json.loads(errors_json)
            arrays = {name: _npy(z, name, (rows, *shape)) for name, shape in fields.items()}
    except UntrustedChunk:
        raise
    except Exception as exc:  # whatever a damaged or foreign file makes zipfile/json raise
        text = " ".join(str(exc).split())[:120]
        reason = f"unreadable ({type(exc).__name__}{': ' + text if text else ''})"
        raise UntrustedChunk(reason) from None
    if checksum(record, errors_json, arrays) != record.get("sha256"):
        raise UntrustedChunk("checksum mismatch (its content changed after it was written)")
    return arrays, errors


def _member(z: zipfile.ZipFile, name: str, limit: int) -> bytes:
    """A member's bytes, refused when the archive declares (or yields) more than ``limit``."""
    if z.getinfo(name).file_size > limit:
        raise UntrustedChunk(f"{name} larger than a chunk's ({z.getinfo(name).file_size} bytes)")
    with z.open(name) as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        raise UntrustedChunk(f"{name} larger than a chunk's")
    return data


def _check_meta(record: Any, expected: Mapping[str, Any]) -> None:
    if not isinstance(record, dict):
        raise UntrustedChunk("meta.json is not an object")
    if record.get("format") != CHUNK_FORMAT:
        raise UntrustedChunk(f"layout {record.get('format')!r}, not {CHUNK_FORMAT}")
    if record.get("key") != expected["key"]:
        raise UntrustedChunk("from another sweep (its key differs)")
    place = ("chunk", "rest", "start", "stop")
    if any(record.get(k) != expected[k] for k in place):
        got = {k: record.get(k) for k in place}
        raise UntrustedChunk(f"holds another chunk ({got})")


def _npy(z: zipfile.ZipFile, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """Field ``name``, checked to be ``shape`` of :data:`FIELD_DTYPE` before it is read."""
    member = f"{name}.npy"
    nbytes = int(np.prod(shape, dtype=np.int64)) * FIELD_DTYPE.itemsize
    if z.getinfo(member).file_size > nbytes + MAX_NPY_HEADER_BYTES:
        raise UntrustedChunk(f"{name} larger than the chunk's {shape}")
    with z.open(member) as f:
        version = np.lib.format.read_magic(f)
        readers = {
            (1, 0): np.lib.format.read_array_header_1_0,
            (2, 0): np.lib.format.read_array_header_2_0,
        }
        if version not in readers:
            raise UntrustedChunk(f"{name}: .npy version {version} not written by rt70")
        got, fortran, dtype = readers[version](f, max_header_size=MAX_NPY_HEADER_BYTES)
        if tuple(got) != shape or dtype != FIELD_DTYPE or fortran:
            raise UntrustedChunk(
                f"{name} is {tuple(got)} {dtype}{' (Fortran order)' if fortran else ''}, "
                f"not the chunk's {shape} float64"
            )
        data = f.read(nbytes + 1)
    if len(data) != nbytes:
        raise UntrustedChunk(f"{name}: {len(data)} bytes of data, not {nbytes} (truncated?)")
    return np.frombuffer(data, dtype=FIELD_DTYPE).reshape(shape).copy()


# --- the lock --------------------------------------------------------------------------


class DirectoryLock:
    """An exclusive lock on a directory: ``fcntl.flock`` on ``DIRECTORY/lock``.

    :meth:`acquire` creates the directory if need be and refuses at once
    (:class:`LockedError`, naming the owner's pid and host) when another process holds
    the lock: two sweeps never write one partial directory. Re-entrant within a process
    (counted). :meth:`release` removes the lock file, and the directory too if nothing
    else is left in it.

    The kernel drops a ``flock`` when the process that holds it ends, however it ends,
    so a lock left by a killed sweep is free at once. A file system without ``flock``
    (some network mounts) is refused: the lock could not be trusted there.
    """

    #: Locks this process holds: directory → [file descriptor, count].
    _held: dict[Path, list[int]] = {}
    _guard = threading.Lock()

    def __init__(self, directory: Path):
        self.directory = Path(directory)
        self.path = self.directory / "lock"

    def acquire(self) -> None:
        """Take the lock (or count one more use of it in this process).

        Raises
        ------
        LockedError
            Another process holds it.
        OSError
            The directory or its lock file cannot be created (the caller names them).
        """
        key = self.directory.resolve()
        with self._guard:
            if key in self._held:
                self._held[key][1] += 1
                return
            self._held[key] = [self._lock_file(), 1]

    def release(self) -> None:
        """Give the lock back; the last release removes the lock file (and an empty directory)."""
        key = self.directory.resolve()
        with self._guard:
            held = self._held.get(key)
            if held is None:
                return
            held[1] -= 1
            if held[1] > 0:
                return
            del self._held[key]
            try:
                self.path.unlink(missing_ok=True)  # while still locked: no one else owns it
                if self.directory.is_dir() and not any(self.directory.iterdir()):
                    self.directory.rmdir()
            except OSError:
                pass  # the lock file stays; the next sweep takes it (a lock is only a flock)
            finally:
                os.close(held[0])

    def _lock_file(self) -> int:
        """Open, lock and sign the lock file; its descriptor."""
        for _ in range(10):  # the previous owner may remove the file between open and lock
            self.directory.mkdir(parents=True, exist_ok=True)
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
            except FileNotFoundError:
                continue  # the directory was removed by its previous owner meanwhile
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                owner = _owner(fd)
                os.close(fd)
                if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise LockedError(
                        f"{self.directory}: another rt70 sweep ({owner}) is writing its "
                        "results here; wait for it to finish, or write to another --out"
                    ) from None
                raise LockedError(
                    f"{self.path}: cannot lock ({exc.strerror}); this file system does not "
                    "support file locks: write --out to a local disk"
                ) from None
            try:
                same = os.stat(self.path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                _sign(fd)
                return fd
            os.close(fd)
        raise LockedError(f"{self.path}: keeps being replaced; is another sweep starting here?")


def _sign(fd: int) -> None:
    """Write the owner (``pid N on HOST``) into the lock file (best effort: a full disk)."""
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()}\n".encode(), 0)
    except OSError:
        pass  # the lock holds without it; a second sweep's message says "owner unknown"


def _owner(fd: int) -> str:
    """What the lock file says of its owner (``pid N on HOST``)."""
    try:
        text = os.pread(fd, 200, 0).decode("utf-8", "replace").strip()
    except OSError:
        text = ""
    return text if text.startswith("pid ") else "owner unknown"


def is_regular_or_missing(path: Path) -> bool:
    """True if nothing is at ``path`` or a regular file (a symlink to one counts)."""
    return not os.path.lexists(path) or path.is_file()


def first(items: Sequence[str], n: int = 3) -> str:
    """The first ``n`` items, comma-separated, with ``…`` if there are more."""
    return ", ".join(items[:n]) + (", …" if len(items) > n else "")
