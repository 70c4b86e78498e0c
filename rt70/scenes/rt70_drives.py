"""RT-70 pointing-drive parameters (book 4.1.7, eqs. 4.137–4.150) as plain SI data.

One job: hold the numbers of ``docs/drives.md`` — the DC motors, compliant reducers,
gear trains (backlash and its counter-torque remedy), dry friction and servo targets of
the azimuth and elevation drives — as frozen dataclasses. No dynamics here: the drive
elements, the bond graph and the servo loops read these values.

Every field names its row in ``docs/drives.md`` (``az.*``, ``el.*`` or ``*.*`` for rows
shared by both axes); that page gives the source of each number ("book", "cited" or
"derived", with the formula and its inputs). ``tests/test_rt70_drives.py`` checks that
this module and the page agree, the unit conversions and every derivation.

Sign and meaning of the reducer follow (4.139)/(4.146): the twist is
``Δα = α_axis − α_motor / i_r`` and the torque on the axis ``K = −D_r Δα̇ − C_r Δα``
(4.143); the elevation drive acts through a gear sector of radius ``r`` as the force
``F = K / r`` on the counterweight (4.150). All torques, stiffnesses, friction and
backlash figures marked "axis-referred" are on the axis side of the reducer and are the
total of the axis (both gear trains), unless said otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from rt70.bondgraph.parameters import DriveParameters
from rt70.errors import Rt70Error

#: One kilogram-force metre in newton metres (standard gravity). Row ``*.kgf_m``.
KGF_M = 9.80665


def _check_positive(obj: object, allow_zero: tuple[str, ...] = ()) -> None:
    """Raise :class:`Rt70Error` naming the field if a number is not finite and positive."""
    for f in fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        low_ok = value >= 0.0 if f.name in allow_zero else value > 0.0
        if not (math.isfinite(value) and low_ok):
            raise Rt70Error(
                f"{type(obj).__name__}.{f.name} must be finite and "
                f"{'non-negative' if f.name in allow_zero else 'positive'}, got {value!r}"
            )


@dataclass(frozen=True)
class DcMotor:
    """One separately excited DC motor of a drive (4.137), SI units, motor side.

    Attributes
    ----------
    armature_inductance
        L_a, H (row ``*.motor.armature_inductance``).
    armature_resistance
        R_a, Ω (row ``*.motor.armature_resistance``).
    back_emf_constant
        c_e, V·s/rad (row ``*.motor.back_emf_constant``).
    torque_constant
        c_m, N·m/A; equal to c_e in SI (the motor is a power-conserving gyrator)
        (row ``*.motor.torque_constant``).
    rotor_inertia
        J_m, kg·m² (row ``*.motor.rotor_inertia``).
    viscous_friction
        D_m, N·m·s/rad on the motor shaft (row ``*.motor.viscous_friction``).
    rated_voltage
        U_n, V (row ``*.motor.rated_voltage``).
    rated_current
        I_n, A (row ``*.motor.rated_current``).
    rated_speed
        ω_n, rad/s, also the top speed of the motor (row ``*.motor.rated_speed``).
    rated_torque
        c_m I_n, N·m, motor side (row ``*.motor.rated_torque``).
    peak_torque
        Short-time limit, N·m, motor side (row ``*.motor.peak_torque``).
    """

    armature_inductance: float
    armature_resistance: float
    back_emf_constant: float
    torque_constant: float
    rotor_inertia: float
    viscous_friction: float
    rated_voltage: float
    rated_current: float
    rated_speed: float
    rated_torque: float
    peak_torque: float

    def __post_init__(self) -> None:
        _check_positive(self)

    @property
    def electrical_time_constant(self) -> float:
        """T_a = L_a / R_a (s), the book's T^я of (4.137)."""
        return self.armature_inductance / self.armature_resistance


@dataclass(frozen=True)
class Reducer:
    """The compliant reducer between the motors and the axis (4.137)–(4.143).

    Attributes
    ----------
    ratio
        i_r = motor angle / axis angle (row ``*.reducer.ratio``).
    stiffness
        C_r, N·m/rad, axis-referred (rows ``az.reducer.stiffness``,
        ``el.reducer.stiffness``).
    damping
        D_r, N·m·s/rad, axis-referred (rows ``az.reducer.damping``,
        ``el.reducer.damping``).
    """

    ratio: float
    stiffness: float
    damping: float

    def __post_init__(self) -> None:
        _check_positive(self)


@dataclass(frozen=True)
class GearTrains:
    """Backlash and the book's remedy: counter-torqued parallel gear trains (p. 51).

    Attributes
    ----------
    count
        Gear trains (each with its own motor) closed on the axis's main gear
        (row ``*.trains.count``).
    backlash_half_width
        Half the dead zone of one train, rad, axis side (row ``*.trains.backlash``).
    bias_torque
        Counter-torque each train applies against the other, N·m, axis-referred
        (row ``*.trains.bias_torque``).
    """

    count: int
    backlash_half_width: float
    bias_torque: float

    def __post_init__(self) -> None:
        if isinstance(self.count, bool) or not isinstance(self.count, int) or self.count < 1:
            raise Rt70Error(f"GearTrains.count must be a positive integer, got {self.count!r}")
        _check_positive(self)


@dataclass(frozen=True)
class DryFriction:
    """Dry friction of an axis (book p. 51), axis-referred, relay-like at zero speed.

    The magnitude rises from ``static_torque`` at rest to ``top_speed_torque`` at
    ``top_speed``; :attr:`slope` is the rise per unit speed if the rise is taken as
    linear (the book gives only the two end points).

    Attributes
    ----------
    static_torque
        N·m (row ``*.friction.static_torque``).
    top_speed_torque
        N·m (row ``*.friction.top_speed_torque``).
    top_speed
        rad/s, the axis top speed (row ``*.axis.top_speed``).
    """

    static_torque: float
    top_speed_torque: float
    top_speed: float

    def __post_init__(self) -> None:
        _check_positive(self)
        if self.top_speed_torque < self.static_torque:
            raise Rt70Error(
                "DryFriction.top_speed_torque must not be below static_torque "
                f"({self.top_speed_torque!r} < {self.static_torque!r})"
            )

    @property
    def slope(self) -> float:
        """Rise of friction per unit speed, N·m·s/rad (row ``*.friction.slope``).

        (top_speed_torque − static_torque) / top_speed.
        """
        return (self.top_speed_torque - self.static_torque) / self.top_speed


@dataclass(frozen=True)
class ServoTargets:
    """Loop bandwidths and limits the servo slice designs for (antenna practice).

    Attributes
    ----------
    position_bandwidth_hz
        Row ``*.servo.position_bandwidth``.
    rate_bandwidth_hz
        Row ``*.servo.rate_bandwidth``.
    current_bandwidth_hz
        Row ``*.servo.current_bandwidth``.
    rate_limit
        rad/s, axis (row ``*.servo.rate_limit``).
    acceleration_limit
        rad/s², axis (rows ``az.servo.acceleration_limit``, ``el.servo.acceleration_limit``).
    """

    position_bandwidth_hz: float
    rate_bandwidth_hz: float
    current_bandwidth_hz: float
    rate_limit: float
    acceleration_limit: float

    def __post_init__(self) -> None:
        _check_positive(self)


@dataclass(frozen=True)
class AxisDrive:
    """Everything about one pointing axis's drive (book 4.1.7, Fig. 4.8).

    Attributes
    ----------
    name
        ``"azimuth"`` or ``"elevation"``.
    acts_on
        Where the drive's torque or force enters the structure (rows ``az.acts_on``,
        ``el.acts_on``).
    motor
        One motor; ``motors_per_axis`` identical ones drive the axis.
    motors_per_axis
        Row ``*.motors_per_axis`` (one per gear train).
    reducer, trains, friction, servo
        See the classes.
    sector_radius
        r, m: pitch radius of the elevation gear sector, or ``None`` for a torque drive
        (row ``el.sector_radius``).
    nominal_torque
        The book's nominal motor torque, N·m, axis-referred (row ``*.nominal_torque``).
    wind_torque
        The book's nominal wind torque, N·m, axis (row ``*.wind_torque``).
    reference_inertia
        Rigid inertia of everything the axis turns, kg·m², from the §4.2.3 listing at
        its zero configuration (rows ``az.reference_inertia``, ``el.reference_inertia``).
    locked_rotor_hz
        Lowest locked-rotor frequency of the book's chapter-2 model of the axis with
        this reducer, Hz (rows ``az.locked_rotor``, ``el.locked_rotor``).
    clamped_hz
        The same with a rigid reducer (C_r → ∞), Hz (rows ``az.clamped``,
        ``el.clamped``).
    """

    name: str
    acts_on: str
    motor: DcMotor
    motors_per_axis: int
    reducer: Reducer
    trains: GearTrains
    friction: DryFriction
    servo: ServoTargets
    sector_radius: float | None
    nominal_torque: float
    wind_torque: float
    reference_inertia: float
    locked_rotor_hz: float
    clamped_hz: float

    def __post_init__(self) -> None:
        _check_positive(self, allow_zero=())
        if self.sector_radius is not None and not (
            math.isfinite(self.sector_radius) and self.sector_radius > 0.0
        ):
            raise Rt70Error(f"AxisDrive.sector_radius must be positive, got {self.sector_radius!r}")
        if self.motors_per_axis != self.trains.count:
            raise Rt70Error(
                f"AxisDrive {self.name!r}: {self.motors_per_axis} motors for "
                f"{self.trains.count} gear trains (one motor drives each train)"
            )

    def motor_parameters(self, load_inertia: float) -> DriveParameters:
        """ONE of the axis's motors with the axis's reducer (its totals, axis-referred).

        The caller lumps the ``motors_per_axis`` motors as the drive needs:
        :func:`rt70.control.geartrains.parallel_drive` (armatures on one voltage, the scene's
        ``<rt70:drive>``) or :func:`rt70.control.geartrains.equivalent_drive` (in series).
        """
        m = self.motor
        return DriveParameters(
            L_a=m.armature_inductance,
            R_a=m.armature_resistance,
            c_m=m.torque_constant,
            c_e=m.back_emf_constant,
            J_m=m.rotor_inertia,
            D_m=m.viscous_friction,
            i_r=self.reducer.ratio,
            C_r=self.reducer.stiffness,
            D_r=self.reducer.damping,
            J_l=load_inertia,
            D_l=0.0,
        )

    @property
    def reflected_motor_inertia(self) -> float:
        """All rotors seen from the axis, n·J_m·i_r² (kg·m², row ``*.reflected_inertia``)."""
        return self.motors_per_axis * self.motor.rotor_inertia * self.reducer.ratio**2


# ---------------------------------------------------------------------------------------
# The numbers (docs/drives.md). Shared by both axes unless the row key says az/el.
# ---------------------------------------------------------------------------------------

#: Row ``*.motor.*``: one drive motor (derived from the book's nominal torque, the ratio
#: and a 3000 rpm, 440 V motor class; see docs/drives.md §2).
MOTOR = DcMotor(
    armature_inductance=4.52447e-3,
    armature_resistance=0.226223,
    back_emf_constant=1.26051,
    torque_constant=1.26051,
    rotor_inertia=0.351175,
    viscous_friction=7.80388e-3,
    rated_voltage=440.0,
    rated_current=194.498,
    rated_speed=314.159,
    rated_torque=245.166,
    peak_torque=490.333,
)

#: Row ``*.reducer.ratio`` (book: 10⁵–10⁶; the lower end).
REDUCER_RATIO = 1.0e5

#: Row ``*.axis.top_speed``: ω_n / i_r (rad/s), 0.18 °/s.
TOP_SPEED = 3.14159e-3

#: Row ``*.nominal_torque``: 5·10⁶ kgf·m (book p. 51).
NOMINAL_TORQUE = 4.903325e7
#: Row ``*.wind_torque``: 5·10⁵ kgf·m (book p. 51).
WIND_TORQUE = 4.903325e6

#: Rows ``*.friction.*``: 7·10⁴ kgf·m at rest, 1.5·10⁵ kgf·m (mid of the book's
#: (1–2)·10⁵) at top speed.
FRICTION = DryFriction(static_torque=6.864655e5, top_speed_torque=1.4709975e6, top_speed=TOP_SPEED)

#: Rows ``*.trains.*``: two counter-torqued trains; backlash 1″; bias (wind + static
#: friction)/2 per train.
TRAINS = GearTrains(count=2, backlash_half_width=4.84814e-6, bias_torque=2.79490e6)

AZIMUTH_DRIVE = AxisDrive(
    name="azimuth",
    acts_on="platform, torque about z (the ground-platform rz coordinate)",
    motor=MOTOR,
    motors_per_axis=2,
    reducer=Reducer(ratio=REDUCER_RATIO, stiffness=1.009e10, damping=1.74749e8),
    trains=TRAINS,
    friction=FRICTION,
    servo=ServoTargets(
        position_bandwidth_hz=1.0,
        rate_bandwidth_hz=5.0,
        current_bandwidth_hz=25.0,
        rate_limit=TOP_SPEED,
        acceleration_limit=6.03982e-3,
    ),
    sector_radius=None,
    nominal_torque=NOMINAL_TORQUE,
    wind_torque=WIND_TORQUE,
    reference_inertia=3.9449095e7,
    locked_rotor_hz=0.918959,
    clamped_hz=0.967314,
)

ELEVATION_DRIVE = AxisDrive(
    name="elevation",
    acts_on="counterweight, force along the base's y axis at the sector radius",
    motor=MOTOR,
    motors_per_axis=2,
    reducer=Reducer(ratio=REDUCER_RATIO, stiffness=5.407e10, damping=3.10865e8),
    trains=TRAINS,
    friction=FRICTION,
    servo=ServoTargets(
        position_bandwidth_hz=1.0,
        rate_bandwidth_hz=5.0,
        current_bandwidth_hz=25.0,
        rate_limit=TOP_SPEED,
        acceleration_limit=5.83958e-3,
    ),
    sector_radius=16.0,
    nominal_torque=NOMINAL_TORQUE,
    wind_torque=WIND_TORQUE,
    reference_inertia=2.81635522e8,
    locked_rotor_hz=2.76824,
    clamped_hz=2.91393,
)

#: Both drives by axis name.
DRIVES: dict[str, AxisDrive] = {"azimuth": AZIMUTH_DRIVE, "elevation": ELEVATION_DRIVE}
