"""Loop closures on the textbook side: Φ(q), B_c, C and the constrained dynamics (14).

A ``<rt70:loop>`` makes frame 1 (on one body) coincide with frame 2 (on another, or
the ground): source 004's "coincidence of bases". Everything here comes from the book's
kinematics — frame poses of the forward pass, frame Jacobians ``(T(r)[c])ᵀ (Sᵀ)_body``
(4.63) and the structure rate Ṡ (4.81) — with no finite differences:

* ``Φ = [p₁ − p₂; log(R₁R₂ᵀ)]`` in ground axes (the rotation rows for ``type="frame"``
  only);
* ``B_c = [J_v1 − J_v2; J_ω1 − J_ω2]``, the ground-axis point and angular velocity
  Jacobians, so that ``B_c q̇ = Φ̇`` (the rotation rows exactly on ``Φ = 0``, to first
  order off it);
* ``C = Ḃ_c q̇``: the difference of the two frames' accelerations at q̈ = 0. With the
  body's twist ``V = [v; ω] = Sᵀ q̇`` (body axes) and ``V̇|_{q̈=0} = Ṡᵀ q̇``, a point r
  of the body accelerates by ``R (v̇ + ω̇×r + ω×(v + ω×r))`` and the body's angular
  acceleration is ``R ω̇``.

The constrained equations (14), ``A q̈ = f + B_cᵀ λ``, ``B_c q̈ = g``, are solved by
:func:`rt70.physics.kkt.solve_kkt` (range-space method), ``f = Q_g + Q_c + Q_d + Q − B q̇``
(gravity, the scene's springs and dampers, further forces Q) and ``g`` from
:mod:`rt70.physics.baumgarte`. λ are the reactions of the loop joints in ground axes: the
force on frame 1 (and its moment for ``frame``); frame 2 takes −λ. The reference side
(:mod:`rt70.reference.loops`) computes the same from Pinocchio.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from rt70.guards.arrays import check_vector
from rt70.physics.baumgarte import Baumgarte, consistent_rhs, constraint_rhs
from rt70.physics.kkt import solve_kkt
from rt70.textbook import modal_bodies
from rt70.textbook.data import Data
from rt70.textbook.dynamics import (
    _bias_force,
    _gravity_force,
    body_velocities,
    structure_matrix_rate,
)
from rt70.textbook.forces import spring_damper_force
from rt70.textbook.kinematics import frame_pose, update_structure
from rt70.textbook.model import LoopModel, Model
from rt70.textbook.points import ground_bias_acceleration, ground_jacobian


def loop_rows(model: Model) -> int:
    """Number of constraint rows m of all the model's loops."""
    return sum(loop.rows for loop in model.loops)


def _residual(data: Data, loop: LoopModel) -> np.ndarray:
    """Φ of one loop for the configuration in ``data``."""
    R1, p1 = frame_pose(data, loop.body1, loop.r1, loop.c1)
    R2, p2 = frame_pose(data, loop.body2, loop.r2, loop.c2)
    if loop.rows == 3:
        return p1 - p2
    return np.concatenate([p1 - p2, Rotation.from_matrix(R1 @ R2.T).as_rotvec()])


def _jacobian(data: Data, body: int, r: np.ndarray, rows: int) -> np.ndarray:
    """Ground-axis ``[J_v; J_ω]`` (first ``rows`` rows) of the point r of a body."""
    return np.vstack(ground_jacobian(data, body, r))[:rows]


def _acceleration(data: Data, body: int, r: np.ndarray, Vdot: np.ndarray, rows: int):
    """Ground-axis acceleration of point r of a body (and the body's ω̇) at q̈ = 0."""
    return np.concatenate(ground_bias_acceleration(data, body, r, Vdot))[:rows]


def loop_residual(model: Model, data: Data, q: np.ndarray) -> np.ndarray:
    """Φ(q), shape (m,): the loops' point differences (and orientation errors).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    update_structure(model, data, q)
    parts = [_residual(data, loop) for loop in model.loops]
    return np.concatenate(parts) if parts else np.zeros(0)


def _jacobian_here(model: Model, data: Data) -> np.ndarray:
    """B_c for the configuration already in ``data``."""
    rows = [
        _jacobian(data, lp.body1, lp.r1, lp.rows) - _jacobian(data, lp.body2, lp.r2, lp.rows)
        for lp in model.loops
    ]
    return np.vstack(rows) if rows else np.zeros((0, model.nv))


def loop_jacobian(model: Model, data: Data, q: np.ndarray) -> np.ndarray:
    """``B_c = ∂Φ/∂q``, shape (m, nv), in the sense ``B_c q̇ = Φ̇``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    update_structure(model, data, q)
    return _jacobian_here(model, data)


def _bias_here(
    model: Model, data: Data, q: np.ndarray, qd: np.ndarray, S_dot: np.ndarray | None = None
) -> np.ndarray:
    """C for the configuration in ``data`` (body velocities set by this call).

    ``S_dot``: the structure rate Ṡ (4.81) at (q, q̇) when already computed (the bias
    force's, ``data.S_dot``), else computed here.
    """
    body_velocities(model, data, qd)
    if S_dot is None:
        S_dot = structure_matrix_rate(model, data, q, qd)
    Vdot = (S_dot.T @ qd).reshape(model.nb, 6)
    parts = [
        _acceleration(data, lp.body1, lp.r1, Vdot, lp.rows)
        - _acceleration(data, lp.body2, lp.r2, Vdot, lp.rows)
        for lp in model.loops
    ]
    return np.concatenate(parts) if parts else np.zeros(0)


def loop_bias(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``C = Ḃ_c q̇``, shape (m,): the frames' relative acceleration at q̈ = 0.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    update_structure(model, data, q)
    return _bias_here(model, data, q, qd)


def loop_terms(
    model: Model, data: Data, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Φ, B_c, C)`` from one forward pass (what a simulation step needs).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    update_structure(model, data, q)
    residual = [_residual(data, loop) for loop in model.loops]
    return (
        np.concatenate(residual) if residual else np.zeros(0),
        _jacobian_here(model, data),
        _bias_here(model, data, q, qd),
    )


def constrained_forward_dynamics(
    model: Model,
    data: Data,
    q: np.ndarray,
    qd: np.ndarray,
    Q: np.ndarray | None = None,
    stabilization: Baumgarte | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(q̈, λ)`` of the constrained equations (14), solved by :func:`rt70.physics.kkt.solve_kkt`.

    ``A q̈ = Q_g + Q_c + Q_d + Q − B q̇ + B_cᵀ λ`` and ``B_c q̈ = g``, g = −C or the
    perturbation equations (2.2) of :class:`rt70.physics.baumgarte.Baumgarte`, projected onto
    the range of B_c when rows are dependent (:func:`rt70.physics.baumgarte.consistent_rhs`).

    Parameters
    ----------
    model, data : Model, Data
        The textbook model (with its ``loops``) and its work buffers.
    q, qd : numpy.ndarray
        The state, (nv,) each.
    Q : numpy.ndarray, optional
        Further generalised forces (inputs), (nv,).
    stabilization : Baumgarte, optional
        Gains of ``Φ̈ + 2ζω Φ̇ + ω² Φ = 0``; None: ``Φ̈ = 0``.
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    Qc, Qd = spring_damper_force(model, data, q, qd)
    update_structure(model, data, q)
    f = _gravity_force(model, data) + Qc + Qd - _bias_force(model, data, q, qd)
    if Q is not None:
        f = f + check_vector("Q", Q, model.nv)
    A = data.S @ data.Theta @ data.S.T
    if model.modal:
        frames = modal_bodies.dense_frames(model, data)
        A += modal_bodies.mass_matrix_terms(model, frames, q)
        f += modal_bodies.gravity_terms(model, frames, q)
    B_c = _jacobian_here(model, data)
    C = _bias_here(model, data, q, qd, S_dot=data.S_dot)  # Ṡ of the bias force above
    residual = np.concatenate([_residual(data, loop) for loop in model.loops] or [np.zeros(0)])
    g = consistent_rhs(B_c, constraint_rhs(C, B_c @ qd, residual, stabilization))
    sol = solve_kkt(A, B_c, f, g)
    return sol.x, sol.lam
