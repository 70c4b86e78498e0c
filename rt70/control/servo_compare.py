"""Measure a closed servo loop: the numbers a servo engineer compares between controllers.

One job: measure a closed servo loop around the full linear plant — bandwidth and
resonant peak (reference → axis angle), the step's overshoot and 2 % settling time,
and the pointing error under a step of disturbance torque (e.g. the RT-70 book's
nominal wind torque, 5·10⁵ kgf·m) — the same way for any controller
(:func:`rt70.control.loops.cascade_system`, :func:`rt70.control.lqg.lqg_system`).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from rt70.control import loop_measures
from rt70.control.axis_plant import POINTING
from rt70.units import ARCSEC_PER_RAD

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
        Axis-angle error under a step of the wind torque: largest and at the end.
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


def performance(
    closed: control.StateSpace, wind_torque: float, times: np.ndarray = TIMES
) -> Performance:
    """Measure a closed loop around the full plant (see :class:`Performance`).

    Parameters
    ----------
    closed : control.StateSpace
        The closed loop, with the inputs ``reference`` (rad) and ``wind_torque`` (N·m)
        and the outputs ``axis_angle`` (rad) and :data:`rt70.control.axis_plant.POINTING`
        (arc seconds).
    wind_torque : float
        The size of the disturbance step, N·m.
    times : numpy.ndarray
        The time grid of the step responses, s, from 0.
    """
    T = closed["axis_angle", "reference"]
    mag = np.abs(loop_measures.siso_response(T))
    step = control.step_response(T, T=times)
    info = control.step_info(
        np.asarray(step.outputs).reshape(-1), times, SettlingTimeThreshold=0.02
    )
    wind = control.step_response(closed[["axis_angle", *POINTING], "wind_torque"], T=times)
    y = np.asarray(wind.outputs).reshape(3, -1) * wind_torque
    axis = np.abs(y[0]) * ARCSEC_PER_RAD
    pointing = np.hypot(y[1], y[2])  # the pointing outputs are in arc seconds
    return Performance(
        bandwidth_hz=loop_measures.bandwidth_hz(T),
        peak_db=float(20 * np.log10(mag.max())),
        overshoot_pct=float(info["Overshoot"]),
        settling_s=float(info["SettlingTime"]),
        wind_axis_peak_arcsec=float(axis.max()),
        wind_axis_final_arcsec=float(axis[-1]),
        wind_pointing_peak_arcsec=float(pointing.max()),
        wind_pointing_final_arcsec=float(pointing[-1]),
        stable=loop_measures.stable(closed),
    )
