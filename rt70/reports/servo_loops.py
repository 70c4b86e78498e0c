"""The RT-70's servo loops in frequency analysis: its axis plants, PI cascade against LQG.

One job: put the RT-70 into the generic servo analyses (:mod:`rt70.control.axis_plant`,
:mod:`rt70.control.loops`, :mod:`rt70.control.lqg`, :mod:`rt70.control.servo_compare`):
its axis plants at a pointing on the ``rt70_servo`` scene, its drives (docs/drives.md),
its wind torque, and the designs compared (:func:`compare`, used by validation/servo_loops.py).

- :func:`axis_plant`: the structure linearised at :func:`rt70.linear.linearize.equilibrium`
  of :func:`rt70.scenes.rt70_state.rt70_pointing`, the driven axis free and the other
  locked; the disturbance a torque about the axis on the main mirror
  (:func:`wind_wrench`); the pointing output the corrections Δα, Δβ (4.159)–(4.163) of
  :func:`rt70.scenes.rt70_optics.rt70_mirror_outputs`, in arc seconds; joined to the
  axis's drive (:func:`drive_parameters`).
- The elevation drive's torque enters as a torque on the elevation coordinate
  ``base_rx`` (between the platform and the swinging part), not yet as the gear
  sector's force on the counterweight (4.150).
"""

from __future__ import annotations

from dataclasses import asdict, replace

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control import loop_measures, loops, lqg
from rt70.control.axis_plant import AxisPlant, connect_drive, structure_plant
from rt70.control.geartrains import parallel_drive
from rt70.control.servo_compare import performance
from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.model.scene import Scene
from rt70.physics.loads import Wrench
from rt70.scenes.rt70_drives import DRIVES, WIND_TORQUE, AxisDrive
from rt70.scenes.rt70_optics import rt70_mirror_outputs
from rt70.scenes.rt70_state import AZIMUTH_COORDINATE, ELEVATION_COORDINATE, rt70_pointing

#: The driven coordinate of each axis.
AXIS_COORDINATES = {"azimuth": AZIMUTH_COORDINATE, "elevation": ELEVATION_COORDINATE}
#: The cascade's design position bandwidth, Hz: below the largest with GM ≥ 6 dB and
#: PM ≥ 30° in every loop on both axes at 10°, 45° and 80°, 0.172 Hz (bisection in
#: validation/servo_loops.py; the azimuth at 10° limits it), rounded down.
CASCADE_POSITION_HZ = 0.15
#: The LQG's weights: an axis-angle error of 1e-3 rad costs as much as 440 V, integral
#: time 3 s (about 1 Hz closed-loop bandwidth, as the DSN's LQG, antenna-servo.md).
LQG_WEIGHTS = lqg.LqgWeights(angle=1e-3, integral=3.0)


def drive_parameters(axis: AxisDrive, load_inertia: float) -> DriveParameters:
    """The axis's drive as one equivalent motor and its reducer (docs/drives.md).

    The ``n = motors_per_axis`` identical motors drive one reducer; with their
    armatures in parallel on one voltage they are one motor of ``L_a/n``, ``R_a/n``,
    ``n J_m``, ``n D_m`` and the same ``c_m``, ``c_e`` (n times the current, n times the
    torque). C_r and D_r are the axis's totals (axis-referred).

    Parameters
    ----------
    axis : AxisDrive
        ``rt70.scenes.rt70_drives.AZIMUTH_DRIVE`` or ``ELEVATION_DRIVE``.
    load_inertia : float
        J_l, kg·m²: the rigid structure about the axis (the servo design's load).
    """
    return parallel_drive(axis.motor_parameters(load_inertia), axis.motors_per_axis)


def wind_wrench(axis: str, azimuth_deg: float) -> Wrench:
    """A unit torque (N·m) about the axis, on the main mirror: the wind's moment on the dish.

    Azimuth: about the ground z axis; elevation: about the elevation bearing, the
    platform's x axis turned by the azimuth (``Rz(A) e_x``).
    """
    if axis == "azimuth":
        direction = np.array([0.0, 0.0, 1.0])
    else:
        a = np.radians(azimuth_deg)
        direction = np.array([np.cos(a), np.sin(a), 0.0])
    return Wrench("main_mirror", np.zeros(3), force=np.zeros(3), torque=direction)


def axis_plant(
    scene: Scene, axis: str, elevation_deg: float, azimuth_deg: float = 0.0
) -> AxisPlant:
    """The linear plant of one RT-70 axis (drive + structure) at a pointing.

    Parameters
    ----------
    scene : Scene
        The control object, ``load_scene("rt70_servo")``.
    axis : {"azimuth", "elevation"}
        The driven axis (the other one is locked).
    elevation_deg, azimuth_deg : float
        The pointing (:func:`rt70.scenes.rt70_state.rt70_pointing`).
    """
    if axis not in AXIS_COORDINATES:
        raise Rt70Error(f"unknown axis '{axis}' (azimuth or elevation)")
    coordinate = AXIS_COORDINATES[axis]
    other = tuple(c for c in AXIS_COORDINATES.values() if c != coordinate)
    q0 = lin.equilibrium(scene, rt70_pointing(elevation_deg, azimuth_deg))
    optics = {o.name: o for o in rt70_mirror_outputs(scene, elevation_deg, azimuth_deg)}
    pointing = replace(optics["pointing_correction"], name="pointing")
    structure, load_inertia = structure_plant(
        scene, q0, coordinate, wind_wrench(axis, azimuth_deg), pointing, locked=other
    )
    p = drive_parameters(DRIVES[axis], load_inertia)
    system = connect_drive(structure, p)
    return AxisPlant(system, structure, p, axis, elevation_deg, azimuth_deg, q0)


def compare(
    scene: Scene,
    axis: str,
    elevation_deg: float,
    position_hz: float = CASCADE_POSITION_HZ,
    weights: lqg.LqgWeights = LQG_WEIGHTS,
) -> dict:
    """Cascade and LQG on one plant: margins, bandwidths, step and wind numbers (a dict).

    The LQG is designed on :func:`rt70.control.lqg.reduce_plant` of the plant and checked
    on the full plant; its margins are at the plant input (the armature voltage). The
    wind step is the book's nominal wind torque (``WIND_TORQUE``, 5·10⁵ kgf·m).

    Parameters
    ----------
    scene : Scene
        The control object, ``load_scene("rt70_servo")``.
    axis : {"azimuth", "elevation"}
        The driven axis (the other one is locked).
    elevation_deg : float
        Elevation of the pointing, degrees (azimuth 0°).
    position_hz : float, optional
        The cascade's position-loop bandwidth, Hz.
    weights : LqgWeights, optional
        The LQR and Kalman filter weights of the LQG.
    """
    ap = axis_plant(scene, axis, elevation_deg)
    cascade = loops.analyse_cascade(ap, position_hz)
    ctrl = lqg.design(ap, weights=weights)
    closed_cascade = loops.cascade_system(ap, cascade.gains)
    return {
        "axis": axis,
        "elevation_deg": elevation_deg,
        "plant_states": ap.system.nstates,
        "reduced_states": ctrl.reduced.nstates,
        "cascade": {
            "position_hz": position_hz,
            "margins": {k: asdict(m) for k, m in cascade.margins.items()},
            **asdict(performance(closed_cascade, WIND_TORQUE)),
        },
        "lqg": {
            "input_margins": asdict(loop_measures.margins(lqg.input_loop(ap, ctrl))),
            **asdict(performance(lqg.lqg_system(ap, ctrl), WIND_TORQUE)),
        },
    }
