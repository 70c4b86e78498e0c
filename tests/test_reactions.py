"""Joint reaction wrenches, source 004 (9)–(13), (16): both sides, the (11) projection, errata.

The textbook side (:mod:`rt70.textbook.reactions`, the book's matrices) against the
reference side (:mod:`rt70.reference.reactions`, ``pin.rnea`` and ``data.f``) and
against Pinocchio called directly; the projection identity ``S W = A q̈ + B q̇ − S G −
S U``; the impulse form (16) against ``rnea(q, 0, Δv, fext)`` with gravity off; and
errata X.3.12, the double counting of the literal leaf-to-root walks of (13).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from rt70.errors import ShapeError, UnknownLinkError
from rt70.model.scene import load_scene, scene_from_text
from rt70.physics.loads import Wrench
from rt70.reference import reactions as ref_reactions
from rt70.testing import assert_close
from rt70.textbook import dynamics, points
from rt70.textbook import reactions as tb_reactions

ALL_JOINTS = Path(__file__).parent / "data" / "all_joint_types.urdf"


def _link(name: str, rng: np.random.Generator) -> str:
    """A link with a random mass, centre of mass and rotated principal inertia."""
    m = rng.uniform(0.5, 3.0)
    a, b = rng.uniform(0.05, 0.5, 2)
    c = rng.uniform(abs(a - b) + 0.01, a + b - 0.01)  # triangle inequality
    x, y, z = rng.uniform(-0.3, 0.3, 3)
    r, p, w = rng.uniform(-1.0, 1.0, 3)
    return (
        f'<link name="{name}"><inertial><origin xyz="{x} {y} {z}" rpy="{r} {p} {w}"/>'
        f'<mass value="{m}"/><inertia ixx="{a}" ixy="0" ixz="0" iyy="{b}" iyz="0" '
        f'izz="{c}"/></inertial></link>'
    )


def _joint(name: str, kind: str, parent: str, child: str, axis: str, xyz: str, rpy: str) -> str:
    limit = '<limit lower="-3" upper="3" effort="1" velocity="1"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}</joint>'
    )


def branched_tree_text(seed: int = 4) -> str:
    """Test mechanism 2 of 004.4: RZ → RY → {RY → PX} and {RX → RZ}, random inertias.

    Fixed placements with rotations ``rpy = (0.3, 0, 0.2)`` and arbitrary offsets.
    """
    rng = np.random.default_rng(seed)
    rot = "0.3 0 0.2"
    joints = [
        ("j1", "revolute", "world", "l1", "0 0 1", "0.1 -0.2 0.3", rot),
        ("j2", "revolute", "l1", "l2", "0 1 0", "0.4 0.1 0.2", rot),
        ("j3", "revolute", "l2", "l3", "0 1 0", "0.5 0 -0.1", rot),
        ("j4", "prismatic", "l3", "l4", "1 0 0", "0.2 0.3 0", rot),
        ("j5", "revolute", "l2", "l5", "1 0 0", "-0.3 0.2 0.4", rot),
        ("j6", "revolute", "l5", "l6", "0 0 1", "0 -0.4 0.25", rot),
    ]
    links = "".join(_link(f"l{k}", rng) for k in range(1, 7))
    body = "".join(_joint(*j) for j in joints)
    head = '<?xml version="1.0"?><robot name="branched_tree"><link name="world"/>'
    return f"{head}{links}{body}</robot>"


@pytest.fixture(scope="module")
def tree():
    scene = scene_from_text(branched_tree_text(), "branched_tree")
    scene.reference  # noqa: B018
    return scene


@pytest.fixture(scope="module")
def scenes(tree):
    out = {"branched_tree": tree}
    for name in ("two_body_gravity", "rt70_servo", "gear_reducer"):
        out[name] = load_scene(name)
    out["all_joint_types"] = load_scene(ALL_JOINTS)
    return out


def _state(nv: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.5, 0.5, nv), rng.uniform(-1, 1, nv), rng.uniform(-1, 1, nv)


def _loads(scene, seed: int) -> list[Wrench]:
    rng = np.random.default_rng(seed)
    links = [n for n, (body, _, _) in scene.textbook.link_frames.items() if body >= 0]
    picked = rng.choice(links, 2)
    return [Wrench(str(link), *rng.uniform(-2.0, 2.0, (3, 3))) for link in picked]


def _stack(values: dict, names) -> np.ndarray:
    return np.concatenate([values[n] for n in names])


def test_sides_agree_on_the_branched_tree_and_pinocchio_itself(tree):
    """Mechanism 2 of 004.4: the textbook reactions are ``data.f`` of a plain ``pin.rnea``."""
    tm, td = tree.textbook, tree.textbook_data
    q, qd, qdd = _state(tm.nv, 1)
    loads = _loads(tree, 2)
    tb = tb_reactions.joint_reactions(tm, td, q, qd, qdd, loads)
    assert list(tb) == ["j1", "j2", "j3", "j4", "j5", "j6"]
    ref = ref_reactions.joint_reactions(tree.reference, tree.reference_data, q, qd, qdd, loads)
    m = tree.reference.pin_model
    d = m.createData()
    pin.forwardKinematics(m, d, q)
    fext = ref_reactions.external_forces(tree.reference, d, loads)
    pin.rnea(m, d, q, qd, qdd, fext)  # identity map: the book's q is Pinocchio's
    direct = {m.names[i]: d.f[i].vector for i in range(1, m.njoints)}
    assert_close(_stack(tb, tb), _stack(direct, tb), rel=1e-14)
    # the reference side is this very call of pin.rnea: the same numbers, bit for bit
    assert np.array_equal(_stack(ref, tb), _stack(direct, tb))


@pytest.mark.parametrize(
    "name", ["branched_tree", "two_body_gravity", "rt70_servo", "gear_reducer", "all_joint_types"]
)
def test_projection_is_the_generalised_force(scenes, name):
    """004 (11): ``Gᵀ [(M_k f_k)ᵀ R_k] = A q̈ + B q̇ − S G − S U`` to rounding."""
    scene = scenes[name]
    tm, td = scene.textbook, scene.textbook_data
    q, qd, qdd = _state(tm.nv, 3)
    loads = _loads(scene, 4)
    R = tb_reactions.pair_reactions(tm, td, q, qd, qdd, loads)
    Q = tb_reactions.projection(tm, td, R)
    terms = [
        dynamics.mass_matrix(tm, td, q) @ qdd,
        dynamics.bias_force(tm, td, q, qd),
        -dynamics.gravity_force(tm, td, q),
        *(-points.generalized_force(tm, td, q, w) for w in loads),
    ]
    scale = max(float(np.max(np.abs(t))) for t in terms)
    assert_close(Q, sum(terms), rel=1e-13, scale=scale)


@pytest.mark.parametrize("name", ["two_body_gravity", "rt70_servo", "all_joint_types"])
def test_sides_agree_per_joint(scenes, name):
    """Every URDF joint (euler6 chains, floating, planar, mimic), textbook vs Pinocchio."""
    scene = scenes[name]
    q, qd, qdd = _state(scene.textbook.nv, 5)
    loads = _loads(scene, 6)
    tb = tb_reactions.joint_reactions(scene.textbook, scene.textbook_data, q, qd, qdd, loads)
    ref = ref_reactions.joint_reactions(scene.reference, scene.reference_data, q, qd, qdd, loads)
    assert sorted(tb) == sorted(ref)
    x, y = _stack(tb, tb), _stack(ref, tb)
    assert_close(x, y, rel=1e-13)


def test_reactions_equal_configuration_matrix_times_body_wrenches(tree):
    """The backward pass is ``R = L W`` (4.64): one sum over each subtree."""
    tm, td = tree.textbook, tree.textbook_data
    q, _, _ = _state(tm.nv, 7)
    W = np.random.default_rng(8).normal(size=(tm.nb, 6))
    dynamics.mass_matrix(tm, td, q)  # the forward pass: L_pair and L
    R = tb_reactions.subtree_sums(tm, td, W)
    # a matrix–vector product: each entry on the size of its own terms, |L| |W|
    scale = np.abs(td.L) @ np.abs(W.ravel())
    assert_close(R.ravel(), td.L @ W.ravel(), rel=1e-14, scale=scale)


def literal_walk(model, data, W: np.ndarray) -> np.ndarray:
    """004 (12)–(13) read literally: from every leaf, walk to the root adding the totals."""
    children = {k: [c for c in range(model.nb) if model.parent[c] == k] for k in range(model.nb)}
    R = np.zeros_like(W)
    unvisited = np.ones(model.nb)
    for leaf in [k for k in range(model.nb) if not children[k]]:
        R[leaf], unvisited[leaf] = W[leaf], 0.0  # (12)
        i = leaf
        while model.parent[i] >= 0:
            n = int(model.parent[i])
            R[n] = R[n] + data.L_pair[i] @ R[i] + unvisited[n] * W[n]  # (13)
            unvisited[n] = 0.0
            i = n
    return R


def test_literal_leaf_to_root_walk_double_counts(tree):
    """Errata X.3.12: the second walk re-adds the shared vertex's whole total to its parent."""
    tm, td = tree.textbook, tree.textbook_data
    q, qd, qdd = _state(tm.nv, 9)
    R = tb_reactions.pair_reactions(tm, td, q, qd, qdd)
    W = np.linalg.solve(td.L, R.ravel()).reshape(tm.nb, 6)  # the body wrenches, R = L W
    literal = literal_walk(tm, td, W)
    # pairs: j1 = 0, j2 = 1 (two branches: j3 → j4, j5 → j6); below the branch all agree
    assert_close(literal[1:], R[1:], rel=1e-13)
    # the root got j2's first-branch total twice: W_j2 + L_j3 R_j3 more than the truth
    first_branch = W[1] + td.L_pair[2] @ R[2]
    scale = max(np.max(np.abs(literal[0])), np.max(np.abs(R[0])))  # a difference of totals
    assert_close(literal[0] - R[0], td.L_pair[1] @ first_branch, rel=1e-12, scale=scale)
    assert np.max(np.abs(literal[0] - R[0])) > 0.1 * np.max(np.abs(R[0]))


@pytest.mark.parametrize("name", ["branched_tree", "all_joint_types"])
def test_impulse_form_is_rnea_of_the_velocity_jump(scenes, name):
    """004 (16): ``rnea(q, 0, J Δq̇, fext = impulses)`` with gravity off; its projection."""
    scene = scenes[name]
    tm, td = scene.textbook, scene.textbook_data
    q, dqd, _ = _state(tm.nv, 10)
    w1, w2 = _loads(scene, 11)
    impulses = [w1, Wrench(w2.link, w2.xyz, -np.asarray(w1.force), w2.torque)]
    tb = tb_reactions.reaction_impulses(tm, td, q, dqd, impulses)
    ref = ref_reactions.reaction_impulses(scene.reference, scene.reference_data, q, dqd, impulses)
    x, y = _stack(tb, tb), _stack(ref, tb)
    assert_close(x, y, rel=1e-13)
    if name == "branched_tree":  # identity map: Pinocchio's own call, Algorithm 004-D
        m = scene.reference.pin_model_no_gravity
        d = m.createData()
        pin.forwardKinematics(m, d, q)
        fext = ref_reactions.external_forces(scene.reference, d, impulses)
        pin.rnea(m, d, q, np.zeros(tm.nv), dqd, fext)
        direct = {m.names[i]: d.f[i].vector for i in range(1, m.njoints)}
        assert_close(x, _stack(direct, tb), rel=1e-13, scale=np.max(np.abs(y)))
    R = tb_reactions.pair_reactions(tm, td, q, np.zeros(tm.nv), dqd, impulses, gravity=False)
    Gamma = sum(points.generalized_force(tm, td, q, w) for w in impulses)
    momentum = dynamics.mass_matrix(tm, td, q) @ dqd
    scale = max(np.max(np.abs(momentum)), np.max(np.abs(Gamma)))  # the terms of the difference
    assert_close(tb_reactions.projection(tm, td, R), momentum - Gamma, rel=1e-13, scale=scale)


def test_euler6_chain_carries_one_wrench_in_six_frames(scenes):
    """The six joints of a pair transmit one wrench: the same force and moment in ground."""
    scene = scenes["two_body_gravity"]
    tm, td = scene.textbook, scene.textbook_data
    q, qd, qdd = _state(tm.nv, 12)
    tb = tb_reactions.joint_reactions(tm, td, q, qd, qdd)
    frames = tb_reactions.joint_frames(tm, td, q)
    ref_frames = ref_reactions.joint_frames(scene.reference, scene.reference_data, q)
    size = max(np.max(np.abs(p)) for _, p in ref_frames.values())  # of the mechanism, m
    for names in tm.pair_joints:
        assert len(names) == 6
        at_ground = []
        for n in names:
            c, p = frames[n]
            assert_close(c, ref_frames[n][0], rel=1e-14, what=f"{n} rotation")
            assert_close(p, ref_frames[n][1], rel=1e-14, scale=size, what=f"{n} position")
            F, M = c @ tb[n][:3], c @ tb[n][3:]
            at_ground.append(np.concatenate([F, M + np.cross(p, F)]))
        at_ground = np.array(at_ground)
        assert_close(at_ground, np.broadcast_to(at_ground[0], at_ground.shape), rel=1e-13)


def test_rest_reaction_at_the_foundation_is_the_weight(scenes):
    """At rest at q = 0 the platform carries the weight of the whole RT-70 straight up."""
    scene = scenes["rt70_servo"]
    tm, td = scene.textbook, scene.textbook_data
    zero = np.zeros(tm.nv)
    tb = tb_reactions.joint_reactions(tm, td, zero, zero, zero)
    weight = float(tm.mass.sum()) * 9.81
    F = tb["platform_x"][:3]
    assert_close(F[2], weight, rel=1e-14)
    assert_close(F[:2], [0.0, 0.0], rel=1e-13, scale=weight)  # gravity is vertical


def test_ground_loads_are_carried_by_no_joint(tree):
    tm, td = tree.textbook, tree.textbook_data
    q, qd, qdd = _state(tm.nv, 13)
    on_ground = [Wrench("world", [1.0, 2.0, 3.0], [5.0, 0, 0], [0, 1.0, 0])]
    for side, m, d in (
        (tb_reactions, tm, td),
        (ref_reactions, tree.reference, tree.reference_data),
    ):
        a = side.joint_reactions(m, d, q, qd, qdd)
        b = side.joint_reactions(m, d, q, qd, qdd, on_ground)
        assert np.array_equal(_stack(a, a), _stack(b, a))  # the ground load is dropped


def test_bad_input_is_refused_on_both_sides(tree):
    nv = tree.textbook.nv
    zero = np.zeros(nv)
    unknown = [Wrench("nowhere", zero[:3], zero[:3], zero[:3])]
    for side, m, d in (
        (tb_reactions, tree.textbook, tree.textbook_data),
        (ref_reactions, tree.reference, tree.reference_data),
    ):
        with pytest.raises(ShapeError):
            side.joint_reactions(m, d, zero, zero, np.zeros(nv + 1))
        with pytest.raises(UnknownLinkError, match="nowhere"):
            side.joint_reactions(m, d, zero, zero, zero, unknown)
