"""Closed chains in time simulation: constraints per side, assembly, constrained q̈.

A scene with ``<rt70:loop>`` elements is a tree plus the constraints ``Φ(q) = 0``
(source 004 (14)). This module holds what :func:`rt70.simulation.simulate.simulate` needs beyond
the tree's dynamics, written once for both sides:

* :class:`Constraint` — the interface of one group of holonomic constraints on one side:
  ``rows``, ``residual(q)`` Φ, ``jacobian(q)`` B_c, ``bias(q, q̇)`` C. The loops of a
  scene are one (:func:`scene_constraints`); a brake or stow pin locking a coordinate
  is another kind with the same three methods.
* :func:`assemble` — consistent initial conditions: Newton on ``Φ(q) = 0`` keeping
  chosen coordinates, and ``q̇`` projected onto ``B_c q̇ = 0`` keeping the chosen
  velocities.
* :func:`closure_search` and :func:`require_closable` — whether the loops can close at
  all: a model whose loops cannot (lengths that do not reach, loops that contradict each
  other) is refused with :class:`~rt70.errors.LoopClosureError` naming the file, the
  loops and the residual, rather than failing later as a Newton iteration or a
  disagreement between the sides.
* :class:`ConstrainedBackend` — wraps a backend of :mod:`rt70.simulation.simulate`: q̈ and λ of the
  constrained equations (14) with the Baumgarte stabilisation of source 002 (2.2)
  (:mod:`rt70.physics.baumgarte`): on the textbook side the KKT system by the range-space method
  (:func:`rt70.physics.kkt.solve_kkt`); on Pinocchio's ``pin.constraintDynamics`` for the loops
  (:func:`rt70.reference.loops.constrained_forward_dynamics`) — any further constraint
  on that side goes through the same KKT solve with Pinocchio's A and forces.

Ideal constraints do no work (``q̇ᵀ B_cᵀ λ = (B_c q̇)ᵀ λ = 0``), so the energy audit of
the tree still closes; the residual ``max |Φ|`` is reported with the result.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.optimize

from rt70.errors import LoopClosureError, Rt70Error, SimulationError
from rt70.guards.arrays import check_vector
from rt70.model.scene import Scene
from rt70.physics.baumgarte import Baumgarte, consistent_rhs, constraint_rhs
from rt70.physics.kkt import solve_kkt
from rt70.urdf.description import Loop

#: Newton iterations of :func:`assemble` before it gives up.
MAX_NEWTON = 50

#: Seeded random starts of :func:`closure_search` after q = 0 (each coordinate uniform
#: in ±π): a reproducible search, not a proof — a loop that closes only in a region these
#: miss would be refused.
CLOSURE_STARTS = 12

#: Residual evaluations of the least-squares descent from each start.
MAX_DESCENT = 100

#: Newton steps after the descent (quadratic convergence from near closure).
MAX_POLISH = 8

#: Closed: ``max |Φ| ≤ CLOSURE_TOL · (1 + reach)``, reach the largest distance (m) of a
#: loop frame from the ground origin (the rounding of the frames' positions).
CLOSURE_TOL = 1e-13


@dataclass(frozen=True)
class Constraint:
    """One group of holonomic constraints ``Φ(q) = 0`` as one side computes them.

    Attributes
    ----------
    name : str
        What the rows are (for messages).
    rows : int
        Number of rows m.
    residual : callable q -> (m,)
        Φ(q).
    jacobian : callable q -> (m, nv)
        ``B_c`` with ``B_c q̇ = Φ̇``.
    bias : callable (q, q̇) -> (m,)
        ``C = Ḃ_c q̇`` (``B_c q̈ + C = Φ̈``).
    terms : callable (q, q̇) -> (Φ, B_c, C), optional
        All three at once when a side can share the work (one forward pass).
    """

    name: str
    rows: int
    residual: object
    jacobian: object
    bias: object
    terms: object = None


def scene_constraints(scene: Scene, side: str = "textbook") -> list[Constraint]:
    """The scene's loop closures as one :class:`Constraint` of ``side`` (or none).

    Parameters
    ----------
    scene : Scene
        The scene, its ``<rt70:loop>`` elements.
    side : {"textbook", "reference"}
        Whose kinematics compute Φ, B_c and C.
    """
    loops = scene.description.loops
    if not loops:
        return []
    if side == "textbook":
        from rt70.textbook import loops as tl

        model, data = scene.textbook, scene.textbook_data
    elif side == "reference":
        from rt70.reference import loops as tl

        model, data = scene.reference, scene.reference_data
    else:
        raise Rt70Error(f"unknown side '{side}' (textbook or reference)")
    return [
        Constraint(
            ", ".join(f"loop '{loop.name}'" for loop in loops),
            sum(loop.rows for loop in loops),
            lambda q: tl.loop_residual(model, data, q),
            lambda q: tl.loop_jacobian(model, data, q),
            lambda q, qd: tl.loop_bias(model, data, q, qd),
            (lambda q, qd: tl.loop_terms(model, data, q, qd)) if side == "textbook" else None,
        )
    ]


def stacked(constraints: Sequence[Constraint], q, qd=None):
    """``(Φ, B_c, C)`` of all constraints stacked (C None without q̇)."""
    if qd is not None and all(c.terms is not None for c in constraints):
        parts = [c.terms(q, qd) for c in constraints]
        phi, B, C = zip(*parts, strict=True)
        return np.concatenate(phi), np.vstack(B), np.concatenate(C)
    phi = np.concatenate([c.residual(q) for c in constraints])
    B = np.vstack([c.jacobian(q) for c in constraints])
    C = None if qd is None else np.concatenate([c.bias(q, qd) for c in constraints])
    return phi, B, C


def _indices(names: Sequence[str | int], coordinates: Sequence[str]) -> np.ndarray:
    out = []
    for name in names:
        if isinstance(name, str):
            if name not in coordinates:
                raise Rt70Error(
                    f"unknown coordinate '{name}' (coordinates: {', '.join(coordinates)})"
                )
            out.append(coordinates.index(name))
        else:
            out.append(int(name))
    return np.array(sorted(set(out)), dtype=int)


def assemble(
    scene: Scene,
    q: np.ndarray,
    qd: np.ndarray | None = None,
    keep: Sequence[str | int] = (),
    side: str = "textbook",
    tol: float = CLOSURE_TOL,
) -> tuple[np.ndarray, np.ndarray]:
    """Close the scene's chains from a guess: consistent ``(q, q̇)``.

    Newton's method on ``Φ(q) = 0`` moves only the coordinates not in ``keep`` (the
    least-norm step ``Δq = −B_c⁺ Φ`` on them, so dependent rows are harmless); the
    velocities not kept are then the least-norm solution of
    ``B_c[:, free] q̇_free = −B_c[:, kept] q̇_kept``.

    Parameters
    ----------
    scene : Scene
        The scene with loops (without, the guess is returned unchanged).
    q, qd : numpy.ndarray
        The guess (q̇ default zero).
    keep : sequence of str or int
        Coordinates (names or indices) whose position and velocity are kept — e.g. the
        crank angle and speed of a crank–slider.
    side : {"textbook", "reference"}
        Whose kinematics compute Φ and B_c.
    tol : float
        Convergence: ``max |Φ| ≤ tol · (1 + reach)``, reach the largest distance (m) of a
        loop frame from the ground origin.

    Raises
    ------
    LoopClosureError
        If Newton's method does not converge and the loops cannot close anywhere
        (:func:`closure_search`): a contradiction in the model.
    Rt70Error
        If Newton's method does not converge but the loops do close elsewhere (no
        closed configuration near the guess with the kept coordinates), or the kept
        velocities violate the constraints.
    """
    n = scene.textbook.nv
    q = check_vector("q", q, n).copy()
    qd = np.zeros(n) if qd is None else check_vector("qd", qd, n).copy()
    constraints = scene_constraints(scene, side)
    if not constraints:
        return q, qd
    kept = _indices(keep, scene.textbook.coordinate_names)
    free = np.setdiff1d(np.arange(n), kept)
    if free.size == 0:
        raise Rt70Error(f"{scene.name}: assemble: every coordinate is kept, nothing can move")
    residual_jacobian = _residual_jacobian(constraints)
    q, phi, closed = _newton(residual_jacobian, q, free, _closed_test(scene, side, tol))
    if not closed:
        require_closable(scene, tol=tol)  # a contradiction in the model: LoopClosureError
        raise Rt70Error(
            f"{scene.name}: assemble: Newton's method did not close "
            f"{constraints[0].name} (|Φ| = {np.max(np.abs(phi)):.3g} after {MAX_NEWTON} "
            "iterations): no closed configuration near the guess with the kept "
            "coordinates (the loops do close elsewhere)"
        )
    _, B, _ = stacked(constraints, q)
    rhs = -B[:, kept] @ qd[kept]
    qd[free] = np.linalg.lstsq(B[:, free], rhs, rcond=None)[0]
    scale = 1.0 + float(np.max(np.abs(qd)))
    if np.max(np.abs(B @ qd), initial=0.0) > 1e-10 * scale:
        raise Rt70Error(
            f"{scene.name}: assemble: the kept velocities violate {constraints[0].name}"
        )
    return q, qd


def closed_rest(scene: Scene, side: str = "textbook") -> tuple[np.ndarray, np.ndarray]:
    """A closed configuration at rest: :func:`assemble` from q = 0, else from a search.

    q = 0 is often a singular guess (a four-bar's links all on one line: Newton cannot
    move across the line); the first closed configuration :func:`closure_search` finds
    is then assembled instead.

    Raises
    ------
    LoopClosureError
        If the loops cannot close (:func:`require_closable`).
    """
    n = scene.textbook.nv
    if not scene.description.loops:
        return np.zeros(n), np.zeros(n)
    try:
        return assemble(scene, np.zeros(n), side=side)
    except LoopClosureError:
        raise
    except Rt70Error:  # not from q = 0: from where the search closed the loops
        return assemble(scene, closure_search(scene, side).q, side=side)


def _residual_jacobian(constraints: Sequence[Constraint], rows=slice(None)):
    """``q -> (Φ, B_c)`` of the constraints stacked, restricted to ``rows``."""

    def evaluate(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        phi, B, _ = stacked(constraints, q)
        return phi[rows], B[rows]

    return evaluate


def _closed_test(scene: Scene, side: str, tol: float):
    """``(q, Φ) -> bool``: ``max |Φ| ≤ tol · (1 + reach(q))`` (reach: see :data:`CLOSURE_TOL`)."""
    if side == "textbook":
        from rt70.textbook import points

        model, data = scene.textbook, scene.textbook_data
    else:
        from rt70.reference import points

        model, data = scene.reference, scene.reference_data
    located = [
        (f.link, f.xyz) for loop in scene.description.loops for f in (loop.frame1, loop.frame2)
    ]

    def closed(q: np.ndarray, phi: np.ndarray) -> bool:
        if not (np.isfinite(phi).all() and np.isfinite(q).all()):
            return False
        reach = np.linalg.norm(points.point_positions(model, data, q, located), axis=1)
        return bool(np.max(np.abs(phi), initial=0.0) <= tol * (1.0 + float(np.max(reach))))

    return closed


def _newton(
    residual_jacobian, q: np.ndarray, free: np.ndarray, closed, iterations: int = MAX_NEWTON
) -> tuple:
    """Newton on ``Φ = 0`` moving ``free`` (least-norm steps): ``(q, Φ, closed)``."""
    q = q.copy()
    for _ in range(iterations):
        phi, B = residual_jacobian(q)
        if closed(q, phi) or not (np.isfinite(phi).all() and np.isfinite(B).all()):
            break
        q[free] -= np.linalg.lstsq(B[:, free], phi, rcond=None)[0]
    else:
        phi, _ = residual_jacobian(q)
    return q, phi, closed(q, phi)


@dataclass(frozen=True)
class Closure:
    """What :func:`closure_search` found.

    Attributes
    ----------
    q : numpy.ndarray
        A closed configuration, or the least-squares minimum with the smallest ``|Φ|``.
    phi : numpy.ndarray
        Φ there (the rows searched).
    closed : bool
        Whether ``q`` closes the loops (:data:`CLOSURE_TOL`).
    starts : int
        Starts tried.
    """

    q: np.ndarray
    phi: np.ndarray
    closed: bool
    starts: int


def closure_search(
    scene: Scene,
    side: str = "textbook",
    loops: Sequence[str] | None = None,
    tol: float = CLOSURE_TOL,
) -> Closure:
    """Look for a configuration that closes the scene's loops (all, or those named).

    From q = 0 and :data:`CLOSURE_STARTS` seeded random configurations, a trust-region
    least-squares descent of ``½|Φ|²`` (``scipy.optimize.least_squares``, with B_c as its
    Jacobian) then Newton's method; the first closed configuration is returned, or the
    least-squares minimum with the smallest ``|Φ|`` — the loops' frames come no closer
    than that from any start tried.

    Parameters
    ----------
    scene : Scene
        The scene with loops.
    side : {"textbook", "reference"}
        Whose kinematics compute Φ and B_c.
    loops : sequence of str, optional
        Names of the loops to close (default all).
    tol : float
        Closure tolerance (:data:`CLOSURE_TOL`).

    Raises
    ------
    Rt70Error
        If Φ or B_c is not finite at every start.
    """
    constraints = scene_constraints(scene, side)
    n = scene.textbook.nv
    residual_jacobian = _residual_jacobian(constraints, _rows_of(scene, loops))
    closed = _closed_test(scene, side, tol)
    rng = np.random.default_rng(0)
    starts = [np.zeros(n)] + [rng.uniform(-np.pi, np.pi, n) for _ in range(CLOSURE_STARTS)]
    best: Closure | None = None
    for k, start in enumerate(starts, start=1):
        descent = _descend(residual_jacobian, start)
        if descent is None:  # not finite at the start
            continue
        q, phi = descent
        q, phi, ok = (q, phi, True) if closed(q, phi) else _polish(residual_jacobian, q, closed)
        if ok:
            return Closure(q, phi, True, k)
        if best is None or np.linalg.norm(descent[1]) < np.linalg.norm(best.phi):
            best = Closure(*descent, False, len(starts))  # a least-squares minimum
    if best is None:
        raise Rt70Error(f"{scene.path}: the loops' Φ is not finite at any start of the search")
    return best


def _rows_of(scene: Scene, names: Sequence[str] | None) -> np.ndarray | slice:
    """Rows of Φ that belong to the loops named (all without names)."""
    if names is None:
        return slice(None)
    rows, at = [], 0
    for loop in scene.description.loops:
        if loop.name in names:
            rows += range(at, at + loop.rows)
        at += loop.rows
    return np.array(rows, dtype=int)


def _descend(residual_jacobian, start: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``(q, Φ)`` at the local minimum of ``½|Φ|²`` a trust-region descent reaches from ``start``.

    None if Φ or B_c is not finite at the start.
    """
    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def evaluate(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # Φ and B_c in one pass
        key = q.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = residual_jacobian(q)
        return cache[key]

    try:
        fit = scipy.optimize.least_squares(
            lambda q: evaluate(q)[0],
            start,
            jac=lambda q: evaluate(q)[1],
            method="trf",
            max_nfev=MAX_DESCENT,
        )
    except (ValueError, np.linalg.LinAlgError):
        return None
    return fit.x, evaluate(fit.x)[0]


def _polish(residual_jacobian, q: np.ndarray, closed) -> tuple:
    """Newton (:data:`MAX_POLISH` steps) from near closure: ``(q, Φ, closed)``."""
    return _newton(residual_jacobian, q, np.arange(q.size), closed, MAX_POLISH)


def require_closable(
    scene: Scene, sides: Sequence[str] = ("textbook", "reference"), tol: float = CLOSURE_TOL
) -> None:
    """Refuse a scene whose loops cannot close, naming the file, the loops and the residual.

    Each side in ``sides`` searches (:func:`closure_search`); the scene is refused when
    no side finds a closed configuration. The loops that cannot close on their own are
    named as such; if each closes alone, the loops contradict each other.

    Raises
    ------
    LoopClosureError
        If the loops cannot close on any side in ``sides``.
    """
    loops = scene.description.loops
    if not loops:
        return
    found: dict[str, Closure] = {}
    for side in sides:
        found[side] = closure_search(scene, side, tol=tol)
        if found[side].closed:
            return
    side = sides[0]
    closure = found[side]
    alone = (
        {loops[0].name: closure}
        if len(loops) == 1
        else {loop.name: closure_search(scene, side, [loop.name], tol) for loop in loops}
    )
    stuck = [name for name, c in alone.items() if not c.closed]
    what = (
        _names(stuck) + " cannot close"
        if stuck
        else _names([loop.name for loop in loops]) + " contradict each other: each closes alone"
    )
    by_loop = ", ".join(_apart(loop, part) for loop, part in _per_loop(scene, closure.phi))
    there = [  # every other side's Φ at the same configuration
        f"{_SIDE_NAMES[s]} there: "
        + ", ".join(
            _apart(loop, part) for loop, part in _per_loop(scene, _phi(scene, s, closure.q))
        )
        for s in sides
        if s != side
    ]
    raise LoopClosureError(
        f"{scene.path}: {what}; the closest configuration found ({closure.starts} starts, "
        f"{' and '.join(_SIDE_NAMES[s] for s in sides)}) leaves {by_loop}"
        + (f" ({'; '.join(there)})" if there else "")
        + ": the model contradicts itself (check the link lengths and the loops' xyz/rpy)"
    )


#: How messages name the sides.
_SIDE_NAMES = {"textbook": "the textbook", "reference": "Pinocchio"}


def _phi(scene: Scene, side: str, q: np.ndarray) -> np.ndarray:
    """Φ(q) of every loop on ``side``."""
    return stacked(scene_constraints(scene, side), q)[0]


def _names(names: Sequence[str]) -> str:
    """``loop 'a'`` or ``loops 'a', 'b'``."""
    quoted = ", ".join(f"'{n}'" for n in names)
    return f"loop {quoted}" if len(names) == 1 else f"loops {quoted}"


def _per_loop(scene: Scene, phi: np.ndarray) -> Iterator[tuple[Loop, np.ndarray]]:
    """``(loop, its rows of Φ)`` for every loop."""
    at = 0
    for loop in scene.description.loops:
        yield loop, phi[at : at + loop.rows]
        at += loop.rows


def _apart(loop: Loop, phi: np.ndarray) -> str:
    """``loop 'a' 0.15 m apart`` (and the angle for a ``frame`` loop)."""
    text = f"loop '{loop.name}' {np.linalg.norm(phi[:3]):.3g} m apart"
    if loop.rows == 6:
        text += f" and {np.linalg.norm(phi[3:]):.3g} rad turned"
    return text


class ConstrainedBackend:
    """A backend of :mod:`rt70.simulation.simulate` with the scene's constraints added.

    ``accelerations`` returns q̈ of the constrained equations (14) with Baumgarte
    stabilisation; ``jacobian`` is None (the solver differences the right-hand side);
    the mass matrix and the energies are the tree's.
    """

    def __init__(self, side, stabilization: Baumgarte | None) -> None:
        self.side = side
        self.name = side.name
        self.nv = side.nv
        self.scene = side.scene
        self.stabilization = stabilization
        self.side_name = "reference" if side.name == "pinocchio" else "textbook"
        self.constraints = scene_constraints(side.scene, self.side_name)

    def mass_matrix(self, q):
        """The tree's A(q)."""
        return self.side.mass_matrix(q)

    def energies(self, q, qd):
        """The tree's T, U_g, U_c (the constraints store no energy)."""
        return self.side.energies(q, qd)

    def jacobian(self, q, qd, Q_u):
        """None: the solver differences the constrained right-hand side."""
        return None

    def residual(self, q) -> np.ndarray:
        """Φ(q) of every constraint, stacked."""
        return np.concatenate([c.residual(q) for c in self.constraints])

    def accelerations(self, q, qd, Q_u):
        """``(q̈, Q_d)``: q̈ of (14) with (2.2), the dampers' force for the energy audit."""
        if self.side_name == "reference":
            from rt70.reference import loops

            scene = self.scene
            qdd, _ = loops.constrained_forward_dynamics(
                scene.reference, scene.reference_data, q, qd, Q_u, self.stabilization
            )
            _, Qd = self._damper(q, qd)
            return qdd, Qd
        A, f, Qd = self.side.system(q, qd, Q_u)  # the tree's A q̈ = f
        phi, B, C = stacked(self.constraints, q, qd)
        g = consistent_rhs(B, constraint_rhs(C, B @ qd, phi, self.stabilization))
        try:
            sol = solve_kkt(A, B, f, g)
        except Rt70Error as exc:
            raise SimulationError(str(exc)) from None
        return sol.x, Qd

    def _damper(self, q, qd):
        from rt70 import reference

        scene = self.scene
        return reference.spring_damper_force(scene.reference, scene.reference_data, q, qd)


def constrained_start(
    scene: Scene,
    backend,
    x0: tuple[np.ndarray, np.ndarray] | None,
    stabilization: Baumgarte | None,
):
    """``(backend, q0, q̇0)`` for :func:`rt70.simulation.simulate.simulate`.

    Without loops: the backend and x0 unchanged (x0 may be None). With loops: the
    :class:`ConstrainedBackend`, and the initial state closed at rest (x0 None,
    :func:`closed_rest`) or
    checked (a given x0 must satisfy ``Φ = 0``, ``B_c q̇ = 0`` to 1e-8 — close it with
    :func:`assemble`).

    Raises
    ------
    SimulationError
        If the given initial state violates the constraints.
    """
    if not scene.description.loops:
        return backend, None, None
    wrapped = ConstrainedBackend(backend, stabilization)
    n = scene.textbook.nv
    if x0 is None:
        q0, qd0 = closed_rest(scene, side=wrapped.side_name)
        return wrapped, q0, qd0
    q0, qd0 = (
        check_vector("initial state q0", x0[0], n),
        check_vector("initial state qd0", x0[1], n),
    )
    phi, B, _ = stacked(wrapped.constraints, q0)
    rate = B @ qd0
    if np.max(np.abs(phi)) > 1e-8 * (1.0 + np.max(np.abs(q0))) or np.max(
        np.abs(rate), initial=0.0
    ) > 1e-8 * (1.0 + np.max(np.abs(qd0))):
        raise SimulationError(
            f"{scene.name}: the initial state violates {wrapped.constraints[0].name} "
            f"(|Φ| = {np.max(np.abs(phi)):.3g}, |B_c q̇| = {np.max(np.abs(rate)):.3g}); "
            "close it with rt70.simulation.closed_chains.assemble"
        )
    return wrapped, q0, qd0


def residual_trajectory(backend, q: np.ndarray) -> np.ndarray:
    """``max |Φ|`` at every sample of a trajectory (empty without constraints)."""
    if not isinstance(backend, ConstrainedBackend):
        return np.zeros(0)
    return np.array([np.max(np.abs(backend.residual(x))) for x in q])
