"""A flexible body in the floating frame of reference: its mass matrix and velocity terms.

One job: the equations of one modal body on its own — a frame that moves as a rigid body
and ``k`` modal coordinates η that deform it — written from its inertia invariants, as
the floating-frame-of-reference (FFRF) literature does (Shabana, *Dynamics of Multibody
Systems*, ch. 5; Schwertassek & Wallrapp, *Dynamik flexibler Mehrkörpersysteme*, 1999,
the "standard input data"). The tree's algorithm places the body (its frame's velocity
``[v; ω]`` comes from the pairs above it, as a rigid body's); this module gives what the
body adds to A, the velocity terms and the forces (docs/fe-models.md).

The body: N nodes with lumped masses ``m_n`` at ``x_n`` in the body frame, moved by the
mode shapes ``Φ_n`` (3 × k, body frame) to ``r_n = x_n + Φ_n η``. With the body-frame
velocities ``w = [v; ω; η̇]`` a node moves at ``v + ω × r_n + Φ_n η̇``, so

    T = ½ wᵀ M(η) w,   M(η) = [[ m I,   −S̃,   C_t ],
                               [  S̃,    J,    C_r ],
                               [ C_tᵀ,  C_rᵀ, M_ηη]]

with ``m = Σ m_n``, the first moment ``S = Σ m_n r_n``, the inertia about the frame's
origin ``J = Σ m_n r̃_nᵀ r̃_n``, the couplings ``C_t = Σ m_n Φ_n`` and
``C_r = Σ m_n r̃_n Φ_n``, the modal mass ``M_ηη = Σ m_n Φ_nᵀ Φ_n`` — each a polynomial in
η whose coefficients are the invariants (:class:`Invariants`), summed over the nodes once.
Nothing is linearised in η: with lumped masses the body is exactly the nodes' motion
restricted to ``u = Φ η``.

The equations of motion are Kirchhoff's for the frame and Lagrange's for η, with
``p = M(η) w``:

    d/dt p_v + ω × p_v                 = F,
    d/dt p_ω + ω × p_ω + v × p_v       = N,
    d/dt p_η − ∂T/∂η                   = Q_η − K η − D η̇,

so ``M(η) ẇ + h(η, w) = [F; N; Q_η] − [0; 0; K η + D η̇]`` with the velocity terms
``h = Ṁ w + [ω × p_v; ω × p_ω + v × p_v; −½ wᵀ (∂M/∂η_j) w]`` (:func:`velocity_terms`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.textbook.spatial import skew
from rt70.textbook.spatial_batch import skew_batch


@dataclass(frozen=True)
class Invariants:
    """The inertia invariants of a modal body: sums over its nodes, made once.

    Attributes
    ----------
    mass : float
        ``m = Σ m_n``, kg.
    first : numpy.ndarray, shape (3,)
        ``Σ m_n x_n``, kg·m.
    first_modal : numpy.ndarray, shape (3, k)
        ``C_t = Σ m_n Φ_n``.
    second : numpy.ndarray, shape (3, 3)
        ``Σ m_n x_n x_nᵀ``, kg·m².
    second_mixed : numpy.ndarray, shape (k, 3, 3)
        ``Σ m_n x_n (Φ_n e_j)ᵀ`` for each mode j.
    second_modal : numpy.ndarray, shape (k, k, 3, 3)
        ``Σ m_n (Φ_n e_i)(Φ_n e_j)ᵀ`` for each pair of modes.
    rotation_coupling : numpy.ndarray, shape (3, k)
        ``Σ m_n x̃_n Φ_n``.
    rotation_modal : numpy.ndarray, shape (k, 3, k)
        ``Σ m_n (Φ_n e_j)~ Φ_n`` for each mode j.
    modal_mass : numpy.ndarray, shape (k, k)
        ``M_ηη = Σ m_n Φ_nᵀ Φ_n``.
    """

    mass: float
    first: np.ndarray
    first_modal: np.ndarray
    second: np.ndarray
    second_mixed: np.ndarray
    second_modal: np.ndarray
    rotation_coupling: np.ndarray
    rotation_modal: np.ndarray
    modal_mass: np.ndarray

    @property
    def modes(self) -> int:
        """k, the number of modal coordinates."""
        return self.modal_mass.shape[0]


def inertia_invariants(nodes: np.ndarray, masses: np.ndarray, shapes: np.ndarray) -> Invariants:
    """The invariants of N lumped nodal masses and their k mode shapes.

    Parameters
    ----------
    nodes : numpy.ndarray, shape (N, 3)
        ``x_n``: the nodes in the body frame, m.
    masses : numpy.ndarray, shape (N,)
        ``m_n``: the lumped masses, kg.
    shapes : numpy.ndarray, shape (N, 3, k)
        ``Φ_n``: each node's displacement per unit modal coordinate, body frame.
    """
    x = np.asarray(nodes, dtype=float)
    m = np.asarray(masses, dtype=float)
    phi = np.asarray(shapes, dtype=float)
    x_skew = skew_batch(x)
    phi_skew = skew_batch(np.moveaxis(phi, 2, 0))  # (k, N, 3, 3)
    return Invariants(
        mass=float(m.sum()),
        first=m @ x,
        first_modal=np.einsum("n,naj->aj", m, phi),
        second=np.einsum("n,na,nb->ab", m, x, x),
        second_mixed=np.einsum("n,na,nbj->jab", m, x, phi),
        second_modal=np.einsum("n,nai,nbj->ijab", m, phi, phi),
        rotation_coupling=np.einsum("n,nab,nbj->aj", m, x_skew, phi),
        rotation_modal=np.einsum("n,jnab,nbi->jai", m, phi_skew, phi),
        modal_mass=np.einsum("n,nai,naj->ij", m, phi, phi),
    )


def _second_moment(inv: Invariants, eta: np.ndarray) -> np.ndarray:
    """``Σ m_n r_n r_nᵀ`` at η."""
    mixed = np.einsum("j,jab->ab", eta, inv.second_mixed)
    return inv.second + mixed + mixed.T + np.einsum("i,j,ijab->ab", eta, eta, inv.second_modal)


def _inertia(second_moment: np.ndarray) -> np.ndarray:
    """``Σ m (|r|² I − r rᵀ)`` from ``Σ m r rᵀ``."""
    return np.trace(second_moment) * np.eye(3) - second_moment


def body_mass_matrix(inv: Invariants, eta: np.ndarray) -> np.ndarray:
    """M(η), (6 + k) × (6 + k), over the body-frame velocities ``[v; ω; η̇]``.

    Parameters
    ----------
    inv : Invariants
        The body's invariants.
    eta : numpy.ndarray, shape (k,)
        The modal coordinates.
    """
    k = inv.modes
    s_tilde = skew(inv.first + inv.first_modal @ eta)
    rotation = inv.rotation_coupling + np.einsum("j,jai->ai", eta, inv.rotation_modal)
    M = np.zeros((6 + k, 6 + k))
    M[:3, :3] = inv.mass * np.eye(3)
    M[:3, 3:6], M[3:6, :3] = -s_tilde, s_tilde
    M[3:6, 3:6] = _inertia(_second_moment(inv, eta))
    M[:3, 6:], M[6:, :3] = inv.first_modal, inv.first_modal.T
    M[3:6, 6:], M[6:, 3:6] = rotation, rotation.T
    M[6:, 6:] = inv.modal_mass
    return M


def mass_matrix_derivative(inv: Invariants, eta: np.ndarray, j: int) -> np.ndarray:
    """∂M/∂η_j at η (the mass matrix is affine in η but for J, quadratic).

    Parameters
    ----------
    inv : Invariants
        The body's invariants.
    eta : numpy.ndarray, shape (k,)
        The modal coordinates.
    j : int
        The modal coordinate differentiated by.
    """
    k = inv.modes
    ds = skew(inv.first_modal[:, j])
    mixed = inv.second_mixed[j]
    d_second = (
        mixed
        + mixed.T
        + np.einsum("i,iab->ab", eta, inv.second_modal[:, j])
        + np.einsum("i,iab->ab", eta, inv.second_modal[j, :])
    )
    dM = np.zeros((6 + k, 6 + k))
    dM[:3, 3:6], dM[3:6, :3] = -ds, ds
    dM[3:6, 3:6] = _inertia(d_second)
    dM[3:6, 6:], dM[6:, 3:6] = inv.rotation_modal[j], inv.rotation_modal[j].T
    return dM


def velocity_terms(
    inv: Invariants, eta: np.ndarray, w: np.ndarray, mass: np.ndarray | None = None
) -> np.ndarray:
    """h(η, w): the body's velocity terms (module docstring), (6 + k,).

    ``Ṁ w = Σ_j η̇_j (∂M/∂η_j) w`` and ``½ wᵀ (∂M/∂η_j) w`` for all j at once, from the
    blocks of ∂M/∂η_j (:func:`mass_matrix_derivative`) without forming them:
    ``[−a_j × ω;  a_j × v + J_j ω + R_j η̇;  R_jᵀ ω]`` with ``a_j = C_t e_j``, ``J_j``
    the inertia of ∂(Σ m r rᵀ)/∂η_j and ``R_j`` the rotation coupling's derivative.

    Parameters
    ----------
    inv : Invariants
        The body's invariants.
    eta : numpy.ndarray, shape (k,)
        The modal coordinates.
    w : numpy.ndarray, shape (6 + k,)
        ``[v; ω; η̇]``: the frame's velocity and angular velocity in its own axes (m/s,
        rad/s) and the modal rates.
    mass : numpy.ndarray, shape (6 + k, 6 + k), optional
        ``M(η)`` when the caller has it (:func:`body_mass_matrix`).
    """
    v, omega, eta_dot = w[:3], w[3:6], w[6:]
    p = (body_mass_matrix(inv, eta) if mass is None else mass) @ w
    a = inv.first_modal.T  # (k, 3): a_j
    mixed = inv.second_mixed + np.swapaxes(inv.second_mixed, 1, 2)
    d_second = (
        mixed
        + np.einsum("i,ijab->jab", eta, inv.second_modal)
        + np.einsum("i,jiab->jab", eta, inv.second_modal)
    )  # (k, 3, 3): ∂(Σ m r rᵀ)/∂η_j
    trace = np.trace(d_second, axis1=1, axis2=2)
    u = np.empty((a.shape[0], w.size))  # row j: (∂M/∂η_j) w
    u[:, :3] = -np.cross(a, omega)
    u[:, 3:6] = (
        np.cross(a, v) + trace[:, None] * omega - d_second @ omega + inv.rotation_modal @ eta_dot
    )
    u[:, 6:] = np.einsum("jai,a->ji", inv.rotation_modal, omega)
    h = eta_dot @ u
    h[:3] += np.cross(omega, p[:3])
    h[3:6] += np.cross(omega, p[3:6]) + np.cross(v, p[:3])
    h[6:] -= 0.5 * (u @ w)
    return h
