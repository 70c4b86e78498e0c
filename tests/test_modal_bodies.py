"""Modal flexible bodies in the tree (``<rt70:modal_body>``), on both sides.

The textbook side writes a modal body from its inertia invariants in the floating frame
(rt70.textbook.modal_bodies); the reference side makes its nodes point masses on
translation joints in Pinocchio, tied to the modes (rt70.reference.modal_nodes). With
lumped masses the two are one body in two sets of variables, so every quantity agrees
to rounding — on a deep tree, on a link welded at an offset, on the ground, with some
of the file's modes. Independent of both: the slewing truss with every mode of its FE
model gives the frequencies of the FE model itself with the hub's rotation added.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70.errors import ExtensionError
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.scene import load_scene, scene_from_text
from rt70.reference import dynamics as ref_dynamics
from rt70.reference import forces as ref_forces
from rt70.reference import reactions as ref_reactions
from rt70.reports import slewing_truss
from rt70.scenes import modal_scenes
from rt70.testing import assert_close
from rt70.textbook import dynamics as tb_dynamics
from rt70.textbook import forces as tb_forces
from rt70.textbook import reactions as tb_reactions
from rt70.textbook import structured
from rt70.urdf.modal_file import ModalArrays, read_modal_file, write_modal_file

RNG = np.random.default_rng(20261127)
NS = 'xmlns:rt70="urn:rt70:urdf-extensions:1"'
ROUNDING = 1e-12  # relative to each quantity's largest entry: sums of ~100 products


@pytest.fixture(scope="module")
def truss_file(tmp_path_factory) -> Path:
    """The slewing truss's arm with 4 modes, as a modal body file."""
    path = tmp_path_factory.mktemp("modal") / "arm.npz"
    return write_modal_file(path, modal_scenes.truss_arm(modes=4))


def deep_tree(file: Path, extra: str = "") -> str:
    """A slewing base, an elevation boom, a body welded at an offset, a prismatic tip.

    Two modal bodies: ``arm`` (3 of the file's modes, damped at 2 %) on the welded link
    ``mount``, and ``pad_arm`` (2 modes) on a link welded to the ground.
    """
    inertia = '<inertia ixx="{0}" iyy="{1}" izz="{2}" ixy="1" ixz="0.5" iyz="0"/>'
    return f"""<robot name="deep" {NS}>
  <link name="world"/>
  <link name="base"><inertial><mass value="300"/><origin xyz="0.1 0 0.2"/>
    {inertia.format(30, 25, 20)}</inertial></link>
  <joint name="slew" type="continuous"><parent link="world"/><child link="base"/>
    <axis xyz="0 0 1"/></joint>
  <link name="boom"><inertial><mass value="100"/><origin xyz="0 0.2 0"/>
    {inertia.format(10, 20, 20)}</inertial></link>
  <joint name="elev" type="revolute"><parent link="base"/><child link="boom"/>
    <origin xyz="0 0 2" rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="mount"/>
  <joint name="weld" type="fixed"><parent link="boom"/><child link="mount"/>
    <origin xyz="0.5 0.1 -0.2" rpy="0.3 -0.2 0.1"/></joint>
  <link name="tip"><inertial><mass value="5"/><origin xyz="0 0 0"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="mount"/><child link="tip"/>
    <origin xyz="1 0 0"/><axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <rt70:joint_spring name="elev_spring" joint="elev" stiffness="2e6" damping="100"/>
  <rt70:modal_body name="arm" link="mount" file="{file}" modes="3" damping_ratio="0.02"/>
  <link name="pad"/>
  <joint name="pad_weld" type="fixed"><parent link="world"/><child link="pad"/>
    <origin xyz="3 0 0" rpy="0 0.4 0"/></joint>
  <rt70:modal_body name="pad_arm" link="pad" file="{file}" modes="2"/>
  {extra}
</robot>"""


@pytest.fixture(scope="module")
def deep(truss_file):
    return scene_from_text(deep_tree(truss_file), "deep")


def states(nv: int, count: int = 3):
    for _ in range(count):
        yield RNG.normal(0.0, 0.4, nv), RNG.normal(0.0, 1.0, nv), RNG.normal(0.0, 1.0, nv)


def test_coordinates_follow_the_joints(deep):
    names = ["slew", "elev", "slide", "arm:eta1", "arm:eta2", "arm:eta3"]
    assert deep.textbook.coordinate_names == names + ["pad_arm:eta1", "pad_arm:eta2"]
    assert deep.reference.coordinate_names == deep.textbook.coordinate_names


def assert_sides_agree(scene, q: np.ndarray, qd: np.ndarray) -> None:
    """A, S G, B q̇, T, U, the spring and damper forces, their potential and q̈ of the two
    sides at one state, to rounding (q̈ to 1e-10)."""
    tm, td = scene.textbook, scene.textbook_data
    rm, rd = scene.reference, scene.reference_data
    for name, args in (
        ("mass_matrix", (q,)),
        ("gravity_force", (q,)),
        ("bias_force", (q, qd)),
    ):
        expected = getattr(ref_dynamics, name)(rm, rd, *args)
        actual = getattr(tb_dynamics, name)(tm, td, *args)
        assert_close(actual, expected, rel=ROUNDING, scale=np.abs(expected).max(), what=name)
    T = ref_dynamics.kinetic_energy(rm, rd, q, qd)
    assert_close(tb_dynamics.kinetic_energy(tm, td, q, qd), T, rel=ROUNDING)
    U = ref_dynamics.gravity_potential(rm, rd, q)
    assert_close(tb_dynamics.gravity_potential(tm, td, q), U, rel=ROUNDING)
    Qc, Qd = tb_forces.spring_damper_force(tm, td, q, qd)
    for actual, expected in zip((Qc, Qd), ref_forces.spring_damper_force(rm, rd, q, qd),
                                strict=True):  # fmt: skip
        assert_close(actual, expected, rel=ROUNDING, scale=np.abs(expected).max())
    U_c = ref_forces.spring_potential(rm, rd, q)
    assert U_c > 0.0
    assert_close(tb_forces.spring_potential(tm, td, q), U_c, rel=ROUNDING)
    qdd = ref_dynamics.forward_dynamics(rm, rd, q, qd)
    actual = tb_dynamics.forward_dynamics(tm, td, q, qd, Qc + Qd)
    assert_close(actual, qdd, rel=1e-10, scale=np.abs(qdd).max(), what="q̈")


def test_the_sides_agree_to_rounding(deep):
    for q, qd, _ in states(deep.textbook.nv):
        assert_sides_agree(deep, q, qd)


def test_reactions_carry_the_bodies(deep):
    tm, td, rm, rd = deep.textbook, deep.textbook_data, deep.reference, deep.reference_data
    for q, qd, qdd in states(tm.nv):
        expected = ref_reactions.joint_reactions(rm, rd, q, qd, qdd)
        actual = tb_reactions.joint_reactions(tm, td, q, qd, qdd)
        assert sorted(actual) == sorted(expected) == ["elev", "slew", "slide"]
        scale = max(np.abs(v).max() for v in expected.values())
        for joint, wrench in expected.items():
            assert_close(actual[joint], wrench, rel=ROUNDING, scale=scale, what=joint)


def test_structured_form_equals_the_dense_one(deep):
    tm, td = deep.textbook, deep.textbook_data
    bd = structured.BatchData(tm, 2)
    Q = RNG.normal(0.0, 0.4, (2, tm.nv))
    Qd = RNG.normal(0.0, 1.0, (2, tm.nv))
    A = structured.mass_matrix_batch(tm, bd, Q)
    b = structured.bias_force_batch(tm, bd, Q, Qd)
    g = structured.gravity_force_batch(tm, bd, Q)
    for c in range(2):
        for actual, expected in (
            (A[c], tb_dynamics.mass_matrix(tm, td, Q[c])),
            (b[c], tb_dynamics.bias_force(tm, td, Q[c], Qd[c])),
            (g[c], tb_dynamics.gravity_force(tm, td, Q[c])),
        ):
            assert_close(actual, expected, rel=ROUNDING, scale=np.abs(expected).max())


def test_a_body_on_the_ground_has_the_files_frequencies(truss_file):
    text = f"""<robot name="fixed" {NS}><link name="world"/>
      <rt70:modal_body name="arm" link="world" file="{truss_file}"/></robot>"""
    scene = scene_from_text(text, "fixed")
    lm = lin.linearize(scene, np.zeros(scene.textbook.nv))
    found = modal.modes(lm.M, lm.K).freq_hz
    body = read_modal_file(truss_file, "test")
    expected = np.sqrt(np.diag(body.stiffness)) / (2.0 * np.pi)
    assert_close(np.sort(found), np.sort(expected), rel=1e-9)


@pytest.mark.slow
def test_full_basis_truss_on_its_hub_is_the_fe_model(tmp_path):
    """Every mode: the FE model itself (the stiffness by central differences, 1e-7)."""
    found = slewing_truss.modal_frequencies(slewing_truss.interior_dofs(), tmp_path, 10)
    assert_close(found, slewing_truss.direct_frequencies(10), rel=1e-7)


def test_truncated_truss_on_its_hub_lies_above_the_fe_model(tmp_path):
    """Four modes: the frequencies are a Ritz estimate, above the FE model's, near for f1."""
    found = slewing_truss.modal_frequencies(4, tmp_path, 4)
    exact = slewing_truss.direct_frequencies(4)
    assert np.all(found >= exact * (1.0 - 1e-9))
    assert_close(found[0], exact[0], rel=1e-4)


def test_the_shipped_scene_and_file():
    scene = load_scene("slewing_truss")
    assert scene.textbook.nv == 1 + modal_scenes.TRUSS_MODES
    body = scene.description.modal_bodies[0]
    fresh = modal_scenes.truss_arm()
    assert_close(body.masses, fresh.masses, rel=1e-15)
    assert_close(np.diag(body.stiffness), np.diag(fresh.stiffness), rel=1e-9)
    assert_close(body.shapes, fresh.shapes, rel=1e-7, scale=np.abs(fresh.shapes).max())


def _arrays(**changes) -> ModalArrays:
    body = modal_scenes.truss_arm(modes=2)
    fields = {k: getattr(body, k) for k in ("nodes", "masses", "shapes", "stiffness", "damping")}
    fields.update(changes)
    return ModalArrays(**fields)


@pytest.mark.parametrize(
    ("attributes", "message"),
    [
        ('link="nowhere" file="{f}"', "nowhere"),
        ('link="world" file="{f}.missing"', "not found"),
        ('link="world" file="{f}" modes="0"', 'modes="0"'),
        ('link="world" file="{f}" modes="3"', 'modes="3"'),
        ('link="world" file="{f}" damping_ratio="-0.1"', "damping_ratio"),
    ],
)
def test_bad_elements_are_refused(tmp_path, attributes, message):
    path = write_modal_file(tmp_path / "b.npz", _arrays())
    text = f"""<robot name="bad" {NS}><link name="world"/>
      <rt70:modal_body name="b" {attributes.format(f=path)}/></robot>"""
    with pytest.raises(ExtensionError, match=message):
        scene_from_text(text, "bad")


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"stiffness": np.array([[1.0, 2.0], [0.0, 1.0]])}, "stiffness is not symmetric"),
        ({"stiffness": np.diag([1.0, -1.0])}, "not positive semidefinite"),
        ({"masses": np.zeros(24)}, "positive total"),
        ({"shapes": np.zeros((24, 3, 2))}, "moves no mass"),
        ({"nodes": np.full((24, 3), np.nan)}, "NaN"),
        ({"damping": np.ones((3, 3))}, r"damping has shape \(3, 3\)"),
    ],
)
def test_bad_files_are_refused(tmp_path, changes, message):
    with pytest.raises(ExtensionError, match=message):
        write_modal_file(tmp_path / "b.npz", _arrays(**changes))


def test_a_damping_ratio_beside_the_files_damping_is_refused(tmp_path):
    path = write_modal_file(tmp_path / "d.npz", _arrays(damping=np.eye(2)))
    text = f"""<robot name="bad" {NS}><link name="world"/>
      <rt70:modal_body name="b" link="world" file="{path}" damping_ratio="0.01"/></robot>"""
    with pytest.raises(ExtensionError, match="not both"):
        scene_from_text(text, "bad")


def test_another_format_is_refused(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, format=np.array("rt70-fe/1"))
    text = f"""<robot name="bad" {NS}><link name="world"/>
      <rt70:modal_body name="b" link="world" file="{path}"/></robot>"""
    with pytest.raises(ExtensionError, match="expected 'rt70-modal/1'"):
        scene_from_text(text, "bad")


def test_a_sweep_scales_the_modal_stiffness_and_damping():
    from rt70.sweep.quantities import PARAMETERS

    desc = load_scene("slewing_truss").description
    body = desc.modal_bodies[0]
    stiff = PARAMETERS["stiffness"].apply(desc, 4.0).modal_bodies[0]
    damped = PARAMETERS["damping"].apply(desc, 0.5).modal_bodies[0]
    assert np.array_equal(stiff.stiffness, 4.0 * body.stiffness)
    assert np.array_equal(stiff.damping, body.damping)
    assert np.array_equal(damped.damping, 0.5 * body.damping)
    assert float(body.stiffness[0, 0]) in PARAMETERS["stiffness"].values(desc)


def test_mode_shapes_draw_the_bodys_nodes():
    from rt70.linear.mode_shapes import link_positions, structure_lines

    scene = load_scene("slewing_truss")
    body = scene.description.modal_bodies[0]
    lines = structure_lines(scene)
    assert len(lines.nodes) == body.nodes.shape[0]
    assert len(lines.segments) >= body.edges.shape[0] > 0
    q = np.zeros(scene.textbook.nv)
    q[scene.textbook.modal[0].coords.start] = 0.01  # the first mode, the hub at rest
    moved = link_positions(scene, q, lines) - link_positions(scene, 0 * q, lines)
    expected = 0.01 * body.shapes[:, :, 0]
    at = [i for i, _, _ in lines.nodes]
    assert_close(moved[at], expected, rel=1e-12, scale=np.abs(expected).max())
