"""The constraint manifold Φ(q) = 0: constraints as callables of q and their algebra.

One job: what the equilibrium (:mod:`rt70.linear.constrained_equilibrium`) and the
linearisations (:mod:`rt70.linear.constrained`) on a manifold both need —

- holonomic constraints Φ(q) = 0 given as callables of q (:class:`Constraints`), stacked
  (:func:`combine`) or holding coordinates at values (:func:`fixed`);
- the split of ``B_c = ∂Φ/∂q`` into its row space and null space by the SVD
  (:func:`subspaces`), with the least-norm multipliers of a force and the least-norm step
  that closes Φ;
- the stiffness ``K = −∂Q/∂q`` of a static force by central differences
  (:func:`force_stiffness`) and the multipliers' geometric stiffness
  ``G = −Σ λ_i ∇²Φ_i`` (:func:`geometric_stiffness`).

Convention (that of :mod:`rt70.physics.kkt`): the reactions enter the equations of motion as
``A q̈ + B q̇ = Q + B_cᵀ λ`` with ``B_c = ∂Φ/∂q`` (companion source 004 (14),
``B_c q̈ + C = 0``); docs/constrained-modes.md.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error

#: A function of the coordinates q, shape (n,), to a vector (a force, a residual).
Vector = Callable[[np.ndarray], np.ndarray]

#: Singular values of B_c below this fraction of the largest count as zero (dependent
#: constraint rows, as in :data:`rt70.physics.kkt.RANK_RTOL`).
RANK_RTOL = 1e-10
#: Central-difference step per coordinate of the stiffness matrices (m or rad): the
#: truncation error is O(h²) ≈ 1e-12 relative, the rounding O(ε/h) ≈ 1e-10 relative.
FD_STEP = 1e-6
#: Newton (the equilibrium's, and that of a partition's dependent coordinates) stops when
#: its step moves no coordinate by more than this (relative to the largest ``|q|``, at least
#: 1): the configuration is fixed to rounding.
STEP_TOL = 1e-13


@dataclass(frozen=True)
class Constraints:
    """Holonomic constraints Φ(q) = 0 as callables of q.

    Attributes
    ----------
    residual : callable
        ``Φ(q)``, shape (m,).
    jacobian : callable
        ``B_c(q) = ∂Φ/∂q``, shape (m, n) (``B_c q̇ = Φ̇``).
    bias : callable, optional
        ``C(q, q̇) = Ḃ_c q̇`` (``B_c q̈ + C = 0``, source 004 (14)), shape (m,). For
        holonomic Φ its row i is the quadratic form ``q̇ᵀ ∇²Φ_i q̇``, so it gives the
        geometric stiffness exactly (:func:`geometric_stiffness`); without it G is
        differenced from the Jacobian.
    """

    residual: Vector
    jacobian: Vector
    bias: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None

    def evaluate(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(Φ(q), B_c(q))`` as float arrays of shapes (m,) and (m, n), checked."""
        phi = np.atleast_1d(np.asarray(self.residual(q), dtype=float))
        B = np.asarray(self.jacobian(q), dtype=float)
        B = B.reshape(phi.size, q.size if B.size == 0 else -1)
        if B.shape[1] != q.size:
            raise Rt70Error(f"constraint Jacobian has {B.shape[1]} columns, q has {q.size}")
        if not (np.isfinite(phi).all() and np.isfinite(B).all()):
            raise Rt70Error("constraint residual or Jacobian is NaN or infinite")
        return phi, B


def combine(*parts: Constraints) -> Constraints:
    """The constraints of all ``parts`` stacked (their rows in the given order)."""

    def residual(q: np.ndarray) -> np.ndarray:
        return np.concatenate([np.atleast_1d(p.residual(q)) for p in parts])

    def jacobian(q: np.ndarray) -> np.ndarray:
        return np.vstack([np.atleast_2d(p.jacobian(q)) for p in parts])

    def bias(q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return np.concatenate([np.atleast_1d(p.bias(q, qd)) for p in parts])

    exact = all(p.bias is not None for p in parts)
    return Constraints(residual, jacobian, bias if exact else None)


def fixed(n: int, indices: Sequence[int], values: Sequence[float]) -> Constraints:
    """Linear constraints ``q[i] = value``: held coordinates.

    The multiplier of a row is the force that holds its coordinate; ∇²Φ = 0, so the rows
    add no geometric stiffness.

    Parameters
    ----------
    n : int
        Number of coordinates.
    indices : sequence of int
        The held coordinates' indices in q.
    values : sequence of float
        Their values, m or rad.
    """
    idx = np.asarray(indices, dtype=int)
    val = np.asarray(values, dtype=float)
    E = np.eye(n)[idx]
    return Constraints(lambda q: np.asarray(q)[idx] - val, lambda q: E, lambda q, qd: 0.0 * val)


# ------------------------------------------------------------------------ linear algebra


@dataclass(frozen=True)
class Subspaces:
    """The row space and null space of B_c from its SVD ``B_c = U Σ Vᵀ``.

    Attributes
    ----------
    null : ndarray, shape (n, n − r)
        Orthonormal basis N of the null space (the admissible displacements δq = N z).
    row : ndarray, shape (n, r)
        Orthonormal basis R of the row space.
    U, sigma : ndarray
        The r left singular vectors and singular values kept.
    rank : int
        r, the number of independent constraint rows.
    """

    null: np.ndarray
    row: np.ndarray
    U: np.ndarray
    sigma: np.ndarray
    rank: int

    def multipliers(self, Q: np.ndarray) -> np.ndarray:
        """Least-norm λ with ``B_cᵀ λ`` closest to ``−Q`` (exact at an equilibrium)."""
        return -self.U @ ((self.row.T @ Q) / self.sigma)

    def closing_step(self, phi: np.ndarray) -> np.ndarray:
        """Least-norm δq in the row space with ``B_c δq = −Φ`` (on the independent rows)."""
        return -self.row @ ((self.U.T @ phi) / self.sigma)


def subspaces(B_c: np.ndarray, rank_rtol: float = RANK_RTOL) -> Subspaces:
    """SVD split of B_c (m, n) into row and null space; dependent rows are dropped."""
    B_c = np.atleast_2d(np.asarray(B_c, dtype=float))
    n = B_c.shape[1]
    if B_c.shape[0] == 0:
        return Subspaces(np.eye(n), np.zeros((n, 0)), np.zeros((0, 0)), np.zeros(0), 0)
    U, s, Vt = np.linalg.svd(B_c)
    r = int(np.sum(s > rank_rtol * s[0])) if s.size and s[0] > 0 else 0
    return Subspaces(Vt[r:].T, Vt[:r].T, U[:, :r], s[:r], r)


def force_stiffness(force: Vector, q: np.ndarray, h: float = FD_STEP) -> np.ndarray:
    """``K = −∂force/∂q`` by central differences with step h per coordinate, symmetrised.

    The stiffness of a conservative force (its Jacobian is a Hessian of the potential).

    Parameters
    ----------
    force : callable
        ``q ↦ Q(q)``, shape (n,): N or N·m per coordinate.
    q : numpy.ndarray, shape (n,)
        The point, m or rad per coordinate.
    h : float
        The difference step per coordinate, m or rad.
    """
    cols = []
    for i in range(q.size):
        e = np.zeros(q.size)
        e[i] = h
        cols.append(-(np.asarray(force(q + e)) - np.asarray(force(q - e))) / (2.0 * h))
    K = np.column_stack(cols)
    return 0.5 * (K + K.T)


def geometric_stiffness(
    constraints: Constraints, q: np.ndarray, lam: np.ndarray, h: float = FD_STEP
) -> np.ndarray:
    """``G = −∂(B_c(q)ᵀ λ)/∂q = −Σ λ_i ∇²Φ_i`` at fixed λ.

    The stiffness the reactions add when the constraint surface is curved: with the
    reactions ``+B_cᵀ λ`` on the right-hand side, ``K + G`` is the stiffness along the
    manifold. With the constraints' ``bias`` it is exact, by polarisation of the
    quadratic form ``λᵀ C(q, u) = uᵀ (Σ λ_i ∇²Φ_i) u``:
    ``G_jj = −λᵀ C(e_j)``, ``G_jk = −½ λᵀ (C(e_j + e_k) − C(e_j) − C(e_k))``
    (n(n+1)/2 calls). Without it, central differences of ``B_cᵀ λ`` with step h per
    coordinate (2n calls), symmetrised (the ∇²Φ_i are symmetric).

    Parameters
    ----------
    constraints : Constraints
        Φ, B_c and, if known, the bias C.
    q : array_like, shape (n,)
        The point (on the manifold), m or rad per coordinate.
    lam : array_like, shape (m,)
        The multipliers λ, one per constraint row (N or N·m for a row of m or rad).
    h : float
        The difference step per coordinate, m or rad (without the bias).
    """
    q = np.asarray(q, dtype=float)
    lam = np.asarray(lam, dtype=float)
    if constraints.bias is None:
        return force_stiffness(lambda x: constraints.evaluate(x)[1].T @ lam, q, h)
    n = q.size
    eye = np.eye(n)

    def form(u: np.ndarray) -> float:
        C = np.atleast_1d(np.asarray(constraints.bias(q, u), dtype=float))
        if C.shape != lam.shape:
            raise Rt70Error(f"constraint bias has shape {C.shape}, the multipliers {lam.shape}")
        return float(lam @ C)

    diag = np.array([form(eye[j]) for j in range(n)])
    H = np.diag(diag)
    for j in range(n):
        for k in range(j + 1, n):
            H[j, k] = H[k, j] = 0.5 * (form(eye[j] + eye[k]) - diag[j] - diag[k])
    return -H


def force_vector(force: Vector, q: np.ndarray) -> np.ndarray:
    """``force(q)`` as a finite float vector of q's length, or a clear error.

    Raises
    ------
    Rt70Error
        If the force's shape is not q's, or it is NaN or infinite.
    """
    Q = np.asarray(force(q), dtype=float)
    if Q.shape != q.shape:
        raise Rt70Error(f"the force has shape {Q.shape}, q has {q.shape}")
    if not np.isfinite(Q).all():
        raise Rt70Error("the force is NaN or infinite")
    return Q
