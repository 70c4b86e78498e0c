"""Elastic and dissipative elements: one list of kinds per side, each defined by δ(q), ∂δ/∂q.

Every element kind the URDF description can hold has an implementation on both sides
(``forces.ELEMENTS``); each kind's Jacobian is the derivative of its deformation (so the
force ``−Jᵀ C δ`` is that of the potential ``½ δᵀ C δ``); and the two independent
implementations agree kind by kind.
"""

import dataclasses
import typing

import numpy as np
import pytest
from scipy.linalg import block_diag

import rt70.reference as reference
from rt70.model.scene import load_scene, scene_from_text
from rt70.reference import forces as ref_forces
from rt70.scenes.synthetic import random_tree
from rt70.testing import assert_close
from rt70.textbook import forces as tb_forces
from rt70.textbook.kinematics import update_structure
from rt70.urdf.description import RobotDescription

INERTIA = '<inertia ixx="0.1" iyy="0.2" izz="0.15" ixy="0.01" ixz="0" iyz="0.02"/>'
LIMIT = '<limit lower="-3" upper="3" effort="1" velocity="1"/>'


def _coupled(scale: float, seed: int) -> np.ndarray:
    """A full symmetric positive definite 6 × 6: every axis coupled to every other."""
    L = np.random.default_rng(seed).uniform(-1.0, 1.0, (6, 6))
    C = scale * (L @ L.T + np.eye(6))
    return 0.5 * (C + C.T)


COUPLED_C, COUPLED_D = _coupled(80.0, 11), _coupled(0.5, 12)


def _numbers(matrix: np.ndarray) -> str:
    return " ".join(f"{x:.17g}" for x in matrix.ravel())


def chain(mimic: bool, extra_spring: bool = False) -> str:
    """Three bodies, joint springs on every joint and a bushing to the ground."""
    link = "".join(
        f'<link name="l{i}"><inertial><origin xyz="0.2 0.1 0"/><mass value="{i}"/>{INERTIA}'
        "</inertial></link>"
        for i in (1, 2, 3)
    )
    coupling = '<mimic joint="j1" multiplier="-0.7" offset="0.1"/>' if mimic else ""
    joints = (
        f'<joint name="j1" type="revolute"><parent link="world"/><child link="l1"/>'
        f'<axis xyz="0 0 1"/>{LIMIT}</joint>'
        f'<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>'
        f'<origin xyz="0.5 0 0" rpy="0.1 0 0"/><axis xyz="0 1 0"/>{coupling}{LIMIT}</joint>'
        f'<joint name="j3" type="prismatic"><parent link="l2"/><child link="l3"/>'
        f'<origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>{LIMIT}</joint>'
    )
    springs = "".join(
        f'<rt70:joint_spring name="s{j}" joint="j{j}" stiffness="{10 * j}" damping="{0.1 * j}"/>'
        for j in (1, 2, 3)
    )
    if extra_spring:
        springs += '<rt70:joint_spring name="s1b" joint="j1" stiffness="7" damping="0.2"/>'
    bushing = (
        '<rt70:bushing name="b" stiffness="100 110 120 50 60 70" damping="1 2 3 0.4 0.5 0.6">'
        '<rt70:frame1 link="world" xyz="0.9 0 0.1" rpy="0 0.1 0"/>'
        '<rt70:frame2 link="l3" xyz="0 0 0.1"/></rt70:bushing>'
        f'<rt70:bushing name="coupled" stiffness="{_numbers(COUPLED_C)}" '
        f'damping="{_numbers(COUPLED_D)}">'
        '<rt70:frame1 link="l1" xyz="0.3 0.1 0" rpy="0.2 0 0"/>'
        '<rt70:frame2 link="l3" xyz="0 0.1 0"/></rt70:bushing>'
    )
    return (
        '<robot name="chain" xmlns:rt70="urn:rt70:urdf-extensions:1"><link name="world"/>'
        f"{link}{joints}{springs}{bushing}</robot>"
    )


def element_kinds_of_the_description() -> list[str]:
    """The RobotDescription lists whose items are elements (they carry stiffness, damping)."""
    hints = typing.get_type_hints(RobotDescription)
    kinds = []
    for f in dataclasses.fields(RobotDescription):
        if typing.get_origin(hints[f.name]) is not list:
            continue
        (item,) = typing.get_args(hints[f.name])
        if {"stiffness", "damping"} <= {g.name for g in dataclasses.fields(item)}:
            kinds.append(f.name)
    return kinds


def test_every_element_kind_of_the_description_is_implemented_on_both_sides():
    """A new element list in RobotDescription without an implementation on a side fails."""
    kinds = element_kinds_of_the_description()
    assert set(kinds) == {"joint_springs", "bushings"}  # the finder finds what exists
    assert set(tb_forces.ELEMENTS) == set(kinds)
    assert set(ref_forces.ELEMENTS) == set(kinds)
    assert list(tb_forces.ELEMENTS) == list(ref_forces.ELEMENTS)  # same summation order


def _gain(e, what):
    """The kind's gain as one matrix on its stacked δ: block-diagonal over its elements."""
    w = np.asarray(getattr(e, what))
    return np.diag(np.broadcast_to(w, np.shape(e.delta))) if w.ndim < 3 else block_diag(*w)


def _textbook_kinds(scene, q):
    model, data = scene.textbook, scene.textbook_data
    update_structure(model, data, q)
    return {name: kind(model, data) for name, kind in tb_forces.ELEMENTS.items()}


def _reference_kinds(scene, data, q):
    model = scene.reference
    assert model.identity_map  # book coordinates are Pinocchio's (q, v)
    return {name: kind(model, data, q) for name, kind in ref_forces.ELEMENTS.items()}


def _difference_jacobian(kinds_at, q, h=1e-6):
    """∂δ/∂q of every kind by central differences of its δ."""
    cols = {name: [] for name in kinds_at(q)}
    for i in range(q.size):
        plus, minus = kinds_at(q + h * np.eye(q.size)[i]), kinds_at(q - h * np.eye(q.size)[i])
        for name in cols:
            if plus[name] is not None:
                cols[name].append(
                    (np.ravel(plus[name].delta) - np.ravel(minus[name].delta)) / 2 / h
                )
    return {name: np.column_stack(c) for name, c in cols.items() if c}


SCENES = {
    "chain": lambda: scene_from_text(chain(mimic=False), "chain"),
    "chain-mimic": lambda: scene_from_text(chain(mimic=True), "chain-mimic"),
    "random-tree": lambda: scene_from_text(random_tree(3), "tree3"),
    "rt70": lambda: load_scene("rt70"),
}


@pytest.mark.parametrize("name", SCENES)
def test_textbook_kinds_force_is_minus_jt_c_delta_of_their_own_delta(name):
    scene = SCENES[name]()
    model, n = scene.textbook, scene.textbook.nv
    rng = np.random.default_rng(2)
    q, qd = rng.uniform(-0.1, 0.1, n), rng.uniform(-0.5, 0.5, n)
    kinds = _textbook_kinds(scene, q)
    J_fd = _difference_jacobian(lambda x: _textbook_kinds(scene, x), q)
    assert set(J_fd) == {k for k, e in kinds.items() if e is not None} and J_fd
    for kind, J in J_fd.items():
        e = kinds[kind]
        f = _gain(e, "stiffness") @ np.ravel(e.delta)
        assert_close(np.ravel(e.weighted(e.stiffness, e.delta)), f, rel=1e-14, what=kind)
        Q = np.zeros(n)
        e.subtract_jt(model, Q, e.weighted(e.stiffness, e.delta))
        # against central differences of δ (h = 1e-6: error ≈ ε/h ≈ 1e-10 of δ's scale)
        assert_close(Q, -J.T @ f, rel=1e-6, what=kind)
        assert_close(np.ravel(e.rate(model, qd)), J @ qd, rel=1e-6, what=kind)
        assert_close(sum(e.squares(e.stiffness)), np.ravel(e.delta) @ f, rel=1e-13, what=kind)


@pytest.mark.parametrize("name", ["chain", "rt70"])
def test_reference_kinds_products_are_those_of_the_jacobian_of_their_delta(name):
    scene = SCENES[name]()
    data = reference.ReferenceData(scene.reference)
    n = scene.reference.nv
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-0.1, 0.1, n), rng.uniform(-0.5, 0.5, n)
    kinds = _reference_kinds(scene, data, q)
    J_fd = _difference_jacobian(lambda x: _reference_kinds(scene, data, x), q)
    assert J_fd
    for kind, J in J_fd.items():
        e = kinds[kind]
        C = _gain(e, "stiffness")
        f, terms = C @ np.ravel(e.delta), np.abs(C) @ np.abs(np.ravel(e.delta))
        Q, S, K = np.zeros(n), np.zeros(n), np.zeros((n, n))
        e.subtract_jt(Q, e.weighted(e.stiffness, e.delta))
        e.add_abs_jt(S, e.weighted_terms(e.stiffness, e.delta))
        e.add_jt_w_j(K, e.stiffness)
        # against central differences of δ, as on the textbook side
        assert_close(Q, -J.T @ f, rel=1e-6, what=kind)
        assert_close(S, np.abs(J).T @ terms, rel=1e-6, what=kind)
        assert_close(K, J.T @ C @ J, rel=1e-6, what=kind)
        assert_close(np.ravel(e.rate(v)), J @ v, rel=1e-6, what=kind)


@pytest.mark.parametrize("name", ["chain", "rt70"])
def test_the_two_sides_agree_kind_by_kind(name):
    """Same elements in the same order: equal δ and gains, per kind, from both sides."""
    scene = SCENES[name]()
    data = reference.ReferenceData(scene.reference)
    q = np.random.default_rng(5).uniform(-0.1, 0.1, scene.textbook.nv)
    tb, ref = _textbook_kinds(scene, q), _reference_kinds(scene, data, q)
    present = [k for k, e in tb.items() if e is not None]
    assert present and present == [k for k, e in ref.items() if e is not None]
    for kind in present:
        a, b = tb[kind], ref[kind]
        assert_close(np.ravel(a.delta), np.ravel(b.delta), rel=1e-12, what=kind)
        for gain in ("stiffness", "damping"):  # both read the one description: copies
            assert np.array_equal(_gain(a, gain), _gain(b, gain)), (kind, gain)


def test_two_springs_on_one_joint_add_up_in_the_gains():
    """element_gains (the implicit integrator's Σ JᵀCJ) counts every spring of a joint."""
    one = scene_from_text(chain(mimic=False), "one")
    two = scene_from_text(chain(mimic=False, extra_spring=True), "two")
    q = np.full(one.reference.nv, 0.05)
    K1, D1 = reference.element_gains(one.reference, reference.ReferenceData(one.reference), q)
    K2, D2 = reference.element_gains(two.reference, reference.ReferenceData(two.reference), q)
    i = two.reference.coordinate_index(["j1"])[0]
    # differences of sums: on the scale of the sums
    assert_close(K2[i, i] - K1[i, i], 7.0, rel=1e-12, scale=K2[i, i])
    assert_close(D2[i, i] - D1[i, i], 0.2, rel=1e-12, scale=D2[i, i])
    Qc1, _ = reference.spring_damper_force(
        one.reference, reference.ReferenceData(one.reference), q, 0 * q
    )
    Qc2, _ = reference.spring_damper_force(
        two.reference, reference.ReferenceData(two.reference), q, 0 * q
    )
    assert_close(Qc2[i] - Qc1[i], -7.0 * 0.05, rel=1e-12, scale=abs(Qc2[i]) + abs(Qc1[i]))
