"""A scene's loop closures as constraints, per side, and Newton's method on them.

A scene with ``<rt70:loop>`` elements is a tree plus the constraints ``Φ(q) = 0``
(source 004 (14)). :class:`Constraint` is the interface of one group of holonomic
constraints on one side: ``rows``, ``residual(q)`` Φ, ``jacobian(q)`` B_c,
``bias(q, q̇)`` C. The loops of a scene are one (:func:`scene_constraints`); a brake or
stow pin locking a coordinate is another kind with the same three methods.
:func:`stacked` stacks them; :func:`residual_and_jacobian`, :func:`closed_test` and
:func:`newton` are the pieces the assembly (:mod:`rt70.simulation.closed_chains`) and
the closure search (:mod:`rt70.simulation.closure`) share.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from rt70.model.scene import Scene
from rt70.model.sides import check_side, side_of

#: Newton iterations of :func:`newton` (:func:`rt70.simulation.closed_chains.assemble`)
#: before it gives up.
MAX_NEWTON = 50

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
    check_side(side)
    loops = scene.description.loops
    if not loops:
        return []
    s = side_of(scene, side)
    tl, model, data = s.loops, s.model, s.data
    return [
        Constraint(
            ", ".join(f"loop '{loop.name}'" for loop in loops),
            sum(loop.rows for loop in loops),
            lambda q: tl.loop_residual(model, data, q),
            lambda q: tl.loop_jacobian(model, data, q),
            lambda q, qd: tl.loop_bias(model, data, q, qd),
            lambda q, qd: tl.loop_terms(model, data, q, qd),
        )
    ]


def stacked(constraints: Sequence[Constraint], q: np.ndarray, qd: np.ndarray | None = None):
    """``(Φ, B_c, C)`` of all constraints stacked (C None without q̇).

    Parameters
    ----------
    constraints : sequence of Constraint
        The groups of constraints, stacked in this order (m rows in all).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,), optional
        Their velocities, rad/s or m/s; without them C is not computed.

    Returns
    -------
    phi : numpy.ndarray, shape (m,)
        Φ(q), m or rad.
    B : numpy.ndarray, shape (m, nv)
        B_c(q).
    C : numpy.ndarray, shape (m,), or None
        ``Ḃ_c q̇``.
    """
    if qd is not None and all(c.terms is not None for c in constraints):
        parts = [c.terms(q, qd) for c in constraints]
        phi, B, C = zip(*parts, strict=True)
        return np.concatenate(phi), np.vstack(B), np.concatenate(C)
    phi = np.concatenate([c.residual(q) for c in constraints])
    B = np.vstack([c.jacobian(q) for c in constraints])
    C = None if qd is None else np.concatenate([c.bias(q, qd) for c in constraints])
    return phi, B, C


def residual_and_jacobian(
    constraints: Sequence[Constraint], rows: slice | np.ndarray = slice(None)
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """``q -> (Φ, B_c)`` of the constraints stacked, restricted to ``rows`` (all by default)."""

    def evaluate(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        phi, B, _ = stacked(constraints, q)
        return phi[rows], B[rows]

    return evaluate


def closed_test(scene: Scene, side: str, tol: float) -> Callable[[np.ndarray, np.ndarray], bool]:
    """``(q, Φ) -> bool``: ``max |Φ| ≤ tol · (1 + reach(q))`` (reach: see :data:`CLOSURE_TOL`).

    Parameters
    ----------
    scene : Scene
        The scene with loops: reach is the largest distance of its loop frames from the
        ground origin at q, m.
    side : {"textbook", "reference"}
        Whose kinematics place the loop frames.
    tol : float
        The closure tolerance, relative to ``1 + reach`` (:data:`CLOSURE_TOL`).
    """
    s = side_of(scene, side)
    points, model, data = s.points, s.model, s.data
    located = [
        (f.link, f.xyz) for loop in scene.description.loops for f in (loop.frame1, loop.frame2)
    ]

    def closed(q: np.ndarray, phi: np.ndarray) -> bool:
        if not (np.isfinite(phi).all() and np.isfinite(q).all()):
            return False
        reach = np.linalg.norm(points.point_positions(model, data, q, located), axis=1)
        return bool(np.max(np.abs(phi), initial=0.0) <= tol * (1.0 + float(np.max(reach))))

    return closed


def newton(
    residual_jacobian: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    q: np.ndarray,
    free: np.ndarray,
    closed: Callable[[np.ndarray, np.ndarray], bool],
    iterations: int = MAX_NEWTON,
) -> tuple[np.ndarray, np.ndarray, bool]:
    """Newton on ``Φ = 0`` moving ``free`` (least-norm steps): ``(q, Φ, closed)``.

    Stops when ``closed(q, Φ)``, when Φ or B_c is not finite, or after ``iterations``.

    Parameters
    ----------
    residual_jacobian : callable q -> (Φ, B_c)
        The constraints (:func:`residual_and_jacobian`).
    q : numpy.ndarray, shape (nv,)
        The start, rad or m (not changed: the result is a copy).
    free : numpy.ndarray of int
        Indices of the coordinates Newton may move.
    closed : callable (q, Φ) -> bool
        The convergence test (:func:`closed_test`).
    iterations : int
        Newton steps at most.
    """
    q = q.copy()
    for _ in range(iterations):
        phi, B = residual_jacobian(q)
        if closed(q, phi) or not (np.isfinite(phi).all() and np.isfinite(B).all()):
            break
        q[free] -= np.linalg.lstsq(B[:, free], phi, rcond=None)[0]
    else:
        phi, _ = residual_jacobian(q)
    return q, phi, closed(q, phi)
