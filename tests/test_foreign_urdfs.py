"""The classifier of validation/foreign_urdfs.py on a fixed subset of pybullet_data.

The subset covers every category and refusal kind the full run meets (the full run is
``python validation/foreign_urdfs.py``, results in validation/results/foreign_urdfs.md),
each file with its expected outcome as is and with ``balance_inertia``; hand-made files
cover the refusal kinds pybullet_data does not contain. No file may crash or disagree
(r2d2, whose q̈ is rounding, included), and every refusal must be of a known kind.
"""

from __future__ import annotations

import faulthandler
import importlib.util
import os
import signal
import sys
from pathlib import Path

import pytest

pybullet_data = pytest.importorskip("pybullet_data")

SCRIPT = Path(__file__).resolve().parents[1] / "validation" / "foreign_urdfs.py"
_spec = importlib.util.spec_from_file_location("foreign_urdfs", SCRIPT)
fu = importlib.util.module_from_spec(_spec)
sys.modules["foreign_urdfs"] = fu  # the forked children pickle its Outcome
_spec.loader.exec_module(fu)

ROOT = Path(pybullet_data.getDataPath())

#: file -> (as is, with balance, warnings as is); an outcome is "agree" or a refusal kind.
SUBSET = {
    "kuka_iiwa/model.urdf": ("agree", "agree", ["ground inertia ignored"]),
    "franka_panda/panda.urdf": ("agree", "agree", ["zero-mass inertia merged"]),
    "differential/diff_ring.urdf": (
        "agree",
        "agree",
        ["unknown URDF attribute", "whitespace before <?xml"],  # <axis rpy>
    ),
    "cartpole.urdf": ("agree", "agree", ["ground inertia ignored"]),
    "pendulum5.urdf": ("agree", "agree", []),
    "random_urdfs/000/000.urdf": (fu.NO_DOF, fu.NO_DOF, ["ground inertia ignored"]),
    "cube.urdf": (fu.NO_DOF, fu.NO_DOF, []),
    "TwoJointRobot_wo_fixedJoints.urdf": ("impossible inertia", "agree", []),
    "biped/biped2d_pybullet.urdf": (
        "impossible inertia",
        "malformed URDF",  # Pinocchio refuses its <limit lower="-1.57.">
        ["ground inertia ignored", "whitespace before <?xml"],
    ),
    "bicycle/bike.urdf": ("malformed URDF", "malformed URDF", []),
    "quadruped/microtaur/microtaur.urdf": ("malformed URDF", "malformed URDF", []),
    "torus_deform.urdf": ("malformed URDF", "malformed URDF", []),
    "spherical_joint_limit.urdf": (
        "unsupported joint type",
        "unsupported joint type",
        ["unknown URDF attribute"],  # <limit twist>
    ),
    "humanoid/humanoid.urdf": (
        "unsupported joint type",
        "unsupported joint type",
        ["NUL after the document"],
    ),
    "husky/husky.urdf": ("xacro file", "xacro file", []),
}


def _outcome(o) -> str:
    return "agree" if o.category == "agree" else o.kind


@pytest.mark.parametrize("name", list(SUBSET))
def test_pybullet_file(name):
    plain = fu.classify(ROOT / name, samples=2, label=name)
    balanced = fu.classify(ROOT / name, samples=2, balance_inertia=True, label=name)
    expected_plain, expected_balanced, expected_warnings = SUBSET[name]
    for o in (plain, balanced):
        assert o.category in ("agree", "refused"), f"{o.category}: {o.detail}"
        assert o.category != "refused" or o.kind in fu.KNOWN_KINDS, o.kind
        assert "other" not in o.warnings
    assert (_outcome(plain), _outcome(balanced)) == (expected_plain, expected_balanced)
    assert plain.warnings == expected_warnings
    if expected_balanced != expected_plain and expected_balanced == "agree":
        assert "inertia balanced" in balanced.warnings


def test_r2d2():
    """r2d2's q̈ is ~1e-17: its error 5e-17 is rounding, within q̈'s natural-scale floor."""
    o = fu.classify(ROOT / "r2d2.urdf", samples=3, label="r2d2.urdf")
    assert o.category == "agree", o.detail


HANDMADE = {
    "dtd": (
        '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY m "2">]>\n<robot name="t">'
        '<link name="a"/></robot>',
        "DTD entity",
    ),
    "massless": (
        '<robot name="t"><link name="a"/><joint name="j" type="continuous"><parent link="a"/>'
        '<child link="b"/></joint><link name="b"/></robot>',
        "coordinate moves no mass",
    ),
    "huge": (
        '<robot name="t"><link name="a"/><joint name="j" type="continuous"><parent link="a"/>'
        '<child link="b"/><axis xyz="1e200 1e200 0"/></joint><link name="b"/></robot>',
        "huge value",
    ),
}


@pytest.mark.parametrize("name", list(HANDMADE))
def test_handmade_refusal_kinds(name, tmp_path):
    text, kind = HANDMADE[name]
    path = tmp_path / f"{name}.urdf"
    path.write_text(text)
    o = fu.classify(path, samples=1)
    assert (o.category, o.kind) == ("refused", kind), o.detail
    assert str(path) not in o.detail  # the report lists files by name


def test_a_python_exception_is_a_crash(monkeypatch):
    def broken(*args, **kwargs):
        raise KeyError("boom")

    monkeypatch.setattr(fu, "load_scene", broken)
    o = fu.classify(ROOT / "cartpole.urdf")
    assert (o.category, o.kind) == ("crashed", "KeyError")
    assert "boom" in o.detail


def test_isolated_records_a_segfault_and_goes_on(monkeypatch):
    """A child killed by a signal is a crash of that file only; results keep their order."""
    real = fu.classify

    def classify(path, *args, **kwargs):
        if path.name == "cube.urdf":
            faulthandler.disable()  # pytest's dump of the child's stack is noise here
            os.kill(os.getpid(), signal.SIGSEGV)
        return real(path, *args, **kwargs)

    monkeypatch.setattr(fu, "classify", classify)
    jobs = [(ROOT / n, n, False) for n in ("cartpole.urdf", "cube.urdf", "husky/husky.urdf")]
    out = fu.isolated(jobs, samples=1, jobs=2)
    assert [o.file for o in out] == [n for _, n, _ in jobs]
    assert [(o.category, o.kind) for o in out] == [
        ("agree", ""),
        ("crashed", "signal"),
        ("refused", "xacro file"),
    ]
    assert str(-signal.SIGSEGV) in out[1].detail


def test_report(tmp_path):
    names = ["cartpole.urdf", "TwoJointRobot_wo_fixedJoints.urdf", "cube.urdf"]
    plain = [fu.classify(ROOT / n, samples=1, label=n) for n in names]
    balanced = [fu.classify(ROOT / n, samples=1, balance_inertia=True, label=n) for n in names]
    meta = {"files": 3, "pybullet": "x", "pinocchio": "y", "python": "z"}
    meta |= {"samples": 1, "jobs": 1, "seconds": 1.0}
    md, csv_path = fu.write_report(plain, balanced, tmp_path, meta)
    text = md.read_text()
    assert "| agree | 1 | 2 |" in text and "| refused | 2 | 1 |" in text
    assert "| impossible inertia | 1 | 0 | 1 |" in text
    assert "1 more file(s) agree" in text
    assert len(csv_path.read_text().splitlines()) == 1 + 2 * len(names)
