"""No element kind is read and then dropped: each is used where its kind says.

The reader turns every ``<rt70:...>`` element into a field of
:class:`rt70.urdf.description.RobotDescription`. An element that changes the dynamics
must be used by both sides (``rt70/textbook/`` and ``rt70/reference/``), or the
cross-check compares two models without it; any other field must be used by some code
outside the reader. A new field of the description fails here until it is classified
below (docs/architecture.md, 'Adding an element kind').
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from rt70.urdf.description import RobotDescription

PACKAGE = Path(__file__).resolve().parents[1] / "rt70"

#: The tree itself: what every URDF file has.
TREE = {"name", "source", "root", "links", "joints", "gravity"}

#: Fields that change the equations of motion: used by both sides.
DYNAMICS = {
    "bushings",
    "joint_springs",
    "drives",
    "winds",
    "air_density",
    "loops",
    "modal_bodies",
}

#: Fields used above the sides, each with where and why.
ELSEWHERE = {
    "optical_points": "outputs of either side by link and offset (rt70.model.outputs)",
    "no_slips": "constraints on a scene's velocities (rt70.mechanics, rt70.crosscheck)",
    "mount": "the pointing axes, read where a pointing is asked for (rt70.model.antenna)",
    "optics": "the reflector system: the pointing outputs (rt70.model.antenna)",
    "beams": "the members written as rigid finite elements (rt70.scenes.beam_scenes)",
    "inertia_repairs": "the repairs the scene writes into the text both sides read (model.scene)",
}


def _uses(field: str, folders: tuple[str, ...]) -> list[str]:
    """The modules under ``folders`` that read ``.field``."""
    pattern = re.compile(rf"\.{field}\b")
    return [
        str(p.relative_to(PACKAGE))
        for folder in folders
        for p in sorted((PACKAGE / folder).rglob("*.py"))
        if pattern.search(p.read_text(encoding="utf-8"))
    ]


FIELDS = [f.name for f in dataclasses.fields(RobotDescription)]


def test_every_field_of_the_description_is_classified():
    unclassified = set(FIELDS) - TREE - DYNAMICS - ELSEWHERE.keys()
    assert not unclassified, (
        f"new description fields {sorted(unclassified)}: add each to DYNAMICS (both sides "
        "use it) or ELSEWHERE (say who uses it) in this test"
    )
    assert not (DYNAMICS & ELSEWHERE.keys()) and set(FIELDS) >= DYNAMICS | ELSEWHERE.keys()


@pytest.mark.parametrize("field", sorted(DYNAMICS))
@pytest.mark.parametrize("side", ["textbook", "reference"])
def test_an_element_of_the_dynamics_is_used_by_each_side(field, side):
    assert _uses(field, (side,)), f"rt70/{side}/ never reads RobotDescription.{field}"


@pytest.mark.parametrize("field", sorted(ELSEWHERE))
def test_any_other_element_is_used_outside_the_reader(field):
    folders = tuple(
        p.name for p in PACKAGE.iterdir() if p.is_dir() and p.name not in {"urdf", "__pycache__"}
    )
    assert _uses(field, folders), f"no code outside rt70/urdf/ reads RobotDescription.{field}"


def test_the_search_sees_a_use_and_no_false_one():
    """The search finds ``desc.winds`` on the reference side and no ``.windsx``."""
    assert "reference/wind.py" in _uses("winds", ("reference",))
    assert _uses("winds_that_do_not_exist", ("reference", "textbook")) == []
