"""An az–el antenna of the user's own, written as an editable URDF from a few engineering numbers.

One job: turn an :class:`AntennaSpec` — diameter, focal ratio, reflector system, the masses
of the elevation and azimuth structures, the target locked-rotor frequencies, the axes'
rate and acceleration limits and ranges, a design wind — into a scene rt70 reads
(``rt70 new antenna``; docs/own-antenna.md). Every number the file holds that the spec
does not is derived here by a stated rule, and the file says which in a comment beside
it, so the engineer can replace it with the real one.

The lumped model (q = 0: the boresight along −y at the horizon, the elevation axis along
x at height ``h``, z up; azimuth 0 looks along −y and azimuth grows towards +x, the
convention of the wind's directions, :func:`rt70.physics.aerodynamics.horizontal_direction`):

- ``azimuth`` (revolute about z) turns the ``turntable``; the spring ``alidade_twist``
  joins it to the ``alidade`` (the structure's torsion between the drive and the
  elevation bearings);
- ``elevation`` (revolute about −x, so a positive angle raises the boresight) on the
  alidade turns the ``elevation_hub``; the spring ``reflector_twist`` joins it to the
  ``reflector`` (the elevation structure: dish, backup structure, counterweight, whose
  centre of mass with the subreflector's is on the elevation axis);
- the reflector's frame has its z along the boresight (the reference frame of the
  pointing corrections, ``<rt70:optics reference_link>``);
- a dual-reflector antenna's ``subreflector`` sits on the focal axis on two tilt springs
  (the feed legs), its focus confocal with the primary's;
- one ``<rt70:drive>`` per axis on the axis's joint (a torque drive; no gear sector) and
  its ``<rt70:servo>``; the dish's ``<rt70:wind>``.

Derivations (:func:`derive`): the reflector's inertias are a uniform thin disk's (``m R²/4``
about a diameter, ``m R²/2`` about the boresight), the alidade's a uniform cylinder's of
radius ``D/4``; the locked-rotor stiffness of an axis is ``k = I (2π f)²`` with I the load's
inertia about it (motors held, one mode), shared equally by the reducer and the
structure's spring (``2k`` each, in series ``k``); the motor runs at 3000 rpm at the
axis's rate limit (``i_r = ω_n / Ω``), its reflected inertia matches the load's
(``J_m i_r² = I``); the peak axis torque is the acceleration torque of load and motor
(``2 I a``) plus the design wind's largest moment on the dish; the nominal torque is half
the peak; a 400 V motor with ``c_e = 0.9 U/ω_n``, a 10 % resistive drop at rated
current and a 20 ms electrical time constant; every spring and reducer damped at
``damping_ratio`` of its mode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rt70.physics.aerodynamics import DEFAULT_AIR_DENSITY
from rt70.physics.coefficient_tables import builtin_table
from rt70.scenes import urdf_writer as uw
from rt70.scenes.urdf_writer import check_name, fmt, fmt_vec

#: Reflector systems the generator writes.
OPTICS = ("prime_focus", "cassegrain", "beam_waveguide")
#: Rated motor speed, rad/s (a 3000 rpm motor class) and its rated voltage, V.
MOTOR_SPEED, MOTOR_VOLTAGE = 2 * math.pi * 50.0, 400.0
#: Share of the hubs' (turntable, elevation hub) mass in their structure's, and of the
#: feed legs' (the link between the two tilt joints) in the subreflector's.
HUB_SHARE, FEED_LEGS_SHARE = 0.05, 1e-3


@dataclass(frozen=True)
class AntennaSpec:
    """The engineering numbers an antenna is generated from (SI, angles in degrees).

    Attributes
    ----------
    name : str
        The scene's name (a URDF name: letters, digits, ``_``).
    diameter : float
        Reflector diameter D, m.
    elevation_mass, azimuth_mass : float
        Mass of the elevation structure (dish, backup structure, counterweight) and of
        the alidade, kg.
    locked_rotor_hz : (float, float)
        Target lowest locked-rotor frequency of the azimuth and elevation axes, Hz.
    rate_limit_deg_s, acceleration_deg_s2 : (float, float)
        Azimuth and elevation rate and acceleration limits.
    focal_ratio : float
        f/D of the primary.
    optics : str
        One of :data:`OPTICS`.
    secondary_mass : float or None
        The subreflector's mass, kg; None: 1 % of the elevation mass (assumed).
    secondary_hz : float
        Target frequency of the subreflector's tilt on its feed legs, Hz.
    elevation_range_deg, azimuth_range_deg : (float, float)
        The axes' ranges.
    design_wind : float
        The wind the drives are sized for, m/s.
    damping_ratio : float
        Modal damping of every spring and reducer.
    position_bandwidth_hz : (float, float) or None
        The servo's position-loop bandwidths; None: tuned on the model when used.
    sources : dict of str to str
        Where each number came from, written into the file's comments.
    """

    name: str
    diameter: float
    elevation_mass: float
    azimuth_mass: float
    locked_rotor_hz: tuple[float, float]
    rate_limit_deg_s: tuple[float, float]
    acceleration_deg_s2: tuple[float, float]
    focal_ratio: float = 0.4
    optics: str = "cassegrain"
    secondary_mass: float | None = None
    secondary_hz: float = 10.0
    elevation_range_deg: tuple[float, float] = (0.0, 90.0)
    azimuth_range_deg: tuple[float, float] = (-270.0, 270.0)
    design_wind: float = 20.0
    damping_ratio: float = 0.02
    position_bandwidth_hz: tuple[float, float] | None = None
    sources: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_name(self.name)
        if self.optics not in OPTICS:
            raise ValueError(f"optics is one of {', '.join(OPTICS)}, got {self.optics!r}")
        positive = {
            "diameter": self.diameter,
            "elevation_mass": self.elevation_mass,
            "azimuth_mass": self.azimuth_mass,
            "focal_ratio": self.focal_ratio,
            "secondary_hz": self.secondary_hz,
            "design_wind": self.design_wind,
            "damping_ratio": self.damping_ratio,
        }
        pairs = {
            "locked_rotor_hz": self.locked_rotor_hz,
            "rate_limit_deg_s": self.rate_limit_deg_s,
            "acceleration_deg_s2": self.acceleration_deg_s2,
        }
        if self.position_bandwidth_hz is not None:
            pairs["position_bandwidth_hz"] = self.position_bandwidth_hz
        for key, pair in pairs.items():
            if len(pair) != 2:
                raise ValueError(f"{key} is an (azimuth, elevation) pair, got {pair!r}")
            positive.update({f"{key}[{i}]": v for i, v in enumerate(pair)})
        if self.secondary_mass is not None:
            positive["secondary_mass"] = self.secondary_mass
        for key, value in positive.items():
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{key} must be finite and positive, got {value!r}")
        for key, (low, high) in (
            ("elevation_range_deg", self.elevation_range_deg),
            ("azimuth_range_deg", self.azimuth_range_deg),
        ):
            if not low < high:
                raise ValueError(f"{key}: {low:g} is not below {high:g}")
        low, high = self.elevation_range_deg
        if not (-90.0 <= low and high <= 180.0):
            raise ValueError(f"elevation_range_deg lies within -90…180°, got {low:g}…{high:g}")


def derive(spec: AntennaSpec) -> dict[str, float]:
    """Every derived number of the scene by name (module docstring: the rules)."""
    R, D = spec.diameter / 2.0, spec.diameter
    m_el, m_az = spec.elevation_mass, spec.azimuth_mass
    d = {"R": R, "height": 0.6 * D, "vertex": 0.1 * D, "focal_length": spec.focal_ratio * D}
    d["I_reflector_diameter"] = m_el * R**2 / 4.0
    d["I_reflector_axis"] = m_el * R**2 / 2.0
    d["I_alidade_z"] = m_az * (D / 4.0) ** 2 / 2.0
    e_mid = math.radians(sum(spec.elevation_range_deg) / 2.0)
    d["I_elevation"] = d["I_reflector_diameter"]
    d["I_azimuth"] = d["I_alidade_z"] + d["I_reflector_diameter"] * (1.0 + math.sin(e_mid) ** 2)
    table = builtin_table("dish")
    wind_moment = (
        0.5 * DEFAULT_AIR_DENSITY * spec.design_wind**2 * math.pi * R**2 * D
        * float(np.max(np.abs(table.moment)))
    )  # fmt: skip
    d["wind_moment"] = wind_moment
    for k, axis in enumerate(("azimuth", "elevation")):
        inertia = d[f"I_{axis}"]
        w = 2 * math.pi * spec.locked_rotor_hz[k]
        k_axis = inertia * w**2
        rate = math.radians(spec.rate_limit_deg_s[k])
        i_r = MOTOR_SPEED / rate
        peak = 2.0 * inertia * math.radians(spec.acceleration_deg_s2[k]) + wind_moment
        nominal = peak / 2.0
        c = 0.9 * MOTOR_VOLTAGE / MOTOR_SPEED
        rated_current = nominal / i_r / c
        R_a = 0.1 * MOTOR_VOLTAGE / rated_current
        zeta = spec.damping_ratio
        d.update(
            {
                f"{axis}_structure_stiffness": 2.0 * k_axis,
                f"{axis}_structure_damping": 2.0 * zeta * math.sqrt(2.0 * k_axis * inertia),
                f"{axis}_C_r": 2.0 * k_axis,
                f"{axis}_D_r": 2.0 * zeta * math.sqrt(2.0 * k_axis * inertia),
                f"{axis}_i_r": i_r,
                f"{axis}_J_m": inertia / i_r**2,
                f"{axis}_D_m": 0.01 * nominal / i_r / MOTOR_SPEED,
                f"{axis}_c": c,
                f"{axis}_R_a": R_a,
                f"{axis}_L_a": 0.02 * R_a,
                f"{axis}_peak_torque": peak,
                f"{axis}_nominal_torque": nominal,
            }
        )
    m_sub = 0.01 * m_el if spec.secondary_mass is None else spec.secondary_mass
    r_sub = 0.05 * D
    d["secondary_mass"], d["secondary_radius"] = m_sub, r_sub
    d["secondary_z"] = d["vertex"] + 0.9 * d["focal_length"]
    dual = spec.optics != "prime_focus"
    # the counterweight balances the subreflector and its feed legs (1e-3 of it)
    d["balance"] = -(1.0 + FEED_LEGS_SHARE) * m_sub * d["secondary_z"] / m_el if dual else 0.0
    d["I_secondary_diameter"] = m_sub * r_sub**2 / 4.0
    d["secondary_stiffness"] = d["I_secondary_diameter"] * (2 * math.pi * spec.secondary_hz) ** 2
    d["secondary_damping"] = (
        2.0 * spec.damping_ratio * math.sqrt(d["secondary_stiffness"] * d["I_secondary_diameter"])
    )
    return d


def _disk_moments(m: float, r: float) -> tuple[float, float, float]:
    """Principal moments of a thin disk of mass m, radius r, its axis along z."""
    return (m * r**2 / 4.0, m * r**2 / 4.0, m * r**2 / 2.0)


def _spring(w: uw.Writer, joint: str, stiffness: float, damping: float, why: str) -> None:
    w.comment(why)
    w.empty(
        "rt70:joint_spring",
        ("name", f"{joint}_spring"),
        ("joint", joint),
        ("stiffness", fmt(stiffness)),
        ("damping", fmt(damping)),
    )


def antenna_urdf(spec: AntennaSpec) -> str:
    """The URDF text of the antenna ``spec`` describes (module docstring)."""
    d = derive(spec)
    w = uw.Writer()
    w.lines.append('<?xml version="1.0"?>')
    w.comment(
        f"{spec.name}: a {spec.diameter:g}-m az-el antenna ({spec.optics}), generated by "
        "'rt70 new antenna' (rt70.scenes.antenna)"
    )
    w.comment(
        "Edit it freely: every derived number says how it was derived; replace it with your "
        "structure's own (docs/own-antenna.md)"
    )
    w.open("robot", ("name", spec.name), ("xmlns:rt70", uw.RT70_NS))
    w.empty("link", ("name", uw.ROOT_LINK))
    for key, text in spec.sources.items():
        w.comment(f"source of {key}: {text}")
    _bodies(w, spec, d)
    _elements(w, spec, d)
    return uw.end(w)


def _bodies(w: uw.Writer, spec: AntennaSpec, d: dict[str, float]) -> None:
    """The links and joints (module docstring)."""
    m_el, m_az, R = spec.elevation_mass, spec.azimuth_mass, d["R"]
    hub_az = (HUB_SHARE * m_az, HUB_SHARE * d["I_alidade_z"])
    w.comment("Azimuth: the drive's turntable, then the alidade through its torsion spring")
    uw.joint(w, "azimuth", "revolute", uw.ROOT_LINK, "turntable", axis=(0, 0, 1))
    uw.massive_link(w, "turntable", hub_az[0], (hub_az[1] / 2, hub_az[1] / 2, hub_az[1]))
    uw.joint(w, "alidade_twist", "revolute", "turntable", "alidade", axis=(0, 0, 1))
    w.comment("alidade: a uniform cylinder of radius D/4 as high as the elevation axis (derived)")
    i_z, h = d["I_alidade_z"], d["height"]
    i_t = m_az * (3.0 * (spec.diameter / 4.0) ** 2 + h**2) / 12.0
    uw.massive_link(w, "alidade", m_az, (i_t, i_t, i_z), com=(0.0, 0.0, h / 2))
    w.comment("Elevation: the drive's hub on the alidade, then the reflector through its spring")
    uw.joint(
        w, "elevation", "revolute", "alidade", "elevation_hub", xyz=(0, 0, d["height"]),
        axis=(-1, 0, 0),
    )  # fmt: skip
    i_hub = HUB_SHARE * d["I_reflector_diameter"]
    uw.massive_link(w, "elevation_hub", HUB_SHARE * m_el, (i_hub, i_hub, i_hub))
    w.comment("reflector frame: z along the boresight (-y of the ground at q = 0)")
    uw.joint(
        w, "reflector_twist", "revolute", "elevation_hub", "reflector", rpy=(math.pi / 2, 0, 0),
        axis=(-1, 0, 0),
    )  # fmt: skip
    w.comment(
        "reflector: a uniform thin disk about its boresight z; its counterweight puts the centre "
        "of mass of reflector and subreflector on the elevation axis (derived)"
    )
    uw.massive_link(w, "reflector", m_el, _disk_moments(m_el, R), com=(0.0, 0.0, d["balance"]))
    if spec.optics != "prime_focus":
        _subreflector(w, d)


def _subreflector(w: uw.Writer, d: dict[str, float]) -> None:
    """The subreflector on two tilt joints (the feed legs), inside the prime focus."""
    z = d["secondary_z"]
    w.comment("Subreflector on its feed legs: tilts about x and y at its vertex")
    uw.joint(w, "feed_legs_x", "revolute", "reflector", "feed_legs", xyz=(0, 0, z), axis=(1, 0, 0))
    uw.massive_link(w, "feed_legs", 1e-3 * d["secondary_mass"], (1e-3,) * 3)
    uw.joint(w, "feed_legs_y", "revolute", "feed_legs", "subreflector", axis=(0, 1, 0))
    uw.massive_link(
        w,
        "subreflector",
        d["secondary_mass"],
        _disk_moments(d["secondary_mass"], d["secondary_radius"]),
    )


def _elements(w: uw.Writer, spec: AntennaSpec, d: dict[str, float]) -> None:
    """Gravity, springs, optical points, drives, mount with servos, optics and wind."""
    w.empty("rt70:gravity", ("xyz", "0 0 -9.80665"))
    for k, (axis, joint) in enumerate(
        (("azimuth", "alidade_twist"), ("elevation", "reflector_twist"))
    ):
        why = f"{axis} structure: 2k, k = I (2 pi f_lr)^2, f_lr = {spec.locked_rotor_hz[k]:g} Hz"
        stiffness, damping = d[f"{axis}_structure_stiffness"], d[f"{axis}_structure_damping"]
        _spring(w, joint, stiffness, damping, f"{why} (derived)")
    if spec.optics != "prime_focus":
        for joint in ("feed_legs_x", "feed_legs_y"):
            _spring(
                w, joint, d["secondary_stiffness"], d["secondary_damping"],
                f"feed legs: subreflector tilt at {spec.secondary_hz:g} Hz (assumed)",
            )  # fmt: skip
    _points(w, spec, d)
    _drives(w, d)
    _mount(w, spec, d)
    _optics(w, spec)
    w.comment("The dish's wind load: area pi R^2, length D, the built-in dish table")
    w.empty(
        "rt70:wind", ("name", "reflector"), ("link", "reflector"), ("shape", "dish"),
        ("area", fmt(math.pi * d["R"] ** 2)), ("length", fmt(spec.diameter)),
        ("xyz", fmt_vec((0.0, 0.0, d["vertex"]))), ("axis", "0 0 1"),
    )  # fmt: skip


def _points(w: uw.Writer, spec: AntennaSpec, d: dict[str, float]) -> None:
    """The primary's vertex and focus, and a subreflector's (confocal at construction)."""
    vertex, f = d["vertex"], d["focal_length"]
    w.comment(f"Optical points: vertex {vertex:g} m in front of the axis, f = {f:g} m")
    points = [("primary_vertex", "reflector", vertex), ("primary_focus", "reflector", vertex + f)]
    if spec.optics != "prime_focus":  # the subreflector's vertex 0.1 f inside the focus
        points += [
            ("secondary_vertex", "subreflector", 0.0),
            ("secondary_focus", "subreflector", 0.1 * f),
        ]
    for name, link, z in points:
        w.empty(
            "rt70:optical_point", ("name", name), ("link", link), ("xyz", fmt_vec((0.0, 0.0, z)))
        )


def _drives(w: uw.Writer, d: dict[str, float]) -> None:
    """One torque drive per axis (module docstring: the sizing rules)."""
    for axis in ("azimuth", "elevation"):
        w.comment(
            f"{axis} drive: i_r = 3000 rpm / rate limit, J_m i_r^2 = I, 400 V motor "
            "(derived; replace with your drive's data)"
        )
        w.empty(
            "rt70:drive", ("name", f"{axis}_drive"), ("joint", axis),
            ("L_a", fmt(d[f"{axis}_L_a"])), ("R_a", fmt(d[f"{axis}_R_a"])),
            ("c_m", fmt(d[f"{axis}_c"])), ("c_e", fmt(d[f"{axis}_c"])),
            ("J_m", fmt(d[f"{axis}_J_m"])), ("D_m", fmt(d[f"{axis}_D_m"])),
            ("i_r", fmt(d[f"{axis}_i_r"])), ("C_r", fmt(d[f"{axis}_C_r"])),
            ("D_r", fmt(d[f"{axis}_D_r"])),
        )  # fmt: skip


def _mount(w: uw.Writer, spec: AntennaSpec, d: dict[str, float]) -> None:
    """The az-el mount (q = angle for both axes) with each axis's servo."""
    w.comment("Pointing axes: q = 0 looks at the horizon towards -y; E = elevation joint's q")
    w.open("rt70:mount", ("type", "az-el"))
    ranges = (spec.azimuth_range_deg, spec.elevation_range_deg)
    for k, axis in enumerate(("azimuth", "elevation")):
        low, high = ranges[k]
        w.open(
            "rt70:axis", ("name", axis), ("joint", axis), ("zero_deg", "0"), ("sign", "1"),
            ("min_deg", fmt(low)), ("max_deg", fmt(high)),
        )  # fmt: skip
        attrs = [("drive", f"{axis}_drive")]
        if spec.position_bandwidth_hz is not None:
            attrs.append(("position_bandwidth_hz", fmt(spec.position_bandwidth_hz[k])))
        attrs += [
            ("rate_limit_deg_s", fmt(spec.rate_limit_deg_s[k])),
            ("torque_limit", fmt(d[f"{axis}_peak_torque"])),
            ("voltage_limit", fmt(MOTOR_VOLTAGE)),
            ("nominal_torque", fmt(d[f"{axis}_nominal_torque"])),
        ]
        w.empty("rt70:servo", *attrs)
        w.close("rt70:axis")
    w.close("rt70:mount")


def _optics(w: uw.Writer, spec: AntennaSpec) -> None:
    """The reflector system: the reflector's frame is the reference frame."""
    w.open("rt70:optics", ("type", spec.optics), ("reference_link", "reflector"))
    w.empty(
        "rt70:reflector",
        ("role", "primary"),
        ("focus", "primary_focus"),
        ("vertex", "primary_vertex"),
    )
    if spec.optics != "prime_focus":
        w.empty(
            "rt70:reflector", ("role", "secondary"), ("focus", "secondary_focus"),
            ("vertex", "secondary_vertex"), ("support", "reflector"),
        )  # fmt: skip
    w.close("rt70:optics")
