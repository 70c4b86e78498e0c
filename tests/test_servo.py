"""The current-rate-position cascade (rt70.control.servo) closing a DC drive on a rotor."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_drives import J_L, PARAMS, ROTOR  # the same rotor and drive

from rt70.control.servo import ServoDrive, cascade_gains
from rt70.errors import Rt70Error
from rt70.model.scene import scene_from_text
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close

STEP = np.radians(1.0)
#: A reducer stiff enough that the rotor's resonance (√(C_r/J_l) = 36 Hz) lies above the
#: loops: the rigid-axis design of cascade_gains holds.
STIFF = replace(PARAMS, C_r=1e5, D_r=10.0)


def _step_run(gains, t_end=4.0):
    scene = scene_from_text(ROTOR, "rotor")
    servo = ServoDrive("az", scene.coordinate_names, "axis", STIFF, gains, lambda t: STEP)
    t = np.linspace(0.0, t_end, 801)
    run = simulate(scene, (0.0, t_end), components=[servo], t_eval=t, method="Radau", rtol=1e-8)
    return t, run


@pytest.mark.slow
def test_one_degree_step_settles_without_error():
    """1° step, 1 Hz position loop: 10 % overshoot, 2 % band in 2.0 s, error decaying.

    Measured: overshoot 0.105, settling to 2 % at 1.99 s, error 1.8e-5 of the step at
    6 s (the position integrator's slow tail).
    """
    gains = cascade_gains(STIFF, J_L, position_hz=1.0)
    t, run = _step_run(gains, t_end=6.0)
    angle = run.q[:, 0]
    assert run.success
    assert_close(angle[-1], STEP, rel=1e-4)  # the integrators remove the error
    overshoot = (angle.max() - STEP) / STEP
    assert 0.0 <= overshoot < 0.25
    # settling to 2 % within a few time constants of a 1 Hz loop
    outside = np.flatnonzero(np.abs(angle - STEP) > 0.02 * STEP)
    settle = t[outside[-1] + 1]
    assert 0.5 < settle < 2.5, settle


@pytest.mark.slow
def test_slower_position_loop_settles_later():
    """The bandwidth sets the speed: a 0.5 Hz loop settles later than a 1 Hz loop."""

    def settling(hz):
        t, run = _step_run(cascade_gains(STIFF, J_L, position_hz=hz), t_end=6.0)
        outside = np.flatnonzero(np.abs(run.q[:, 0] - STEP) > 0.02 * STEP)
        return t[outside[-1] + 1]

    assert settling(0.5) > 1.5 * settling(1.0)


@pytest.mark.slow
def test_rate_limit_clamps_the_axis_speed():
    """With the axis rate clamped, the step becomes a ramp at the limit (anti-windup)."""
    limit = 0.2 * STEP  # rad/s: the 1° step takes about 5 s
    gains = cascade_gains(STIFF, J_L, position_hz=1.0, rate_limit=limit)
    t, run = _step_run(gains, t_end=8.0)
    speed = run.qd[:, 0]
    ramp = (t > 1.0) & (t < 4.0)  # after the rate loop's step response, before arrival
    assert_close(speed[ramp], np.full(ramp.sum(), limit), rel=0.02)  # the clamped reference
    assert speed.max() < 1.2 * limit  # the rate loop's own overshoot on its reference step
    assert_close(run.q[-1, 0], STEP, rel=1e-3)  # and still arrives


def test_bad_gains_request():
    with pytest.raises(Rt70Error, match="position_hz"):
        cascade_gains(STIFF, J_L, position_hz=0.0)
