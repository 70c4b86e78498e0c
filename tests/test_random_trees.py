"""Property tests: the textbook algorithm agrees with Pinocchio on generated scenes.

Hundreds of seeded random trees (``rt70.scenes.synthetic.random_tree``), grouped by
joint-type family so that a failure says which joint type is at fault, plus large
chains, trees and elastic chains. Every quantity of the cross-check must agree to
``TOL`` relative to Pinocchio's max-norm.

A quantity that nearly cancels (the velocity-product force of a tree whose joints
barely couple) carries the rounding error of its terms; ``rt70.crosscheck.validate`` measures
each quantity against ``max(own norm, FLOOR · scale)`` with the scale the size of its
terms at the state (``natural_scales``), so every row is held to the same tolerance.

To reproduce a failure: ``rt70 validate`` takes no generated scenes, so in Python::

    from rt70.model.scene import scene_from_text
    from rt70.scenes.synthetic import random_tree
    from rt70.crosscheck.validate import cross_check, format_table
    scene = scene_from_text(random_tree(SEED, joint_types=TYPES), "s")
    print(format_table(cross_check(scene, samples=2, seed=SEED, repeat=1)))
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter

import numpy as np
import pinocchio as pin
import pytest

from rt70.crosscheck.compiled_check import ROWS as COMPILED_ROWS
from rt70.crosscheck.validate import QUANTITIES, cross_check
from rt70.model.scene import scene_from_text
from rt70.scenes.synthetic import (
    ALL_JOINT_TYPES,
    balanced_tree,
    elastic_chain,
    random_tree,
    serial_chain,
)
from rt70.testing import assert_close, close
from rt70.textbook import forces
from rt70.urdf import read_urdf_string

TOL = 1e-10
SEEDS = range(50)
NS = "{urn:rt70:urdf-extensions:1}"

BASIC = ("revolute", "prismatic", "fixed")
# Each family draws its own joint type twice as often as each basic one (a type listed
# twice in ``joint_types`` is drawn twice as often), and starts at its own seed, so the
# families test different trees.
FAMILIES = {
    "continuous": (2000, ("continuous", "continuous", *BASIC)),
    "floating": (3000, ("floating", "floating", *BASIC)),
    "planar": (4000, ("planar", "planar", *BASIC)),
    "all": (5000, ALL_JOINT_TYPES),
}


def assert_agrees(text: str, label: str, seed: int, samples: int = 2) -> None:
    """Cross-check one generated scene; the message names the scene, seed and quantities."""
    scene = scene_from_text(text, label)
    # one coordinate order for the user: the textbook derives it, the file fixes it
    assert scene.textbook.coordinate_names == scene.coordinate_names, label
    assert scene.reference.coordinate_names == scene.coordinate_names, label
    records = cross_check(scene, samples=samples, seed=seed, repeat=1)
    # the compiled kernels' rows too: random trees have no modal bodies or mimic joints
    assert [r.quantity for r in records] == list(QUANTITIES + COMPILED_ROWS)
    bad = [
        f"{r.quantity} (rel {r.max_rel_err:.3g}, abs {r.max_abs_err:.3g})"
        for r in records
        if not close(r.max_rel_err, 0.0, rel=TOL, scale=1.0)  # a relative error: scale 1
    ]
    assert not bad, f"{label} seed={seed} nv={scene.textbook.nv}: " + "; ".join(bad)


# --- (a) revolute, prismatic and fixed joints -------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS, ids=lambda s: f"seed={s}")
def test_random_tree_basic(seed):
    assert_agrees(random_tree(seed, joint_types=BASIC), "random_tree[basic]", seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(1000, 1000 + len(SEEDS)), ids=lambda s: f"seed={s}")
def test_random_tree_basic_more(seed):
    assert_agrees(random_tree(seed, joint_types=BASIC), "random_tree[basic]", seed)


# --- (b) continuous, floating and planar joints, each mixed with the basic ones ----------


FAMILY_CASES = [(family, base + k) for family, (base, _) in FAMILIES.items() for k in SEEDS]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("family", "seed"), FAMILY_CASES, ids=[f"{f}-seed={s}" for f, s in FAMILY_CASES]
)
def test_random_tree_family(family, seed):
    types = FAMILIES[family][1]
    assert_agrees(random_tree(seed, joint_types=types), f"random_tree[{family}]", seed)


# --- large and structured scenes --------------------------------------------------------


@pytest.mark.slow
def test_serial_chain_50():
    assert_agrees(serial_chain(50), "serial_chain(50)", 0)


def test_balanced_tree_50():
    assert_agrees(balanced_tree(50), "balanced_tree(50)", 0)


def test_elastic_chain_5():
    text = elastic_chain(5)
    scene = scene_from_text(text, "elastic_chain(5)")
    assert scene.textbook.nv == 30 and set(scene.textbook.kind) == {"euler6"}
    assert_agrees(text, "elastic_chain(5)", 0)


def test_elastic_chain_bushing_deformation_is_the_pair_coordinates():
    """Frame 1 = construction frame, frame 2 = body frame, so δ = q_j and U = ½ Σ C q²."""
    scene = scene_from_text(elastic_chain(3, seed=7), "elastic_chain(3)")
    tm, td = scene.textbook, scene.textbook_data
    index = {name: i for i, name in enumerate(tm.coordinate_names)}
    q = np.random.default_rng(7).uniform(-0.5, 0.5, tm.nv)
    expected = 0.0
    for b in scene.description.bushings:
        names = [f"{b.frame2.link}_{s}" for s in ("x", "y", "z", "rx", "ry", "rz")]
        qj = q[[index[n] for n in names]]
        expected += 0.5 * float(qj @ b.stiffness @ qj)
    assert len(scene.description.bushings) == 3
    assert_close(forces.spring_potential(tm, td, q), expected, rel=1e-12)


ONE_COORDINATE_WITH_BUSHING = """<?xml version="1.0"?>
<robot name="one_coordinate" xmlns:rt70="urn:rt70:urdf-extensions:1">
  <link name="world"/>
  <joint name="j1" type="revolute">
    <parent link="world"/>
    <child link="b1"/>
    <origin xyz="0 0 1" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1000" upper="1000" effort="1e+12" velocity="1e+06"/>
  </joint>
  <link name="b1">
    <inertial>
      <origin xyz="0.1 0 -0.5" rpy="0 0 0"/>
      <mass value="2"/>
      <inertia ixx="0.2" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.1"/>
    </inertial>
  </link>
  <rt70:bushing name="ground_b1" stiffness="10 20 30 4 5 6" damping="1 2 3 0.4 0.5 0.6">
    <rt70:frame1 link="world" xyz="0.3 0 1" rpy="0 0 0"/>
    <rt70:frame2 link="b1" xyz="0.3 0 0" rpy="0 0 0"/>
  </rt70:bushing>
</robot>
"""


def test_one_coordinate_scene_with_bushing():
    """One coordinate and a bushing: Pinocchio returns a 6 × 1 frame Jacobian as shape (6,)."""
    assert_agrees(ONE_COORDINATE_WITH_BUSHING, "one_coordinate", 0)


def test_mixed_chain_and_tree_with_all_joint_types():
    assert_agrees(serial_chain(12, seed=3, joint_types=ALL_JOINT_TYPES), "serial_chain(12)", 3)
    text = balanced_tree(15, branching=3, seed=4, joint_types=ALL_JOINT_TYPES)
    assert_agrees(text, "balanced_tree(15, 3)", 4)


# --- the generators themselves ----------------------------------------------------------


def _joints(text: str) -> list[ET.Element]:
    return ET.fromstring(text).findall("joint")


def test_generators_are_deterministic():
    for make in (
        lambda s: random_tree(s),
        lambda s: serial_chain(6, seed=s, joint_types=ALL_JOINT_TYPES),
        lambda s: balanced_tree(9, 3, seed=s, joint_types=ALL_JOINT_TYPES),
        lambda s: elastic_chain(2, seed=s),
    ):
        assert make(11) == make(11)
        assert make(11) != make(12)


def test_generated_text_loads_in_both_readers():
    texts = [random_tree(seed) for seed in range(60)]
    texts += [serial_chain(5, seed=1, joint_types=ALL_JOINT_TYPES), elastic_chain(2)]
    texts += [balanced_tree(7, branching=2, seed=2, joint_types=ALL_JOINT_TYPES)]
    for text in texts:
        read_urdf_string(text)
        model = pin.buildModelFromXML(text)
        assert scene_from_text(text).textbook.nv == model.nv


def test_structure_of_chain_and_tree():
    chain = _joints(serial_chain(5))
    assert [j.find("parent").get("link") for j in chain] == ["world", "b1", "b2", "b3", "b4"]
    tree = _joints(balanced_tree(7, branching=2))
    assert [j.find("parent").get("link") for j in tree] == [
        "world", "b1", "b1", "b2", "b2", "b3", "b3",
    ]  # fmt: skip
    assert {j.get("type") for j in chain} == {"revolute"}


def test_random_trees_cover_what_they_promise():
    """Over 200 seeds: every joint type, axes of every kind, massless links, springs."""
    types, axes, features = Counter(), Counter(), Counter()
    for seed in range(200):
        root = ET.fromstring(random_tree(seed))
        links = {link.get("name"): link for link in root.findall("link")}
        parents = {j.find("parent").get("link") for j in root.findall("joint")}
        for joint in root.findall("joint"):
            jtype = joint.get("type")
            types[jtype] += 1
            child = links[joint.find("child").get("link")]
            if child.find("inertial") is None:
                features["massless"] += 1
                assert child.get("name") in parents, f"seed {seed}: massless leaf"
                assert jtype in ("fixed", "revolute", "prismatic", "continuous")
            axis = joint.find("axis")
            if jtype == "planar":
                assert axis.get("xyz") == "0 0 1"
            elif jtype in ("fixed", "floating"):
                assert axis is None
            else:
                a = np.array([float(x) for x in axis.get("xyz").split()])
                assert_close(np.linalg.norm(a), 1.0, rel=1e-12)  # unit axis, as written
                if np.count_nonzero(a) > 1:
                    axes["unaligned"] += 1
                else:
                    axes["negative" if a.sum() < 0 else "positive"] += 1
            has_limit = joint.find("limit") is not None
            assert has_limit == (jtype in ("revolute", "prismatic"))
        features["bushing"] += len(root.findall(f"{NS}bushing"))
        features["joint_spring"] += len(root.findall(f"{NS}joint_spring"))
    assert set(types) == set(ALL_JOINT_TYPES)
    assert min(axes[k] for k in ("unaligned", "negative", "positive")) > 10
    assert min(features[k] for k in ("massless", "bushing", "joint_spring")) > 10


def test_inertias_are_valid_with_off_diagonal_terms():
    desc = read_urdf_string(random_tree(5, n_bodies=8, joint_types=BASIC))
    masses = [link.inertial.mass for link in desc.links.values() if link.inertial is not None]
    assert masses and all(0.1 <= m <= 10.0 for m in masses)
    for link in desc.links.values():
        if link.inertial is not None:
            moments = np.linalg.eigvalsh(link.inertial.inertia)
            assert moments[0] > 0 and moments[2] < moments[0] + moments[1]
            assert np.abs(link.inertial.inertia - np.diag(np.diag(link.inertial.inertia))).max() > 0


@pytest.mark.parametrize(
    "call",
    [
        lambda: serial_chain(0),
        lambda: balanced_tree(3, branching=0),
        lambda: elastic_chain(0),
        lambda: random_tree(0, n_bodies=0),
        lambda: random_tree(0, joint_types=("ball",)),
        lambda: serial_chain(3, joint_types=()),
    ],
)
def test_bad_arguments_raise(call):
    with pytest.raises(ValueError):
        call()


def test_hanging_elastic_chain_hangs_straight_down():
    """The same draws as the standing chain, the construction frames straight below."""
    import re

    standing, hanging = elastic_chain(3, seed=5), elastic_chain(3, seed=5, hanging=True)
    pattern = r'<origin xyz="([^"]+)" rpy="([^"]+)"/>\s*<axis xyz="1 0 0"/>\s*<limit[^>]*/>'
    pattern = r'_x" type="prismatic">\s*<parent[^>]*/>\s*<child[^>]*/>\s*' + pattern
    up = [list(map(float, x.split())) for x, _ in re.findall(pattern, standing)]
    down = re.findall(pattern, hanging)
    assert len(up) == len(down) == 3
    for (x, rpy), (_, _, z) in zip(down, up, strict=True):
        assert list(map(float, x.split())) == [0.0, 0.0, -z] and z > 0
        assert list(map(float, rpy.split())) == [0.0, 0.0, 0.0]
    assert elastic_chain(3, seed=5, hanging=False) == standing
