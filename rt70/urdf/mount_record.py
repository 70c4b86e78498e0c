"""The records of the pointing axes and the reflector system: ``<rt70:mount>``, ``<rt70:optics>``.

Plain data read by :mod:`rt70.urdf.mount` and :mod:`rt70.urdf.optics`; part of a
:class:`rt70.urdf.description.RobotDescription`, which re-exports them.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class AxisServo:
    """The servo of a pointing axis (``<rt70:servo>`` in ``<rt70:axis>``), SI units.

    Attributes
    ----------
    drive : str
        The ``<rt70:drive>`` the cascade closes around (on the axis's joint).
    rate_limit : float
        Largest axis rate the position loop asks, rad/s.
    torque_limit : float
        Peak torque on the axis, N·m (the current loop's clamp: ``torque_limit /
        (c_m i_r)`` A).
    voltage_limit : float
        Largest armature voltage of the drive, V.
    position_bandwidth_hz : float or None
        The position loop's design bandwidth, Hz; None: tuned on the model
        (:mod:`rt70.telescope.servo_design`).
    loop_ratio : float
        Bandwidth ratio between a loop and the one inside it (position, rate, current).
    nominal_torque : float
        Continuous torque on the axis, N·m: what it may hold (default the peak).
    reference_inertia : float or None
        The inertia the loops are designed for, kg·m²; None: the rigid inertia about the
        axis at the pointing (the mass matrix's diagonal entry of the axis).
    static_friction, top_speed_friction : float or None
        Dry friction on the axis at rest and at the rate limit, N·m (``rt70 simulate
        --friction``); None: not declared.
    """

    drive: str
    rate_limit: float
    torque_limit: float
    voltage_limit: float
    position_bandwidth_hz: float | None = None
    loop_ratio: float = 5.0
    nominal_torque: float = 0.0
    reference_inertia: float | None = None
    static_friction: float | None = None
    top_speed_friction: float | None = None


@dataclass(frozen=True)
class MountAxis:
    """A pointing axis of a mount: which joint turns it and how its angle is counted.

    The joint's coordinate is ``q = sign · (angle − zero)``, rad: for the RT-70's
    elevation, ``base_rx = −(E − 90°) = π/2 − E`` (``zero`` = π/2, ``sign`` = −1).
    ``lower`` and ``upper`` bound the pointing angle (rad), not the coordinate;
    ``servo`` is the axis's servo, if declared.
    """

    name: str
    joint: str
    zero: float
    sign: int
    lower: float
    upper: float
    servo: AxisServo | None = None

    def coordinate(self, angle: float) -> float:
        """The joint coordinate, rad, that points the axis at ``angle``, rad."""
        return self.sign * (angle - self.zero)

    def angle(self, coordinate: float) -> float:
        """The pointing angle, rad, of a joint coordinate, rad."""
        return self.zero + self.sign * coordinate


@dataclass(frozen=True)
class Mount:
    """How the structure points: the mount's type and its axes (``<rt70:mount>``)."""

    type: str
    axes: tuple[MountAxis, ...]

    def axis(self, name: str) -> MountAxis:
        """The axis called ``name`` (KeyError if the mount has none)."""
        for axis in self.axes:
            if axis.name == name:
                return axis
        raise KeyError(name)


#: Reflector systems (``<rt70:optics type>``) and whether each has a secondary reflector.
OPTICS_TYPES = {
    "prime_focus": False,
    "cassegrain": True,
    "gregorian": True,
    "beam_waveguide": True,
}


@dataclass(frozen=True)
class Reflector:
    """One reflector of an optics: its focus and vertex (names of optical points).

    ``support`` is the link that carries a secondary reflector's drive (its frame gives
    the drive's axes, book 4.1.8 frame 7c); None for the primary.
    """

    focus: str
    vertex: str
    support: str | None = None


@dataclass(frozen=True)
class Optics:
    """The reflector system (``<rt70:optics>``): its type, reference frame and reflectors.

    ``reference_link`` is the link whose frame is the reflector's reference frame (the
    book's reference ring, OK): its z axis is the focal axis at construction.
    ``secondary`` is None for a single reflector (``prime_focus``).
    """

    type: str
    reference_link: str
    primary: Reflector
    secondary: Reflector | None = None
