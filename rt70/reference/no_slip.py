"""Rolling and knife-edge constraints ``A(q) q̇ = 0`` on the reference side (source 002 (1.1)).

The same rows as :mod:`rt70.textbook.no_slip`, ``dᵀ (J_v + a [n]× J_ω)``, from
Pinocchio's own kinematics: the point Jacobian of :func:`rt70.reference.points.point_jacobian`,
the direction turned by the frame link's placement ``oMi · placement``; the velocity
product ``Ȧ q̇`` from ``pin.forwardKinematics(q, v, J̇ q̇)`` — Pinocchio's joint
velocities and (bias) accelerations moved to the point, classical acceleration
``a_p = a.linear + ω × v_p``. Independent of the textbook side.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from rt70.reference.coordinates import to_pinocchio
from rt70.reference.model import ReferenceData, ReferenceModel
from rt70.reference.points import link_point, point_jacobian
from rt70.urdf.description import NoSlip


def _frame(model: ReferenceModel, data: ReferenceData, link: str):
    """Parent joint, ground placement of ``link``'s frame and its placement in the joint."""
    joint, placement = link_point(model, link, np.zeros(3))
    return joint, data.pin_data.oMi[joint] * placement, placement


def constraint_matrix(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, elements: Sequence[NoSlip]
) -> np.ndarray:
    """``A(q)`` (m × nv): one row ``dᵀ (J_v + a [n]× J_ω)`` per element (1.1).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    elements : sequence of rt70.urdf.description.NoSlip
        The ``<rt70:no_slip>`` constraints, one row each.
    """
    A = np.zeros((len(elements), model.nv))
    for i, e in enumerate(elements):
        Jv, Jw = point_jacobian(model, data, q, e.link, e.xyz)  # runs forwardKinematics
        d = _frame(model, data, e.frame)[1].rotation @ e.direction
        A[i] = d @ Jv + e.radius * np.cross(d, e.normal) @ Jw
    return A


def constraint_bias(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    qd: np.ndarray,
    elements: Sequence[NoSlip],
) -> np.ndarray:
    """``Ȧ q̇`` (m,): ``ċ`` of every row at ``q̈ = 0`` (Pinocchio's bias accelerations).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the book's
        order (:func:`rt70.urdf.coordinate_names`).
    elements : sequence of rt70.urdf.description.NoSlip
        The ``<rt70:no_slip>`` constraints, one row each.
    """
    qp, vp, _, Jdqd = to_pinocchio(model, q, qd)
    m, d = model.pin_model, data.pin_data
    pin.forwardKinematics(m, d, qp, vp, np.zeros(m.nv) if Jdqd is None else Jdqd)
    out = np.zeros(len(elements))
    for i, e in enumerate(elements):
        joint, placement = link_point(model, e.link, e.xyz)
        R = (d.oMi[joint] * placement).rotation
        vel = placement.actInv(d.v[joint])  # [v_p; ω] in the point frame's axes
        acc = placement.actInv(d.a[joint])
        w_g, dw_g = R @ vel.angular, R @ acc.angular
        v_p = R @ vel.linear
        a_p = R @ (acc.linear + np.cross(vel.angular, vel.linear))
        fjoint, oMf, fplacement = _frame(model, data, e.frame)
        dg = oMf.rotation @ e.direction
        w_f = oMf.rotation @ fplacement.actInv(d.v[fjoint]).angular
        u = v_p + e.radius * np.cross(e.normal, w_g)
        out[i] = np.cross(w_f, dg) @ u + dg @ (a_p + e.radius * np.cross(e.normal, dw_g))
    return out


def reduced_terms(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    qd: np.ndarray,
    basis: np.ndarray,
    basis_rate_qd: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``A* = 𝔅ᵀ crba 𝔅`` and ``a = 𝔅ᵀ rnea(q, 𝔅 q̇_ind, 𝔅̇ q̇_ind)`` (gravity off), 002.4.

    ``qd`` is the full ``𝔅 q̇_ind``; both are mapped to Pinocchio's velocities by ``J``
    (``v = J q̇``, ``v̇ = J q̈ + J̇ q̇``) and back by ``Jᵀ``.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    qd : numpy.ndarray, shape (nv,)
        The full velocities ``𝔅 q̇_ind``, rad/s or m/s.
    basis : numpy.ndarray, shape (nv, n_ind)
        The velocity map 𝔅 (``q̇ = 𝔅 q̇_ind``, rows in the full order).
    basis_rate_qd : numpy.ndarray, shape (nv,)
        ``𝔅̇ q̇_ind``, rad/s² or m/s².
    """
    qp, vp, J, Jdqd = to_pinocchio(model, q, qd)
    pm, pd = model.pin_model_no_gravity, data.pin_data_no_gravity
    M = pin.crba(pm, pd, qp)
    M = np.triu(M) + np.triu(M, 1).T
    if J is None:
        tau = pin.rnea(pm, pd, qp, vp, basis_rate_qd)
        return basis.T @ M @ basis, basis.T @ tau
    tau = pin.rnea(pm, pd, qp, vp, J @ basis_rate_qd + Jdqd)
    Jb = J @ basis
    return Jb.T @ M @ Jb, Jb.T @ tau
