"""The damped system's own eigenvalues: which motions oscillate and which creep.

The undamped modes (:mod:`rt70.linear.modal`) give ξ = (VᵀDV)_ii / 2ω_i, exact only for
proportional damping. The eigenvalues of the state matrix ``[[0, 1], [−M⁻¹K, −M⁻¹D]]``
say it without approximation: every one of them by a dense ``eig``
(:func:`damped_modes`), or those nearest zero of a large model
(:mod:`rt70.linear.damped_lowest`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.linear.checks import _mass, _square


@dataclass(frozen=True)
class DampedModes:
    """Eigenvalues of the damped system ``M q̈ + D q̇ + K q = 0`` (its state matrix).

    The undamped modes' ξ = (VᵀDV)_ii / 2ω_i is exact only for proportional damping; the
    damped system's own eigenvalues λ say without approximation which motions oscillate
    (a complex pair ``−ξω ± iω√(1−ξ²)``) and which creep (real λ: overdamped, or rigid
    at λ = 0, or unstable at λ > 0).

    Attributes
    ----------
    eigenvalues : ndarray, shape (2n,)
        λ of ``[[0, 1], [−M⁻¹K, −M⁻¹D]]``, complex, sorted by ``|λ|``.
    oscillatory : ndarray of complex
        One λ of each complex pair (positive imaginary part), by frequency.
    real : ndarray of float
        The real eigenvalues (1/s), ascending.
    """

    eigenvalues: np.ndarray
    oscillatory: np.ndarray
    real: np.ndarray

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies ``|λ|/2π`` of the oscillatory pairs, Hz.

        For a mode under proportional damping it is the undamped ω/2π; ``Im λ`` is the
        damped frequency.
        """
        return np.abs(self.oscillatory) / (2.0 * np.pi)

    @property
    def zeta(self) -> np.ndarray:
        """Damping ratios ``−Re λ / |λ|`` of the oscillatory pairs."""
        return -self.oscillatory.real / np.abs(self.oscillatory)


def damped_modes(
    M: np.ndarray, K: np.ndarray, D: np.ndarray, real_rtol: float = 1e-9
) -> DampedModes:
    """Eigenvalues of the damped system, split into oscillatory pairs and real ones.

    Parameters
    ----------
    M, K, D : ndarray, shape (n, n)
        Mass (symmetric positive definite), stiffness and damping matrices.
    real_rtol : float
        An eigenvalue with ``|Im λ| ≤ real_rtol · |λ|`` (or ``|λ|`` at rounding level)
        is real.
    """
    M, _ = _mass(M)  # symmetric positive definite, or a clear error
    n = M.shape[0]
    K = _square("K", K, n)
    D = _square("D", D, n)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -scipy.linalg.solve(M, K, assume_a="pos")
    A[n:, n:] = -scipy.linalg.solve(M, D, assume_a="pos")
    return split_damped(scipy.linalg.eigvals(A), real_rtol)


def split_damped(lam: np.ndarray, real_rtol: float = 1e-9) -> DampedModes:
    """Eigenvalues ``lam`` of a damped system sorted by ``|λ|`` and split (:func:`damped_modes`)."""
    lam = lam[np.argsort(np.abs(lam), kind="stable")]
    scale = max(float(np.max(np.abs(lam))), 1.0)
    is_real = np.abs(lam.imag) <= real_rtol * np.maximum(np.abs(lam), 1e-12 * scale)
    pairs = lam[~is_real & (lam.imag > 0)]
    return DampedModes(lam, pairs[np.argsort(np.abs(pairs))], np.sort(lam[is_real].real))
