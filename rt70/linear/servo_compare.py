"""The PI cascade against the LQG servo on one RT-70 axis: the numbers a servo engineer compares.

One job: measure a closed servo loop around the full linear plant — bandwidth and
resonant peak (reference → axis angle), the step's overshoot and 2 % settling time,
and the pointing error under the book's nominal wind torque (5·10⁵ kgf·m, applied as a
step about the axis on the main mirror) — the same way for both controllers
(:func:`rt70.linear.loops.cascade_system`, :func:`rt70.linear.lqg.lqg_system`), and
collect them per axis and elevation (:func:`compare`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import control
import numpy as np

from rt70.linear import loops, lqg
from rt70.scene import Scene
from rt70.scenes.rt70_drives import WIND_TORQUE

#: Arc seconds per radian.
ARCSEC_PER_RAD = 180.0 * 3600.0 / np.pi
#: Time grid of the step and wind responses, s.
TIMES = np.linspace(0.0, 40.0, 4001)


@dataclass(frozen=True)
class Performance:
    """A closed servo loop measured on the full linear plant.

    Attributes
    ----------
    bandwidth_hz : float
        −3 dB frequency of reference → axis angle.
    peak_db : float
        Largest ``|T|`` of reference → axis angle, dB.
    overshoot_pct, settling_s : float
        Of the unit step in reference (2 % band).
    wind_axis_peak_arcsec, wind_axis_final_arcsec : float
        Axis-angle error under a step of the nominal wind torque: largest and at the end.
    wind_pointing_peak_arcsec, wind_pointing_final_arcsec : float
        The pointing correction's magnitude ``|(Δα, Δβ)|`` under the same step.
    stable : bool
        All closed-loop poles in the left half-plane.
    """

    bandwidth_hz: float
    peak_db: float
    overshoot_pct: float
    settling_s: float
    wind_axis_peak_arcsec: float
    wind_axis_final_arcsec: float
    wind_pointing_peak_arcsec: float
    wind_pointing_final_arcsec: float
    stable: bool


def performance(closed: control.StateSpace, times: np.ndarray = TIMES) -> Performance:
    """Measure a closed loop around the full plant (see :class:`Performance`).

    ``closed`` has the inputs ``reference``, ``wind_torque`` and the outputs
    ``axis_angle`` and :data:`rt70.linear.loops.POINTING`.
    """
    T = closed["axis_angle", "reference"]
    mag = np.abs(loops.frequency_response(T))
    step = control.step_response(T, T=times)
    info = control.step_info(
        np.asarray(step.outputs).reshape(-1), times, SettlingTimeThreshold=0.02
    )
    wind = control.step_response(closed[["axis_angle", *loops.POINTING], "wind_torque"], T=times)
    y = np.asarray(wind.outputs).reshape(3, -1) * WIND_TORQUE
    axis = np.abs(y[0]) * ARCSEC_PER_RAD
    pointing = np.hypot(y[1], y[2])  # the pointing outputs are in arc seconds
    return Performance(
        bandwidth_hz=loops.bandwidth_hz(T),
        peak_db=float(20 * np.log10(mag.max())),
        overshoot_pct=float(info["Overshoot"]),
        settling_s=float(info["SettlingTime"]),
        wind_axis_peak_arcsec=float(axis.max()),
        wind_axis_final_arcsec=float(axis[-1]),
        wind_pointing_peak_arcsec=float(pointing.max()),
        wind_pointing_final_arcsec=float(pointing[-1]),
        stable=loops.stable(closed),
    )


#: The cascade's design position bandwidth, Hz: the largest with GM ≥ 6 dB and PM ≥ 30°
#: in every loop on both axes at 10°, 45° and 80° (validation/servo_loops.py measures it
#: by bisection: 0.176 Hz; rounded down).
CASCADE_POSITION_HZ = 0.15
#: The LQG's weights: an axis-angle error of 1e-3 rad costs as much as 440 V, integral
#: time 3 s (gives
#: about 1 Hz closed-loop bandwidth, as DSN's LQG).
LQG_WEIGHTS = lqg.LqgWeights(angle=1e-3, integral=3.0)


def compare(
    scene: Scene,
    axis: str,
    elevation_deg: float,
    position_hz: float = CASCADE_POSITION_HZ,
    weights: lqg.LqgWeights = LQG_WEIGHTS,
) -> dict:
    """Cascade and LQG on one plant: margins, bandwidths, step and wind numbers (a dict).

    The LQG is designed on :func:`rt70.linear.lqg.reduce_plant` of the plant and checked
    on the full plant; its margins are at the plant input (the armature voltage).
    """
    ap = loops.axis_plant(scene, axis, elevation_deg)
    cascade = loops.analyse_cascade(ap, position_hz)
    ctrl = lqg.design(ap, weights=weights)
    return {
        "axis": axis,
        "elevation_deg": elevation_deg,
        "plant_states": ap.system.nstates,
        "reduced_states": ctrl.reduced.nstates,
        "cascade": {
            "position_hz": position_hz,
            "margins": {k: asdict(m) for k, m in cascade.margins.items()},
            **asdict(performance(loops.cascade_system(ap, cascade.gains))),
        },
        "lqg": {
            "input_margins": asdict(loops.margins(lqg.input_loop(ap, ctrl))),
            **asdict(performance(lqg.lqg_system(ap, ctrl))),
        },
    }
