"""Backlash and the two counter-torqued gear trains (rt70.control.geartrains)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_drives import J_L, PARAMS, ROTOR  # the same rotor and drive as the DcDrive tests

from rt70.control.geartrains import (
    TwoTrainDrive,
    TwoTrainServo,
    backlash_torque,
    dead_zone,
    equivalent_drive,
    train_gains,
)
from rt70.control.servo import ServoDrive, cascade_gains
from rt70.errors import Rt70Error
from rt70.model.scene import scene_from_text
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close

#: Stiff enough for the rigid-axis cascade design (as tests/test_servo.py).
STIFF = replace(PARAMS, C_r=1e5, D_r=10.0)
STEP = np.radians(1.0)
B = 1e-3  # rad: a gap wide enough to see


def test_dead_zone_transmits_nothing_inside_the_gap():
    twists = np.linspace(-B, B, 101)
    assert not dead_zone(twists, B).any()
    for twist in twists:
        for rate in (-5.0, 0.0, 5.0):  # whatever the teeth's relative speed
            assert backlash_torque(twist, rate, 1e5, 10.0, B) == 0.0
    # outside: the spring of the twist past the flank, plus the damper (3B − B rounds
    # on the scale of 3B: 1e-14 of the result covers it)
    assert_close(backlash_torque(3 * B, 0.0, 1e5, 10.0, B), 1e5 * 2 * B, rel=1e-14)
    assert_close(backlash_torque(-3 * B, 0.0, 1e5, 10.0, B), -1e5 * 2 * B, rel=1e-14)
    assert_close(backlash_torque(3 * B, 1.0, 1e5, 10.0, B), 1e5 * 2 * B + 10.0, rel=1e-14)
    # in contact the teeth never pull: a fast separation gives zero, not a negative torque
    assert backlash_torque(1.5 * B, -1e3, 1e5, 10.0, B) == 0.0
    assert backlash_torque(-1.5 * B, 1e3, 1e5, 10.0, B) == 0.0
    # without a gap it is the linear reducer, of either sign
    assert_close(backlash_torque(B, -1e3, 1e5, 10.0, 0.0), 1e5 * B - 1e4, rel=1e-14)


def test_bad_drive_requests():
    with pytest.raises(Rt70Error, match="backlash"):
        TwoTrainDrive("d", ["axis"], "axis", PARAMS, backlash=-1.0)
    with pytest.raises(Rt70Error, match="no coordinate 'x'"):
        TwoTrainDrive("d", ["axis"], "x", PARAMS)
    with pytest.raises(Rt70Error, match="bias_torque"):
        TwoTrainServo("d", ["axis"], "axis", STIFF, train_gains(STIFF, J_L), abs, bias_torque=-1)


def _step(component, t, rtol=1e-10):
    scene = scene_from_text(ROTOR, "rotor")
    return simulate(
        scene, (t[0], t[-1]), components=[component], t_eval=t, method="BDF",
        rtol=rtol, atol=1e-12,
    )  # fmt: skip


def test_pair_without_gap_or_bias_is_the_servo_drive():
    """No backlash, no bias: the two trains are the series equivalent of one drive closed
    by the same cascade. At random states (each motor in the equivalent drive's state) the
    pair's rates, integrator rates and force equal ServoDrive's to rounding."""
    names = scene_from_text(ROTOR, "rotor").coordinate_names
    eq = equivalent_drive(STIFF)
    one = ServoDrive("one", names, "axis", eq, cascade_gains(eq, J_L, current_limit=3.0,
                     rate_limit=0.5, voltage_limit=40.0), lambda s: STEP)  # fmt: skip
    gains = train_gains(STIFF, J_L, current_limit=3.0, rate_limit=0.5, voltage_limit=40.0)
    two = TwoTrainServo("two", names, "axis", STIFF, gains, lambda s: STEP)
    rng = np.random.default_rng(10)
    for _ in range(50):  # inside and beyond the limits
        q, qd = rng.normal(0, 0.02, 1), rng.normal(0, 0.5, 1)
        x = rng.normal(0, [2.0, 1.0, 5.0, 0.01, 0.1, 0.05])  # I, α_m, ω_m, ∫e_p, ∫e_v, ∫e_i
        y = np.concatenate([x[:3], x[:3], x[3:], x[5:]])
        ds1, ds2 = one.derivative(0.0, q, qd, x, None), two.derivative(0.0, q, qd, y, None)
        for k in (0, 3):
            assert_close(ds2[k : k + 3], ds1[:3], rel=1e-12, what=f"train {k // 3 + 1}")
        assert_close(ds2[6:], ds1[[3, 4, 5, 5]], rel=1e-12, what="integrators")
        assert_close(two.force(0.0, q, qd, y)[0], one.force(0.0, q, qd, x)[0], rel=1e-12)


@pytest.mark.slow
def test_counter_torque_keeps_both_trains_engaged():
    """Backlash in both trains, a bias of 10 N·m per train: through a 1° step (peak net
    torque 13.6 N·m, below twice the bias) train 1 always pushes and train 2 always holds back,
    both past their gap; the force on the axis is their sum; the step is made."""
    names = scene_from_text(ROTOR, "rotor").coordinate_names
    bias = 10.0  # N·m per train on the axis (2 A of bias current)
    drive = TwoTrainServo(
        "two", names, "axis", STIFF, train_gains(STIFF, J_L), lambda s: STEP, backlash=B,
        bias_torque=bias, atol=np.full(10, 1e-9),
    )  # fmt: skip
    drive.initial = np.concatenate([drive.bias_state(0.0, bias), np.zeros(4)])
    # the two trains' states are mirror images: their torques cancel exactly
    assert sum(drive.train_torques(np.zeros(1), np.zeros(1), drive.initial)) == 0.0
    t = np.linspace(0.0, 1.5, 301)
    run = _step(drive, t, rtol=1e-7)
    s = np.array([run.states[n] for n in drive.names]).T
    p = STIFF
    twists = np.array(
        [[x[3 * j + 1] / p.i_r - q[0] for j in (0, 1)] for q, x in zip(run.q, s, strict=True)]
    )
    taus = np.array(
        [drive.train_torques(q, v, x) for q, v, x in zip(run.q, run.qd, s, strict=True)]
    )
    net = taus.sum(axis=1)
    assert np.abs(net).max() < 2 * bias  # the step stays within the bias ...
    assert np.abs(net).max() > 0.3 * bias  # ... but uses a good part of it
    assert (twists[:, 0] > B).all() and (twists[:, 1] < -B).all()  # both always engaged
    assert (taus[:, 0] > 0).all() and (taus[:, 1] < 0).all()
    forces = np.array(
        [drive.force(0.0, q, v, x)[0] for q, v, x in zip(run.q, run.qd, s, strict=True)]
    )
    assert np.array_equal(forces, net)  # force sums the same train_torques
    # the gap is invisible and the bias cancels: the motion is the pair's without either
    linear = TwoTrainServo(
        "lin", names, "axis", STIFF, train_gains(STIFF, J_L), lambda s: STEP,
        atol=np.full(10, 1e-9),
    )  # fmt: skip
    assert_close(_step(linear, t, rtol=1e-7).q, run.q, rel=1e-5, scale=STEP)


@pytest.mark.slow
def test_without_bias_the_gap_is_crossed():
    """The same step without bias: the trains leave contact (torque zero inside the gap) on
    the way: what the bias prevents."""
    names = scene_from_text(ROTOR, "rotor").coordinate_names
    drive = TwoTrainServo(
        "two", names, "axis", STIFF, train_gains(STIFF, J_L), lambda s: STEP, backlash=B,
        atol=np.full(10, 1e-9),
    )  # fmt: skip
    t = np.linspace(0.0, 1.5, 301)
    run = _step(drive, t, rtol=1e-6)
    s = np.array([run.states[n] for n in drive.names]).T
    taus = np.array(
        [drive.train_torques(q, v, x) for q, v, x in zip(run.q, run.qd, s, strict=True)]
    )
    assert (taus[:, 0] == 0.0).sum() > 10  # some time with no contact at all
    assert (taus[:, 0] > 0).any() and (taus[:, 0] < 0).any()  # both flanks are used
