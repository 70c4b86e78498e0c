"""Links on a modal body's nodes (``<rt70:interface>``), on both sides.

A link on a node is carried by a chain of joints whose coordinates follow the modes
(rt70.urdf.modal_interfaces): the textbook side takes them out of q through
``q_full = G q + H η``, the reference side maps Pinocchio's joints to η. The two agree to
rounding on a tree that hangs a body and a hinged flap on a node, with the node's
rotations and without. Independent of both: a rigid body on a node of a grounded body
adds its closed-form kinetic energy; the slewing truss with a mass on its corner and
every mode gives the frequencies of its FE model with the mass added to the node.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from test_modal_bodies import NS, ROUNDING, assert_sides_agree, deep_tree, states

from rt70.errors import ExtensionError, Rt70Error
from rt70.model.scene import scene_from_text
from rt70.reference import dynamics as ref_dynamics
from rt70.reference import reactions as ref_reactions
from rt70.reports import slewing_truss
from rt70.scenes import modal_scenes
from rt70.testing import assert_close
from rt70.textbook import dynamics as tb_dynamics
from rt70.textbook import reactions as tb_reactions
from rt70.textbook import structured
from rt70.urdf.modal_file import read_modal_file, write_modal_file

RNG = np.random.default_rng(20261128)
NODE = 5  # a node of the truss arm off its clamped face

HANG = """<link name="hang"><inertial><mass value="40"/><origin xyz="0.2 0.1 -0.3"/>
    <inertia ixx="3" iyy="2.5" izz="1.5" ixy="0.1" ixz="0" iyz="0"/></inertial></link>
  <joint name="hang_mount" type="fixed"><parent link="arm_tip"/><child link="hang"/>
    <origin xyz="0.1 0 0" rpy="0.2 0 0"/></joint>
  <link name="flap"><inertial><mass value="7"/><origin xyz="0.3 0 0"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="hang"/><child link="flap"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>"""


def with_interface(text: str, node: int = NODE, link: str = "arm_tip") -> str:
    """``text`` with an interface on the body ``arm``."""
    return text.replace(
        'modes="3" damping_ratio="0.02"/>',
        f'modes="3" damping_ratio="0.02"><rt70:interface link="{link}" node="{node}"/>'
        "</rt70:modal_body>",
    )


@pytest.fixture(scope="module", params=["translations", "rotations"])
def arm_file(request, tmp_path_factory) -> Path:
    """The truss arm's file, as it is (nodes that only translate) and with rotations."""
    arm = modal_scenes.truss_arm(modes=4)
    if request.param == "rotations":  # any rows will do for the two sides' agreement
        arm = dataclasses.replace(arm, rotations=RNG.normal(0.0, 0.1, arm.shapes.shape))
    return write_modal_file(tmp_path_factory.mktemp("iface") / f"{request.param}.npz", arm)


@pytest.fixture(scope="module")
def hanging(arm_file):
    return scene_from_text(with_interface(deep_tree(arm_file, HANG)), "hanging")


def test_chain_joints_are_not_coordinates(hanging, arm_file):
    names = ["slew", "elev", "slide", "hinge", "arm:eta1", "arm:eta2", "arm:eta3"]
    assert hanging.textbook.coordinate_names == names + ["pad_arm:eta1", "pad_arm:eta2"]
    assert hanging.reference.coordinate_names == hanging.textbook.coordinate_names
    (interface,) = hanging.description.modal_bodies[0].interfaces
    six = read_modal_file(arm_file, "test").rotations is not None
    assert interface.joints == tuple(
        f"arm_tip__{s}" for s in ("x", "y", "z", "rx", "ry", "rz")[: 6 if six else 3]
    )
    assert interface.rows.shape == (6 if six else 3, 3)


def test_the_sides_agree_to_rounding(hanging):
    tm, td, rm, rd = (
        hanging.textbook,
        hanging.textbook_data,
        hanging.reference,
        hanging.reference_data,
    )
    for q, qd, qdd in states(tm.nv):
        assert_sides_agree(hanging, q, qd)
        expected = ref_reactions.joint_reactions(rm, rd, q, qd, qdd)
        reactions = tb_reactions.joint_reactions(tm, td, q, qd, qdd)
        assert sorted(reactions) == sorted(expected)
        assert "hinge" in expected and "arm_tip__z" in expected
        scale = max(np.abs(v).max() for v in expected.values())
        for joint, wrench in expected.items():
            assert_close(reactions[joint], wrench, rel=ROUNDING, scale=scale, what=joint)


def test_structured_form_equals_the_dense_one(hanging):
    tm, td = hanging.textbook, hanging.textbook_data
    data = structured.BatchData(tm, 1)
    for q, qd, _ in states(tm.nv):
        A = tb_dynamics.mass_matrix(tm, td, q)
        assert_close(structured.mass_matrix_batch(tm, data, q[None])[0], A, rel=ROUNDING,
                     scale=np.abs(A).max())  # fmt: skip
        b = tb_dynamics.bias_force(tm, td, q, qd)
        assert_close(structured.bias_force(tm, data, q, qd), b, rel=ROUNDING,
                     scale=np.abs(b).max())  # fmt: skip
        g = tb_dynamics.gravity_force(tm, td, q)
        assert_close(structured.gravity_force_batch(tm, data, q[None])[0], g, rel=ROUNDING,
                     scale=np.abs(g).max())  # fmt: skip


def test_a_rigid_body_on_a_node_adds_its_kinetic_energy(tmp_path):
    """A grounded body with a rigid link on node n: at η = 0 the link's velocity is
    ``v = Φ_n η̇ + (Ψ_n η̇) × c`` at its centre of mass c (from the node) and its angular
    velocity ``Ψ_n η̇``, so ``A = M_ηη + m Dᵀ D + Ψ_nᵀ J Ψ_n`` with ``D = Φ_n − <c> Ψ_n``."""
    arm = modal_scenes.truss_arm(modes=4)
    arm = dataclasses.replace(arm, rotations=RNG.normal(0.0, 0.1, arm.shapes.shape))
    file = write_modal_file(tmp_path / "arm.npz", arm)
    mass, c = 30.0, np.array([0.3, -0.2, 0.5])
    J = np.array([[4.0, 0.2, 0.1], [0.2, 3.0, -0.3], [0.1, -0.3, 2.0]])
    text = f"""<robot name="grounded" {NS}>
  <link name="world"/>
  <rt70:modal_body name="arm" link="world" file="{file}">
    <rt70:interface link="tip" node="{NODE}"/></rt70:modal_body>
  <link name="load"><inertial><mass value="{mass}"/><origin xyz="{c[0]} {c[1]} {c[2]}"/>
    <inertia ixx="{J[0, 0]}" iyy="{J[1, 1]}" izz="{J[2, 2]}" ixy="{J[0, 1]}" ixz="{J[0, 2]}"
      iyz="{J[1, 2]}"/></inertial></link>
  <joint name="load_mount" type="fixed"><parent link="tip"/><child link="load"/></joint>
</robot>"""
    scene = scene_from_text(text, "grounded")
    Phi, Psi = arm.shapes[NODE], arm.rotations[NODE]
    c_skew = np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])
    D = Phi - c_skew @ Psi
    expected = arm.modal_mass + mass * D.T @ D + Psi.T @ J @ Psi
    q = np.zeros(4)
    for A in (
        tb_dynamics.mass_matrix(scene.textbook, scene.textbook_data, q),
        ref_dynamics.mass_matrix(scene.reference, scene.reference_data, q),
    ):
        assert_close(A, expected, rel=ROUNDING, scale=np.abs(expected).max())


def test_a_mass_on_the_truss_corner_with_every_mode_is_the_fe_model_with_it(tmp_path):
    modes = slewing_truss.interior_dofs()
    found = slewing_truss.modal_frequencies(modes, tmp_path, 10, tip_mass=150.0)
    expected = slewing_truss.direct_frequencies(10, tip_mass=150.0)
    assert expected[0] < slewing_truss.direct_frequencies(1)[0]  # the mass counts
    assert_close(found, expected, rel=1e-7)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: with_interface(t, node=999), 'node="999" is not a node of the file'),
        (lambda t: with_interface(t, node=-1), 'node="-1" is not a node of the file'),
        (lambda t: with_interface(t, link="base"), "generated name 'base' is taken"),
        (
            lambda t: with_interface(t).replace(
                "</rt70:modal_body>",
                '<rt70:interface link="arm_tip" node="2"/></rt70:modal_body>',
            ),
            "generated name 'arm_tip__x' is taken",
        ),
        (
            lambda t: with_interface(t).replace('node="5"', 'node="5" side="left"'),
            "side",
        ),
    ],
)
def test_a_wrong_interface_is_refused(tmp_path, edit, message):
    file = write_modal_file(tmp_path / "arm.npz", modal_scenes.truss_arm(modes=4))
    with pytest.raises(ExtensionError, match=message):
        scene_from_text(edit(deep_tree(file)), "bad")


def test_a_file_with_rotations_of_the_wrong_shape_is_refused(tmp_path):
    arm = modal_scenes.truss_arm(modes=4)
    bad = dataclasses.replace(arm, rotations=np.zeros((3, 3, 4)))
    with pytest.raises(ExtensionError, match="rotations has shape"):
        write_modal_file(tmp_path / "bad.npz", bad)


def test_the_corner_as_a_boundary_node_is_its_displacement(tmp_path):
    """Constraint modes of an interface node first: its rows of the shapes are the unit
    matrix there, the file stays sound, and with every coordinate the scene with a mass
    on the corner is again the FE model with the mass."""
    corner = slewing_truss.tip_node() + 1
    arm = modal_scenes.truss_arm(modes=5, interface=(corner,))
    node = int(np.argmax(arm.nodes.sum(axis=1)))
    assert arm.shapes.shape[2] == 8
    assert_close(arm.shapes[node, :, :3], np.eye(3), rel=ROUNDING)
    assert_close(arm.shapes[node, :, 3:], np.zeros((3, 5)), rel=ROUNDING, scale=1.0)
    write_modal_file(tmp_path / "checked.npz", arm)  # symmetric, semidefinite, massive
    full = slewing_truss.interior_dofs() - 3
    found = slewing_truss.modal_frequencies(full, tmp_path, 6, 150.0, corner_modes=True)
    assert_close(found, slewing_truss.direct_frequencies(6, tip_mass=150.0), rel=1e-7)


def test_a_clamped_node_cannot_be_an_interface_node():
    with pytest.raises(Rt70Error, match="both clamped and an interface node"):
        modal_scenes.truss_arm(modes=4, interface=(1,))
