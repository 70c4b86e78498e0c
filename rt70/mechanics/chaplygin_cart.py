"""The two-wheeled cart of companion source 002 steered around an obstacle by program constraints.

The worked example 002.1.4 in the physically consistent formulation of its
observation 2 (erratum X.3.8): the wheel angles are eliminated by the rolling
constraints (4.1)–(4.2) (Algorithm 002-A on the scene's ``<rt70:no_slip>`` rows, so
``A*`` is (4.8) and ``a`` the corrected (4.12)); the no-lateral-slip constraint (4.3)
is kept with its physical reaction ``λ (sin θ, −cos θ, 0)``; the unknowns are the wheel
torques M1, M2 and that reaction, found by Algorithm 002-B from three equations:

1. (4.3) differentiated, Baumgarte-stabilised: ``ċ = −k_b c``, ``c = ẋ sin θ − ẏ cos θ``;
2. the holonomic program constraint ``f1 = X sin θ − Y cos θ = α0`` (4.10), heading
   along the programmed field, ``α̈0 = −2ζω α̇0 − ω² α0``;
3. the speed program constraint ``f4 = (ẋ cos θ + ẏ sin θ) − (X cos θ + Y sin θ) = α4``,
   ``α̇4 = −κ α4``;

with the programmed field (4.6) whose separatrix is the ellipse (4.5). Gains of 002.3:
ω = 4, ζ = 1, κ = 4, k_b = 10. The state is the scene's full ``q`` (x, y, θ, φ1, φ2)
and the independent velocities ``(ẋ, ẏ, θ̇)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from rt70.errors import Rt70Error
from rt70.mechanics.nonholonomic_scene import constraint_rows, reduced_system
from rt70.model.scene import Scene
from rt70.physics.nonholonomic import perturbation_matrix, program_acceleration, program_multipliers
from rt70.simulation.integrators import budgeted

#: Independent coordinates (x, y, θ) of the cart and the constraints eliminated / kept.
INDEPENDENT = (0, 1, 2)
ROLLING = ("right_rolling", "left_rolling")
LATERAL = ("lateral",)


def check_scene(scene: Scene) -> None:
    """Refuse a scene that is not a cart of this module's kind.

    Raises
    ------
    Rt70Error
        Unless the scene has 5 coordinates and the ``<rt70:no_slip>`` elements
        ``right_rolling``, ``left_rolling`` and ``lateral`` (as urdf/two_wheeled_cart.urdf).
    """
    names = {e.name for e in scene.description.no_slips}
    missing = [n for n in (*ROLLING, *LATERAL) if n not in names]
    if missing or len(scene.coordinate_names) != 5:
        raise Rt70Error(
            f"{scene.path}: not a two-wheeled cart: needs 5 coordinates (x, y, θ, φ1, φ2) and "
            f"<rt70:no_slip> {', '.join((*ROLLING, *LATERAL))}"
            + (f" (missing: {', '.join(missing)})" if missing else "")
        )


def obstacle(x, y):
    """``g = (x − 2)² + 4y² − 1`` (4.5): negative inside the ellipse."""
    return (x - 2.0) ** 2 + 4.0 * y**2 - 1.0


def field(x: float, y: float) -> np.ndarray:
    """The programmed velocity field (4.6), ``(X, Y)`` (coefficients of erratum X.3.2)."""
    g = obstacle(x, y)
    return np.array([-x * g / 3.0 - 4.0 * x * y**2, -2.0 * y * g / 3.0 + x * y * (x - 2.0)])


def field_derivatives(x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """First derivatives ``[[X_x, X_y], [Y_x, Y_y]]`` and second ``[[X_xx, X_xy, X_yy], [Y_…]]``."""
    d1 = np.array(
        [
            [-(3 * x**2 - 8 * x + 3 + 16 * y**2) / 3.0, -32.0 / 3.0 * x * y],
            [2.0 / 3.0 * (x + 1) * y, (x**2 + 2 * x - 6 - 24 * y**2) / 3.0],
        ]
    )
    d2 = np.array(
        [
            [-(6 * x - 8) / 3.0, -32.0 / 3.0 * y, -32.0 / 3.0 * x],
            [2.0 / 3.0 * y, 2.0 / 3.0 * (x + 1), -16.0 * y],
        ]
    )
    return d1, d2


def heading_constraint(q: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """``f1 = X sin θ − Y cos θ`` (4.10), its gradient ``(f11, f12, f13)`` and Hessian H (4.14)."""
    x, y, th = q[:3]
    s, c = np.sin(th), np.cos(th)
    X, Y = field(x, y)
    (Xx, Xy), (Yx, Yy) = (d1 := field_derivatives(x, y)[0])[0], d1[1]
    (Xxx, Xxy, Xyy), (Yxx, Yxy, Yyy) = field_derivatives(x, y)[1]
    f1 = X * s - Y * c
    grad = np.array([Xx * s - Yx * c, Xy * s - Yy * c, X * c + Y * s])
    H = np.array(
        [
            [Xxx * s - Yxx * c, Xxy * s - Yxy * c, Xx * c + Yx * s],
            [Xxy * s - Yxy * c, Xyy * s - Yyy * c, Xy * c + Yy * s],
            [Xx * c + Yx * s, Xy * c + Yy * s, -f1],
        ]
    )
    return f1, grad, H


def speed_constraint(q: np.ndarray, qd: np.ndarray) -> tuple[float, np.ndarray, float]:
    """``f4 = (ẋ cos θ + ẏ sin θ) − (X cos θ + Y sin θ)``, ``∂f4/∂q̇`` and ``(∂f4/∂q) q̇``."""
    x, y, th = q[:3]
    xd, yd, thd = qd[:3]
    s, c = np.sin(th), np.cos(th)
    X, Y = field(x, y)
    (Xx, Xy), (Yx, Yy) = field_derivatives(x, y)[0]
    f4 = xd * c + yd * s - (X * c + Y * s)
    Xd, Yd = Xx * xd + Xy * yd, Yx * xd + Yy * yd
    w = (-xd * s + yd * c) * thd - (Xd * c + Yd * s + (-X * s + Y * c) * thd)
    return f4, np.array([c, s, 0.0]), w


@dataclass(frozen=True)
class Gains:
    """Perturbation gains of 002.3: heading ω, ζ; speed κ; Baumgarte k_b of (4.3)."""

    omega: float = 4.0
    zeta: float = 1.0
    kappa: float = 4.0
    baumgarte: float = 10.0


@dataclass(frozen=True)
class ServoForces:
    """Wheel torques M1, M2 (N·m), lateral reaction λ (N) and the accelerations q̈_ind."""

    M1: float
    M2: float
    lateral: float
    qdd: np.ndarray
    residuals: np.ndarray  # (c, f1, ḟ1, f4): the constraint violations at this state
    qd: np.ndarray  # the full q̇ = 𝔅 q̇_ind (the wheels' rates included)


def servo(
    scene: Scene, q: np.ndarray, qd_ind: np.ndarray, gains: Gains = Gains(), side: str = "reference"
) -> ServoForces:
    """The servo forces of Algorithm 002-B at the state ``(q, q̇_ind)`` on one side.

    ``D = [𝔅ᵀ e_φ1, 𝔅ᵀ e_φ2, (A_lat 𝔅)ᵀ]``: the wheel torques act on the wheel
    coordinates, projected by the rolling constraints; the lateral reaction along the
    reduced row of (4.3).

    Parameters
    ----------
    scene : Scene
        The cart (:func:`check_scene`: urdf/two_wheeled_cart.urdf).
    q : numpy.ndarray, shape (5,)
        ``(x, y, θ, φ1, φ2)``: position m, heading and wheel angles rad.
    qd_ind : numpy.ndarray, shape (3,)
        The independent velocities ``(ẋ, ẏ, θ̇)``, m/s and rad/s.
    gains : Gains
        The perturbation gains ω, ζ, κ and the Baumgarte k_b of (4.3).
    side : {"reference", "textbook"}
        Whose constraint rows and reduced dynamics.
    """
    q = np.asarray(q, dtype=float)
    qd_ind = np.asarray(qd_ind, dtype=float)
    proj, red = reduced_system(scene, side, q, qd_ind, INDEPENDENT, names=ROLLING)
    qd_full = proj.basis @ qd_ind
    A_lat, A_lat_dot = constraint_rows(scene, side, q, qd_full, LATERAL)
    rate = proj.rate(*constraint_rows(scene, side, q, qd_full, ROLLING))
    row = A_lat[0] @ proj.basis
    c = row @ qd_ind
    f1, grad, H = heading_constraint(q)
    f4, V4, w4 = speed_constraint(q, qd_ind)
    # rows: f1 (holonomic), then c and f4 (first order), as perturbation_matrix orders them
    V = np.vstack([grad, row, V4])
    w = np.array([qd_ind @ H @ qd_ind, A_lat[0] @ rate + A_lat_dot[0], w4])
    P = perturbation_matrix(1, 2, gains.omega, gains.zeta, (gains.baumgarte, gains.kappa))
    beta = P @ np.array([f1, grad @ qd_ind, c, f4])
    n = q.size
    D = np.column_stack([proj.basis.T @ np.eye(n)[3], proj.basis.T @ np.eye(n)[4], row])
    lam = program_multipliers(red.A_star, red.a, red.Q_star, V, w, beta, D)  # (M1, M2, λ)
    qdd = program_acceleration(red.A_star, red.a, red.Q_star, D, lam)
    residuals = np.array([c, f1, grad @ qd_ind, f4])
    return ServoForces(lam[0], lam[1], lam[2], qdd, residuals, qd_full)


def on_manifold_start(x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """The start ``(q, q̇_ind)`` on the program manifold at (x, y).

    ``θ = atan2(Y, X)``, ``(ẋ, ẏ) = (X, Y)``, ``θ̇`` such that ``ḟ1 = 0``; wheel angles
    zero.
    """
    X, Y = field(x, y)
    if np.hypot(X, Y) < 1e-9:
        raise Rt70Error(
            f"start ({x:g}, {y:g}) is an equilibrium of the programmed field (4.6): no "
            "heading is programmed there"
        )
    q = np.array([x, y, np.arctan2(Y, X), 0.0, 0.0])
    _, grad, _ = heading_constraint(q)
    thd = -(grad[0] * X + grad[1] * Y) / grad[2]
    return q, np.array([X, Y, thd])


def simulate(
    scene: Scene,
    q0: np.ndarray,
    qd0_ind: np.ndarray,
    times: np.ndarray,
    gains: Gains = Gains(),
    side: str = "reference",
    rtol: float = 1e-10,
    atol: float = 1e-12,
    stop_radius: float = 0.0,
):
    """Integrate the controlled cart (DOP853); returns scipy's solution at ``times``.

    The state is ``[q (5), q̇_ind (3)]``; ``q̇ = 𝔅 q̇_ind`` turns the wheels. With
    ``stop_radius`` > 0 the run stops where M comes that close to the target (the
    origin, where the programmed speed vanishes and S becomes singular).

    Parameters
    ----------
    scene : Scene
        The cart (:func:`check_scene`).
    q0 : numpy.ndarray, shape (5,)
        Initial ``(x, y, θ, φ1, φ2)``, m and rad (:func:`on_manifold_start`).
    qd0_ind : numpy.ndarray, shape (3,)
        Initial ``(ẋ, ẏ, θ̇)``, m/s and rad/s.
    times : numpy.ndarray
        Increasing output times from 0, s; the run ends at the last.
    gains : Gains
        The perturbation gains (:func:`servo`).
    side : {"reference", "textbook"}
        Whose constraint rows and reduced dynamics.
    rtol, atol : float
        DOP853's relative and absolute tolerances.
    stop_radius : float
        Distance of the cart's point M from the origin at which the run stops, m
        (0: it does not stop early).
    """
    n = len(q0)

    def near(_t, s):
        return np.hypot(s[0], s[1]) - stop_radius

    near.terminal = True

    def rhs(_t, s):
        forces = servo(scene, s[:n], s[n:], gains, side)
        return np.concatenate([forces.qd, forces.qdd])

    times = np.asarray(times, dtype=float)
    return solve_ivp(
        budgeted(rhs, float(times[-1])),
        (0.0, float(times[-1])),
        np.concatenate([q0, qd0_ind]),
        method="DOP853",
        t_eval=times,
        rtol=rtol,
        atol=atol,
        events=near if stop_radius > 0.0 else None,
    )
