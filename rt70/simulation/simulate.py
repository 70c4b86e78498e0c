"""Time simulation of a scene with an energy audit (formalism §1, (1.73)).

Both backends integrate the same equations ``A q̈ + B q̇ = Q_g + Q_c + Q_d + Q_u``: the
Pinocchio backend by ABA with the spring and damper forces as ``tau``, the textbook
backend by the structured ``S Θ Sᵀ`` algorithm and a Cholesky solve. The state is
``[q, q̇]`` followed by the states of every :class:`rt70.simulation.states.StateComponent`,
integrated with it (not by quadrature of samples). The first component is always the
energy audit (:class:`rt70.simulation.states.EnergyAudit`): the dissipated energy
``E_ψ = ∫ q̇ᵀ D q̇ dt = −∫ q̇ᵀ Q_d dt`` and the work of the inputs ``W_u = ∫ q̇ᵀ Q_u dt``.
Along any trajectory ``T + U_g + U_c + E_ψ − W_u`` is constant; its drift is reported
with every result.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rt70.errors import (
    OutputError,
    Rt70Error,
    ShapeError,
    SimulationError,
    SingularConfigurationError,
)
from rt70.guards.arrays import check_vector
from rt70.guards.resources import check_time_series, time_series_samples
from rt70.model.outputs import Output, column_labels, evaluate, evaluate_trajectory
from rt70.model.scene import Scene
from rt70.physics.baumgarte import DEFAULT_STABILIZATION, Baumgarte
from rt70.simulation.closed_chains import constrained_start, residual_trajectory
from rt70.simulation.integrators import (
    CVODE_METHODS,
    METHODS,
    Stopwatch,
    budget_limit,
    integrate,
    load,
)
from rt70.simulation.states import EnergyAudit, MechanicsForces, StateComponent, StateLayout
from rt70.textbook.massless import require_diagonal
from rt70.textbook.spatial import DYNAMICS_GIMBAL_COS, check_euler_pairs, euler_theta_indices

#: Smallest rtol solve_ivp honours (it raises smaller ones to 100 machine epsilons).
MIN_RTOL = 100 * np.finfo(float).eps
#: Output formats of :meth:`SimulationResult.save`, by suffix.
OUTPUT_SUFFIXES = (".csv", ".npz")
#: solve_ivp methods that use the Jacobian of the right-hand side (CVODE's all do).
IMPLICIT = ("Radau", "BDF", "LSODA")
#: A drift of the energy balance larger than this many times rtol (relative to the energy
#: exchanged during the run) is flagged: more than the tolerance explains.
DRIFT_FACTOR = 100.0

Inputs = Callable[[float, np.ndarray, np.ndarray], np.ndarray]
#: An event function g(t, q, q̇), with optional ``terminal`` and ``direction`` attributes.
Event = Callable[[float, np.ndarray, np.ndarray], float]


class _Backend:
    """Right-hand side, Jacobian and energies of one side of the cross-check."""

    name = ""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.nv = scene.textbook.nv

    def accelerations(self, q, qd, Q_u) -> tuple[np.ndarray, np.ndarray]:  # q̈, Q_d
        raise NotImplementedError

    def mass_matrix(self, q) -> np.ndarray:  # A(q) in the textbook's coordinate order
        raise NotImplementedError

    def jacobian(self, q, qd, Q_u) -> np.ndarray | None:  # ∂(q̇, q̈)/∂(q, q̇) or None
        return None

    def energies(self, q, qd) -> tuple[float, float, float]:  # T, U_g, U_c
        raise NotImplementedError


class _PinocchioBackend(_Backend):
    """Pinocchio's ABA with springs as tau; analytic Jacobian from computeABADerivatives.

    The springs and dampers come from the compiled kernels of
    :mod:`rt70.reference.element_kernels` where the model allows (the same forces as
    :mod:`rt70.reference.forces`, tested); ``kernels=False`` keeps the Python path.
    """

    name = "pinocchio"

    def __init__(self, scene: Scene, kernels: bool = True) -> None:
        super().__init__(scene)
        import pinocchio as pin

        from rt70 import reference

        self.pin, self.reference = pin, reference
        self.ref, self.rd = scene.reference, scene.reference_data
        self.direct = self.ref.identity_map  # book coordinates are Pinocchio's (q, v)
        self.theta = euler_theta_indices(scene.textbook)
        self.kernels = None
        if kernels and self.direct and (self.ref.bushings or self.ref.spring_v.size):
            from rt70.reference.element_kernels import ElementKernels

            guard = lambda q: check_euler_pairs(scene.textbook, q)  # noqa: E731
            self.kernels = ElementKernels.of(self.ref, (self.theta, DYNAMICS_GIMBAL_COS, guard))

    def mass_matrix(self, q):
        return self.reference.mass_matrix(self.ref, self.rd, q)

    def _check_pairs(self, q) -> None:
        """check_euler_pairs, vectorised for the common case that nothing is near lock."""
        q_full = self.scene.textbook.expand(q)
        if self.theta.size and np.min(np.abs(np.cos(q_full[self.theta]))) < DYNAMICS_GIMBAL_COS:
            check_euler_pairs(self.scene.textbook, q_full)

    def torques(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper forces τ_c, τ_d in Pinocchio's velocity space."""
        if self.kernels is not None:
            return self.kernels.torques(q, qd)
        return self.reference.element_torques(self.ref, self.rd, q, qd)

    def accelerations(self, q, qd, Q_u):
        if self.kernels is None:  # the kernels check the pairs themselves
            self._check_pairs(q)
        reference, ref, rd = self.reference, self.ref, self.rd
        if not self.direct:  # general coordinates: through the book-coordinate map
            a = reference.forward_dynamics(ref, rd, q, qd)
            _, Qd = reference.spring_damper_force(ref, rd, q, qd)
            if Q_u is not None:
                a = a + np.linalg.solve(reference.mass_matrix(ref, rd, q), Q_u)
            return a, Qd
        Qc, Qd = self.torques(q, qd)
        tau = Qc + Qd if Q_u is None else Qc + Qd + Q_u
        return self.pin.aba(ref.pin_model, rd.pin_data, q, qd, tau), Qd

    def jacobian(self, q, qd, Q_u):
        if not self.direct:
            return None
        reference, ref, rd, pin = self.reference, self.ref, self.rd, self.pin
        if self.kernels is not None:
            Qc, Qd, Kc, Dc = self.kernels.torques_and_gains(q, qd)
        else:
            Qc, Qd = reference.element_torques(ref, rd, q, qd)
            Kc, Dc = reference.element_gains(ref, rd, q)
        tau = Qc + Qd if Q_u is None else Qc + Qd + Q_u
        dq, dv, Minv = pin.computeABADerivatives(ref.pin_model, rd.pin_data, q, qd, tau)
        n = self.nv
        J = np.zeros((2 * n, 2 * n))
        J[:n, n:] = np.eye(n)
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        J[n:, :n] = dq - Minv @ Kc
        J[n:, n:] = dv - Minv @ Dc
        return J

    def energies(self, q, qd):
        reference, ref, rd = self.reference, self.ref, self.rd
        if self.kernels is not None:
            U_c = self.kernels.potential(q)
        else:
            U_c = reference.spring_potential(ref, rd, q)
        return (
            reference.kinetic_energy(ref, rd, q, qd),
            reference.gravity_potential(ref, rd, q),
            U_c,
        )


class _TextbookBackend(_Backend):
    """The structured S Θ Sᵀ algorithm; the Jacobian by finite differences (scipy's)."""

    name = "textbook"

    def __init__(self, scene: Scene) -> None:
        super().__init__(scene)
        from rt70.textbook import structured

        scene.textbook_data  # noqa: B018  (its memory guard covers the structured form too)
        self.structured = structured
        self.bdata = structured.BatchData(scene.textbook, 1)

    def mass_matrix(self, q):
        return self.structured.mass_matrix(self.scene.textbook, self.bdata, q)

    def system(self, q, qd, Q_u) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, f, Q_d)`` of ``A q̈ = f``: f = gravity, springs, dampers, inputs − B q̇."""
        from rt70.textbook import forces

        st, model = self.structured, self.scene.textbook
        check_euler_pairs(model, model.expand(q))
        A = st.mass_matrix(model, self.bdata, q)
        Qc, Qd = forces.spring_damper_force(model, self.scene.textbook_data, q, qd)
        rhs = st.gravity_force_batch(model, self.bdata, q[None])[0] + Qc + Qd
        rhs -= st.bias_force(model, self.bdata, q, qd)
        if Q_u is not None:
            rhs += Q_u
        return A, rhs, Qd

    def accelerations(self, q, qd, Q_u):
        import scipy.linalg

        A, rhs, Qd = self.system(q, qd, Q_u)
        try:
            factor = scipy.linalg.cho_factor(A)
        except np.linalg.LinAlgError:
            raise Rt70Error(f"{self.scene.name}: mass matrix not positive definite") from None
        return scipy.linalg.cho_solve(factor, rhs), Qd

    def energies(self, q, qd):
        from rt70.textbook import forces

        model, data = self.scene.textbook, self.scene.textbook_data
        return (
            forces.kinetic_energy(model, data, q, qd),
            forces.gravity_potential(model, data, q),
            forces.spring_potential(model, data, q),
        )


BACKENDS = {"pinocchio": _PinocchioBackend, "textbook": _TextbookBackend}


@dataclass
class SimulationResult:
    """Trajectory, energies and solver statistics of one run.

    Energies in J: ``kinetic`` T, ``gravity`` U_g, ``elastic`` U_c, ``dissipated`` E_ψ,
    ``input_work`` W_u; ``balance = T + U_g + U_c + E_ψ − W_u − (its value at t0)`` and
    ``balance_scale`` the energy exchanged in the run (what ``relative_drift`` is
    relative to). ``drift_flagged`` is set when a passive run drifts by more than
    ``DRIFT_FACTOR · rtol`` of it. ``states`` holds the trajectory of every extra state
    by name (:mod:`rt70.simulation.states`; the energy audit's ``dissipated`` and ``input_work``
    first). ``constraint_residual`` is ``max |Φ|`` per sample for a scene with closed
    chains (:mod:`rt70.simulation.closed_chains`), empty otherwise. ``t_events`` holds the times
    at which each of the ``events`` of :func:`simulate` crossed zero. ``timing`` splits
    ``wall_time_s``: "rhs" (s inside the right-hand side, including the calls of a
    difference-quotient Jacobian), "jacobian" (s inside the analytic Jacobian) and
    "integrator" (the rest: the solver's own work, its linear algebra included).
    ``nlu`` is −1 where the solver does not report it (CVODE), ``n_steps`` −1 when
    ``t_eval`` was given.
    """

    scene: str
    backend: str
    method: str
    rtol: float
    atol: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    kinetic: np.ndarray
    gravity: np.ndarray
    elastic: np.ndarray
    dissipated: np.ndarray
    input_work: np.ndarray
    balance: np.ndarray
    balance_scale: float
    nfev: int
    njev: int
    nlu: int
    n_steps: int
    wall_time_s: float
    success: bool
    message: str
    coordinates: list[str] = field(default_factory=list)
    drift_flagged: bool = False
    outputs: dict[str, np.ndarray] = field(default_factory=dict)
    states: dict[str, np.ndarray] = field(default_factory=dict)
    constraint_residual: np.ndarray = field(default_factory=lambda: np.zeros(0))
    t_events: list[np.ndarray] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)

    @property
    def relative_drift(self) -> float:
        """Largest |balance| over the run, relative to ``balance_scale``."""
        return float(np.max(np.abs(self.balance)) / self.balance_scale)

    @property
    def real_time_factor(self) -> float:
        """Simulated time per wall-clock second."""
        return float((self.t[-1] - self.t[0]) / self.wall_time_s)

    def save(self, path: str | Path) -> Path:
        """Write the result atomically: ``.npz`` (all arrays) or ``.csv`` (a table)."""
        from rt70.guards.atomic import atomic_write

        return atomic_write(path, self.writer(path))

    def writer(self, path: str | Path) -> Callable[[Path], None]:
        """The function that writes the result to a (temporary) file, in ``path``'s format.

        For :func:`rt70.guards.atomic.atomic_write_all`, to write it together with other files.

        Raises
        ------
        OutputError
            If ``path`` does not end in one of :data:`OUTPUT_SUFFIXES`.
        """
        suffix = check_output_suffix(path)
        if suffix == ".npz":
            arrays = {
                k: getattr(self, k)
                for k in ("t", "q", "qd", "kinetic", "gravity", "elastic", "dissipated")
            }
            arrays.update(input_work=self.input_work, balance=self.balance)
            arrays.update({f"state:{k}": v for k, v in self._component_states().items()})
            arrays["coordinates"] = np.array(self.coordinates)
            if self.constraint_residual.size:  # closed chains: max |Φ| per sample
                arrays["constraint_residual"] = self.constraint_residual
            arrays.update({f"output:{k}": v for k, v in self.outputs.items()})
            return lambda tmp: np.savez_compressed(tmp, **arrays)
        extra = self._component_states()
        names = ["t"] + [f"q:{c}" for c in self.coordinates] + [f"qd:{c}" for c in self.coordinates]
        names += ["kinetic", "gravity", "elastic", "dissipated", "input_work", "balance"]
        names += [f"state:{k}" for k in extra]
        table = np.column_stack(
            [self.t, self.q, self.qd, self.kinetic, self.gravity, self.elastic]
            + [self.dissipated, self.input_work, self.balance, *extra.values()]
        )
        if self.constraint_residual.size:  # closed chains: max |Φ| per sample
            names.append("constraint_residual")
            table = np.column_stack([table, self.constraint_residual])
        for name, values in self.outputs.items():  # rt70.model.outputs, one column per component
            names += column_labels(name, values.shape[1])
            table = np.column_stack([table, values])
        lines = [",".join(names)] + [",".join(f"{x:.17g}" for x in row) for row in table]
        text = "\n".join(lines) + "\n"
        return lambda tmp: tmp.write_text(text, encoding="utf-8", newline="\n")

    def _component_states(self) -> dict[str, np.ndarray]:
        """The extra states other than the energy audit's (written as ``state:<name>``)."""
        return {k: v for k, v in self.states.items() if k not in EnergyAudit.names}


def check_output_suffix(path: str | Path) -> str:
    """The suffix of an output path, one of :data:`OUTPUT_SUFFIXES`, or an OutputError."""
    suffix = Path(path).suffix
    if suffix not in OUTPUT_SUFFIXES:
        raise OutputError(f"{path}: output must end in {' or '.join(OUTPUT_SUFFIXES)}")
    return suffix


def simulate(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None = None,
    backend: str = "pinocchio",
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
        Initial state; default rest (q = 0, q̇ = 0). The RT-70 listing's state is
        :func:`rt70.scenes.rt70_state.listing_initial_state`.
    backend : {"pinocchio", "textbook"}
        Which implementation evaluates q̈ (and, for "pinocchio", the analytic Jacobian
        ``∂q̈/∂(q, q̇)`` of ``computeABADerivatives`` plus the springs' ``Σ JᵀCJ``,
        ``Σ JᵀDJ``; the textbook backend lets scipy difference the right-hand side).
    method : str
        A ``scipy.integrate.solve_ivp`` method or "CVODE" / "CVODE_ADAMS" (SUNDIALS;
        :data:`METHODS`, :mod:`rt70.simulation.integrators`).
    rtol, atol : float
        Tolerances; ``atol`` defaults to ``1e-3 · rtol`` on q and q̇ (m, rad) and
        ``rtol`` of the initial energy scale on the two energy states.
    inputs : callable (t, q, q̇) -> Q_u, optional
        Generalised input forces (drives, wind).
    t_eval : array, optional
        Output times (default: the solver's steps).
    progress : bool
        Show a progress bar (tqdm) on stderr.
    components : sequence of StateComponent
        Extra states integrated with the mechanics, after the energy audit's
        (:mod:`rt70.simulation.states`); their trajectories are in ``result.states`` by name.
    outputs : sequence of rt70.model.outputs.Output
        Quantities evaluated on the trajectory by the backend's side (e.g.
        :func:`rt70.model.outputs.optical_point_outputs`), in ``result.outputs`` by name,
        arrays (n_t, size); checked at the initial state before the run.
    stabilization : rt70.physics.baumgarte.Baumgarte or None
        For a scene with ``<rt70:loop>`` closures (:mod:`rt70.simulation.closed_chains`): the gains
        of the perturbation equations (2.2); None integrates ``Φ̈ = 0`` and lets Φ
        drift. The start is assembled from rest (x0 None) or must be closed; the
        residual ``max |Φ|`` is in ``result.constraint_residual``.
    events : sequence of callable (t, q, q̇) -> float
        Functions whose zero crossings are located (e.g. a brake engaging), with the
        optional attributes ``terminal`` (stop there) and ``direction`` of solve_ivp,
        for every method; the times are in ``result.t_events``, one array per function.
    """
    from tqdm import tqdm

    if backend not in BACKENDS:
        raise Rt70Error(f"unknown backend '{backend}' (choose from {', '.join(BACKENDS)})")
    if method not in METHODS:
        raise Rt70Error(f"unknown method '{method}' (choose from {', '.join(METHODS)})")
    if not all(callable(g) for g in events):
        raise Rt70Error("events must be callables g(t, q, qd)")
    if not (np.isfinite(rtol) and MIN_RTOL <= rtol < 1.0):
        raise Rt70Error(f"rtol must lie in [{MIN_RTOL:.3g}, 1), got {rtol!r}")
    if atol is not None and not (np.isfinite(atol) and atol > 0.0):
        raise Rt70Error(f"atol must be a positive finite number, got {atol!r}")
    t0, t1 = map(float, t_span)
    if not (np.isfinite(t0) and np.isfinite(t1) and t1 > t0):
        raise Rt70Error(f"bad time span {t_span!r}")
    if t_eval is not None:
        t_eval = np.asarray(t_eval, dtype=float)
        if t_eval.ndim != 1 or not np.all((t_eval >= t0) & (t_eval <= t1)):
            raise Rt70Error(f"t_eval must be a vector of times within [{t0:g}, {t1:g}]")
        if np.any(np.diff(t_eval) <= 0.0):
            raise Rt70Error("t_eval must be increasing")
    n = scene.textbook.nv
    if n == 0:
        raise SimulationError(f"{scene.name}: the model has no degree of freedom: nothing moves")
    side, *closed = constrained_start(scene, BACKENDS[backend](scene), x0, stabilization)
    q0, qd0 = (np.zeros(n), np.zeros(n)) if x0 is None else x0
    q0, qd0 = (q0, qd0) if closed[0] is None else closed
    q0 = check_vector("initial state q0", q0, n)
    qd0 = check_vector("initial state qd0", qd0, n)
    output_side = "reference" if backend == "pinocchio" else "textbook"
    evaluate(scene, q0, outputs, output_side)  # refuses an unknown link before the run
    try:
        check_euler_pairs(scene.textbook, scene.textbook.expand(q0))
        _check_mass_matrix(scene, side, q0)
        with np.errstate(over="ignore", invalid="ignore"):  # checked just below
            T0, Ug0, Uc0 = side.energies(q0, qd0)
    except SingularConfigurationError as exc:  # same class, with the scene's name
        raise SingularConfigurationError(f"{scene.name}: at the initial state: {exc}") from None
    if not np.isfinite([T0, Ug0, Uc0]).all():
        raise SimulationError(
            f"{scene.name}: the energy at the initial state overflows (a stiffness or mass "
            "near the largest floating-point number?)"
        )
    energy_scale = max(T0 + Uc0, 1e-12 * max(abs(Ug0), 1.0), 1e-300)
    atol_q = 1e-3 * rtol if atol is None else atol
    layout = StateLayout([EnergyAudit(rtol * energy_scale), *components], n)
    _check_stiffness(scene, components, t1 - t0)
    atol_vec = np.concatenate([np.full(2 * n, atol_q), *layout.atol()])
    channels = sample_channels(n, layout.size, outputs)
    most_samples = None
    if t_eval is not None:
        check_time_series(t_eval.size, channels, "the output times", f"{scene.name}: t_eval")
    else:  # one sample per step, each step at least one evaluation
        most_samples = time_series_samples(channels)
    reached = [t0]  # the last time the right-hand side was evaluated at
    pushed = [False]  # whether a component ever pushed a force on the mechanics

    def input_force(t, x):
        q, qd = x[:n], x[n : 2 * n]
        Q_u = None
        if inputs is not None:
            Q_u = np.asarray(inputs(t, q, qd), dtype=float)
            if Q_u.shape != (n,):
                raise ShapeError(f"inputs(t, q, qd): expected shape ({n},), got shape {Q_u.shape}")
        Q_s = layout.force(t, q, qd, x) if layout.pushing else None
        if Q_s is not None:
            pushed[0] = True
            Q_u = Q_s if Q_u is None else Q_u + Q_s
        return Q_u

    def rhs(t, x):
        reached[0] = t
        q, qd = x[:n], x[n : 2 * n]
        Q_u = input_force(t, x)
        qdd, Qd = side.accelerations(q, qd, Q_u)
        if progress and t - t0 > bar.n:
            bar.update(t - t0 - bar.n)
        extra = layout.derivatives(t, q, qd, x, MechanicsForces(Qd, Q_u))
        out = np.concatenate([qd, qdd, *extra])
        if not np.isfinite(out).all():
            raise SimulationError("the accelerations are not finite")
        return out

    jac = None
    implicit = method in IMPLICIT or method in CVODE_METHODS
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # checked in jac
        analytic = implicit and side.jacobian(q0, qd0, None) is not None
    if analytic:

        def jac(t, x):
            q, qd = x[:n], x[n : 2 * n]
            J = np.zeros((2 * n + layout.size, 2 * n + layout.size))  # zero for extra states
            J[: 2 * n, : 2 * n] = side.jacobian(q, qd, input_force(t, x))
            if not np.isfinite(J).all():
                raise SimulationError("the Jacobian of the right-hand side is not finite")
            return J

    bar = tqdm(  # on stderr; simulated time since t0
        total=t1 - t0,
        disable=not progress,
        bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} s [{elapsed}<{remaining}]",
    )
    rhs_clock, jac_clock = Stopwatch(rhs), None if jac is None else Stopwatch(jac)
    load(method)  # the import is not part of the integration's wall time
    start = time.perf_counter()
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # checked above
            sol = integrate(
                method,
                rhs_clock,
                jac_clock,
                (t0, t1),
                np.concatenate([q0, qd0, *layout.initial()]),
                rtol,
                atol_vec,
                t_eval,
                [_state_event(g, n) for g in events],
                max_evaluations=most_samples,
            )
    except (Rt70Error, ValueError) as exc:
        # Rt70Error: the model cannot be integrated beyond this state; ValueError "array
        # must not contain infs or NaNs": scipy's difference Jacobian overflowed
        if not isinstance(exc, Rt70Error) and "inf" not in str(exc):
            raise
        kind = type(exc) if isinstance(exc, Rt70Error) else SimulationError
        raise kind(f"{scene.name}: integration stopped at t = {reached[0]:.6g} s: {exc}") from None
    finally:
        bar.close()
    wall = time.perf_counter() - start
    spent = {"rhs": rhs_clock.seconds, "jacobian": 0.0 if jac_clock is None else jac_clock.seconds}
    timing = {**spent, "integrator": wall - spent["rhs"] - spent["jacobian"]}
    if sol.t.size == 0:
        raise SimulationError(
            f"{scene.name}: integration failed before the first output time: {sol.message}"
        )
    q, qd = sol.y[:n].T, sol.y[n : 2 * n].T
    energies = np.array([side.energies(a, b) for a, b in zip(q, qd, strict=True)])
    states = layout.read(sol.y)
    E_psi, W_u = states["dissipated"], states["input_work"]
    total = energies.sum(axis=1) + E_psi - W_u
    balance = total - total[0]
    mech = energies[:, 0] + energies[:, 2]
    exchanged = max(float(np.max(mech)), float(E_psi[-1]), float(np.max(np.abs(W_u))))
    scale = max(exchanged, energy_scale)
    result = SimulationResult(
        scene=scene.name,
        backend=backend,
        method=method,
        rtol=rtol,
        atol=atol_q,
        t=sol.t,
        q=q,
        qd=qd,
        kinetic=energies[:, 0],
        gravity=energies[:, 1],
        elastic=energies[:, 2],
        dissipated=E_psi,
        input_work=W_u,
        balance=balance,
        balance_scale=scale,
        nfev=sol.nfev,
        njev=sol.njev,
        nlu=sol.nlu,
        n_steps=sol.n_steps,
        wall_time_s=wall,
        success=sol.success,
        message=sol.message,
        coordinates=list(scene.textbook.coordinate_names),
        states=states,
        constraint_residual=residual_trajectory(side, q),
        t_events=sol.t_events,
        timing=timing,
    )
    passive = inputs is None and not pushed[0]
    result.drift_flagged = passive and result.relative_drift > DRIFT_FACTOR * rtol
    result.outputs = evaluate_trajectory(scene, q, outputs, output_side)
    return result


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
    """Values a run keeps per sample: q, q̇, the extra states, three energies, the outputs."""
    return 2 * nv + extra_states + 3 + sum(o.size for o in outputs)


def _state_event(g: Event, n: int) -> Callable[[float, np.ndarray], float]:
    """The event ``g(t, q, q̇)`` as a function of the state, its attributes kept."""

    def event(t, x):
        return float(g(t, x[:n], x[n : 2 * n]))

    event.terminal = getattr(g, "terminal", False)
    event.direction = getattr(g, "direction", 0.0)
    return event


def _check_mass_matrix(scene: Scene, side: _Backend, q0: np.ndarray) -> None:
    """Refuse a model whose mass matrix is singular at the initial state.

    A coordinate that moves no mass has a zero diagonal entry; it is named. (Euler pairs
    at gimbal lock are refused before, by ``check_euler_pairs``.)
    """
    A = side.mass_matrix(q0)
    if not np.isfinite(A).all():
        raise SimulationError(f"{scene.name}: the mass matrix is not finite at the initial state")
    require_diagonal(A, scene.textbook.coordinate_names, f"{scene.name}: ", SimulationError)
    try:
        np.linalg.cholesky(A)
    except np.linalg.LinAlgError:
        raise SimulationError(
            f"{scene.name}: the mass matrix is not positive definite at the initial state"
        ) from None
