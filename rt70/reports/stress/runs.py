"""Capped simulations of the stress cases, with accepted and rejected steps counted.

A short simulation (:func:`rt70.simulation.simulate.simulate`, reference side, BDF,
``rtol = 1e-6`` unless stated) gives its outcome, accepted and rejected steps, the
number of right-hand-side evaluations, the relative drift of the energy balance
``T + U_g + U_c + E_ψ`` and the wall time of the integration. :class:`Settings` holds the
sizes of the full report and of the quick smoke test.

**Rejected steps.** ``scipy.integrate.solve_ivp`` does not report them. They are counted
from the times at which the right-hand side is evaluated, observed through the
``inputs`` hook of :func:`~rt70.simulation.simulate.simulate` (which returns ``Q_u = 0``, so the
equations are unchanged). For BDF every attempt of a step evaluates the right-hand side
at its end time ``t + h`` (Newton iterations, Jacobian updates), so consecutive equal
times form one attempt, and an attempt is rejected exactly when the next attempt ends
earlier (the step is retried with a smaller h). Checked against an instrumented
``scipy.integrate.BDF`` on the RT-70 (identical counts, accepted attempts equal to the
solver's steps). For the explicit Runge–Kutta methods every attempt costs ``s``
evaluations (``s`` = 12 for DOP853, 6 for RK45, 3 for RK23) after the 2 of the start,
so ``rejected = (nfev − 2)/s − steps``. Other methods: not counted ("—").

**Cap.** Each simulation of the report is given :data:`MAX_EVALUATIONS` right-hand-side
evaluations: the same hook raises when they are spent, the run is reported as ``over
cap`` with the time it reached, and the report goes on. A budget of work, not of time,
so where a run stops is the same on every machine and the report regenerates identically
but for its wall times. :data:`TIME_CAP_S` seconds of wall time remain as a guard, so no
run can hang the report (tests give :func:`run_capped` a clock that counts evaluations,
or a cap of ``math.inf``, so their verdicts do not depend on the machine either).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.scene import Scene
from rt70.model.sides import refuses_backend
from rt70.reports.stress.measures import CROSS_CHECK_SAMPLES
from rt70.simulation.result import SimulationResult
from rt70.simulation.simulate import simulate

#: Simulated time of each run, s (the quick report uses :data:`QUICK_SPAN_S`).
SIM_SPAN_S = 0.5
#: Simulated time of each run in the quick (smoke-test) report, s.
QUICK_SPAN_S = 0.02
#: Relative tolerance of the stress runs.
SIM_RTOL = 1e-6
#: Right-hand-side evaluations one simulation of the report may spend (the cap).
MAX_EVALUATIONS = 40_000
#: Wall-time guard of one simulation, s (see the module docstring).
TIME_CAP_S = 300.0

#: Right-hand-side evaluations per step attempt of the explicit Runge–Kutta methods.
_RK_STAGES = {"DOP853": 12, "RK45": 6, "RK23": 3}


class _OverCap(Exception):
    pass


@dataclass
class RunOutcome:
    """One capped simulation (see the module docstring for the counts)."""

    status: str  # "ok", "failed: …", "over cap", "error: …"
    t_reached: float
    n_steps: int | None
    n_rejected: int | None
    nfev: int
    drift: float | None
    wall_s: float
    result: SimulationResult | None = None

    @property
    def ok(self) -> bool:
        """The integration reached the end of its span."""
        return self.status == "ok"


def count_bdf_steps(times: list[float], t0: float) -> tuple[int, int]:
    """Accepted and rejected BDF step attempts from the right-hand-side evaluation times.

    Evaluations up to the last one at ``t0`` belong to the start (f0, the initial-step
    probe, the first Jacobian). Consecutive equal times are one attempt; an attempt is
    rejected when the next one ends earlier. An unfinished last attempt counts as
    accepted.
    """
    start = max((i for i, t in enumerate(times) if t == t0), default=-1) + 1
    attempts: list[float] = []
    for t in times[start:]:
        if not attempts or t != attempts[-1]:
            attempts.append(t)
    rejected = sum(1 for a, b in zip(attempts, attempts[1:], strict=False) if b < a)
    return len(attempts) - rejected, rejected


def _warm_up(scene: Scene, t_span: tuple[float, float], x0: tuple | None, side: str) -> None:
    """A few right-hand sides evaluated before the cap's clock starts.

    The compiled kernels compile (or load from numba's cache) on their first call: on a
    fresh checkout that took 15.8 s, more than the whole cap, inside the first capped run.
    A run of 1 ns with RK45 calls every kernel the capped run will; what it returns or
    raises is discarded (the capped run meets the same error and reports it).
    """
    t0 = float(t_span[0])
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            simulate(scene, (t0, t0 + 1e-9), x0, side, "RK45", 1e-3)
    except (Rt70Error, np.linalg.LinAlgError):
        pass


@refuses_backend
def run_capped(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None = None,
    side: str = "reference",
    method: str = "BDF",
    rtol: float = SIM_RTOL,
    cap_s: float = TIME_CAP_S,
    t_eval: np.ndarray | None = None,
    clock: Callable[[], float] = time.perf_counter,
    max_evaluations: float = math.inf,
) -> RunOutcome:
    """:func:`rt70.simulation.simulate.simulate` with a wall-time cap and step/rejection counts.

    Parameters
    ----------
    scene, t_span, x0, side, method, rtol, t_eval
        As for :func:`rt70.simulation.simulate.simulate`.
    cap_s : float
        The cap, s of ``clock``: checked at every right-hand-side evaluation, the first
        one past it ends the run as ``over cap`` (``math.inf``: no cap).
    clock : callable () -> float
        The clock the cap is measured on (default the wall clock; a test gives one that
        counts, so that where a run stops does not depend on the machine's speed).
    max_evaluations : float
        Right-hand-side evaluations the run may spend; the first one past them ends it
        as ``over cap`` (default: no budget).

    Returns
    -------
    RunOutcome
        Rt70 errors (gimbal lock, a singular mass matrix) and numpy's LinAlgError end the
        run as ``error: …``; nothing is raised.
    """
    zero = np.zeros(scene.textbook.nv)
    times: list[float] = []
    _warm_up(scene, t_span, x0, side)
    start = clock()

    def hook(t, q, qd):
        times.append(t)
        if len(times) > max_evaluations or clock() - start > cap_s:
            raise _OverCap
        return zero

    status, result = "ok", None
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            result = simulate(scene, t_span, x0, side, method, rtol, inputs=hook, t_eval=t_eval)
        if not result.success:
            status = f"failed: {result.message}"
    except _OverCap:
        status = "over cap"
    except (Rt70Error, np.linalg.LinAlgError) as exc:
        status = f"error: {type(exc).__name__}: {exc}"
    wall = clock() - start
    t0 = float(t_span[0])
    steps = rejected = None
    if method == "BDF":
        steps, rejected = count_bdf_steps(times, t0)
    elif method in _RK_STAGES and result is not None and t_eval is None:
        attempts, rest = divmod(result.nfev - 2, _RK_STAGES[method])
        if rest == 0:
            steps, rejected = result.n_steps, attempts - result.n_steps
    if result is not None and result.n_steps >= 0:
        if method == "BDF" and steps != result.n_steps:
            steps = rejected = None  # the count did not match the solver: do not report it
        else:
            steps = result.n_steps
    return RunOutcome(
        status=status,
        t_reached=float(result.t[-1]) if result is not None else max(times, default=t0),
        n_steps=steps,
        n_rejected=rejected,
        nfev=result.nfev if result is not None else len(times),
        drift=None if result is None else result.relative_drift,
        wall_s=result.wall_time_s if result is not None else wall,
        result=result,
    )


@dataclass(frozen=True)
class Settings:
    """Sizes of the report: the full one, or the quick smoke test."""

    span: float
    cap_s: float
    max_evaluations: int
    samples: int
    stiffness_k: tuple[int, ...]
    mass_k: tuple[int, ...]
    gimbal_k: tuple[int, ...]
    chains: tuple[int, ...]
    chain_sim_max: int
    floating_span: float

    @classmethod
    def make(cls, quick: bool) -> Settings:
        """The settings of the full (``quick=False``) or the quick report."""
        if quick:
            return cls(QUICK_SPAN_S, 60.0, 2_000, 1, (0, 3), (0, 3), (1, 4, 8, 9), (10,), 10, 0.05)
        return cls(
            SIM_SPAN_S,
            TIME_CAP_S,
            MAX_EVALUATIONS,
            CROSS_CHECK_SAMPLES,
            tuple(range(7)),
            tuple(range(7)),
            tuple(range(1, 11)),
            (10, 30, 60, 100, 300, 1000),
            30,
            1.0,
        )
