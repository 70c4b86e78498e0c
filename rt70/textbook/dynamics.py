"""Equations of motion ``A(q) q̈ + B(q, q̇) q̇ = Q`` by the book's matrix algorithm (§4.3).

Every function takes the plain model, its work buffers and the state, in the manner of
Pinocchio's ``crba(model, data, q)``. This is the dense, readable form of the book:
L, S and Θ are assembled as full block matrices. The kinetic and gravity energies are
here too, as on the reference side (:mod:`rt70.reference.dynamics`). The modal flexible
bodies add their terms to each (:mod:`rt70.textbook.modal_bodies`).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector
from rt70.textbook import modal_bodies
from rt70.textbook.data import Data
from rt70.textbook.kinematics import pair_motion_rate, update_structure
from rt70.textbook.model import Model
from rt70.textbook.spatial import check_euler_pairs, crf


def mass_matrix(model: Model, data: Data, q: np.ndarray) -> np.ndarray:
    """Mass matrix ``A = S Θ Sᵀ`` (4.79).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    S = update_structure(model, data, q)
    data.A = S @ data.Theta @ S.T
    if model.modal:
        data.A += modal_bodies.mass_matrix_terms(model, modal_bodies.dense_frames(model, data), q)
    return data.A


def body_velocities(model: Model, data: Data, qd: np.ndarray) -> np.ndarray:
    """Absolute body velocities ``V⁰ = Sᵀ q̇`` (4.63), each in its own body frame.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers, with S of the configuration (:func:`update_structure`); ``data.V``
        is set here.
    qd : numpy.ndarray, shape (nv,)
        Generalised velocities, rad/s or m/s.
    """
    qd = check_vector("qd", qd, model.nv)
    data.V = (data.S.T @ qd).reshape(model.nb, 6)
    return data.V


def structure_matrix_rate(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``Ṡ = [f]ᵀ (Ṁᵀ L + Mᵀ L̇)`` (4.81), with ``L̇_k^j = L_k^j Φ(V_j^{k,j})`` (§4.2).

    ``V_j^{k,j} = V_j⁰ − (L_k^j)ᵀ V_k⁰`` is the velocity of body j relative to body k,
    in j's frame. Requires :func:`body_velocities` to have been called for (q, q̇).
    With mimic constraints (constant G) ``Ṡ = Gᵀ Ṡ_full``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers with L, S (:func:`update_structure`) and V
        (:func:`body_velocities`) of this state.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).
    """
    L, V = data.L, data.V
    q_full, qd_full = data.q_full, model.expand(qd, offset=False)
    S_dot = np.zeros_like(data.S_full)
    for k in range(model.nb):
        rows = model.coords(k)
        if rows.stop == rows.start:
            continue
        mf = data.Mf[k]
        dmf = pair_motion_rate(model, k, q_full[rows], qd_full[rows])
        for j in range(model.nb):
            L_kj = L[6 * k : 6 * k + 6, 6 * j : 6 * j + 6]
            if not L_kj.any():
                continue
            v_rel = V[j] - L_kj.T @ V[k]
            L_kj_dot = L_kj @ crf(v_rel)
            S_dot[rows, 6 * j : 6 * j + 6] = dmf.T @ L_kj + mf.T @ L_kj_dot
    return model.reduce(S_dot)


def bias_matrix(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Matrix ``B = S Θ Ṡᵀ + S Φ⁰ Θ Sᵀ`` (4.80), ``Φ⁰ = diag(Φ(V_k⁰))``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).

    Raises
    ------
    Rt70Error
        For a model with modal bodies: their velocity terms are a vector, not
        ``B q̇`` of one matrix (:func:`bias_force` gives them).
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    if model.modal:
        raise Rt70Error(
            f"{model.name}: B is not formed as a matrix with modal bodies; use bias_force"
        )
    update_structure(model, data, q)
    return _bias_matrix(model, data, q, qd)


def _bias_matrix(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """B of (4.80) for the configuration already in ``data`` (L, S up to date)."""
    S = data.S
    V = body_velocities(model, data, qd)
    S_dot = data.S_dot = structure_matrix_rate(model, data, q, qd)  # kept for the loops' C
    Phi0 = np.zeros_like(data.Theta)
    for k in range(model.nb):
        Phi0[6 * k : 6 * k + 6, 6 * k : 6 * k + 6] = crf(V[k])
    return S @ data.Theta @ S_dot.T + S @ Phi0 @ data.Theta @ S.T


def bias_force(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Velocity-product force ``B(q, q̇) q̇`` (4.78)–(4.81).

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
    return _bias_force(model, data, q, qd)


def _bias_force(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``B q̇`` for the configuration already in ``data``, the modal bodies' terms added."""
    force = _bias_matrix(model, data, q, qd) @ qd
    if model.modal:
        frames = modal_bodies.dense_frames(model, data, qd)
        force += modal_bodies.bias_terms(model, frames, q, qd)
    return force


def gravity_force(model: Model, data: Data, q: np.ndarray) -> np.ndarray:
    """Generalised gravity force ``Q_g = S G`` (4.113)–(4.128).

    ``G_k = [m_k g_k; <p_cm,k> m_k g_k] = Θ_k [g_k; 0]``, ``g_k = c_{0k}ᵀ g0``.

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
    force = _gravity_force(model, data)
    if model.modal:
        force += modal_bodies.gravity_terms(model, modal_bodies.dense_frames(model, data), q)
    return force


def _gravity_force(model: Model, data: Data) -> np.ndarray:
    """``S G`` for the configuration already in ``data``."""
    accel = np.zeros((model.nb, 6))
    accel[:, :3] = np.einsum("kji,j->ki", data.R, model.gravity)
    G = np.einsum("kij,kj->ki", model.Theta, accel).ravel()
    return data.S @ G


def forward_dynamics(
    model: Model, data: Data, q: np.ndarray, qd: np.ndarray, Q: np.ndarray
) -> np.ndarray:
    """``q̈ = A⁻¹ (Q_g + Q − B q̇)`` with Q the other generalised forces (springs, inputs).

    A is factorised by Cholesky (it is symmetric positive definite for a well-posed
    model); a singular A raises :class:`~rt70.errors.Rt70Error`, and an Euler pair
    within ``DYNAMICS_GIMBAL_COS`` of gimbal lock a
    :class:`~rt70.errors.SingularConfigurationError`.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).
    Q : numpy.ndarray, shape (nv,)
        The other generalised forces (springs, dampers, inputs), N or N·m.
    """
    Q = check_vector("Q", Q, model.nv)
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    check_euler_pairs(model, model.expand(q))
    update_structure(model, data, q)  # one forward pass for A, B q̇ and S G
    rhs = Q + _gravity_force(model, data) - _bias_force(model, data, q, qd)
    A = data.S @ data.Theta @ data.S.T
    if model.modal:
        frames = modal_bodies.dense_frames(model, data)
        A += modal_bodies.mass_matrix_terms(model, frames, q)
        rhs += modal_bodies.gravity_terms(model, frames, q)
    try:
        factor = scipy.linalg.cho_factor(A)
    except np.linalg.LinAlgError:
        raise Rt70Error("mass matrix A is not positive definite at this configuration") from None
    return scipy.linalg.cho_solve(factor, rhs)


def gravity_potential(model: Model, data: Data, q: np.ndarray) -> float:
    """Gravity potential ``−Σ m_k g0 · (p_k + c_{0k} p_cm,k)`` of the moving bodies.

    Bodies welded to the ground through fixed joints only are part of E0: their
    potential is a constant and is left out (Pinocchio's convention too).

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
    com_world = data.p + np.einsum("kij,kj->ki", data.R, model.com)
    moving = np.array([model.ndof[model.ancestors(j)].sum() > 0 for j in range(model.nb)])
    potential = -float((model.mass * moving) @ (com_world @ model.gravity))
    if model.modal:
        potential += modal_bodies.gravity_potential(
            model, modal_bodies.dense_frames(model, data), q
        )
    return potential


def kinetic_energy(model: Model, data: Data, q: np.ndarray, qd: np.ndarray) -> float:
    """Kinetic energy ``½ q̇ᵀ A q̇`` (1.61).

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
    qd = check_vector("qd", qd, model.nv)
    return 0.5 * float(qd @ mass_matrix(model, data, q) @ qd)
