"""A simulation's files carry what its run printed, and the unit of every column.

``rt70 simulate SCENE --scenario ... --out run.csv`` writes, beside the coordinates and
energies, the references, the encoder and pointing errors, the motor torques and
currents the summary quotes (``series:*`` columns), and ``run.units.json`` with the unit
of every column; the ``.npz`` likewise for every array.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.model.scene import load_scene
from rt70.simulation.result import units_path
from rt70.simulation.simulate import coordinate_units
from rt70.telescope import scenarios
from rt70.telescope.scene_servo import choose_drives

SERIES = {
    "reference:azimuth": "deg",
    "reference:elevation": "deg",
    "encoder_error:azimuth": "arcsec",
    "encoder_error:elevation": "arcsec",
    "pointing_error:cross_elevation": "arcsec",
    "pointing_error:elevation": "arcsec",
    "pointing_error:total": "arcsec",
    "torque:azimuth": "N·m",
    "torque:elevation": "N·m",
    "current:azimuth": "A",
    "current:elevation": "A",
}


@pytest.fixture(scope="module")
def run():
    scene = load_scene("rt70_servo")
    sc = scenarios.scenario("step-azimuth", 45.0, 0.0, 2.0)
    drives, _ = choose_drives(scene, None)
    return scenarios.run_scenario(scene, sc, drives=drives, rtol=1e-6)


def test_the_series_are_what_the_summary_quotes(run):
    result = run.result
    assert {k: result.series_units[k] for k in result.series} == SERIES
    total = result.series["pointing_error:total"]
    assert float(total.max()) == run.metrics["pointing_drift_arcsec"]
    torque = result.series["torque:azimuth"]
    assert float(np.abs(torque).max()) == run.metrics["peak_torque_azimuth_Nm"]
    # the pointing asked for, degrees: azimuth 0° + the 1° step from t = 0, elevation 45°
    assert np.all(result.series["reference:azimuth"] == 1.0)
    assert np.all(result.series["reference:elevation"] == 45.0)


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_every_column_has_a_unit(run, tmp_path, suffix):
    path = tmp_path / f"run{suffix}"
    run.result.save(path)
    units = run.result.units(path)
    if suffix == ".csv":
        header = path.read_text(encoding="utf-8").splitlines()[0].split(",")
        assert set(header) == set(units)
    else:
        with np.load(path) as data:
            assert set(data.files) == set(units)
    assert "unknown" not in units.values() and all(units.values())
    assert units["t"] == "s" and units["kinetic"] == "J"


def test_the_command_writes_the_units_beside_the_file(tmp_path, capsys):
    out = tmp_path / "run.csv"
    code = main(
        [
            "simulate",
            "rt70_servo",
            "--scenario",
            "hold",
            "--t-end",
            "1",
            "--out",
            str(out),
            "--no-plot",
        ]
    )
    assert code == 0
    sidecar = json.loads(units_path(out).read_text(encoding="utf-8"))
    assert sidecar["scene"] == "rt70_servo" and sidecar["file"] == "run.csv"
    header = out.read_text(encoding="utf-8").splitlines()[0].split(",")
    assert set(header) == set(sidecar["units"])
    assert sidecar["units"]["q:platform_rz"] == "rad" and sidecar["units"]["q:base_y"] == "m"
    assert sidecar["units"]["series:pointing_error:total"] == "arcsec"


def test_coordinate_units_follow_the_joints():
    scene = load_scene("rt70_servo")
    units = dict(zip(scene.textbook.coordinate_names, coordinate_units(scene), strict=True))
    assert units["base_x"] == "m" and units["base_rx"] == "rad"
    assert set(units.values()) == {"m", "rad"}
