"""Equations of motion from Pinocchio's recursive algorithms, in the book's coordinates.

``algorithm(model, data, q, …)`` as on the textbook side (:mod:`rt70.textbook.dynamics`):
CRBA for A, RNEA for ``B q̇`` and gravity, ABA for ``q̈``, Pinocchio's energies — each
mapped back through ``J`` of :func:`rt70.reference.coordinates.to_pinocchio`.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import rt70.reference.modal_nodes as modal_nodes
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.forces import element_gains, element_torques
from rt70.reference.model import ReferenceData, ReferenceModel


def _crba(model: ReferenceModel, data: ReferenceData, qp: np.ndarray) -> np.ndarray:
    """Pinocchio's CRBA, symmetrised (it fills the upper triangle)."""
    A = pin.crba(model.pin_model, data.pin_data, qp)
    return np.triu(A) + np.triu(A, 1).T


def mass_matrix(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> np.ndarray:
    """``A = Jᵀ crba J`` (``J`` includes the map to the user's order).

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
    A = _crba(model, data, qp)
    return A if J is None else J.T @ A @ J


def bias_force(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> np.ndarray:
    """``B(q, q̇) q̇ = Jᵀ rnea(q, v, J̇ q̇)`` with gravity switched off.

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
    qp, vp, J, Jdqd = to_pinocchio(model, q, qd)
    pm, pd = model.pin_model_no_gravity, data.pin_data_no_gravity
    if J is None:
        return pin.rnea(pm, pd, qp, vp, np.zeros(model.nv))
    return J.T @ pin.rnea(pm, pd, qp, vp, Jdqd)


def gravity_force(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> np.ndarray:
    """Generalised gravity force on the right-hand side: ``−Jᵀ g(q)``.

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
    g = pin.computeGeneralizedGravity(model.pin_model, data.pin_data, qp)
    return -g if J is None else -(J.T @ g)


def newton_stiffness(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray
) -> np.ndarray | None:
    """Newton's matrix of a static equilibrium: ``∂g/∂q + Σ Jᵀ C J``, symmetrised.

    The stiffness ``K = −∂(Q_g + Q_c)/∂q`` (formalism §4.4) without the springs'
    geometric term (each element's force times the second derivative of its
    deformation): gravity's part exact (Pinocchio's
    ``computeGeneralizedGravityDerivatives``), the springs' part the Gauss–Newton
    :func:`~rt70.reference.forces.element_gains`. It steers Newton's steps; the
    equilibrium is decided by the residual, so the term left out slows the convergence
    (a contraction by its ratio to K per step), not the answer.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order.

    Returns
    -------
    numpy.ndarray, shape (nv, nv), or None
        N·m/rad or N/m per coordinate pair; None when the book's coordinates are not
        Pinocchio's own (modal bodies, mimic joints, reordered or Euler-angle joints).
    """
    if not model.identity_map:
        return None
    dg = pin.computeGeneralizedGravityDerivatives(model.pin_model, data.pin_data, q)
    K = dg + element_gains(model, data, q)[0]
    return 0.5 * (K + K.T)


def forward_dynamics(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> np.ndarray:
    """``q̈`` under gravity and the scene's springs and dampers: ``pin.aba`` with them as τ.

    Unlike the textbook side's ``forward_dynamics(model, data, q, q̇, Q)`` the spring
    and damper forces are the reference side's own (:func:`element_torques`, in
    Pinocchio's velocity space), so that the comparison checks them too. With mimic
    joints (a constraint ABA cannot take) or modal bodies (nodes tied to the modes) the
    reduced equations
    ``Jᵀ A J q̈ = Jᵀ (τ − rnea(q, v, J̇ q̇))`` are solved with Pinocchio's CRBA and RNEA.

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
    qp, vp, J, Jdqd = to_pinocchio(model, q, qd)
    Qc, Qd = element_torques(model, data, qp, vp)
    tau = Qc + Qd
    pm, pd = model.pin_model, data.pin_data
    if J is None:
        return pin.aba(pm, pd, qp, vp, tau)
    if J.shape[0] == J.shape[1] and not model.modal_bodies:
        vdot = pin.aba(pm, pd, qp, vp, tau)
        return np.linalg.solve(J, vdot - Jdqd)
    A = _crba(model, data, qp)
    rhs = J.T @ (tau - pin.rnea(pm, pd, qp, vp, Jdqd))
    if model.modal_bodies:  # their stiffness and damping act on η itself
        Kc, Kd = modal_nodes.elastic_force(model, q, qd)
        rhs += Kc + Kd
    return np.linalg.solve(J.T @ A @ J, rhs)


def kinetic_energy(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray
) -> float:
    """``pin.computeKineticEnergy``.

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
    qp, vp, _, _ = to_pinocchio(model, q, qd)
    return float(pin.computeKineticEnergy(model.pin_model, data.pin_data, qp, vp))


def gravity_potential(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> float:
    """``pin.computePotentialEnergy`` (gravity only).

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
    return float(pin.computePotentialEnergy(model.pin_model, data.pin_data, qp))


def weight_moment(model: ReferenceModel, data: ReferenceData, q: np.ndarray) -> float:
    """``G₀ = Σ_b m_b |g| |c_b|``: the moment of the weights about the ground origin.

    ``c_b`` is body b's centre of mass in the ground frame (Pinocchio's joint placements
    ``oMi`` and inertia levers). It is the size of the terms that gravity torques and
    the gravity potential are sums and differences of (the natural scale of
    :func:`rt70.crosscheck.scales.natural_scales`), in N·m = J.

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
    pm, pd = model.pin_model, data.pin_data
    pin.forwardKinematics(pm, pd, qp)
    g = float(np.linalg.norm(pm.gravity.linear))
    total = 0.0
    for i in range(1, pm.njoints):
        inertia = pm.inertias[i]
        com = pd.oMi[i].act(inertia.lever)
        total += inertia.mass * g * float(np.linalg.norm(com))
    return total
