"""Linearisation and modes of a system with holonomic constraints Φ(q) = 0.

The chapter-3 elimination (:mod:`rt70.linear.holonomic`,
:class:`rt70.physics.constraints.HolonomicMap`) removes constraints that are linear in the
coordinates, ``q = T q_r + q₀``, by ``Tᵀ M T``. A closed chain (companion source 004 (14),
``B_c q̈ + C = 0``) is held by constraints Φ(q) = 0 that are nonlinear; this module
generalises the elimination to them about an equilibrium on the constraint manifold
(docs/constrained-modes.md). The constraints and their algebra are in
:mod:`rt70.linear.manifold`, the equilibrium (q*, λ*) in
:mod:`rt70.linear.constrained_equilibrium`.

Convention (that of :mod:`rt70.physics.kkt`): the reactions enter the equations of motion as
``A q̈ + B q̇ = Q + B_cᵀ λ`` with ``B_c = ∂Φ/∂q``; K = −∂Q/∂q is the stiffness of the
static forces (springs and gravity), D = −∂Q/∂q̇ the damping.

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

Generic: the constraints and forces come in as callables of q
(:class:`rt70.linear.manifold.Constraints`); the wiring to a URDF scene is
:mod:`rt70.linear.constrained_scene`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.linear import modal
from rt70.linear.manifold import (
    FD_STEP,
    RANK_RTOL,
    STEP_TOL,
    Constraints,
    Vector,
    force_stiffness,
    force_vector,
    geometric_stiffness,
    subspaces,
)

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
    (:func:`~rt70.linear.manifold.geometric_stiffness`).

    Parameters
    ----------
    constraints : Constraints
        Φ and B_c.
    q0, lam : array_like
        The equilibrium and its multipliers
        (:func:`~rt70.linear.constrained_equilibrium.equilibrium`).
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
    :data:`~rt70.linear.manifold.STEP_TOL` of the coordinate scale.

    Parameters
    ----------
    constraints : Constraints
        Φ and B_c.
    part : Partition
        The independent rows and the dependent and independent coordinates.
    q_guess : array_like, shape (n,)
        The independent coordinates' values and the dependent ones' start, m or rad.
    max_iter : int
        Newton steps allowed.

    Raises
    ------
    Rt70Error
        If Newton does not converge.
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

    Parameters
    ----------
    force : callable
        Static generalised force ``q ↦ Q(q)``, shape (n,), N or N·m per coordinate.
    constraints : Constraints
        Φ and B_c.
    q0 : array_like, shape (n,)
        The equilibrium on the manifold, m or rad per coordinate.
    M, D : ndarray, shape (n, n)
        Mass and damping matrices at q0 in the full coordinates (D default zero).
    partition : Partition, optional
        The coordinate partition (default :func:`choose_partition` of ``B_c(q0)``).
    h : float
        The difference step of ``K_r`` per independent coordinate, m or rad.

    Raises
    ------
    Rt70Error
        If the constraints leave no motion at q0, or a dependent coordinate cannot be
        solved for.
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
        return J.T @ force_vector(force, q)

    K_r = force_stiffness(reduced_force, q0[part.independent], h)
    lam = subspaces(B).multipliers(force_vector(force, q0))
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
