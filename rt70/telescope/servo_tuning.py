"""How the scenarios' servos are built: drive parameters, gains, presets, tolerances, holding.

One job: say how a scene's servos are built from what it declares
(:mod:`rt70.telescope.axis_servos`: each axis's ``<rt70:servo>`` and the ``<rt70:drive>``
it closes around): the coordinate drive factory (:func:`servo_drives`), the state a servo
starts in when it already holds the structure, the integration tolerances of its states,
and whether the drives can hold the structure at a pointing at all. The RT-70 table's
own helpers (:func:`drive_parameters`, :func:`axis_gains`, on
:mod:`rt70.scenes.rt70_drives`) serve the RT-70's analyses.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.antiwindup import BackCalculationServo
from rt70.control.geartrains import equivalent_drive
from rt70.control.servo import CascadeGains, ServoDrive, cascade_gains
from rt70.linear.linearize import equilibrium, static_force
from rt70.model.antenna import pointing
from rt70.model.scene import Scene
from rt70.scenes.rt70_drives import AxisDrive
from rt70.simulation.states import StateComponent
from rt70.telescope.axis_servos import Tuning, axis_servos, servo_gains, servo_parameters
from rt70.telescope.drive_equilibrium import EQUILIBRIUM_TOL
from rt70.telescope.servo_design import declared_tuning

#: Builds the drive components: (scene, q0, held torques by coordinate, references in
#: coordinate radians by coordinate) -> components.
DriveFactory = Callable[
    [Scene, np.ndarray, dict[str, float], dict[str, Callable[[float], float]]],
    list[StateComponent],
]


def drive_parameters(axis: AxisDrive) -> DriveParameters:
    """One :class:`DcDrive`'s parameters for an RT-70 table axis's motors, lumped.

    The axis's ``n`` identical motors turn the same gear at the same speed; taken with
    their armatures in series (one current), they are one motor with ``n`` times the
    inductance, resistance, torque and back-EMF constants, rotor inertia and viscous
    friction (the time constants L_a/R_a and J_m R_a/(c_m c_e) are unchanged). The
    counter-torque between the two gear trains is not modelled here (a factory with the
    gear trains takes its place). ``J_l`` is the table's reference inertia of the axis.
    """
    p = axis.motor_parameters(axis.reference_inertia)
    return equivalent_drive(p, axis.motors_per_axis)


def axis_gains(axis: AxisDrive, position_hz: float, ratio: float) -> CascadeGains:
    """The cascade of one axis with the table's limits (:func:`rt70.control.servo.cascade_gains`).

    Current reference clamped to the peak torque (2 I_n per motor), axis rate to the
    table's rate limit, armature voltage to the motors' rated voltage (n U_n lumped).

    Parameters
    ----------
    axis : AxisDrive
        The RT-70 table's axis.
    position_hz : float
        Bandwidth of the position loop, Hz.
    ratio : float
        Ratio of the position loop's proportional to integral corner.
    """
    p = drive_parameters(axis)
    return cascade_gains(
        p,
        axis.reference_inertia,
        position_hz=position_hz,
        ratio=ratio,
        current_limit=axis.motor.peak_torque / axis.motor.torque_constant,
        rate_limit=axis.servo.rate_limit,
        voltage_limit=axis.motors_per_axis * axis.motor.rated_voltage,
    )


def preset_servo_state(p: DriveParameters, gains: CascadeGains, angle: float, torque: float):
    """States of a :class:`ServoDrive` holding ``torque`` at ``angle`` at rest, loops settled.

    ``[I, α_m, ω_m]`` of :meth:`DcDrive.holding`, the position integral 0 (no rate
    asked), the rate integral giving the holding current ``I = K_i,v ∫e_v`` and the
    current integral the voltage ``R_a I = K_i,i ∫e_i``.

    Parameters
    ----------
    p : DriveParameters
        The drive's parameters.
    gains : CascadeGains
        Its cascade's gains.
    angle : float
        The axis angle held, rad.
    torque : float
        The torque the drive supplies on the axis, N·m.
    """
    hold = ServoDrive.holding(p, angle, torque)
    return np.concatenate([hold, [0.0, hold[0] / gains.ki_v, p.R_a * hold[0] / gains.ki_i]])


def servo_tolerances(p: DriveParameters, axis_atol: float = 1e-9) -> np.ndarray:
    """Absolute tolerances of a ServoDrive's states matching ``axis_atol`` on its axis.

    Motor-side angles and speeds (and the rate integral) are ``i_r`` times the axis's,
    so their tolerance is ``i_r · axis_atol``; currents (and the current integral) get
    ``axis_atol · C_r / (c_m i_r)`` — the current whose torque twists the reducer by
    ``axis_atol``. The drive's default 1e-9 on every state asks the motor angle for
    1e-14 rad on the axis, below the rounding of the axis angle: at the zenith, where
    the motor angle is near zero and the relative tolerance does not help, BDF's step
    collapsed ("Required step size is less than spacing between numbers", 60 s hold at
    90°).
    """
    motor = p.i_r * axis_atol
    amp = axis_atol * p.C_r / (p.c_m * p.i_r)
    return np.array([amp, motor, motor, axis_atol, motor, amp])


def servo_drives(tuning: Tuning | None = None) -> DriveFactory:
    """The coordinate drives: one servo per declared axis, its torque on the axis coordinate.

    Each axis's ``<rt70:servo>`` names its ``<rt70:drive>``: the drive's motor and
    reducer (:func:`rt70.telescope.axis_servos.servo_parameters`) push on the joint's
    coordinate itself, not through a gear sector the element may have (the scene's own
    drive model is :class:`rt70.telescope.scene_servo.SceneServoFactory`).

    Parameters
    ----------
    tuning : dict, optional
        ``{"azimuth": (position_hz, ratio), ...}`` overriding the scene's
        (:func:`rt70.telescope.servo_design.declared_tuning`).
    """

    def build(scene, q0, torques, references):
        names = scene.coordinate_names
        design = {**declared_tuning(scene), **(tuning or {})}
        out: list[StateComponent] = []
        for name, declared in axis_servos(scene).items():
            coordinate = declared.axis.joint
            p = servo_parameters(scene, declared)
            gains = servo_gains(p, declared.servo, *design[name])
            k = names.index(coordinate)
            initial = preset_servo_state(p, gains, q0[k], torques[coordinate])
            ref = references[coordinate]
            atol = servo_tolerances(p)
            out.append(BackCalculationServo(name, names, coordinate, p, gains, ref, initial, atol))
        return out

    return build


def holding_excess(scene: Scene, elevation_deg: float, azimuth_deg: float = 0.0) -> str | None:
    """Why the drives cannot hold ``scene`` at a pointing, or None if they can.

    The static torque the drives must supply on each axis at the equilibrium of the
    pointing, against the servo's declared nominal (continuous) torque
    (``<rt70:servo nominal_torque>``). The RT-70 listing as printed would need 2.66×
    its drives' on elevation at the horizon (docs/rt70-errata.md item 12).

    Parameters
    ----------
    scene : Scene
        A scene whose mount's axes declare their servos.
    elevation_deg : float
        The elevation, degrees.
    azimuth_deg : float
        The azimuth, degrees.
    """
    servos = axis_servos(scene)
    held = pointing(scene, elevation_deg, azimuth_deg)
    q0 = equilibrium(scene, held, tol=EQUILIBRIUM_TOL)
    Q0 = static_force(scene, q0)
    names = scene.coordinate_names
    for name, declared in servos.items():
        torque = abs(float(Q0[names.index(declared.axis.joint)]))
        nominal = declared.servo.nominal_torque
        if torque > nominal:
            return (
                f"gravity torque {torque:.3g} N·m on {name} at elevation {elevation_deg:g}° "
                f"exceeds the drive's nominal {nominal:.3g} N·m"
            )
    return None
