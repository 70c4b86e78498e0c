"""The antenna industry's servo cascade around one DC drive: current, rate and position loops.

Each axis of a large antenna is closed in three nested loops (antenna-servo.md; Gawronski,
*Modeling and Control of Antennas and Telescopes*, 2008, ch. 8): an inner current loop
(PI) that makes the motor a torque source, a rate loop (PI) on the motor speed, and an
outer position loop (PI) on the axis angle, each some five times slower than the one
inside it, with the rate reference clamped to the axis' top speed and the current
reference to the motor's peak current. An integrator stops integrating while its loop's
output is clamped (anti-windup by conditional integration).

:class:`ServoDrive` is a :class:`rt70.control.drives.DcDrive` whose armature voltage comes from
this cascade; the three integrators are states of its own, after the drive's
``[I, α_m, ω_m]``. :func:`cascade_gains` places the loops by pole–zero cancellation on
the rigid-axis model (current loop: ``K_p = L_a ω_c``, ``K_i = R_a ω_c``; rate loop on
the total inertia seen by the motor ``J = J_m + J_l / i_r²``; position loop on the
closed rate loop), from the three bandwidths; each PI's zero sits ``ratio`` below its
crossover. The rigid-axis design assumes the structure's first resonance (with the
reducer) lies above the rate loop: below it, the loops must be designed on the plant
(:mod:`rt70.linear.plant`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.drives import DcDrive
from rt70.errors import Rt70Error
from rt70.simulation.states import MechanicsForces


@dataclass(frozen=True)
class CascadeGains:
    """PI gains of the current, rate and position loops and their limits.

    Attributes
    ----------
    kp_i, ki_i : float
        Current loop: V/A, V/(A·s).
    kp_v, ki_v : float
        Rate loop on the motor speed: A/(rad/s), A/rad.
    kp_p, ki_p : float
        Position loop on the axis angle: (rad/s of axis rate)/rad, 1/s² likewise.
    current_limit : float
        Largest current reference, A.
    rate_limit : float
        Largest axis-rate reference, rad/s.
    voltage_limit : float
        Largest armature voltage, V.
    """

    kp_i: float
    ki_i: float
    kp_v: float
    ki_v: float
    kp_p: float
    ki_p: float
    current_limit: float
    rate_limit: float
    voltage_limit: float


def cascade_gains(
    p: DriveParameters,
    load_inertia: float,
    position_hz: float = 1.0,
    ratio: float = 5.0,
    current_limit: float = np.inf,
    rate_limit: float = np.inf,
    voltage_limit: float = np.inf,
) -> CascadeGains:
    """Gains of the cascade from the position-loop bandwidth, each loop ``ratio`` × faster.

    Parameters
    ----------
    p : DriveParameters
        The drive.
    load_inertia : float
        Inertia of the axis, kg·m² (the rigid structure about it).
    position_hz : float
        Position-loop bandwidth, Hz (antenna practice: about 1 Hz for a 70-m dish).
    ratio : float
        Bandwidth ratio between a loop and the one inside it.
    current_limit, rate_limit, voltage_limit : float
        Clamps of the current reference (A), the axis-rate reference (rad/s) and the
        armature voltage (V).
    """
    if not (position_hz > 0 and ratio > 1):
        raise Rt70Error("cascade_gains: position_hz must be positive and ratio above 1")
    w_p = 2 * np.pi * position_hz
    w_v, w_c = ratio * w_p, ratio**2 * w_p
    J = p.J_m + load_inertia / p.i_r**2  # motor-side inertia of the rigid axis
    kp_v = J * w_v / p.c_m
    return CascadeGains(
        kp_i=p.L_a * w_c,
        ki_i=p.R_a * w_c,
        kp_v=kp_v,
        ki_v=kp_v * w_v / ratio,
        kp_p=w_p,
        ki_p=w_p * w_p / ratio,
        current_limit=current_limit,
        rate_limit=rate_limit,
        voltage_limit=voltage_limit,
    )


def clamped_pi(kp: float, ki: float, error: float, integral: float, limit: float):
    """A loop's PI output ``K_p e + K_i ∫e`` clamped to ±limit, and whether it was clamped.

    Parameters
    ----------
    kp : float
        Proportional gain K_p (output unit per error unit).
    ki : float
        Integral gain K_i (output unit per error unit and second).
    error : float
        The loop's error e.
    integral : float
        ``∫e dt``, the loop's integrator state.
    limit : float
        The clamp: the output is kept within ±limit (``numpy.inf``: none).

    Returns
    -------
    (float, bool)
        The clamped output and the flag that stops its integrator (anti-windup by
        conditional integration).
    """
    out = kp * error + ki * integral
    return float(np.clip(out, -limit, limit)), abs(out) > limit


class ServoDrive(DcDrive):
    """A DC drive closed by the current–rate–position cascade on its coordinate.

    The position loop reads the drive's angle (``coupling.angle``: the coordinate, or a
    scene drive's θ_d; pass ``coupling=`` as to :class:`rt70.control.drives.DcDrive`), or
    ``encoder(q)`` if given: e.g. the axis coordinate while the reducer acts on a gear
    sector's mesh angle, as a telescope's axis encoder reads the axis, not the mesh.
    States: the drive's ``[I, α_m, ω_m]`` then the integrals of the position, rate and
    current errors. The position reference is ``reference(t)`` (rad), e.g. a step or a
    sidereal ramp.
    """

    STATES = DcDrive.STATES + ("int_position", "int_rate", "int_current")
    STATE_UNITS: ClassVar[dict[str, str]] = {
        **DcDrive.STATE_UNITS,
        "int_position": "rad·s",
        "int_rate": "rad",
        "int_current": "A·s",
    }

    def __init__(
        self,
        name: str,
        coordinates: list[str],
        coordinate: str,
        parameters: DriveParameters,
        gains: CascadeGains,
        reference,
        initial=None,
        atol=None,
        *,
        coupling=None,
        encoder=None,
    ) -> None:
        # the armature voltage comes from the cascade (derivative), not from a voltage law
        super().__init__(
            name, coordinates, coordinate, parameters, 0.0, initial, atol, coupling=coupling
        )
        self.g = gains
        self.reference = reference
        #: The angle the position loop reads, ``encoder(q)`` (rad).
        self.encoder = self.coupling.angle if encoder is None else encoder

    def _loops(self, t: float, q: np.ndarray, s: np.ndarray):
        """References and clamps of the three loops: (errors, saturated flags, voltage)."""
        g, p = self.g, self.p
        e_p = float(self.reference(t)) - self.encoder(q)
        rate_ref, sat_p = clamped_pi(g.kp_p, g.ki_p, e_p, s[3], g.rate_limit)
        e_v = p.i_r * rate_ref - s[2]  # on the motor speed
        current_ref, sat_v = clamped_pi(g.kp_v, g.ki_v, e_v, s[4], g.current_limit)
        e_i = current_ref - s[0]
        u, sat_i = clamped_pi(g.kp_i, g.ki_i, e_i, s[5], g.voltage_limit)
        return (e_p, e_v, e_i), (sat_p, sat_v, sat_i), u

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """The drive's ``[İ, α̇_m, ω̇_m]`` under the cascade's voltage, then the integrators.

        Parameters
        ----------
        t : float
            Time, s (the position reference is taken at t).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray, shape (6,)
            ``[I, α_m, ω_m]`` (A, rad, rad/s), then the integrals of the position (rad·s),
            rate (rad, on the motor speed) and current (A·s) errors.
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        errors, saturated, u = self._loops(t, q, s)
        drive = self.motor_rates(q, qd, s[:3], u)
        # conditional integration: an integrator holds while its loop's output is clamped
        integrals = [0.0 if sat else e for e, sat in zip(errors, saturated, strict=True)]
        return np.concatenate([drive, integrals])

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The reducer torque on the driven coordinate (from the drive's own states).

        Parameters
        ----------
        t : float
            Time, s (unused).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray, shape (6,)
            ``[I, α_m, ω_m]`` (A, rad, rad/s), then the integrals of the position (rad·s),
            rate (rad, on the motor speed) and current (A·s) errors.
        """
        return super().force(t, q, qd, s[:3])
