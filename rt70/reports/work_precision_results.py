"""The work–precision rows read back: the summary, the targets, the table and the files.

:func:`rt70.reports.work_precision.run` measures; this module says what the rows mean.
:func:`summary` gives per problem the fastest method to a state error and its speed-up
over RK45, :func:`format_table` the report as text, :func:`write_results` the CSV and
the log–log plot of centre-of-mass error against run time.

Targets
-------
The simulation-speed targets (10 s transient at 1e-5 m, the whole command, the right-hand side
and Jacobian against Pinocchio's) are judged in :mod:`rt70.reports.simulation_targets`.
:func:`check_targets` judges the integration target that this report measures:
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
from dataclasses import asdict, fields
from pathlib import Path
from typing import TYPE_CHECKING

from rt70.guards.atomic import atomic_write_all
from rt70.reports import targets
from rt70.reports.targets import TargetCheck
from rt70.reports.work_precision import METHODS, REFERENCE_RTOL, Row
from rt70.reports.work_precision_problems import PROBLEMS

if TYPE_CHECKING:
    from matplotlib.axes import Axes

#: The accuracy at which the summary compares methods (error ≤ this).
TARGET_ERROR = 1e-6
#: The target problem and its targets: error ≤ this, real-time factor ≥ that.
TARGET_PROBLEM = "rt70"
REAL_TIME_TARGET = 50.0


def time_to_reach(
    rows: list[Row], problem: str, method: str, target: float, metric: str = "error"
) -> Row | None:
    """The fastest ``ok`` run of ``method`` on ``problem`` with ``metric`` ≤ ``target``.

    Parameters
    ----------
    rows : list of Row
        The report's rows.
    problem : str
        Name of the problem, e.g. ``"rt70"``.
    method : str
        The integrator.
    target : float
        Largest value of ``metric`` that counts (dimensionless, or m for ``com_error``).
    metric : {"error", "com_error"}, optional
        A field of :class:`Row`: ``error`` (relative state error) or ``com_error``
        (centre-of-mass error, m).

    Returns
    -------
    Row or None
        The row with the least ``time_s``; None if no run reached the target.
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
    """The integration target that this report measures, against ``rows``.

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
        "real time"
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
        "report: the energy balance (see `rt70 simulate`)"
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
    text = _csv_text(rows)
    names = list(dict.fromkeys(r.problem for r in rows))
    ncols = 2 if len(names) > 1 else 1
    nrows = math.ceil(len(names) / ncols)
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(6.5 * ncols, 4.8 * nrows), squeeze=False, constrained_layout=True
    )
    markers = "osD^v<>PX*"
    style = {m: (f"C{i % 10}", markers[i % len(markers)]) for i, m in enumerate(METHODS)}
    for ax, problem in zip(axes.flat, names, strict=False):
        _plot_problem(ax, [r for r in rows if r.problem == problem], style)
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


def _csv_text(rows: list[Row]) -> str:
    """The rows as CSV text, one column per field of :class:`Row`, floats as ``repr``."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=[f.name for f in fields(Row)], lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in asdict(r).items()})
    return buf.getvalue()


def _plot_problem(ax: Axes, mine: list[Row], style: dict[str, tuple[str, str]]) -> None:
    """One problem's panel: each method's error against time, the cap, target and floor."""
    problem, cap = mine[0].problem, mine[0].cap_s
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
    if problem == targets.TRANSIENT_PROBLEM:  # the simulation-speed target region
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
