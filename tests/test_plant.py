"""The linear plant (rt70.linear.plant): named inputs and outputs, python-control export,
and the small-signal response of the nonlinear model."""

from __future__ import annotations

import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.linear import plant as pl
from rt70.linear.responses import frequency_response
from rt70.model.outputs import optical_point_outputs
from rt70.model.scene import load_scene
from rt70.physics.loads import Wrench
from rt70.scenes.rt70_state import AZIMUTH_COORDINATE, ELEVATION_COORDINATE, rt70_pointing
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close

AXES = (AZIMUTH_COORDINATE, ELEVATION_COORDINATE)


@pytest.fixture(scope="module")
def rt70_plant():
    scene = load_scene("rt70")
    q0 = lin.equilibrium(scene, rt70_pointing(45.0, 0.0))
    inputs = [pl.CoordinateInput(f"torque:{a}", a) for a in AXES]
    inputs.append(pl.LoadInput("counterweight_fz", Wrench("counterweight", force=(0, 0, 1.0))))
    outputs = [pl.CoordinateOutput(f"angle:{a}", a) for a in AXES]
    outputs += optical_point_outputs(scene)[:1]
    return scene, q0, pl.plant(scene, q0, inputs, outputs)


def test_plant_has_named_inputs_outputs_states(rt70_plant):
    scene, q0, ss = rt70_plant
    assert ss.input_labels == ["torque:platform_rz", "torque:base_rx", "counterweight_fz"]
    assert ss.output_labels[:2] == ["angle:platform_rz", "angle:base_rx"]
    assert tuple(ss.output_labels[2:]) == (
        "main_mirror_focus:x",
        "main_mirror_focus:y",
        "main_mirror_focus:z",
    )
    assert ss.nstates == 84 and ss.state_labels[0] == scene.coordinate_names[0]
    # the axis-torque columns are unit generalised forces on their coordinates
    lm = lin.linearize(scene, q0)
    Minv_B = np.linalg.solve(lm.M, np.eye(42)[:, [lm.coordinates.index(a) for a in AXES]])
    assert_close(ss.B[42:, :2], Minv_B, rel=1e-10)


def test_output_rows_match_point_jacobian(rt70_plant):
    """The optical point's rows (outputs.output_matrix) equal linearize's point Jacobian."""
    scene, q0, ss = rt70_plant
    lm = lin.linearize(scene, q0)
    exact = lin.point_output(lm, scene, "main_mirror", (0, 0, 13))
    rows = ss.C[2:5, :42]
    assert_close(rows, exact, rel=1e-8)


def test_python_control_model_keeps_names_and_response(rt70_plant):
    control = pytest.importorskip("control")
    _, _, ss = rt70_plant
    sys = ss
    assert isinstance(sys, control.StateSpace)
    assert sys.input_labels == ["torque:platform_rz", "torque:base_rx", "counterweight_fz"]
    assert sys.output_labels[:2] == ["angle:platform_rz", "angle:base_rx"]
    f = 1.3  # Hz, between resonances
    H_ref = frequency_response(ss, np.array([f])).H[0]
    H_ctl = sys(2j * np.pi * f)
    # complex: the modulus of the difference, entry by entry on |H| (outputs of mixed units)
    error = np.abs(np.asarray(H_ctl) - H_ref)
    assert_close(error, np.zeros(error.shape), rel=1e-8, scale=np.abs(H_ref))


def test_small_signal_matches_the_nonlinear_model():
    """A small axis torque on the elevation model: linear and nonlinear responses agree.

    The chapter-2 elevation scene (bodies turning about parallel axes, held by springs)
    under a torque step of amplitude a on one coordinate: the nonlinear run's deviation
    from equilibrium over 1 s equals the linear plant's step response × a. Measured:
    1.3e-10 and 1.6e-10 of the response at a = 1e3 and 2e3 N·m (the integration and
    finite-difference floor; this structure's equations are linear in these angles).
    """
    from rt70.linear.responses import step_response

    scene = load_scene("rt70_elevation")
    q0 = lin.equilibrium(scene)
    name = scene.coordinate_names[1]
    ss = pl.plant(scene, q0, [pl.CoordinateInput("u", name)], [pl.CoordinateOutput("y", name)])
    t = np.linspace(0.0, 1.0, 201)
    _, y_lin = step_response(ss, t)
    y_lin = np.asarray(y_lin).reshape(t.size, -1)[:, 0]
    for a in (1e3, 2e3):
        idx = scene.coordinate_names.index(name)

        def torque(_t, _q, _qd, a=a, idx=idx):
            Q = np.zeros(q0.size)
            Q[idx] = a
            return Q

        run = simulate(
            scene,
            (0.0, 1.0),
            x0=(q0, np.zeros(q0.size)),
            inputs=torque,
            t_eval=t,
            method="DOP853",
            rtol=1e-11,
            atol=1e-14,
        )
        y_nl = run.q[:, idx] - q0[idx]
        assert_close(y_nl, a * y_lin, rel=1e-8, what=f"a = {a:g}")


def test_bad_plant_requests_are_clear(rt70_plant):
    scene, q0, _ = rt70_plant
    with pytest.raises(Rt70Error, match="at least one input"):
        pl.plant(scene, q0, [], [pl.CoordinateOutput("y", "base_rx")])
    with pytest.raises(Rt70Error, match="locked"):
        pl.plant(
            scene,
            q0,
            [pl.CoordinateInput("u", "base_rx")],
            [pl.CoordinateOutput("y", "platform_rz")],
            locked=AXES,
        )
    with pytest.raises(Rt70Error, match="used twice"):
        pl.plant(
            scene,
            q0,
            [pl.CoordinateInput("u", "base_rx"), pl.CoordinateInput("u", "platform_rz")],
            [pl.CoordinateOutput("y", "base_rx")],
        )


def test_cli_plant_json_lists_named_inputs_and_outputs(capsys, tmp_path):
    import json

    from rt70.cli.main import main

    out = tmp_path / "plant.npz"
    assert main(["plant", "rt70", "--elevation", "60", "--json", "--out", str(out)]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["inputs"] == ["torque:platform_rz", "torque:base_rx"]
    assert info["outputs"][:2] == ["angle:platform_rz", "angle:base_rx"]
    assert "main_mirror_focus:z" in info["outputs"] and len(info["states"]) == 84
    # the mirror system's pointing corrections (4.159)-(4.163), away from the zenith
    assert {"pointing_correction:0", "pointing_correction:1", "focal_offset:z"} <= set(
        info["outputs"]
    )
    assert info["unstable_modes"] >= 1  # the unbalanced swinging part on its free axis
    data = np.load(out)
    assert data["A"].shape == (84, 84) and data["B"].shape == (84, 2)
    assert data["C"].shape == (len(info["outputs"]), 84)
    assert list(data["inputs"]) == info["inputs"]


def test_cli_plant_bad_input(capsys, tmp_path):
    from rt70.cli.main import main

    assert main(["plant", "rt70", "--out", str(tmp_path / "plant.txt")]) == 2
    assert ".npz" in capsys.readouterr().err
    assert main(["plant", "rt70_elevation", "--elevation", "30"]) == 2
    assert "pointing axes" in capsys.readouterr().err
    assert main(["plant", "rt70_elevation"]) == 0  # no axes: every coordinate in and out
    out = capsys.readouterr().out
    assert "6 inputs, 6 outputs" in out and "1 rigid" in out


def test_writing_a_plant_does_not_import_python_control(tmp_path):
    """``rt70 plant --out`` writes ``plant_matrices`` without importing python-control
    (2.2 s with matplotlib); ``plant`` is the same matrices held by python-control."""
    import subprocess
    import sys

    out = tmp_path / "plant.npz"
    script = (
        "import sys; from rt70.cli.main import main; "
        f"code = main(['plant', 'rt70', '--out', {str(out)!r}]); "
        "sys.exit(10 + code if 'control' in sys.modules else code)"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr or run.stdout
    assert np.isfinite(np.load(out)["A"]).all()
    scene = load_scene("rt70")
    held = rt70_pointing(60.0, 0.0)
    q0 = lin.equilibrium(scene, held)
    inputs = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
    outputs = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
    matrices = pl.plant_matrices(scene, q0, inputs, outputs)
    ss = pl.plant(scene, q0, inputs, outputs)
    for name in "ABCD":
        assert np.array_equal(getattr(matrices, name), getattr(ss, name))
    assert tuple(ss.state_labels) == matrices.state_labels
