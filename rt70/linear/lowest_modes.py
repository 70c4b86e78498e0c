"""The modes nearest zero of a model too large to want every mode: shift-invert Lanczos.

:func:`rt70.linear.modal.modes` finds all n modes by a dense ``eigh``: at n = 2004 that
is 1.7 s of the eigensolver alone (two BLAS threads), and a table of 2004 modes no
engineer reads. A modal analysis of a large structure asks for its lowest modes, as a
finite-element code does (Nastran's ``EIGRL``, Abaqus's ``*FREQUENCY``): this module
finds the k eigenvalues of ``K v = ω² M v`` nearest zero by ARPACK's implicitly
restarted Lanczos (:func:`scipy.sparse.linalg.eigsh`) on a shifted inverse. With
``M = LLᵀ`` (the Cholesky factor the mass check computes anyway) the pencil is the
standard symmetric problem ``C y = ω² y``, ``C = L⁻¹KL⁻ᵀ``, ``v = L⁻ᵀy``, and

    ``(C − σ1)⁻¹ = Lᵀ (K − σM)⁻¹ L``

has the largest eigenvalues ``1/(ω² − σ)`` at the ω² nearest the shift σ. Each product is
two triangular products with L and two triangular solves with the factor of ``K − σM``:
no product with M, no M inner product (ARPACK's generalised mode 3 needs both, and on the
2004-coordinate chain took twice as long and stopped at a backward error of 3e-11 where
this form reaches 1e-15).

1. **The scale.** The rigid and cluster tolerances of :func:`~rt70.linear.modal.modes`
   are relative to the largest ``|ω²|``, which a partial spectrum does not contain: it
   is estimated by Lanczos on C (the largest-magnitude eigenvalue to 1e-3, enough for a
   tolerance).
2. **The shift** ``σ = −rigid_tol``, just below zero: a rigid mode (``ω² = 0``) keeps
   ``K − σM`` regular, and Sylvester's law of inertia turns the factorisation into a
   count: ``K − σM`` is positive definite (Cholesky succeeds) when no ``ω² < σ``;
   otherwise the negative pivots of ``K − σM = L B Lᵀ`` (Bunch–Kaufman, LAPACK
   ``sytrf``) count the ``ω² < −rigid_tol`` — every unstable mode of the model,
   including any the k found do not reach.
3. **Lanczos** on ``(C − σ1)⁻¹``, the factor reused for every product, started from a
   fixed vector (reproducible), to ARPACK's default tolerance (machine precision).
   ARPACK resolves each eigenvalue of the inverse to about ε times the largest, so a
   mode's relative accuracy is about ``ε (ω² − σ)/|σ|``: rigid modes found at σ just
   below them (``1/|σ|`` = 1e10 over the scale) would cost the others theirs (a test
   model with two rigid modes came out at a backward error of 2e-10). When the modes
   found include rigid and other modes, Lanczos runs again with σ halfway to the
   nearest non-rigid ``|ω²|`` found (1e-14 on that model). A shift far below the wanted
   modes would not do: their inverses would crowd together (1e-6 of the scale took the
   chain's Lanczos twice as long).
4. **Rayleigh–Ritz** on the k vectors found: ``eigh(VᵀKV, VᵀMV)`` rotates them into
   exact ``VᵀMV = 1``, ``VᵀKV = diag(ω²)`` (to rounding), and
   :func:`~rt70.linear.modal.finished_modes` classifies them, rotates clusters and
   computes ``VᵀDV`` (k × k) as for the full spectrum.

:func:`rt70.fe.modes.lowest_modes` does the same for a finite-element model's sparse M
and K (SuperLU in nested-dissection order). A model in the book's joint coordinates is
dense instead — the tree couples each coordinate to its ancestors' — so this module
factors by LAPACK, works in the standard form above, and returns the
:class:`~rt70.linear.modal.Modes` of :func:`~rt70.linear.modal.modes` (rigid and unstable
flags, clusters, damping) that ``rt70 modes`` prints.

The modes are exact to the eigensolver's tolerance, not those of a reduced model; the
tests hold them equal to the dense solution's lowest k.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.sparse.linalg
from scipy.linalg import blas

from rt70.errors import Rt70Error
from rt70.linear.checks import _mass, _symmetric
from rt70.linear.modal import Modes, _classify, _rigid_tolerance, finished_modes
from rt70.linear.solvers import symmetric_solver

#: Up to this many coordinates every mode is found by default, undamped and damped (dense
#: ``eigh`` and ``eig``: ``rt70 modes``, :func:`rt70.linear.damped_lowest.damped_spectrum`).
DENSE_MAX = 500

#: Above :data:`DENSE_MAX`, the default number of modes found nearest zero.
LOWEST = 20

#: Relative tolerance of the largest ``|ω²|`` estimate (it only scales tolerances).
SCALE_TOL = 1e-3


def lowest_modes(
    M: np.ndarray,
    K: np.ndarray,
    D: np.ndarray | None,
    count: int,
    rigid_tol: float | None = None,
) -> tuple[Modes, int]:
    """The ``count`` modes nearest zero, and how many modes of the model are unstable.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Symmetric positive definite mass matrix.
    K : ndarray, shape (n, n)
        Symmetric stiffness matrix.
    D : ndarray, shape (n, n), or None
        Symmetric damping matrix (gives ``VᵀDV`` and ξ of the modes found).
    count : int
        How many modes, ``1 ≤ count ≤ n − 2`` (ARPACK's limit; use
        :func:`rt70.linear.modal.modes` for more).
    rigid_tol : float, optional
        As :func:`rt70.linear.modal.modes` (default ``RIGID_RTOL`` times the estimated
        largest ``|ω²|``).

    Returns
    -------
    modes : Modes
        The ``count`` modes, ascending (module docstring).
    unstable : int
        The number of modes of the whole model with ``ω² < −rigid_tol`` (by inertia).
    """
    M, chol = _mass(M)
    n = M.shape[0]
    K = _symmetric("K", K, n)
    D = None if D is None else _symmetric("D", D, n)
    if not 1 <= count <= n - 2:
        raise Rt70Error(f"lowest modes: count must be between 1 and {n - 2}, got {count}")
    L = np.asfortranarray(chol[0])  # lower; BLAS and LAPACK read that triangle only
    scale = largest_eigenvalue(L, K)
    tol = _rigid_tolerance(rigid_tol, scale)
    if not tol > 0:
        raise Rt70Error(f"lowest modes: rigid_tol must be positive, got {rigid_tol}")
    solve, unstable = symmetric_solver(K + tol * M)
    omega2, V = _lanczos(L, K, M, solve, count)
    rigid, _, _ = _classify(omega2, tol, scale)
    if rigid.any() and not rigid.all():  # again, the shift halfway to the nearest non-rigid
        solve, _ = symmetric_solver(K + 0.5 * float(np.min(np.abs(omega2[~rigid]))) * M)
        omega2, V = _lanczos(L, K, M, solve, count)
    return finished_modes(omega2, V, D, scale, tol), unstable


def _lanczos(L: np.ndarray, K: np.ndarray, M: np.ndarray, solve, count: int) -> tuple:
    """``(ω², V)``: Lanczos on ``(C − σ1)⁻¹ = Lᵀ (K − σM)⁻¹ L`` then Rayleigh–Ritz.

    ``solve`` applies ``(K − σM)⁻¹``; ``M = LLᵀ`` (module docstring, 3 and 4).
    """
    n = L.shape[0]

    def inverse(y: np.ndarray) -> np.ndarray:
        return blas.dtrmv(L, solve(blas.dtrmv(L, np.ravel(y), lower=1)), lower=1, trans=1)

    op = scipy.sparse.linalg.LinearOperator((n, n), matvec=inverse, dtype=float)
    _, Y = scipy.sparse.linalg.eigsh(op, k=count, which="LM", v0=np.ones(n))
    V = scipy.linalg.solve_triangular(L, Y, lower=True, trans="T", check_finite=False)
    omega2, R = scipy.linalg.eigh(V.T @ K @ V, V.T @ M @ V)
    return omega2, V @ R


def largest_eigenvalue(L: np.ndarray, K: np.ndarray) -> float:
    """The largest ``|ω²|`` of ``K v = ω² M v`` to :data:`SCALE_TOL`, ``M = LLᵀ``.

    Lanczos on ``C = L⁻¹KL⁻ᵀ`` (module docstring).

    Parameters
    ----------
    L : ndarray, shape (n, n)
        The lower Cholesky factor of the mass matrix (Fortran order).
    K : ndarray, shape (n, n)
        Stiffness matrix.
    """
    n = L.shape[0]

    def product(y: np.ndarray) -> np.ndarray:
        x = scipy.linalg.solve_triangular(L, y, lower=True, trans="T", check_finite=False)
        return scipy.linalg.solve_triangular(L, K @ x, lower=True, check_finite=False)

    op = scipy.sparse.linalg.LinearOperator((n, n), matvec=product, dtype=float)
    top = scipy.sparse.linalg.eigsh(op, k=1, which="LM", tol=SCALE_TOL,
                                    return_eigenvectors=False, v0=np.ones(n))  # fmt: skip
    return float(abs(top[0])) or 1.0
