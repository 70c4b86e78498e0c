"""Closed chains in time simulation: consistent initial states and the constrained q̈.

A scene with ``<rt70:loop>`` elements is a tree plus the constraints ``Φ(q) = 0``
(source 004 (14); the constraints per side: :mod:`rt70.simulation.loop_constraints`).
This module holds what :func:`rt70.simulation.simulate.simulate` needs beyond the tree's
dynamics, written once for both sides:

* :func:`assemble` — consistent initial conditions: Newton on ``Φ(q) = 0`` keeping
  chosen coordinates, and ``q̇`` projected onto ``B_c q̇ = 0`` keeping the chosen
  velocities; a model whose loops cannot close at all is refused
  (:func:`rt70.simulation.closure.require_closable`).
* :class:`ConstrainedBackend` — wraps a backend of :mod:`rt70.simulation.backends`: q̈
  and λ of the constrained equations (14) with the Baumgarte stabilisation of source
  002 (2.2) (:mod:`rt70.physics.baumgarte`), each side its own way
  (:meth:`rt70.simulation.backends.Backend.constrained_accelerations`): on the textbook
  side the KKT system by the range-space method (:func:`rt70.physics.kkt.solve_kkt`); on
  the reference side Pinocchio's ``pin.constraintDynamics`` for the loops
  (:func:`rt70.reference.loops.constrained_forward_dynamics`).

Ideal constraints do no work (``q̇ᵀ B_cᵀ λ = (B_c q̇)ᵀ λ = 0``), so the energy audit of
the tree still closes; the residual ``max |Φ|`` is reported with the result.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.errors import LoopClosureError, Rt70Error, SimulationError
from rt70.guards.arrays import check_vector
from rt70.model.scene import Scene
from rt70.physics.baumgarte import Baumgarte
from rt70.simulation.closure import closure_search, require_closable
from rt70.simulation.loop_constraints import (
    CLOSURE_TOL,
    MAX_NEWTON,
    closed_test,
    newton,
    residual_and_jacobian,
    scene_constraints,
    stacked,
)


def _indices(names: Sequence[str | int], coordinates: Sequence[str]) -> np.ndarray:
    """The sorted indices of coordinates given by name or index."""
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
        (:func:`rt70.simulation.closure.closure_search`): a contradiction in the model.
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
    residual_jacobian = residual_and_jacobian(constraints)
    q, phi, closed = newton(residual_jacobian, q, free, closed_test(scene, side, tol))
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
    move across the line); the first closed configuration
    :func:`rt70.simulation.closure.closure_search` finds is then assembled instead.

    Raises
    ------
    LoopClosureError
        If the loops cannot close (:func:`rt70.simulation.closure.require_closable`).
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


class ConstrainedBackend:
    """A backend of :mod:`rt70.simulation.backends` with the scene's constraints added.

    ``accelerations`` returns q̈ of the constrained equations (14) with Baumgarte
    stabilisation; ``jacobian`` is None (the solver differences the right-hand side);
    the mass matrix and the energies are the tree's.
    """

    def __init__(self, tree, stabilization: Baumgarte | None) -> None:
        self.tree = tree
        self.side = tree.side
        self.nv = tree.nv
        self.scene = tree.scene
        self.stabilization = stabilization
        self.constraints = scene_constraints(tree.scene, tree.side)

    def mass_matrix(self, q):
        """The tree's A(q)."""
        return self.tree.mass_matrix(q)

    def energies(self, q, qd):
        """The tree's T, U_g, U_c (the constraints store no energy)."""
        return self.tree.energies(q, qd)

    def jacobian(self, q, qd, Q_u):
        """None: the solver differences the constrained right-hand side.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N.
        """
        return None

    def residual(self, q) -> np.ndarray:
        """Φ(q) of every constraint, stacked."""
        return np.concatenate([c.residual(q) for c in self.constraints])

    def accelerations(self, q, qd, Q_u):
        """``(q̈, Q_d)``: q̈ of (14) with (2.2), the dampers' force for the energy audit.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        """
        return self.tree.constrained_accelerations(q, qd, Q_u, self.constraints, self.stabilization)


def constrained_start(
    scene: Scene,
    backend,
    x0: tuple[np.ndarray, np.ndarray] | None,
    stabilization: Baumgarte | None,
):
    """``(backend, q0, q̇0)`` for :func:`rt70.simulation.simulate.simulate`.

    Without loops: the backend and ``(None, None)``. With loops: the
    :class:`ConstrainedBackend`, and the initial state closed at rest (x0 None,
    :func:`closed_rest`) or checked (a given x0 must satisfy ``Φ = 0``, ``B_c q̇ = 0``
    to 1e-8 — close it with :func:`assemble`).

    Parameters
    ----------
    scene : Scene
        The scene, its ``<rt70:loop>`` elements.
    backend : rt70.simulation.backends.Backend
        The tree's backend, wrapped when the scene has loops.
    x0 : (q0, q̇0) or None
        The initial state asked for, each shape (nv,), rad or m and rad/s or m/s.
    stabilization : rt70.physics.baumgarte.Baumgarte or None
        Baumgarte's gains (2.2) of the constrained q̈; None lets Φ drift.

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
        q0, qd0 = closed_rest(scene, side=wrapped.side)
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
