"""A small step on one axis, nonlinear and linear: how far the linear closed loop holds.

One job: run a step of a few arc seconds — small enough that no loop clamps — on one axis
with the scene's own servo, once on the nonlinear model
(:func:`rt70.telescope.scenarios.run_scenario`, the scene's drives) and once on the linear
closed loop about the drive-held equilibrium (:func:`rt70.control.scene_loop.closed_loop`,
the same drives, gains and encoders), and report the largest difference of the axis's
angle over the run, relative to the step, with the settling time each gives. It says how
far the linear model a servo engineer designs on stands for the structure the
simulation runs.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import control
import numpy as np

from rt70.control.scene_loop import closed_loop
from rt70.model.antenna import pointing
from rt70.model.scene import Scene
from rt70.telescope.axis_servos import axis_servos
from rt70.telescope.drive_equilibrium import drive_held_linearization
from rt70.telescope.scenario import scenario
from rt70.telescope.servo_metrics import settling_time

#: The step, arc seconds: far inside every loop's linear range.
STEP_ARCSEC = 20.0


@dataclass(frozen=True)
class StepCheck:
    """A small step's nonlinear and linear responses and how they differ.

    Attributes
    ----------
    axis : str
        The stepped axis.
    step_arcsec : float
        The step.
    t : numpy.ndarray
        Sample times, s.
    nonlinear, linear : numpy.ndarray
        The axis angle's offset from its start, arcsec.
    difference : float
        ``max |nonlinear − linear| / step``.
    settle_nonlinear_s, settle_linear_s : float
        When each comes to stay within :data:`rt70.telescope.servo_metrics.BAND_ARCSEC`
        of the step, s (NaN if not by the end).
    """

    axis: str
    step_arcsec: float
    t: np.ndarray
    nonlinear: np.ndarray
    linear: np.ndarray
    difference: float
    settle_nonlinear_s: float
    settle_linear_s: float


def small_step(
    scene: Scene, axis: str, elevation_deg: float, t_end: float, step_arcsec: float = STEP_ARCSEC
) -> StepCheck:
    """Step ``axis`` by ``step_arcsec`` at ``elevation_deg`` for ``t_end`` s, both ways.

    Parameters
    ----------
    scene : Scene
        A scene whose axes declare their servos (on its ``<rt70:drive>`` elements).
    axis : {"azimuth", "elevation"}
        The axis stepped.
    elevation_deg : float
        The start pointing's elevation (azimuth 0), degrees.
    t_end : float
        The run's length, s.
    step_arcsec : float
        The step, arc seconds.
    """
    from rt70.telescope.scenarios import run_scenario
    from rt70.telescope.scene_servo import SceneServoFactory, scene_servos

    deg = step_arcsec / 3600.0
    base = scenario(f"step-{axis}", elevation_deg, 0.0, t_end)
    steps = (deg, 0.0) if axis == "azimuth" else (0.0, deg)
    sc = replace(base, **{axis: lambda t: deg}, step_deg=steps)
    run = run_scenario(scene, sc, drives=SceneServoFactory())
    t = run.result.t
    nonlinear = step_arcsec - run.axis_error[axis]
    lm = drive_held_linearization(scene, pointing(scene, elevation_deg, 0.0))
    loop = closed_loop(scene, lm, {}, [], scene_servos(scene))
    drive = axis_servos(scene)[axis].drive.name
    response = control.step_response(loop[f"{drive}_encoder", f"{drive}_reference"], T=t)
    linear = step_arcsec * np.asarray(response.outputs, dtype=float).reshape(-1)
    return StepCheck(
        axis,
        step_arcsec,
        t,
        nonlinear,
        linear,
        float(np.max(np.abs(nonlinear - linear)) / step_arcsec),
        settling_time(t, step_arcsec - nonlinear),
        settling_time(t, step_arcsec - linear),
    )
