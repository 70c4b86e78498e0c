"""The reflector surface in the workflows: ``rt70 pointing`` and ``rt70 sweep``.

- ``rt70 pointing`` on ``rt70_mirror`` reports the surface beside the pointing: its
  parts add up (gravity and steady wind as residual vectors, gusts in quadrature), its
  Ruze efficiencies are those of the total at the frequencies asked, and the gust RMS is
  the weighted sum of the residual's variances (one Lyapunov solution with the pointing);
- the ``surface`` sweep quantity without wind is the homology of
  :mod:`rt70.telescope.homology` at the mount's middle elevation as rigging;
- options that need a surface are refused by name on a scene without one.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.model.scene import load_scene
from rt70.model.surface_outputs import reflector_surface
from rt70.surface.ruze import ruze_efficiency
from rt70.sweep.quantities import SweepPoint
from rt70.sweep.surface_quantity import ruze_field, surface_quantity
from rt70.telescope.homology import homology
from rt70.telescope.surface_budget import default_rigging


def test_pointing_reports_the_surface(capsys):
    code = main(
        ["pointing", "rt70_mirror", "--elevation", "30", "--wind", "8", "--frequency", "22",
         "--frequency", "5", "--rigging-elevation", "40", "--json"]
    )  # fmt: skip
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    s = out["surface"]
    assert s["rigging_elevation_deg"] == 40.0
    rms = s["rms_um"]
    assert all(np.isfinite(v) and v > 0.0 for v in rms.values())
    # gravity and steady wind add as vectors: the total lies between |g − w| and g + w
    steady = np.sqrt(rms["total"] ** 2 - rms["gust"] ** 2)
    assert abs(rms["gravity"] - rms["steady_wind"]) <= steady <= rms["gravity"] + rms["steady_wind"]
    for label, f in (("22 GHz", 22e9), ("5 GHz", 5e9)):
        assert s["ruze_efficiency"][label] == pytest.approx(
            ruze_efficiency(rms["total"] * 1e-6, f), rel=1e-12
        )
    assert len(s["steady"]["focus_shift"]) == 3 and len(s["steady"]["axis_tilt"]) == 2
    assert out["steady"]["main_mirror_error"] > 0.0  # the pointing is still there


def test_surface_options_need_a_surface(capsys):
    for option in (["--frequency", "22"], ["--rigging-elevation", "40"]):
        assert main(["pointing", "rt70_servo", "--wind", "5", *option]) == 2
        assert "has no reflecting surface" in capsys.readouterr().err
    for option, message in ((["--frequency", "0"], "must be greater than 0"),
                            (["--rigging-elevation", "95"], "[0, 90]")):  # fmt: skip
        with pytest.raises(SystemExit) as exit_:
            main(["pointing", "rt70_mirror", "--wind", "5", *option])
        assert exit_.value.code == 2 and message in capsys.readouterr().err


def test_sweep_quantity_without_wind_is_the_homology():
    scene = load_scene("rt70_mirror")
    quantity = surface_quantity([86.0])
    assert [f.name for f in quantity.fields][-1] == ruze_field(86.0) == "surface_ruze_86GHz"
    point = SweepPoint(elevation=20.0)
    values = quantity.compute(scene, point)
    rigging = default_rigging(scene)
    curve = homology(scene, reflector_surface(scene), [20.0], rigging, side="reference")
    assert values["surface_gravity_rms"] == pytest.approx(curve.rms_um[0], rel=1e-9)
    assert values["surface_rms"] == values["surface_gravity_rms"] > 50.0
    assert values["surface_wind_rms"] == values["surface_gust_rms"] == 0.0
    np.testing.assert_allclose(values["surface_focus_shift"], curve.focus_shift_mm[0], rtol=1e-9)
    assert values["surface_ruze_86GHz"] == pytest.approx(
        ruze_efficiency(values["surface_rms"] * 1e-6, 86e9), rel=1e-12
    )


def test_sweep_refuses_surface_options_where_they_mean_nothing(capsys, tmp_path):
    out = str(tmp_path / "s.npz")
    assert main(["sweep", "rt70_servo", "--quantity", "surface", "--out", out]) == 2
    assert "no reflecting surface" in capsys.readouterr().err
    assert (
        main(["sweep", "rt70_mirror", "--quantity", "sag", "--frequency", "3", "--out", out]) == 2
    )
    assert "only the surface quantity" in capsys.readouterr().err


def test_the_plant_carries_the_surface_outputs(capsys):
    assert main(["plant", "antenna_12m_dish", "--elevation", "40", "--json"]) == 0
    outputs = json.loads(capsys.readouterr().out)["outputs"]
    surface = reflector_surface(load_scene("antenna_12m_dish"))
    assert "surface_focus_shift:z" in outputs and "surface_beam_deviation:1" in outputs
    assert sum(o.startswith("surface_residual:") for o in outputs) == len(surface.nodes)
