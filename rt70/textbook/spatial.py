"""Small spatial-algebra helpers of the book, shared by every textbook algorithm.

Spatial vectors are ``[linear; angular]`` (formalism §0): body velocity ``V = [v; ω]``,
wrench ``Ξ = [F; K]``.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import SingularConfigurationError
from rt70.physics.rotations import c1, c2, c3, rpy_matrix, rpy_of_matrix  # noqa: F401 (the book's (1.23))

#: Gimbal-lock threshold: configurations with ``|cos θ|`` below this raise
#: :class:`~rt70.errors.SingularConfigurationError` wherever Euler-angle rates are needed.
GIMBAL_LOCK_COS = 1e-8

#: Gimbal-lock threshold of the dynamics of a 6-DOF Euler pair: its M_j = diag(cᵀ, ε)
#: makes cond(A) grow as 1/cos²θ, and accelerations lose accuracy as ε·cond(A) (the
#: stress report measures 1e-5 relative at ``|cos θ| = 1e-4`` with springs, and 66 % at
#: 1e-8). Forward dynamics refuses pairs with ``|cos θ|`` below this.
DYNAMICS_GIMBAL_COS = 1e-4


def check_euler_pairs(model, q_full: np.ndarray, threshold: float = DYNAMICS_GIMBAL_COS) -> None:
    """Raise :class:`SingularConfigurationError` if an euler6 pair is near gimbal lock.

    ``θ`` is the pair's fifth coordinate (``q_j = [x, y, z, β, θ, α]``); the Euler
    matrix (1.38) is singular at ``θ = ±π/2``.

    Parameters
    ----------
    model : rt70.textbook.model.Model
        The textbook model.
    q_full : numpy.ndarray, shape (n_full,)
        Pair coordinates ``q_full = G q + q_offset``, rad or m.
    threshold : float
        Smallest ``|cos θ|`` accepted (:data:`DYNAMICS_GIMBAL_COS` by default).
    """
    for j, kind in enumerate(model.kind):
        if kind == "euler6":
            theta = float(q_full[model.q_start[j] + 4])
            if abs(np.cos(theta)) < threshold:
                raise SingularConfigurationError(
                    f"pair '{model.body_names[j]}': θ = {theta:.17g} rad is within "
                    f"|cos θ| = {abs(np.cos(theta)):.3g} < {threshold:g} of gimbal lock "
                    "(Euler matrix (1.38) singular; accelerations would be unreliable)"
                )


def euler_theta_indices(model) -> np.ndarray:
    """Indices in the full q of every euler6 pair's θ (what :func:`check_euler_pairs` reads)."""
    return np.array(
        [model.q_start[j] + 4 for j, kind in enumerate(model.kind) if kind == "euler6"],
        dtype=int,
    )


def skew(x: np.ndarray) -> np.ndarray:
    """Return ``<x>``, the skew matrix with ``<x> y = x × y`` (formalism §0)."""
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def euler123(phi: np.ndarray) -> np.ndarray:
    """Rotation ``c = c1(β) c2(θ) c3(α)`` of the 1–2–3 sequence, ``phi = [β, θ, α]``."""
    return c1(phi[0]) @ c2(phi[1]) @ c3(phi[2])


def axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit vector ``axis`` (Rodrigues' formula)."""
    k = skew(axis)
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def euler123_angles(c: np.ndarray) -> np.ndarray:
    """Return ``[β, θ, α]`` with ``euler123([β, θ, α]) = c``, ``|θ| ≤ π/2``.

    Raises
    ------
    SingularConfigurationError
        If ``|cos θ| < GIMBAL_LOCK_COS`` (gimbal lock, the Euler matrix (1.38) is
        singular and the angles are not unique).
    """
    sin_theta = float(np.clip(c[0, 2], -1.0, 1.0))
    cos_theta = float(np.hypot(c[0, 0], c[0, 1]))
    if cos_theta < GIMBAL_LOCK_COS:
        raise SingularConfigurationError(
            f"Euler angles 1-2-3 at gimbal lock: |cos θ| = {cos_theta:.3g} < "
            f"{GIMBAL_LOCK_COS:g} (θ = ±π/2)"
        )
    beta = np.arctan2(-c[1, 2], c[2, 2])
    theta = np.arctan2(sin_theta, cos_theta)
    alpha = np.arctan2(-c[0, 1], c[0, 0])
    return np.array([beta, theta, alpha])


def euler_matrix(phi: np.ndarray) -> np.ndarray:
    """Euler matrix ε of (1.38): body angular velocity ``ω = ε φ̇`` for 1–2–3 angles.

    ``ε = [c3ᵀ c2ᵀ e_x | c3ᵀ e_y | e_z]``.
    """
    _, theta, alpha = phi
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    return np.array([[ct * ca, sa, 0.0], [-ct * sa, ca, 0.0], [st, 0.0, 1.0]])


def euler_matrix_inverse(phi: np.ndarray) -> np.ndarray:
    """Inverse of the Euler matrix (1.38): ``φ̇ = ε⁻¹ ω``.

    Raises
    ------
    SingularConfigurationError
        At gimbal lock, ``|cos θ| < GIMBAL_LOCK_COS``.
    """
    _, theta, alpha = phi
    ct, st = np.cos(theta), np.sin(theta)
    if abs(ct) < GIMBAL_LOCK_COS:
        raise SingularConfigurationError(
            f"Euler matrix (1.38) singular: θ = {theta:.17g} is within "
            f"{GIMBAL_LOCK_COS:g} of ±π/2 (gimbal lock)"
        )
    ca, sa = np.cos(alpha), np.sin(alpha)
    return np.array([[ca / ct, -sa / ct, 0.0], [sa, ca, 0.0], [-st * ca / ct, st * sa / ct, 1.0]])


def translation(r: np.ndarray) -> np.ndarray:
    """Translation matrix ``T(r) = [[1, 0], [<r>, 1]]`` of (4.3)."""
    t = np.eye(6)
    t[3:, :3] = skew(r)
    return t


def rotation_block(c: np.ndarray) -> np.ndarray:
    """Block rotation ``[c] = diag(c, c)`` of (4.3)."""
    out = np.zeros((6, 6))
    out[:3, :3] = c
    out[3:, 3:] = c
    return out


def placement(r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """``T(r) [c]``: a frame at ``r`` rotated by ``c``; ``V_j = (T(r)[c])ᵀ V_i`` (4.3)."""
    out = np.zeros((6, 6))
    out[:3, :3] = c
    out[3:, 3:] = c
    out[3:, :3] = skew(r) @ c
    return out


def crf(v: np.ndarray) -> np.ndarray:
    """Force cross product ``Φ(V) = [[<ω>, 0], [<v>, <ω>]]`` of (1.55)/(1.57)."""
    out = np.zeros((6, 6))
    w = skew(v[3:])
    out[:3, :3] = w
    out[3:, 3:] = w
    out[3:, :3] = skew(v[:3])
    return out


def crm(v: np.ndarray) -> np.ndarray:
    """Motion cross product ``V×``, equal to ``−Φ(V)ᵀ``."""
    return -crf(v).T


def body_inertia(mass: float, com: np.ndarray, inertia_com: np.ndarray) -> np.ndarray:
    """Θ about a frame displaced by ``p = com`` from the centre of mass (4.77).

    ``Θ = T(p) diag(m 1₃, I_c) T(p)ᵀ = [[m 1₃, −m<p>], [m<p>, I_c − m<p><p>]]``.

    Parameters
    ----------
    mass : float
        The body's mass m, kg.
    com : numpy.ndarray, shape (3,)
        Its centre of mass p in the frame, m.
    inertia_com : numpy.ndarray, shape (3, 3)
        Its inertia tensor ``I_c`` about the centre of mass in the frame's axes, kg·m².
    """
    p = skew(com)
    out = np.zeros((6, 6))
    out[:3, :3] = mass * np.eye(3)
    out[:3, 3:] = -mass * p
    out[3:, :3] = mass * p
    out[3:, 3:] = inertia_com - mass * (p @ p)
    return out
