"""Spring and damper forces from Pinocchio's own kinematics (Pinocchio has no springs).

Every element is a deformation δ with its Jacobian ∂δ/∂v, computed here from
Pinocchio's frame placements and frame Jacobians of the attachment points and its
roll-pitch-yaw Jacobian for the Euler-angle rates — independently of the textbook
side's :class:`rt70.textbook.forces.Deformation`. Potential ``½ δᵀ C δ``, spring force
``−(∂δ/∂v)ᵀ C δ``, damper force ``−(∂δ/∂v)ᵀ D δ̇``; the results go to Pinocchio as
``tau`` (:func:`element_torques`) or back to book coordinates through ``Jᵀ``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rt70.arrays import check_vector
from rt70.errors import SingularConfigurationError
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.model import ReferenceData, ReferenceModel

#: Same threshold as the textbook side: |cos θ| of the 1–2–3 angles below it is gimbal lock.
GIMBAL_LOCK_COS = 1e-8


def spring_damper_force(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Spring force ``Q_c`` and damper force ``Q_d`` in book coordinates: ``Jᵀ τ``."""
    qp, vp, J, _ = to_pinocchio(model, q, qd)
    Qc, Qd = element_torques(model, data, qp, vp)
    return (Qc, Qd) if J is None else (J.T @ Qc, J.T @ Qd)


def element_torques(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, vp: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Spring and damper forces as Pinocchio joint torques τ_c, τ_d.

    ``qp``, ``vp`` are Pinocchio's own configuration and velocity (see
    :func:`~rt70.reference.coordinates.to_pinocchio`), and so are the results (its
    velocity space): the form ``pin.aba`` takes as ``tau``, used by the simulation's
    fast path.
    """
    nv = model.pin_model.nv
    Qc, Qd = np.zeros(nv), np.zeros(nv)
    if model.spring_v.size:
        angles = _joint_angles(model, qp)
        np.subtract.at(Qc, model.spring_v, model.spring_k * angles[model.spring_v])
        np.subtract.at(Qd, model.spring_v, model.spring_d * vp[model.spring_v])
    if model.bushings:
        delta, jac = deformations(model, data, qp)
        rate = jac @ vp  # δ̇ of every bushing, (n_b, 6)
        Qc -= np.einsum("bin,bi->n", jac, model.stiffness * delta)
        Qd -= np.einsum("bin,bi->n", jac, model.damping * rate)
    return Qc, Qd


def element_gains(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``Σ Jᵀ C J`` and ``Σ Jᵀ D J`` of the springs and dampers, in Pinocchio's space.

    ``−∂τ_c/∂v`` without the term of the deformation's second derivative (the
    Gauss–Newton part) and ``−∂τ_d/∂v`` exactly: what an implicit integrator's
    Jacobian needs besides ``pin.computeABADerivatives``.
    """
    n = model.pin_model.nv
    K, D = np.zeros((n, n)), np.zeros((n, n))
    K[model.spring_v, model.spring_v] += model.spring_k
    D[model.spring_v, model.spring_v] += model.spring_d
    if model.bushings:
        _, jac = deformations(model, data, qp)
        K += np.einsum("bin,bi,bim->nm", jac, model.stiffness, jac)
        D += np.einsum("bin,bi,bim->nm", jac, model.damping, jac)
    return K, D


def spring_potential(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> float:
    """``Σ ½ δᵀ C δ`` with δ from Pinocchio's frame placements."""
    qp, _, _, _ = to_pinocchio(model, q)
    U = 0.0
    if model.spring_v.size:
        angles = _joint_angles(model, qp)
        U += 0.5 * float(np.sum(model.spring_k * angles[model.spring_v] ** 2))
    if model.bushings:
        delta, _ = deformations(model, data, qp, jacobian=False)
        U += 0.5 * float(np.sum(model.stiffness * delta**2))
    return U


def spring_damper_magnitudes(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Sizes of the terms of the spring and damper forces: ``Σ_e |J_e|ᵀ |C_e δ_e|``.

    The same sums as :func:`spring_damper_force` with every term taken by its absolute
    value (joint springs ``|k q|``, bushings ``|∂δ/∂q|ᵀ |C δ|`` and
    ``|∂δ/∂q|ᵀ |D δ̇|``): forces of elements that oppose each other cancel in the sum
    but not here. The natural scale of :func:`rt70.validate.natural_scales`.
    """
    qp, vp, J, _ = to_pinocchio(model, q, qd)
    nv = model.pin_model.nv
    Sc, Sd = np.zeros(nv), np.zeros(nv)
    if model.spring_v.size:
        angles = _joint_angles(model, qp)
        np.add.at(Sc, model.spring_v, np.abs(model.spring_k * angles[model.spring_v]))
        np.add.at(Sd, model.spring_v, np.abs(model.spring_d * vp[model.spring_v]))
    if model.bushings:
        delta, jac = deformations(model, data, qp)
        rate = jac @ vp
        Sc += np.einsum("bin,bi->n", np.abs(jac), np.abs(model.stiffness * delta))
        Sd += np.einsum("bin,bi->n", np.abs(jac), np.abs(model.damping * rate))
    return (Sc, Sd) if J is None else (np.abs(J).T @ Sc, np.abs(J).T @ Sd)


def deformations(model: ReferenceModel, data: ReferenceData, qp: np.ndarray, jacobian: bool = True):
    """δ of every bushing (n_b, 6) and ∂δ/∂v (n_b, 6, nv), from Pinocchio's kinematics.

    Frame placements ``oMi · placement`` and local frame Jacobians (Pinocchio's
    ``getFrameJacobian`` of a joint and a placement) come from Pinocchio; the relative
    placement, Pinocchio's roll-pitch-yaw of its transpose and the inverse world rpy
    Jacobian are evaluated for all bushings at once (the formulas of
    ``pin.rpy.matrixToRpy`` / ``computeRpyJacobianInverse``, checked against them in
    the tests). ``c12 = Rx(β) Ry(θ) Rz(α)`` has ``c12ᵀ`` with rpy ``ρ = −[β, θ, α]``;
    the angular velocity of frame 2 relative to frame 1 is ``ω = J_W(ρ) φ̇``.
    """
    m, d = model.pin_model, data.pin_data
    qp = check_vector("qp", qp, m.nq)
    if jacobian:
        pin.computeJointJacobians(m, d, qp)
    else:
        pin.forwardKinematics(m, d, qp)
    f1, f2 = model.frames1, model.frames2
    M1 = [d.oMi[joint] * placement for joint, placement in f1]
    M2 = [d.oMi[joint] * placement for joint, placement in f2]
    R1 = np.array([M.rotation for M in M1])
    R2 = np.array([M.rotation for M in M2])
    p1 = np.array([M.translation for M in M1])
    p2 = np.array([M.translation for M in M2])
    R1t = np.swapaxes(R1, -1, -2)
    c12 = R1t @ R2
    r12 = (R1t @ (p2 - p1)[..., None])[..., 0]
    ct = np.swapaxes(c12, -1, -2)  # ρ = rpy of c12ᵀ (Pinocchio's Rz(y) Ry(p) Rx(r))
    pitch = np.arctan2(-ct[:, 2, 0], np.hypot(ct[:, 0, 0], ct[:, 1, 0]))
    roll = np.arctan2(ct[:, 2, 1], ct[:, 2, 2])
    yaw = np.arctan2(ct[:, 1, 0], ct[:, 0, 0])
    cp = np.cos(pitch)
    if np.any(np.abs(cp) < GIMBAL_LOCK_COS):
        raise SingularConfigurationError("bushing at Euler-angle gimbal lock (θ = ±π/2)")
    delta = np.concatenate([r12, -np.stack([roll, pitch, yaw], axis=1)], axis=1)
    if not jacobian:
        return delta, None
    J1 = np.array([pin.getFrameJacobian(m, d, *f, pin.LOCAL) for f in f1]).reshape(-1, 6, m.nv)
    J2 = np.array([pin.getFrameJacobian(m, d, *f, pin.LOCAL) for f in f2]).reshape(-1, 6, m.nv)
    # J_rel = J2 − Ad(M12⁻¹) J1; δ̇_trans = c12 v_rel, φ̇ = J_W(ρ)⁻¹ ω_rel
    lin1 = J1[:, :3] - _skew(r12) @ J1[:, 3:]
    jac = np.empty_like(J2)
    jac[:, :3] = c12 @ J2[:, :3] - lin1
    w_rel = J2[:, 3:] - ct @ J1[:, 3:]
    cy, sy, tp = np.cos(yaw), np.sin(yaw), np.tan(pitch)
    inv = np.zeros((len(f1), 3, 3))
    inv[:, 0, 0], inv[:, 0, 1] = cy / cp, sy / cp
    inv[:, 1, 0], inv[:, 1, 1] = -sy, cy
    inv[:, 2, 0], inv[:, 2, 1], inv[:, 2, 2] = cy * tp, sy * tp, 1.0
    jac[:, 3:] = inv @ w_rel
    return delta, jac


def _joint_angles(model: ReferenceModel, qp: np.ndarray) -> np.ndarray:
    """Coordinate of every 1-DOF joint, indexed by velocity index (cos/sin → angle)."""
    m = model.pin_model
    out = np.zeros(m.nv)
    for i in range(1, m.njoints):
        jm = m.joints[i]
        if jm.nv == 1 and jm.nq == 1:
            out[jm.idx_v] = qp[jm.idx_q]
        elif jm.nv == 1 and jm.nq == 2:
            out[jm.idx_v] = np.arctan2(qp[jm.idx_q + 1], qp[jm.idx_q])
    return out


def _skew(x: np.ndarray) -> np.ndarray:
    """Skew matrices of an array of 3-vectors (n, 3) → (n, 3, 3)."""
    out = np.zeros(x.shape + (3,))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -x[:, 2], x[:, 1], -x[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = x[:, 2], -x[:, 1], x[:, 0]
    return out
