"""Bearing and reducer loads of an antenna: joint reactions at the drive-held equilibrium.

What a structural or drive engineer asks of the model: at a pointing,
at rest under gravity and optionally a steady wind, what do the azimuth bearing, the
elevation bearing and the two reducers carry? The answer is the joint reaction
wrenches of source 004 (9)–(13) (:mod:`rt70.textbook.reactions`, cross-checked by
:mod:`rt70.reference.reactions`) at the static equilibrium the drives hold
(:func:`rt70.telescope.scene_servo.scene_equilibrium`, the wind's generalised force added as in
:mod:`rt70.telescope.pointing`). The bearings are the joints of the scene's
``<rt70:mount>`` axes; in the RT-70 scenes (rt70_servo; docs/reactions.md):

- **azimuth bearing**: the wrench across the azimuth joint ``platform_rz`` (ground →
  the platform and all it carries, through the ``ground_platform`` bushing: the
  foundation's elastic pair), in the joint's axes (the alidade's, z the azimuth axis)
  about its origin: the axial force ``F_z``, the radial force ``|F_xy|``, the
  overturning moment ``|M_xy|``;
- **azimuth reducer**: the axis moment ``M_z`` of the same wrench, which the azimuth
  drive's reducer carries (the bushing has no stiffness about z); it equals the drive's
  reducer torque K_az of the equilibrium;
- **elevation bearing**: the wrench across the elevation joint ``base_rx`` (platform →
  the elevation structure, through the ``platform_base`` strut package: the two
  bearings at x = ±13.45 m) with the elevation drive's gear-sector mesh force taken out
  (it acts on the counterweight from the pinion on the platform, bypassing the
  bearings), in the alidade's axes (those of ``platform_rz``) about its origin: the
  force along the elevation axis ``F_x``, the radial force ``|F_yz|``, the bending
  moment ``|M_yz|`` (shared by the two bearings), and the axis moment ``M_x`` (≈ 0: the
  struts do not resist the elevation turn);
- **elevation reducer**: the drive's reducer torque K_el and the sector's mesh force
  (magnitude ``K_el/ρ``, ρ ≈ 16 m).

Sanity checks carried in each :class:`BearingLoads`: the vertical (ground) force
across the azimuth joint is the weight of everything above the foundation (calm), that
across the elevation joint with the mesh force left in is the elevation structure's
weight, and the two sides agree.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.antenna import ELEVATION_SPAN_DEG
from rt70.model.scene import Scene
from rt70.model.sides import side_of
from rt70.physics.loads import Wrench

#: How many elevations the report has by default, evenly over the axis's range.
N_ELEVATIONS = 7


@dataclass(frozen=True)
class LoadCase:
    """One case: a pointing, and a steady wind (speed 0: calm).

    ``wind_direction_deg`` is the azimuth the wind blows from; None is a front wind
    (from the pointing's azimuth, into the dish).
    """

    elevation_deg: float
    azimuth_deg: float = 0.0
    wind_speed: float = 0.0
    wind_direction_deg: float | None = None

    @property
    def wind_from(self) -> float:
        """The wind's direction, degrees."""
        return self.azimuth_deg if self.wind_direction_deg is None else self.wind_direction_deg

    @property
    def label(self) -> str:
        """``calm``, ``front``, ``back`` or the wind's direction in degrees."""
        if self.wind_speed == 0.0:
            return "calm"
        relative = (self.wind_from - self.azimuth_deg) % 360.0
        return {0.0: "front", 180.0: "back"}.get(relative, f"from {self.wind_from:g}°")


@dataclass(frozen=True)
class BearingLoads:
    """The loads of one case, N and N·m (see the module docstring for the axes).

    ``azimuth`` is the wrench across the azimuth joint in its own (the alidade's) axes;
    ``elevation`` the wrench across the elevation joint in the same axes with the mesh force
    taken out, ``elevation_total`` with it left in; ``vertical`` the upward ground
    component of the force across each joint (mesh force left in); ``mesh_force`` the
    sector's force on the counterweight (ground axes); ``torques`` the drives' reducer
    torques of the equilibrium by axis (``azimuth``, ``elevation``); ``weight_azimuth`` and
    ``weight_elevation`` the weights above each joint; ``sides_difference`` the largest
    difference of the two sides' values relative to their max-norm; ``residual`` the
    equilibrium's.
    """

    case: LoadCase
    azimuth: np.ndarray
    elevation: np.ndarray
    elevation_total: np.ndarray
    mesh_force: np.ndarray
    vertical: tuple[float, float]
    torques: dict[str, float]
    weight_azimuth: float
    weight_elevation: float
    sides_difference: float
    residual: float
    seconds_textbook: float
    seconds_reference: float

    def row(self) -> dict[str, float | str]:
        """The engineer's table row: kN and kN·m."""
        a, e = self.azimuth / 1e3, self.elevation / 1e3
        return {
            "elevation_deg": self.case.elevation_deg,
            "azimuth_deg": self.case.azimuth_deg,
            "wind_speed": self.case.wind_speed,
            "wind": self.case.label,
            "az_axial_kN": a[2],
            "az_radial_kN": float(np.hypot(a[0], a[1])),
            "az_overturning_kNm": float(np.hypot(a[3], a[4])),
            "az_reducer_kNm": a[5],
            "az_drive_kNm": self.torques.get("azimuth", float("nan")) / 1e3,
            "el_axial_kN": e[0],
            "el_radial_kN": float(np.hypot(e[1], e[2])),
            "el_bending_kNm": float(np.hypot(e[4], e[5])),
            "el_axis_moment_kNm": e[3],
            "el_reducer_kNm": self.torques.get("elevation", float("nan")) / 1e3,
            "el_mesh_force_kN": float(np.linalg.norm(self.mesh_force)) / 1e3,
            "az_vertical_kN": self.vertical[0] / 1e3,
            "weight_above_az_kN": self.weight_azimuth / 1e3,
            "el_vertical_kN": self.vertical[1] / 1e3,
            "weight_above_el_kN": self.weight_elevation / 1e3,
            "sides_rel_diff": self.sides_difference,
            "residual": self.residual,
        }

    def to_dict(self) -> dict:
        """JSON-ready: the row, the full wrenches and the drives' torques."""
        return {
            **self.row(),
            "azimuth_wrench": self.azimuth.tolist(),
            "elevation_wrench": self.elevation.tolist(),
            "elevation_total_wrench": self.elevation_total.tolist(),
            "mesh_force": self.mesh_force.tolist(),
            "torques": dict(self.torques),
            "case": asdict(self.case),
            "seconds_textbook": self.seconds_textbook,
            "seconds_reference": self.seconds_reference,
        }


def check_scene(scene: Scene, wind: bool) -> None:
    """Refuse a scene without a mount, drives on its axes (or wind elements if asked).

    Raises
    ------
    Rt70Error
        Naming the scene and what it lacks.
    """
    from rt70.model.antenna import mount_of
    from rt70.telescope.scene_servo import has_scene_drives

    mount_of(scene)  # one line naming the element when the scene has no axes
    if not has_scene_drives(scene):
        raise Rt70Error(
            f"{scene.name}: needs a <rt70:drive> on each axis of its <rt70:mount> to hold the "
            "pointing"
        )
    if wind and not scene.description.winds:
        raise Rt70Error(f"{scene.name}: no <rt70:wind> element: no wind load (docs/wind.md)")
    if wind:
        from rt70.model.antenna import check_wind_convention

        check_wind_convention(scene)  # the wind's directions are azimuths of the mount


def check_case(case: LoadCase) -> None:
    """Refuse a non-finite case, an elevation beyond a quarter turn or a negative wind speed.

    The scene's own range is checked where the pointing is held
    (:func:`rt70.model.antenna.pointing`).
    """
    values = [case.elevation_deg, case.azimuth_deg, case.wind_speed, case.wind_from]
    if not np.isfinite(values).all():
        raise Rt70Error(f"load case must be finite, got {case}")
    low, high = ELEVATION_SPAN_DEG
    if not low <= case.elevation_deg <= high:
        raise Rt70Error(f"elevation {case.elevation_deg:g}° outside {low:g}…{high:g}°")
    if case.wind_speed < 0.0:
        raise Rt70Error(f"wind speed must not be negative, got {case.wind_speed:g} m/s")


def bearing_loads(scene: Scene, case: LoadCase) -> BearingLoads:
    """The bearing and reducer loads of ``case`` (see the module docstring).

    The equilibrium is solved once (reference side, as :mod:`rt70.telescope.pointing`); each side
    then computes its own loads (wind Wrenches, the sector's mesh Wrenches at the
    elevation drive's torque) and reactions at it.
    """
    from rt70.model.antenna import pointing
    from rt70.physics.aerodynamics import WindCondition
    from rt70.telescope.scene_servo import SceneServoFactory, scene_equilibrium

    check_case(case)
    condition = WindCondition(case.wind_speed, case.wind_from) if case.wind_speed else None
    load = None
    if condition is not None:
        from rt70.reference import wind as ref_wind

        ref, rd = scene.reference, scene.reference_data
        load = lambda q: ref_wind.wind_force(ref, rd, q, condition)  # noqa: E731
    couplings = SceneServoFactory(side="reference").couplings(scene)
    held = pointing(scene, case.elevation_deg, case.azimuth_deg)
    q, K, residual = scene_equilibrium(scene, couplings, held, load=load)
    torques = {c.drive.name: float(k) for c, k in zip(couplings, K, strict=True)}
    drives = {c.drive.name: c.drive for c in couplings}
    results = {}
    seconds = {}
    for side in ("textbook", "reference"):
        start = time.perf_counter()
        results[side] = _side_loads(scene, side, q, condition, drives, torques)
        seconds[side] = time.perf_counter() - start
    tb, ref_ = results["textbook"], results["reference"]
    stacked_tb = np.concatenate(tb[:4])
    stacked_ref = np.concatenate(ref_[:4])
    diff = float(np.max(np.abs(stacked_tb - stacked_ref)) / np.max(np.abs(stacked_ref)))
    model = scene.textbook
    g = float(np.linalg.norm(model.gravity))
    azimuth_joint, elevation_joint = bearing_joints(scene)
    axes = {azimuth_joint: "azimuth", elevation_joint: "elevation"}
    below = _subtree_mass(scene, elevation_joint)
    return BearingLoads(
        case,
        azimuth=tb[0],
        elevation=tb[1],
        elevation_total=tb[2],
        mesh_force=tb[3],
        vertical=tb[4],
        torques={axes[c.drive.joint]: torques[c.drive.name] for c in couplings},
        weight_azimuth=_subtree_mass(scene, azimuth_joint) * g,
        weight_elevation=below * g,
        sides_difference=diff,
        residual=residual,
        seconds_textbook=seconds["textbook"],
        seconds_reference=seconds["reference"],
    )


def _side_loads(scene: Scene, side: str, q: np.ndarray, condition, drives: dict, torques: dict):
    """One side's (azimuth, elevation, elevation total, mesh force, vertical forces) at q."""
    zero = np.zeros(q.size)
    s = side_of(scene, side)
    model, data = s.model, s.data
    side_drives, reactions, side_wind = s.drives, s.reactions, s.wind
    loads: list[Wrench] = []
    if condition is not None:
        loads += list(side_wind.wind_wrenches(model, data, q, condition).values())
    mesh: list[Wrench] = []
    mesh_force = np.zeros(3)
    for name, drive in drives.items():
        if drive.sector is None:
            continue  # a torque drive acts inside its joint: the axis moment
        s = drive.sector
        circle = side_drives.sector_mesh(model, data, drive)
        link = side_drives.link_pose(model, data, q, s.link)
        stator = side_drives.link_pose(model, data, q, s.stator)
        on_link, on_stator = circle.wrenches(s.link, s.stator, s.xyz, torques[name], link, stator)
        mesh += [on_link, on_stator]
        mesh_force += np.asarray(on_link.force)
    total = reactions.joint_reactions(model, data, q, zero, zero, loads)
    bearing = reactions.joint_reactions(model, data, q, zero, zero, loads + mesh)
    poses = reactions.joint_frames(model, data, q)
    az, el = bearing_joints(scene)
    c_az, c_el = poses[az][0], poses[el][0]
    up = -np.asarray(scene.description.gravity, dtype=float)
    up /= np.linalg.norm(up)
    vertical = (
        float(up @ c_az @ total[az][:3]),
        float(up @ c_el @ total[el][:3]),
    )
    to_alidade = c_az.T @ c_el  # elevation joint axes → the alidade's

    def turned(c: np.ndarray, w: np.ndarray) -> np.ndarray:
        return np.concatenate([c @ w[:3], c @ w[3:]])

    return (
        total[az],
        turned(to_alidade, bearing[el]),
        turned(to_alidade, total[el]),
        mesh_force,
        vertical,
    )


def default_elevations(scene: Scene) -> tuple[float, ...]:
    """:data:`N_ELEVATIONS` elevations evenly over the scene's elevation range, degrees."""
    from rt70.model.antenna import mount_of, range_deg

    axis = mount_of(scene).axis("elevation")
    low, high = range_deg(axis)
    return tuple(float(round(e, 9)) for e in np.linspace(low, high, N_ELEVATIONS))


def bearing_joints(scene: Scene) -> tuple[str, str]:
    """The azimuth and elevation joints of the scene's ``<rt70:mount>``: its bearings."""
    from rt70.model.antenna import mount_of

    mount = mount_of(scene)
    return mount.axis("azimuth").joint, mount.axis("elevation").joint


def _subtree_mass(scene: Scene, joint: str) -> float:
    """Mass of the bodies below ``joint`` (its pair's subtree), kg."""
    model = scene.textbook
    pair = next(k for k, names in enumerate(model.pair_joints) if joint in names)
    below = {pair}
    for k in range(pair + 1, model.nb):
        if int(model.parent[k]) in below:
            below.add(k)
    return float(sum(model.mass[k] for k in below))


def load_table(
    scene: Scene,
    elevations=None,
    azimuth_deg: float = 0.0,
    wind_speed: float = 0.0,
    directions: tuple[float | None, ...] = (None,),
) -> list[BearingLoads]:
    """The loads at every elevation: calm, and with the wind from each of ``directions``.

    Parameters
    ----------
    scene : Scene
        A scene with the RT-70's drives (and ``<rt70:wind>`` elements for a wind).
    elevations : sequence of float
        The elevations, degrees; None: :func:`default_elevations`.
    azimuth_deg : float
        The azimuth of every case, degrees.
    wind_speed : float
        Mean wind speed, m/s; 0: calm cases only.
    directions : tuple of float or None
        Azimuths the wind blows from, degrees (None: front, into the dish), used when
        ``wind_speed`` > 0.
    """
    cases = []
    for e in default_elevations(scene) if elevations is None else elevations:
        cases.append(LoadCase(float(e), azimuth_deg))
        if wind_speed > 0.0:
            cases += [LoadCase(float(e), azimuth_deg, wind_speed, d) for d in directions]
    for case in cases:
        check_case(case)
    check_scene(scene, wind_speed > 0.0)
    return [bearing_loads(scene, case) for case in cases]


def format_table(scene_name: str, rows: list[BearingLoads], joints: tuple[str, str]) -> str:
    """The loads as a fixed-width text table (kN, kN·m), with the checks' extremes.

    Parameters
    ----------
    scene_name : str
        The scene, for the title.
    rows : list of BearingLoads
        The cases (:func:`bearing_loads`).
    joints : (str, str)
        The azimuth and elevation joints (:func:`bearing_joints`).
    """
    head = (
        f"{'elev':>5} {'wind':>11} | {'az axial':>9} {'radial':>8} {'overturn':>9} "
        f"{'reducer':>9} | {'el axial':>8} {'radial':>8} {'bending':>8} {'axis M':>7} "
        f"{'reducer':>8} {'mesh F':>7}"
    )
    units = (
        f"{'deg':>5} {'m/s':>11} | {'kN':>9} {'kN':>8} {'kN·m':>9} {'kN·m':>9} | "
        f"{'kN':>8} {'kN':>8} {'kN·m':>8} {'kN·m':>7} {'kN·m':>8} {'kN':>7}"
    )
    lines = [
        f"{scene_name}: bearing and reducer loads at the drive-held equilibrium "
        "(docs/reactions.md)",
        f"  azimuth: wrench across {joints[0]}; elevation: across {joints[1]}, mesh force "
        "taken out; both in the alidade's axes (z: azimuth axis, x: elevation axis)",
        head,
        units,
    ]
    for b in rows:
        r = b.row()
        wind = "calm" if r["wind"] == "calm" else f"{r['wind_speed']:g} {r['wind']}"
        lines.append(
            f"{r['elevation_deg']:>5g} {wind:>11} | {r['az_axial_kN']:>9.1f} "
            f"{r['az_radial_kN']:>8.1f} {r['az_overturning_kNm']:>9.1f} "
            f"{r['az_reducer_kNm']:>9.2f} | {r['el_axial_kN']:>8.1f} {r['el_radial_kN']:>8.1f} "
            f"{r['el_bending_kNm']:>8.1f} {r['el_axis_moment_kNm']:>7.2f} "
            f"{r['el_reducer_kNm']:>8.1f} {r['el_mesh_force_kN']:>7.1f}"
        )
    if rows:
        worst = max(b.sides_difference for b in rows)
        res = max(b.residual for b in rows)
        w = rows[0]
        lines.append(
            f"checks: weight above the azimuth bearing {w.weight_azimuth / 1e3:.1f} kN, above "
            f"the elevation bearing {w.weight_elevation / 1e3:.1f} kN; textbook vs Pinocchio "
            f"max rel. difference {worst:.2g}; equilibrium residual ≤ {res:.2g}"
        )
    return "\n".join(lines)


def write_output(path, rows: list[BearingLoads]) -> None:
    """Write the rows atomically: ``.csv`` (the table rows) or ``.json`` (everything)."""
    import csv
    import io
    import json
    from pathlib import Path

    from rt70.guards.atomic import atomic_write_text

    path = Path(path)
    if path.suffix == ".json":
        atomic_write_text(path, json.dumps([b.to_dict() for b in rows], indent=2) + "\n")
        return
    if path.suffix != ".csv":
        raise Rt70Error(f"{path}: --output must be a .csv or .json file")
    buffer = io.StringIO()
    fields = list(rows[0].row()) if rows else []
    writer = csv.DictWriter(buffer, fieldnames=fields, lineterminator="\n")
    writer.writeheader()
    for b in rows:
        writer.writerow(b.row())
    atomic_write_text(path, buffer.getvalue())
