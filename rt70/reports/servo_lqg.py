"""The RT-70's LQG servo closed around the nonlinear model: factory, runs, linear prediction.

One job: put the LQG of :mod:`rt70.control.lqg` (designed for an RT-70 axis at a
pointing by :mod:`rt70.reports.servo_loops`: plant reduced to 16–20 states, the other
axis locked) into the servo scenarios of :mod:`rt70.telescope.scenarios` as a
:class:`rt70.control.lqg_drive.LqgDrive`, and compare it with its linear closed loop and with
the PI cascade, both closed around the nonlinear model in simulation.

- :func:`lqg_drives`: a :data:`rt70.telescope.scenarios.DriveFactory` with the LQG on the azimuth
  (where the PI cascade is held to 0.2 Hz) and the default factory's PI cascade on the
  elevation. The drive is the one the LQG was designed on
  (:func:`rt70.reports.servo_loops.drive_parameters`: the two motors' armatures in
  parallel, clamped at their rated voltage U_n; the PI factory takes them in series at
  2 U_n — the same machine, see :func:`rt70.telescope.scenarios.drive_parameters`). It starts
  holding the gravity torque with the controller at rest
  (:meth:`rt70.control.lqg_drive.LqgDrive.steady_controller`: the integral state carries the
  holding voltage).
- :func:`step_scenario`: an azimuth step of any size (small: the loop stays linear).
- :func:`linear_step`: the linear LQG closed loop's response to the same step
  (:func:`rt70.control.lqg.lqg_system` on the full linear plant).
"""

from __future__ import annotations

import control
import numpy as np

from rt70.control import lqg
from rt70.control.lqg_drive import LqgDrive
from rt70.reports import servo_loops as rs
from rt70.scenes.rt70_drives import AZIMUTH_DRIVE
from rt70.scenes.rt70_state import AZIMUTH_COORDINATE
from rt70.telescope.scenarios import DriveFactory, Scenario, servo_drives, servo_tolerances
from rt70.telescope.servo_metrics import settling_time
from rt70.units import ARCSEC_PER_DEG, RAD_PER_ARCSEC

#: Tracking time of the integral state's back-calculation, s: the LQR's integral time
#: (:data:`rt70.reports.servo_loops.LQG_WEIGHTS`).
TRACKING_TIME_S = rs.LQG_WEIGHTS.integral


def controller_parts(ctrl: lqg.LqgController) -> dict:
    """The LQG's matrices and anti-windup vectors for :class:`LqgDrive`.

    ``matrices`` ``(A_c, B_c, C_c, D_c)`` of ``ctrl.controller`` (inputs reference,
    :data:`rt70.control.lqg.MEASURED`); ``observer_input`` ``[B − L D; 0]`` of the
    (scaled) reduced plant at the voltage: how the voltage enters the Kalman filter;
    ``integral_states`` the last state, the integral of the angle error.
    """
    red, c = ctrl.reduced, ctrl.controller
    iu = list(red.input_labels).index("voltage")
    names = list(red.output_labels)
    im = [names.index(m) for m in lqg.MEASURED]
    b_u = red.B[:, iu] - ctrl.L @ red.D[im, iu]
    return {
        "matrices": (c.A, c.B, c.C, c.D),
        "measured": lqg.MEASURED,
        "observer_input": np.r_[b_u, 0.0],
        "integral_states": (c.nstates - 1,),
    }


def lqg_drives(
    elevation_deg: float,
    azimuth_deg: float = 0.0,
    weights: lqg.LqgWeights = rs.LQG_WEIGHTS,
    tracking_time: float = TRACKING_TIME_S,
) -> DriveFactory:
    """LQG on the azimuth (designed at the pointing), the default PI cascade on elevation.

    The LQG is designed by :func:`rt70.control.lqg.design` on
    :func:`rt70.reports.servo_loops.axis_plant` ``(scene, "azimuth", elevation_deg)``
    when the factory is called (about 1 s).

    Parameters
    ----------
    elevation_deg : float
        Elevation of the pointing the LQG is designed at, degrees.
    azimuth_deg : float, optional
        Azimuth of that pointing, degrees.
    weights : LqgWeights, optional
        The LQR and Kalman filter weights.
    tracking_time : float, optional
        ``T_t`` of the integral state's back-calculation (anti-windup), s.

    Returns
    -------
    DriveFactory
        ``(scene, q0, torques, references) -> [azimuth LQG drive, elevation PI drive]``.
    """
    pi = servo_drives()

    def build(scene, q0, torques, references):
        ap = rs.axis_plant(scene, "azimuth", elevation_deg, azimuth_deg)
        ctrl = lqg.design(ap, weights=weights)
        parts = controller_parts(ctrl)
        p = ap.parameters
        names = scene.coordinate_names
        angle = float(q0[names.index(AZIMUTH_COORDINATE)])
        hold = LqgDrive.holding(p, angle, torques[AZIMUTH_COORDINATE])
        # the controller at rest, its reference and measurements at the operating point,
        # its output the holding voltage R_a I
        xc = LqgDrive.steady_controller(parts["matrices"], np.zeros(3), p.R_a * hold[0])
        drive_atol = servo_tolerances(p)[:3]
        # each controller state to the accuracy of its share of the voltage: the
        # voltage that drives the tolerance's current through R_a
        volts = p.R_a * drive_atol[0]
        gain = np.abs(parts["matrices"][2][0])
        atol = np.r_[drive_atol, volts / np.maximum(gain, 1e-300)]
        azimuth = LqgDrive(
            AZIMUTH_DRIVE.name,
            names,
            AZIMUTH_COORDINATE,
            p,
            parts["matrices"],
            parts["measured"],
            references[AZIMUTH_COORDINATE],
            voltage_limit=AZIMUTH_DRIVE.motor.rated_voltage,  # armatures in parallel
            operating={"axis_angle": angle, "motor_angle": hold[1]},
            observer_input=parts["observer_input"],
            integral_states=parts["integral_states"],
            tracking_time=tracking_time,
            initial=np.r_[hold, xc],
            atol=atol,
        )
        elevation = [c for c in pi(scene, q0, torques, references) if c.index != azimuth.index]
        return [azimuth, *elevation]

    return build


def step_scenario(step_arcsec: float, elevation_deg: float = 45.0, t_end: float = 15.0) -> Scenario:
    """An azimuth step of ``step_arcsec`` at t = 0 from the pointing (a scenario).

    Parameters
    ----------
    step_arcsec : float
        Size of the azimuth step, ″ (positive or negative).
    elevation_deg : float, optional
        Elevation of the pointing, degrees (azimuth 0°).
    t_end : float, optional
        Length of the run, s.
    """
    deg = step_arcsec / ARCSEC_PER_DEG
    return Scenario(
        name="step-azimuth",
        elevation_deg=elevation_deg,
        azimuth_deg=0.0,
        t_end=t_end,
        azimuth=lambda t: deg,
        elevation=lambda t: 0.0,
        step_deg=(deg, 0.0),
    )


def linear_step(
    scene, step_arcsec: float, t: np.ndarray, elevation_deg: float = 45.0
) -> dict[str, np.ndarray]:
    """The linear LQG closed loop's azimuth step (full linear plant, elevation locked).

    Parameters
    ----------
    scene : Scene
        The control object, ``load_scene("rt70_servo")``.
    step_arcsec : float
        Size of the azimuth step, ″.
    t : ndarray, shape (n_t,)
        Times of the response, s, from 0.
    elevation_deg : float, optional
        Elevation of the pointing, degrees (azimuth 0°).

    Returns
    -------
    dict of str to ndarray, shape (n_t,)
        ``axis_arcsec`` (the axis angle's deviation, ″), ``voltage`` (V, deviation),
        ``current`` (A, deviation) on the times ``t``.
    """
    ap = rs.axis_plant(scene, "azimuth", elevation_deg)
    closed = lqg.lqg_system(ap, lqg.design(ap, weights=rs.LQG_WEIGHTS))
    keys = ["axis_angle", "voltage", "current"]
    y = np.asarray(control.step_response(closed[keys, "reference"], T=t).outputs).reshape(3, -1)
    y = y * step_arcsec * RAD_PER_ARCSEC
    return {"axis_arcsec": y[0] / RAD_PER_ARCSEC, "voltage": y[1], "current": y[2]}


def step_numbers(t: np.ndarray, axis_arcsec: np.ndarray, step_arcsec: float) -> dict[str, float]:
    """Settling to 1″ and overshoot (%) of an axis's step response (arc seconds).

    Parameters
    ----------
    t : ndarray, shape (n_t,)
        Times of the response, s.
    axis_arcsec : ndarray, shape (n_t,)
        The axis angle's deviation from the start, ″.
    step_arcsec : float
        Size of the step, ″ (not zero).

    Returns
    -------
    dict of str to float
        ``settle_1arcsec_s``: first time after which the error stays within 1″, s (NaN
        if never); ``overshoot_pct``: largest overshoot past the step, % of the step.
    """
    error = step_arcsec - axis_arcsec
    return {
        "settle_1arcsec_s": settling_time(t, error),
        "overshoot_pct": float(max(0.0, (-error * np.sign(step_arcsec)).max()) / abs(step_arcsec))
        * 100,
    }
