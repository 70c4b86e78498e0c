"""``rt70 plant --drives [--loop ...]``: the servo plant with the scene's own drives.

The structure with its ``<rt70:drive>`` elements (voltages in, gear sector included),
its servos closed or one loop broken, as python-control systems with named signals and
units, written as ``.npz`` or ``.mat``.
"""

from __future__ import annotations

import json

import control
import numpy as np
import pytest
import scipy.io

from rt70.cli.main import main
from rt70.control.scene_loop import driven_plant
from rt70.linear import linearize as lin
from rt70.model.antenna import pointing
from rt70.model.couplings import SceneCoupling
from rt70.model.scene import load_scene
from rt70.telescope.drive_equilibrium import scene_equilibrium
from rt70.testing import assert_close


def test_the_json_names_every_signal_with_its_unit(capsys):
    assert main(["plant", "rt70_servo", "--drives", "--elevation", "45", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["inputs"] == ["azimuth_voltage", "elevation_voltage"]
    assert set(info["input_units"].values()) == {"V"}
    units = info["output_units"]
    assert units["azimuth_encoder"] == "rad" and units["elevation_current"] == "A"
    assert units["pointing_correction:1"] == "arcsec" and units["focal_offset:z"] == "mm"
    assert len(info["states"]) == 84 + 6  # the structure's and three per drive


def test_the_mat_file_holds_matrices_names_and_units(tmp_path, capsys):
    out = tmp_path / "plant.mat"
    assert main(["plant", "antenna_12m", "--loop", "closed", "--out", str(out)]) == 0
    m = scipy.io.loadmat(out)
    n = m["A"].shape[0]
    assert m["B"].shape == (n, 2) and m["C"].shape[1] == n
    inputs = [str(x[0]) for x in m["inputs"].ravel()]
    assert inputs == ["azimuth_drive_reference", "elevation_drive_reference"]
    assert [str(x[0]) for x in m["input_units"].ravel()] == ["rad", "rad"]
    assert json.loads(str(m["description"][0]))["plant"] == "every loop closed"
    closed = control.ss(m["A"], m["B"], m["C"], m["D"])
    assert np.max(np.real(closed.poles())) < 0.0  # its servos, closed, are stable
    # each encoder follows its reference at low frequency
    outputs = [str(x[0]) for x in m["outputs"].ravel()]
    k = outputs.index("elevation_drive_encoder")
    assert_close(abs(closed(2j * np.pi * 1e-3)[k, 1]), 1.0, rel=1e-3)


def test_a_constant_voltage_spins_a_free_axis_at_its_no_load_speed():
    """Azimuth is free (a rigid mode): at low frequency voltage → motor speed is the
    motor's c_m / (R_a D_m + c_m c_e), the structure's inertia no load at constant speed."""
    scene = load_scene("antenna_12m")
    couplings = [SceneCoupling(scene, d, "reference") for d in scene.description.drives]
    q0, _, _ = scene_equilibrium(scene, couplings, pointing(scene, 45.0))
    plant = driven_plant(scene, lin.linearize(scene, q0), [])
    d = scene.description.drives[0]
    expected = d.c_m / (d.R_a * d.D_m + d.c_m * d.c_e)
    H = plant(2j * np.pi * 1e-4)
    k = list(plant.output_labels).index(f"{d.name}_motor_speed")
    assert_close(abs(H[k, 0]), expected, rel=1e-3)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["rt70", "--drives"], "need the scene's <rt70:drive> elements"),
        (["rt70_servo", "--drives", "--reduce", "10"], "--reduce works on the structure"),
        (["rt70_servo", "--drives", "--at", "rate"], "--at needs --loop open"),
        (["rt70_servo", "--out", "plant.txt"], "--out must be a .npz or .mat file"),
        (["rt70", "--loop", "closed"], "need the scene's <rt70:drive> elements"),
    ],
)
def test_bad_requests_are_one_line(argv, message, capsys):
    assert main(["plant", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
