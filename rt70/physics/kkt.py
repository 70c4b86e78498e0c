"""The constrained equations of motion (14) of companion source 004, solved correctly.

With m additional constraints ``B_c(q) q̈ = g`` (loop closure, a brake, a stow pin) the
equations of motion ``A q̈ = f`` gain the reactions ``B_cᵀ λ``::

    [ A    B_cᵀ ] [  q̈ ]   [ f ]        f = Q − B q̇ + P   (everything but the reactions)
    [ B_c   0   ] [ −λ ] = [ g ]        g = −C(q, q̇)       (B_c q̈ + C = 0)

The same system with ``q̇⁺`` for ``q̈``, ``A q̇⁻ + Γ`` for f and 0 for g is the impact
(15), its λ the impulses Λ.

The matrix is symmetric but **indefinite** (n positive and m negative eigenvalues when
B_c has full rank; erratum X.3.11 of the companion sources), so the conjugate gradients
the source proposes are not guaranteed to converge. This module uses the range-space
method instead: the Cholesky factor ``A = L Lᵀ`` of the positive definite mass matrix,
``Y = L⁻¹ B_cᵀ``, and the Schur complement ``B_c A⁻¹ B_cᵀ = Yᵀ Y`` through the singular
values of Y, so that redundant constraints (a planar loop closed in 3-D has dependent
rows) give the unique q̈ and the least-norm λ instead of a singular solve. Constraints
that contradict each other are refused. λ gets one step of iterative refinement
(``λ += W⁺ (r − Yᵀ Y λ)``, Higham §12.1): the SVD's error in a small singular value of Y
(rows nearly dependent: a stow pin near a singular configuration) otherwise reaches λ
amplified by ``1/σ_min²``; on g1 (example-robot-data) a pin with ``cond W = 7e8`` had
λ off the exact solution of its own A, B_c by 14 times the first-order rounding bound
of :func:`rt70.crosscheck.impact_check.impact_scales`, 0.16 times after one step (Pinocchio's
``impulseDynamics``: 0.03).

Plain linear algebra below both sides: the textbook side and the analyses use it, the
reference side compares against Pinocchio's ``constraintDynamics``/``impulseDynamics``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error

#: Singular values of ``L⁻¹ B_cᵀ`` below this fraction of the largest count as zero
#: (dependent constraint rows).
RANK_RTOL = 1e-10


@dataclass(frozen=True)
class KKTSolution:
    """Solution of ``A x = f + B_cᵀ λ``, ``B_c x = g``.

    Attributes
    ----------
    x : numpy.ndarray
        q̈ (or q̇⁺ for an impact), shape (n,).
    lam : numpy.ndarray
        The multipliers λ (reactions, or impulses Λ), shape (m,); the least-norm ones
        when the constraint rows are dependent.
    rank : int
        Number of independent constraint rows (m when B_c has full row rank).
    """

    x: np.ndarray
    lam: np.ndarray
    rank: int


def solve_kkt(
    A: np.ndarray, B_c: np.ndarray, f: np.ndarray, g: np.ndarray, rank_rtol: float = RANK_RTOL
) -> KKTSolution:
    """Solve the KKT system (14) by the range-space method.

    Parameters
    ----------
    A : numpy.ndarray
        Symmetric positive definite mass matrix, (n, n).
    B_c : numpy.ndarray
        Constraint Jacobian, (m, n).
    f : numpy.ndarray
        Right-hand side of the equations of motion without the reactions, (n,).
    g : numpy.ndarray
        Right-hand side of the constraints at acceleration (or velocity) level, (m,).
    rank_rtol : float
        Relative cut-off of the singular values of ``L⁻¹ B_cᵀ`` (dependent rows).

    Returns
    -------
    KKTSolution

    Raises
    ------
    Rt70Error
        If A is not positive definite, or the constraints contradict each other
        (g has a part outside the range of B_c's independent rows).
    """
    import scipy.linalg  # here, not at import: rt70's start-up does not pay for it

    B_c = np.atleast_2d(np.asarray(B_c, dtype=float))
    m = B_c.shape[0]
    L = _cholesky(A)
    x0 = scipy.linalg.cho_solve((L, True), f)
    if m == 0:
        return KKTSolution(x0, np.zeros(0), 0)
    Y, V, s = _schur_basis(L, B_c, rank_rtol)
    r = g - B_c @ x0  # what the reactions must achieve: (Yᵀ Y) λ = r
    lam = V @ ((V.T @ r) / s**2)
    lam += V @ ((V.T @ (r - Y.T @ (Y @ lam))) / s**2)  # one step of iterative refinement
    residual = r - V @ (V.T @ r)
    scale = max(float(np.abs(r).max(initial=0.0)), float(np.abs(B_c @ x0).max(initial=0.0)), 1.0)
    if float(np.abs(residual).max(initial=0.0)) > 1e-8 * scale:
        raise Rt70Error(
            f"the {m} constraints contradict each other: {m - s.size} dependent "
            "row(s) demand different accelerations"
        )
    x = x0 + scipy.linalg.cho_solve((L, True), B_c.T @ lam)
    return KKTSolution(x, lam, int(s.size))


def schur_pinv(A: np.ndarray, B_c: np.ndarray, rank_rtol: float = RANK_RTOL) -> np.ndarray:
    """``W⁺``, the pseudo-inverse of the Schur complement ``W = B_c A⁻¹ B_cᵀ``.

    With the rank decision of :func:`solve_kkt` (the singular values of
    ``Y = L⁻¹ B_cᵀ`` against ``rank_rtol``; W's own are their squares, so a cut-off of
    W's singular values at ``rank_rtol`` would drop rows the solve keeps): the matrix
    that maps what the reactions must achieve to the multipliers, ``λ = W⁺ r``.

    Parameters
    ----------
    A : numpy.ndarray
        Symmetric positive definite mass matrix, (n, n).
    B_c : numpy.ndarray
        Constraint Jacobian, (m, n).
    rank_rtol : float
        Relative cut-off of the singular values of ``L⁻¹ B_cᵀ`` (dependent rows).

    Returns
    -------
    numpy.ndarray
        ``W⁺ = V diag(σ⁻²) Vᵀ`` over the kept singular values σ of Y, (m, m).

    Raises
    ------
    Rt70Error
        If A is not positive definite.
    """
    B_c = np.atleast_2d(np.asarray(B_c, dtype=float))
    if B_c.shape[0] == 0:
        return np.zeros((0, 0))
    _, V, s = _schur_basis(_cholesky(A), B_c, rank_rtol)
    return (V / s**2) @ V.T


def _cholesky(A: np.ndarray) -> np.ndarray:
    """The lower Cholesky factor L of A, or an Rt70Error if A is not positive definite."""
    import scipy.linalg

    try:
        return scipy.linalg.cholesky(A, lower=True)
    except np.linalg.LinAlgError:
        raise Rt70Error("mass matrix A is not positive definite at this configuration") from None


def _schur_basis(
    L: np.ndarray, B_c: np.ndarray, rank_rtol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Y, V, σ)``: ``Y = L⁻¹ B_cᵀ``, its right singular vectors and values above the cut-off.

    ``W = Yᵀ Y = V diag(σ²) Vᵀ`` on the independent rows; σ ≤ ``rank_rtol`` σ_max count
    as zero (dependent rows).
    """
    import scipy.linalg

    Y = scipy.linalg.solve_triangular(L, B_c.T, lower=True)  # L⁻¹ B_cᵀ, (n, m)
    _, sigma, Vt = np.linalg.svd(Y, full_matrices=False)
    keep = sigma > rank_rtol * sigma[0] if sigma[0] > 0 else np.zeros_like(sigma, dtype=bool)
    return Y, Vt[keep].T, sigma[keep]
