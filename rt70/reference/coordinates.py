"""The book's coordinates as Pinocchio's ``(q, v)``, and the Jacobian between them.

One angle per revolute or continuous joint (Pinocchio stores cos/sin), one length per
prismatic joint, ``[x, y, z, β, θ, α]`` for a floating joint (Pinocchio: position and
quaternion, velocity ``v = M q̇`` with ``M = diag(cᵀ, ε)``), ``[x, y, α]`` for a planar
joint; mimic joints are not coordinates (``q_m = k q_s + o``). The map and its Jacobian
``J`` (``v = J q̇``) are built from Pinocchio's own quaternion and roll-pitch-yaw
functions; every result is transformed back: ``A = Jᵀ A_pin J``,
``B q̇ = Jᵀ rnea(q, v, J̇ q̇)``, ``Q = Jᵀ τ`` (formalism §5).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rt70.guards.arrays import check_vector
from rt70.reference.model import ReferenceModel


def to_pinocchio(model: ReferenceModel, q: np.ndarray, qd: np.ndarray | None = None):
    """Pinocchio's ``(q, v)``, the Jacobian ``J`` (``v = J q̇``) and ``J̇ q̇``.

    ``J`` is None when it is the identity (only 1-DOF joints in the user's order, no
    mimic); a mere reordering of 1-DOF joints is a permutation matrix. Every algorithm
    of the reference side passes its state through here: a wrong shape raises
    :class:`~rt70.errors.ShapeError`, a NaN or infinity
    :class:`~rt70.errors.NonFiniteError` (as on the textbook side).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    qd : numpy.ndarray, shape (nv,), optional
        Generalised velocities, rad/s or m/s; None: only the configuration is mapped
        (``v`` is None, ``J̇ q̇`` zero).
    """
    q = check_vector("q", q, model.nv)
    qd = None if qd is None else check_vector("qd", qd, model.nv)
    if model.identity_map:
        return q, qd, None, None
    m = model.pin_model
    qp = np.zeros(m.nq)
    J = np.zeros((m.nv, model.nv))
    Jdqd = np.zeros(m.nv)
    qd_ = np.zeros(model.nv) if qd is None else qd
    for c in model.coords:
        b, iq, iv = c.book, c.iq, c.iv
        if c.kind == "1dof":
            qp[iq] = q[b]
            J[iv, b] = 1.0
        elif c.kind == "continuous":
            qp[iq : iq + 2] = np.cos(q[b]), np.sin(q[b])
            J[iv, b] = 1.0
        elif c.kind in ("mimic", "mimic-continuous"):
            angle = c.multiplier * q[b] + c.offset
            if c.kind == "mimic":
                qp[iq] = angle
            else:
                qp[iq : iq + 2] = np.cos(angle), np.sin(angle)
            J[iv, b] = c.multiplier
        elif c.kind == "modal":  # a node (u = Φ_n η) or an interface chain joint (row · η)
            rows, k = c.shape.shape
            qp[iq : iq + rows] = c.shape @ q[b : b + k]
            J[iv : iv + rows, b : b + k] = c.shape
        elif c.kind == "floating":
            x, phi, dx, dphi = q[b : b + 3], q[b + 3 : b + 6], qd_[b : b + 3], qd_[b + 3 : b + 6]
            # c = Rx(β) Ry(θ) Rz(α); its transpose has Pinocchio rpy ρ = −φ
            rho = -phi
            rot = pin.rpy.rpyToMatrix(rho).T
            qp[iq : iq + 3] = x
            qp[iq + 3 : iq + 7] = pin.Quaternion(rot).coeffs()
            eps = pin.rpy.computeRpyJacobian(rho, pin.WORLD)
            J[iv : iv + 3, b : b + 3] = rot.T
            J[iv + 3 : iv + 6, b + 3 : b + 6] = eps
            omega = eps @ dphi
            eps_dot = pin.rpy.computeRpyJacobianTimeDerivative(rho, -dphi, pin.WORLD)
            Jdqd[iv : iv + 3] = -np.cross(omega, rot.T @ dx)
            Jdqd[iv + 3 : iv + 6] = eps_dot @ dphi
        else:  # planar: [x, y, α], v = [c3ᵀ (ẋ, ẏ); α̇] in the moving frame
            x, y, a = q[b : b + 3]
            ca, sa = np.cos(a), np.sin(a)
            qp[iq : iq + 4] = x, y, ca, sa
            J[iv : iv + 2, b : b + 2] = [[ca, sa], [-sa, ca]]
            J[iv + 2, b + 2] = 1.0
            dx, dy, da = qd_[b : b + 3]
            Jdqd[iv : iv + 2] = da * (-sa * dx + ca * dy), da * (-ca * dx - sa * dy)
    vp = None if qd is None else J @ qd
    return qp, vp, J, Jdqd
