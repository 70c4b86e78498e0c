"""The servo each pointing axis declares (``<rt70:servo>``), resolved against its scene.

One job: read what the scene's mount says of its servos — which ``<rt70:drive>`` each
axis's cascade closes around, its limits, its design bandwidth and ratio, the inertia it
is designed for, its dry friction — and turn it into what the servo code takes: the
drive's :class:`~rt70.bondgraph.parameters.DriveParameters` and the cascade's
:class:`~rt70.control.servo.CascadeGains`. A scene that declares no servo on an axis is
refused with one line naming the element (docs/urdf-extensions.md, ``<rt70:servo>``);
nothing here knows any telescope.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.drives import drive_parameters
from rt70.control.servo import CascadeGains, cascade_gains
from rt70.errors import SceneError
from rt70.model.antenna import mount_of
from rt70.model.scene import Scene
from rt70.urdf.description import Drive
from rt70.urdf.mount_record import AxisServo, MountAxis

#: Position-loop design of each axis: ``{axis name: (bandwidth Hz, loop ratio)}``.
Tuning = dict[str, tuple[float, float]]


@dataclass(frozen=True)
class DeclaredServo:
    """One axis's servo as declared: the mount axis, its ``<rt70:servo>`` and drive."""

    axis: MountAxis
    servo: AxisServo
    drive: Drive


def axis_servos(scene: Scene) -> dict[str, DeclaredServo]:
    """Every axis's :class:`DeclaredServo`, by axis name (the mount's order).

    Raises
    ------
    SceneError
        If the scene declares no mount, or an axis of it has no ``<rt70:servo>``.
    """
    drives = {d.name: d for d in scene.description.drives}
    out = {}
    for axis in mount_of(scene).axes:
        if axis.servo is None:
            raise SceneError(
                f"{scene.name}: axis '{axis.name}' declares no servo: add an <rt70:servo> to "
                f"its <rt70:axis> (docs: 'rt70 URDF extensions', docs/urdf-extensions.md)"
            )
        out[axis.name] = DeclaredServo(axis, axis.servo, drives[axis.servo.drive])
    return out


def has_servos(scene: Scene) -> bool:
    """Whether the scene has a mount whose every axis declares a servo."""
    mount = scene.description.mount
    return mount is not None and all(a.servo is not None for a in mount.axes)


def design_inertia(scene: Scene, declared: DeclaredServo) -> float:
    """The inertia an axis's loops are designed for, kg·m².

    The servo's ``reference_inertia`` if it gives one; otherwise the rigid inertia about
    the axis — the mass matrix's diagonal entry of its coordinate — with the axes at the
    middle of their ranges (azimuth 0 if in range) and every other coordinate zero.
    """
    if declared.servo.reference_inertia is not None:
        return declared.servo.reference_inertia
    names = scene.coordinate_names
    q = np.zeros(len(names))
    for axis in mount_of(scene).axes:
        middle = 0.0 if axis.lower <= 0.0 <= axis.upper else 0.5 * (axis.lower + axis.upper)
        if axis.name == "elevation":
            middle = 0.5 * (axis.lower + axis.upper)
        q[names.index(axis.joint)] = axis.coordinate(middle)
    from rt70.model.sides import side_of

    side = side_of(scene, "textbook")
    M = side.dynamics.mass_matrix(side.model, side.data, q)
    return float(M[names.index(declared.axis.joint), names.index(declared.axis.joint)])


def servo_parameters(scene: Scene, declared: DeclaredServo) -> DriveParameters:
    """The drive's parameters with the design inertia as its load (:func:`design_inertia`)."""
    return drive_parameters(declared.drive, design_inertia(scene, declared))


def drive_servos(scene: Scene, tuning: Tuning) -> dict[str, tuple[DriveParameters, CascadeGains]]:
    """Each servo drive's parameters and cascade gains at a full ``tuning``, by drive name.

    What :func:`rt70.control.scene_loop.closed_loop` takes; ``tuning`` gives every axis
    (:func:`rt70.telescope.scene_servo.scene_servos` fills it from the scene's design).
    """
    out = {}
    for name, declared in axis_servos(scene).items():
        p = servo_parameters(scene, declared)
        out[declared.drive.name] = (p, servo_gains(p, declared.servo, *tuning[name]))
    return out


def servo_gains(
    p: DriveParameters, servo: AxisServo, position_hz: float, ratio: float
) -> CascadeGains:
    """The cascade of a declared servo at a position bandwidth, with its limits.

    Current clamp ``torque_limit / (c_m i_r)`` (the peak torque on the axis through the
    drive's reducer), rate clamp and voltage clamp as declared
    (:func:`rt70.control.servo.cascade_gains`, designed on ``p.J_l``).

    Parameters
    ----------
    p : DriveParameters
        The drive with its design inertia (:func:`servo_parameters`).
    servo : AxisServo
        The declaration.
    position_hz : float
        Position-loop bandwidth, Hz.
    ratio : float
        Bandwidth ratio between nested loops.
    """
    return cascade_gains(
        p,
        p.J_l,
        position_hz=position_hz,
        ratio=ratio,
        current_limit=servo.torque_limit / (p.c_m * p.i_r),
        rate_limit=servo.rate_limit,
        voltage_limit=servo.voltage_limit,
    )


@dataclass(frozen=True)
class DeclaredFriction:
    """An axis's dry friction as declared: F_s at rest, its rise k per rad/s (linear).

    The rise is taken linear from ``static_friction`` at rest to ``top_speed_friction``
    at the rate limit (the two points a servo declares).
    """

    static_torque: float
    slope: float


def friction_of(scene: Scene, declared: DeclaredServo) -> DeclaredFriction:
    """The axis's declared dry friction (:class:`rt70.control.friction.DryFriction`).

    Raises
    ------
    SceneError
        If its servo declares none.
    """
    s = declared.servo
    if s.static_friction is None or s.top_speed_friction is None:
        raise SceneError(
            f"{scene.name}: axis '{declared.axis.name}' declares no dry friction: give its "
            "<rt70:servo> static_friction and top_speed_friction"
        )
    return DeclaredFriction(
        s.static_friction, (s.top_speed_friction - s.static_friction) / s.rate_limit
    )


def rate_limit_deg_s(declared: DeclaredServo) -> float:
    """The axis's rate limit, °/s."""
    return math.degrees(declared.servo.rate_limit)
