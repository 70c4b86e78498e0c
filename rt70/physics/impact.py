"""Impacts: a constraint engaged suddenly, the equations (15) of companion source 004.

When m constraints ``B_c q̇ = 0`` engage at once (a brake on an axis, a stow pin, an end
stop), the velocities jump while the positions stay. Integrating the equations of motion
(3) over the short impact interval gives (15)::

    A q̇⁺ − B_cᵀ Λ = A q̇⁻ + Γ,        B_c q̇⁺ = −e B_c q̇⁻

with ``q̇⁻``, ``q̇⁺`` the velocities before and after, ``Λ`` the impulses of the
constraint reactions, ``e`` the restitution (0: plastic — brakes, stow pins; the source's
case) and ``Γ`` the known impulses of external forces reduced to the coordinates.

Sign convention of Γ (erratum X.3.15: the scan shows "− Γ"): ``Γ = ∫ Q dt`` is the
impulse of generalised forces in the sense of the right-hand side of (3),
``A q̈ + B = Q + P`` — its power is ``q̇ᵀ Q``, so a wrench impulse ``(F̂, M̂)`` on a point
gives ``Γ = J_vᵀ F̂ + J_ωᵀ M̂`` (:func:`rt70.textbook.points.generalized_force` of the
impulse). With this sign ``A (q̇⁺ − q̇⁻) = Γ + B_cᵀ Λ`` is the change of momentum; the
scan's "− Γ" would be the impulse of the inertial forces. ``tests/test_impact.py`` checks
the sign against a short, strong force integrated by :func:`rt70.simulation.simulate.simulate`.

Energy (positions do not change, so the potential energy does not either)::

    T⁺ − T⁻ = ½ (Γ + B_cᵀ Λ)ᵀ (q̇⁺ + q̇⁻) = W_Γ + W_Λ

the work of the known impulses ``W_Γ = ½ Γᵀ (q̇⁻ + q̇⁺)`` and of the reactions
``W_Λ = ½ Λᵀ B_c (q̇⁻ + q̇⁺) = ½ (1 − e) Λᵀ B_c q̇⁻ ≤ 0``; the energy lost is
``−W_Λ``. For a plastic impact without Γ it is Carnot's theorem,
``T⁻ − T⁺ = ½ (q̇⁻ − q̇⁺)ᵀ A (q̇⁻ − q̇⁺)`` (the kinetic energy of the lost velocities).

The system is the KKT system of :func:`rt70.physics.kkt.solve_kkt` for the jump
(x = Δq̇ = q̇⁺ − q̇⁻, f = Γ, g = −(1 + e) B_c q̇⁻, λ = Λ; the same equations less
``A q̇⁻`` on both sides, so q̇⁻ does not make a round trip through A⁻¹, which would cost
ε·cond(A) and leave q̇ changed by rounding where no row holds): redundant constraint
rows give the unique q̇⁺ and the least-norm Λ. Plain linear algebra, no side imported:
the textbook side's A and B_c go in here; the reference side solves the same impact with
Pinocchio's ``impulseDynamics`` (:mod:`rt70.reference.locks`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector
from rt70.physics.kkt import solve_kkt


@dataclass(frozen=True)
class Impact:
    """Result of one impact (15).

    Attributes
    ----------
    qd_before, qd_after : numpy.ndarray
        ``q̇⁻`` and ``q̇⁺``, shape (n,).
    impulses : numpy.ndarray
        ``Λ``, the reactions' impulses (N·s or N·m·s per constraint row), shape (m,);
        the least-norm ones when rows are dependent.
    rank : int
        Number of independent constraint rows.
    restitution : float
        ``e``.
    kinetic_before, kinetic_after : float
        ``T⁻ = ½ q̇⁻ᵀ A q̇⁻`` and ``T⁺``, J.
    work_known : float
        ``W_Γ = ½ Γᵀ (q̇⁻ + q̇⁺)``, J (0 without Γ).
    energy_lost : float
        ``−W_Λ = −½ Λᵀ B_c (q̇⁻ + q̇⁺)``, J: what the impact dissipates.
    carnot : float
        ``½ (q̇⁻ − q̇⁺)ᵀ A (q̇⁻ − q̇⁺)``, J: the kinetic energy of the lost velocities
        (equal to ``energy_lost`` for a plastic impact without Γ).
    """

    qd_before: np.ndarray
    qd_after: np.ndarray
    impulses: np.ndarray
    rank: int
    restitution: float
    kinetic_before: float
    kinetic_after: float
    work_known: float
    energy_lost: float
    carnot: float

    @property
    def balance(self) -> float:
        """``T⁺ + energy_lost − W_Γ − T⁻``: zero up to rounding (the balance closes)."""
        return self.kinetic_after + self.energy_lost - self.work_known - self.kinetic_before


def check_restitution(restitution: float) -> float:
    """The restitution ``e`` as a float in [0, 1], or an :class:`~rt70.errors.Rt70Error`."""
    e = float(restitution)
    if not (np.isfinite(e) and 0.0 <= e <= 1.0):
        raise Rt70Error(f"restitution must lie in [0, 1] (0 plastic, 1 elastic), got {e!r}")
    return e


def solve_impact(
    A: np.ndarray,
    B_c: np.ndarray,
    qd_before: np.ndarray,
    restitution: float = 0.0,
    gamma: np.ndarray | None = None,
) -> Impact:
    """Post-impact velocities and impulses of the sudden constraint ``B_c`` (15).

    Parameters
    ----------
    A : numpy.ndarray
        Mass matrix at the impact's configuration, (n, n), positive definite.
    B_c : numpy.ndarray
        Rows of the engaging constraints, (m, n): ``B_c q̇⁺ = −e B_c q̇⁻``.
    qd_before : numpy.ndarray
        ``q̇⁻``, (n,).
    restitution : float
        ``e`` in [0, 1]; 0 (plastic) for brakes and stow pins.
    gamma : numpy.ndarray, optional
        Known impulses Γ of external forces in the coordinates, (n,) (sign: module
        docstring); none by default.

    Returns
    -------
    Impact

    Raises
    ------
    Rt70Error
        If A is not positive definite, e is outside [0, 1], or a shape is wrong.
    """
    A = np.asarray(A, dtype=float)
    n = A.shape[0]
    if A.shape != (n, n):
        raise Rt70Error(f"mass matrix must be square, got shape {A.shape}")
    B_c = np.atleast_2d(np.asarray(B_c, dtype=float))
    if B_c.shape[1] != n:
        raise Rt70Error(f"constraint rows must have {n} columns, got shape {B_c.shape}")
    qd0 = check_vector("qd_before", qd_before, n)
    e = check_restitution(restitution)
    gam = np.zeros(n) if gamma is None else check_vector("gamma", gamma, n)
    jump = solve_kkt(A, B_c, gam, -(1.0 + e) * (B_c @ qd0))  # x = Δq̇ = q̇⁺ − q̇⁻
    return impact_energies(A, B_c, qd0, qd0 + jump.x, jump.lam, jump.rank, e, gam)


def impact_energies(
    A: np.ndarray,
    B_c: np.ndarray,
    qd_before: np.ndarray,
    qd_after: np.ndarray,
    impulses: np.ndarray,
    rank: int,
    restitution: float,
    gamma: np.ndarray | None = None,
) -> Impact:
    """The :class:`Impact` of a solved impact, with its energies from A and B_c.

    For an impact solved elsewhere (the reference side's ``impulseDynamics``) as for
    :func:`solve_impact`'s own.

    Parameters
    ----------
    A : numpy.ndarray
        Mass matrix at the impact's configuration, (n, n).
    B_c : numpy.ndarray
        Rows of the engaged constraints, (m, n).
    qd_before, qd_after : numpy.ndarray
        ``q̇⁻`` and ``q̇⁺``, (n,): m/s or rad/s per coordinate.
    impulses : numpy.ndarray
        ``Λ``, the reactions' impulses, (m,): N·s or N·m·s per row.
    rank : int
        Number of independent constraint rows.
    restitution : float
        ``e`` in [0, 1].
    gamma : numpy.ndarray, optional
        Known impulses Γ of external forces in the coordinates, (n,) (sign: module
        docstring); none by default.
    """
    qd0, qd1 = np.asarray(qd_before, dtype=float), np.asarray(qd_after, dtype=float)
    gam = np.zeros(qd0.size) if gamma is None else np.asarray(gamma, dtype=float)
    lam = np.asarray(impulses, dtype=float)
    lost = qd0 - qd1
    return Impact(
        qd_before=qd0,
        qd_after=qd1,
        impulses=lam,
        rank=int(rank),
        restitution=float(restitution),
        kinetic_before=0.5 * float(qd0 @ A @ qd0),
        kinetic_after=0.5 * float(qd1 @ A @ qd1),
        work_known=0.5 * float(gam @ (qd0 + qd1)),
        energy_lost=-0.5 * float(lam @ (B_c @ (qd0 + qd1))),
        carnot=0.5 * float(lost @ A @ lost),
    )
