"""``simulate(..., method="generalized-alpha")``: large models on the compiled kernels.

A model of thousands of coordinates is integrated by the generalized-α method
(:mod:`rt70.simulation.generalized_alpha`) on the compiled equations of motion of the
book's model (:mod:`rt70.textbook.motion_kernel`): the residual
``A q̈ + B q̇ − Q_g − Q_c − Q_d − Q_u`` by Newton–Euler and the iteration matrix
``A + γ′h D + β′h² K`` by the articulated-body algorithm, with D and K the pairs' own
blocks of ``Σ JᵀDJ`` and ``Σ JᵀCJ`` (exact for a model whose bushings each act on one
pair, the book's elastic pairs; bushings across pairs, gravity's stiffness and the
velocity terms are left to Newton's iterations). Nothing of size nv² is formed, so memory
and work per step grow as nv. The energy audit is the same as the other methods':
T, U_g, U_c at every step, the dissipated energy and the inputs' work by the trapezoidal
rule on their power.

The kernels compute the textbook side's quantities (tested against it and against
Pinocchio on every scene they cover, :mod:`tests.test_motion_kernel`), and a run is
compared with BDF on the reference side in the tests.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from rt70.errors import Rt70Error, ShapeError, SimulationError
from rt70.guards.arrays import check_vector
from rt70.guards.resources import time_series_samples
from rt70.model.scene import Scene
from rt70.simulation.generalized_alpha import SPECTRAL_RADIUS, integrate
from rt70.simulation.integrators import GENERALIZED_ALPHA, budgeted
from rt70.simulation.request import run_compiled, uncovered
from rt70.simulation.result import (
    DRIFT_FACTOR,
    SimulationResult,
    coordinate_units,
    energy_balance,
    initial_energy_scale,
)
from rt70.textbook import articulated_kernel, motion_kernel
from rt70.textbook.spatial import check_euler_pairs

#: The method's name in :func:`rt70.simulation.simulate.simulate` and ``rt70 simulate``.
METHOD = GENERALIZED_ALPHA


class CompiledEquations:
    """The scene's equations for :func:`rt70.simulation.generalized_alpha.integrate`.

    Each residual records ``[T, U_g, U_c, P_d, P_u]``: the energies (J) and the dampers'
    and inputs' power (W).
    """

    def __init__(self, scene: Scene, inputs: Callable | None = None) -> None:
        self.model = scene.textbook
        self.data = motion_kernel.MotionData.of(self.model)
        if self.data is None or scene.description.loops:
            raise uncovered(scene, METHOD)
        self.nv, self.inputs = self.model.nv, inputs
        self.count: Callable = lambda t, x: None  # the run's budget (simulate_compiled)

    def residual(self, t: float, q: np.ndarray, v: np.ndarray, qdd: np.ndarray):
        """``(r, record)``: ``r = A q̈ + B q̇ − Q_g − Q_c − Q_d − Q_u`` and the record.

        Parameters
        ----------
        t : float
            Time, s (the inputs' argument).
        q, v, qdd : numpy.ndarray, shape (nv,)
            Coordinates, velocities and accelerations in the model's order.
        """
        self.count(t, None)
        r, energies = motion_kernel.residual(self.model, self.data, q, v, qdd)
        power = 0.0
        if self.inputs is not None:
            Q_u = np.asarray(self.inputs(t, q, v), dtype=float)
            if Q_u.shape != (self.nv,):
                raise ShapeError(f"inputs(t, q, qd): expected shape ({self.nv},), got {Q_u.shape}")
            r = r - Q_u
            power = float(v @ Q_u)
        if not np.isfinite(r).all():
            raise SimulationError("the equations of motion are not finite")
        return r, np.append(energies, power)

    def factor(self, q: np.ndarray, v: np.ndarray, c_v: float, c_q: float) -> None:
        """Factor ``A + c_v D + c_q K`` with the pairs' own blocks of D and K.

        Parameters
        ----------
        q, v : numpy.ndarray, shape (nv,)
            The state the matrix is taken at.
        c_v, c_q : float
            The weights of D (s) and K (s²).
        """
        K, D = motion_kernel.pair_gains(self.model, self.data, q)
        articulated_kernel.articulated_factor(self.model, self.data, q, c_v * D + c_q * K)

    def solve(self, r: np.ndarray) -> np.ndarray:
        """``S⁻¹ r`` with the last factor."""
        return articulated_kernel.articulated_solve(self.model, self.data, r)


def run(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None,
    tolerances: tuple[float, float | None],
    inputs: Callable | None,
    progress: bool,
    t_eval: np.ndarray | None,
    extras: dict,
) -> SimulationResult:
    """:func:`simulate_compiled` for :func:`rt70.simulation.simulate.simulate`'s arguments.

    Parameters
    ----------
    scene, t_span, x0, inputs, progress, t_eval
        As :func:`simulate_compiled` (checked by
        :func:`rt70.simulation.request.checked_request`).
    tolerances : (rtol, atol or None)
        ``atol`` defaults to ``1e-3 rtol`` (as the other methods').
    extras : dict
        ``components`` and ``events`` (refused unless empty) and ``outputs``:
        ``(outputs, side)``, the quantities evaluated on the trajectory by ``side``.
    """
    refused = {"components": extras["components"], "events": extras["events"]}
    return run_compiled(
        METHOD, scene, x0, tolerances, refused, extras["outputs"],
        lambda tol: simulate_compiled(scene, t_span, x0, tol, inputs, progress, t_eval),
    )  # fmt: skip


def simulate_compiled(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None,
    tolerances: tuple[float, float],
    inputs: Callable | None = None,
    progress: bool = False,
    t_eval: np.ndarray | None = None,
    rho: float = SPECTRAL_RADIUS,
) -> SimulationResult:
    """Integrate ``scene`` by the generalized-α method on the compiled kernels.

    Parameters
    ----------
    scene : Scene
        A scene the kernels cover (no modal bodies, mimic joints or loops).
    t_span : (t0, t1)
        Time interval, s.
    x0 : (q0, q̇0) or None
        Initial state (default rest at q = 0), in the file's coordinate order.
    tolerances : (rtol, atol)
        The local error of q per step (:func:`rt70.simulation.generalized_alpha.integrate`).
    inputs : callable (t, q, q̇) -> Q_u, optional
        Generalised input forces, N·m or N (taken at each iterate; not in the iteration
        matrix).
    progress : bool
        Show a progress bar (tqdm) on stderr.
    t_eval : numpy.ndarray, optional
        Output times, s, increasing within ``t_span``: the steps' cubic Hermite
        interpolants there (:func:`_sampled`); default every step.
    rho : float
        Spectral radius ρ∞ in [0, 1].
    """
    from tqdm import tqdm

    equations = CompiledEquations(scene, inputs)
    n = equations.nv
    q0, v0 = (np.zeros(n), np.zeros(n)) if x0 is None else x0
    q0, v0 = check_vector("initial state q0", q0, n), check_vector("initial state qd0", v0, n)
    check_euler_pairs(scene.textbook, scene.textbook.expand(q0))
    t0, t1 = map(float, t_span)
    # a sample per step (q, q̇, the audit's 2 states and 3 energies), a step at least one
    # evaluation: the samples memory holds and the budget in force bound the evaluations
    samples = time_series_samples(2 * n + 5)
    equations.count = budgeted(lambda t, x: None, t1 - t0, samples, t0)
    shape = "{l_bar}{bar}| {n:.3f}/{total:.3f} s [{elapsed}<{remaining}]"
    bar = tqdm(total=t1 - t0, disable=not progress, bar_format=shape)
    try:
        equations.residual(t0, q0, v0, np.zeros(n))  # loads the compiled kernels: not timed
        equations.factor(q0, v0, 0.0, 0.0)
        start = time.perf_counter()
        run = integrate(equations, (t0, t1), (q0, v0), tolerances, rho,
                        on_step=lambda t: bar.update(t - t0 - bar.n))  # fmt: skip
        wall = time.perf_counter() - start
    except Rt70Error as exc:
        raise type(exc)(f"{scene.name}: {exc}") from None
    finally:
        bar.close()
    t, q, qd, energies = _sampled(equations, run, t_eval)
    samples = (t, q, qd, energies)
    return _result(scene, run, samples, tolerances, (wall, rho), equations.inputs is None)


def _hermite(y0, y1, d0, d1, theta, h):
    """The cubic through (0, y0) and (1, y1) with slopes ``h d0`` and ``h d1`` at θ."""
    t2, t3 = theta * theta, theta * theta * theta
    return ((2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + theta) * h * d0
            + (3 * t2 - 2 * t3) * y1 + (t3 - t2) * h * d1)  # fmt: skip


def _sampled(equations: CompiledEquations, run, t_eval: np.ndarray | None) -> tuple:
    """``(t, q, q̇, [T, U_g, U_c, E_ψ, W_u])`` at every step, or at ``t_eval``.

    E_ψ and W_u by the trapezoidal rule on their power over the steps. At output times:
    q from the step's q and q̇, q̇ from its q̇ and q̈, E_ψ and W_u from their values and
    powers, by cubic Hermite interpolation (the method's own order); T, U_g and U_c of
    the interpolated state.
    """
    t, q, v, a = (np.array(x) for x in (run.t, run.q, run.v, run.qdd))
    T, U_g, U_c, P_d, P_u = np.array(run.records).T
    steps = np.diff(t)
    E_psi = np.r_[0.0, np.cumsum(0.5 * steps * (P_d[1:] + P_d[:-1]))]
    W_u = np.r_[0.0, np.cumsum(0.5 * steps * (P_u[1:] + P_u[:-1]))]
    if t_eval is None:
        return t, q, v, np.stack([T, U_g, U_c, E_psi, W_u])
    i = np.clip(np.searchsorted(t, t_eval, side="right") - 1, 0, t.size - 2)
    h = steps[i]
    theta = (t_eval - t[i]) / h
    qs = _hermite(q[i], q[i + 1], v[i], v[i + 1], theta[:, None], h[:, None])
    vs = _hermite(v[i], v[i + 1], a[i], a[i + 1], theta[:, None], h[:, None])
    E_s = _hermite(E_psi[i], E_psi[i + 1], P_d[i], P_d[i + 1], theta, h)
    W_s = _hermite(W_u[i], W_u[i + 1], P_u[i], P_u[i + 1], theta, h)
    zero = np.zeros(equations.nv)
    samples = zip(t_eval, qs, vs, strict=True)
    state = np.array([equations.residual(te, x, y, zero)[1][:3] for te, x, y in samples])
    return t_eval, qs, vs, np.stack([*state.T, E_s, W_s])


def _result(
    scene: Scene, run, samples: tuple, tolerances, clock, passive: bool
) -> SimulationResult:
    """The run as a :class:`SimulationResult` with its energy audit (module docstring).

    The drift of a ``passive`` run (no input forces) is flagged as the other methods'.
    """
    t, q, qd, (T, U_g, U_c, E_psi, W_u) = samples
    wall, rho = clock
    balance, exchanged = energy_balance(T, U_g, U_c, E_psi, W_u)
    rtol, atol = tolerances
    result = SimulationResult(
        scene=scene.name,
        side="compiled",
        method=f"{METHOD} ρ∞={rho:g}",
        rtol=rtol,
        atol=atol,
        t=t,
        q=q,
        qd=qd,
        kinetic=T,
        gravity=U_g,
        elastic=U_c,
        dissipated=E_psi,
        input_work=W_u,
        balance=balance,
        balance_scale=max(exchanged, initial_energy_scale(T[0], U_g[0], U_c[0])),
        nfev=run.evaluations,
        njev=run.factors,
        nlu=-1,  # the iteration matrix is factored by the articulated-body algorithm, no LU
        n_steps=run.n_steps,
        wall_time_s=wall,
        success=True,
        message=f"{run.n_steps} steps, {run.rejected} rejected",
        coordinates=list(scene.textbook.coordinate_names),
        states={"dissipated": E_psi, "input_work": W_u},
        timing={"integrator": wall},
        coordinate_units=coordinate_units(scene),
    )
    result.drift_flagged = passive and result.relative_drift > DRIFT_FACTOR * rtol
    return result
