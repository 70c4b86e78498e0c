"""The cross-check never passes on what it did not check (issue 8, item 1).

- a NaN or an infinity on either side of any compared quantity fails that row;
- a run that checks no target, or a model with no degree of freedom, exits 2;
- rounding is not disagreement: every quantity has a floor from the state's natural
  scale (:func:`rt70.crosscheck.scales.natural_scales`), and the floor hides no real error.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pybullet_data
import pytest

import rt70.crosscheck.validate as validate
from rt70 import reference
from rt70.cli.main import main
from rt70.crosscheck.compiled_check import ROWS as COMPILED_ROWS
from rt70.crosscheck.samples import random_state
from rt70.crosscheck.scales import natural_scales
from rt70.crosscheck.validate import QUANTITIES, cross_check
from rt70.errors import Rt70Error, SceneError
from rt70.model.scene import load_scene, scene_from_text

PYBULLET = Path(pybullet_data.getDataPath())
TOL = 1e-10


def _corrupt(monkeypatch, quantity: str, side: int, value: float) -> None:
    """Make one side of one quantity return ``value`` in one entry."""
    pairs = validate._pairs

    def corrupted(scene, q, qd):
        out = pairs(scene, q, qd)
        fn = out[quantity][side]

        def bad():
            x = np.array(fn(), dtype=float, copy=True)
            x.flat[x.size // 2] = value
            return x

        out[quantity] = (bad, out[quantity][1]) if side == 0 else (out[quantity][0], bad)
        return out

    monkeypatch.setattr(validate, "_pairs", corrupted)


@pytest.fixture(scope="module")
def two_body():
    scene = load_scene("two_body_gravity")
    scene.reference  # noqa: B018
    return scene


@pytest.mark.slow
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf], ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize("side", [0, 1], ids=["textbook", "reference"])
@pytest.mark.parametrize("quantity", QUANTITIES + COMPILED_ROWS)
def test_nonfinite_value_fails_its_row(two_body, monkeypatch, quantity, side, value):
    _corrupt(monkeypatch, quantity, side, value)
    records = {r.quantity: r for r in cross_check(two_body, samples=2, seed=0, repeat=0)}
    bad = records[quantity]
    assert not bad.passed(TOL) and not bad.passed(math.inf)
    assert bad.max_rel_err == math.inf and bad.max_abs_err == math.inf
    assert bad.nonfinite == ("textbook" if side == 0 else "reference")
    for name, r in records.items():
        if name != quantity:
            assert r.passed(TOL) and not r.nonfinite, (name, r)


def test_nonfinite_row_makes_the_command_fail(monkeypatch, capsys):
    _corrupt(monkeypatch, "mass_matrix", 0, math.nan)
    assert main(["validate", "two_body_gravity", "--samples", "1"]) == 1
    out = capsys.readouterr().out
    assert "NaN/inf on the textbook side" in out
    _corrupt(monkeypatch, "forward_dynamics", 1, math.inf)
    assert main(["validate", "two_body_gravity", "--samples", "1", "--json"]) == 1


def test_small_injected_error_still_fails(two_body, monkeypatch):
    """The floors hide rounding only: a 1e-8 relative slip of q̈ on one side fails."""
    pairs = validate._pairs

    def slipped(scene, q, qd):
        out = pairs(scene, q, qd)
        tb, ref = out["forward_dynamics"]
        out["forward_dynamics"] = (lambda: tb() * (1.0 + 1e-8), ref)
        return out

    monkeypatch.setattr(validate, "_pairs", slipped)
    records = {r.quantity: r for r in cross_check(two_body, samples=2, seed=0, repeat=0)}
    assert not records["forward_dynamics"].passed(TOL)
    assert records["forward_dynamics"].max_rel_err > 1e-9


@pytest.mark.parametrize(
    ("urdf", "quantities"),
    [
        ("r2d2.urdf", ("bias", "forward_dynamics")),  # q̈ ~ 1e-17: a balanced robot
        ("racecar/racecar.urdf", ("gravity",)),  # wheels' gravity torque ~ 3e-17
    ],
)
def test_rounding_is_not_disagreement(urdf, quantities, monkeypatch):
    """These rows fail against their own tiny norm and pass against their natural scale."""
    scene = load_scene(PYBULLET / urdf)
    with_floor = {r.quantity: r for r in cross_check(scene, samples=10, seed=0, repeat=0)}
    assert all(r.passed(TOL) for r in with_floor.values()), with_floor
    monkeypatch.setattr(validate, "FLOOR", 0.0)
    own_norm = {r.quantity: r for r in cross_check(scene, samples=10, seed=0, repeat=0)}
    for name in quantities:
        # the same absolute error (the same computation, only the denominator differs),
        # which against the natural scale passed above: rounding of the terms
        assert own_norm[name].max_abs_err == with_floor[name].max_abs_err
        assert not own_norm[name].passed(TOL), (name, own_norm[name])


def test_natural_scales_are_positive_and_finite(two_body):
    q, qd = random_state(two_body.textbook.nv, np.random.default_rng(1))
    values = {
        name: (np.asarray(a(), dtype=float), np.asarray(b(), dtype=float))
        for name, (a, b) in validate._pairs(two_body, q, qd).items()
    }
    scales = natural_scales(two_body, values, q, qd)
    assert set(scales) == set(QUANTITIES + COMPILED_ROWS)  # the kernels cover it
    assert all(np.all(np.isfinite(v)) and np.all(np.asarray(v) > 0.0) for v in scales.values())
    # q̈: per coordinate, |A⁻¹| (f + |A||q̈|) ≥ |A⁻¹| |Q_g| ≥ |q̈ from gravity alone|
    A, Q_g = values["mass_matrix"][1], values["gravity"][1]
    assert scales["forward_dynamics"].shape == (two_body.textbook.nv,)
    assert np.all(scales["forward_dynamics"] >= np.abs(np.linalg.solve(A, Q_g)))
    g0 = reference.weight_moment(two_body.reference, two_body.reference_data, q)
    assert g0 > 0.0 and scales["gravity"] >= g0


FIXED_ONLY = """<?xml version="1.0"?>
<robot name="welded">
  <link name="world"/>
  <link name="box"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="world"/><child link="box"/></joint>
</robot>
"""


def _run(*args: str, env: dict | None = None, cwd: str | None = None):
    return subprocess.run(
        [sys.executable, "-m", "rt70.cli.main", *args],
        capture_output=True,
        text=True,
        env=env,
        cwd=cwd,
        check=False,
    )


def test_model_without_degree_of_freedom_exits_2(tmp_path):
    path = tmp_path / "welded.urdf"
    path.write_text(FIXED_ONLY)
    with pytest.raises(SceneError, match="no degree of freedom"):
        cross_check(scene_from_text(FIXED_ONLY, "welded"), samples=1)
    proc = _run("validate", str(path))
    assert proc.returncode == 2, proc
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "welded.urdf" in lines[0] and "no degree of freedom" in lines[0]


def test_robot_without_degree_of_freedom_exits_2():
    proc = _run("validate", "robot:hector")
    assert proc.returncode == 2, proc
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "hector" in lines[0] and "no degree of freedom" in lines[0]


@pytest.mark.slow
def test_no_target_exits_2(tmp_path):
    env = {**os.environ, "RT70_URDF_DIR": str(tmp_path)}
    proc = _run("validate", env=env, cwd=str(tmp_path))
    assert proc.returncode == 2, proc
    assert proc.stderr.count("\n") == 1 and "no target" in proc.stderr
    proc = _run("validate", "rt70", env=env, cwd=str(tmp_path))
    assert proc.returncode == 2 and "no scene files in" in proc.stderr


def test_validate_from_another_directory(tmp_path):
    proc = _run("validate", "rt70", "--samples", "1", cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert "1 target(s)" in proc.stdout


def test_samples_below_one_is_refused(two_body):
    with pytest.raises(Rt70Error, match="samples"):
        cross_check(two_body, samples=0)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("target", "message"), [("/dev/null", "not a regular file"), ("/tmp", "is a directory")]
)
def test_special_paths_are_named_as_such(target, message):
    proc = _run("validate", target)
    assert proc.returncode == 2 and message in proc.stderr
    assert proc.stderr.count("\n") == 1
