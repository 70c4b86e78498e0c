"""Command-line options checked before any work: argparse types, output paths, signals.

Every bad option ends the run at once with exit code 2 and one line on stderr,
``rt70: error: argument --rtol: ...`` — no usage block, no traceback — before a scene
is read or a simulation started. Output paths are probed (a temporary file is created
and removed in the directory that will receive them), so a read-only directory, a
directory where a file should go or a wrong suffix is refused up front.
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
import tempfile
import threading
import warnings
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import NoReturn

from rt70.errors import OutputError, Rt70Error, Rt70Warning
from rt70.guards import stop
from rt70.scenes.rt70_state import ELEVATION_RANGE

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


#: Largest magnitude of an azimuth or a wind direction on the command line, degrees: one
#: turn either way holds every direction; beyond it a float's spacing grows until the
#: angle means nothing (1e300° is no direction at all). ``rt70 sweep`` has the same bound.
MAX_TURN_DEG = 360.0

#: Smallest relative tolerance ``solve_ivp`` honours (100 machine epsilons).
MIN_RTOL = 100 * sys.float_info.epsilon

#: Largest magnitude of a physical number given as an option (a rate, a position): the
#: bound of every number rt70 reads from a model (``rt70.urdf.elements.MAX_MAGNITUDE``,
#: docs/urdf-reader.md): a product of ten such numbers stays below the largest double.
MAX_MAGNITUDE = 1e30

#: Largest mean wind speed, m/s: the wind load's model (constant coefficients, dynamic
#: pressure ½ρv², docs/wind.md) is that of incompressible flow, which holds below Mach 0.3
#: — 0.3 × 340.3 m/s, the speed of sound in the ISA sea-level air the default density is
#: of. (The strongest gust measured, 113 m/s at Barrow Island in 1996, is above it.)
MAX_WIND_SPEED = 0.3 * 340.3

#: Largest ``rt70 bench --K``: the batched mass matrices alone take ``K nv²`` floats
#: (1.4 GB for the RT-70 scene at this K).
MAX_BATCH = 100_000


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line, ``rt70: error: ...``, and exit 2."""

    def error(self, message: str) -> NoReturn:
        """Print ``message`` as one line (with where to find help) and exit 2."""
        command = self.prog.removeprefix("rt70").strip()
        hint = f"see 'rt70 {command} --help'" if command else "see 'rt70 --help'"
        print(f"rt70: error: {' '.join(message.split())} ({hint})", file=sys.stderr)
        sys.exit(2)


def version_line() -> str:
    """What ``rt70 --version`` prints: ``rt70 X.Y.Z``, the installed version (pyproject's)."""
    import rt70

    return f"rt70 {rt70.__version__}"


class PrintVersion(argparse.Action):
    """``--version``: print :func:`version_line` and exit 0.

    The version is read from the package metadata only when the option is given, so
    other commands do not pay for the lookup.
    """

    def __init__(
        self,
        option_strings: list[str],
        dest: str = argparse.SUPPRESS,
        default: str = argparse.SUPPRESS,
        help: str = "print 'rt70 X.Y.Z' (the installed version) and exit",
    ) -> None:
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> NoReturn:
        """Print the version line on standard output and exit 0."""
        print(version_line())
        parser.exit()


# --- argparse types: each raises ArgumentTypeError with the reason ---------------------
def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"'{text}' is not a finite number")
    return value


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not an integer") from None


def finite_float(text: str) -> float:
    """A finite number."""
    return _number(text)


def positive_float(text: str) -> float:
    """A finite number > 0."""
    value = _number(text)
    if not value > 0.0:
        raise argparse.ArgumentTypeError(f"must be greater than 0, got {text}")
    return value


def non_negative_float(text: str) -> float:
    """A finite number ≥ 0."""
    value = _number(text)
    if value < 0.0:
        raise argparse.ArgumentTypeError(f"must be at least 0, got {text}")
    return value


def physical_float(text: str) -> float:
    """A finite number of magnitude at most :data:`MAX_MAGNITUDE`."""
    value = _number(text)
    if abs(value) > MAX_MAGNITUDE:
        raise argparse.ArgumentTypeError(
            f"magnitude above {MAX_MAGNITUDE:g}, the largest number rt70 reads "
            f"(docs/urdf-reader.md), got {text}"
        )
    return value


def wind_speed(text: str) -> float:
    """A mean wind speed, m/s: ``0 < v ≤`` :data:`MAX_WIND_SPEED` (incompressible flow)."""
    value = positive_float(text)
    if value > MAX_WIND_SPEED:
        raise argparse.ArgumentTypeError(
            f"at most {MAX_WIND_SPEED:.0f} m/s, Mach 0.3: the wind load's model (½ρv², constant "
            f"coefficients) is that of incompressible flow, got {text}"
        )
    return value


def angle_error(text: str) -> float:
    """An angle off a programmed one, rad: ``|x| ≤ π`` (a heading is an angle modulo 2π)."""
    value = _number(text)
    if abs(value) > math.pi:
        raise argparse.ArgumentTypeError(
            f"must lie in [-π, π] (an angle off the programmed heading), got {text}"
        )
    return value


def rtol(text: str) -> float:
    """A relative tolerance of ``solve_ivp``: ``MIN_RTOL ≤ rtol < 1``."""
    value = _number(text)
    if not MIN_RTOL <= value < 1.0:
        raise argparse.ArgumentTypeError(
            f"must lie in [{MIN_RTOL:.3g}, 1) (scipy's solve_ivp raises smaller values to "
            f"100 machine epsilons), got {text}"
        )
    return value


def positive_int(text: str) -> int:
    """An integer ≥ 1."""
    value = _integer(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text}")
    return value


def seed(text: str) -> int:
    """A random seed: an integer ≥ 0 (numpy's generators take no negative seed)."""
    value = _integer(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be at least 0, got {text}")
    return value


def batch_size(text: str) -> int:
    """A batch size: 1 … :data:`MAX_BATCH`."""
    value = positive_int(text)
    if value > MAX_BATCH:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_BATCH}, got {text}")
    return value


def elevation(text: str) -> float:
    """An RT-70 elevation in degrees, within :data:`rt70.scenes.rt70_state.ELEVATION_RANGE`."""
    value = _number(text)
    low, high = ELEVATION_RANGE
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(
            f"the RT-70 points from {low:g}° (horizon) to {high:g}° (zenith), got {text}"
        )
    return value


def angle_deg(text: str) -> float:
    """An azimuth or a wind direction in degrees, within ±:data:`MAX_TURN_DEG`."""
    value = _number(text)
    if not abs(value) <= MAX_TURN_DEG:
        raise argparse.ArgumentTypeError(
            f"must lie in [-{MAX_TURN_DEG:g}, {MAX_TURN_DEG:g}] degrees (one turn either way "
            f"holds every direction), got {text}"
        )
    return value


# --- values checked where they are used ------------------------------------------------
@contextmanager
def option_at_fault(option: str) -> Iterator[None]:
    """Name the command-line option behind a value the library refuses inside the block.

    Some values can only be judged once the model is built (``plant --reduce`` against
    the plant's order, ``impact --brake`` against the scene's joints). The library's
    message knows no options; the command line passes the value in inside this block,
    and an :class:`~rt70.errors.Rt70Error` comes out as the same class with
    ``"<option>: "`` in front: ``--reduce 10000: order must be between 3 and 84 …``.

    Parameters
    ----------
    option
        The option and its value as the user wrote them (``"--reduce 10000"``), with the
        scene in front where the limit is the scene's (``"rt70: --reduce 10000"``).

    A floating-point failure inside the block (a ``RuntimeWarning`` raised, as the
    command line raises them: :func:`warning_guards`) becomes an
    :class:`~rt70.errors.Rt70Error` naming the option the same way.
    """
    try:
        yield
    except Rt70Error as exc:
        raise type(exc)(f"{option}: {exc}") from None
    except RuntimeWarning as exc:
        raise Rt70Error(f"{option}: {_numerical(exc)}") from None


# --- results ---------------------------------------------------------------------------
def check_finite(result: object, what: str) -> None:
    """Refuse a result (nested dicts, lists, numbers) holding a NaN or an infinity.

    A command calls this on what it is about to print or write, so that NaN never
    reaches an output without an error; a value that may be absent is None, not NaN.

    Raises
    ------
    Rt70Error
        Naming ``what`` and the key path of the first bad value.
    """
    path = _non_finite(result, "")
    if path is not None:
        raise Rt70Error(f"{what}: {path or 'the result'} is NaN or infinite: nothing to report")


def json_text(result: object, what: str) -> str:
    """``json.dumps(result, indent=2)`` after :func:`check_finite` (no ``NaN`` in JSON)."""
    import json

    check_finite(result, what)
    return json.dumps(result, indent=2)


def _non_finite(value: object, path: str) -> str | None:
    """The key path of the first NaN or infinity in ``value``, or None."""
    if isinstance(value, dict):
        items = ((f"{path}.{k}" if path else str(k), v) for k, v in value.items())
    elif isinstance(value, list | tuple):
        items = ((f"{path}[{i}]", v) for i, v in enumerate(value))
    elif isinstance(value, float):
        return None if math.isfinite(value) else path
    else:
        items = ()
        if hasattr(value, "dtype") and getattr(value.dtype, "kind", "") in "fc":
            import numpy as np

            return None if np.isfinite(value).all() else path
    for key, item in items:
        bad = _non_finite(item, key)
        if bad is not None:
            return bad
    return None


# --- output paths ------------------------------------------------------------------------
def check_outputs(args: argparse.Namespace) -> None:
    """Refuse output paths the command could not write, before it starts.

    ``simulate --out FILE`` (and the ``.png`` beside it unless ``--no-plot``),
    ``bench --out DIRECTORY``, ``plant --out FILE.npz`` and ``sweep --out FILE.npz``.

    Raises
    ------
    OutputError
        Naming the path and the reason.
    """
    if args.command == "simulate" and args.out == "":
        raise OutputError("--out: empty path")
    if args.command == "simulate" and args.out:
        from rt70.simulation.result import check_output_suffix

        out = Path(args.out)
        files = [out] if args.no_plot else [out, out.with_suffix(".png")]
        for path in files:
            if path.is_dir():
                raise OutputError(f"{path}: is a directory, not a file")
        check_output_suffix(out)
        check_writable_directory(out.parent)
    elif args.command == "bench":
        check_writable_directory(Path(args.out))
    elif args.command == "sweep":
        out = Path(args.out)
        if out.suffix != ".npz" or out.is_dir():
            raise OutputError(f"{out}: --out must be a .npz file")
        check_writable_directory(out.parent)
    elif args.command == "plant" and args.out is not None:
        out = Path(args.out)
        if out.suffix != ".npz" or out.is_dir():
            raise OutputError(f"{out}: --out must be a .npz file")
        check_writable_directory(out.parent)


def check_writable_directory(directory: Path) -> None:
    """Refuse a directory that cannot receive new files (or cannot be created).

    The nearest existing ancestor is probed by creating and removing a temporary file
    in it, so the answer is the file system's (read-only mounts, permissions, quotas).
    """
    probe = directory
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        raise OutputError(f"{directory}: '{probe}' is not a directory")
    try:
        fd, name = tempfile.mkstemp(dir=probe, prefix=".rt70-probe.")
    except OSError as exc:
        raise OutputError(
            f"{directory}: cannot create files in '{probe}' ({exc.strerror})"
        ) from None
    os.close(fd)
    os.unlink(name)


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

    return f"rt70 {shlex.join(argv)}: {_numerical(exc)}"


def _numerical(exc: RuntimeWarning) -> str:
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
    nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(signum: int, _frame: object) -> NoReturn:
        stop.request(lambda: SystemExit(code))

    def interrupt(signum: int, _frame: object) -> NoReturn:
        stop.request(KeyboardInterrupt)

    previous = {
        signal.SIGTERM: signal.signal(signal.SIGTERM, terminate),
        signal.SIGINT: signal.signal(signal.SIGINT, interrupt),
    }
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        stop.clear()
