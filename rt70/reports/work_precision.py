"""Work–precision report of the integrators of :func:`rt70.simulation.simulate.simulate`.

For each test problem and each ``solve_ivp`` method the run is repeated over a ladder
of relative tolerances; every run gives one point (run time, error) of the method's
work–precision curve.

The problems (the RT-70's 10 s transient of the speed targets, the RT-70 over 2 s with the
listing's and with light damping, a double pendulum, a 50-body chain) are built in
:mod:`rt70.reports.work_precision_problems`; the runs
happen in a worker process (:mod:`rt70.reports.work_precision_worker`).

Accuracy
--------
The state is ``x = (q, q̇)`` (the energy-audit states are left out). On the output grid
``t_eval`` (``N_EVAL`` points over the span, the same for every run),
``error = max_t ‖x(t) − x_ref(t)‖∞ / max_t ‖x_ref(t)‖∞``.
The reference is computed at ``rtol = 1e-12`` by a *different* method than the one
measured: each problem has a primary and an alternate reference method
(``Problem.references``); rows of the primary method are measured against the
alternate one. The two references are compared with each other by the same formula:
that is the floor of the measurement (``reference_floor``), below which errors mean
nothing.

Beside it, the engineering metric of the speed targets: the largest error over time and bodies
of the bodies' centres of mass, ``com_error = max_t max_b |c_b(t) − c_b,ref(t)|`` in
metres (world frame, every Pinocchio joint body with mass, computed on the reference
side by :func:`rt70.reports.work_precision_worker.com_positions`), against the same
reference on the same grid; ``com_floor`` is the references' agreement in it. The
pointing error in arc seconds needs the main mirror's optical output, which the servo
scene (``rt70_servo``) has and the free-axes RT-70 of these problems does not; it is
left out here.

The non-stiff problems use DOP853 (alternate LSODA) with the default
``atol``; the RT-70 problems use Radau (alternate BDF) with ``atol = 1e-12`` — the
default ``atol = 1e-3·rtol = 1e-15`` is below the rounding level of the stiff forces
and makes BDF take 186 s instead of 3 s for the same result to 5e-10.

Time and the cap
----------------
Time is the best of ``REPEATS`` (3) values of ``SimulationResult.wall_time_s`` (the
``solve_ivp`` call only); a run whose first attempt takes over :data:`REPEAT_BELOW_S`
is timed once (the repeats guard short runs against the machine's noise; a run of
seconds is far from every target, and repeating it would push the full report, with
the RT-70's 10 s transient, past ten minutes). Every run happens in a worker process
(:mod:`multiprocessing`, ``spawn``) that keeps its scenes and, before a method's first
run on a problem, runs it over a short span untimed (a compiled method's first call after
an install compiles its kernels, for a minute or more); the parent waits for the result
at most the cap plus a small allowance for the post-processing, then kills the worker
(and starts a new one for the next run). A run over the cap is reported as
``over cap`` after one attempt, and the tighter tolerances of the same method on the
same problem are not run (reported ``over cap (not run)``): a tighter tolerance is
assumed to cost at least as much. The worker runs with BLAS and OpenMP pinned to one
thread (:func:`rt70.reports.threads.single_threaded`; every row records the thread count
read back from the pools and what they would use otherwise): on this 2-core machine a
threaded 102 × 102 complex LU (Radau on the 50-body chain) takes 30 times longer than a
single-threaded one.

Solver statistics
-----------------
Every row records evaluations, Jacobians and LU decompositions, the step count where the
integrator reports it (scipy's ``solve_ivp`` does not with ``t_eval``: ``-1``), and the
time split ``rhs_s``, ``jacobian_s``, ``integrator_s`` (integrator overhead including
linear algebra) from ``SimulationResult.timing`` where the method measures it (NaN
otherwise).

Results
-------
This module runs the report and gives its rows (:func:`run`, :class:`Row`);
:mod:`rt70.reports.work_precision_results` reads them: the summary, the integration
target this report measures, the table, and the CSV and plot.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.reports.work_precision_problems import PROBLEMS, QUICK_PROBLEMS, Problem
from rt70.reports.work_precision_worker import Attempt, Worker
from rt70.simulation import simulate as _simulate

#: Methods measured: every method of :data:`rt70.simulation.simulate.METHODS` (the compiled
#: integrators such as CVODE included once they are there) but RK23, which is RK45's
#: lower order and adds nothing to the comparison.
METHODS = tuple(m for m in _simulate.METHODS if m != "RK23")
#: Methods that need no cap against stiffness: the implicit ones (scipy's and SUNDIALS').
STIFF_METHODS = tuple(
    m
    for m in METHODS
    if m in _simulate.IMPLICIT
    or m.startswith("CVODE")
    or m in (_simulate.GENERALIZED_ALPHA, _simulate.COMPILED_BDF)
)
#: The tolerance ladder (relative tolerance; ``atol`` is the default of
#: :func:`~rt70.simulation.simulate.simulate`).
RTOLS = tuple(10.0**-k for k in range(3, 10))
#: Relative tolerance of the references.
REFERENCE_RTOL = 1e-12
#: Attempts per run; the best wall time is reported.
REPEATS = 3
#: A run whose first attempt takes longer than this (s) is not repeated.
REPEAT_BELOW_S = 2.0
#: Wall-time cap per run, s.
TIME_CAP_S = 20.0
#: Cap of a reference run, s (a reference over it is an error).
REFERENCE_CAP_S = 240.0
#: Tolerances, cap and repeats of the quick run.
QUICK_RTOLS = (1e-3, 1e-6)
QUICK_CAP_S = 2.0
QUICK_REPEATS = 2


@dataclass(frozen=True)
class Row:
    """One run: a method at one tolerance on one problem.

    ``status`` is ``ok``, ``over cap`` (abandoned at the cap), ``over cap (not run)``
    (a looser tolerance of the same method was over the cap) or ``failed: <message>``.
    ``error`` and ``time_s`` are NaN unless the status is ``ok``; ``times_s`` lists the
    attempts. ``reference`` names the reference of this row and ``reference_floor`` is
    the error of the alternate reference against the primary one (the measurement
    floor). ``notes`` describes the problem. ``threads`` is the largest BLAS/OpenMP thread
    count in the worker (1: pinned), ``threads_unpinned`` what its pools would use
    otherwise (``"openblas 2, openmp 2"``).
    """

    problem: str
    nv: int
    t_end: float
    method: str
    rtol: float
    atol: float
    status: str
    over_cap: bool
    error: float
    time_s: float
    times_s: str
    nfev: int
    njev: int
    nlu: int
    cap_s: float
    reference: str
    reference_floor: float
    notes: str
    threads: int
    threads_unpinned: str
    com_error: float = math.nan
    com_floor: float = math.nan
    n_steps: int = -1
    rhs_s: float = math.nan
    jacobian_s: float = math.nan
    integrator_s: float = math.nan


def relative_error(x: np.ndarray, x_ref: np.ndarray) -> float:
    """``max_t ‖x(t) − x_ref(t)‖∞ / max_t ‖x_ref(t)‖∞`` over a common grid (rows = times)."""
    return float(np.max(np.abs(x - x_ref)) / np.max(np.abs(x_ref)))


def com_error(com: np.ndarray, com_ref: np.ndarray) -> float:
    """``max_t max_b |c_b(t) − c_b,ref(t)|``, m, of (n_t, n_bodies, 3) centre-of-mass arrays."""
    return float(np.max(np.linalg.norm(com - com_ref, axis=-1), initial=0.0))


def _label(method: str, atol: float | None) -> str:
    a = "default atol" if atol is None else f"atol={atol:g}"
    return f"{method} rtol={REFERENCE_RTOL:g} {a}"


def run(
    quick: bool = False,
    problems: tuple[Problem, ...] | None = None,
    methods: tuple[str, ...] = METHODS,
    rtols: tuple[float, ...] | None = None,
    cap_s: float | None = None,
    repeats: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """Run the work–precision report.

    Parameters
    ----------
    quick : bool
        Small version for tests: :data:`QUICK_PROBLEMS`, :data:`QUICK_RTOLS`,
        :data:`QUICK_CAP_S`, :data:`QUICK_REPEATS` (a few seconds).
    problems, methods, rtols : tuple, optional
        Override the problems, methods and tolerance ladder.
    cap_s : float, optional
        Wall-time cap per run, s (default :data:`TIME_CAP_S`).
    repeats : int, optional
        Attempts per run; the best time is reported (default :data:`REPEATS`).
    progress : callable (str) -> None, optional
        Receives one line per run.

    Returns
    -------
    list of Row
        One row per problem, method and tolerance.

    Raises
    ------
    Rt70Error
        If a problem cannot be built or a reference run fails or exceeds
        :data:`REFERENCE_CAP_S`.

    Notes
    -----
    The runs happen in a ``spawn``-ed worker process, which re-imports the caller's
    ``__main__``: a script calling this must do so under ``if __name__ == "__main__"``.
    """
    problems = problems or (QUICK_PROBLEMS if quick else PROBLEMS)
    rtols = rtols or (QUICK_RTOLS if quick else RTOLS)
    cap = cap_s if cap_s is not None else (QUICK_CAP_S if quick else TIME_CAP_S)
    repeats = repeats or (QUICK_REPEATS if quick else REPEATS)
    say = progress or (lambda _msg: None)
    worker = Worker()
    rows: list[Row] = []
    try:
        for problem in problems:
            refs = _references(worker, problem, say)
            mine = [m for m in methods if not problem.stiff_only or m in STIFF_METHODS]
            for method in mine:
                ladder = problem.rtols or rtols
                rows += _method_rows(worker, problem, method, ladder, cap, repeats, refs, say)
    finally:
        worker.close()
    return rows


@dataclass(frozen=True)
class _References:
    """The reference runs of one problem and the floor of the measurement.

    ``x`` and ``com`` map each reference method to its states ``(n_t, 2 nv)`` and
    centres of mass ``(n_t, n_bodies, 3)`` (m); ``floor`` and ``com_floor`` are the
    alternate reference's errors against the primary one.
    """

    x: dict[str, np.ndarray]
    com: dict[str, np.ndarray]
    floor: float
    com_floor: float


def _references(worker: Worker, problem: Problem, say: Callable[[str], None]) -> _References:
    """Run the problem's two references; :class:`Rt70Error` if one fails."""
    refs, coms = {}, {}
    for method in problem.references:
        start = time.perf_counter()
        got = worker.run(problem, method, REFERENCE_RTOL, problem.reference_atol, REFERENCE_CAP_S)
        if got.status != "ok":
            raise Rt70Error(
                f"{problem.name}: reference {_label(method, problem.reference_atol)}: {got.status}"
            )
        refs[method] = got.x
        coms[method] = got.com
        say(
            f"{problem.name}: reference {_label(method, problem.reference_atol)} "
            f"{got.wall_s:.2f} s ({time.perf_counter() - start:.1f} s with set-up)"
        )
    primary, alternate = problem.references
    floor = relative_error(refs[alternate], refs[primary])
    c_floor = com_error(coms[alternate], coms[primary])
    say(f"{problem.name}: references agree to {floor:.2e} (COM {c_floor:.1e} m)")
    return _References(refs, coms, floor, c_floor)


def _method_rows(
    worker: Worker,
    problem: Problem,
    method: str,
    rtols: tuple[float, ...],
    cap: float,
    repeats: int,
    refs: _References,
    say: Callable[[str], None],
) -> list[Row]:
    """One method down the tolerance ladder; past a run over the cap, the rest is not run."""
    rows = []
    over = False
    for rtol in rtols:
        ref_method = problem.reference_for(method)
        common = _common(worker, problem, method, rtol, cap, refs)
        if over:
            rows.append(_row(common, "over cap (not run)", []))
            continue
        attempts = _attempts(worker, problem, method, rtol, cap, repeats)
        done = [a for a in attempts if a.status == "ok"]
        if done:  # an attempt over the cap after good ones is noise: drop it
            err = relative_error(done[0].x, refs.x[ref_method])
            c_err = com_error(done[0].com, refs.com[ref_method])
            row = _row(common, "ok", done, err, c_err)
        else:
            over = attempts[-1].status == "over cap"
            row = _row(common, attempts[-1].status, attempts)
        rows.append(row)
        say(
            f"{problem.name}: {method} rtol={rtol:g}: {row.status}, "
            f"error {row.error:.2e} ({row.com_error:.1e} m), best {row.time_s:.3f} s"
        )
    return rows


def _attempts(
    worker: Worker, problem: Problem, method: str, rtol: float, cap: float, repeats: int
) -> list[Attempt]:
    """Up to ``repeats`` attempts of one run: fewer after a failure or a long first one."""
    attempts = []
    for _ in range(repeats):
        attempts.append(worker.run(problem, method, rtol, None, cap))
        if attempts[-1].status != "ok" or attempts[0].wall_s > REPEAT_BELOW_S:
            break
    return attempts


def _common(
    worker: Worker, problem: Problem, method: str, rtol: float, cap: float, refs: _References
) -> dict:
    """The fields of a :class:`Row` that do not depend on the run's outcome."""
    return dict(
        problem=problem.name,
        t_end=problem.t_end,
        method=method,
        rtol=rtol,
        cap_s=cap,
        reference=_label(problem.reference_for(method), problem.reference_atol),
        reference_floor=refs.floor,
        com_floor=refs.com_floor,
        notes=worker.notes[problem],
        nv=worker.nv[problem],
        threads=worker.threads[problem][0],
        threads_unpinned=worker.threads[problem][1],
    )


def _row(
    common: dict,
    status: str,
    attempts: list[Attempt],
    error: float = math.nan,
    c_error: float = math.nan,
) -> Row:
    ok = status == "ok"
    walls = [a.wall_s for a in attempts if not math.isnan(a.wall_s)]
    first = attempts[0] if attempts else Attempt(status)
    best = min(attempts, key=lambda a: a.wall_s) if ok else first
    timing = best.timing or {}
    rtol = common["rtol"]
    return Row(
        **common,
        atol=first.atol if not math.isnan(first.atol) else 1e-3 * rtol,
        status=status,
        over_cap=status.startswith("over cap"),
        error=error if ok else math.nan,
        time_s=min(walls) if ok else math.nan,
        times_s=";".join(f"{w:.4f}" for w in walls),
        nfev=first.nfev,
        njev=first.njev,
        nlu=first.nlu,
        com_error=c_error if ok else math.nan,
        n_steps=first.n_steps,
        rhs_s=float(timing.get("rhs", math.nan)),
        jacobian_s=float(timing.get("jacobian", math.nan)),
        integrator_s=float(timing.get("integrator", math.nan)),
    )
