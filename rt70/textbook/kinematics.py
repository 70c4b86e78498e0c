"""Pair kinematics, configuration matrix L and structure matrix S (book §4.1–§4.2)."""

from __future__ import annotations

import numpy as np

from rt70.guards.arrays import check_vector
from rt70.textbook.data import Data
from rt70.textbook.model import Model
from rt70.textbook.spatial import (
    axis_rotation,
    c3,
    euler123,
    euler_matrix,
    placement,
    skew,
)


def pair_motion(model: Model, j: int, qj: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Variable part of pair j: translation ``r_j^{jc}``, rotation ``c_j^{jc}``, ``M_j f_j``.

    ``V_j^{jc,j} = M_j f_j q̇_j`` (4.10)/(4.13); for the euler6 pair
    ``M_j = diag(c_jᵀ, ε_j)`` with the Euler matrix ε of (1.38).

    Parameters
    ----------
    model : Model
        The textbook model.
    j : int
        The pair.
    qj : numpy.ndarray, shape (k_j,)
        The pair's coordinates (its slice of ``q_full``), rad or m.
    """
    kind = model.kind[j]
    if kind == "euler6":
        c = euler123(qj[3:])
        mf = np.zeros((6, 6))
        mf[:3, :3] = c.T
        mf[3:, 3:] = euler_matrix(qj[3:])
        return qj[:3].copy(), c, mf
    if kind == "planar":
        c = c3(qj[2])
        mf = np.zeros((6, 3))
        mf[:3, :2] = c.T[:, :2]
        mf[5, 2] = 1.0
        return np.array([qj[0], qj[1], 0.0]), c, mf
    a = model.axis[j]
    if kind == "revolute":
        return np.zeros(3), axis_rotation(a, qj[0]), np.concatenate([np.zeros(3), a])[:, None]
    if kind == "prismatic":
        return a * qj[0], np.eye(3), np.concatenate([a, np.zeros(3)])[:, None]
    return np.zeros(3), np.eye(3), np.zeros((6, 0))


def pair_motion_rate(model: Model, j: int, qj: np.ndarray, qdj: np.ndarray) -> np.ndarray:
    """``Ṁ_j f_j`` (6 × k_j): zero except for the euler6 pair (4.82).

    For it ``Ṁ_j = diag(ċ_jᵀ, ε̇_j)``, ``ċ = c <ω_rel>``, ``ω_rel = ε φ̇``, so ``ċᵀ = −<ω_rel> cᵀ``.

    Parameters
    ----------
    model : Model
        The textbook model.
    j : int
        The pair.
    qj, qdj : numpy.ndarray, shape (k_j,)
        The pair's coordinates (rad or m) and velocities (rad/s or m/s).
    """
    if model.kind[j] == "planar":
        out = np.zeros((6, 3))
        out[:3, :2] = (-skew(np.array([0.0, 0.0, qdj[2]])) @ c3(qj[2]).T)[:, :2]
        return out
    if model.kind[j] != "euler6":
        return np.zeros((6, int(model.ndof[j])))
    phi, dphi = qj[3:], qdj[3:]
    omega = euler_matrix(phi) @ dphi
    _, theta, alpha = phi
    st, ct, sa, ca = np.sin(theta), np.cos(theta), np.sin(alpha), np.cos(alpha)
    d_eps_dtheta = np.array([[-st * ca, 0, 0], [st * sa, 0, 0], [ct, 0, 0]])
    d_eps_dalpha = np.array([[-ct * sa, ca, 0], [-ct * ca, -sa, 0], [0, 0, 0]])
    out = np.zeros((6, 6))
    out[:3, :3] = -skew(omega) @ euler123(phi).T
    out[3:, 3:] = dphi[1] * d_eps_dtheta + dphi[2] * d_eps_dalpha
    return out


def forward_kinematics(model: Model, data: Data, q: np.ndarray) -> None:
    """Forward pass: pair transforms ``L_i^j`` (4.5)–(4.7), ``M_j f_j``, absolute poses.

    ``L_i^j = T(r_jc^i)[c_jc^i] · T(r_j^jc)[c_j^jc]``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers: ``L_pair``, ``Mf``, ``R`` and ``p`` are set here.
    q : numpy.ndarray, shape (n_full,)
        Pair coordinates ``q_full = G q + q_offset`` (mimic joints included), rad or m.
    """
    for j in range(model.nb):
        r, c, mf = pair_motion(model, j, q[model.coords(j)])
        r_total = model.r_c[j] + model.c_c[j] @ r
        c_total = model.c_c[j] @ c
        data.L_pair[j] = placement(r_total, c_total)
        data.Mf[j] = mf
        i = model.parent[j]
        if i < 0:
            data.R[j], data.p[j] = c_total, r_total
        else:
            data.R[j] = data.R[i] @ c_total
            data.p[j] = data.p[i] + data.R[i] @ r_total


def configuration_matrix(model: Model, data: Data) -> np.ndarray:
    """Configuration matrix L (4.64): identity blocks on the diagonal, ``L_k^j`` above.

    Block (k, j) is ``L_k^j = L_k^{i} L_i^j`` (chain property, i = parent of j) when k is
    an ancestor of j, zero otherwise.
    """
    L = data.L
    L[:] = 0.0
    for j in range(model.nb):
        L[6 * j : 6 * j + 6, 6 * j : 6 * j + 6] = np.eye(6)
        i = model.parent[j]
        for k in model.ancestors(i) if i >= 0 else []:
            L[6 * k : 6 * k + 6, 6 * j : 6 * j + 6] = (
                L[6 * k : 6 * k + 6, 6 * i : 6 * i + 6] @ (data.L_pair[j])
            )
    return L


def structure_matrix(model: Model, data: Data) -> np.ndarray:
    """Structure matrix ``S = [f]ᵀ Mᵀ L`` (4.66); ``V⁰ = Sᵀ q̇`` (4.63).

    Row block k (pair k's coordinates), column block j: ``(M_k f_k)ᵀ L_k^j``. With mimic
    constraints the rows are reduced to the independent coordinates, ``S = Gᵀ S_full``.
    """
    S = data.S_full
    L = data.L
    for k in range(model.nb):
        rows = model.coords(k)
        S[rows, :] = data.Mf[k].T @ L[6 * k : 6 * k + 6, :]
    data.S = model.reduce(S)
    return data.S


def update_structure(model: Model, data: Data, q: np.ndarray) -> np.ndarray:
    """Run forward kinematics and fill L and S for configuration q; return S.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers: the forward pass, ``q_full``, L and S are set here.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    data.q_full = model.expand(q)
    forward_kinematics(model, data, data.q_full)
    configuration_matrix(model, data)
    return structure_matrix(model, data)


def frame_jacobian(data: Data, body: int, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Jacobian of a frame fixed to ``body`` at ``(r, c)``: its velocity in its own axes.

    ``V_F = (T(r)[c])ᵀ V_body`` (formalism §0) and ``V_body = (Sᵀ q̇)_body`` (4.63).
    The ground (``body = −1``) has a zero Jacobian.

    Parameters
    ----------
    data : Data
        Work buffers holding S of the configuration (:func:`update_structure`).
    body : int
        The body (pair index) the frame is fixed to; −1 for the ground.
    r : numpy.ndarray, shape (3,)
        The frame's origin in the body's frame, m.
    c : numpy.ndarray, shape (3, 3)
        The frame's orientation in the body's frame.
    """
    if body < 0:
        return np.zeros((6, data.S.shape[0]))
    return placement(r, c).T @ data.S[:, 6 * body : 6 * body + 6].T


def frame_pose(
    data: Data, body: int, r: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Absolute orientation and origin of a frame fixed to ``body`` at ``(r, c)``.

    Parameters
    ----------
    data : Data
        Work buffers holding the poses of the configuration (:func:`forward_kinematics`).
    body : int
        The body (pair index) the frame is fixed to; −1 for the ground.
    r : numpy.ndarray, shape (3,)
        The frame's origin in the body's frame, m.
    c : numpy.ndarray, shape (3, 3)
        The frame's orientation in the body's frame.
    """
    if body < 0:
        return c, r
    return data.R[body] @ c, data.p[body] + data.R[body] @ r
