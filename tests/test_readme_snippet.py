"""The Python snippets of the README and docs/python.md are right as printed.

The README's example goes through the names ``rt70`` exports (the front door) and is
run as printed. docs/python.md's snippet calls both sides and must compare like with
like on the RT-70 and on any URDF: Pinocchio numbers talos_full's sibling joints
differently from the file; the public API must still give both sides in one coordinate
order (issue 8, item 4).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from rt70.crosscheck.robots import robot_path
from rt70.testing import assert_close

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PYTHON_PAGE = ROOT / "docs" / "python.md"


def _block(path: Path, heading: str) -> str:
    """The first python block of ``path`` after ``heading``."""
    text = path.read_text(encoding="utf-8")
    section = text[text.index(heading) :]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, f"no python block in {path.name}'s {heading!r} section"
    return match.group(1)


def _snippet() -> str:
    return _block(PYTHON_PAGE, "## Both sides, side by side")


@pytest.mark.parametrize("target", ["rt70", "talos_full", "baxter"])
def test_readme_snippet_compares_like_with_like(target, capsys):
    code = _snippet()
    assert 'load_scene("rt70")' in code
    if target != "rt70":
        code = code.replace('load_scene("rt70")', f"load_scene({str(robot_path(target))!r})")
    ns: dict = {}
    exec(compile(code, "docs/python.md", "exec"), ns)  # noqa: S102 - our own docs
    printed = float(capsys.readouterr().out.split()[-1])
    A, A_pin, qdd, qdd_pin = ns["A"], ns["A_pin"], ns["qdd"], ns["qdd_pin"]
    assert np.all(np.isfinite(A)) and np.all(np.isfinite(qdd))
    assert_close(printed, 0.0, rel=1e-13, scale=1.0)  # the printed relative error: scale 1
    assert_close(A, A_pin, rel=1e-13, what="mass matrix")
    assert_close(qdd, qdd_pin, rel=1e-9, what="accelerations")
    assert ns["scene"].coordinate_names == ns["model"].coordinate_names


def test_talos_full_is_a_reordering_for_pinocchio():
    """The case the snippet guards: Pinocchio's own order differs from the file's."""
    from rt70.model.scene import load_scene

    scene = load_scene(robot_path("talos_full"))
    ref = scene.reference
    pin_order = [c.names[0] for c in sorted(ref.coords, key=lambda c: c.iv) if c.names]
    assert pin_order != scene.coordinate_names
    assert sorted(pin_order) == sorted(scene.coordinate_names)
    assert not ref.identity_map


@pytest.mark.slow
def test_every_robot_names_its_coordinates_in_the_files_order():
    from rt70.crosscheck.robots import survey

    loaded, _ = survey()
    assert len(loaded) >= 40
    for scene in loaded:
        assert scene.textbook.coordinate_names == scene.coordinate_names, scene.name
        assert scene.reference.coordinate_names == scene.coordinate_names, scene.name


@pytest.mark.slow
def test_readme_example_runs_as_printed(capsys):
    """The README's example: only names ``rt70`` exports, each step's result as claimed."""
    code = _block(README, "## Using it from Python")
    lines = [line for line in code.splitlines() if line.strip()]
    assert len(lines) <= 15, f"the README's example has {len(lines)} lines"
    imports = [line for line in lines if line.startswith(("import ", "from "))]
    assert imports == ["import rt70"]
    ns: dict = {}
    exec(compile(code, "README.md", "exec"), ns)  # noqa: S102 - our own README
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"True {len(ns['records'])} quantities agree"
    assert all(r.passed() for r in ns["records"])
    assert out[1].endswith(" Hz") and ns["lm"].coordinates
    assert ns["ss"].nstates == 84 and out[2].startswith("84 states")
    assert ns["run"].success and not ns["run"].drift_flagged
