"""Atomic output files: written to a temporary file beside the target, then renamed.

A failure part-way leaves the previous file intact; nothing is half-written, and the
temporary file is removed — also when the process is asked to stop: the command line
turns SIGTERM into a normal exit (``SystemExit``), which runs the clean-up below.
:func:`atomic_write_all` writes a *set* of files (a trajectory and its plot) so that
they appear together: every temporary file is written first, then all are renamed with
SIGTERM and SIGINT held back, so a stop request either leaves every old file or
installs every new one. (SIGKILL or a power cut between two renames cannot be held
back; a rename that fails part-way — the disk fills up — is reported and leaves the
files renamed so far.)
"""

from __future__ import annotations

import os
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

#: Signals held back while a set of files is renamed (delivered right after).
DEFERRED_SIGNALS = (signal.SIGTERM, signal.SIGINT)


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary path in the target's directory, then rename it.

    The temporary file keeps the target's suffix (so writers that infer the format from
    the name, such as matplotlib, behave the same).
    """
    return atomic_write_all({Path(path): write})[0]


def atomic_write_all(writers: Mapping[str | Path, Callable[[Path], None]]) -> list[Path]:
    """Write several files so that they appear together; return their paths.

    Each ``write(tmp)`` fills a temporary file beside its target (suffix kept); only
    when all succeeded are they renamed, in order, with :data:`DEFERRED_SIGNALS` held
    back. On any exception (``SystemExit`` from SIGTERM included) every temporary file
    is removed and no target is touched.
    """
    pending: list[tuple[Path, Path]] = []
    try:
        for target, write in writers.items():
            path = Path(target)
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp_name = tempfile.mkstemp(
                dir=path.parent, prefix=f".{path.stem}.", suffix=path.suffix
            )
            os.close(fd)
            pending.append((Path(tmp_name), path))
            write(pending[-1][0])
            with open(pending[-1][0], "rb") as handle:  # on disk before it takes the name
                os.fsync(handle.fileno())
            os.chmod(pending[-1][0], 0o644)
        with signals_deferred():
            for tmp, path in pending:
                os.replace(tmp, path)
    finally:
        for tmp, _ in pending:
            tmp.unlink(missing_ok=True)
    return [path for _, path in pending]


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8", newline="\n"))


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
