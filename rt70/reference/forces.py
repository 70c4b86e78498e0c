"""Spring and damper forces from Pinocchio's own kinematics (Pinocchio has no springs).

Every element is a deformation δ with its Jacobian ∂δ/∂v, computed here from
Pinocchio's frame placements and frame Jacobians of the attachment points and its
roll-pitch-yaw Jacobian for the Euler-angle rates — independently of the textbook
side's :class:`rt70.textbook.forces.Deformation`. Potential ``½ δᵀ C δ``, spring force
``−(∂δ/∂v)ᵀ C δ``, damper force ``−(∂δ/∂v)ᵀ D δ̇``; the results go to Pinocchio as
``tau`` (:func:`element_torques`) or back to book coordinates through ``Jᵀ``.

The element kinds are listed once, in :data:`ELEMENTS` (the same kinds as the textbook
side's, tested): the ``RobotDescription`` list each is read into, and the function
giving the deformations of all its elements at once (:class:`CoordinateElements` when
each δ is a joint's coordinate, :class:`GeneralElements` with batched dense Jacobians
otherwise). The sums over them — forces, gains, potential, magnitudes — are written
once, for every kind.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin

import rt70.reference.modal_nodes as modal_nodes
from rt70.errors import SingularConfigurationError
from rt70.guards.arrays import check_vector
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.model import FrameStack, ReferenceData, ReferenceModel

#: Same threshold as the textbook side: ``|cos θ|`` of the 1–2–3 angles below it is gimbal lock.
GIMBAL_LOCK_COS = 1e-8


@dataclass(frozen=True)
class CoordinateElements:
    """Elements of one kind whose deformation is one joint coordinate each (joint springs).

    ``δ_e`` is the coordinate of the 1-DOF joint with velocity index ``v_e`` (its angle
    for a continuous joint), so ``∂δ_e/∂v`` is the unit row ``v_e``: ``Jᵀ f`` scatters
    ``f`` on those indices, without forming J.

    Attributes
    ----------
    model : ReferenceModel
        The model the elements belong to.
    qp : numpy.ndarray
        Pinocchio's configuration they are evaluated at.
    index : numpy.ndarray
        Pinocchio velocity index of each element, shape (n_e,).
    stiffness, damping : numpy.ndarray
        C and D of each element, shape (n_e,).
    """

    model: ReferenceModel
    qp: np.ndarray
    index: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    @cached_property
    def delta(self) -> np.ndarray:
        """δ of each element, shape (n_e,); read on first use (the gains need none)."""
        return _joint_angles(self.model, self.qp)[self.index]

    def rate(self, vp: np.ndarray) -> np.ndarray:
        """``δ̇ = (∂δ/∂v) v`` of each element, shape (n_e,)."""
        return vp[self.index]

    def subtract_jt(self, Q: np.ndarray, f: np.ndarray) -> None:
        """``Q −= Σ_e (∂δ_e/∂v)ᵀ f_e`` in place."""
        np.subtract.at(Q, self.index, f)

    def add_abs_jt(self, S: np.ndarray, f: np.ndarray) -> None:
        """``S += Σ_e |∂δ_e/∂v|ᵀ |f_e|`` in place."""
        np.add.at(S, self.index, np.abs(f))

    def add_jt_w_j(self, K: np.ndarray, w: np.ndarray) -> None:
        """``K += Σ_e (∂δ_e/∂v)ᵀ W_e (∂δ_e/∂v)`` in place (``w``: one weight each).

        Unbuffered (``np.add.at``): two springs on one joint add up.
        """
        np.add.at(K, (self.index, self.index), w)

    def weighted(self, w: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``W_e x_e`` of each element (``w``: one weight each)."""
        return w * x

    def weighted_terms(self, w: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``|W_e| |x_e|``: the sizes of the terms of :meth:`weighted`."""
        return np.abs(w * x)

    def squares(self, w: np.ndarray) -> float:
        """``Σ_e δ_eᵀ W_e δ_e``."""
        return float(np.sum(w * self.delta**2))


@dataclass(frozen=True)
class GeneralElements:
    """Elements of one kind with a deformation and a dense Jacobian each, batched (bushings).

    Attributes
    ----------
    delta : numpy.ndarray
        δ of each element, shape (n_e, k).
    jacobian : numpy.ndarray or None
        ``∂δ/∂v`` of each element, shape (n_e, k, nv); None when not computed.
    stiffness, damping : numpy.ndarray
        C and D of each element, shape (n_e, k, k).
    """

    delta: np.ndarray
    jacobian: np.ndarray | None
    stiffness: np.ndarray
    damping: np.ndarray

    def rate(self, vp: np.ndarray) -> np.ndarray:
        """``δ̇ = (∂δ/∂v) v`` of each element, shape (n_e, k)."""
        return self.jacobian @ vp

    def subtract_jt(self, Q: np.ndarray, f: np.ndarray) -> None:
        """``Q −= Σ_e (∂δ_e/∂v)ᵀ f_e`` in place."""
        Q -= np.einsum("bin,bi->n", self.jacobian, f)

    def add_abs_jt(self, S: np.ndarray, f: np.ndarray) -> None:
        """``S += Σ_e |∂δ_e/∂v|ᵀ |f_e|`` in place."""
        S += np.einsum("bin,bi->n", np.abs(self.jacobian), np.abs(f))

    def add_jt_w_j(self, K: np.ndarray, w: np.ndarray) -> None:
        """``K += Σ_e (∂δ_e/∂v)ᵀ W_e (∂δ_e/∂v)`` in place (``w``: (n_e, k, k))."""
        K += np.einsum("bin,bij,bjm->nm", self.jacobian, w, self.jacobian, optimize=True)

    def weighted(self, w: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``W_e x_e`` of each element (``w``: (n_e, k, k), ``x``: (n_e, k))."""
        return np.einsum("bij,bj->bi", w, x)

    def weighted_terms(self, w: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``|W_e| |x_e|``: the sizes of the terms of :meth:`weighted`."""
        return np.einsum("bij,bj->bi", np.abs(w), np.abs(x))

    def squares(self, w: np.ndarray) -> float:
        """``Σ_e δ_eᵀ W_e δ_e``."""
        return float(np.einsum("bi,bi->", self.delta, self.weighted(w, self.delta)))


Elements = CoordinateElements | GeneralElements


def joint_spring_elements(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, jacobian: bool = True
) -> CoordinateElements | None:
    """Joint springs: δ is the joint's coordinate, read from Pinocchio's ``q``.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    jacobian : bool
        Whether to compute the Jacobians ``∂δ/∂v`` too (unused: a joint spring's is a unit row).
    """
    if not model.spring_v.size:
        return None
    return CoordinateElements(model, qp, model.spring_v, model.spring_k, model.spring_d)


def bushing_elements(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, jacobian: bool = True
) -> GeneralElements | None:
    """Bushings and struts: :func:`deformations` from Pinocchio's frame kinematics.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    jacobian : bool
        Whether to compute the Jacobians ``∂δ/∂v`` too (the potential needs none).
    """
    if not model.bushings:
        return None
    delta, jac = deformations(model, data, qp, jacobian=jacobian)
    return GeneralElements(delta, jac, model.stiffness, model.damping)


#: Every element kind of the reference side: the ``RobotDescription`` list its elements
#: are read into → the function giving their deformations at Pinocchio's ``qp`` (the
#: Jacobians only with ``jacobian=True``), None when the model has none. In summation
#: order; the textbook side lists the same kinds (tested).
ELEMENTS: dict[str, Callable[..., Elements | None]] = {
    "joint_springs": joint_spring_elements,
    "bushings": bushing_elements,
}


def elements(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, jacobian: bool = True
) -> list[Elements]:
    """The deformations of every element at Pinocchio's ``qp``, kind by kind.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    jacobian : bool
        Whether to compute the Jacobians ``∂δ/∂v`` too (the potential needs none).
    """
    found = [kind(model, data, qp, jacobian) for kind in ELEMENTS.values()]
    return [e for e in found if e is not None]


def spring_damper_force(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Spring force ``Q_c`` and damper force ``Q_d`` in book coordinates: ``Jᵀ τ``.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the book's
        order (:func:`rt70.urdf.coordinate_names`).
    """
    qp, vp, J, _ = to_pinocchio(model, q, qd)
    Qc, Qd = element_torques(model, data, qp, vp)
    if J is None:
        return Qc, Qd
    Qc, Qd = J.T @ Qc, J.T @ Qd
    if model.modal_bodies:  # their stiffness and damping act on η itself
        Kc, Kd = modal_nodes.elastic_force(model, q, qd)
        Qc, Qd = Qc + Kc, Qd + Kd
    return Qc, Qd


def element_torques(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, vp: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Spring and damper forces as Pinocchio joint torques τ_c, τ_d.

    ``qp``, ``vp`` are Pinocchio's own configuration and velocity (see
    :func:`~rt70.reference.coordinates.to_pinocchio`), and so are the results (its
    velocity space): the form ``pin.aba`` takes as ``tau``, used by the simulation's
    fast path.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp, vp : numpy.ndarray
        Pinocchio's configuration (nq,) and velocity (nv_pin,)
        (:func:`~rt70.reference.coordinates.to_pinocchio`).
    """
    nv = model.pin_model.nv
    Qc, Qd = np.zeros(nv), np.zeros(nv)
    for e in elements(model, data, qp):  # τ_c = −Σ Jᵀ C δ, τ_d = −Σ Jᵀ D δ̇
        e.subtract_jt(Qc, e.weighted(e.stiffness, e.delta))
        e.subtract_jt(Qd, e.weighted(e.damping, e.rate(vp)))
    return Qc, Qd


def element_gains(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``Σ Jᵀ C J`` and ``Σ Jᵀ D J`` of the springs and dampers, in Pinocchio's space.

    ``−∂τ_c/∂v`` without the term of the deformation's second derivative (the
    Gauss–Newton part) and ``−∂τ_d/∂v`` exactly: what an implicit integrator's
    Jacobian needs besides ``pin.computeABADerivatives``.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    """
    n = model.pin_model.nv
    K, D = np.zeros((n, n)), np.zeros((n, n))
    for e in elements(model, data, qp):
        e.add_jt_w_j(K, e.stiffness)
        e.add_jt_w_j(D, e.damping)
    return K, D


def spring_potential(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> float:
    """``Σ ½ δᵀ C δ`` with δ from Pinocchio's frame placements.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    """
    qp, _, _, _ = to_pinocchio(model, q)
    U = 0.0
    for e in elements(model, data, qp, jacobian=False):
        U += 0.5 * e.squares(e.stiffness)
    return U + modal_nodes.elastic_potential(model, q)


def spring_damper_magnitudes(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Sizes of the terms of the spring and damper forces: ``Σ_e |J_e|ᵀ |C_e δ_e|``.

    The same sums as :func:`spring_damper_force` with every term taken by its absolute
    value (joint springs ``|k q|``, bushings ``|∂δ/∂q|ᵀ |C δ|`` and
    ``|∂δ/∂q|ᵀ |D δ̇|``): forces of elements that oppose each other cancel in the sum
    but not here. The natural scale of :func:`rt70.crosscheck.scales.natural_scales`.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the book's
        order (:func:`rt70.urdf.coordinate_names`).
    """
    qp, vp, J, _ = to_pinocchio(model, q, qd)
    nv = model.pin_model.nv
    Sc, Sd = np.zeros(nv), np.zeros(nv)
    for e in elements(model, data, qp):
        e.add_abs_jt(Sc, e.weighted_terms(e.stiffness, e.delta))
        e.add_abs_jt(Sd, e.weighted_terms(e.damping, e.rate(vp)))
    return (Sc, Sd) if J is None else (np.abs(J).T @ Sc, np.abs(J).T @ Sd)


def deformations(model: ReferenceModel, data: ReferenceData, qp: np.ndarray, jacobian: bool = True):
    """δ of every bushing (n_b, 6) and ∂δ/∂v (n_b, 6, nv), from Pinocchio's kinematics.

    Frame placements ``oMi · placement`` and local frame Jacobians (Pinocchio's
    ``getFrameJacobian`` of a joint and a placement: the joint's ``LOCAL`` Jacobian moved
    by the placement's ``toActionMatrixInverse``) come from Pinocchio, one call per
    parent joint, applied to every frame at once (:class:`FrameStack`); the relative
    placement, Pinocchio's roll-pitch-yaw of its transpose and the inverse world rpy
    Jacobian are evaluated for all bushings at once (the formulas of
    ``pin.rpy.matrixToRpy`` / ``computeRpyJacobianInverse``, checked against them in
    the tests). ``c12 = Rx(β) Ry(θ) Rz(α)`` has ``c12ᵀ`` with rpy ``ρ = −[β, θ, α]``;
    the angular velocity of frame 2 relative to frame 1 is ``ω = J_W(ρ) φ̇``.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    jacobian : bool
        Whether to compute the Jacobians ``∂δ/∂v`` too (the potential needs none).
    """
    m, d = model.pin_model, data.pin_data
    qp = check_vector("qp", qp, m.nq)
    if jacobian:
        pin.computeJointJacobians(m, d, qp)
    else:
        pin.forwardKinematics(m, d, qp)
    f1, f2 = model.stack1, model.stack2
    R1, p1 = _placed(d, f1)
    R2, p2 = _placed(d, f2)
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
    joints = np.union1d(f1.joints, f2.joints)
    joint_jac = np.zeros((m.njoints, 6, m.nv))  # each parent joint's LOCAL Jacobian, once
    for joint in joints:
        # eigenpy returns a 6×1 Jacobian (nv = 1) as a vector of 6
        joint_jac[joint] = np.reshape(pin.getJointJacobian(m, d, int(joint), pin.LOCAL), (6, m.nv))
    J1 = f1.act_inverse @ joint_jac[f1.joints]  # getFrameJacobian(…, LOCAL), all frames
    J2 = f2.act_inverse @ joint_jac[f2.joints]
    # J_rel = J2 − Ad(M12⁻¹) J1; δ̇_trans = c12 v_rel, φ̇ = J_W(ρ)⁻¹ ω_rel
    lin1 = J1[:, :3] - _skew(r12) @ J1[:, 3:]
    jac = np.empty_like(J2)
    jac[:, :3] = c12 @ J2[:, :3] - lin1
    w_rel = J2[:, 3:] - ct @ J1[:, 3:]
    cy, sy, tp = np.cos(yaw), np.sin(yaw), np.tan(pitch)
    inv = np.zeros((len(R1), 3, 3))
    inv[:, 0, 0], inv[:, 0, 1] = cy / cp, sy / cp
    inv[:, 1, 0], inv[:, 1, 1] = -sy, cy
    inv[:, 2, 0], inv[:, 2, 1], inv[:, 2, 2] = cy * tp, sy * tp, 1.0
    jac[:, 3:] = inv @ w_rel
    return delta, jac


def _placed(d: pin.Data, frames: FrameStack) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (n, 3, 3) and origins (n, 3) of the frames, ``oMi[joint] · placement``."""
    joints = np.unique(frames.joints)
    R_joint = np.zeros((int(joints.max(initial=0)) + 1, 3, 3))
    p_joint = np.zeros((len(R_joint), 3))
    for joint in joints:
        R_joint[joint], p_joint[joint] = d.oMi[int(joint)].rotation, d.oMi[int(joint)].translation
    R, p = R_joint[frames.joints], p_joint[frames.joints]
    return R @ frames.rotations, p + (R @ frames.translations[..., None])[..., 0]


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
