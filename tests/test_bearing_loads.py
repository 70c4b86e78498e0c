"""The RT-70's bearing and reducer loads (rt70.telescope.bearing_loads) and ``rt70 reactions``."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.model.scene import load_scene
from rt70.telescope import bearing_loads as bl
from rt70.telescope.scenarios import EQUILIBRIUM_TOL
from rt70.testing import assert_close


@pytest.fixture(scope="module")
def servo():
    return load_scene("rt70_servo")


@pytest.fixture(scope="module")
def calm(servo):
    return bl.bearing_loads(servo, bl.LoadCase(30.0))


def test_calm_loads_carry_the_weights(servo, calm):
    """Vertical forces are the weights above each joint; the reducers hold the rest."""
    masses = servo.textbook.mass
    g = 9.81
    assert_close(calm.weight_azimuth, masses.sum() * g, rel=1e-14)
    assert_close(calm.weight_elevation, masses[1:].sum() * g, rel=1e-14)  # all but the platform
    assert_close(calm.vertical[0], calm.weight_azimuth, rel=1e-12)
    assert_close(calm.vertical[1], calm.weight_elevation, rel=1e-12)
    K_az, K_el = calm.torques["azimuth"], calm.torques["elevation"]
    assert K_el > 1e6  # the elevation structure is not balanced at 30°
    # K comes from the equilibrium, solved to EQUILIBRIUM_TOL of its force scale (the
    # weights' static force, at 30° the unbalanced moment K_el)
    assert_close(calm.azimuth[5], K_az, rel=EQUILIBRIUM_TOL, scale=K_el)  # reducer: M_z
    # the struts do not resist the turn
    assert_close(calm.elevation[3], 0.0, rel=EQUILIBRIUM_TOL, scale=K_el)
    assert_close(calm.elevation_total[3], K_el, rel=1e-3)  # the sector does
    assert_close(np.linalg.norm(calm.mesh_force), K_el / 16.0, rel=1e-3)
    assert calm.sides_difference < 1e-13  # already relative to the loads' max-norm


def test_side_wind_loads_the_azimuth_reducer(servo):
    side = bl.bearing_loads(servo, bl.LoadCase(45.0, 0.0, 20.0, 90.0))
    assert side.case.label == "from 90°"
    K_az = side.torques["azimuth"]
    assert abs(K_az) > 1e6
    # K_az balances the wind to the equilibrium's tolerance of its force scale, the weight
    assert_close(side.azimuth[5], K_az, rel=EQUILIBRIUM_TOL, scale=side.weight_azimuth)
    assert side.sides_difference < 1e-13
    front = bl.bearing_loads(servo, bl.LoadCase(45.0, 0.0, 20.0))
    assert front.case.label == "front"
    # a front wind turns no azimuth (to the equilibrium's tolerance, as above)
    assert_close(front.azimuth[5], 0.0, rel=EQUILIBRIUM_TOL, scale=front.weight_azimuth)


def test_bad_cases_and_scenes_are_refused(servo):
    with pytest.raises(Rt70Error, match="outside -90…180"):
        bl.check_case(bl.LoadCase(181.0))
    with pytest.raises(Rt70Error, match="outside its axis's range 0…90°"):
        bl.bearing_loads(servo, bl.LoadCase(91.0))
    with pytest.raises(Rt70Error, match="finite"):
        bl.check_case(bl.LoadCase(np.nan))
    with pytest.raises(Rt70Error, match="declares no pointing axes"):
        bl.check_scene(load_scene("double_pendulum"), wind=False)
    with pytest.raises(Rt70Error, match="rt70:drive"):
        bl.check_scene(load_scene("rt70"), wind=False)


def test_command_prints_writes_and_agrees(tmp_path, capsys):
    out = tmp_path / "loads.csv"
    argv = ["reactions", "rt70_servo", "--elevation", "60", "--wind", "20", "--output", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "front" in text and "back" in text and "checks: weight above" in text
    rows = list(csv.DictReader(out.open()))
    assert [r["wind"] for r in rows] == ["calm", "front", "back"]
    assert main(["reactions", "rt70_servo", "--elevation", "60", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # one computation by the same code, written twice: the CSV's repr round-trips exactly
    assert float(rows[0]["az_axial_kN"]) == data["rows"][0]["az_axial_kN"]


def _exit_code(argv: list[str]) -> int:
    """The exit code of the command line, whether the parser exits or main returns."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--elevation", "0,,30"], "expected elevations"),
        (["--elevation", "95"], "elevation 95° lies outside its axis's range 0…90°"),
        (["--direction", "90"], "--direction needs --wind"),
        (["--output", "loads.txt"], ".csv or .json"),
        (["--wind", "-3"], "--wind"),
    ],
)
def test_command_refuses_bad_options_in_one_line(argv, message, capsys):
    assert _exit_code(["reactions", "rt70_servo", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and err.startswith("rt70: error:")


def test_command_refuses_a_scene_without_axes(capsys):
    assert _exit_code(["reactions", "double_pendulum"]) == 2
    err = capsys.readouterr().err
    assert "declares no pointing axes" in err and err.count("\n") == 1
