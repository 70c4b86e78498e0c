"""Spring and damper generalised forces of the textbook side (formalism §4.4).

Every elastic element is defined by its deformation δ(q): its potential is
``U = ½ δᵀ C δ``, its force ``Q_c = −(∂δ/∂q)ᵀ C δ`` and its damper's force
``Q_d = −(∂δ/∂q)ᵀ D δ̇`` with ``δ̇ = (∂δ/∂q) q̇`` — conservative by construction, so the
energy audit (1.73) closes. The book's direct pair (4.83) and strut package
(4.85)–(4.110) are both bushings between two frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.arrays import check_vector
from rt70.errors import SingularConfigurationError
from rt70.textbook.data import Data
from rt70.textbook.kinematics import (
    frame_jacobian,
    frame_pose,
    update_structure,
)
from rt70.textbook.model import BushingModel, Model
from rt70.textbook.spatial import euler123_angles, euler_matrix_inverse, placement


@dataclass(frozen=True)
class Deformation:
    """Deformation δ of one elastic element and its Jacobian ``∂δ/∂q`` (6 × nv)."""

    delta: np.ndarray
    jacobian: np.ndarray


def bushing_deformation(data: Data, b: BushingModel) -> Deformation:
    """Deformation of a bushing: frame 2's position in frame 1, and its 1–2–3 angles.

    With ``V_rel`` the velocity of frame 2 relative to frame 1 in frame 2's axes,
    ``δ̇ = M⁻¹ V_rel``, ``M = diag(cᵀ, ε)`` (1.38), c the relative rotation — the
    kinematic Euler equations of one body (formalism §1), read backwards.
    """
    R1, p1 = frame_pose(data, b.body1, b.r1, b.c1)
    R2, p2 = frame_pose(data, b.body2, b.r2, b.c2)
    r12 = R1.T @ (p2 - p1)
    c12 = R1.T @ R2
    try:
        phi = euler123_angles(c12)
    except SingularConfigurationError as exc:
        raise SingularConfigurationError(f"bushing '{b.name}': {exc}") from None
    J1 = frame_jacobian(data, b.body1, b.r1, b.c1)
    J2 = frame_jacobian(data, b.body2, b.r2, b.c2)
    J_rel = J2 - placement(r12, c12).T @ J1
    jac = np.empty_like(J_rel)
    jac[:3] = c12 @ J_rel[:3]
    jac[3:] = euler_matrix_inverse(phi) @ J_rel[3:]
    return Deformation(np.concatenate([r12, phi]), jac)


def spring_damper_force(
    model: Model, data: Data, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Generalised spring force ``Q_c`` and damper force ``Q_d`` of all elements."""
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    update_structure(model, data, q)
    q_full, qd_full = data.q_full, model.expand(qd, offset=False)
    idx = model.spring_coords
    Qc = np.zeros(model.n_full)
    Qd = np.zeros(model.n_full)
    np.subtract.at(Qc, idx, model.spring_stiffness * q_full[idx])
    np.subtract.at(Qd, idx, model.spring_damping * qd_full[idx])
    Qc, Qd = model.reduce(Qc), model.reduce(Qd)
    for b in model.bushings:
        d = bushing_deformation(data, b)
        Qc -= d.jacobian.T @ (b.stiffness * d.delta)
        Qd -= d.jacobian.T @ (b.damping * (d.jacobian @ qd))
    return Qc, Qd


def spring_potential(model: Model, data: Data, q: np.ndarray) -> float:
    """Elastic potential ``Σ ½ δᵀ C δ`` of all springs."""
    q = check_vector("q", q, model.nv)
    update_structure(model, data, q)
    idx = model.spring_coords
    U = 0.5 * float(np.sum(model.spring_stiffness * data.q_full[idx] ** 2))
    for b in model.bushings:
        delta = bushing_deformation(data, b).delta
        U += 0.5 * float(delta @ (b.stiffness * delta))
    return U


def gravity_potential(model: Model, data: Data, q: np.ndarray) -> float:
    """Gravity potential ``−Σ m_k g0 · (p_k + c_{0k} p_cm,k)`` of the moving bodies.

    Bodies welded to the ground through fixed joints only are part of E0: their
    potential is a constant and is left out (Pinocchio's convention too).
    """
    update_structure(model, data, q)
    com_world = data.p + np.einsum("kij,kj->ki", data.R, model.com)
    moving = np.array([model.ndof[model.ancestors(j)].sum() > 0 for j in range(model.nb)])
    return -float((model.mass * moving) @ (com_world @ model.gravity))


def kinetic_energy(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> float:
    """Kinetic energy ``½ q̇ᵀ A q̇`` (1.61)."""
    from rt70.textbook.dynamics import mass_matrix

    qd = check_vector("qd", qd, model.nv)
    return 0.5 * float(qd @ mass_matrix(model, data, q) @ qd)
