"""Stabilisation of constraints: the perturbation equations of companion source 002 (2.2).

A holonomic constraint ``Φ(q) = 0`` differentiated twice, ``B_c q̈ + C = 0``, lets the
numerical solution drift off ``Φ = 0`` (the errors of Φ and Φ̇ grow like t and t² —
nothing pulls them back). Source 002 replaces ``Φ̈ = 0`` by the stable perturbation
equations (2.2)

    Φ̈ + 2ζω Φ̇ + ω² Φ = 0,

so that a deviation decays like a damped oscillator of natural frequency ω and damping
ratio ζ (Baumgarte's method). The acceleration-level constraint becomes

    B_c q̈ = −C − 2ζω B_c q̇ − ω² Φ   (the g of rt70.physics.kkt).

Pinocchio's ``RigidConstraintModel.corrector`` implements the same law with
``Kp = ω²``, ``Kd = 2ζω`` (:func:`Baumgarte.gains`).

Choice of ω and the step. The exact solution of (2.2) decays for any ω > 0, ζ > 0; the
discretised one only if the step h resolves it: for an explicit Runge–Kutta method the
eigenvalues ``−ω(ζ ± √(ζ²−1))`` times h must lie in its stability region (with ζ = 1,
both eigenvalues −ω, on the real axis: ``hω ≤ 2.51`` for RK23, ``≤ 3.31`` for RK45,
``≤ 6.39`` for DOP853 — the real stability intervals of scipy's tableaus); adaptive
solvers keep this by themselves, at the price of steps of a few 1/ω. A ω far
above the mechanism's own frequencies makes the equations stiff for nothing; far below
them the drift is corrected slowly. The default ω = 20 rad/s, ζ = 1 (critically damped,
deviations decay like e^{−20 t}: by 1e-9 in 1 s) suits mechanisms running at a few Hz,
such as the crank–slider at 10 rad/s (docs/loops.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error

#: Default natural frequency ω of the perturbation equations, rad/s.
DEFAULT_OMEGA = 20.0
#: Default damping ratio ζ (critical damping).
DEFAULT_ZETA = 1.0


@dataclass(frozen=True)
class Baumgarte:
    """Gains of the perturbation equations ``Φ̈ + 2ζω Φ̇ + ω² Φ = 0`` (source 002 (2.2)).

    Parameters
    ----------
    omega : float
        Natural frequency ω > 0, rad/s.
    zeta : float
        Damping ratio ζ > 0.
    """

    omega: float = DEFAULT_OMEGA
    zeta: float = DEFAULT_ZETA

    def __post_init__(self) -> None:
        for name in ("omega", "zeta"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and np.isfinite(value) and value > 0.0):
                raise Rt70Error(f"Baumgarte {name} must be a positive finite number, got {value!r}")

    def gains(self) -> tuple[float, float]:
        """``(Kp, Kd) = (ω², 2ζω)``: Pinocchio's ``corrector.Kp``, ``corrector.Kd``."""
        return self.omega**2, 2.0 * self.zeta * self.omega

    def rhs(self, C: np.ndarray, rate: np.ndarray, residual: np.ndarray) -> np.ndarray:
        """``g = −C − Kd Φ̇ − Kp Φ`` of ``B_c q̈ = g`` (``rate = Φ̇ = B_c q̇``).

        Parameters
        ----------
        C : ndarray, shape (m,)
            ``Ḃ_c q̇`` of ``B_c q̈ + C = 0``: the constraints' acceleration at q̈ = 0,
            m/s² or rad/s² per row.
        rate : ndarray, shape (m,)
            ``Φ̇ = B_c q̇``, m/s or rad/s per row.
        residual : ndarray, shape (m,)
            ``Φ(q)``, m or rad per row.
        """
        kp, kd = self.gains()
        return -C - kd * rate - kp * residual


def constraint_rhs(
    C: np.ndarray, rate: np.ndarray, residual: np.ndarray, stabilization: Baumgarte | None
) -> np.ndarray:
    """``g`` of ``B_c q̈ = g``: ``−C`` without stabilisation, (2.2) with it.

    Parameters
    ----------
    C : ndarray, shape (m,)
        ``Ḃ_c q̇`` of ``B_c q̈ + C = 0``, m/s² or rad/s² per row.
    rate : ndarray, shape (m,)
        ``Φ̇ = B_c q̇``, m/s or rad/s per row (unused without stabilisation).
    residual : ndarray, shape (m,)
        ``Φ(q)``, m or rad per row (unused without stabilisation).
    stabilization : Baumgarte or None
        The gains of (2.2); None: the bare ``Φ̈ = 0``.
    """
    if stabilization is None:
        return -np.asarray(C, dtype=float)
    return stabilization.rhs(C, rate, residual)


def consistent_rhs(B_c: np.ndarray, g: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """``g`` projected onto the range of ``B_c`` (least squares; unchanged if it lies in it).

    With dependent rows (a weld closed in 3-D, a planar loop) the rows of Φ and of C
    that depend on each other on the manifold need not do so off it, and (2.2) would
    demand contradicting accelerations; the stabilisation then acts in the least-squares
    sense: ``B_c q̈ = B_c B_c⁺ g``. Exact at Φ = 0 and for independent rows.

    Parameters
    ----------
    B_c : ndarray, shape (m, n)
        The constraint Jacobian ``∂Φ/∂q`` (m rows, n velocity coordinates).
    g : ndarray, shape (m,)
        The right-hand side of ``B_c q̈ = g`` (:func:`constraint_rhs`), m/s² or rad/s²
        per row.
    rtol : float
        Singular values of B_c below ``rtol`` times the largest count as zero
        (``rcond`` of :func:`numpy.linalg.lstsq`).
    """
    if B_c.size == 0:
        return g
    x = np.linalg.lstsq(B_c, g, rcond=rtol)[0]
    return B_c @ x


#: The default gains (ω = 20 rad/s, ζ = 1) as one shared value, for argument defaults.
DEFAULT_STABILIZATION = Baumgarte()
