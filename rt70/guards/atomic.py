"""Atomic output files: written to a temporary file beside the target, then renamed.

A failure part-way leaves the previous file intact; nothing is half-written, and the
temporary file is removed — also when the process is asked to stop: the command line
turns SIGTERM into a normal exit (``SystemExit``), which runs the clean-up below.
:func:`atomic_write_all` writes a *set* of files (a trajectory and its plot) so that
they appear together: every temporary file is written and flushed to disk first, then
all are renamed with SIGTERM and SIGINT held back, so a stop request either leaves every
old file or installs every new one. A file system that refuses part of the work — full
(``ENOSPC``), over quota (``EDQUOT``), read-only (``EROFS``), failing (``EIO``) — at the
creation of a temporary file, a write, the ``fsync`` or a rename ends in one
:class:`~rt70.errors.OutputError` naming the target (``<path>: cannot write (No space
left on device)``) with the previous files intact and no temporary file left: before a
set is renamed, each existing target is kept under a second name (a hard link, which
takes no data blocks), and a rename that fails part-way puts the renamed ones back.
(SIGKILL or a power cut between two renames cannot be held back.)
"""

from __future__ import annotations

import errno
import os
import secrets
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager, suppress
from pathlib import Path

from rt70.errors import OutputError

#: Signals held back while a set of files is renamed (delivered right after).
DEFERRED_SIGNALS = (signal.SIGTERM, signal.SIGINT)

#: ``os.link`` errors of a file system without hard links: the set is renamed without
#: keeping the old files (a failed rename then leaves the files renamed before it).
NO_HARD_LINKS = frozenset({errno.EPERM, errno.EXDEV, errno.EMLINK, errno.ENOTSUP, errno.ENOSYS})


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary path in the target's directory, then rename it.

    The temporary file keeps the target's suffix (so writers that infer the format from
    the name, such as matplotlib, behave the same).

    Raises
    ------
    OutputError
        The file system refused the file (full disk, quota, read-only, I/O error).
    """
    return atomic_write_all({Path(path): write})[0]


def atomic_write_all(writers: Mapping[str | Path, Callable[[Path], None]]) -> list[Path]:
    """Write several files so that they appear together; return their paths.

    Each ``write(tmp)`` fills a temporary file beside its target (suffix kept), which is
    then flushed to disk (``fsync``); only when all succeeded are they renamed, in order,
    with :data:`DEFERRED_SIGNALS` held back. On any exception (``SystemExit`` from
    SIGTERM included) every temporary file is removed, every directory this call created
    too, and no target is changed.

    Parameters
    ----------
    writers
        Target path → function that writes the file's content to the path it is given.

    Returns
    -------
    list of Path
        The targets, in the order given.

    Raises
    ------
    OutputError
        An ``OSError`` of the file system (creating, writing, syncing or renaming a
        file): ``<target>: cannot write (<reason>)``. Other exceptions of ``write``
        pass through unchanged.
    """
    pending: list[tuple[Path, Path]] = []
    created: list[Path] = []
    done = False
    try:
        for target, write in writers.items():
            path = Path(target)
            with cannot_write(path):
                created += _make_directories(path.parent)
                pending.append((_temporary_beside(path), path))
                write(pending[-1][0])
                _flush_to_disk(pending[-1][0])
        with signals_deferred():
            _rename_all(pending)
        done = True
    finally:
        for tmp, _ in pending:
            with suppress(OSError):
                tmp.unlink(missing_ok=True)
        if not done:
            for directory in reversed(created):
                with suppress(OSError):
                    directory.rmdir()
    return [path for _, path in pending]


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (:func:`atomic_write`)."""
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8", newline="\n"))


@contextmanager
def cannot_write(path: Path) -> Iterator[None]:
    """Turn an ``OSError`` inside the block into ``OutputError('<path>: cannot write (…)')``."""
    try:
        yield
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror or exc})") from exc


def _make_directories(directory: Path) -> list[Path]:
    """Create ``directory`` and its missing ancestors; return those created, outermost first."""
    missing = []
    while not directory.exists() and directory.parent != directory:
        missing.append(directory)
        directory = directory.parent
    for d in reversed(missing):
        d.mkdir(exist_ok=True)
    return missing[::-1]


def _temporary_beside(path: Path) -> Path:
    """An empty new file in ``path``'s directory, hidden, with ``path``'s suffix."""
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=path.suffix)
    os.close(fd)
    return Path(name)


def _flush_to_disk(tmp: Path) -> None:
    """``fsync`` the written file (on disk before it takes the name) and make it 0644."""
    with open(tmp, "rb") as handle:
        os.fsync(handle.fileno())
    os.chmod(tmp, 0o644)


def _rename_all(pending: list[tuple[Path, Path]]) -> None:
    """Rename each temporary file to its target; on a failure put the old targets back.

    A single file needs nothing kept: ``os.replace`` is atomic. For a set, each existing
    target is hard-linked to a hidden name first; if a rename fails, the targets renamed
    so far get their old file back (or are removed if they had none).
    """
    kept = _keep_old_files([path for _, path in pending]) if len(pending) > 1 else {}
    renamed: list[Path] = []
    try:
        for tmp, path in pending:
            with cannot_write(path):
                os.replace(tmp, path)
            renamed.append(path)
    except BaseException:
        _put_back(renamed, kept)
        raise
    finally:
        for old in kept.values():
            if old is not None:
                with suppress(OSError):
                    old.unlink(missing_ok=True)


def _keep_old_files(targets: list[Path]) -> dict[Path, Path | None]:
    """Hard-link each existing target to a hidden name beside it: target → that name.

    A target that does not exist maps to None; one whose file system has no hard links
    is left out (it cannot be put back).
    """
    kept: dict[Path, Path | None] = {}
    try:
        for path in targets:
            if not path.exists():
                kept[path] = None
                continue
            old = path.with_name(f".{path.name}.{secrets.token_hex(4)}.old")
            try:
                os.link(path, old, follow_symlinks=False)
            except OSError as exc:
                if exc.errno in NO_HARD_LINKS:
                    continue
                raise OutputError(f"{path}: cannot write ({exc.strerror or exc})") from exc
            kept[path] = old
    except BaseException:
        for old in kept.values():
            if old is not None:
                with suppress(OSError):
                    old.unlink()
        raise
    return kept


def _put_back(renamed: list[Path], kept: dict[Path, Path | None]) -> None:
    """Undo the renames of ``renamed``: the old file back where one was kept, else none.

    An old file that cannot be put back is dropped from ``kept``, so that it stays on
    disk under its hidden name rather than being removed with the others.
    """
    for path in reversed(renamed):
        if path not in kept:  # no hard link on this file system: the new file stays
            continue
        old = kept[path]
        try:
            if old is None:
                path.unlink()
            else:
                os.replace(old, path)
        except OSError:
            del kept[path]


@contextmanager
def signals_deferred(signals: tuple[int, ...] = DEFERRED_SIGNALS) -> Iterator[None]:
    """Hold back ``signals`` inside the block; each one received is re-raised after it.

    The Python-level handlers are swapped for one that only records the signal (the
    interpreter runs handlers in the main thread, whichever thread the kernel picked),
    and the original handlers get the recorded signals once the block is done. Outside
    the main thread, where handlers cannot be changed, the block runs unprotected.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    previous = {
        s: signal.signal(s, lambda signum, _frame: received.append(signum)) for s in signals
    }
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        for s in dict.fromkeys(received):
            signal.raise_signal(s)
