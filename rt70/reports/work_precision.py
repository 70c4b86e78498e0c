"""Work–precision report of the integrators of :func:`rt70.simulation.simulate.simulate`.

For each test problem and each ``solve_ivp`` method the run is repeated over a ladder
of relative tolerances; every run gives one point (run time, error) of the method's
work–precision curve.

The problems (the RT-70's 10 s transient of issue 13, the RT-70 over 2 s with the
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

Beside it, the engineering metric of issue 13: the largest error over time and bodies
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
(:mod:`multiprocessing`, ``spawn``) that keeps its scenes; the parent waits for the
result at most the cap plus a small allowance for the post-processing, then kills the
worker (and starts a new one for the next run). A run over the cap is reported as
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

Targets
-------
The issue-13 targets (10 s transient at 1e-5 m, the whole command, the right-hand side
and Jacobian against Pinocchio's) are judged in :mod:`rt70.reports.simulation_targets`.
:func:`check_targets` judges the targets of issues 5 and 13 that this report measures:
the RT-70 (listing damping) integrated to state error ≤ 1e-6 at ≥ 50× real time, i.e.
in ≤ T/50 of wall time (0.2 s for the 10 s transient). The report's span is T = 2 s,
its error the state error above; the quick run's 0.05 s span measures start-up more than
the transient, so it prints the value but does not judge it. The whole-command time, the
centre-of-mass error in metres and the energy balance are not measured here.
"""

from __future__ import annotations

import csv
import io
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.atomic import atomic_write_all
from rt70.reports import targets
from rt70.reports.targets import TargetCheck
from rt70.reports.work_precision_problems import PROBLEMS, QUICK_PROBLEMS, Problem
from rt70.reports.work_precision_worker import Attempt, Worker
from rt70.simulation import simulate as _simulate

#: Methods measured: every method of :data:`rt70.simulation.simulate.METHODS` (the compiled
#: integrators such as CVODE included once they are there) but RK23, which is RK45's
#: lower order and adds nothing to the comparison.
METHODS = tuple(m for m in _simulate.METHODS if m != "RK23")
#: Methods that need no cap against stiffness: the implicit ones (scipy's and SUNDIALS').
STIFF_METHODS = tuple(m for m in METHODS if m in _simulate.IMPLICIT or m.startswith("CVODE"))
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
#: The accuracy at which the summary compares methods (error ≤ this).
TARGET_ERROR = 1e-6
#: The target problem and its targets (issues 5 and 13): error ≤ this, real-time factor ≥ that.
TARGET_PROBLEM = "rt70"
REAL_TIME_TARGET = 50.0
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
            refs, coms = {}, {}
            for method in problem.references:
                start = time.perf_counter()
                got = worker.run(
                    problem, method, REFERENCE_RTOL, problem.reference_atol, REFERENCE_CAP_S
                )
                if got.status != "ok":
                    raise Rt70Error(
                        f"{problem.name}: reference {_label(method, problem.reference_atol)}: "
                        f"{got.status}"
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
            mine = [m for m in methods if not problem.stiff_only or m in STIFF_METHODS]
            for method in mine:
                over = False
                for rtol in problem.rtols or rtols:
                    ref_method = problem.reference_for(method)
                    common = dict(
                        problem=problem.name,
                        t_end=problem.t_end,
                        method=method,
                        rtol=rtol,
                        cap_s=cap,
                        reference=_label(ref_method, problem.reference_atol),
                        reference_floor=floor,
                        com_floor=c_floor,
                        notes=worker.notes[problem],
                        nv=worker.nv[problem],
                        threads=worker.threads[problem][0],
                        threads_unpinned=worker.threads[problem][1],
                    )
                    if over:
                        rows.append(_row(common, "over cap (not run)", []))
                        continue
                    attempts = []
                    for _ in range(repeats):
                        attempts.append(worker.run(problem, method, rtol, None, cap))
                        if attempts[-1].status != "ok" or attempts[0].wall_s > REPEAT_BELOW_S:
                            break
                    done = [a for a in attempts if a.status == "ok"]
                    if done:  # an attempt over the cap after good ones is noise: drop it
                        err = relative_error(done[0].x, refs[ref_method])
                        c_err = com_error(done[0].com, coms[ref_method])
                        row = _row(common, "ok", done, err, c_err)
                    else:
                        over = attempts[-1].status == "over cap"
                        row = _row(common, attempts[-1].status, attempts)
                    rows.append(row)
                    say(
                        f"{problem.name}: {method} rtol={rtol:g}: {row.status}, "
                        f"error {row.error:.2e} ({row.com_error:.1e} m), best {row.time_s:.3f} s"
                    )
    finally:
        worker.close()
    return rows


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


def time_to_reach(
    rows: list[Row], problem: str, method: str, target: float, metric: str = "error"
) -> Row | None:
    """The fastest ``ok`` run of ``method`` on ``problem`` with ``metric`` ≤ ``target``.

    ``metric`` is a field of :class:`Row`: ``error`` (relative state error) or
    ``com_error`` (centre-of-mass error, m).
    """
    ok = [
        r
        for r in rows
        if r.problem == problem
        and r.method == method
        and r.status == "ok"
        and getattr(r, metric) <= target
    ]
    return min(ok, key=lambda r: r.time_s, default=None)


def summary(rows: list[Row], target: float = TARGET_ERROR) -> list[str]:
    """Per problem: the fastest method reaching ``error ≤ target`` and its speed-up over RK45."""
    lines = []
    for problem in dict.fromkeys(r.problem for r in rows):
        methods = dict.fromkeys(r.method for r in rows if r.problem == problem)
        best = [b for m in methods if (b := time_to_reach(rows, problem, m, target))]
        if not best:
            lines.append(f"{problem}: no method reached error ≤ {target:g} within the cap")
            continue
        win = min(best, key=lambda r: r.time_s)
        line = (
            f"{problem}: fastest to error ≤ {target:g}: {win.method} at rtol {win.rtol:g} "
            f"({win.time_s:.3f} s, error {win.error:.1e})"
        )
        rk = time_to_reach(rows, problem, "RK45", target)
        if win.method == "RK45":
            line += "; RK45 itself is the fastest"
        elif rk is not None:
            line += f"; {rk.time_s / win.time_s:.1f}× faster than RK45 ({rk.time_s:.3f} s)"
        elif "RK45" in methods:
            rk_rows = [r for r in rows if r.problem == problem and r.method == "RK45"]
            if any(r.over_cap for r in rk_rows):
                cap = rk_rows[0].cap_s
                line += (
                    f"; RK45 did not reach it within the {cap:g} s cap "
                    f"(speed-up > {cap / win.time_s:.0f}×)"
                )
            else:
                line += f"; RK45 did not reach it down to rtol {min(r.rtol for r in rk_rows):g}"
        lines.append(line)
    return lines


def check_targets(rows: list[Row], target: float = TARGET_ERROR) -> list[TargetCheck]:
    """The targets of issues 5 and 13 that this report measures, against ``rows``.

    The RT-70 (:data:`TARGET_PROBLEM`) must reach state error ≤ ``target`` at
    ≥ :data:`REAL_TIME_TARGET` × real time: the fastest ``ok`` run of any method with
    that error must take at most ``T / REAL_TIME_TARGET`` of integration wall time.
    """
    mine = [r for r in rows if r.problem == TARGET_PROBLEM]
    if not mine:
        goal = f"{TARGET_PROBLEM} at state error ≤ {target:g}, ≥ {REAL_TIME_TARGET:g}× real time"
        return [TargetCheck(goal, "— (not in this run)", None)]
    t_end = mine[0].t_end
    goal = (
        f"{TARGET_PROBLEM} (listing damping, T = {t_end:g} s) to state error ≤ {target:g} in "
        f"≤ {t_end / REAL_TIME_TARGET:.3g} s of integration, i.e. ≥ {REAL_TIME_TARGET:g}× "
        "real time (issues 5, 13)"
    )
    methods = dict.fromkeys(r.method for r in mine)
    best = [b for m in methods if (b := time_to_reach(rows, TARGET_PROBLEM, m, target))]
    if not best:
        reached = f"no method reached it within the {mine[0].cap_s:g} s cap"
        return [TargetCheck(goal, reached, False)]
    win = min(best, key=lambda r: r.time_s)
    factor = t_end / win.time_s
    measured = (
        f"{win.time_s:.3f} s, {factor:.1f}× real time ({win.method}, rtol {win.rtol:g}, "
        f"error {win.error:.1e})"
    )
    full_span = next(p.t_end for p in PROBLEMS if p.name == TARGET_PROBLEM)
    if t_end < full_span:  # a quick run's short span measures start-up, not the transient
        return [TargetCheck(goal, measured + f"; span under the report's {full_span:g} s", None)]
    return [TargetCheck(goal, measured, factor >= REAL_TIME_TARGET)]


def format_table(rows: list[Row]) -> str:
    """The report as text: per problem its description, references, rows and the summary."""
    lines = []
    head = (
        f"{'method':<11} {'rtol':>7} {'error':>9} {'COM m':>8} {'time s':>8} {'steps':>6} "
        f"{'nfev':>6} {'njev':>5} {'nlu':>5} {'rhs s':>7} {'jac s':>7} {'integ s':>7}  status"
    )
    for problem in dict.fromkeys(r.problem for r in rows):
        mine = [r for r in rows if r.problem == problem]
        r0 = mine[0]
        refs = sorted({r.reference for r in mine})
        lines += [
            f"{problem} (nv = {r0.nv}): {r0.notes}",
            f"  references: {'; '.join(refs)}; they agree to {r0.reference_floor:.1e} "
            f"(centres of mass to {r0.com_floor:.1e} m)",
            f"  time = best of the attempts' wall times; cap {r0.cap_s:g} s",
            "  " + head,
            "  " + "-" * len(head),
        ]
        for r in mine:
            lines.append("  " + _table_line(r))
        lines.append("")
    lines += summary(rows)
    if rows:
        lines.append(
            f"BLAS/OpenMP threads in the worker: {rows[0].threads} "
            f"(unpinned: {rows[0].threads_unpinned})"
        )
    lines += [c.line() for c in check_targets(rows)]
    lines.append(
        "COM m: largest centre-of-mass position error over time and bodies against the same "
        "reference; steps — where the integrator does not report them (scipy with t_eval); "
        "rhs/jac/integ s: the time split where the method measures it; not measured by this "
        "report: the energy balance (issue 5; see `rt70 simulate`)"
    )
    return "\n".join(lines)


def _table_line(r: Row) -> str:
    """One row of :func:`format_table` (— where not measured)."""
    ok = r.status == "ok"

    def num(value: float | int, fmt: str) -> str:
        bad = not ok or (isinstance(value, float) and math.isnan(value)) or value == -1
        return "—" if bad else format(value, fmt)

    t = f"{r.time_s:.3f}" if ok else f"> {r.cap_s:g}" if r.over_cap else "—"
    return (
        f"{r.method:<11} {r.rtol:>7.0e} {num(r.error, '.2e'):>9} {num(r.com_error, '.1e'):>8} "
        f"{t:>8} {num(r.n_steps, 'd'):>6} {num(r.nfev, 'd'):>6} {num(r.njev, 'd'):>5} "
        f"{num(r.nlu, 'd'):>5} {num(r.rhs_s, '.3f'):>7} {num(r.jacobian_s, '.3f'):>7} "
        f"{num(r.integrator_s, '.3f'):>7}  {r.status}"
    )


def write_results(rows: list[Row], directory: str | Path) -> list[Path]:
    """Write ``work_precision.csv`` and the log–log plot ``work_precision.png`` atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = Path(directory)
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=[f.name for f in fields(Row)], lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in asdict(r).items()})
    text = buf.getvalue()

    names = list(dict.fromkeys(r.problem for r in rows))
    ncols = 2 if len(names) > 1 else 1
    nrows = math.ceil(len(names) / ncols)
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(6.5 * ncols, 4.8 * nrows), squeeze=False, constrained_layout=True
    )
    markers = "osD^v<>PX*"
    style = {m: (f"C{i % 10}", markers[i % len(markers)]) for i, m in enumerate(METHODS)}
    for ax, problem in zip(axes.flat, names, strict=False):
        mine = [r for r in rows if r.problem == problem]
        cap = mine[0].cap_s
        for method in dict.fromkeys(r.method for r in mine):
            color, marker = style.get(method, ("k", "x"))
            runs = [r for r in mine if r.method == method]
            pts = [(r.time_s, r.com_error) for r in runs if r.status == "ok"]
            over = [r.rtol for r in runs if r.over_cap]
            label = method
            if over:
                label += f" (over the cap from rtol {max(over):.0e})"
            if pts:
                t, e = zip(*pts, strict=True)
                ax.loglog(t, e, "-", color=color, marker=marker, label=label)
            else:
                ax.plot([], [], "none", color=color, marker=marker, label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.axvline(cap, color="0.5", ls="--", lw=1, label=f"time cap {cap:g} s")
        if problem == targets.TRANSIENT_PROBLEM:  # the issue-13 target region
            ax.axhline(targets.COM_TARGET_M, color="C3", ls="-.", lw=1)
            ax.axvline(
                mine[0].t_end / targets.REAL_TIME_TARGET,
                color="C3",
                ls="-.",
                lw=1,
                label=f"target: ≤ {targets.COM_TARGET_M:g} m in ≤ T/{targets.REAL_TIME_TARGET:g}",
            )
        floor = mine[0].com_floor
        if floor > 0:
            ax.axhline(floor, color="0.5", ls=":", lw=1, label="references' agreement")
        title = f"{problem} (nv = {mine[0].nv}, T = {mine[0].t_end:g} s)"
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("run time, s (best of repeats)")
        ax.set_ylabel("max centre-of-mass position error, m")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    for ax in list(axes.flat)[len(names) :]:
        ax.set_visible(False)
    ladder = sorted({r.rtol for r in rows}, reverse=True)
    fig.suptitle(
        f"Work–precision: centre-of-mass error against run time, rtol {ladder[0]:.0e} … "
        f"{ladder[-1]:.0e} "
        f"(references: another method at rtol {REFERENCE_RTOL:g})",
        fontsize=11,
    )
    try:  # the table and its plot appear together, or neither changes
        return atomic_write_all(
            {
                directory / "work_precision.csv": lambda tmp: tmp.write_text(
                    text, encoding="utf-8", newline="\n"
                ),
                directory / "work_precision.png": lambda tmp: fig.savefig(tmp, dpi=110),
            }
        )
    finally:
        plt.close(fig)
