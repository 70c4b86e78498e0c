"""Steady wind on exposed bodies: the flow, the book's wind frame, coefficient tables, Wrenches.

Shared below both sides, as :mod:`rt70.physics.loads`: each side hands in a link's pose from its
own kinematics and turns the :class:`~rt70.physics.loads.Wrench` returned here into a
generalised force (``Q = S W`` on the textbook side, ``Q = Jᵀ f`` on the reference
side; formalism §4.4, (4.132)–(4.136)). Imports nothing of rt70 but the coefficient
tables, the errors and the Wrench (tests/test_import_rules.py, ``SHARED``).

Conventions (docs/wind.md)
--------------------------
**Direction.** :class:`WindCondition` ``direction_deg`` is a *telescope azimuth* (the
convention of ``--azimuth``, :func:`rt70.scenes.rt70_optics.pointing_source`): the dish
at azimuth A looks toward the horizontal direction ``h(A) = [cos(A − 90°), sin(A − 90°),
0]`` (:func:`horizontal_direction`), and the wind blows FROM ``h(direction)``: the flow
velocity in ground axes is ``v0 = −speed · h(direction)``. ``direction == azimuth`` is a
front wind, blowing into the dish's face.

**Wind frame (4.132)–(4.133).** The flow in body i's axes is ``v_i = c_0iᵀ v0``; its
slip ``β = −arcsin(v_x / |v|)`` and attack ``α = arctan2(v_z, v_y)`` define the wind
frame ``c_iv = R_x(α) R_z(β)`` whose y axis is the flow: ``c_iv [0, |v|, 0]ᵀ = v_i``
(:func:`wind_frame`).

**Coefficients.** A body is axisymmetric about its unit axis ``a`` (for a dish its
boresight, out of the concave face). ``u`` is the flow's unit vector and θ the angle
between ``a`` and ``−u`` (θ = 0: the flow hits the concave face head-on). With the
dynamic pressure ``q = ½ ρ |v|²``, the reference area S and length l,

    F = q S [ −C_A(θ) a + (C_N(θ)/sin θ) (u − (u·a) a) ],
    M = q S l (C_M(θ)/sin θ) (u × a),

F acting at the element's reference point, M a free moment. C_A > 0 pushes the body
back along −a (a dish face-on), C_N > 0 pushes along the flow's cross component, C_M > 0
turns the face toward the wind. In the wind frame this is the book's
``½ ρ |v|² S l [c]`` rotated back (4.134)–(4.136), with the coefficients as functions
of θ only (a body of revolution; no rate terms: a steady flow).

**Tables.** C_A, C_N and C_M come from a
:class:`~rt70.physics.coefficient_tables.CoefficientTable` (its module reads, checks and
evaluates them; the built-in ``dish`` and ``cylinder``).

The structure's own velocity is neglected against the wind's (no aerodynamic damping),
and so is shielding of one body by another (conservative).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from rt70.physics.coefficient_tables import CoefficientTable, WindError
from rt70.physics.loads import Pose, Wrench

#: ISA sea-level air density, kg/m³ (the default of ``<rt70:air density>``).
DEFAULT_AIR_DENSITY = 1.225


def horizontal_direction(azimuth_deg: float) -> np.ndarray:
    """``h(A) = [cos(A − 90°), sin(A − 90°), 0]``: where the dish at azimuth A looks."""
    a = math.radians(azimuth_deg - 90.0)
    return np.array([math.cos(a), math.sin(a), 0.0])


def _finite(name: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise WindError(f"wind {name} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise WindError(f"wind {name} must be finite, got {value!r}")
    return x


@dataclass(frozen=True)
class WindCondition:
    """A steady, uniform wind.

    Parameters
    ----------
    speed : float
        Wind speed ``|v0|``, m/s (≥ 0).
    direction_deg : float
        The telescope azimuth the wind blows FROM, degrees: the flow velocity is
        ``v0 = −speed · h(direction_deg)`` (:func:`horizontal_direction`), so
        ``direction_deg`` equal to the pointing's azimuth is a front wind into the dish.
    density : float or None
        Air density ρ, kg/m³; None takes the scene's ``<rt70:air density>``.

    Raises
    ------
    WindError
        If a value is not finite, the speed negative or the density not positive.
    """

    speed: float
    direction_deg: float
    density: float | None = None

    def __post_init__(self) -> None:
        speed = _finite("speed", self.speed)
        if speed < 0.0:
            raise WindError(f"wind speed must be non-negative, got {speed:g} m/s")
        object.__setattr__(self, "speed", speed)
        object.__setattr__(self, "direction_deg", _finite("direction", self.direction_deg))
        if self.density is not None:
            rho = _finite("density", self.density)
            if rho <= 0.0:
                raise WindError(f"air density must be positive, got {rho:g} kg/m³")
            object.__setattr__(self, "density", rho)

    def velocity(self) -> np.ndarray:
        """Flow velocity v0 in ground axes, m/s: ``−speed · h(direction_deg)``."""
        return -self.speed * horizontal_direction(self.direction_deg)

    def air_density(self, default: float) -> float:
        """ρ of this condition, or ``default`` (the scene's) when it has none."""
        return default if self.density is None else self.density


def wind_frame(v_body: np.ndarray) -> tuple[float, float, np.ndarray]:
    """``(α, β, c_iv)`` of a flow velocity in body axes (4.132)–(4.133).

    ``β = −arcsin(v_x/|v|)``, ``α = arctan2(v_z, v_y)`` and ``c_iv = R_x(α) R_z(β)``:
    ``c_iv [0, |v|, 0]ᵀ = v_body`` (the wind frame's y axis is the flow).

    Raises
    ------
    WindError
        If the velocity is zero (no flow, no frame).
    """
    v = np.asarray(v_body, dtype=float)
    speed = float(np.linalg.norm(v))
    if speed == 0.0:
        raise WindError("no wind frame for a zero flow velocity")
    beta = -math.asin(max(-1.0, min(1.0, v[0] / speed)))
    alpha = math.atan2(v[2], v[1])
    ca, sa, cb, sb = math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    rz = np.array([[cb, -sb, 0.0], [sb, cb, 0.0], [0.0, 0.0, 1.0]])
    return alpha, beta, rx @ rz


class WindSurface(Protocol):
    """What :func:`wind_wrench` reads of a ``<rt70:wind>`` (:class:`rt70.urdf.Wind`)."""

    link: str
    xyz: np.ndarray
    axis: np.ndarray
    area: float
    length: float
    table: CoefficientTable


def body_load(
    table: CoefficientTable, axis: np.ndarray, flow: np.ndarray, force_scale: float, length: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(F, M)`` of the axisymmetric model, in the axes ``axis`` and ``flow`` are given in.

    ``F = qS[−C_A a + (C_N/sinθ)(u − (u·a)a)]``, ``M = qSl (C_M/sinθ) (u × a)`` with
    ``cos θ = −u·a``, ``sin θ = |u × a|`` (θ the angle of attack, 0 when the flow
    meets the body head on).

    Parameters
    ----------
    table : CoefficientTable
        ``C_A(θ)``, ``C_N(θ)``, ``C_M(θ)`` of the body's shape.
    axis : ndarray, shape (3,)
        The unit body (symmetry) axis a.
    flow : ndarray, shape (3,)
        The unit flow direction u, in the same axes as ``axis``.
    force_scale : float
        ``q S``, N: the dynamic pressure ``½ ρ |v|²`` (Pa) times the reference area (m²).
    length : float
        The reference length l of the moment, m.

    Returns
    -------
    tuple of ndarray, shape (3,)
        The force F (N) and the free moment M (N·m), in those axes.
    """
    a, u = axis, flow
    (a0, a1, a2), (u0, u1, u2) = a.tolist(), u.tolist()
    cross = np.array([u1 * a2 - u2 * a1, u2 * a0 - u0 * a2, u0 * a1 - u1 * a0])  # u × a
    cos_theta = -(u0 * a0 + u1 * a1 + u2 * a2)
    sin_theta = math.sqrt(float(cross @ cross))
    c_a, n_ratio, m_ratio = table.ratios(cos_theta, sin_theta)
    force = force_scale * (-c_a * a + n_ratio * (u + cos_theta * a))
    torque = (force_scale * length * m_ratio) * cross
    return force, torque


def wind_wrench(
    surface: WindSurface, pose: Pose, condition: WindCondition, density: float
) -> Wrench:
    """The wind's Wrench on one exposed body at the link pose ``(R, p)`` (4.132)–(4.136).

    The flow in body axes ``v_i = Rᵀ v0`` (4.132) gives ``u`` and ``q = ½ ρ |v|²``
    (ρ the condition's, else ``density``); :func:`body_load` gives F and M in body axes,
    turned back to ground axes by R. F acts at ``surface.xyz``; M is a free moment. A
    uniform flow does not depend on the origin p (kept for a sheared profile).

    Parameters
    ----------
    surface : WindSurface
        The exposed body (a ``<rt70:wind>``): its link, reference point ``xyz`` (link
        frame, m), unit axis, area (m²), length (m) and coefficient table.
    pose : Pose
        The link's pose in ground axes: rotation R, shape (3, 3), and origin p,
        shape (3,), m.
    condition : WindCondition
        The steady wind: speed (m/s), direction and, optionally, the air density.
    density : float
        The scene's air density ρ, kg/m³, used when ``condition`` gives none.

    Returns
    -------
    Wrench
        On ``surface.link`` at ``surface.xyz``: force (N) and moment (N·m) in ground
        axes (zero in still air).
    """
    R = np.asarray(pose[0], dtype=float)
    load = wind_load(surface, R, condition.velocity(), condition.air_density(density))
    if load is None:
        return Wrench(surface.link, tuple(surface.xyz))
    return Wrench(surface.link, tuple(surface.xyz), tuple(load[0]), tuple(load[1]))


def wind_load(
    surface: WindSurface, R: np.ndarray, velocity: np.ndarray, density: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """The force F (N) and moment M (N·m) of :func:`wind_wrench`, ground axes; None in still air.

    The arrays without the :class:`~rt70.physics.loads.Wrench` around them, from the
    flow's velocity and density: what a simulation's wind force sums at every evaluation
    (:func:`rt70.reference.wind.wind_force_function`).

    Parameters
    ----------
    surface : WindSurface
        The exposed body, as for :func:`wind_wrench`.
    R : numpy.ndarray, shape (3, 3)
        The link's rotation in ground axes.
    velocity : numpy.ndarray, shape (3,)
        The flow velocity v0 in ground axes, m/s (:meth:`WindCondition.velocity`).
    density : float
        The air density ρ, kg/m³.
    """
    v = R.T @ velocity
    speed = math.sqrt(float(v @ v))
    if speed == 0.0:
        return None
    force_scale = 0.5 * density * speed * speed * surface.area
    force, torque = body_load(
        surface.table, np.asarray(surface.axis, dtype=float), v / speed, force_scale, surface.length
    )
    return R @ force, R @ torque
