"""What surrounds a command's run: exit codes, standard output, warnings and signals.

The command line (:func:`rt70.cli.main.main`) runs every command inside these guards:
a failed write to standard output is one :class:`~rt70.errors.OutputError`
(:func:`checked_stdout`); numpy's and scipy's floating-point warnings are raised and
printed as one error line, rt70's own warnings as one ``rt70: warning:`` line each, and
the integrations run under an evaluation budget (:func:`warning_guards`); SIGTERM and
Ctrl-C end the run with the exit codes of :data:`EXIT_CODES`, removing temporary output
files on the way (:func:`stop_signals`).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import warnings
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from typing import NoReturn

from rt70.errors import OutputError, Rt70Warning
from rt70.guards import stop

#: Exit status on SIGTERM, Ctrl-C and a closed standard output (128 + signal number).
EXIT_TERMINATED = 128 + signal.SIGTERM
EXIT_INTERRUPTED = 128 + signal.SIGINT
EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE

#: What each exit code of the command line means (the epilog of ``rt70 --help``).
EXIT_CODES = {
    0: "success",
    1: "a check disagreed (validate), a robot failed unexpectedly (a bug in rt70), or "
    "simulate's integration stopped before the end time",
    2: "bad input: one line 'rt70: error: ...' naming the option or the file",
    int(EXIT_INTERRUPTED): "interrupted (Ctrl-C)",
    int(EXIT_BROKEN_PIPE): "standard output closed early ('rt70 ... | head')",
    int(EXIT_TERMINATED): "stopped by SIGTERM (temporary files removed)",
}


# --- standard output ----------------------------------------------------------------------
class _CheckedOutput:
    """Standard output whose write errors are one :class:`OutputError` (a closed pipe aside).

    ``rt70 ... > file`` on a full disk fails inside ``print``; the error names standard
    output, and what is still buffered goes to ``os.devnull`` so that the interpreter's
    last flush at exit does not fail a second time.
    """

    def __init__(self, stream) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        with self._errors():
            return self._stream.write(text)

    def flush(self) -> None:
        with self._errors():
            self._stream.flush()

    def __getattr__(self, name: str):
        return getattr(self._stream, name)

    @contextmanager
    def _errors(self) -> Iterator[None]:
        try:
            yield
        except BrokenPipeError:  # the reader went away: the command line's exit 141
            raise
        except OSError as exc:
            with suppress(OSError, ValueError):  # no file descriptor (a StringIO): nothing to do
                _point_at_devnull(self._stream.fileno())
            raise OutputError(f"standard output: cannot write ({exc.strerror or exc})") from None


def _point_at_devnull(fd: int) -> None:
    """Make file descriptor ``fd`` write to ``os.devnull``."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
    finally:
        os.close(devnull)


@contextmanager
def checked_stdout() -> Iterator[None]:
    """Inside the block, a failed write to standard output raises :class:`OutputError`."""
    stream = sys.stdout
    sys.stdout = _CheckedOutput(stream)
    try:
        yield
    finally:
        sys.stdout = stream


# --- numerical trouble -------------------------------------------------------------------
#: Commands run without an :class:`~rt70.simulation.integrators.EvaluationBudget`: ``bench``
#: measures methods at any cost by design, ``sweep`` keeps its own limits.
UNBUDGETED = ("bench", "sweep")


@contextmanager
def warning_guards(command: str) -> Iterator[None]:
    """Warnings as the command line treats them, and the integrations' budget.

    Enter it inside ``warnings.catch_warnings()`` (rt70/cli/main.py's docstring): an
    :class:`~rt70.errors.Rt70Warning` is printed each time as one ``rt70: warning:``
    line; numpy's floating-point warnings and scipy's ``LinAlgWarning`` (every
    ``RuntimeWarning``) become exceptions that the command line prints as its one error
    line (:func:`numerical_failure`); every integration of ``command`` but those of
    :data:`UNBUDGETED` runs under :func:`rt70.simulation.integrators.evaluation_budget`.
    """
    from contextlib import nullcontext

    from rt70.simulation.integrators import evaluation_budget

    warnings.simplefilter("error", RuntimeWarning)
    warnings.simplefilter("always", Rt70Warning)
    warnings.showwarning = _show_warning
    with nullcontext() if command in UNBUDGETED else evaluation_budget():
        yield


_default_showwarning = warnings.showwarning


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Print an :class:`~rt70.errors.Rt70Warning` as one ``rt70: warning:`` line on stderr."""
    if issubclass(category, Rt70Warning):
        print(f"rt70: warning: {message}", file=sys.stderr)
    else:
        _default_showwarning(message, category, filename, lineno, file, line)


def numerical_failure(argv: list[str], exc: RuntimeWarning) -> str:
    """The error line of a RuntimeWarning that reached the command line.

    No check named the value at fault, so the line names what the user gave: the
    command as typed (its scene file and options, ``argv``) and the failure.
    """
    import shlex

    return f"rt70 {shlex.join(argv)}: {numerical_message(exc)}"


def numerical_message(exc: RuntimeWarning) -> str:
    """``numerical failure (<warning>): ...``: what a floating-point failure says."""
    what = " ".join(str(exc).split())
    return (
        f"numerical failure ({type(exc).__name__}: {what}): an input is beyond what the "
        "computation can represent; check the magnitudes of these options and of the model"
    )


# --- signals -----------------------------------------------------------------------------
@contextmanager
def stop_signals(code: int) -> Iterator[None]:
    """Inside the block SIGTERM raises ``SystemExit(code)`` and SIGINT ``KeyboardInterrupt``.

    ``finally`` blocks run, so temporary output files are removed
    (:mod:`rt70.guards.atomic`). Each stop is recorded as well
    (:func:`rt70.guards.stop.request`), so one raised where it gets lost is raised again
    at the integrators' next right-hand side (:func:`rt70.guards.stop.check`). The previous
    handlers are restored afterwards and the record cleared; outside the main thread
    nothing changes. A SIGINT the process was started ignoring (a job started in the
    background, ``nohup``) stays ignored, as Python itself leaves it.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(signum: int, _frame: object) -> NoReturn:
        stop.request(lambda: SystemExit(code))

    def interrupt(signum: int, _frame: object) -> NoReturn:
        stop.request(KeyboardInterrupt)

    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, terminate)}
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # a background job's stays
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, interrupt)
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        stop.clear()
