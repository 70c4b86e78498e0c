"""Loop closures on the reference side: Pinocchio's ``RigidConstraintModel``.

Each ``<rt70:loop>`` is a ``RigidConstraintModel`` (``CONTACT_3D`` for ``point``,
``CONTACT_6D`` for ``frame``) between the parent joints of its two links, with the
frames' placements in them, in Pinocchio's ``LOCAL`` frame of constraint frame 1.
Everything is taken from Pinocchio and mapped to the book's coordinates through ``J``
of :func:`rt70.reference.coordinates.to_pinocchio` (``v = J q̇``) and to ground axes
through frame 1's rotation ``R₁``, independently of :mod:`rt70.textbook.loops`:

* ``Φ = [p₁ − p₂; log₃(R₁R₂ᵀ)]`` from ``oMi · placement`` (``pin.log3``);
* ``B_c = R₁ · getConstraintJacobian · J`` (Pinocchio's Jacobian of the relative
  velocity of the two frames, in frame 1's axes);
* ``C``: the frames' classical accelerations from ``pin.forwardKinematics(q, v, J̇q̇)``
  (Pinocchio's spatial accelerations at ``q̈ = 0``, made classical by ``ω × v``);
* ``pin.constraintDynamics`` with ``ProximalSettings`` (the proximal iterations take the
  dependent rows of a planar loop closed in 3-D) and the Baumgarte corrector
  ``Kp = ω²``, ``Kd = 2ζω`` — Pinocchio's placement error is ``−log₆(c₁Mc₂)``, for a
  point loop ``R₁ᵀ(p₁ − p₂)``, the same law as the textbook's. Pinocchio's multipliers
  (``data.lambda_c``, frame 1's axes) are turned to ground axes by ``R₁``.

Pinocchio's equations are ``M a = τ − h + J_cᵀ λ`` with ``J_c`` the Jacobian of frame
1 relative to frame 2, the sign of the textbook's ``A q̈ = f + B_cᵀ λ``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector
from rt70.physics.baumgarte import Baumgarte
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.forces import element_torques
from rt70.reference.model import ReferenceData, ReferenceModel

#: Proximal settings of ``pin.constraintDynamics``: absolute accuracy, μ, iterations.
PROXIMAL = (1e-14, 1e-10, 200)


def _frames(model: ReferenceModel, data: ReferenceData):
    """``(rows, oMc1, oMc2)`` of every loop for the kinematics in ``data``."""
    d = data.pin_data
    return [(rows, d.oMi[j1] * M1, d.oMi[j2] * M2) for rows, (j1, M1), (j2, M2) in model.loops]


def loop_residual(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> np.ndarray:
    """Φ(q), shape (m,): ``p₁ − p₂`` (and ``log₃(R₁R₂ᵀ)``) in ground axes.

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
    pin.forwardKinematics(model.pin_model, data.pin_data, qp)
    parts = []
    for rows, o1, o2 in _frames(model, data):
        parts.append(o1.translation - o2.translation)
        if rows == 6:
            parts.append(pin.log3(o1.rotation @ o2.rotation.T))
    return np.concatenate(parts) if parts else np.zeros(0)


def _constraints(model: ReferenceModel, data: ReferenceData, stabilization: Baumgarte | None):
    """Pinocchio's constraint models and datas for these gains (cached on ``data``)."""
    cache = data.__dict__.setdefault("loop_constraints", {})
    key = None if stabilization is None else stabilization.gains()
    if key not in cache:
        cmodels = pin.StdVec_RigidConstraintModel()
        for rows, (j1, M1), (j2, M2) in model.loops:
            kind = pin.ContactType.CONTACT_3D if rows == 3 else pin.ContactType.CONTACT_6D
            cm = pin.RigidConstraintModel(kind, model.pin_model, j1, M1, j2, M2, pin.LOCAL)
            if key is not None:
                cm.m_baumgarte_parameters.Kp, cm.m_baumgarte_parameters.Kd = key
            cmodels.append(cm)
        cdatas = pin.StdVec_RigidConstraintData()
        for cm in cmodels:
            cdatas.append(cm.createData())
        pin.initConstraintDynamics(model.pin_model, data.pin_data, cmodels, cdatas)
        cache[key] = (cmodels, cdatas)
    return cache[key]


def _rotations(model: ReferenceModel, data: ReferenceData) -> np.ndarray:
    """Block-diagonal ``R₁`` (one 3×3 block per three rows): frame 1's axes → ground."""
    blocks = [o1.rotation for rows, o1, _ in _frames(model, data) for _ in range(rows // 3)]
    out = np.zeros((3 * len(blocks), 3 * len(blocks)))
    for k, R in enumerate(blocks):
        out[3 * k : 3 * k + 3, 3 * k : 3 * k + 3] = R
    return out


def loop_jacobian(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> np.ndarray:
    """``B_c``, shape (m, nv): ``R₁ · getConstraintJacobian · J`` (``B_c q̇ = Φ̇``).

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
    qp, _, J, _ = to_pinocchio(model, q)
    m, d = model.pin_model, data.pin_data
    if not model.loops:
        return np.zeros((0, model.nv))
    cmodels, cdatas = _constraints(model, data, None)
    pin.computeJointJacobians(m, d, qp)  # also the forward kinematics
    blocks = []
    for cm, cd in zip(cmodels, cdatas, strict=True):
        cm.calc(m, d, cd)
        blocks.append(pin.getConstraintJacobian(m, d, cm, cd))
    B = _rotations(model, data) @ np.vstack(blocks)
    return B if J is None else B @ J


def loop_bias(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> np.ndarray:
    """``C = Ḃ_c q̇``, shape (m,): the frames' relative acceleration at ``q̈ = 0``.

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
    qp, vp, _, Jdqd = to_pinocchio(model, q, qd)
    m, d = model.pin_model, data.pin_data
    pin.forwardKinematics(m, d, qp, vp, np.zeros(m.nv) if Jdqd is None else Jdqd)
    parts = []
    for rows, (j1, M1), (j2, M2) in model.loops:
        acc = [_classical(d, j1, M1), _classical(d, j2, M2)]
        diff = acc[0] - acc[1]
        parts.append(diff if rows == 6 else diff[:3])
    return np.concatenate(parts) if parts else np.zeros(0)


def loop_terms(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Φ, B_c, C)``: :func:`loop_residual`, :func:`loop_jacobian` and :func:`loop_bias`.

    The twin of :func:`rt70.textbook.loops.loop_terms` (which shares one forward pass);
    here each of the three is computed on its own.

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
    return (
        loop_residual(model, data, q),
        loop_jacobian(model, data, q),
        loop_bias(model, data, q, qd),
    )


def _classical(d: pin.Data, joint: int, placement: pin.SE3) -> np.ndarray:
    """Ground-axis ``[a_p; ω̇]`` of a frame on a joint: classical acceleration of its origin."""
    if joint == 0:
        return np.zeros(6)
    v, a = placement.actInv(d.v[joint]), placement.actInv(d.a[joint])
    R = (d.oMi[joint] * placement).rotation
    linear = a.linear + np.cross(v.angular, v.linear)
    return np.concatenate([R @ linear, R @ a.angular])


def constrained_forward_dynamics(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    qd: np.ndarray,
    Q: np.ndarray | None = None,
    stabilization: Baumgarte | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(q̈, λ)`` by ``pin.constraintDynamics``; λ in ground axes (force on frame 1).

    τ holds the scene's springs and dampers (Pinocchio's own, :func:`element_torques`)
    and ``J⁻ᵀ Q``; ``q̈ = J⁻¹ (a − J̇ q̇)``. Raises :class:`~rt70.errors.Rt70Error` for a
    scene with mimic joints (Pinocchio's constraint dynamics has no mimic constraint).

    Parameters
    ----------
    model : ReferenceModel
        The reference model, with its loops.
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the book's
        order (:func:`rt70.urdf.coordinate_names`).
    Q : numpy.ndarray, shape (nv,), optional
        Further generalised forces (inputs) in the book's coordinates, N or N·m.
    stabilization : rt70.physics.baumgarte.Baumgarte, optional
        Gains of ``Φ̈ + 2ζω Φ̇ + ω² Φ = 0`` (Pinocchio's ``Kp = ω²``, ``Kd = 2ζω``);
        None: ``Φ̈ = 0``.
    """
    qp, vp, J, Jdqd = to_pinocchio(model, q, qd)
    if model.modal_bodies:
        raise Rt70Error(
            f"{model.pin_model.name}: loops with modal bodies are not supported on the "
            "reference side (Pinocchio's constraint dynamics would free their nodes)"
        )
    if J is not None and J.shape[0] != J.shape[1]:
        raise Rt70Error(f"{model.pin_model.name}: loops with mimic joints are not supported")
    m, d = model.pin_model, data.pin_data
    Qc, Qd = element_torques(model, data, qp, vp)
    tau = Qc + Qd
    if Q is not None:
        Q = check_vector("Q", Q, model.nv)
        tau = tau + (Q if J is None else np.linalg.solve(J.T, Q))
    cmodels, cdatas = _constraints(model, data, stabilization)
    settings = pin.ProximalSettings(*PROXIMAL)
    a = pin.constraintDynamics(m, d, qp, vp, tau, cmodels, cdatas, settings)
    lam = _rotations(model, data) @ np.asarray(d.lambda_c).copy()
    if J is None:
        return a, lam
    return np.linalg.solve(J, a - Jdqd), lam
