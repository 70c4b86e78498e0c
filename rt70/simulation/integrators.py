"""The time integrators behind :func:`rt70.simulation.simulate.simulate`, one interface for all.

Two families integrate ``ẋ = f(t, x)``:

* scipy's ``solve_ivp`` methods (:data:`SCIPY_METHODS`), the integration loop in Python;
* SUNDIALS CVODE through scikit-sundae (:data:`CVODE_METHODS`), the loop compiled:
  "CVODE" is variable-order BDF (order ≤ 5) for stiff problems, "CVODE_ADAMS" the
  Adams–Moulton family (order ≤ 12) for non-stiff ones. Both solve their implicit
  stages by Newton's method with the dense direct solver, using the analytic Jacobian
  when one is given and CVODE's internal difference quotients otherwise.

:func:`integrate` runs either and returns an :class:`Integration` with the samples, the
solver's statistics, the event times and the time spent in the callbacks
(:class:`Stopwatch`). Each family is imported only when it is used: scipy.integrate
costs ~0.35 s and sksundae ~0.45 s of start-up.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field

import numpy as np

from rt70.errors import SimulationError
from rt70.guards import stop

#: scipy.integrate.solve_ivp methods.
SCIPY_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA", "RK23")
#: SUNDIALS CVODE methods, by rt70's name: CVODE's linear multistep family.
CVODE_METHODS = {"CVODE": "BDF", "CVODE_ADAMS": "Adams"}
#: Smallest rtol solve_ivp honours (it raises smaller ones to 100 machine epsilons).
MIN_RTOL = 100 * np.finfo(float).eps
#: The generalized-α method on the compiled kernels (:mod:`rt70.simulation.compiled_run`).
GENERALIZED_ALPHA = "generalized-alpha"
#: scipy's BDF compiled with the equations of a passive scene (:mod:`rt70.simulation.compiled_bdf`).
COMPILED_BDF = "compiled-BDF"
#: The methods integrating the first-order form (scipy's, then SUNDIALS').
METHODS = SCIPY_METHODS + tuple(CVODE_METHODS)
#: Largest number of CVODE steps between two output times (CVODE's default, 500, is
#: for a caller that samples often; solve_ivp has no such limit).
CVODE_MAX_STEPS = 10_000_000

Rhs = Callable[[float, np.ndarray], np.ndarray]
Jacobian = Callable[[float, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class EvaluationBudget:
    """Right-hand-side evaluations a run may take: ``minimum + per_second · (t1 − t0)``.

    The command line's runs take a few hundred evaluations per simulated second
    (measured: ``rt70 simulate rt70`` 3 125 over 10 s with BDF, the rt70_servo hold
    11 639 over 60 s with LSODA, ``rt70 cart --duration 20`` 2 453 over 7 s with DOP853),
    so the default allows 2 000 per second, six times the most, and 20 000 besides. A run over
    the budget is one its method cannot integrate at a reasonable cost — an explicit
    method on stiff springs, a drive or element stiffer than the implicit methods'
    Jacobian covers (its rows of the extra states are zero, :mod:`rt70.simulation.states`), a
    state driven extremely fast — and would otherwise look like a hang.
    """

    minimum: int = 20_000
    per_second: float = 2_000.0

    def limit(self, span: float) -> int:
        """The number of evaluations allowed over a span of ``span`` seconds."""
        return int(min(self.minimum + self.per_second * span, 1e15))


#: The budget of every run of the command line (rt70/cli/main.py).
COMMAND_BUDGET = EvaluationBudget()

_BUDGET: ContextVar[EvaluationBudget | None] = ContextVar("rt70_evaluation_budget", default=None)


@contextmanager
def evaluation_budget(budget: EvaluationBudget | None = None) -> Iterator[None]:
    """Inside the block every :func:`integrate` (and :func:`budgeted`) run has ``budget``.

    ``budget`` defaults to :data:`COMMAND_BUDGET`.

    The command line runs its commands inside one (rt70/cli/main.py); library calls have none
    unless they ask.
    """
    token = _BUDGET.set(COMMAND_BUDGET if budget is None else budget)
    try:
        yield
    finally:
        _BUDGET.reset(token)


def budget_limit(span: float) -> int | None:
    """Evaluations allowed over ``span`` seconds by the budget in force, or None."""
    budget = _BUDGET.get()
    return None if budget is None else budget.limit(span)


#: Evaluations after which a run that keeps one sample per step (no output times)
#: checks its pace (:func:`budgeted`): about a second of work on the RT-70.
PACE_CHECK = 2_000

#: How many times the samples memory holds the extrapolated evaluations must exceed
#: for the pace check to stop a run: a step takes one to a few evaluations, and a run's
#: start (transients, the step size growing from its cautious first value) is slower
#: than the rest, so the extrapolation overestimates the samples — never by this much.
PACE_MARGIN = 10


def budgeted(rhs: Rhs, span: float, limit: int | None = None, t0: float = 0.0) -> Rhs:
    """``rhs`` counting its calls; past the limit it raises :class:`SimulationError`.

    The limit is the smaller of ``limit`` and the budget in force
    (:func:`evaluation_budget`); with neither, only the stop check remains. Every call
    first raises a stop the command line recorded (:func:`rt70.guards.stop.check`): a
    Ctrl-C or SIGTERM lost inside a library is raised again at the next evaluation.

    ``limit`` is the most samples a run without output times may keep (one per step,
    each step at least one evaluation: :func:`rt70.guards.resources.time_series_samples`). Such
    a run also checks its pace after :data:`PACE_CHECK` evaluations: extrapolated from
    how far it got (from ``t0``) to the whole ``span``, a run that would take over
    :data:`PACE_MARGIN` times ``limit`` evaluations is stopped then, in about a second,
    rather than after minutes at the memory limit (``rt70 simulate rt70 --t-end 1e12``).

    Parameters
    ----------
    rhs : callable (t, x) -> ẋ
        The right-hand side counted.
    span : float
        The run's length ``t1 − t0``, s (the budget in force grows with it).
    limit : int, optional
        The most samples memory holds for the run (none: only the budget in force).
    t0 : float
        The run's start time, s (for the pace check).

    Raises
    ------
    SimulationError
        Past the limit, or at the pace check (the run would keep more samples than
        memory holds).
    """
    counter = EvaluationCounter(span, limit, t0)

    def counted(t: float, x: np.ndarray) -> np.ndarray:
        counter.add(1, t)
        return rhs(t, x)

    return counted


class EvaluationCounter:
    """Evaluations counted against the limits of :func:`budgeted`, a stop checked at each count.

    Parameters
    ----------
    span : float
        The run's length ``t1 − t0``, s.
    limit : int, optional
        The most samples memory holds for the run (none: only the budget in force).
    t0 : float
        The run's start time, s (for the pace check).
    """

    def __init__(self, span: float, limit: int | None = None, t0: float = 0.0) -> None:
        budget = _BUDGET.get()
        self.budget, self.span, self.limit, self.t0 = budget, span, limit, t0
        limits = [
            x for x in (limit, None if budget is None else budget.limit(span)) if x is not None
        ]
        self.most = min(limits) if limits else None
        self.calls = 0

    def add(self, calls: int, t: float) -> None:
        """Count ``calls`` more evaluations, the run having reached ``t``, s.

        Raises
        ------
        SimulationError
            Past the limit, or at the pace check (:func:`budgeted`).
        """
        stop.check()
        if self.most is None:
            return
        before, self.calls = self.calls, self.calls + calls
        if before < PACE_CHECK <= self.calls and self.limit is not None:
            _check_pace(t - self.t0, self.span, self.limit)
        if self.calls > self.most:
            budget = self.budget
            why = (
                "the memory this run may use for its samples (one per step)"
                if self.limit is not None and self.most == self.limit
                else f"{budget.minimum} + {budget.per_second:g} per simulated second: the "
                "equations are too stiff or too fast for this method here (an explicit "
                "method on stiff springs, a drive or element far stiffer or faster than "
                "its parameters' usual range)"
            )
            raise SimulationError(f"stopped after {self.most} right-hand-side evaluations ({why})")


def _check_pace(elapsed: float, span: float, limit: int) -> None:
    """Refuse a run whose pace so far needs far more samples than memory holds."""
    if elapsed <= 0.0:
        return
    expected = PACE_CHECK * (span / elapsed)
    if expected > PACE_MARGIN * limit:
        raise SimulationError(
            f"at the pace of its first {PACE_CHECK} evaluations (over {elapsed:.3g} s) a "
            f"run of {span:.3g} s takes about {expected:.2g} evaluations and keeps a "
            f"sample per step, far more than the {limit} samples this machine's memory "
            "holds; shorten the run (from Python, or give output times: t_eval)"
        )


class Stopwatch:
    """A callable wrapped with a call counter and a ``time.perf_counter`` accumulator.

    Parameters
    ----------
    func : callable
        The function to time; its result is returned unchanged.
    """

    def __init__(self, func: Callable) -> None:
        self.func = func
        self.calls = 0
        self.seconds = 0.0

    def __call__(self, *args):
        """Call the function, counting the call and the seconds it took."""
        start = time.perf_counter()
        try:
            return self.func(*args)
        finally:
            self.seconds += time.perf_counter() - start
            self.calls += 1


@dataclass
class Integration:
    """Samples and statistics of one integration, whichever the method.

    ``y`` has one row per state and one column per time (solve_ivp's layout).
    ``n_steps`` is the number of steps when the samples are the steps (no ``t_eval``),
    −1 otherwise; ``nlu`` the number of LU decompositions, −1 where the solver does not
    report it (CVODE through scikit-sundae). ``t_events`` holds one array of crossing
    times per event function.
    """

    t: np.ndarray
    y: np.ndarray
    nfev: int
    njev: int
    nlu: int
    n_steps: int
    success: bool
    message: str
    t_events: list[np.ndarray] = field(default_factory=list)


def load(method: str) -> None:
    """Import the integrator family of ``method`` (scipy.integrate or scikit-sundae).

    Called before a run is timed, so that its wall time is the integration's, not the
    import's (0.3–0.45 s, which the first run in a process would otherwise carry).
    """
    if method in CVODE_METHODS:
        import sksundae.cvode  # noqa: F401
    else:
        import scipy.integrate  # noqa: F401


def integrate(
    method: str,
    rhs: Rhs,
    jac: Jacobian | None,
    t_span: tuple[float, float],
    y0: np.ndarray,
    rtol: float,
    atol: np.ndarray,
    t_eval: np.ndarray | None = None,
    events: Sequence[Callable[[float, np.ndarray], float]] = (),
    max_evaluations: int | None = None,
) -> Integration:
    """Integrate ``ẋ = rhs(t, x)`` from ``y0`` over ``t_span``.

    Parameters
    ----------
    method : str
        One of :data:`SCIPY_METHODS` or :data:`CVODE_METHODS`.
    rhs : callable (t, x) -> ẋ
        Right-hand side; exceptions it raises propagate unchanged.
    jac : callable (t, x) -> ∂ẋ/∂x, or None
        Analytic Jacobian, used by the implicit methods (None: difference quotients).
    t_span : (t0, t1)
        Interval, t1 > t0.
    y0 : array
        Initial state.
    rtol : float
        Relative tolerance.
    atol : array
        Absolute tolerance per state.
    t_eval : array, optional
        Output times (default: every step).
    events : sequence of callable (t, x) -> float
        Event functions with optional attributes ``terminal`` (bool, or int: stop after
        that many crossings) and ``direction`` (−1, 0, +1), as in solve_ivp.
    max_evaluations : int, optional
        Most calls of ``rhs`` (with the :class:`EvaluationBudget` in force, the smaller).

    Raises
    ------
    SimulationError
        When the run takes more evaluations than allowed (:func:`budgeted`).
    """
    rhs = budgeted(rhs, float(t_span[1]) - float(t_span[0]), max_evaluations, float(t_span[0]))
    if method in CVODE_METHODS:
        return _cvode(method, rhs, jac, t_span, y0, rtol, atol, t_eval, events)
    from scipy.integrate import solve_ivp

    kw = {} if jac is None else {"jac": jac}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = solve_ivp(
            rhs,
            t_span,
            y0,
            method=method,
            rtol=rtol,
            atol=atol,
            t_eval=t_eval,
            events=list(events) or None,
            **kw,
        )
    # solve_ivp leaves ``y`` a list when it failed before the first output time
    y = np.asarray(sol.y, dtype=float).reshape(len(y0), -1)
    return Integration(
        t=np.asarray(sol.t, dtype=float),
        y=y,
        nfev=int(sol.nfev),
        njev=int(sol.njev),
        nlu=int(sol.nlu),
        n_steps=len(sol.t) - 1 if t_eval is None else -1,
        success=bool(sol.success),
        message=_with_warnings(str(sol.message), caught),
        t_events=[np.asarray(t, dtype=float) for t in (sol.t_events or [])],
    )


def _with_warnings(message: str, caught: list[warnings.WarningMessage]) -> str:
    """The solver's message with the warnings it issued (LSODA's, ODEintWarning) appended.

    The solvers warn on their way to a failure ("lsoda: Repeated convergence failures");
    the warnings belong in the run's message, not on stderr beside it.
    """
    seen = dict.fromkeys(" ".join(str(w.message).split()) for w in caught)
    return "; ".join([message, *seen]) if seen else message


def _cvode(method, rhs, jac, t_span, y0, rtol, atol, t_eval, events) -> Integration:
    """:func:`integrate` by SUNDIALS CVODE (scikit-sundae), dense direct linear solver.

    ``nfev`` counts every call of ``rhs`` (CVODE's own count leaves out the calls of its
    difference-quotient Jacobian); ``njev`` is CVODE's count of Jacobian evaluations.
    """
    from sksundae.cvode import CVODE

    calls = [0]

    def rhsfn(t, y, yp):
        calls[0] += 1
        yp[:] = rhs(t, np.array(y))  # y is CVODE's read-only memory: a private copy

    options = {}
    if jac is not None:

        def jacfn(t, y, yp, JJ):
            JJ[:, :] = jac(t, np.array(y))

        options["jacfn"] = jacfn
    if events:

        def eventsfn(t, y, out):
            x = np.array(y)
            for i, g in enumerate(events):
                out[i] = g(t, x)

        eventsfn.terminal = [_terminal(g) for g in events]
        eventsfn.direction = [int(np.sign(getattr(g, "direction", 0))) for g in events]
        options.update(eventsfn=eventsfn, num_events=len(events))
    solver = CVODE(
        rhsfn,
        method=CVODE_METHODS[method],
        rtol=rtol,
        atol=np.asarray(atol, dtype=float),
        linsolver="dense",
        max_num_steps=CVODE_MAX_STEPS,
        **options,
    )
    tspan = np.array(t_span, dtype=float) if t_eval is None else _tspan(t_span, t_eval)
    sol = solver.solve(tspan, np.asarray(y0, dtype=float))
    t = np.asarray(sol.t, dtype=float).ravel()
    y = np.asarray(sol.y, dtype=float).reshape(-1, len(y0)).T
    if t_eval is not None:  # the rows at t_eval (not t0, t1 or a terminal event's time)
        keep = (t == tspan[: t.size]) & np.isin(t, t_eval)
        t, y = t[keep], y[:, keep]
    return Integration(
        t=t,
        y=y,
        nfev=calls[0],
        njev=int(sol.njev),
        nlu=-1,
        n_steps=len(t) - 1 if t_eval is None else -1,
        success=bool(sol.success),
        message=str(sol.message),
        t_events=_event_times(sol, len(events)),
    )


def _terminal(g) -> bool | int:
    """The ``terminal`` attribute of an event function as CVODE takes it."""
    terminal = getattr(g, "terminal", False)
    return terminal if isinstance(terminal, bool) else int(terminal)


def _tspan(t_span, t_eval: np.ndarray) -> np.ndarray:
    """CVODE's output times: t0, ``t_eval`` and t1 (CVODE stops at the last one)."""
    return np.unique(np.concatenate([t_span, t_eval]))


def _event_times(sol, count: int) -> list[np.ndarray]:
    """One array of crossing times per event function from CVODE's ``i_events``."""
    if not count:
        return []
    if sol.t_events is None:
        return [np.zeros(0) for _ in range(count)]
    hits = np.asarray(sol.i_events).reshape(-1, count)
    times = np.asarray(sol.t_events, dtype=float).ravel()
    return [times[hits[:, i] != 0] for i in range(count)]
