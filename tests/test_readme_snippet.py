"""The README's Python snippet is right as printed, on the RT-70 and on any URDF.

Pinocchio numbers talos_full's sibling joints differently from the file; the public API
must still give both sides in one coordinate order (issue 8, item 4).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from rt70.crosscheck.robots import robot_path
from rt70.testing import assert_close

README = Path(__file__).resolve().parents[1] / "README.md"


def _snippet() -> str:
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## Using it from Python") :]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, "no python block in the README's 'Using it from Python' section"
    return match.group(1)


@pytest.mark.parametrize("target", ["rt70", "talos_full", "baxter"])
def test_readme_snippet_compares_like_with_like(target, capsys):
    code = _snippet()
    assert 'load_scene("rt70")' in code
    if target != "rt70":
        code = code.replace('load_scene("rt70")', f"load_scene({str(robot_path(target))!r})")
    ns: dict = {}
    exec(compile(code, "README.md", "exec"), ns)  # noqa: S102 - our own README
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
