"""Modal analysis, state space and frequency responses of ``M q̈ + D q̇ + K q = B u``.

The linear models of chapter 2 (``m q̈ + ΓᵀDΓ q̇ + ΓᵀCΓ q = Q``, (2.9)), of chapter 3
(the reduced A*, D*, C*) and the linearisation of a nonlinear scene all end in the same
form ``M q̈ + D q̇ + K q = B_in u`` with M symmetric positive definite and K, D
symmetric. This module turns it into what a control engineer uses (formalism §2):

- eigenfrequencies and mode shapes from the generalised symmetric eigenproblem
  ``K v = ω² M v`` (:func:`modes`; never ``inv(M) @ K``), checked by :func:`residuals`;
- the principal coordinates (2.17)–(2.21), ``z̈ + VᵀDV ż + Ω² z = Vᵀ Q``
  (:func:`principal_coordinates`);
- the state space ``ẋ = A x + B u``, ``y = C x + D u`` with ``x = [q; q̇]``
  (:func:`state_space`) or in modal coordinates truncated to the lowest modes
  (:func:`modal_state_space`);
- the frequency response (the book's ЛАХ/ЛФХ, i.e. Bode magnitude and phase,
  :func:`frequency_response`) and the step response (:func:`step_response`);
- plot helpers (:func:`plot_bode`, :func:`plot_step`, :func:`plot_mode_shapes`) that
  draw on a given axes or return a new :class:`matplotlib.figure.Figure` (no pyplot
  state, safe with the Agg backend; saving files is left to the caller).

Proportional damping (2.16) ``D = δ C`` with ``δ = 0.1/Ω1`` gives ``ξ_1 = 0.05`` — the
book's "+20 dB at the first resonance" — and ``ξ_i = 0.05 Ω_i/Ω1`` (§2.3);
:func:`stiffness_proportional_damping` builds it.

Only numpy and scipy are needed; matplotlib is imported by the plot helpers alone.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Relative asymmetry ``max|X − Xᵀ| / max|X|`` tolerated in M, K and D (rounding).
SYMMETRY_RTOL = 1e-9
#: Default rigid-mode tolerance, relative to the largest ``|ω²|``.
RIGID_RTOL = 1e-10
#: Two eigenvalues closer than this (relative to the largest ``|ω²|``) form a cluster
#: (repeated eigenvalues carry a rounding spread of about ``n ε max|ω²|``).
CLUSTER_RTOL = 1e-10
#: ``VᵀDV`` counts as diagonal when its off-diagonal part is below this (relative).
PROPORTIONAL_RTOL = 1e-8


# --------------------------------------------------------------------------- input checks


def _array(name: str, X: np.ndarray) -> np.ndarray:
    try:
        return np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        raise Rt70Error(f"{name} is not a numeric array") from None


def _matrix(name: str, X: np.ndarray, shape: tuple[int | None, int | None]) -> np.ndarray:
    """Return ``X`` as a finite 2-D float array of ``shape`` (None: any), or raise."""
    X = _array(name, X)
    if X.ndim != 2 or any(s is not None and s != x for s, x in zip(shape, X.shape, strict=True)):
        want = " × ".join("·" if s is None else str(s) for s in shape)
        raise Rt70Error(f"{name} must be a {want} matrix, got shape {X.shape}")
    if not np.all(np.isfinite(X)):
        raise Rt70Error(f"{name} contains NaN or infinite values")
    return X


def _square(name: str, X: np.ndarray, n: int | None = None) -> np.ndarray:
    X = _matrix(name, X, (n, n))
    if X.shape[0] != X.shape[1]:
        raise Rt70Error(f"{name} must be square, got shape {X.shape}")
    if X.shape[0] == 0:
        raise Rt70Error(f"{name} is empty")
    return X


def _symmetric(name: str, X: np.ndarray, n: int | None = None) -> np.ndarray:
    """Square, finite and symmetric up to rounding; returns the symmetric part."""
    X = _square(name, X, n)
    scale = np.max(np.abs(X))
    asym = np.max(np.abs(X - X.T))
    if asym > SYMMETRY_RTOL * scale:
        raise Rt70Error(
            f"{name} is not symmetric: max|{name} − {name}ᵀ| = {asym:.3g} "
            f"(max|{name}| = {scale:.3g})"
        )
    return 0.5 * (X + X.T)


def _cholesky(M: np.ndarray) -> tuple[np.ndarray, bool]:
    """Cholesky factor of M (:func:`scipy.linalg.cho_factor`), or raise if not PD."""
    try:
        return scipy.linalg.cho_factor(M, lower=True)
    except np.linalg.LinAlgError:
        raise Rt70Error("mass matrix M is not positive definite (Cholesky failed)") from None


def _mass(M: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, bool]]:
    M = _symmetric("M", M)
    return M, _cholesky(M)


def _columns(name: str, X: np.ndarray, n: int) -> np.ndarray:
    """An input matrix with n rows; a 1-D vector is one column."""
    X = _array(name, X)
    if X.ndim == 1:
        X = X.reshape(-1, 1)
    return _matrix(name, X, (n, None))


def _rows(name: str, X: np.ndarray, n: int) -> np.ndarray:
    """An output matrix with n columns; a 1-D vector is one row."""
    X = _array(name, X)
    if X.ndim == 1:
        X = X.reshape(1, -1)
    return _matrix(name, X, (None, n))


def _names(given: Sequence[str] | None, prefix: str, count: int, what: str) -> tuple[str, ...]:
    if given is None:
        return tuple(f"{prefix}{i + 1}" for i in range(count))
    names = tuple(str(s) for s in given)
    if len(names) != count:
        raise Rt70Error(f"{len(names)} {what} names given for {count} {what}s")
    return names


# --------------------------------------------------------------------------------- modes


@dataclass(frozen=True)
class Modes:
    """Eigenfrequencies and mode shapes of ``K v = ω² M v`` (formalism §2).

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
        """Number of modes (= number of coordinates)."""
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
    M, _ = _mass(M)
    n = M.shape[0]
    K = _symmetric("K", K, n)
    if D is not None:
        D = _symmetric("D", D, n)
    try:
        omega2, V = scipy.linalg.eigh(K, M)
    except np.linalg.LinAlgError as exc:  # pragma: no cover - M was checked by Cholesky
        raise Rt70Error(f"generalised eigenproblem failed: {exc}") from None
    scale = float(np.max(np.abs(omega2)))
    if rigid_tol is None:
        rigid_tol = RIGID_RTOL * scale
    elif not (np.isfinite(rigid_tol) and rigid_tol >= 0):
        raise Rt70Error(f"rigid_tol must be a finite non-negative number, got {rigid_tol}")
    rigid_tol = float(rigid_tol)

    rigid = np.abs(omega2) <= rigid_tol
    negative = omega2 < -rigid_tol
    Z = None
    if D is not None:
        Z = V.T @ D @ V
        for idx in _clusters(np.where(rigid, 0.0, omega2), CLUSTER_RTOL * scale):
            _, R = np.linalg.eigh(Z[np.ix_(idx, idx)])
            V[:, idx] = V[:, idx] @ R
        Z = V.T @ D @ V
    # Deterministic sign: largest-magnitude entry of each column positive.
    big = np.argmax(np.abs(V), axis=0)
    sign = np.where(V[big, np.arange(n)] < 0, -1.0, 1.0)
    V = V * sign
    if Z is not None:
        Z = sign[:, None] * Z * sign[None, :]
        Z = 0.5 * (Z + Z.T)

    omega = np.sqrt(np.where(rigid, 0.0, np.abs(omega2)))
    omega[negative] = np.nan
    freq_hz = omega / (2.0 * np.pi)

    zeta = offdiag = proportional = None
    if Z is not None:
        zeta = np.full(n, np.nan)
        el = ~(rigid | negative)
        zeta[el] = np.diag(Z)[el] / (2.0 * omega[el])
        zmax = float(np.max(np.abs(Z)))
        off = Z - np.diag(np.diag(Z))
        offdiag = float(np.max(np.abs(off)) / zmax) if zmax > 0 else 0.0
        proportional = offdiag <= PROPORTIONAL_RTOL
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
    V = _matrix("modes.shapes", modes.shapes, (n, n))
    w2 = modes.omega2
    R = K @ V - (M @ V) * w2
    nK, nM = np.linalg.norm(K, 2), np.linalg.norm(M, 2)
    nv = np.linalg.norm(V, axis=0)
    nR = np.linalg.norm(R, axis=0)
    scale = max(float(np.max(np.abs(w2))), np.finfo(float).tiny)
    return {
        "eigen": float(np.max(nR / (max(nK, np.finfo(float).tiny) * nv))),
        "eigen_backward": float(np.max(nR / ((nK + np.abs(w2) * nM) * nv))),
        "orthonormality": float(np.max(np.abs(V.T @ M @ V - np.eye(n)))),
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


# ---------------------------------------------------------------------------- state space


@dataclass(frozen=True)
class SecondOrder:
    """The second-order model ``M q̈ + D q̇ + K q = B_in u``, ``y = C_out q + C_vel q̇ + D_ff u``.

    Kept by :class:`StateSpace` so that :func:`frequency_response` can solve
    ``(K − ω²M + jωD) X = B_in`` directly.
    """

    M: np.ndarray
    K: np.ndarray
    D: np.ndarray
    B_in: np.ndarray
    C_out: np.ndarray
    C_vel: np.ndarray
    D_ff: np.ndarray


@dataclass(frozen=True)
class StateSpace:
    """``ẋ = A x + B u``, ``y = C x + D u``, with names of states, inputs and outputs.

    Attributes
    ----------
    A, B, C, D : ndarray
        System matrices (D is the feedthrough, not the damping).
    state_names, input_names, output_names : tuple of str
        Labels.
    second_order : SecondOrder or None
        The second-order model it was built from, if any.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    second_order: SecondOrder | None = field(default=None, repr=False)

    @property
    def n_states(self) -> int:
        """Number of states."""
        return self.A.shape[0]

    @property
    def n_inputs(self) -> int:
        """Number of inputs."""
        return self.B.shape[1]

    @property
    def n_outputs(self) -> int:
        """Number of outputs."""
        return self.C.shape[0]


def _assemble(
    M: np.ndarray,
    chol: tuple[np.ndarray, bool],
    K: np.ndarray,
    D: np.ndarray,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray,
    D_ff: np.ndarray,
    coord_names: tuple[str, ...],
    input_names: tuple[str, ...],
    output_names: tuple[str, ...],
    rate_suffix: str,
) -> StateSpace:
    n, m = B_in.shape
    MinvK = scipy.linalg.cho_solve(chol, K)
    MinvD = scipy.linalg.cho_solve(chol, D)
    MinvB = scipy.linalg.cho_solve(chol, B_in)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-MinvK, -MinvD]])
    B = np.vstack([np.zeros((n, m)), MinvB])
    C = np.hstack([C_out, C_vel])
    states = coord_names + tuple(f"{s}{rate_suffix}" for s in coord_names)
    return StateSpace(
        A=A,
        B=B,
        C=C,
        D=D_ff,
        state_names=states,
        input_names=input_names,
        output_names=output_names,
        second_order=SecondOrder(M, K, D, B_in, C_out, C_vel, D_ff),
    )


def _io(
    n: int,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None,
    D_ff: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    B_in = _columns("B_in", B_in, n)
    C_out = _rows("C_out", C_out, n)
    p, m = C_out.shape[0], B_in.shape[1]
    C_vel = np.zeros((p, n)) if C_vel is None else _rows("C_vel", C_vel, n)
    if C_vel.shape[0] != p:
        raise Rt70Error(f"C_vel has {C_vel.shape[0]} rows, C_out has {p}")
    D_ff = np.zeros((p, m)) if D_ff is None else _matrix("D_ff", np.atleast_2d(D_ff), (p, m))
    return B_in, C_out, C_vel, D_ff


def state_space(
    M: np.ndarray,
    K: np.ndarray,
    D: np.ndarray | None,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None = None,
    D_ff: np.ndarray | None = None,
    *,
    coord_names: Sequence[str] | None = None,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
) -> StateSpace:
    """State space of ``M q̈ + D q̇ + K q = B_in u``, ``y = C_out q + C_vel q̇ + D_ff u``.

    With ``x = [q; q̇]``::

        A = [[0, 1], [−M⁻¹K, −M⁻¹D]],  B = [[0], [M⁻¹B_in]],
        C = [C_out, C_vel],             D = D_ff,

    M⁻¹ applied by a Cholesky solve (:func:`scipy.linalg.cho_solve`), never ``inv(M)``.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Symmetric positive definite mass matrix.
    K : ndarray, shape (n, n)
        Stiffness matrix (any finite square matrix).
    D : ndarray, shape (n, n), or None
        Damping matrix (None: undamped).
    B_in : ndarray, shape (n, m) or (n,)
        Input matrix (generalised forces per unit input); 1-D means one input.
    C_out : ndarray, shape (p, n) or (n,)
        Position output matrix; 1-D means one output.
    C_vel : ndarray, shape (p, n), optional
        Velocity output matrix (default 0).
    D_ff : ndarray, shape (p, m), optional
        Feedthrough (default 0).
    coord_names, input_names, output_names : sequence of str, optional
        Labels (default ``q1…``, ``u1…``, ``y1…``); states are ``q…`` and ``q…_dot``.

    Returns
    -------
    StateSpace
        Also remembers the second-order matrices for :func:`frequency_response`.
    """
    M, chol = _mass(M)
    n = M.shape[0]
    K = _square("K", K, n)
    D = np.zeros((n, n)) if D is None else _square("D", D, n)
    B_in, C_out, C_vel, D_ff = _io(n, B_in, C_out, C_vel, D_ff)
    return _assemble(
        M,
        chol,
        K,
        D,
        B_in,
        C_out,
        C_vel,
        D_ff,
        _names(coord_names, "q", n, "coordinate"),
        _names(input_names, "u", B_in.shape[1], "input"),
        _names(output_names, "y", C_out.shape[0], "output"),
        "_dot",
    )


def modal_state_space(
    modes: Modes,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None = None,
    D_ff: np.ndarray | None = None,
    n_modes: int | None = None,
    *,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
) -> StateSpace:
    """State space in principal coordinates (2.21), truncated to the lowest modes.

    With ``q ≈ V_r z`` (V_r the first ``n_modes`` columns of V) and ``x = [z; ż]``::

        A = [[0, 1], [−Ω_r², −Z_r]],  B = [[0], [V_rᵀ B_in]],
        C = [C_out V_r, C_vel V_r],    D = D_ff,

    with ``Z_r`` the leading block of ``VᵀDV`` (``modes.modal_damping``; 0 if the modes
    were computed without D). Truncation drops the higher modes and, for
    non-proportional damping, their coupling to the kept ones; the static contribution
    of the dropped modes is not added back.

    Parameters
    ----------
    modes : Modes
        From :func:`modes` (with D for a damped model).
    B_in : ndarray, shape (n, m) or (n,)
        Input matrix in the original coordinates.
    C_out : ndarray, shape (p, n) or (n,)
        Position output matrix in the original coordinates.
    C_vel : ndarray, shape (p, n), optional
        Velocity output matrix (default 0).
    D_ff : ndarray, shape (p, m), optional
        Feedthrough (default 0).
    n_modes : int, optional
        Number of lowest modes kept (default all; rigid modes count).
    input_names, output_names : sequence of str, optional
        Labels; states are ``z1…`` and ``z1_dot…``.

    Returns
    -------
    StateSpace
        Its ``second_order`` is the modal model ``(1, Ω_r², Z_r, V_rᵀB_in, C_out V_r, …)``.
    """
    n = modes.n
    r = n if n_modes is None else int(n_modes)
    if not 1 <= r <= n:
        raise Rt70Error(f"n_modes must be between 1 and {n}, got {n_modes}")
    B_in, C_out, C_vel, D_ff = _io(n, B_in, C_out, C_vel, D_ff)
    Vr = modes.shapes[:, :r]
    Z = np.zeros((r, r)) if modes.modal_damping is None else modes.modal_damping[:r, :r]
    eye = np.eye(r)
    return _assemble(
        eye,
        (eye, True),
        np.diag(modes.omega2[:r]),
        Z.copy(),
        Vr.T @ B_in,
        C_out @ Vr,
        C_vel @ Vr,
        D_ff,
        _names(None, "z", r, "mode"),
        _names(input_names, "u", B_in.shape[1], "input"),
        _names(output_names, "y", C_out.shape[0], "output"),
        "_dot",
    )


# ----------------------------------------------------------------------------- responses


@dataclass(frozen=True)
class FrequencyResponse:
    """Complex frequency response ``H(jω)`` of every output/input pair.

    Attributes
    ----------
    freq_hz : ndarray, shape (nf,)
        Frequencies (Hz).
    H : ndarray of complex, shape (nf, p, m)
        ``H[k, i, j]``: output i per unit input j at ``freq_hz[k]``.
    input_names, output_names : tuple of str
        Labels.
    method : str
        ``"second_order"`` or ``"state_space"``.
    """

    freq_hz: np.ndarray
    H: np.ndarray
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    method: str

    @property
    def magnitude_db(self) -> np.ndarray:
        """``20 log10 |H|`` (dB) — the ЛАХ (log magnitude)."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(np.abs(self.H))

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase of H in degrees, unwrapped along frequency — the ЛФХ."""
        return np.degrees(np.unwrap(np.angle(self.H), axis=0))


def _solve(A: np.ndarray, B: np.ndarray, f: float) -> np.ndarray:
    try:
        return scipy.linalg.solve(A, B)
    except np.linalg.LinAlgError:
        raise Rt70Error(
            f"frequency response undefined at {f:g} Hz: the system has a pole there "
            "(e.g. a rigid-body mode at 0 Hz)"
        ) from None


def frequency_response(
    ss: StateSpace, freq_hz: np.ndarray, method: str = "auto"
) -> FrequencyResponse:
    """Frequency response ``H(jω)``, ω = 2π f, of every output/input pair.

    Parameters
    ----------
    ss : StateSpace
        The system.
    freq_hz : array_like, shape (nf,)
        Frequencies (Hz).
    method : {"auto", "second_order", "state_space"}
        ``"second_order"`` solves ``(K − ω²M + jωD) X = B_in`` and forms
        ``H = (C_out + jω C_vel) X + D_ff`` — n × n instead of 2n × 2n, no M⁻¹, and more
        accurate near lightly damped resonances; it needs ``ss.second_order``.
        ``"state_space"`` forms ``H = C (jω1 − A)⁻¹ B + D``. Both use
        :func:`scipy.linalg.solve` per frequency. ``"auto"`` takes the second-order
        path when available.

    Returns
    -------
    FrequencyResponse
        With ``magnitude_db`` and ``phase_deg`` (Bode, the book's ЛАХ/ЛФХ).

    Raises
    ------
    Rt70Error
        On non-finite frequencies, an unknown method, or a pole exactly at one of the
        frequencies (a free structure at 0 Hz). Near such a pole scipy may warn that
        the system is ill-conditioned; evaluate rigid-body systems at f > 0.
    """
    f = np.asarray(freq_hz, dtype=float)
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)):
        raise Rt70Error("freq_hz must be a non-empty 1-D array of finite frequencies")
    if method == "auto":
        method = "second_order" if ss.second_order is not None else "state_space"
    p, m = ss.n_outputs, ss.n_inputs
    H = np.empty((f.size, p, m), dtype=complex)
    if method == "second_order":
        so = ss.second_order
        if so is None:
            raise Rt70Error("this state space was not built from M, K, D")
        for k, fk in enumerate(f):
            w = 2.0 * np.pi * fk
            X = _solve(so.K - w * w * so.M + 1j * w * so.D, so.B_in, fk)
            H[k] = (so.C_out + 1j * w * so.C_vel) @ X + so.D_ff
    elif method == "state_space":
        eye = np.eye(ss.n_states)
        for k, fk in enumerate(f):
            w = 2.0 * np.pi * fk
            H[k] = ss.C @ _solve(1j * w * eye - ss.A, ss.B, fk) + ss.D
    else:
        raise Rt70Error(f"unknown method {method!r} (auto, second_order, state_space)")
    return FrequencyResponse(f, H, ss.input_names, ss.output_names, method)


def step_response(ss: StateSpace, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Response to a unit step on each input, from rest, by the matrix exponential.

    Over a step h the state obeys ``x(t+h) = Φ x(t) + Γ u`` with ``Φ = e^{Ah}`` and
    ``Γ = ∫₀ʰ e^{Aτ} dτ B``, both read off one :func:`scipy.linalg.expm` of the
    augmented matrix ``[[A, B], [0, 0]] h``. For a constant input this is exact (no
    discretisation error, rigid modes and A singular included); only rounding
    accumulates over the steps. Uniformly spaced ``t`` (to 1e-9 relative) needs one
    exponential, otherwise one per interval.

    Parameters
    ----------
    ss : StateSpace
        The system (x(t[0]) = 0).
    t : array_like, shape (nt,)
        Increasing times (s); the step is applied at ``t[0]``.

    Returns
    -------
    t : ndarray, shape (nt,)
        The times.
    y : ndarray, shape (nt, p, m)
        ``y[k, i, j]``: output i at ``t[k]`` for a unit step on input j.
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise Rt70Error("t must be a non-empty 1-D array of finite times")
    h = np.diff(t)
    if np.any(h <= 0):
        raise Rt70Error("t must be strictly increasing")
    ns, m = ss.n_states, ss.n_inputs
    aug = np.zeros((ns + m, ns + m))
    aug[:ns, :ns], aug[:ns, ns:] = ss.A, ss.B

    def discrete(step: float) -> tuple[np.ndarray, np.ndarray]:
        E = scipy.linalg.expm(aug * step)
        return E[:ns, :ns], E[:ns, ns:]

    X = np.zeros((t.size, ns, m))
    if h.size:
        uniform = np.ptp(h) <= 1e-9 * np.max(h)
        Phi, Gam = discrete(float((t[-1] - t[0]) / h.size)) if uniform else (None, None)
        for k, hk in enumerate(h):
            if not uniform:
                Phi, Gam = discrete(float(hk))
            X[k + 1] = Phi @ X[k] + Gam
    y = np.einsum("pi,kij->kpj", ss.C, X) + ss.D
    return t, y


# ---------------------------------------------------------------------------------- plots


def _new_figure(nrows: int = 1, sharex: bool = False) -> tuple[Figure, list[Axes]]:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.0, 2.6 * nrows + 0.8), layout="constrained")
    axes = fig.subplots(nrows, 1, sharex=sharex, squeeze=False)[:, 0]
    return fig, list(axes)


def plot_bode(
    fr: FrequencyResponse,
    output_index: int = 0,
    input_index: int = 0,
    axes: tuple[Axes, Axes] | None = None,
    label: str | None = None,
    **kwargs: object,
) -> Figure:
    """Bode diagram (ЛАХ/ЛФХ) of one output/input pair: dB and degrees vs log frequency.

    Parameters
    ----------
    fr : FrequencyResponse
        From :func:`frequency_response`.
    output_index, input_index : int, optional
        Indices of the pair (default 0, 0).
    axes : (Axes, Axes), optional
        Magnitude and phase axes to draw on; default a new figure with two rows.
    label : str, optional
        Legend label (default ``"output / input"``).
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.semilogx`.

    Returns
    -------
    Figure
        The figure holding the axes.
    """
    if axes is None:
        fig, (ax_m, ax_p) = _new_figure(2, sharex=True)
    else:
        ax_m, ax_p = axes
        fig = ax_m.figure
    label = label or f"{fr.output_names[output_index]} / {fr.input_names[input_index]}"
    ax_m.semilogx(fr.freq_hz, fr.magnitude_db[:, output_index, input_index], label=label, **kwargs)
    ax_p.semilogx(fr.freq_hz, fr.phase_deg[:, output_index, input_index], label=label, **kwargs)
    ax_m.set_ylabel("magnitude, dB")
    ax_p.set_ylabel("phase, deg")
    ax_p.set_xlabel("frequency, Hz")
    for ax in (ax_m, ax_p):
        ax.grid(True, which="both", alpha=0.3)
    ax_m.legend(loc="best", fontsize="small")
    return fig


def plot_step(
    t: np.ndarray,
    y: np.ndarray,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    **kwargs: object,
) -> Figure:
    """Plot step responses: ``y`` of shape (nt,), (nt, p) or (nt, p, m) against t.

    Parameters
    ----------
    t : ndarray, shape (nt,)
        Times (s).
    y : ndarray
        Responses from :func:`step_response` (every output/input pair is drawn).
    ax : Axes, optional
        Axes to draw on; default a new figure.
    labels : sequence of str, optional
        One label per drawn curve.
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.plot`.

    Returns
    -------
    Figure
        The figure holding the axes.
    """
    if ax is None:
        fig, (ax,) = _new_figure()
    else:
        fig = ax.figure
    y = np.asarray(y)
    curves = y.reshape(y.shape[0], -1)
    for i in range(curves.shape[1]):
        lab = labels[i] if labels is not None else None
        ax.plot(t, curves[:, i], label=lab, **kwargs)
    ax.set_xlabel("time, s")
    ax.set_ylabel("response")
    ax.grid(True, alpha=0.3)
    if labels is not None:
        ax.legend(loc="best", fontsize="small")
    return fig


def plot_mode_shapes(
    modes: Modes,
    names: Sequence[str] | None = None,
    n_modes: int | None = None,
    ax: Axes | None = None,
    include_rigid: bool = False,
) -> Figure:
    """Mode shapes as lines over the coordinates, each scaled to max |v| = 1.

    Parameters
    ----------
    modes : Modes
        From :func:`modes`.
    names : sequence of str, optional
        Coordinate names for the x axis (default ``q1…``).
    n_modes : int, optional
        Number of modes drawn (default all selected).
    ax : Axes, optional
        Axes to draw on; default a new figure.
    include_rigid : bool, optional
        Also draw rigid modes (default False).

    Returns
    -------
    Figure
        The figure holding the axes; each mode is labelled with its frequency.
    """
    if ax is None:
        fig, (ax,) = _new_figure()
    else:
        fig = ax.figure
    names = _names(names, "q", modes.n, "coordinate")
    idx = np.flatnonzero(np.ones(modes.n, bool) if include_rigid else ~modes.rigid)
    if n_modes is not None:
        idx = idx[:n_modes]
    x = np.arange(modes.n)
    for i in idx:
        v = modes.shapes[:, i]
        ax.plot(x, v / np.max(np.abs(v)), marker="o", label=f"{modes.freq_hz[i]:.4g} Hz")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xticks(x, names)
    ax.set_ylabel("normalised shape")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig
