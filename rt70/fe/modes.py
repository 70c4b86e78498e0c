"""The lowest modes of a large sparse model: shift-invert Lanczos on ``K v = ω² M v``.

A finite-element model of 10⁴–10⁶ degrees of freedom never becomes dense: its lowest
modes come from :func:`scipy.sparse.linalg.eigsh` in shift-invert mode, which factors
``K − σ M`` once and runs Lanczos on ``(K − σ M)⁻¹ M`` (spec flexible-and-reflector.md
§2). The factor is SuperLU's in the nested-dissection order of :mod:`rt70.fe.ordering`,
kept as it is (the matrix is symmetric positive definite: no pivoting needed), which
halves its fill and its time on a large mesh. The shift σ is slightly negative, so that a free
structure (K singular: rigid-body modes at ω² = 0) factors too, and close enough to
zero that the lowest modes stay well separated in the transformed problem. The Lanczos
vectors are then polished by Rayleigh–Ritz (the dense eigenproblem of ``Vᵀ K V``,
``Vᵀ M V``): an eigenvalue's error is the square of its subspace's, so a shift that
leaves ``K − σ M`` ill-conditioned (a free structure) costs no accuracy. Each mode
reports its backward error ``‖K v − ω² M v‖₁ / ((‖K‖₁ + ω² ‖M‖₁) ‖v‖₁)`` — the error
that goes with the result (rounding gives about 1e-16 times a modest factor).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rt70.errors import Rt70Error
from rt70.fe.ordering import nested_dissection

#: The shift, as a fraction of the largest ``K_ii / M_ii``: below every mode of a
#: structure whose lowest ω² is above 1e-9 of that ratio, and far enough from zero that
#: ARPACK's Lanczos on a free structure still converges (measured on space frames of 72
#: and 480 DOF with six rigid modes: at 1e-12 the subspace is wrong, at 1e-9 the
#: Ritz frequencies equal the dense solver's to 1e-14).
SHIFT_RTOL = 1e-9
#: Modes with ``|ω²|`` below this fraction of the largest ``K_ii / M_ii`` are rigid.
RIGID_RTOL = 1e-10
#: ARPACK's tolerance on the Ritz values of ``(K − σ M)⁻¹ M``. The Rayleigh–Ritz polish
#: squares the subspace's error in the eigenvalues, so machine precision here buys
#: nothing: on the free 101 400-DOF space frame (30 modes) 1e-10 takes 62 solves instead
#: of 78 for the same backward errors (7.5e-14 against 7.6e-14) and ω² equal to 1.2e-11
#: (the rounding of ω² ≈ 0.1 (rad/s)² itself, not convergence).
LANCZOS_RTOL = 1e-10
#: Seed of Lanczos's starting vector (ARPACK's own is random: results would differ in
#: their last bits from run to run).
START_SEED = 20261127


@dataclass(frozen=True)
class SparseModes:
    """The lowest modes of ``K v = ω² M v`` and their accuracy.

    Attributes
    ----------
    omega2 : numpy.ndarray, shape (k,)
        ω², (rad/s)², ascending (rigid modes ≈ 0).
    shapes : numpy.ndarray, shape (N, k)
        Mode shapes, mass-normalised: ``Vᵀ M V = 1``.
    rigid : numpy.ndarray of bool, shape (k,)
        Rigid-body modes (``|ω²| ≤`` :data:`RIGID_RTOL` of the largest ``K_ii / M_ii``).
    residual : numpy.ndarray, shape (k,)
        Backward error of each mode, ``‖K v − ω² M v‖₁ / ((‖K‖₁ + |ω²| ‖M‖₁) ‖v‖₁)``.
    seconds : float
        Wall time of the factorisation and the iteration.
    """

    omega2: np.ndarray
    shapes: np.ndarray
    rigid: np.ndarray
    residual: np.ndarray
    seconds: float

    @property
    def freq_hz(self) -> np.ndarray:
        """Frequencies, Hz (0 for rigid modes)."""
        return np.where(self.rigid, 0.0, np.sqrt(np.abs(self.omega2)) / (2.0 * np.pi))


def _sym(X: np.ndarray) -> np.ndarray:
    return 0.5 * (X + X.T)


def lowest_modes(
    M: sp.sparray, K: sp.sparray, count: int, tol: float = LANCZOS_RTOL
) -> SparseModes:
    """The ``count`` lowest modes of the sparse pair (M, K).

    Parameters
    ----------
    M, K : scipy.sparse array, shape (N, N)
        Symmetric mass (positive semi-definite, positive definite where K is not) and
        stiffness (positive semi-definite) matrices.
    count : int
        How many modes, 1 ≤ count < N.
    tol : float
        ARPACK's relative tolerance of the transformed eigenvalues (0: machine precision;
        default :data:`LANCZOS_RTOL`, which the Rayleigh–Ritz polish makes enough).

    Raises
    ------
    Rt70Error
        A ``count`` out of range, matrices of different sizes, or no positive mass.
    """
    n = M.shape[0]
    if M.shape != (n, n) or K.shape != (n, n):
        raise Rt70Error(f"M is {M.shape} and K is {K.shape}: both must be N × N")
    if not 1 <= count < n:
        raise Rt70Error(f"asked for {count} modes of a model of {n} degrees of freedom")
    m_diag, k_diag = M.diagonal(), K.diagonal()
    massive = m_diag > 0.0
    if not np.any(massive):
        raise Rt70Error("the mass matrix has no positive diagonal entry")
    ratio = float(np.max(k_diag[massive] / m_diag[massive]))
    sigma = -SHIFT_RTOL * ratio
    start = time.perf_counter()
    Kc, Mc = sp.csc_array(K), sp.csc_array(M)
    shifted = sp.csc_array(Kc - sigma * Mc)
    p = nested_dissection(shifted)  # SuperLU keeps this order: symmetric, no pivoting
    back = np.empty_like(p)
    back[p] = np.arange(n)
    lu = spla.splu(
        sp.csc_array(shifted[p][:, p]),
        permc_spec="NATURAL",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    op_inv = spla.LinearOperator((n, n), matvec=lambda x: lu.solve(x[p])[back], dtype=float)
    v0 = np.random.default_rng(START_SEED).standard_normal(n)  # the same modes every run
    w, V = spla.eigsh(Kc, k=count, M=Mc, sigma=sigma, which="LM", OPinv=op_inv, tol=tol, v0=v0)
    KV, MV = Kc @ V, Mc @ V  # Rayleigh–Ritz on the subspace: its error, squared
    w, Y = scipy.linalg.eigh(_sym(V.T @ KV), _sym(V.T @ MV))
    V = V @ Y  # mass-normalised: Yᵀ (Vᵀ M V) Y = 1
    seconds = time.perf_counter() - start
    residual = backward_errors(Mc, Kc, w, V)
    return SparseModes(w, V, np.abs(w) <= RIGID_RTOL * ratio, residual, seconds)


def backward_errors(M: sp.sparray, K: sp.sparray, omega2: np.ndarray, V: np.ndarray) -> np.ndarray:
    """``‖K v − ω² M v‖₁ / ((‖K‖₁ + |ω²| ‖M‖₁) ‖v‖₁)`` of each mode (column of V), (k,).

    Parameters
    ----------
    M, K : scipy.sparse array, shape (N, N)
        Mass and stiffness.
    omega2 : numpy.ndarray, shape (k,)
        The modes' ω², (rad/s)².
    V : numpy.ndarray, shape (N, k)
        Their shapes.
    """
    norm_k = float(abs(K).sum(axis=0).max())  # ‖K‖₁ and ‖M‖₁
    norm_m = float(abs(M).sum(axis=0).max())
    r = np.abs(K @ V - (M @ V) * omega2).sum(axis=0)
    return r / ((norm_k + np.abs(omega2) * norm_m) * np.abs(V).sum(axis=0))
