"""Equilibrium, linearisation and modes of a system with holonomic constraints Φ(q) = 0.

The chapter-3 elimination (:mod:`rt70.linear.holonomic`,
:class:`rt70.physics.constraints.HolonomicMap`) removes constraints that are linear in the
coordinates, ``q = T q_r + q₀``, by ``Tᵀ M T``. A closed chain (companion source 004 (14),
``B_c q̈ + C = 0``) is held by constraints Φ(q) = 0 that are nonlinear; this module
generalises the elimination to them about an equilibrium on the constraint manifold
(docs/constrained-modes.md).

Convention (that of :mod:`rt70.physics.kkt`): the reactions enter the equations of motion as
``A q̈ + B q̇ = Q + B_cᵀ λ`` with ``B_c = ∂Φ/∂q``; K = −∂Q/∂q is the stiffness of the
static forces (springs and gravity), D = −∂Q/∂q̇ the damping.

- **Equilibrium on the manifold**: ``Q(q) + B_cᵀ λ = 0``, ``Φ(q) = 0``, solved by
  Newton in a null-space form (:func:`equilibrium`): λ are the least-norm multipliers of
  the force, the step splits into a row-space part that closes Φ and a null-space part
  that balances the force along the manifold.
- **Linearisation** about (q*, λ*): with ``q = q* + δq``, ``λ = λ* + δλ`` the reaction's
  change is ``B_cᵀ δλ + Σ λ_i ∇²Φ_i δq``, so::

      A δq̈ + D δq̇ + (K + G) δq = B_cᵀ δλ,    B_c δq = 0,
      G = −∂(B_c(q)ᵀ λ*)/∂q = −Σ λ*_i ∇²Φ_i     (the multipliers' geometric stiffness).

  A basis N of the null space of B_c(q*) (``δq = N z``) gives
  ``M_r = Nᵀ A N``, ``K_r = Nᵀ (K + G) N``, ``D_r = Nᵀ D N`` (:func:`linearize`).
  Projecting K alone (G dropped) is the naive projection; it is wrong whenever the
  reactions are not zero — a particle hanging by the constraint ``x² + y² = l²`` has
  K = 0 in (x, y) and all of its ``g/l`` comes from G (tests/test_constrained_modes.py).
- **The same by a coordinate partition** (:func:`partition_linearize`): independent
  coordinates z, the dependent ones solved from Φ by Newton, ``q = q(z)``; the reduced
  force ``Q_r(z) = J(z)ᵀ Q(q(z))`` with ``J = ∂q/∂z`` is differenced, ``K_r = −∂Q_r/∂z``,
  ``M_r = Jᵀ A J``. No multiplier appears: G is in the curvature of q(z). The two give
  the same spectrum and the same mode shapes in the full coordinates (the tests check it).
- **Modes** (:func:`modes`): :func:`rt70.linear.modal.modes` of the reduced model, the
  shapes taken back to the full coordinates, ``N φ``; they are A-orthonormal because φ
  is ``Nᵀ A N``-orthonormal.

Generic: the constraints and forces come in as callables of q (:class:`Constraints`);
the wiring to a URDF scene is :mod:`rt70.linear.constrained_scene`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.linear import modal

Vector = Callable[[np.ndarray], np.ndarray]

#: Singular values of B_c below this fraction of the largest count as zero (dependent
#: constraint rows, as in :data:`rt70.physics.kkt.RANK_RTOL`).
RANK_RTOL = 1e-10
#: Central-difference step per coordinate of the stiffness matrices (m or rad): the
#: truncation error is O(h²) ≈ 1e-12 relative, the rounding O(ε/h) ≈ 1e-10 relative.
FD_STEP = 1e-6
#: Newton stops when its step moves no coordinate by more than this (relative to the
#: largest |q|, at least 1): the configuration is fixed to rounding.
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


# ---------------------------------------------------------------------------- equilibrium


@dataclass(frozen=True)
class Equilibrium:
    """A static equilibrium on the constraint manifold.

    Attributes
    ----------
    q : ndarray, shape (n,)
        The configuration, ``Φ(q) = 0``.
    lam : ndarray, shape (m,)
        The multipliers, ``Q(q) + B_cᵀ λ = 0`` (least-norm with dependent rows).
    force_residual : float
        ``max|Q + B_cᵀ λ|`` left (the force the reactions cannot balance).
    constraint_residual : float
        ``max|Φ(q)|`` left.
    iterations : int
        Newton steps taken.
    """

    q: np.ndarray
    lam: np.ndarray
    force_residual: float
    constraint_residual: float
    iterations: int


def equilibrium(
    force: Vector,
    constraints: Constraints,
    q_start: np.ndarray,
    stiffness: Vector | None = None,
    tol: float = 1e-10,
    max_iter: int = 50,
    h: float = FD_STEP,
    descend: bool = False,
) -> Equilibrium:
    """Solve ``Q(q) + B_cᵀ λ = 0``, ``Φ(q) = 0`` by Newton's method in null-space form.

    At each iterate: the SVD of B_c gives the row space R and null space N; λ are the
    least-norm multipliers of Q; ``K_t = K + G(q, λ)``; the step
    ``δq = R δy + N δz`` closes the constraints to first order (``B_c R δy = −Φ``) and
    balances the force along the manifold,
    ``Nᵀ K_t N δz = Nᵀ (Q + B_cᵀ λ) − Nᵀ K_t R δy``. Converged when the force left along
    the manifold is below ``tol`` times the force scale (max|Q| at the start, at least 1)
    and ``max|Φ|`` below ``tol`` times the coordinate scale (max|q|, at least 1), or when
    a step moves no coordinate by more than :data:`STEP_TOL` of that scale.

    Parameters
    ----------
    force : callable
        Static generalised force ``Q(q)`` (gravity and springs at rest).
    constraints : Constraints
        Φ and B_c.
    q_start : array_like
        Start (need not satisfy the constraints).
    stiffness : callable, optional
        ``K(q) = −∂Q/∂q``; default central differences of ``force``.
    tol : float
        Relative convergence tolerance (see above).
    max_iter : int
        Newton steps allowed.
    h : float
        Difference step of the geometric stiffness (and of K when not given).
    descend : bool
        Look for a stable equilibrium (a minimum of the potential): where the stiffness
        along the manifold has negative eigenvalues, step downhill along them
        (``|K_r|`` for ``K_r``, steps limited to :data:`MAX_DESCENT_STEP` of the
        coordinate scale) instead of toward the nearest stationary point. Near a stable
        equilibrium it is Newton's method unchanged.

    Returns
    -------
    Equilibrium

    Raises
    ------
    Rt70Error
        If the stiffness along the manifold is singular (a direction the constraints leave
        free and nothing holds), or Newton does not converge. Newton finds stationary
        points: an unstable equilibrium (an inverted pendulum) is one too, and its modes
        say so.
    """
    q = np.array(q_start, dtype=float)
    K_of = stiffness or (lambda x: force_stiffness(force, x, h))
    f_scale = max(_max(_force(force, q)), 1.0)

    def state(q: np.ndarray):
        Q = _force(force, q)
        phi, B = constraints.evaluate(q)
        sub = subspaces(B)
        lam = sub.multipliers(Q)
        r_f = Q + B.T @ lam
        return phi, sub, lam, r_f

    for it in range(max_iter):
        phi, sub, lam, r_f = state(q)
        q_scale = max(float(np.max(np.abs(q), initial=0.0)), 1.0)
        f_left, c_left = _max(r_f), _max(phi)
        if f_left <= tol * f_scale and c_left <= tol * q_scale:
            return Equilibrium(q, lam, f_left, c_left, it)
        dq = sub.closing_step(phi)
        N = sub.null
        if N.shape[1]:
            Kt = np.asarray(K_of(q), dtype=float) + geometric_stiffness(constraints, q, lam, h)
            Kr = N.T @ Kt @ N
            dz = _manifold_step(Kr, N.T @ r_f - N.T @ Kt @ dq, f_scale, descend, q_scale)
            dq = dq + N @ dz
        if not np.isfinite(dq).all():
            raise Rt70Error("the equilibrium's Newton step is not finite")
        q = q + dq
        if _max(dq) <= STEP_TOL * q_scale:  # fixed to rounding: what is left is rounding
            phi, _, lam, r_f = state(q)
            return Equilibrium(q, lam, _max(r_f), _max(phi), it + 1)
    raise Rt70Error(
        f"equilibrium on the constraint manifold not found in {max_iter} Newton steps "
        f"(force left {f_left:.3g}, constraint residual {c_left:.3g})"
    )


#: Largest step (times the coordinate scale, at least 1) of a descent toward a stable
#: equilibrium through a region of negative stiffness.
MAX_DESCENT_STEP = 0.25


def _manifold_step(
    Kr: np.ndarray, rhs: np.ndarray, f_scale: float, descend: bool, q_scale: float
) -> np.ndarray:
    """Solve ``K_r δz = rhs`` for the step along the manifold.

    Directions of zero stiffness (a mechanism that nothing holds, as a crank–slider in a
    horizontal plane) take no step if no force acts along them, and are refused if one
    does. With ``descend`` the negative stiffnesses count as positive (a step downhill).
    """
    w, V = np.linalg.eigh(0.5 * (Kr + Kr.T))
    scale = float(np.max(np.abs(w), initial=0.0))
    zero = np.abs(w) <= 1e-12 * max(scale, f_scale)
    b = V.T @ rhs
    if np.any(np.abs(b[zero]) > 1e-10 * f_scale):
        raise Rt70Error(
            "no equilibrium on the constraint manifold: the stiffness along it is "
            "singular (a motion the constraints allow that nothing holds) and a force "
            "acts along it"
        )
    stiff = np.where(zero, 1.0, np.abs(w) if descend else w)
    dz = V @ np.where(zero, 0.0, b / stiff)
    if descend and np.any(w[~zero] < 0):
        limit = MAX_DESCENT_STEP * q_scale
        size = float(np.max(np.abs(dz), initial=0.0))
        if size > limit:
            dz *= limit / size
    return dz


def _force(force: Vector, q: np.ndarray) -> np.ndarray:
    """``force(q)`` as a finite float vector of q's length, or a clear error."""
    Q = np.asarray(force(q), dtype=float)
    if Q.shape != q.shape:
        raise Rt70Error(f"the force has shape {Q.shape}, q has {q.shape}")
    if not np.isfinite(Q).all():
        raise Rt70Error("the force is NaN or infinite")
    return Q


def _max(x: np.ndarray) -> float:
    return float(np.max(np.abs(x), initial=0.0))


# ------------------------------------------------------------------------- linearisation


@dataclass(frozen=True)
class ConstrainedLinearization:
    """``M_r z̈ + D_r ż + K_r z = 0`` on the manifold, ``δq = N z`` (or ``J z``).

    Attributes
    ----------
    q0, lam : ndarray
        The equilibrium and its multipliers.
    basis : ndarray, shape (n, k)
        N (orthonormal null space of B_c) or J = ∂q/∂z of a coordinate partition.
    M_r, K_r, D_r : ndarray, shape (k, k)
        Reduced mass, stiffness (with the geometric stiffness) and damping.
    K_geometric : ndarray, shape (k, k) or None
        ``Nᵀ G N``, the multipliers' part of K_r (None for a partition: it is implicit).
    rank : int
        Number of independent constraint rows at q0.
    """

    q0: np.ndarray
    lam: np.ndarray
    basis: np.ndarray
    M_r: np.ndarray
    K_r: np.ndarray
    D_r: np.ndarray
    K_geometric: np.ndarray | None
    rank: int

    @property
    def n(self) -> int:
        """Number of independent motions on the manifold."""
        return self.basis.shape[1]


def _matrix(name: str, X, n: int) -> np.ndarray:
    X = np.asarray(X, dtype=float)
    if X.shape != (n, n):
        raise Rt70Error(f"{name} must be {n} × {n}, got shape {X.shape}")
    return X


def linearize(
    constraints: Constraints,
    q0: np.ndarray,
    lam: np.ndarray,
    M: np.ndarray,
    K: np.ndarray,
    D: np.ndarray | None = None,
    geometric: bool = True,
    h: float = FD_STEP,
) -> ConstrainedLinearization:
    """Null-space linearisation about an equilibrium (q0, λ).

    ``M_r = Nᵀ M N``, ``K_r = Nᵀ (K + G) N``, ``D_r = Nᵀ D N`` with N an orthonormal
    basis of the null space of ``B_c(q0)`` and ``G = −Σ λ_i ∇²Φ_i``
    (:func:`geometric_stiffness`).

    Parameters
    ----------
    constraints : Constraints
        Φ and B_c.
    q0, lam : array_like
        The equilibrium and its multipliers (:func:`equilibrium`).
    M, K, D : ndarray, shape (n, n)
        Mass, stiffness ``−∂Q/∂q`` and damping matrices at q0 in the full coordinates.
    geometric : bool
        Keep G (default). ``False`` gives the naive projection ``Nᵀ K N`` — wrong unless
        λ = 0 or Φ is linear; it is there to show the difference.
    h : float
        Difference step of the geometric stiffness.

    Raises
    ------
    Rt70Error
        If the constraints leave no motion (the mechanism is rigid at q0).
    """
    q0 = np.asarray(q0, dtype=float)
    n = q0.size
    M = _matrix("M", M, n)
    K = _matrix("K", K, n)
    D = np.zeros((n, n)) if D is None else _matrix("D", D, n)
    _, B = constraints.evaluate(q0)
    sub = subspaces(B)
    N = sub.null
    if N.shape[1] == 0:
        raise Rt70Error(f"the {sub.rank} independent constraints leave no motion at q0")
    Kg = N.T @ geometric_stiffness(constraints, q0, lam, h) @ N
    K_r = N.T @ K @ N + (Kg if geometric else 0.0)
    return ConstrainedLinearization(
        q0=q0,
        lam=np.asarray(lam, dtype=float),
        basis=N,
        M_r=_sym(N.T @ M @ N),
        K_r=_sym(K_r),
        D_r=_sym(N.T @ D @ N),
        K_geometric=_sym(Kg),
        rank=sub.rank,
    )


def _sym(X: np.ndarray) -> np.ndarray:
    return 0.5 * (X + X.T)


@dataclass(frozen=True)
class Partition:
    """Independent and dependent coordinates of a coordinate partition at a point.

    Attributes
    ----------
    rows : ndarray of int
        The independent constraint rows used (dependent rows are dropped).
    dependent, independent : ndarray of int
        Coordinates solved from Φ, and the free ones z.
    """

    rows: np.ndarray
    dependent: np.ndarray
    independent: np.ndarray


def choose_partition(B_c: np.ndarray, rank_rtol: float = RANK_RTOL) -> Partition:
    """Pick r independent rows and r dependent coordinates of B_c by pivoted QR.

    The rows are the first r pivots of ``qr(B_cᵀ)``; the dependent coordinates the first r
    pivots of ``qr(B_c[rows])`` — the best-conditioned square block ``∂Φ/∂w`` QR finds.
    """
    B_c = np.atleast_2d(np.asarray(B_c, dtype=float))
    n = B_c.shape[1]
    r = subspaces(B_c, rank_rtol).rank
    if r == 0:
        return Partition(np.zeros(0, int), np.zeros(0, int), np.arange(n))
    _, _, prow = scipy.linalg.qr(B_c.T, pivoting=True, mode="economic")
    rows = np.sort(prow[:r])
    _, _, pcol = scipy.linalg.qr(B_c[rows], pivoting=True, mode="economic")
    dependent = np.sort(pcol[:r])
    return Partition(rows, dependent, np.setdiff1d(np.arange(n), dependent))


def _partition_jacobian(B: np.ndarray, part: Partition) -> np.ndarray:
    """``J = ∂q/∂z``: identity on z, ``−(∂Φ/∂w)⁻¹ ∂Φ/∂z`` on the dependent coordinates."""
    n = B.shape[1]
    J = np.zeros((n, part.independent.size))
    J[part.independent, np.arange(part.independent.size)] = 1.0
    if part.dependent.size:
        Bw = B[np.ix_(part.rows, part.dependent)]
        Bz = B[np.ix_(part.rows, part.independent)]
        J[part.dependent] = -np.linalg.solve(Bw, Bz)
    return J


def solve_dependent(
    constraints: Constraints,
    part: Partition,
    q_guess: np.ndarray,
    max_iter: int = 50,
) -> np.ndarray:
    """The point of the manifold with the independent coordinates of ``q_guess``.

    Newton on the partition's rows, ``w ← w − (∂Φ/∂w)⁻¹ Φ``, until the step is below
    :data:`STEP_TOL` of the coordinate scale.
    """
    q = np.array(q_guess, dtype=float)
    scale = max(float(np.max(np.abs(q), initial=0.0)), 1.0)
    for _ in range(max_iter):
        if part.dependent.size == 0:
            return q
        phi, B = constraints.evaluate(q)
        dw = -np.linalg.solve(B[np.ix_(part.rows, part.dependent)], phi[part.rows])
        q[part.dependent] += dw
        if float(np.max(np.abs(dw))) <= STEP_TOL * scale:
            return q
    raise Rt70Error(f"dependent coordinates not found from Φ = 0 in {max_iter} Newton steps")


def partition_linearize(
    force: Vector,
    constraints: Constraints,
    q0: np.ndarray,
    M: np.ndarray,
    D: np.ndarray | None = None,
    partition: Partition | None = None,
    h: float = FD_STEP,
) -> ConstrainedLinearization:
    """Linearisation by a coordinate partition ``q = q(z)`` and differences of ``Q_r(z)``.

    ``Q_r(z) = J(z)ᵀ Q(q(z))`` is the generalised force on the independent coordinates;
    ``K_r = −∂Q_r/∂z`` by central differences (each q(z ± h e_i) solved by Newton,
    :func:`solve_dependent`), symmetrised; ``M_r = Jᵀ M J``, ``D_r = Jᵀ D J`` at q0.
    The multipliers' stiffness is not formed: it is the term ``−(∂J/∂z)ᵀ Q`` of the
    difference. λ is returned for reference (least-norm, from Q at q0).
    """
    q0 = np.asarray(q0, dtype=float)
    n = q0.size
    M = _matrix("M", M, n)
    D = np.zeros((n, n)) if D is None else _matrix("D", D, n)
    _, B = constraints.evaluate(q0)
    part = partition or choose_partition(B)
    J0 = _partition_jacobian(B, part)
    if J0.shape[1] == 0:
        raise Rt70Error("the constraints leave no motion at q0")

    def reduced_force(z: np.ndarray) -> np.ndarray:
        guess = q0.copy()
        guess[part.independent] = z
        q = solve_dependent(constraints, part, guess)
        J = _partition_jacobian(constraints.evaluate(q)[1], part)
        return J.T @ _force(force, q)

    K_r = force_stiffness(reduced_force, q0[part.independent], h)
    lam = subspaces(B).multipliers(_force(force, q0))
    return ConstrainedLinearization(
        q0=q0,
        lam=lam,
        basis=J0,
        M_r=_sym(J0.T @ M @ J0),
        K_r=K_r,
        D_r=_sym(J0.T @ D @ J0),
        K_geometric=None,
        rank=part.rows.size,
    )


# --------------------------------------------------------------------------------- modes


@dataclass(frozen=True)
class ConstrainedModes:
    """Modes of the reduced model and their shapes in the full coordinates.

    Attributes
    ----------
    modes : rt70.linear.modal.Modes
        Of ``K_r v = ω² M_r v`` (with D_r's modal damping when given).
    shapes : ndarray, shape (n, k)
        ``basis @ modes.shapes``: full-coordinate shapes, A-orthonormal
        (``shapesᵀ A shapes = 1``), each column's largest-magnitude entry positive
        (the reduced ``modes.shapes`` carry the same signs).
    """

    modes: modal.Modes
    shapes: np.ndarray


def modes(lin: ConstrainedLinearization, rigid_tol: float | None = None) -> ConstrainedModes:
    """:func:`rt70.linear.modal.modes` of the reduced model, shapes back in full coordinates."""
    result = modal.modes(lin.M_r, lin.K_r, lin.D_r, rigid_tol=rigid_tol)
    shapes = lin.basis @ result.shapes
    big = np.argmax(np.abs(shapes), axis=0)
    sign = np.where(shapes[big, np.arange(shapes.shape[1])] < 0, -1.0, 1.0)
    Z = result.modal_damping
    result = dataclasses.replace(  # the reduced shapes keep the full shapes' signs
        result,
        shapes=result.shapes * sign,
        modal_damping=None if Z is None else sign[:, None] * Z * sign[None, :],
    )
    return ConstrainedModes(result, shapes * sign)
