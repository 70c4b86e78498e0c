"""Locks on the reference side: their rows, and their impact by Pinocchio's ``impulseDynamics``.

The sudden constraint (companion source 004 (15)) is built in Pinocchio's own velocity
space ``v``, independently of the textbook side (:mod:`rt70.textbook.locks`):

- a **brake** on a 1-DOF joint is the unit row of the joint's velocity index
  ``idx_v`` in ``v``;
- a **stow pin** fixing the point ``xyz`` of a link is the linear part of Pinocchio's
  frame Jacobian ``getFrameJacobian(model, data, joint, placement, LOCAL)`` of the
  point (the link's body frame moved by ``xyz``), turned to ground axes by the point's
  rotation ``oMi[joint] · placement``. This is the ``LOCAL_WORLD_ALIGNED`` Jacobian
  without Pinocchio's detour through the ground origin, which costs ε times the point's
  distance from the origin (the RT-70's points are 20–80 m up; see
  :mod:`rt70.reference.points`). It is computed here from ``computeJointJacobians``, not
  by :func:`rt70.reference.points.point_jacobian` (``computeJointJacobian`` in the
  joint's frame): the two reference paths agreeing with the textbook is a check of
  both.

``pin.impulseDynamics(model, data, q, v⁻, J_c, e, 0)`` then solves
``M v⁺ = M v⁻ + J_cᵀ Λ``, ``J_c v⁺ = −e J_c v⁻`` by its Cholesky factorisation of the
KKT matrix, which needs independent rows: dependent ones (a pin on a planar mechanism,
two locks that overlap) are first reduced to an orthonormal basis of the row space,
``Ĵ = U_rᵀ J_c`` (SVD, :data:`RANK_RTOL`), and ``Λ = U_r Λ̂`` is then the least-norm
impulse, as the textbook's :func:`rt70.physics.kkt.solve_kkt`. Where the book's coordinates
are Pinocchio's ``v = J q̇`` with J square (continuous, floating, planar joints, a
reordering), Pinocchio solves in ``v`` and ``q̇⁺ = J⁻¹ v⁺``; with mimic joints (J tall)
the reduced equations are solved in the book's coordinates with Pinocchio's CRBA, as
the forward dynamics does (:func:`_reduced_impact`). Known impulses Γ (book coordinates,
the sign of :mod:`rt70.physics.impact`) come in by linearity: a second ``impulseDynamics`` from
``v⁻ = J A⁻¹ Γ`` with e = 0.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.dynamics import mass_matrix
from rt70.reference.model import ReferenceData, ReferenceModel
from rt70.reference.points import point_jacobian_pinocchio

#: Singular values of the constraint rows below this fraction of the largest count as
#: zero (dependent rows).
RANK_RTOL = 1e-10

#: Pinocchio joint kinds whose velocity is the coordinate's rate (a brake can hold them).
BRAKEABLE = ("1dof", "continuous", "mimic", "mimic-continuous")


def brake_row(model: ReferenceModel, joint: str) -> np.ndarray:
    """Row (nv_pin,) of a brake on ``joint`` in Pinocchio's velocity space."""
    m = model.pin_model
    if not m.existJointName(joint):
        raise Rt70Error(f"{m.name}: no joint '{joint}' among Pinocchio's joints")
    jid = m.getJointId(joint)
    found = [c for c in model.coords if c.joint == jid and c.kind in BRAKEABLE]
    if not found:
        raise Rt70Error(f"{m.name}: joint '{joint}' is not a 1-DOF joint; a brake holds one")
    row = np.zeros(m.nv)
    row[found[0].iv] = 1.0
    return row


def pin_rows(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, link: str, xyz
) -> np.ndarray:
    """Rows (3, nv_pin) of a stow pin at the point ``xyz`` of ``link``, ground axes.

    ``qp`` is Pinocchio's configuration: the point's velocity rows of
    :func:`rt70.reference.points.point_jacobian_pinocchio`.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    link : str
        Name of a URDF link of the scene.
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    return point_jacobian_pinocchio(model, data, qp, link, xyz)[:3]


def constraint_rows(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    brakes: Sequence[str] = (),
    pins: Sequence[tuple[str, np.ndarray]] = (),
) -> np.ndarray:
    """The locks' rows in Pinocchio's velocity space, (m, nv_pin): brakes, then pins.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    brakes : sequence of str
        The braked joints (1-DOF), one row each.
    pins : sequence of (str, array_like)
        The stow pins: a link and the point fixed to the ground in the link's frame (m),
        three rows each.
    """
    qp, _, _, _ = to_pinocchio(model, q)
    return _pinocchio_rows(model, data, qp, brakes, pins)


def _pinocchio_rows(model, data, qp, brakes, pins) -> np.ndarray:
    """:func:`constraint_rows` at Pinocchio's configuration ``qp``."""
    rows = [brake_row(model, j)[None] for j in brakes]
    rows += [pin_rows(model, data, qp, link, xyz) for link, xyz in pins]
    return np.vstack(rows) if rows else np.zeros((0, model.pin_model.nv))


def book_rows(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    brakes: Sequence[str] = (),
    pins: Sequence[tuple[str, np.ndarray]] = (),
) -> np.ndarray:
    """The locks' rows ``B_c = J_c J`` in the book's coordinates, (m, nv).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    brakes : sequence of str
        The braked joints (1-DOF), one row each.
    pins : sequence of (str, array_like)
        The stow pins: a link and the point fixed to the ground in the link's frame (m),
        three rows each.
    """
    qp, _, J, _ = to_pinocchio(model, q)
    J_c = _pinocchio_rows(model, data, qp, brakes, pins)
    return J_c if J is None else J_c @ J


def _reduced(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(U_r, Ĵ = U_rᵀ rows)``: an orthonormal basis of the rows' space."""
    U, s, Vt = np.linalg.svd(rows, full_matrices=False)
    keep = s > RANK_RTOL * s[0] if s.size and s[0] > 0 else np.zeros(s.size, dtype=bool)
    return U[:, keep], s[keep, None] * Vt[keep]


def impulse_dynamics(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    qd: np.ndarray,
    brakes: Sequence[str] = (),
    pins: Sequence[tuple[str, np.ndarray]] = (),
    restitution: float = 0.0,
    gamma: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(q̇⁺, Λ)`` of the locks engaging at ``(q, q̇⁻)``, by ``pin.impulseDynamics``.

    Parameters
    ----------
    model, data : ReferenceModel, ReferenceData
        The reference side of the scene.
    q, qd : numpy.ndarray
        The configuration and the velocities before, ``q̇⁻`` (book coordinates).
    brakes : sequence of str
        Joints braked (1-DOF).
    pins : sequence of (link, xyz)
        Points fixed to the ground.
    restitution : float
        e (``J_c v⁺ = −e J_c v⁻``).
    gamma : numpy.ndarray, optional
        Known impulses Γ in book coordinates, (nv,).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        q̇⁺ (nv,) and the least-norm impulses Λ, one per row (brakes first, then three
        per pin, ground axes).
    """
    qp, vp, J, _ = to_pinocchio(model, q, qd)
    m, d = model.pin_model, data.pin_data
    J_c = constraint_rows(model, data, q, brakes, pins)
    gam = None if gamma is None else check_vector("gamma", gamma, model.nv)
    if J is not None and J.shape[0] > J.shape[1]:
        return _reduced_impact(model, data, q, qd, J_c @ J, restitution, gam)
    U_r, J_hat = _reduced(J_c)

    def solve(v_before: np.ndarray, e: float) -> tuple[np.ndarray, np.ndarray]:
        if not J_hat.shape[0]:  # the rows vanish here: nothing holds, nothing changes
            return np.array(v_before, dtype=float), np.zeros(J_c.shape[0])
        v_after = pin.impulseDynamics(m, d, qp, v_before, J_hat, e, 0.0)
        return np.array(v_after), U_r @ np.array(d.impulse_c)

    v_after, lam = solve(vp, restitution)
    if gam is not None:
        extra = np.linalg.solve(mass_matrix(model, data, q), gam)  # A⁻¹ Γ
        v2, lam2 = solve(extra if J is None else J @ extra, 0.0)
        v_after, lam = v_after + v2, lam + lam2
    if J is None:
        return v_after, lam
    return np.linalg.solve(J, v_after), lam


def _reduced_impact(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    qd: np.ndarray,
    B_c: np.ndarray,
    restitution: float,
    gamma: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """The impact in the book's coordinates, for models with mimic joints.

    Pinocchio's ``v`` then has more entries than the book's q̇ and ``impulseDynamics``
    would need the mimic couplings as extra rows, which loses every digit when a mimic
    factor is large (10³⁰ in tests/test_urdf_reading.py). As the forward dynamics does
    (:func:`rt70.reference.dynamics.forward_dynamics`), the reduced equations
    ``A = Jᵀ crba J`` with the rows ``B_c = J_c J`` are solved instead — the KKT matrix
    of an orthonormal basis of the rows by LU (numpy), not by the textbook's
    range-space method. They are solved for the jump ``Δq̇ = q̇⁺ − q̇⁻`` (not for q̇⁺
    from ``A q̇⁻``, whose round trip through A⁻¹ costs ε·cond(A)), so rows that hold
    nothing — a brake on a mimic joint of multiplier 0 — leave q̇ exactly unchanged.
    """
    n = model.nv
    A = mass_matrix(model, data, q)
    U_r, B_hat = _reduced(B_c)
    r = B_hat.shape[0]
    gam = np.zeros(n) if gamma is None else gamma
    K = np.block([[A, B_hat.T], [B_hat, np.zeros((r, r))]])
    rhs = np.concatenate([gam, -(1.0 + restitution) * (B_hat @ qd)])
    sol = np.linalg.solve(K, rhs)  # the jump: A Δq̇ + B̂ᵀ y = Γ, B̂ Δq̇ = −(1 + e) B̂ q̇⁻
    return qd + sol[:n], U_r @ -sol[n:]  # y = −Λ̂
