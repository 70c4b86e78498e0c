"""The generalized-α method on ``A(q) q̈ = f(t, q, q̇)``, with step-size control.

Chung & Hulbert (*J. Appl. Mech.* 60, 1993) in the form of Arnold & Brüls (*Multibody
Syst. Dyn.* 18, 2007), which keeps the equations of motion exact at every step and
carries an acceleration-like variable ``a``:

    (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n
    q̇_{n+1} = q̇_n + h (1 − γ) a_n + h γ a_{n+1}
    q_{n+1} = q_n + h q̇_n + h² (½ − β) a_n + h² β a_{n+1}

with ``α_m = (2ρ∞ − 1)/(ρ∞ + 1)``, ``α_f = ρ∞/(ρ∞ + 1)``, ``γ = ½ + α_f − α_m``,
``β = ¼ (γ + ½)²``: second order, unconditionally stable on linear systems, damping the
modes the step cannot resolve towards the spectral radius ρ∞ and the resolved ones by
O((ωh)³). The unknown ``q̈_{n+1}`` is found by Newton on the residual
``r = A q̈ + B q̇ − Q``; ``∂q/∂q̈ = β′h²`` and ``∂q̇/∂q̈ = γ′h`` with
``β′ = β (1 − α_f)/(1 − α_m)``, ``γ′ = γ (1 − α_f)/(1 − α_m)``, so the iteration matrix is
``S = A + γ′h D + β′h² K``, which the problem factors (:class:`Problem`).

Why this method and not scipy's or SUNDIALS' (docs/performance.md): those integrate the
first-order form of 2 nv states with a dense 2 nv × 2 nv Jacobian (its LU took 2 s at
nv = 2004), while S is nv × nv and, for a tree whose springs act on single pairs, is
factored in O(nv) by the articulated-body algorithm
(:func:`rt70.textbook.articulated_kernel.articulated_factor`).

The step is controlled by the local errors of q and q̇, estimated against the
linear-acceleration update ``q_n + h q̇_n + h²/6 (2 q̈_n + q̈_{n+1})`` and the trapezoidal
rule ``q̇_n + h/2 (q̈_n + q̈_{n+1})`` (more accurate than the step, so that their
difference with it estimates its local error; for q, Zienkiewicz & Xie, *Earthquake Eng.
Struct. Dyn.* 20, 1991), in the weighted RMS norm of scipy's integrators
(``atol + rtol |x|``): a step is kept when it is at most 1. The next step follows
Gustafsson's PI controller, within [0.2 h, 2 h], without growth right after a rejection;
after a Newton failure the step is halved and capped there, the cap growing 2 % a step.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from rt70.errors import Rt70Error, SimulationError

#: Spectral radius at infinite frequency, ρ∞ (Exudyn's default for its generalized-α).
SPECTRAL_RADIUS = 0.9
#: A Newton iteration has converged when its correction of (q, q̇), in the weighted RMS
#: norm, is below this fraction of the error the step may make.
NEWTON_TOL = 0.03
#: A correction that stops shrinking while below this fraction of the error the step may
#: make has reached the rounding of the residual's terms (sums of forces far larger than
#: their result); the iterate is kept.
ROUND_OFF = 0.5
#: Newton iterations per step before the step is retried shorter.
NEWTON_MAX = 8
#: The next step's size is within these factors of the last one's.
FACTOR_MIN, FACTOR_MAX, SAFETY = 0.2, 2.0, 0.9
#: After Newton fails, the step shrinks by this factor, and is capped there; the cap grows
#: by ``CAP_GROWTH`` per accepted step, so that the method does not go back at once to
#: the size that failed.
NEWTON_SHRINK, CAP_GROWTH = 0.5, 1.02


@dataclass(frozen=True)
class Coefficients:
    """α_m, α_f, γ, β of the method for a spectral radius ρ∞ (module docstring)."""

    alpha_m: float
    alpha_f: float
    gamma: float
    beta: float

    @classmethod
    def of(cls, rho: float) -> Coefficients:
        """The coefficients for ρ∞ = ``rho`` in [0, 1]."""
        if not 0.0 <= rho <= 1.0:
            raise Rt70Error(f"the spectral radius ρ∞ must lie in [0, 1], got {rho!r}")
        am, af = (2.0 * rho - 1.0) / (rho + 1.0), rho / (rho + 1.0)
        gamma = 0.5 + af - am
        return cls(am, af, gamma, 0.25 * (gamma + 0.5) ** 2)

    @property
    def scaled(self) -> tuple[float, float]:
        """``(γ′, β′)``: ``∂q̇/∂q̈ = γ′h`` and ``∂q/∂q̈ = β′h²``."""
        k = (1.0 - self.alpha_f) / (1.0 - self.alpha_m)
        return self.gamma * k, self.beta * k


class Problem(Protocol):
    """What the method needs of the equations ``A(q) q̈ = f(t, q, q̇)``."""

    nv: int

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, qdd: np.ndarray):
        """``(r, record)``: ``r = A q̈ − f``, and what is recorded at each sample.

        Parameters
        ----------
        t : float
            Time, s.
        q, v, qdd : numpy.ndarray, shape (nv,)
            Coordinates, velocities and accelerations.
        """

    def factor(self, q: np.ndarray, v: np.ndarray, c_v: float, c_q: float) -> None:
        """Factor ``S = A + c_v D + c_q K`` at (q, q̇) (D, K: −∂f/∂q̇, −∂f/∂q, or parts).

        Parameters
        ----------
        q, v : numpy.ndarray, shape (nv,)
            The state the matrix is taken at.
        c_v, c_q : float
            The weights γ′h (s) and β′h² (s²).
        """

    def solve(self, r: np.ndarray) -> np.ndarray:
        """``S⁻¹ r`` with the last factor."""


@dataclass
class Trajectory:
    """The steps of a run: times, q, q̇, q̈, the problem's records; counts of the work."""

    t: list[float] = field(default_factory=list)
    q: list[np.ndarray] = field(default_factory=list)
    v: list[np.ndarray] = field(default_factory=list)
    qdd: list[np.ndarray] = field(default_factory=list)
    records: list[np.ndarray] = field(default_factory=list)
    n_steps: int = 0
    rejected: int = 0
    evaluations: int = 0
    factors: int = 0


@dataclass
class _State:
    t: float
    q: np.ndarray
    v: np.ndarray
    qdd: np.ndarray
    a: np.ndarray


def _weights(rtol: float, atol: float, *xs: np.ndarray) -> np.ndarray:
    return 1.0 / (atol + rtol * np.max(np.abs(np.stack(xs)), axis=0))


def _rms(x: np.ndarray, w: np.ndarray) -> float:
    return float(np.sqrt(np.mean((x * w) ** 2))) if x.size else 0.0


def _growth(err: float, previous: float) -> float:
    """The next step's factor: Gustafsson's PI control, ``err^(−0.7/3) previous^(0.4/3)``.

    (Hairer & Wanner, *Solving ODEs II*, §IV.8: the proportional term damps the
    oscillation of step sizes that the plain ``err^(−1/3)`` rule shows on stiff modes.)
    """
    if err == 0.0:
        return FACTOR_MAX
    return min(FACTOR_MAX, max(FACTOR_MIN, SAFETY * err ** (-0.7 / 3.0) * previous ** (0.4 / 3.0)))


def _step(problem: Problem, co: Coefficients, s: _State, h: float, tol, run: Trajectory):
    """One step of size h from ``s``: ``(state, record, error)``, or None if Newton fails."""
    rtol, atol = tol
    gp, bp = co.scaled
    t = s.t + h
    k = 1.0 / (1.0 - co.alpha_m)
    qdd = s.qdd.copy()
    base_a = k * (co.alpha_f * s.qdd - co.alpha_m * s.a)
    base_v = s.v + h * (1.0 - co.gamma) * s.a
    base_q = s.q + h * s.v + h * h * (0.5 - co.beta) * s.a
    problem.factor(s.q, s.v, gp * h, bp * h * h)
    run.factors += 1
    last = np.inf
    for _ in range(NEWTON_MAX):
        a = base_a + k * (1.0 - co.alpha_f) * qdd
        v = base_v + h * co.gamma * a
        q = base_q + h * h * co.beta * a
        r, _ = problem.residual(t, q, v, qdd)
        run.evaluations += 1
        dx = problem.solve(r)
        qdd -= dx
        size = max(_rms(bp * h * h * dx, _weights(rtol, atol, q)),
                   _rms(gp * h * dx, _weights(rtol, atol, v)))  # fmt: skip
        if not np.isfinite(size) or size > last and size > ROUND_OFF:
            return None  # diverges
        if size > last:
            break  # stalled below the tolerance: rounding of the residual's terms
        last = size
        if size <= NEWTON_TOL:
            break
    else:
        return None
    a = base_a + k * (1.0 - co.alpha_f) * qdd
    v = base_v + h * co.gamma * a
    q = base_q + h * h * co.beta * a
    r, record = problem.residual(t, q, v, qdd)  # the record at the converged state
    run.evaluations += 1
    e_q = q - s.q - h * s.v - h * h / 6.0 * (2.0 * s.qdd + qdd)  # against linear q̈
    e_v = v - s.v - 0.5 * h * (s.qdd + qdd)  # against the trapezoidal rule on q̈
    err = max(_rms(e_q, _weights(rtol, atol, s.q, q)), _rms(e_v, _weights(rtol, atol, s.v, v)))
    return _State(t, q, v, qdd, a), record, err


def _keep(run: Trajectory, s: _State, record: np.ndarray) -> None:
    """Append an accepted state and its record to the run."""
    run.t.append(s.t), run.q.append(s.q), run.v.append(s.v), run.qdd.append(s.qdd)
    run.records.append(record)


def _check_progress(t: float, t1: float, h: float, steps: int, max_steps: int | None) -> None:
    """Stop a run whose step underflows the time's spacing or that takes too many steps."""
    why = None
    if h < 16 * np.spacing(max(abs(t), abs(t1))):
        why = "the step size underflowed"
    elif max_steps and steps > max_steps:
        why = f"more than {max_steps} steps"
    if why:
        raise SimulationError(f"integration stopped at t = {t:.6g} s: {why}")


def integrate(
    problem: Problem,
    t_span: tuple[float, float],
    start: tuple[np.ndarray, np.ndarray],
    tolerances: tuple[float, float],
    rho: float = SPECTRAL_RADIUS,
    max_steps: int | None = None,
    on_step: Callable[[float], None] | None = None,
) -> Trajectory:
    """Integrate from ``start`` = (q0, q̇0) over ``t_span``; every accepted step is kept.

    Parameters
    ----------
    problem : Problem
        The equations: residual, factor, solve.
    t_span : (t0, t1)
        Time interval, s.
    start : (q0, q̇0)
        Initial coordinates and velocities, each shape (nv,).
    tolerances : (rtol, atol)
        The local errors of q and q̇ per step, in the weighted RMS norm
        ``atol + rtol |x|`` (module docstring).
    rho : float
        Spectral radius ρ∞ in [0, 1] (:data:`SPECTRAL_RADIUS`).
    max_steps : int, optional
        Stop with an error after this many steps (accepted and rejected).
    on_step : callable(t), optional
        Called after each accepted step (a progress bar).

    Raises
    ------
    SimulationError
        When the step size underflows or ``max_steps`` is exceeded; the time reached is
        named.
    """
    co = Coefficients.of(rho)
    t0, t1 = t_span
    q0, v0 = (np.array(x, dtype=float) for x in start)
    r0, record = problem.residual(t0, q0, v0, np.zeros(problem.nv))
    problem.factor(q0, v0, 0.0, 0.0)
    qdd0 = -problem.solve(r0)  # A q̈0 = f, exactly: the factor of A alone
    run = Trajectory(evaluations=1, factors=1)
    s = _State(t0, q0, v0, qdd0, qdd0.copy())
    _keep(run, s, record)
    scale = _rms(qdd0, _weights(*tolerances, q0))
    h = min(t1 - t0, 0.1 / np.sqrt(scale)) if scale > 0 else t1 - t0
    cap, rejected, previous = np.inf, False, 1.0
    while s.t < t1:
        h = t1 - s.t if t1 - s.t - h < 0.01 * h else h  # no sliver of a last step
        _check_progress(s.t, t1, h, run.n_steps, max_steps)
        out = _step(problem, co, s, h, tolerances, run)
        run.n_steps += 1
        if out is None:  # the iteration matrix is too far from the Jacobian at this h
            run.rejected += 1
            h *= NEWTON_SHRINK
            cap = h
            continue
        new, record, err = out
        if err > 1.0:
            run.rejected += 1
            h *= max(FACTOR_MIN, SAFETY * err ** (-1.0 / 3.0))
            rejected = True
            continue
        s = new
        if t1 - s.t <= 16 * np.spacing(abs(t1)):  # the end, but for rounding of t + h
            s.t = t1
        _keep(run, s, record)
        if on_step is not None:
            on_step(s.t)
        grow = _growth(err, previous)
        h *= min(grow, 1.0) if rejected else grow  # no growth right after a rejection
        rejected, previous = False, max(err, 1e-4)
        cap *= CAP_GROWTH
        h = min(h, cap)
    return run
