"""Resource guards: refuse a model this machine cannot hold *before* building it.

Two limits were measured (``python validation/resource_limits.py`` reproduces them):

Memory
    Pinocchio 4.1's ``Data`` holds four ``nv × nv × nv`` tensors (the second-order
    RNEA derivatives ``d2tau_dqdq`` …, allocated and zeroed whether used or not), so a
    :class:`~rt70.reference.ReferenceModel` with its
    :class:`~rt70.reference.ReferenceData` — two ``Data`` objects, and a third,
    transient one while the second is created (the measured peak is 1.5 times the
    final size: a copy on the way to Python) — peaks at about
    ``96 nv³`` bytes: 2.7 GB at nv = 300, about 100 GB at nv = 1000. The textbook side's
    dense ``Data`` (L and Θ are ``6 nb × 6 nb``; the dense algorithms add Φ⁰, Ṡ and
    products of the same size) peaks at ``O(nb²)``: about 0.4 GB at nb = 600 (27 GB at
    nb = 5000, extrapolated). :func:`reference_peak_bytes` and
    :func:`textbook_peak_bytes` are fits of measured peaks (growth of the anonymous
    resident set in a fresh process), rounded up; a model is refused when its estimate
    exceeds :data:`MEMORY_FRACTION` of ``MemAvailable``.
Parser depth
    Pinocchio's URDF parser recurses once per level of the kinematic tree, about
    2.2 KiB of stack per level: with the usual 8 MiB stack it segfaults at a depth of
    about 3770 links (any joint type; a wide tree is harmless). It is therefore run in a
    thread with a :data:`PARSER_STACK_BYTES` stack (256 MiB: room for about 120 000
    levels; a chain of 40 000 fixed joints parses on 128 MiB, and segfaults on 64 MiB)
    and a tree deeper than :data:`PARSER_MAX_DEPTH` is refused before the parser sees it.
The textbook's mass check
    Building the textbook model checks that every coordinate moves mass
    (:mod:`rt70.textbook.massless`) with the structured mass matrix: its ancestor matrix
    (``nb × nb``) and about eight ``n × n`` arrays (the coordinates' weights, A, its
    scaled form, the Cholesky factor, and the eigenvectors when A is singular) —
    :func:`massless_peak_bytes`. A 20 000-link revolute chain would need 35 GB; it is
    refused before the check starts (:func:`check_massless`).

Time series
    A simulation keeps every sample of its state (the solver's rows), then the result's
    arrays built from them (q, q̇, the energies, the extra states, the outputs) and
    products formed from those: :func:`time_series_bytes` counts
    :data:`TIME_SERIES_COPIES` float64 copies of ``samples × channels``, and
    :func:`check_time_series` refuses a run (a duration, a print step, a sampling rate)
    whose samples would exceed :data:`MEMORY_FRACTION` of ``MemAvailable`` — before the
    run, where the number of samples is known (output times given), or as the most
    samples a run may take where it is not (one per step: :func:`time_series_samples`).

Nothing here imports Pinocchio.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from rt70.errors import ResourceError

#: Share of ``MemAvailable`` a model may take: the rest is margin for the fits' error,
#: the other side of the cross-check, the integrator's arrays and other processes.
MEMORY_FRACTION = 0.5

#: Stack of the thread that runs Pinocchio's URDF parser (virtual; only the pages the
#: recursion touches become resident: about 45 MB for 20 000 levels).
PARSER_STACK_BYTES = 256 * 2**20

#: Deepest kinematic tree (links from the root, the root included) handed to the
#: parser: a third of what the measured 2.2 KiB per level allows on its stack.
PARSER_MAX_DEPTH = 40_000

_MEMINFO = Path("/proc/meminfo")

#: Float64 copies of a run's time series held at its peak (the solver's rows, the
#: result's arrays, the products formed from them; module docstring).
TIME_SERIES_COPIES = 4

T = TypeVar("T")


def available_memory() -> int | None:
    """``MemAvailable`` of ``/proc/meminfo`` in bytes, or None where it is unknown."""
    try:
        for line in _MEMINFO.read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def reference_peak_bytes(nv: int, njoints: int) -> int:
    """Peak memory of a :class:`~rt70.reference.ReferenceModel` and its ``ReferenceData``, bytes.

    Three ``Data`` (two kept, one transient) of four ``nv³`` float64 tensors each are
    ``96 nv³``; a least-squares fit of the measured peaks (nv = 100 … 350) gives
    ``98.5 nv³ − 45 nv² + 11 MB``. The estimate rounds the cubic term up to ``100 nv³``
    and adds the ``nv²`` matrices (about 40 per ``Data``), ``6 nv`` per joint
    (``Fcrb``) and a constant for Pinocchio's model: it lies 5–28 % above the measured
    peaks of chains of revolute, planar and floating joints with nv = 50 … 350 (twice
    the peak at nv = 25, where the allocator's granularity dominates).
    """
    return 100 * nv**3 + 1000 * nv**2 + 150 * nv * njoints + 4_000_000


def textbook_peak_bytes(nb: int, n_full: int) -> int:
    """Peak memory of the dense textbook algorithms on a fresh :class:`Data`, bytes.

    ``8 (144 nb² + 24 nb n + 4 n²)``: four arrays the size of L or Θ (6 nb × 6 nb), four
    the size of S (n × 6 nb) and four of A (n × n). It lies 17–44 % above the measured
    peaks of every dense function of :mod:`rt70.textbook` on chains of revolute
    (nb = 100 … 800) and floating joints.
    """
    return 8 * (144 * nb**2 + 24 * nb * n_full + 4 * n_full**2)


def massless_peak_bytes(nb: int, n_full: int) -> int:
    """Peak memory of the textbook's check that every coordinate moves mass, bytes.

    ``8 (nb² + 10 n²)``: the ancestor matrix and ten ``n × n`` arrays of the structured
    mass matrix, its factor and (when A is singular) ``eigh``. It lies 28–64 % above the
    measured peaks of :func:`rt70.textbook.massless.check_moves_mass` on chains of
    revolute (n = 500 … 3000), planar and floating joints, and on a chain whose last two
    coaxial joints move no mass (the ``eigh`` path; ``validation/resource_limits.py``).
    """
    return 8 * (nb**2 + 10 * n_full**2)


def check_memory(needed: int, what: str, source: str, available: int | None = None) -> None:
    """Raise :class:`ResourceError` if ``needed`` bytes exceed the share this run may use.

    The share is :data:`MEMORY_FRACTION` of the available memory.

    Parameters
    ----------
    needed : int
        The estimated peak memory, bytes.
    what : str
        What needs it, for the message.
    source : str
        The file, option or call that asked for it, for the message.
    available : int, optional
        The available memory, bytes; default :func:`available_memory` (where that is
        unknown nothing is checked).
    """
    available = available_memory() if available is None else available
    if available is None:
        return
    budget = MEMORY_FRACTION * available
    if needed > budget:
        raise ResourceError(
            f"{source}: {what} would need about {_gb(needed)} of memory; this run may use "
            f"{_gb(budget)} ({MEMORY_FRACTION:.0%} of the {_gb(available)} available)"
        )


def time_series_bytes(samples: float, channels: int) -> float:
    """Peak memory of ``samples`` samples of ``channels`` float64 values, bytes.

    ``8 · samples · channels · TIME_SERIES_COPIES``; ``samples`` may be a float (a
    duration over a step, before it is rounded), so a huge request does not overflow.
    """
    return 8.0 * float(samples) * channels * TIME_SERIES_COPIES


def time_series_samples(channels: int, available: int | None = None) -> int | None:
    """Most samples of ``channels`` values this run may keep (None where memory is unknown)."""
    available = available_memory() if available is None else available
    if available is None:
        return None
    return max(int(MEMORY_FRACTION * available / time_series_bytes(1, channels)), 1)


def check_time_series(
    samples: float, channels: int, what: str, source: str, available: int | None = None
) -> None:
    """Refuse a run whose ``samples × channels`` time series this machine cannot hold.

    Parameters
    ----------
    samples : float
        The number of samples (a float: a duration over a step, before rounding).
    channels : int
        Values kept per sample.
    what : str
        What the samples are, for the message.
    source : str
        The option or the call that asked for them (``--t-end 1e+12``).
    available : int, optional
        The available memory, bytes, as :func:`check_memory`.

    Raises
    ------
    ResourceError
        Naming ``source``, the samples and the memory.
    """
    check_memory(
        time_series_bytes(samples, channels),
        f"{what} ({float(samples):.3g} samples of {channels} values)",
        source,
        available,
    )


def check_textbook(nb: int, n_full: int, source: str) -> None:
    """Refuse a textbook model whose dense matrices this machine cannot hold.

    Parameters
    ----------
    nb : int
        Number of bodies.
    n_full : int
        Number of coordinates before the constraints are eliminated.
    source : str
        The file the model is read from, for the message.
    """
    check_memory(
        textbook_peak_bytes(nb, n_full),
        f"the textbook side's dense matrices for {nb} bodies ({6 * nb} × {6 * nb})",
        source,
    )


def check_massless(nb: int, n_full: int, source: str) -> None:
    """Refuse a textbook model whose mass check (:func:`massless_peak_bytes`) cannot fit.

    Parameters
    ----------
    nb : int
        Number of bodies.
    n_full : int
        Number of coordinates before the constraints are eliminated.
    source : str
        The file the model is read from, for the message.
    """
    check_memory(
        massless_peak_bytes(nb, n_full),
        f"the textbook side's check that every coordinate moves mass ({n_full} × {n_full} "
        f"mass matrix and its factor, {nb} bodies)",
        source,
    )


def run_with_stack(fn: Callable[[], T], stack_bytes: int = PARSER_STACK_BYTES) -> T:
    """Call ``fn()`` in a thread with a ``stack_bytes`` stack; return or raise its outcome."""
    outcome: list = []

    def target() -> None:
        try:
            outcome.append((True, fn()))
        except BaseException as exc:  # re-raised in the caller's thread below
            outcome.append((False, exc))

    previous = threading.stack_size(stack_bytes)
    try:
        thread = threading.Thread(target=target, name="rt70-pinocchio-parser")
        thread.start()
    finally:
        threading.stack_size(previous)
    thread.join()
    ok, value = outcome[0]
    if not ok:
        raise value
    return value


def _gb(n: float) -> str:
    return f"{n / 1e9:.3g} GB"
