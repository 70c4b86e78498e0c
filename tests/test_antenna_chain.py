"""The whole chain on a generated antenna whose names share nothing with the RT-70.

``rt70 new antenna``'s generator (:mod:`rt70.scenes.antenna`) writes a 9-m Cassegrain
antenna with no servo bandwidth; the chain runs on it as a user would: validate, modes,
the plant, the servo tuned on its own model, the pointing budget under wind, a step, a
small step against the linear closed loop, and a two-point sweep.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.crosscheck.validate import cross_check
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.antenna import pointing
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes.antenna import AntennaSpec, antenna_urdf
from rt70.sweep import run as sw
from rt70.telescope import scenarios as S
from rt70.telescope.pointing import PointingCase, pointing_budget
from rt70.telescope.scene_servo import choose_drives
from rt70.telescope.servo_design import design
from rt70.telescope.step_check import small_step
from rt70.testing import assert_close

#: A 9-m antenna: 7 Hz locked rotor on both axes, 5 and 2.5 °/s, elevation 5–88°.
SPEC = AntennaSpec(
    name="dish_9m",
    diameter=9.0,
    elevation_mass=30e3,
    azimuth_mass=35e3,
    locked_rotor_hz=(7.0, 7.0),
    rate_limit_deg_s=(5.0, 2.5),
    acceleration_deg_s2=(6.0, 6.0),
    elevation_range_deg=(5.0, 88.0),
    design_wind=15.0,
)


@pytest.fixture(scope="module")
def dish(tmp_path_factory):
    path = tmp_path_factory.mktemp("antenna") / "dish_9m.urdf"
    path.write_text(antenna_urdf(SPEC), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def scene(dish):
    return load_scene(dish)


def _names(scene) -> set[str]:
    d = scene.description
    return set(d.links) | {j.name for j in d.joints} | {p.name for p in d.optical_points}


def test_its_names_share_nothing_with_the_rt70(scene):
    rt70 = set()
    for name in ("rt70", "rt70_servo", "rt70_jack"):
        rt70 |= _names(load_scene(name))
    assert _names(scene) & rt70 == {"world"}


def test_both_sides_agree(scene):
    records = cross_check(scene, samples=2, repeat=1)
    assert records and all(r.passed() for r in records)


def test_its_locked_rotor_frequencies_are_the_targets(scene):
    q0 = lin.equilibrium(scene, pointing(scene, 45.0))
    lm = lin.locked_rotor(scene, lin.linearize(scene, q0))
    freqs = modal.modes(lm.M, lm.K).freq_hz
    # the hubs between reducer and structure take a little: within 10 % of 7 Hz
    assert_close(freqs[:2], [7.0, 7.0], rel=0.1)


def test_its_servo_is_tuned_on_its_own_model(scene):
    result = design(scene)
    assert all(result.tuned.values()) and result.stable and result.adequate
    for axis, loops in result.margins.items():
        for loop, m in loops.items():
            assert m.gm_db >= 6.0 and m.pm_deg >= 30.0, (axis, loop, m)
    # a 7 Hz locked rotor allows a position loop of a few tenths of it, not more
    for hz, _ in result.tuning.values():
        assert 0.3 < hz < 3.5


def test_its_pointing_error_is_quadratic_in_the_wind(scene):
    steady = [
        pointing_budget(scene, PointingCase(30.0, 0.0, v, 0.0)).steady["main_mirror_error"]
        for v in (10.0, 20.0)
    ]
    assert steady[0] > 0.0
    # quadratic but for the wind's change with the deformation it causes: the dish turns
    # by ~1e-5 rad, its coefficients change by that times their slope (measured 2.5e-5)
    assert_close(steady[1] / steady[0], 4.0, rel=1e-4)


def test_a_one_degree_step_settles_as_its_bandwidth_predicts(scene):
    drives, _ = choose_drives(scene, None)
    run = S.run_scenario(scene, S.scenario("step-elevation", 45.0, 0.0, 6.0), drives=drives)
    m = run.metrics
    assert math.isfinite(m["axis_settle_s"]) and math.isfinite(m["predicted_settle_s"])
    assert 0.5 < m["axis_settle_s"] / m["predicted_settle_s"] < 1.5
    assert m["final_pointing_arcsec"] < 1.0


def test_its_linear_closed_loop_agrees_with_the_simulation(scene):
    for axis in ("azimuth", "elevation"):
        check = small_step(scene, axis, 45.0, 3.0)
        assert check.difference < 1e-3, (axis, check.difference)


def test_a_two_point_sweep(dish):
    grid = sw.make_grid({"elevation": (10.0, 80.0)})
    sweep = sw.plan(dish, grid, ["first_frequency", "sag"])
    result = sw.run(sweep, sw.serial)
    assert not result.errors
    assert np.isfinite(result.arrays["first_frequency"]).all()
    assert np.isfinite(result.arrays["sag"]).all()


def test_the_command_line_writes_and_runs_it(dish, tmp_path, capsys):
    out = tmp_path / "mine.urdf"
    argv = [
        "new", "antenna", "--name", "mine", "--diameter", "9", "--masses", "35000,30000",
        "--locked-rotor", "7", "--rate", "5,2.5", "--acceleration", "6",
        "--elevation-range", "5,88", "--wind", "15", "--bandwidth", "1.2,1.3", "--out", str(out),
    ]  # fmt: skip
    assert main(argv) == 0
    mine = scene_from_text(out.read_text(encoding="utf-8"), "mine")
    assert [a.servo.position_bandwidth_hz for a in mine.description.mount.axes] == [1.2, 1.3]
    assert main(["modes", str(out), "--elevation", "30"]) == 0
    assert main(["servo", str(dish)]) == 0  # the design of the fixture's text, kept
    text = capsys.readouterr().out
    assert "tuned on the model" in text and "stable" in text


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--diameter", "-9"], "--diameter"),
        (["--masses", "1,2,3"], "AZ,EL"),
        (["--elevation-range", "80,10"], "is not below"),
        (["--out", "mine.txt"], ".urdf"),
        (["--name", "bad name"], "name"),
    ],
)
def test_bad_options_are_one_line(argv, message, tmp_path, capsys):
    base = {
        "--name": "mine", "--diameter": "9", "--masses": "35000,30000", "--locked-rotor": "7",
        "--rate": "5", "--acceleration": "6", "--out": str(tmp_path / "mine.urdf"),
    }  # fmt: skip
    base.update(dict(zip(argv[::2], argv[1::2], strict=True)))
    args = ["new", "antenna", *[x for kv in base.items() for x in kv]]
    try:
        code = main(args)
    except SystemExit as exc:
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "mine.urdf").exists()
