"""Command-line options checked before any work: argparse types, the RT-70's pointing, outputs.

Every bad option ends the run at once with exit code 2 and one line on stderr,
``rt70: error: argument --rtol: ...`` — no usage block, no traceback — before a scene
is read or a simulation started. Output paths are probed (a temporary file is created
and removed in the directory that will receive them), so a read-only directory, a
directory where a file should go or a wrong suffix is refused up front. What surrounds
the run itself (exit codes, standard output, warnings, signals) is
:mod:`rt70.cli.session`.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import NoReturn

from rt70.cli.session import numerical_message
from rt70.errors import OutputError, Rt70Error
from rt70.model.sides import SIDES, check_side

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
    """What ``rt70 --version`` prints: ``rt70 X.Y.Z`` (:mod:`rt70._version`)."""
    from rt70._version import __version__

    return f"rt70 {__version__}"


class PrintVersion(argparse.Action):
    """``--version``: print :func:`version_line` and exit 0.

    The version is :mod:`rt70._version`'s, the one the package metadata is built from.
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
            f"(docs: 'What rt70 reads from a URDF file', docs/urdf-reader.md), got {text}"
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
    """An elevation in degrees, at most a quarter turn beyond the horizon or the zenith.

    The scene's own range (``<rt70:axis name="elevation" min_deg max_deg>``) is checked
    once the scene is read (:func:`rt70.model.antenna.pointing`).
    """
    from rt70.model.antenna import ELEVATION_SPAN_DEG

    value = _number(text)
    low, high = ELEVATION_SPAN_DEG
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(
            f"an elevation lies between {low:g} and {high:g} degrees, got {text}"
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


# --- the side of the cross-check ---------------------------------------------------------
def side(text: str) -> str:
    """A side of the cross-check, ``reference`` (Pinocchio) or ``textbook``."""
    try:
        return check_side(text)
    except Rt70Error as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


class RenamedBackend(argparse.Action):
    """``--backend``, now ``--side``: refused with the new spelling (one line, exit 2)."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs="?", help=argparse.SUPPRESS)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> NoReturn:
        """Refuse the option, naming ``--side`` and the value it takes now."""
        new = {"pinocchio": "reference", "textbook": "textbook"}.get(str(values).lower())
        use = f"'--side {new}'" if new else "'--side reference' or '--side textbook'"
        parser.error(f"--backend is now --side (reference = Pinocchio, textbook): use {use}")


def add_side_argument(
    parser: argparse.ArgumentParser, default: str = "reference", what: str = "the dynamics"
) -> None:
    """``--side {reference,textbook}``, and ``--backend`` refused with its new name.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    default : str
        The side when the option is not given.
    what : str
        What the side computes, for the help text.
    """
    parser.add_argument(
        "--side",
        type=side,
        choices=SIDES,
        default=default,
        help=f"the side that computes {what}: reference (Pinocchio) or textbook (the "
        f"book's matrix algorithm); default {default}",
    )
    parser.add_argument("--backend", action=RenamedBackend)


# --- the pointing of a scene's mount ----------------------------------------------------
def add_pointing_arguments(parser: argparse.ArgumentParser, default: str = "zenith") -> None:
    """``--elevation`` and ``--azimuth`` of a scene's mount (read by :func:`asked_pointing`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    default : str
        The default elevation as the help text names it ("zenith", "45").
    """
    parser.add_argument(
        "--elevation",
        type=elevation,
        help="elevation, degrees, within the range of the scene's <rt70:mount> elevation "
        f"axis (the RT-70: 0, horizon, to 90, zenith); default {default}",
    )
    parser.add_argument("--azimuth", type=angle_deg, help="azimuth, degrees (default 0)")


def asked_pointing(args: argparse.Namespace, scene, what: str) -> tuple[bool, float, float, dict]:
    """The pointing asked for: (has a mount, elevation, azimuth, held coordinates).

    Azimuth 0° and elevation 90° unless given — the zenith, or the end of the
    elevation axis's range nearest to it — held on the axes of the scene's
    ``<rt70:mount>`` (:func:`rt70.model.antenna.pointing`); a scene without a mount
    holds nothing.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options, with ``elevation`` and ``azimuth`` (degrees or None).
    scene : rt70.model.scene.Scene
        The scene the command runs on.
    what : str
        What the command computes, for the message of a scene that has no coordinate.

    Raises
    ------
    Rt70Error
        If the scene has no degree of freedom, or a pointing is given for a scene
        without a mount, or lies outside an axis's range.
    """
    from rt70.model.antenna import mount_of, pointing, range_deg

    names = scene.textbook.coordinate_names
    if not names:
        raise Rt70Error(f"{scene.name}: the model has no degree of freedom: no {what}")
    has_axes = scene.description.mount is not None
    if (args.elevation is not None or args.azimuth is not None) and not has_axes:
        mount_of(scene)  # one line naming the element
    azimuth = 0.0 if args.azimuth is None else args.azimuth
    if not has_axes:
        return False, 90.0 if args.elevation is None else args.elevation, azimuth, {}
    elevation = args.elevation
    if elevation is None:
        axis = mount_of(scene).axis("elevation")
        low, high = range_deg(axis)
        elevation = min(max(90.0, low), high)
    with option_at_fault(f"--elevation {elevation:g} --azimuth {azimuth:g}"):
        held = pointing(scene, elevation, azimuth)
    return True, elevation, azimuth, held


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
        if str(exc).startswith(f"{option}: "):  # the library named it already
            raise
        raise type(exc)(f"{option}: {exc}") from None
    except RuntimeWarning as exc:
        raise Rt70Error(f"{option}: {numerical_message(exc)}") from None


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
    from rt70.guards.arrays import finite_numbers

    if finite_numbers(value):  # a mode shape: checked at once
        return None
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
#: The files ``modes --plot`` writes: still figures, or an animation (``.gif``).
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".gif")


def check_outputs(args: argparse.Namespace) -> None:
    """Refuse output paths the command could not write, before it starts.

    ``simulate --out FILE`` (and the ``.png`` beside it unless ``--no-plot``),
    ``bench --out DIRECTORY``, ``plant --out FILE.npz|FILE.mat``, ``sweep --out FILE.npz``
    and ``modes --plot FILE`` (:data:`PLOT_SUFFIXES`).

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
    elif args.command == "modes" and args.plot is not None:
        out = Path(args.plot)
        if out.suffix.lower() not in PLOT_SUFFIXES or out.is_dir():
            raise OutputError(
                f"{out}: --plot must be a {', '.join(PLOT_SUFFIXES)} file (.gif: animated)"
            )
        check_writable_directory(out.parent)
    elif args.command == "plant" and args.out is not None:
        out = Path(args.out)
        if out.suffix not in (".npz", ".mat") or out.is_dir():
            raise OutputError(f"{out}: --out must be a .npz or .mat file")
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
