"""Modal analysis of ``M q̈ + D q̇ + K q = B u``: the eigenproblem and its modes.

The linear models of chapter 2 (``m q̈ + ΓᵀDΓ q̇ + ΓᵀCΓ q = Q``, (2.9)), of chapter 3
(the reduced A*, D*, C*) and the linearisation of a nonlinear scene all end in the same
form ``M q̈ + D q̇ + K q = B_in u`` with M symmetric positive definite and K, D
symmetric. This module solves its eigenproblem (formalism §2):

- eigenfrequencies and mode shapes from the generalised symmetric eigenproblem
  ``K v = ω² M v`` (:func:`modes`; never ``inv(M) @ K``), checked by :func:`residuals`;
- the principal coordinates (2.17)–(2.21), ``z̈ + VᵀDV ż + Ω² z = Vᵀ Q``
  (:func:`principal_coordinates`).

Proportional damping (2.16) ``D = δ C`` with ``δ = 0.1/Ω1`` gives ``ξ_1 = 0.05`` — the
book's "+20 dB at the first resonance" — and ``ξ_i = 0.05 Ω_i/Ω1`` (§2.3);
:func:`stiffness_proportional_damping` builds it.

The state space, frequency and step responses built on these modes are in
:mod:`rt70.linear.responses`; their figures in :mod:`rt70.plotting.modal`. Only numpy
and scipy are needed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.linear.checks import _mass, _matrix, _square, _symmetric
from rt70.linear.sparsity import sparse_if_sparse

#: Default rigid-mode tolerance, relative to the largest ``|ω²|``.
RIGID_RTOL = 1e-10
#: Two eigenvalues closer than this (relative to the largest ``|ω²|``) form a cluster
#: (repeated eigenvalues carry a rounding spread of about ``n ε max|ω²|``).
CLUSTER_RTOL = 1e-10
#: ``VᵀDV`` counts as diagonal when its off-diagonal part is below this (relative).
PROPORTIONAL_RTOL = 1e-8


# --------------------------------------------------------------------------------- modes


@dataclass(frozen=True)
class Modes:
    """Eigenfrequencies and mode shapes of ``K v = ω² M v`` (formalism §2).

    All n modes of n coordinates from :func:`modes`; the k nearest zero from
    :func:`rt70.linear.lowest_modes.lowest_modes` (the arrays below then have k entries
    where they say n, and ``shapes`` is n × k).

    Attributes
    ----------
    omega2 : ndarray, shape (n,)
        Eigenvalues ω² (rad²/s²), ascending, exactly as :func:`scipy.linalg.eigh`
        returns them (a rigid mode may carry a rounding residue of either sign).
    omega : ndarray, shape (n,)
        Circular frequencies ω (rad/s): ``sqrt(ω²)``; rigid modes are exactly 0 (a tiny
        negative ω² from rounding is clipped), and a clearly negative ω² (see
        ``negative``) gives NaN — it is a divergence rate ``sqrt(−ω²)``, not a frequency.
    freq_hz : ndarray, shape (n,)
        ``ω / 2π`` (Hz), with the same 0 and NaN conventions.
    shapes : ndarray, shape (n, n)
        Mode shapes V as columns, mass-normalised: ``VᵀMV = 1``, ``VᵀKV = diag(ω²)``.
        Each column's sign is fixed so that its largest-magnitude entry is positive.
    rigid : ndarray of bool, shape (n,)
        Rigid-body modes: ``|ω²| ≤ rigid_tol``.
    negative : ndarray of bool, shape (n,)
        Unstable modes: ``ω² < −rigid_tol`` (negative stiffness, e.g. an overturning
        gravity load). They are flagged here, never clipped; :func:`modes` does not raise.
    rigid_tol : float
        The tolerance used for ``rigid`` and ``negative``.
    modal_damping : ndarray, shape (n, n), or None
        ``VᵀDV`` when D was given (diagonal for proportional damping).
    zeta : ndarray, shape (n,), or None
        Modal damping ratios ``ξ_i = (VᵀDV)_ii / (2 ω_i)`` of elastic modes; NaN for
        rigid and unstable modes.
    damping_offdiag : float or None
        ``max|offdiag(VᵀDV)| / max|VᵀDV|`` (0 for D = 0).
    proportional : bool or None
        True when V diagonalises D to ``PROPORTIONAL_RTOL`` (the modes are decoupled).
    """

    omega2: np.ndarray
    omega: np.ndarray
    freq_hz: np.ndarray
    shapes: np.ndarray
    rigid: np.ndarray
    negative: np.ndarray
    rigid_tol: float
    modal_damping: np.ndarray | None = None
    zeta: np.ndarray | None = None
    damping_offdiag: float | None = None
    proportional: bool | None = None

    @property
    def n(self) -> int:
        """Number of modes (the number of coordinates when every mode was found)."""
        return self.omega2.size

    @property
    def elastic(self) -> np.ndarray:
        """Boolean mask of elastic (neither rigid nor unstable) modes."""
        return ~(self.rigid | self.negative)

    @property
    def stable(self) -> bool:
        """True when no mode has a clearly negative ω²."""
        return not bool(np.any(self.negative))


def _clusters(omega2: np.ndarray, tol: float) -> list[np.ndarray]:
    """Index groups of consecutive (sorted) eigenvalues closer than ``tol`` to a neighbour."""
    groups, start = [], 0
    for i in range(1, omega2.size + 1):
        if i == omega2.size or omega2[i] - omega2[i - 1] > tol:
            if i - start > 1:
                groups.append(np.arange(start, i))
            start = i
    return groups


def modes(
    M: np.ndarray,
    K: np.ndarray,
    D: np.ndarray | None = None,
    rigid_tol: float | None = None,
) -> Modes:
    """Solve ``K v = ω² M v`` by :func:`scipy.linalg.eigh` (Cholesky of M, no inverse).

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Mass (inertia) matrix: symmetric positive definite (checked by Cholesky).
    K : ndarray, shape (n, n)
        Stiffness matrix ``ΓᵀCΓ`` (2.9): symmetric; normally positive semidefinite, but a
        negative-stiffness mode is accepted and flagged in :attr:`Modes.negative`.
    D : ndarray, shape (n, n), optional
        Symmetric damping matrix ``ΓᵀDΓ``; gives ``VᵀDV``, ξ and the proportionality
        flag.
    rigid_tol : float, optional
        Modes with ``|ω²| ≤ rigid_tol`` are rigid. Default ``RIGID_RTOL · max|ω²|``
        (1e-10 relative: the rounding of a rigid mode's ω² is about
        ``ε · max|ω²|``, and a genuine elastic mode five decades below the highest
        frequency would still be elastic).

    Returns
    -------
    Modes
        Eigenvalues, frequencies, M-orthonormal mode shapes and the masks.

    Raises
    ------
    Rt70Error
        On NaN/inf, non-square or mismatched shapes, asymmetric M, K or D, or M not
        positive definite.

    Notes
    -----
    Eigenvalues that coincide (a cluster, closer than ``CLUSTER_RTOL · max|ω²|``; all
    rigid modes form one cluster; symmetric structures give others) have no unique mode
    shapes: eigh returns some M-orthonormal basis of their subspace. When D is given,
    that basis is rotated (orthogonally, so ``VᵀMV = 1`` is kept) within each cluster to
    diagonalise the cluster's block of ``VᵀDV``, so that a damping that commutes with
    the cluster is reported as proportional and ξ is well defined. The rotation mixes
    eigenvalues that differ by at most the cluster tolerance, so ``VᵀKV`` stays
    diagonal to that level. Damping that couples distinct, merely close modes is
    reported as non-proportional, as it physically is.
    """
    omega2, V, D = _eigh(M, K, D)
    return finished_modes(omega2, V, D, float(np.max(np.abs(omega2))), rigid_tol)


def finished_modes(
    omega2: np.ndarray,
    V: np.ndarray,
    D: np.ndarray | None,
    scale: float,
    rigid_tol: float | None = None,
) -> Modes:
    """:class:`Modes` from eigenpairs: classified, clusters rotated, signs fixed, ξ.

    The steps of :func:`modes` after the eigensolver (its Notes), shared with the modes
    found in part (:mod:`rt70.linear.lowest_modes`).

    Parameters
    ----------
    omega2 : ndarray, shape (k,)
        Eigenvalues, ascending.
    V : ndarray, shape (n, k)
        Their M-orthonormal eigenvectors (rotated in place within clusters).
    D : ndarray, shape (n, n), or None
        Symmetric damping matrix (checked).
    scale : float
        The largest ``|ω²|`` of the whole spectrum: the rigid and cluster tolerances are
        relative to it.
    rigid_tol : float, optional
        As :func:`modes` takes it (default ``RIGID_RTOL · scale``).
    """
    rigid, negative, rigid_tol = _classify(omega2, rigid_tol, scale)
    Z = None
    if D is not None:
        Z = _diagonalise_clusters(V, D, np.where(rigid, 0.0, omega2), CLUSTER_RTOL * scale)
    V, Z = _fix_signs(V, Z)
    omega, freq_hz = _frequencies(omega2, rigid, negative)
    zeta = offdiag = proportional = None
    if Z is not None:
        zeta, offdiag, proportional = _modal_damping(Z, omega, ~(rigid | negative))
    return Modes(
        omega2=omega2,
        omega=omega,
        freq_hz=freq_hz,
        shapes=V,
        rigid=rigid,
        negative=negative,
        rigid_tol=rigid_tol,
        modal_damping=Z,
        zeta=zeta,
        damping_offdiag=offdiag,
        proportional=proportional,
    )


def unheld_counts(M: np.ndarray, K: np.ndarray) -> tuple[int, int]:
    """``(unstable, rigid)``: how many modes of ``K v = ω² M v`` are each, eigenvalues only.

    The same test as :func:`modes` (:func:`_classify`), without the mode shapes: 1.2 s
    against 1.8 s for the eigenproblem of 2004 coordinates (measured once, in-process).

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass (symmetric positive definite) and stiffness matrices.
    """
    M, _ = _mass(M)
    omega2 = scipy.linalg.eigh(_symmetric("K", K, M.shape[0]), M, eigvals_only=True)
    rigid, negative, _ = _classify(omega2, None, float(np.max(np.abs(omega2))))
    return int(negative.sum()), int(rigid.sum())


def _classify(
    omega2: np.ndarray, rigid_tol: float | None, scale: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """``(rigid, negative, rigid_tol)``: ``|ω²| ≤ rigid_tol`` and ``ω² < −rigid_tol``.

    ``rigid_tol`` as :func:`modes` takes it (default ``RIGID_RTOL · scale``, ``scale`` the
    largest ``|ω²|`` of the whole spectrum).
    """
    tol = _rigid_tolerance(rigid_tol, scale)
    return np.abs(omega2) <= tol, omega2 < -tol, tol


def _eigh(
    M: np.ndarray, K: np.ndarray, D: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``(ω², V, D)``: M, K (and D) checked, then ``K v = ω² M v`` by eigh."""
    M, _ = _mass(M)
    n = M.shape[0]
    K = _symmetric("K", K, n)
    if D is not None:
        D = _symmetric("D", D, n)
    try:
        omega2, V = scipy.linalg.eigh(K, M)
    except np.linalg.LinAlgError as exc:  # pragma: no cover - M was checked by Cholesky
        raise Rt70Error(f"generalised eigenproblem failed: {exc}") from None
    return omega2, V, D


def _rigid_tolerance(rigid_tol: float | None, scale: float) -> float:
    """The rigid-mode tolerance: ``RIGID_RTOL · scale`` by default, else checked."""
    if rigid_tol is None:
        rigid_tol = RIGID_RTOL * scale
    elif not (np.isfinite(rigid_tol) and rigid_tol >= 0):
        raise Rt70Error(f"rigid_tol must be a finite non-negative number, got {rigid_tol}")
    return float(rigid_tol)


def _diagonalise_clusters(
    V: np.ndarray, D: np.ndarray, omega2: np.ndarray, tol: float
) -> np.ndarray:
    """Rotate V (in place) within each eigenvalue cluster to diagonalise ``VᵀDV``; return it.

    ``omega2`` has the rigid modes' eigenvalues set to 0 (they form one cluster); the
    rotations are orthogonal, so ``VᵀMV = 1`` is kept (:func:`modes`, Notes).
    """
    Z = V.T @ (sparse_if_sparse(D) @ V)
    for idx in _clusters(omega2, tol):
        _, R = np.linalg.eigh(Z[np.ix_(idx, idx)])
        V[:, idx] = V[:, idx] @ R
        Z[idx, :] = R.T @ Z[idx, :]  # Z ← Bᵀ Z B, B the rotation: rows, then columns
        Z[:, idx] = Z[:, idx] @ R
    return 0.5 * (Z + Z.T)


def _fix_signs(V: np.ndarray, Z: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """Deterministic sign: each column's largest-magnitude entry positive; Z follows."""
    n = V.shape[1]
    big = np.argmax(np.abs(V), axis=0)
    sign = np.where(V[big, np.arange(n)] < 0, -1.0, 1.0)
    V = V * sign
    if Z is not None:
        Z = sign[:, None] * Z * sign[None, :]
        Z = 0.5 * (Z + Z.T)
    return V, Z


def _frequencies(
    omega2: np.ndarray, rigid: np.ndarray, negative: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(ω, ω/2π)``: exactly 0 for rigid modes, NaN for unstable ones (:class:`Modes`)."""
    omega = np.sqrt(np.where(rigid, 0.0, np.abs(omega2)))
    omega[negative] = np.nan
    return omega, omega / (2.0 * np.pi)


def _modal_damping(
    Z: np.ndarray, omega: np.ndarray, elastic: np.ndarray
) -> tuple[np.ndarray, float, bool]:
    """``(ξ, off-diagonal fraction, proportional)`` of the modal damping ``Z = VᵀDV``.

    ξ_i = Z_ii / (2 ω_i) for the elastic modes, NaN for the others.
    """
    zeta = np.full(omega.size, np.nan)
    zeta[elastic] = np.diag(Z)[elastic] / (2.0 * omega[elastic])
    zmax = float(np.max(np.abs(Z)))
    off = Z - np.diag(np.diag(Z))
    offdiag = float(np.max(np.abs(off)) / zmax) if zmax > 0 else 0.0
    return zeta, offdiag, offdiag <= PROPORTIONAL_RTOL


def residuals(M: np.ndarray, K: np.ndarray, modes: Modes) -> dict[str, float]:
    """Check an eigen-solution against M and K, independently of how it was computed.

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        The matrices the modes are claimed to belong to.
    modes : Modes
        The solution to check.

    Returns
    -------
    dict
        ``"eigen"``: ``max_i ‖K v_i − ω_i² M v_i‖ / (‖K‖ ‖v_i‖)`` (2-norms);
        ``"eigen_backward"``: the same over ``(‖K‖ + |ω_i²| ‖M‖) ‖v_i‖``, the normwise
        backward error, which stays at rounding level even when M is ill-conditioned;
        ``"orthonormality"``: ``max|VᵀMV − 1|``;
        ``"stiffness_diagonal"``: ``max|VᵀKV − diag(ω²)| / max|ω²|``.
    """
    M = _square("M", M)
    n = M.shape[0]
    K = _square("K", K, n)
    V = _matrix("modes.shapes", modes.shapes, (n, modes.n))
    w2 = modes.omega2
    R = K @ V - (M @ V) * w2
    nK, nM = np.linalg.norm(K, 2), np.linalg.norm(M, 2)
    nv = np.linalg.norm(V, axis=0)
    nR = np.linalg.norm(R, axis=0)
    scale = max(float(np.max(np.abs(w2))), np.finfo(float).tiny)
    return {
        "eigen": float(np.max(nR / (max(nK, np.finfo(float).tiny) * nv))),
        "eigen_backward": float(np.max(nR / ((nK + np.abs(w2) * nM) * nv))),
        "orthonormality": float(np.max(np.abs(V.T @ M @ V - np.eye(modes.n)))),
        "stiffness_diagonal": float(np.max(np.abs(V.T @ K @ V - np.diag(w2))) / scale),
    }


def stiffness_proportional_damping(
    K: np.ndarray, modes: Modes, zeta1: float = 0.05
) -> tuple[np.ndarray, float]:
    """Proportional damping (2.16) ``D = δ K`` with ``ξ = zeta1`` on the first elastic mode.

    For the book's ``D = δ C`` on the links, ``ΓᵀDΓ = δ ΓᵀCΓ = δ K``. Mode i then has
    ``VᵀDV = δ Ω²`` and ``ξ_i = δ Ω_i / 2``; ``δ = 2 ξ_1/Ω1`` — with the book's
    ``ξ_1 = 0.05`` (+20 dB at the first resonance) ``δ = 0.1/Ω1`` and
    ``ξ_i = 0.05 Ω_i/Ω1``.

    Parameters
    ----------
    K : ndarray, shape (n, n)
        Stiffness matrix.
    modes : Modes
        Its modes (the first elastic one gives Ω1).
    zeta1 : float, optional
        Damping ratio of the first elastic mode (default 0.05).

    Returns
    -------
    D : ndarray, shape (n, n)
        ``δ K``.
    delta : float
        ``δ = 2 ξ_1 / Ω1`` (s).
    """
    K = _symmetric("K", K, modes.n)
    el = np.flatnonzero(modes.elastic)
    if el.size == 0:
        raise Rt70Error("no elastic mode: proportional damping has no first resonance")
    delta = 2.0 * float(zeta1) / float(modes.omega[el[0]])
    return delta * K, delta


def principal_coordinates(
    M: np.ndarray, K: np.ndarray, D: np.ndarray | None, modes: Modes
) -> tuple[np.ndarray, np.ndarray]:
    """Principal coordinates (2.17)–(2.21): ``z̈ + VᵀDV ż + Ω² z = Vᵀ Q``.

    With ``q = V z`` (the book's ``α = V z2``, ``α̇ = V z1``), ``Mq̈ + Dq̇ + Kq = Q``
    premultiplied by Vᵀ decouples because V is mass-normalised: ``VᵀMV = 1`` and
    ``VᵀKV = Ω²``. The book writes the input map as ``V⁻¹ I⁻¹`` (with I the inertia
    matrix M); since ``VᵀMV = 1`` gives ``V⁻¹ = VᵀM``, ``V⁻¹ I⁻¹ = Vᵀ M M⁻¹ = Vᵀ``.
    For the book's ``D = δC``, ``VᵀDV = δΩ²`` and (2.21) reads
    ``ż1 = −δΩ² z1 − Ω² z2 + Vᵀ(B M + F M_wind)``, ``ż2 = z1``.

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass and stiffness matrices the modes were computed from (checked).
    D : ndarray, shape (n, n), or None
        Damping matrix (None: undamped).
    modes : Modes
        From :func:`modes`.

    Returns
    -------
    Omega2 : ndarray, shape (n, n)
        ``diag(ω²)``.
    Z_D : ndarray, shape (n, n)
        Modal damping ``VᵀDV`` (diagonal, ``diag(2 ξ_i Ω_i)``, when D is proportional).
        The input map is ``modes.shapes.T``.

    Raises
    ------
    Rt70Error
        If the modes do not diagonalise M and K (they belong to other matrices).
    """
    M = _symmetric("M", M)
    n = M.shape[0]
    K = _symmetric("K", K, n)
    if modes.n != n:
        raise Rt70Error(f"modes are for {modes.n} coordinates, M is {n} × {n}")
    res = residuals(M, K, modes)
    if res["orthonormality"] > 1e-8 or res["stiffness_diagonal"] > 1e-8:
        raise Rt70Error(
            "the modes do not diagonalise M and K "
            f"(max|VᵀMV − 1| = {res['orthonormality']:.3g}, "
            f"relative max|VᵀKV − Ω²| = {res['stiffness_diagonal']:.3g})"
        )
    V = modes.shapes
    Z = np.zeros((n, n)) if D is None else V.T @ _square("D", D, n) @ V
    return np.diag(modes.omega2), Z
