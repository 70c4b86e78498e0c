"""Time simulation of a scene with an energy audit (formalism §1, (1.73)).

Both sides (``side``, :mod:`rt70.model.sides`; their backends:
:mod:`rt70.simulation.backends`) integrate the same equations
``A q̈ + B q̇ = Q_g + Q_c + Q_d + Q_u``: the reference side by Pinocchio's ABA with the
spring and damper forces as ``tau``, the textbook side by the structured ``S Θ Sᵀ``
algorithm and a Cholesky solve. The state is ``[q, q̇]`` followed by the states of every
:class:`rt70.simulation.states.StateComponent`, integrated with it (not by quadrature of
samples). The first component is always the energy audit
(:class:`rt70.simulation.states.EnergyAudit`): the dissipated energy
``E_ψ = ∫ q̇ᵀ D q̇ dt = −∫ q̇ᵀ Q_d dt`` and the work of the inputs ``W_u = ∫ q̇ᵀ Q_u dt``.
Along any trajectory ``T + U_g + U_c + E_ψ − W_u`` is constant; its drift is reported
with every result (:class:`rt70.simulation.result.SimulationResult`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np

from rt70.errors import (
    Rt70Error,
    ShapeError,
    SimulationError,
    SingularConfigurationError,
)
from rt70.guards.arrays import check_vector
from rt70.guards.resources import check_time_series, time_series_samples
from rt70.model.outputs import Output, evaluate, evaluate_trajectory
from rt70.model.scene import Scene
from rt70.model.sides import refuses_backend
from rt70.physics.baumgarte import DEFAULT_STABILIZATION, Baumgarte
from rt70.simulation.backends import BACKENDS, Backend
from rt70.simulation.closed_chains import constrained_start, residual_trajectory
from rt70.simulation.coupling import Coupling
from rt70.simulation.integrators import (
    COMPILED_BDF,
    CVODE_METHODS,
    GENERALIZED_ALPHA,
    Integration,
    Stopwatch,
    budget_limit,
    integrate,
    load,
)
from rt70.simulation.request import ALL_METHODS, checked_request
from rt70.simulation.result import (
    DRIFT_FACTOR,
    SimulationResult,
    coordinate_units,
    energy_balance,
    initial_energy_scale,
)
from rt70.simulation.states import EnergyAudit, MechanicsForces, StateComponent, StateLayout
from rt70.textbook.massless import require_diagonal
from rt70.textbook.spatial import check_euler_pairs

#: Every method :func:`simulate` takes: scipy's, SUNDIALS', the compiled generalized-α.
METHODS = ALL_METHODS
#: solve_ivp methods that use the Jacobian of the right-hand side (CVODE's all do).
IMPLICIT = ("Radau", "BDF", "LSODA")

Inputs = Callable[[float, np.ndarray, np.ndarray], np.ndarray]
#: An event function g(t, q, q̇), with optional ``terminal`` and ``direction`` attributes.
Event = Callable[[float, np.ndarray, np.ndarray], float]


@refuses_backend
def simulate(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None = None,
    side: str = "reference",
    method: str = "BDF",
    rtol: float = 1e-6,
    atol: float | None = None,
    inputs: Inputs | None = None,
    t_eval: np.ndarray | None = None,
    progress: bool = False,
    outputs: Sequence[Output] = (),
    components: Sequence[StateComponent] = (),
    stabilization: Baumgarte | None = DEFAULT_STABILIZATION,
    events: Sequence[Event] = (),
) -> SimulationResult:
    """Integrate the scene's equations of motion over ``t_span``.

    Parameters
    ----------
    scene : Scene
        The scene (:func:`rt70.model.scene.load_scene`).
    t_span : (t0, t1)
        Time interval, s.
    x0 : (q0, q̇0), optional
        Initial state, each shape (nv,) in the file's coordinate order (rad or m, rad/s
        or m/s); default rest (the RT-70 listing's:
        :func:`rt70.scenes.rt70_state.listing_initial_state`).
    side : {"reference", "textbook"}
        Which side evaluates q̈ (:mod:`rt70.model.sides`) and whether the Jacobian is
        analytic (Pinocchio's) or differenced by the solver
        (:mod:`rt70.simulation.backends`).
    method : str
        Of :data:`METHODS`: scipy's, SUNDIALS' (:mod:`~.integrators`); on the compiled
        kernels, any side: generalized-alpha (:mod:`~.compiled_run`), compiled-BDF.
    rtol, atol : float
        Tolerances; ``atol`` defaults to ``1e-3 · rtol`` on q and q̇ (m, rad) and
        ``rtol`` of the initial energy scale on the two energy states.
    inputs : callable (t, q, q̇) -> Q_u, optional
        Generalised input forces (drives, wind), shape (nv,), N·m or N.
    t_eval : array, optional
        Output times, s, increasing within ``t_span`` (default: the solver's steps).
    progress : bool
        Show a progress bar (tqdm) on stderr.
    outputs : sequence of rt70.model.outputs.Output
        Quantities evaluated on the trajectory by ``side`` (checked at the start first), in
        ``result.outputs`` by name, arrays (n_t, size).
    components : sequence of StateComponent
        Extra states integrated with the mechanics after the energy audit's
        (:mod:`rt70.simulation.states`), in ``result.states`` by name.
    stabilization : rt70.physics.baumgarte.Baumgarte or None
        Gains of (2.2) for a scene with ``<rt70:loop>`` closures; None lets Φ drift
        (:func:`rt70.simulation.closed_chains.constrained_start` closes or checks x0).
    events : sequence of callable (t, q, q̇) -> float
        Zero crossings located, with the optional solve_ivp attributes ``terminal`` and
        ``direction``, for every method; their times in ``result.t_events``.
    """
    t0, t1, t_eval = checked_request(side, method, rtol, atol, t_span, t_eval, events)
    if method in (GENERALIZED_ALPHA, COMPILED_BDF):  # the compiled kernels
        extras = {"components": components, "events": events, "outputs": (outputs, side)}
        return _compiled(method)(scene, t_span, x0, (rtol, atol), inputs, progress, t_eval, extras)
    backend, q0, qd0 = _initial_state(scene, side, x0, stabilization)
    evaluate(scene, q0, outputs, side)  # refuses an unknown link before the run
    energy_scale = _energy_scale(scene, backend, q0, qd0)
    atol_q = 1e-3 * rtol if atol is None else atol
    layout = StateLayout([EnergyAudit(rtol * energy_scale), *components], backend.nv)
    _check_stiffness(scene, components, t1 - t0)
    atol_vec = np.concatenate([np.full(2 * backend.nv, atol_q), *layout.atol()])
    limit = _most_samples(scene, layout, outputs, t_eval)
    rhs = _RightHandSide(backend, layout, inputs, (t0, t1), progress)
    x_start = np.concatenate([q0, qd0, *layout.initial()])
    sol, clock = _integrate(scene, method, rhs, x_start, (rtol, atol_vec), t_eval, events, limit)
    result = _result(scene, method, (rtol, atol_q), sol, clock, rhs, energy_scale)
    passive = inputs is None and not rhs.pushed  # only a passive run's drift is flagged
    result.drift_flagged = passive and result.relative_drift > DRIFT_FACTOR * rtol
    result.outputs = evaluate_trajectory(scene, result.q, outputs, side)
    result.output_units = {o.name: o.unit for o in outputs}
    result.state_units = {n: c.unit(n) for c in layout.components for n in c.names}
    result.coordinate_units = coordinate_units(scene)
    return result


def _initial_state(
    scene: Scene,
    side: str,
    x0: tuple[np.ndarray, np.ndarray] | None,
    stabilization: Baumgarte | None,
) -> tuple[Backend, np.ndarray, np.ndarray]:
    """``(backend, q0, q̇0)``: the side's backend (with the scene's constraints), the start.

    Rest when ``x0`` is None; for a scene with loops the start is closed or checked
    (:func:`rt70.simulation.closed_chains.constrained_start`).
    """
    n = scene.textbook.nv
    if n == 0:
        raise SimulationError(f"{scene.name}: the model has no degree of freedom: nothing moves")
    backend, *closed = constrained_start(scene, BACKENDS[side](scene), x0, stabilization)
    q0, qd0 = (np.zeros(n), np.zeros(n)) if x0 is None else x0
    q0, qd0 = (q0, qd0) if closed[0] is None else closed
    q0 = check_vector("initial state q0", q0, n)
    qd0 = check_vector("initial state qd0", qd0, n)
    return backend, q0, qd0


def _energy_scale(scene: Scene, backend: Backend, q0: np.ndarray, qd0: np.ndarray) -> float:
    """The initial state's energy scale, J, after checking the start can be integrated.

    ``max(T + U_c, 10⁻¹² max(|U_g|, 1), 10⁻³⁰⁰)``: the energy audit's tolerances are
    ``rtol`` of it. Refuses Euler pairs at gimbal lock, a singular mass matrix
    (:func:`_check_mass_matrix`) and energies that overflow.
    """
    try:
        check_euler_pairs(scene.textbook, scene.textbook.expand(q0))
        _check_mass_matrix(scene, backend, q0)
        with np.errstate(over="ignore", invalid="ignore"):  # checked just below
            T0, Ug0, Uc0 = backend.energies(q0, qd0)
    except SingularConfigurationError as exc:  # same class, with the scene's name
        raise SingularConfigurationError(f"{scene.name}: at the initial state: {exc}") from None
    if not np.isfinite([T0, Ug0, Uc0]).all():
        raise SimulationError(
            f"{scene.name}: the energy at the initial state overflows (a stiffness or mass "
            "near the largest floating-point number?)"
        )
    return initial_energy_scale(T0, Ug0, Uc0)


def _most_samples(
    scene: Scene, layout: StateLayout, outputs: Sequence[Output], t_eval: np.ndarray | None
) -> int | None:
    """The most samples memory holds for a run without output times (None with them).

    With ``t_eval`` its samples are checked against memory at once; without, the run
    keeps one sample per step, each step at least one evaluation, and the integrator
    stops it at this many evaluations.
    """
    channels = sample_channels(layout.nv, layout.size, outputs)
    if t_eval is not None:
        check_time_series(t_eval.size, channels, "the output times", f"{scene.name}: t_eval")
        return None
    return time_series_samples(channels)


def _compiled(method: str) -> Callable[..., SimulationResult]:
    """The ``run`` of a method on the compiled kernels, its module imported for it (numba's).

    :func:`rt70.simulation.compiled_run.run` for the generalized-α method (large models),
    :func:`rt70.simulation.compiled_bdf.run` for scipy's BDF compiled (passive scenes).
    """
    if method == GENERALIZED_ALPHA:
        from rt70.simulation import compiled_run

        return compiled_run.run
    from rt70.simulation import compiled_bdf

    return compiled_bdf.run


class _RightHandSide:
    """``ẋ = f(t, x)`` of a run: q̇, q̈ of the backend and the extra states' derivatives.

    It records the last time it was evaluated at (``reached``, for the message of a
    failed run) and whether a component ever pushed a force on the mechanics
    (``pushed``: only a passive run's drift is flagged), and advances the progress bar
    ``bar`` (set by :func:`_integrate`).
    """

    def __init__(
        self,
        backend: Backend,
        layout: StateLayout,
        inputs: Inputs | None,
        t_span: tuple[float, float],
        progress: bool,
    ) -> None:
        self.backend, self.layout, self.inputs = backend, layout, inputs
        self.progress = progress
        self.n = backend.nv
        self.t0, self.t1 = t_span
        self.reached = self.t0
        self.pushed = False
        self.coupling: Coupling | None = None
        self.bar = None

    def input_force(self, t: float, x: np.ndarray) -> np.ndarray | None:
        """``Q_u``: the ``inputs`` callable's force plus the components', or None."""
        n = self.n
        q, qd = x[:n], x[n : 2 * n]
        Q_u = None
        if self.inputs is not None:
            Q_u = np.asarray(self.inputs(t, q, qd), dtype=float)
            if Q_u.shape != (n,):
                raise ShapeError(f"inputs(t, q, qd): expected shape ({n},), got shape {Q_u.shape}")
        Q_s = self.layout.force(t, q, qd, x) if self.layout.pushing else None
        if Q_s is not None:
            self.pushed = True
            Q_u = Q_s if Q_u is None else Q_u + Q_s
        return Q_u

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        self.reached = t
        n = self.n
        q, qd = x[:n], x[n : 2 * n]
        Q_u = self.input_force(t, x)
        qdd, Qd = self.backend.accelerations(q, qd, Q_u)
        bar = self.bar
        if self.progress and t - self.t0 > bar.n:
            bar.update(t - self.t0 - bar.n)
        extra = self.layout.derivatives(t, q, qd, x, MechanicsForces(Qd, Q_u))
        out = np.concatenate([qd, qdd, *extra])
        if not np.isfinite(out).all():
            raise SimulationError("the accelerations are not finite")
        return out

    def jacobian(self, t: float, x: np.ndarray) -> np.ndarray:
        """``∂ẋ/∂x``: the backend's analytic Jacobian, the components' couplings by differences.

        :mod:`rt70.simulation.coupling` (found at the first call); the rows of the
        components that push no force (the energy audit) are zero.
        """
        n, size = self.n, self.layout.size
        q, qd = x[:n], x[n : 2 * n]
        J = np.zeros((2 * n + size, 2 * n + size))
        Q_u = self.input_force(t, x)
        J[: 2 * n, : 2 * n] = self.backend.jacobian(q, qd, Q_u)
        if self.coupling is None:
            self.coupling = Coupling(self, t, x)
        if not self.coupling.empty:
            self.coupling.complete(J, self, t, x, Q_u)
        if not np.isfinite(J).all():
            raise SimulationError("the Jacobian of the right-hand side is not finite")
        return J


def _integrate(
    scene: Scene,
    method: str,
    rhs: _RightHandSide,
    x_start: np.ndarray,
    tolerances: tuple[float, np.ndarray],
    t_eval: np.ndarray | None,
    events: Sequence[Event],
    limit: int | None,
) -> tuple[Integration, tuple[float, dict[str, float]]]:
    """Run the integrator: its samples, and its wall time, s, with the split ``timing``.

    The implicit methods get the backend's analytic Jacobian where it has one. A state
    the model cannot be integrated beyond, or scipy's difference Jacobian overflowing,
    stops the run with the scene's name and the time reached.
    """
    from tqdm import tqdm

    n = rhs.n
    implicit = method in IMPLICIT or method in CVODE_METHODS
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # checked in jac
        analytic = (
            implicit and rhs.backend.jacobian(x_start[:n], x_start[n : 2 * n], None) is not None
        )
    rhs.bar = tqdm(  # on stderr; simulated time since t0
        total=rhs.t1 - rhs.t0,
        disable=not rhs.progress,
        bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} s [{elapsed}<{remaining}]",
    )
    rhs_clock, jac_clock = Stopwatch(rhs), Stopwatch(rhs.jacobian) if analytic else None
    load(method)  # the import is not part of the integration's wall time
    start = time.perf_counter()
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # checked above
            sol = integrate(
                method,
                rhs_clock,
                jac_clock,
                (rhs.t0, rhs.t1),
                x_start,
                *tolerances,
                t_eval,
                [_state_event(g, n) for g in events],
                max_evaluations=limit,
            )
    except (Rt70Error, ValueError) as exc:
        # Rt70Error: the model cannot be integrated beyond this state; ValueError "array
        # must not contain infs or NaNs": scipy's difference Jacobian overflowed
        if not isinstance(exc, Rt70Error) and "inf" not in str(exc):
            raise
        kind = type(exc) if isinstance(exc, Rt70Error) else SimulationError
        raise kind(f"{scene.name}: integration stopped at t = {rhs.reached:.6g} s: {exc}") from None
    finally:
        rhs.bar.close()
    wall = time.perf_counter() - start
    spent = {"rhs": rhs_clock.seconds, "jacobian": 0.0 if jac_clock is None else jac_clock.seconds}
    if sol.t.size == 0:
        raise SimulationError(
            f"{scene.name}: integration failed before the first output time: {sol.message}"
        )
    return sol, (wall, {**spent, "integrator": wall - spent["rhs"] - spent["jacobian"]})


def _result(
    scene: Scene,
    method: str,
    tolerances: tuple[float, float],
    sol: Integration,
    clock: tuple[float, dict[str, float]],
    rhs: _RightHandSide,
    energy_scale: float,
) -> SimulationResult:
    """The run's samples with their energy audit and the solver's statistics.

    The balance ``T + U_g + U_c + E_ψ − W_u`` less its initial value, and its scale: the
    largest energy exchanged in the run (mechanical energy, dissipated energy, input
    work), at least the initial energy scale.
    """
    n, backend = rhs.n, rhs.backend
    q, qd = sol.y[:n].T, sol.y[n : 2 * n].T
    energies = np.array([backend.energies(a, b) for a, b in zip(q, qd, strict=True)])
    states = rhs.layout.read(sol.y)
    E_psi, W_u = states["dissipated"], states["input_work"]
    balance, exchanged = energy_balance(*energies.T, E_psi, W_u)
    rtol, atol = tolerances
    wall, timing = clock
    return SimulationResult(
        scene=scene.name,
        side=backend.side,
        method=method,
        rtol=rtol,
        atol=atol,
        t=sol.t,
        q=q,
        qd=qd,
        kinetic=energies[:, 0],
        gravity=energies[:, 1],
        elastic=energies[:, 2],
        dissipated=E_psi,
        input_work=W_u,
        balance=balance,
        balance_scale=max(exchanged, energy_scale),
        nfev=sol.nfev,
        njev=sol.njev,
        nlu=sol.nlu,
        n_steps=sol.n_steps,
        wall_time_s=wall,
        success=sol.success,
        message=sol.message,
        coordinates=list(scene.textbook.coordinate_names),
        states=states,
        constraint_residual=residual_trajectory(backend, q),
        t_events=sol.t_events,
        timing=timing,
    )


def _check_stiffness(scene: Scene, components: Sequence[StateComponent], span: float) -> None:
    """Refuse components too stiff to integrate within the evaluation budget in force.

    A component with a ``fastest_rate()`` (a drive:
    :meth:`rt70.control.drives.DcDrive.fastest_rate`) needs about ``rate · span`` steps, its
    states being treated explicitly by the implicit methods' Jacobian
    (:mod:`rt70.simulation.states`); a run that would need more than the budget
    (:func:`rt70.simulation.integrators.budget_limit`) is refused before it starts.
    """
    limit = budget_limit(span)
    if limit is None:
        return
    for c in components:
        if not hasattr(c, "fastest_rate"):
            continue
        rate, label = c.fastest_rate()
        if rate * span > limit:
            name = c.names[0].split(":")[0]
            raise SimulationError(
                f"{scene.name}: drive '{name}' is too stiff for this run: its rate {label} = "
                f"{rate:.3g} 1/s needs about {rate * span:.3g} steps over {span:g} s, more "
                f"than the evaluation budget ({limit}); check its parameters"
            )


def sample_channels(nv: int, extra_states: int, outputs: Sequence[Output] = ()) -> int:
    """Values a run keeps per sample: q, q̇, the extra states, three energies, the outputs.

    Parameters
    ----------
    nv : int
        Number of coordinates (q and q̇ take ``2 nv``).
    extra_states : int
        Number of extra states (the energy audit's two and every component's).
    outputs : sequence of rt70.model.outputs.Output
        The outputs evaluated on the trajectory (``size`` values each).
    """
    return 2 * nv + extra_states + 3 + sum(o.size for o in outputs)


def _state_event(g: Event, n: int) -> Callable[[float, np.ndarray], float]:
    """The event ``g(t, q, q̇)`` as a function of the state, its attributes kept."""

    def event(t, x):
        return float(g(t, x[:n], x[n : 2 * n]))

    event.terminal = getattr(g, "terminal", False)
    event.direction = getattr(g, "direction", 0.0)
    return event


def _check_mass_matrix(scene: Scene, backend: Backend, q0: np.ndarray) -> None:
    """Refuse a model whose mass matrix is singular at the initial state.

    A coordinate that moves no mass has a zero diagonal entry; it is named. (Euler pairs
    at gimbal lock are refused before, by ``check_euler_pairs``.)
    """
    A = backend.mass_matrix(q0)
    if not np.isfinite(A).all():
        raise SimulationError(f"{scene.name}: the mass matrix is not finite at the initial state")
    require_diagonal(A, scene.textbook.coordinate_names, f"{scene.name}: ", SimulationError)
    try:
        np.linalg.cholesky(A)
    except np.linalg.LinAlgError:
        raise SimulationError(
            f"{scene.name}: the mass matrix is not positive definite at the initial state"
        ) from None
