"""Rolling and knife-edge constraints ``A(q) q̇ = 0`` on the textbook side (source 002 (1.1)).

Each ``<rt70:no_slip>`` (:class:`~rt70.urdf.description.NoSlip`) gives one row: the
velocity of a material point along a direction fixed in a link,

    c = dᵀ (v_p + a n × ω),   A_row = dᵀ (J_v + a [n]× J_ω),

with ``(J_v, J_ω)`` the point Jacobian of :func:`rt70.textbook.points.point_jacobian`
(the book's ``V⁰ = Sᵀ q̇`` (4.63) moved to the point), ``d`` the direction turned to
ground axes by the frame link's rotation, ``a`` the wheel radius and ``n`` the ground
normal (the contact point lies at ``−a n`` from the wheel's centre). The constraint's
velocity product ``Ȧ q̇`` (the acceleration-level constraint is ``A q̈ + Ȧ q̇ = 0``)
comes from the book's structure rate, ``V̇⁰ = Ṡᵀ q̇`` at ``q̈ = 0`` (4.81). The
reference side computes the same from Pinocchio (:mod:`rt70.reference.no_slip`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.guards.arrays import check_vector
from rt70.textbook.data import Data
from rt70.textbook.dynamics import (
    bias_force,
    body_velocities,
    mass_matrix,
    structure_matrix_rate,
)
from rt70.textbook.kinematics import update_structure
from rt70.textbook.model import Model
from rt70.textbook.points import ground_bias_acceleration, ground_jacobian, link_point
from rt70.urdf.description import NoSlip


def _frame_rotation(model: Model, data: Data, link: str) -> tuple[int, np.ndarray]:
    """Body of ``link`` and the ground-axis rotation of the link's frame."""
    body, _, c_link = model.link_frames[link]
    return body, (c_link if body < 0 else data.R[body] @ c_link)


def constraint_matrix(
    model: Model, data: Data, q: np.ndarray, elements: Sequence[NoSlip]
) -> np.ndarray:
    """``A(q)`` (m × nv): one row ``dᵀ (J_v + a [n]× J_ω)`` per element (1.1).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    elements : sequence of rt70.urdf.description.NoSlip
        The ``<rt70:no_slip>`` constraints, one row each.
    """
    q = check_vector("q", q, model.nv)
    update_structure(model, data, q)
    A = np.zeros((len(elements), model.nv))
    for i, e in enumerate(elements):
        Jv, Jw = ground_jacobian(data, *link_point(model, e.link, e.xyz))
        d = _frame_rotation(model, data, e.frame)[1] @ e.direction
        A[i] = d @ Jv + e.radius * np.cross(d, e.normal) @ Jw
    return A


def constraint_bias(
    model: Model, data: Data, q: np.ndarray, qd: np.ndarray, elements: Sequence[NoSlip]
) -> np.ndarray:
    """``Ȧ q̇`` (m,): ``ċ`` of every row at ``q̈ = 0``.

    ``ċ = ḋᵀ u + dᵀ (a_p + a n × ω̇)`` with ``u = v_p + a n × ω``, ``ḋ = ω_f × d``
    (``ω_f`` the frame link's angular velocity), and, in the point body's axes,
    ``a_p = R (v̇ + ω̇ × r + ω × (v + ω × r))``, ``ω̇_ground = R ω̇``: ``[v; ω] = Sᵀ q̇``
    and its rate ``[v̇; ω̇] = Ṡᵀ q̇`` (4.63), (4.81).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).
    elements : sequence of rt70.urdf.description.NoSlip
        The ``<rt70:no_slip>`` constraints, one row each.
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    update_structure(model, data, q)
    V = body_velocities(model, data, qd)
    Vdot = (structure_matrix_rate(model, data, q, qd).T @ qd).reshape(model.nb, 6)
    out = np.zeros(len(elements))
    for i, e in enumerate(elements):
        body, r = link_point(model, e.link, e.xyz)
        if body < 0:
            continue  # a point of the ground: A row and its rate are zero
        v, w = V[body, :3], V[body, 3:]
        R = data.R[body]
        w_g = R @ w
        v_p = R @ (v + np.cross(w, r))
        a_p, dw_g = ground_bias_acceleration(data, body, r, Vdot)
        fbody, Rf = _frame_rotation(model, data, e.frame)
        d = Rf @ e.direction
        w_f = np.zeros(3) if fbody < 0 else data.R[fbody] @ V[fbody, 3:]
        u = v_p + e.radius * np.cross(e.normal, w_g)
        out[i] = np.cross(w_f, d) @ u + d @ (a_p + e.radius * np.cross(e.normal, dw_g))
    return out


def reduced_terms(
    model: Model,
    data: Data,
    q: np.ndarray,
    qd: np.ndarray,
    basis: np.ndarray,
    basis_rate_qd: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``A* = 𝔅ᵀ A 𝔅`` and ``a = 𝔅ᵀ (A 𝔅̇ q̇_ind + B q̇)`` (gravity apart), 002 (1.6)–(1.7).

    The book's A and velocity products ``B q̇`` at ``q̇ = 𝔅 q̇_ind``, projected: the
    twin of :func:`rt70.reference.no_slip.reduced_terms` (Pinocchio's crba and rnea).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    qd : numpy.ndarray, shape (nv,)
        The full velocities ``𝔅 q̇_ind``, rad/s or m/s.
    basis : numpy.ndarray, shape (nv, n_ind)
        The velocity map 𝔅 (``q̇ = 𝔅 q̇_ind``, rows in the full order).
    basis_rate_qd : numpy.ndarray, shape (nv,)
        ``𝔅̇ q̇_ind``, rad/s² or m/s².
    """
    A = mass_matrix(model, data, q)
    h = bias_force(model, data, q, qd)
    return basis.T @ A @ basis, basis.T @ (A @ basis_rate_qd + h)
