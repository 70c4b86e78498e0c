"""Servo scenarios on the scene's own drives: sector, start, hold, command line.

The module: rt70/telescope/scene_servo.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.linear.linearize import equilibrium, static_force
from rt70.model.scene import load_scene
from rt70.scenes.rt70_drives import AZIMUTH_DRIVE, ELEVATION_DRIVE
from rt70.scenes.rt70_state import rt70_pointing
from rt70.telescope import scenarios as S
from rt70.telescope.scene_servo import (
    SceneServoFactory,
    choose_drives,
    scene_equilibrium,
)
from rt70.testing import assert_close
from rt70.units import RAD_PER_ARCSEC

#: The sector's force has these components besides base_rx (rt70_servo at 45°).
SECTOR_COORDINATES = ("base_y", "base_z", "counterweight_y")


@pytest.fixture(scope="module")
def servo_scene():
    return load_scene("rt70_servo")


@pytest.fixture(scope="module")
def started(servo_scene):
    """The factory, its start at elevation 45° and its components."""
    factory = SceneServoFactory()
    held = rt70_pointing(45.0, 0.0)
    q0, torques = factory.start(servo_scene, held)
    refs = {c: (lambda t, v=v: v) for c, v in held.items()}
    return factory, q0, torques, factory(servo_scene, q0, torques, refs)


def test_elevation_drive_pushes_through_the_sector(servo_scene, started):
    """Q = K ∂θ_d/∂q has the sector's components; the encoder reads base_rx, not θ_d."""
    _, q0, torques, components = started
    names = servo_scene.coordinate_names
    el = next(c for c in components if c.names[0].startswith("elevation:"))
    Q = el.force(0.0, q0, np.zeros_like(q0), el.initial[:3])
    K = el.reducer_torque(q0, np.zeros_like(q0), el.initial[:3])
    assert_close(K, torques["base_rx"], rel=1e-9)
    for name in SECTOR_COORDINATES:  # a force on the counterweight, not a torque on base_rx
        assert abs(Q[names.index(name)]) > 1e-3 * abs(K)
    assert_close(Q[names.index("base_rx")], K, rel=1e-3)
    k = names.index("base_rx")
    assert el.encoder(q0) == q0[k]  # the coordinate itself, read
    assert abs(el.coupling.angle(q0) - q0[k]) > 10 * RAD_PER_ARCSEC  # the sag between them (45″)
    az = next(c for c in components if c.names[0].startswith("azimuth:"))
    Qa = az.force(0.0, q0, np.zeros_like(q0), az.initial[:3])
    assert np.count_nonzero(Qa) == 1 and Qa[names.index("platform_rz")] != 0.0


def test_start_is_the_equilibrium_with_the_sector_force(servo_scene, started):
    """Residual of the drives' equilibrium below 1e-9; the coordinate one is far from it."""
    factory, q0, torques, _ = started
    # relative to the weights' static force already: scale 1
    assert_close(factory.residual, 0.0, rel=1e-9, scale=1.0)  # measured 8.1e-12 … 4.8e-10
    held = rt70_pointing(45.0, 0.0)
    couplings = factory.couplings(servo_scene)
    q_coord = equilibrium(servo_scene, held, tol=S.EQUILIBRIUM_TOL)
    Q = static_force(servo_scene, q_coord)
    scale = np.abs(Q).max()
    G = np.column_stack([c.angle_gradient(q_coord)[1] for c in couplings])
    K = np.array([-Q[c.index] for c in couplings])
    off = np.abs(Q + G @ K).max() / scale  # the coordinate start under the sector's force
    assert off > 1e-3
    factory_90 = SceneServoFactory()
    _, zenith = factory_90.start(servo_scene, rt70_pointing(90.0, 0.0))  # no held torque
    assert_close(factory_90.residual, 0.0, rel=1e-9, scale=1.0)
    # no held torque at the zenith (measured 2.5e-11 N·m), on the size of the one at 45°
    assert_close(zenith["base_rx"], 0.0, rel=1e-9, scale=abs(torques["base_rx"]))
    with pytest.raises(Rt70Error, match="hold"):
        scene_equilibrium(servo_scene, couplings, {"platform_rz": 0.0})


def test_torque_limit_is_the_tables_for_either_lumping(started):
    """Parallel (scene) or series lumping: n T_peak i_r = 9.81e7 N·m on the axis."""
    _, _, _, components = started
    for c in components:
        g, p = c.g, c.p
        assert_close(g.current_limit * p.c_m * p.i_r, 9.80666e7, rel=1e-5)
        assert_close(g.voltage_limit, 440.0, rel=1e-6)
    for axis in (AZIMUTH_DRIVE, ELEVATION_DRIVE):
        p = S.drive_parameters(axis)  # the table's motors in series
        g = S.axis_gains(axis, 0.2, 5.0)
        assert_close(g.current_limit * p.c_m * p.i_r, 9.80666e7, rel=1e-5)
        assert_close(g.voltage_limit, 880.0, rel=1e-6)


def test_hold_from_the_start_does_not_move(servo_scene, started):
    """2 s hold at 45°: axis and pointing errors below 2e-6 of the gravity sag between the
    sector and the encoder, 45″ (measured 1.4e-7″ over 3 s).

    The pointing target is the equilibrium with the sector's force too (its start): from
    the coordinate equilibrium the same hold swings 16″ on the elevation encoder.
    """
    _, q0, _, components = started
    el = next(c for c in components if c.names[0].startswith("elevation:"))
    k = servo_scene.coordinate_names.index("base_rx")
    sag = abs(el.coupling.angle(q0) - q0[k]) / RAD_PER_ARCSEC  # the deflection the weights cause, ″
    run = S.run_scenario(servo_scene, S.scenario("hold", 45.0, 0.0, 2.0), SceneServoFactory())
    for axis in ("azimuth", "elevation"):
        error = run.axis_error[axis]
        assert_close(error, np.zeros_like(error), rel=2e-6, scale=sag, what=axis)
    total = run.pointing_error_total
    assert_close(total, np.zeros_like(total), rel=2e-6, scale=sag, what="pointing")


def test_hold_with_dry_friction_runs_and_holds(servo_scene):
    """The book's dry friction on both axes (zone 3·10⁻⁹ rad/s): a 10 s hold integrates
    and holds as the frictionless one does (it stopped 0.4 s in while the zone was
    differenced, rt70/simulation/coupling.py); the axes at rest dissipate no heat."""
    run = S.run_scenario(
        servo_scene, S.scenario("hold", 45.0, 0.0, 10.0), SceneServoFactory(friction=True)
    )
    sag = 45.0  # ″, the sector's deflection (the test above)
    for axis in ("azimuth", "elevation"):
        error = run.axis_error[axis]
        assert_close(error, np.zeros_like(error), rel=2e-6, scale=sag, what=axis)
        heat = run.result.states[f"{axis}_friction:dissipated"]
        assert np.all(np.isfinite(heat)) and heat.size == run.result.t.size
        assert_close(heat, np.zeros_like(heat), rel=1e-9, scale=1.0, what=f"{axis} heat, J")


def test_elevation_step_moves_toward_the_reference(servo_scene):
    """A 1° elevation step: 3 s of the rate-limited slew (0.18 °/s), the other axis still."""
    sc = S.scenario("step-elevation", 45.0, 0.0, 3.0)
    run = S.run_scenario(servo_scene, sc, SceneServoFactory())
    err = run.axis_error["elevation"]
    step = 3600.0  # ″
    assert_close(err[0], step, rel=1e-6)
    growth = np.maximum(np.diff(err), 0.0)  # the error only shrinks
    assert_close(growth, np.zeros_like(growth), rel=3e-10, scale=step)
    assert step - err[-1] > 0.4 * step  # ≥ 0.4° of the 0.54° a 3 s slew can do
    azimuth = run.axis_error["azimuth"]  # the other axis still
    assert_close(azimuth, np.zeros_like(azimuth), rel=3e-6, scale=step)


def test_choose_drives(servo_scene):
    assert choose_drives(servo_scene, None)[1] == "scene drives"
    assert choose_drives(servo_scene, "coordinate", friction=True)[1] == (
        "coordinate drives, dry friction"
    )
    factory, _ = choose_drives(servo_scene, "scene", friction=True)
    assert factory.friction
    with pytest.raises(Rt70Error, match="declares no servo: add an <rt70:servo>"):
        choose_drives(load_scene("rt70"), "scene")


def test_cli_drives_option(capsys):
    assert main(["simulate", "rt70_servo", "--t-end", "0.2"]) == 0
    assert "scene drives and servo holding" in capsys.readouterr().out
    assert main(["simulate", "rt70_servo", "--t-end", "0.2", "--drives", "coordinate"]) == 0
    assert "coordinate drives and servo holding" in capsys.readouterr().out
    for argv in (
        ["simulate", "rt70_servo", "--free-axes", "--drives", "scene"],
        ["simulate", "rt70", "--drives", "scene"],
        ["simulate", "three_masses", "--friction"],
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("rt70: error:")


def test_a_stopped_run_with_friction_names_what_to_try(servo_scene):
    """CVODE stops where the elevation breaks away after sticking (docs/servo-scenarios.md):
    the error says to try LSODA; without friction, or on LSODA, it adds nothing."""
    from rt70.control.friction import AxisFriction
    from rt70.scenes.rt70_drives import FRICTION

    names = servo_scene.coordinate_names
    friction = AxisFriction("f", names, "base_rx", FRICTION, 1e-9, "linear")
    assert "try --method LSODA" in S._friction_hint([friction], "CVODE")
    assert S._friction_hint([friction], "LSODA") == ""
    assert S._friction_hint([], "CVODE") == ""
