"""Linear nonholonomic constraints and program constraints (companion source 002).

Plain linear algebra below both sides, on the matrices a side hands in: the mass
matrix ``M(q)``, the velocity-product force ``h(q, q̇)``, the generalised force ``Q``
and the constraint rows ``A(q)`` of ``A(q) q̇ = 0`` (1.1) with their velocity product
``Ȧ q̇``. The analyses (:mod:`rt70.mechanics.nonholonomic_scene`) evaluate those on the textbook
side or on Pinocchio and compare.

- Algorithm 002-A (Chaplygin reduction, general projection form): partition
  ``A = [A₁ | A₂]``, ``q̇_dep = B q̇_ind`` with ``B = −A₂⁻¹ A₁`` (1.2)–(1.3),
  ``𝔅 = [I; B]`` (in the full coordinate order), ``A* = 𝔅ᵀ M 𝔅`` (1.7),
  ``a = 𝔅ᵀ (M 𝔅̇ q̇_ind + h(q, 𝔅 q̇_ind))``, ``Q* = 𝔅ᵀ Q`` and ``A* q̈_ind + a = Q* + R``
  — identical to the Chaplygin equations (1.6) with the corrected sign (erratum X.3.1).
  :func:`chaplygin_property` checks that ``B`` and ``M`` do not depend on the dependent
  coordinates.
- The reactions of the constraints: ``M q̈ + h = Q + Aᵀ λ`` with ``A q̈ + Ȧ q̇ = 0``,
  solved as a KKT system (:func:`rt70.physics.kkt.solve_kkt`).
- Algorithm 002-B (program constraints ``φ = α`` with stable perturbation equations,
  the generalised Baumgarte scheme (2.2)): ``V q̈ + w = β`` (2.7), the multipliers
  ``λ = S⁻¹ (β − w − V A*⁻¹ (Q − h))``, ``S = V A*⁻¹ D`` (ideal constraints: ``D = Fᵀ``
  (2.4); servo constraints: any force directions D) and ``q̈ = A*⁻¹ (Q − h + D λ)``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.physics.kkt import KKTSolution, solve_kkt

#: ``A₂`` (or ``S``) whose condition number passes this counts as singular.
MAX_CONDITION = 1e12


class ConstraintSingularityError(Rt70Error):
    """A constraint matrix that must be invertible is (numerically) singular here."""


@dataclass(frozen=True)
class Projection:
    """The velocity map ``q̇ = 𝔅 q̇_ind`` of a partition (1.2)–(1.3).

    Attributes
    ----------
    independent, dependent : numpy.ndarray
        Indices of the independent and dependent coordinates in the full order.
    B : numpy.ndarray
        ``−A₂⁻¹ A₁`` (dependent × independent), ``q̇_dep = B q̇_ind`` (1.3).
    basis : numpy.ndarray
        ``𝔅`` (n × p): ``[I; B]`` with its rows in the full coordinate order.
    """

    independent: np.ndarray
    dependent: np.ndarray
    B: np.ndarray
    basis: np.ndarray

    def rate(self, A: np.ndarray, A_dot_qd: np.ndarray) -> np.ndarray:
        """``𝔅̇ q̇_ind`` (n,): zero on the independent rows, ``−A₂⁻¹ (Ȧ q̇)`` on the others.

        Differentiating ``A 𝔅 q̇_ind = 0`` once at ``q̈_ind = 0`` gives
        ``A 𝔅̇ q̇_ind + Ȧ q̇ = 0``; ``Ȧ q̇`` is taken at the full ``q̇ = 𝔅 q̇_ind``.
        """
        out = np.zeros(self.basis.shape[0])
        out[self.dependent] = -np.linalg.solve(A[:, self.dependent], A_dot_qd)
        return out


def partition(A: np.ndarray, independent: Sequence[int]) -> Projection:
    """Solve ``A q̇ = 0`` for the dependent velocities: ``B = −A₂⁻¹ A₁`` (1.3).

    Raises
    ------
    ConstraintSingularityError
        If the numbers of rows and dependent coordinates differ, or ``A₂`` is singular
        (condition number above :data:`MAX_CONDITION`): choose other independent
        coordinates, or use :func:`constrained_dynamics`.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n = A.shape[1]
    ind = np.asarray(independent, dtype=int)
    if len(set(ind.tolist())) != ind.size or np.any((ind < 0) | (ind >= n)):
        raise Rt70Error(f"independent coordinates {ind.tolist()}: not distinct indices below {n}")
    dep = np.setdiff1d(np.arange(n), ind)
    if dep.size != A.shape[0]:
        raise ConstraintSingularityError(
            f"{A.shape[0]} constraint rows cannot fix {dep.size} dependent velocities"
        )
    A2 = A[:, dep]
    if np.linalg.cond(A2) > MAX_CONDITION:
        raise ConstraintSingularityError(
            f"A₂ (columns {dep.tolist()}) is singular here: the dependent velocities are "
            "not determined by the constraints"
        )
    B = -np.linalg.solve(A2, A[:, ind])
    basis = np.zeros((n, ind.size))
    basis[ind] = np.eye(ind.size)
    basis[dep] = B
    return Projection(ind, dep, B, basis)


@dataclass(frozen=True)
class ReducedSystem:
    """``A* q̈_ind + a = Q* + R`` (Algorithm 002-A, steps 3–6)."""

    A_star: np.ndarray
    a: np.ndarray
    Q_star: np.ndarray

    def acceleration(self, R: np.ndarray | None = None) -> np.ndarray:
        """``q̈_ind = A*⁻¹ (Q* + R − a)`` (Cholesky; ``A*`` is positive definite (1.7))."""
        rhs = self.Q_star - self.a + (0.0 if R is None else R)
        return scipy.linalg.cho_solve(scipy.linalg.cho_factor(self.A_star), rhs)


def reduce(
    M: np.ndarray, h: np.ndarray, Q: np.ndarray, basis: np.ndarray, basis_rate_qd: np.ndarray
) -> ReducedSystem:
    """The projection form of the Chaplygin equations (1.6)–(1.7).

    ``A* = 𝔅ᵀ M 𝔅``, ``a = 𝔅ᵀ (M 𝔅̇ q̇_ind + h)``, ``Q* = 𝔅ᵀ Q``, with ``h`` the
    velocity-product force at ``q̇ = 𝔅 q̇_ind`` (gravity belongs to Q).

    Parameters
    ----------
    M : numpy.ndarray, shape (n, n)
        The mass matrix at q, full coordinates.
    h : numpy.ndarray, shape (n,)
        The velocity-product force ``h(q, 𝔅 q̇_ind)``, N or N·m per coordinate.
    Q : numpy.ndarray, shape (n,)
        The generalised force (gravity, springs, inputs), N or N·m per coordinate.
    basis : numpy.ndarray, shape (n, p)
        ``𝔅`` of the partition (:attr:`Projection.basis`).
    basis_rate_qd : numpy.ndarray, shape (n,)
        ``𝔅̇ q̇_ind`` (:meth:`Projection.rate`), m/s² or rad/s² per coordinate.
    """
    return ReducedSystem(
        basis.T @ M @ basis, basis.T @ (M @ basis_rate_qd + h), basis.T @ np.asarray(Q)
    )


def constrained_dynamics(
    M: np.ndarray, h: np.ndarray, Q: np.ndarray, A: np.ndarray, A_dot_qd: np.ndarray
) -> KKTSolution:
    """``q̈`` and the reactions λ of ``M q̈ + h = Q + Aᵀ λ``, ``A q̈ + Ȧ q̇ = 0``.

    The full (unreduced) equations with the constraints' multipliers, by the
    range-space KKT solve of :func:`rt70.physics.kkt.solve_kkt`; ``Aᵀ λ`` are the generalised
    reactions (for a ``<rt70:no_slip>`` row, λ is the contact force along its unit
    direction, in N).

    Parameters
    ----------
    M : numpy.ndarray, shape (n, n)
        The mass matrix at q.
    h : numpy.ndarray, shape (n,)
        The velocity-product force ``h(q, q̇)``, N or N·m per coordinate.
    Q : numpy.ndarray, shape (n,)
        The generalised force, N or N·m per coordinate.
    A : numpy.ndarray, shape (m, n)
        The constraint rows of ``A(q) q̇ = 0`` (1.1).
    A_dot_qd : numpy.ndarray, shape (m,)
        ``Ȧ q̇``, m/s² per row (rad/s² for an angular row).
    """
    return solve_kkt(M, np.atleast_2d(A), np.asarray(Q) - h, -np.asarray(A_dot_qd))


def chaplygin_property(
    constraint_matrix: Callable[[np.ndarray], np.ndarray],
    mass_matrix: Callable[[np.ndarray], np.ndarray],
    q: np.ndarray,
    independent: Sequence[int],
    shifts: Sequence[float] = (0.37, -1.3, 2.9),
    rtol: float = 1e-12,
) -> bool:
    """Whether ``B`` and ``M`` do not depend on the dependent coordinates (002.1.1).

    ``B(q)`` and ``M(q)`` are evaluated at q and with every dependent coordinate shifted
    by each of ``shifts``; the system is a Chaplygin system at q if they all agree to
    ``rtol`` relative to their max-norm. (A sampled check: it proves dependence, and
    is evidence of independence.)

    Parameters
    ----------
    constraint_matrix : callable
        ``q ↦ A(q)``, shape (m, n), the rows of ``A(q) q̇ = 0``.
    mass_matrix : callable
        ``q ↦ M(q)``, shape (n, n).
    q : numpy.ndarray, shape (n,)
        The configuration checked, m or rad per coordinate.
    independent : sequence of int
        Indices of the independent coordinates (:func:`partition`).
    shifts : sequence of float
        The shifts given to every dependent coordinate in turn, m or rad.
    rtol : float
        Relative tolerance of the agreement.
    """
    q = np.asarray(q, dtype=float)
    base = partition(constraint_matrix(q), independent)
    M0 = mass_matrix(q)
    for s in shifts:
        qs = q.copy()
        qs[base.dependent] += s
        B = partition(constraint_matrix(qs), independent).B
        if np.max(np.abs(B - base.B), initial=0.0) > rtol * max(1.0, np.max(np.abs(base.B))):
            return False
        if np.max(np.abs(mass_matrix(qs) - M0)) > rtol * np.max(np.abs(M0)):
            return False
    return True


# --- program constraints (Algorithm 002-B) ------------------------------------------------
def perturbation_matrix(
    m: int, k: int, omega: float, zeta: float, kappa: float | Sequence[float]
) -> np.ndarray:
    """A stable linear choice of the perturbation equations (2.2): ``β = P (α, α̇, α')``.

    ``m`` holonomic constraints follow ``α̈ = −2ζω α̇ − ω² α`` (poles
    ``ω(−ζ ± √(ζ²−1))``), ``k`` first-order ones ``α̇'_i = −κ_i α'_i`` (one κ for all,
    or one per constraint). P is ``(m + k) × (2m + k)``.

    Parameters
    ----------
    m : int
        Number of holonomic (second-order) program constraints α.
    k : int
        Number of first-order program constraints α'.
    omega : float
        Natural frequency ω of the holonomic ones, rad/s.
    zeta : float
        Their damping ratio ζ.
    kappa : float or sequence of float
        Decay rates κ of the first-order ones, 1/s: one for all or ``k`` of them.

    Raises
    ------
    Rt70Error
        If a gain is not positive (the trivial solution would not be asymptotically
        stable).
    """
    kappas = np.broadcast_to(np.asarray(kappa, dtype=float), (k,))
    if not (omega > 0.0 and zeta > 0.0 and np.all(kappas > 0.0)):
        raise Rt70Error(f"perturbation gains must be positive: ω={omega}, ζ={zeta}, κ={kappa}")
    P = np.zeros((m + k, 2 * m + k))
    P[:m, :m] = -(omega**2) * np.eye(m)
    P[:m, m : 2 * m] = -2.0 * zeta * omega * np.eye(m)
    P[m:, 2 * m :] = -np.diag(kappas)
    return P


def program_multipliers(
    A_star: np.ndarray,
    h: np.ndarray,
    Q: np.ndarray,
    V: np.ndarray,
    w: np.ndarray,
    beta: np.ndarray,
    D: np.ndarray,
) -> np.ndarray:
    """Multipliers (servo forces) λ of program constraints ``V q̈ + w = β`` (2.7).

    With ``q̈ = A*⁻¹ (Q − h + D λ)`` (2.5): ``S λ = β − w − V A*⁻¹ (Q − h)``,
    ``S = V A*⁻¹ D``. ``D = Fᵀ`` (F = V) for ideal program constraints (2.4), the
    actuators' force directions for servo constraints.

    Parameters
    ----------
    A_star : numpy.ndarray, shape (p, p)
        The mass matrix of the coordinates the program acts on (positive definite): the
        reduced ``A*`` of Algorithm 002-A, or a full M.
    h : numpy.ndarray, shape (p,)
        The velocity-product force on them (the reduced ``a``), N or N·m.
    Q : numpy.ndarray, shape (p,)
        The generalised force on them (the reduced ``Q*``), N or N·m.
    V : numpy.ndarray, shape (r, p)
        The program constraints' rows at the acceleration level, ``V q̈ + w = β``.
    w : numpy.ndarray, shape (r,)
        Their velocity-product terms.
    beta : numpy.ndarray, shape (r,)
        The perturbation equations' right-hand sides (``P (α, α̇, α')``,
        :func:`perturbation_matrix`).
    D : numpy.ndarray, shape (p, r)
        The force directions of the multipliers, one column each.

    Returns
    -------
    numpy.ndarray, shape (r,)
        λ, in the units of each column of D (N·m for a torque, N for a force).

    Raises
    ------
    ConstraintSingularityError
        If S is singular (condition above :data:`MAX_CONDITION`), e.g. at zero
        programmed speed in the cart example (002.1.4, observation 1).
    """
    V, D = np.atleast_2d(V), np.atleast_2d(D)
    factor = scipy.linalg.cho_factor(A_star)
    S = V @ scipy.linalg.cho_solve(factor, D)
    if S.shape[0] != S.shape[1] or np.linalg.cond(S) > MAX_CONDITION:
        raise ConstraintSingularityError(
            f"S = V A*⁻¹ D ({S.shape[0]}×{S.shape[1]}) is singular here: the program "
            "constraints cannot be enforced along these force directions"
        )
    rhs = beta - w - V @ scipy.linalg.cho_solve(factor, np.asarray(Q) - h)
    return np.linalg.solve(S, rhs)


def program_acceleration(
    A_star: np.ndarray, h: np.ndarray, Q: np.ndarray, D: np.ndarray, lam: np.ndarray
) -> np.ndarray:
    """``q̈ = A*⁻¹ (Q − h + D λ)`` (2.5).

    Parameters
    ----------
    A_star : numpy.ndarray, shape (p, p)
        The mass matrix of the coordinates (positive definite).
    h : numpy.ndarray, shape (p,)
        The velocity-product force, N or N·m per coordinate.
    Q : numpy.ndarray, shape (p,)
        The generalised force, N or N·m per coordinate.
    D : numpy.ndarray, shape (p, r)
        The force directions of the multipliers.
    lam : numpy.ndarray, shape (r,)
        The multipliers (:func:`program_multipliers`).
    """
    rhs = np.asarray(Q) - h + np.atleast_2d(D) @ lam
    return scipy.linalg.cho_solve(scipy.linalg.cho_factor(A_star), rhs)
