"""Chapter 2 topology models and chapter 3 holonomic elimination (formalism §2–§3).

The graph of Fig. 3.1: four coaxial bodies rotating about z, elastic links
s1 = 1–2 (C1, D1), s2 = 1–3 (C2, D2), s3 = 1–4 (C3, D3), s4 = 2–4 (C4, D4) — the rows of
Γ (3.5) in this order — and the rigid links of each case.

Two readings of the exercises ("… – holonomic, all the others elastic"):

* ``fig31``: the elastic links are those of Fig. 3.1 (s1..s4); a pattern's rigid links
  are added, and an elastic link declared rigid loses its spring (rigid wins);
* ``k4``: the graph is the complete graph of Fig. 3.1 (its six links), every link not
  declared rigid is elastic — 2–3 gets C5, D5 and 3–4 gets C6, D6.

The hand results below take six stiffnesses; ``fig31`` is ``k4`` with C5 = C6 = 0.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import scipy.linalg

from rt70.errors import NonFiniteError, Rt70Error, TopologyError
from rt70.linear.holonomic import eliminate, gamma_star, spanning_tree
from rt70.linear.topology import (
    LinearModelError,
    book_delta,
    edges_from_topology,
    from_graph,
    proportional_damping,
    topology_matrix,
)
from rt70.linear.torsion_scene import from_scene
from rt70.model.scene import load_scene
from rt70.scenes import rt70_data
from rt70.scenes.rt70_chapter2 import azimuth_model, elevation_model
from rt70.testing import MIN_REL, assert_close

#: Relative tolerance of the reductions: sums and products of a few terms of three to six
#: decades, far above their rounding (a few ulps) and far below any wrong term.
RTOL = 1e-12
#: The book prints its frequencies to four decimals (Hz).
PRINTED_HZ = 1e-4
KGF = 9.80665
SEEDS = range(5)

#: Elastic links s1..s6 of the complete graph of Fig. 3.1 (s5, s6 only in the k4 reading).
LINKS = ((1, 2), (1, 3), (1, 4), (2, 4), (2, 3), (3, 4))


def assert_rel(actual, expected, scale=None):
    """``assert_close`` at :data:`RTOL`; ``scale`` is that of the terms (stiffnesses, …)."""
    assert_close(actual, expected, rel=RTOL, scale=scale)


def assert_moves_together(alpha, i, j, alpha_star_star):
    """Bodies i and j (1-based) have one displacement in ``α = S*ᵀ α**``.

    Both are the same sum of entries of α**, so they agree to the rounding of that sum,
    whose scale is ``Σ |α**|``.
    """
    scale = np.abs(alpha_star_star).sum()
    assert_close(alpha[i - 1], alpha[j - 1], rel=MIN_REL, scale=scale)


def draw(seed, n_links=4):
    """Random I1..I4, C1..C_n, D1..D_n, log-uniform over three decades."""
    rng = np.random.default_rng(seed)
    return (
        10 ** rng.uniform(-1, 2, 4),
        10 ** rng.uniform(0, 3, n_links),
        10 ** rng.uniform(-2, 1, n_links),
    )


def six(values):
    """Pad four link values with C5 = C6 = 0 (the fig31 reading as a k4 graph)."""
    return np.concatenate([values, np.zeros(6 - len(values))])


# ---------------------------------------------------------------------------------------
# Hand results (derived on paper; kept out of the library on purpose)
# ---------------------------------------------------------------------------------------


def hand_book(inertia, c):
    """Fig. 3.1 as printed: rigid 2–3, 3–4 (3.14)–(3.16).

    Tree: root 1, 1–2 elastic, 2–3 and 3–4 rigid. α** = [a, b] = [α1, α2 − α1], so
    α = [a, a+b, a+b, a+b]. T = ½(I1 ȧ² + (I2+I3+I4)(ȧ+ḃ)²) gives A*. Deformations:
    s1 = s2 = s3 = b, s4 = α4 − α2 = 0 (the internal link drops out), s5 = s6 = 0 (rigid).
    A* = [[I1+I2+I3+I4, I2+I3+I4], [I2+I3+I4, I2+I3+I4]], C* = diag(0, C1+C2+C3).
    """
    I1, I2, I3, I4 = inertia
    C1, C2, C3, C4, C5, C6 = c
    return (
        np.array([[I1 + I2 + I3 + I4, I2 + I3 + I4], [I2 + I3 + I4, I2 + I3 + I4]]),
        np.diag([0.0, C1 + C2 + C3]),
    )


def hand_a(inertia, c):
    """Pattern a): rigid 2–3, 3–4, 1–3.

    The rigid links join all four bodies: tree root 1, 1–3, 3–2, 3–4 all rigid, one
    coordinate α** = [α1], α = [a, a, a, a]. Every link deforms by 0.
    A* = [I1+I2+I3+I4], C* = [0]: one free rigid body.
    """
    I1, I2, I3, I4 = inertia
    return np.array([[I1 + I2 + I3 + I4]]), np.zeros((1, 1))


def hand_b(inertia, c):
    """Pattern b): rigid 2–3 only.

    Tree (rigid first, then s1..s4): 2–3 rigid, root 1, 1–2 elastic, 1–4 elastic (1–3 and
    2–4 close loops). α** = [a, b, d] = [α1, α2 − α1, α4 − α1], α = [a, a+b, a+b, a+d].
    A* = [[I1+I2+I3+I4, I2+I3, I4], [I2+I3, I2+I3, 0], [I4, 0, I4]].
    Deformations: s1 = b, s2 = b, s3 = d, s4 = α4 − α2 = d − b, s5 = 0, s6 = α4 − α3 = d − b.
    C* = [[0, 0, 0], [0, C1+C2+C4+C6, −(C4+C6)], [0, −(C4+C6), C3+C4+C6]].
    """
    I1, I2, I3, I4 = inertia
    C1, C2, C3, C4, C5, C6 = c
    A = np.array([[I1 + I2 + I3 + I4, I2 + I3, I4], [I2 + I3, I2 + I3, 0.0], [I4, 0.0, I4]])
    C = np.array(
        [
            [0.0, 0.0, 0.0],
            [0.0, C1 + C2 + C4 + C6, -(C4 + C6)],
            [0.0, -(C4 + C6), C3 + C4 + C6],
        ]
    )
    return A, C


def hand_c(inertia, c):
    """Pattern c): rigid 3–4, 1–3.

    Tree: 3–4, 1–3 rigid, root 1, 1–2 elastic. α** = [a, b] = [α1, α2 − α1],
    α = [a, a+b, a, a]. A* = [[I1+I2+I3+I4, I2], [I2, I2]].
    Deformations: s1 = b, s2 = s3 = 0, s4 = α4 − α2 = −b, s5 = α3 − α2 = −b, s6 = 0.
    C* = diag(0, C1+C4+C5).
    """
    I1, I2, I3, I4 = inertia
    C1, C2, C3, C4, C5, C6 = c
    return np.array([[I1 + I2 + I3 + I4, I2], [I2, I2]]), np.diag([0.0, C1 + C4 + C5])


def hand_d(inertia, c):
    """Pattern d): rigid 2–3, 1–3.

    Tree: 2–3, 1–3 rigid, root 1, 1–4 elastic (1–2, 1–3 close loops). α** = [a, d] =
    [α1, α4 − α1], α = [a, a, a, a+d]. A* = [[I1+I2+I3+I4, I4], [I4, I4]].
    Deformations: s1 = s2 = 0, s3 = d, s4 = α4 − α2 = d, s5 = 0, s6 = α4 − α3 = d.
    C* = diag(0, C3+C4+C6).
    """
    I1, I2, I3, I4 = inertia
    C1, C2, C3, C4, C5, C6 = c
    return np.array([[I1 + I2 + I3 + I4, I4], [I4, I4]]), np.diag([0.0, C3 + C4 + C6])


def hand_e(inertia, c):
    """Pattern e): rigid 1–2, 1–4 (both also elastic links: their springs C1, C3 drop out).

    Tree: 1–2, 1–4 rigid, root 1, 1–3 elastic. α** = [a, b] = [α1, α3 − α1],
    α = [a, a, a+b, a]. A* = [[I1+I2+I3+I4, I3], [I3, I3]].
    Deformations: s1 = 0, s2 = b, s3 = 0, s4 = α4 − α2 = 0, s5 = α3 − α2 = b,
    s6 = α4 − α3 = −b. C* = diag(0, C2+C5+C6).
    """
    I1, I2, I3, I4 = inertia
    C1, C2, C3, C4, C5, C6 = c
    return np.array([[I1 + I2 + I3 + I4, I3], [I3, I3]]), np.diag([0.0, C2 + C5 + C6])


#: case → (rigid links, hand result, the spanning tree {body: (parent, kind)}).
CASES = {
    "book": (
        ((2, 3), (3, 4)),
        hand_book,
        {1: (0, "root"), 2: (1, "elastic"), 3: (2, "rigid"), 4: (3, "rigid")},
    ),
    "a": (
        ((2, 3), (3, 4), (1, 3)),
        hand_a,
        {1: (0, "root"), 2: (3, "rigid"), 3: (1, "rigid"), 4: (3, "rigid")},
    ),
    "b": (
        ((2, 3),),
        hand_b,
        {1: (0, "root"), 2: (1, "elastic"), 3: (2, "rigid"), 4: (1, "elastic")},
    ),
    "c": (
        ((3, 4), (1, 3)),
        hand_c,
        {1: (0, "root"), 2: (1, "elastic"), 3: (1, "rigid"), 4: (3, "rigid")},
    ),
    "d": (
        ((2, 3), (1, 3)),
        hand_d,
        {1: (0, "root"), 2: (3, "rigid"), 3: (1, "rigid"), 4: (1, "elastic")},
    ),
    "e": (
        ((1, 2), (1, 4)),
        hand_e,
        {1: (0, "root"), 2: (1, "rigid"), 3: (1, "elastic"), 4: (1, "rigid")},
    ),
}

READINGS = {"fig31": 4, "k4": 6}


def fig31_model(inertia, c, d, n_links=4):
    return from_graph(inertia, LINKS[:n_links], c, d, names=["a1", "a2", "a3", "a4"])


# ---------------------------------------------------------------------------------------
# The book's worked example (§3.1)
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", SEEDS)
def test_book_example_matrices(seed):
    inertia, c, d = draw(seed)
    model = fig31_model(inertia, c, d)
    # (3.5), (3.2)–(3.4), (3.6)
    gamma = np.array([[-1, 1, 0, 0], [-1, 0, 1, 0], [-1, 0, 0, 1], [0, -1, 0, 1]])
    assert np.array_equal(model.gamma, gamma)
    assert np.array_equal(model.m, np.diag(inertia))
    assert_rel(model.C, gamma.T @ np.diag(c) @ gamma)
    assert_rel(model.D, gamma.T @ np.diag(d) @ gamma)
    red = eliminate(model, [(2, 3), (3, 4)], root=1)
    # (3.7), (3.9), (3.10), (3.11), (3.18)
    assert np.array_equal(
        red.gamma_star, [[1, 0, 0, 0], [-1, 1, 0, 0], [0, -1, 1, 0], [0, 0, -1, 1]]
    )
    assert np.array_equal(red.L, [[1, 1, 1, 1], [0, 1, 1, 1], [0, 0, 1, 1], [0, 0, 0, 1]])
    assert_rel(red.L, np.linalg.inv(red.gamma_star).T)
    assert np.array_equal(red.f, np.diag([1, 1, 0, 0]))
    assert np.array_equal(red.S, [[1, 1, 1, 1], [0, 1, 1, 1], [0, 0, 0, 0], [0, 0, 0, 0]])
    assert np.array_equal(red.f_star, [[1, 0], [0, 1], [0, 0], [0, 0]])
    assert np.array_equal(red.S_star, red.S[:2])
    # (3.13) before deleting zero rows/columns, then (3.14)–(3.16)
    full = red.S @ model.m @ red.S.T
    assert np.all(full[2:] == 0) and np.all(full[:, 2:] == 0)
    A, C = hand_book(inertia, six(c))
    _, D = hand_book(inertia, six(d))
    assert_rel(red.A_star, A)
    assert_rel(red.C_star, C, scale=c.max())
    assert_rel(red.D_star, D, scale=d.max())
    assert red.names == ("a1", "a2-a1")
    assert red.dropped_rigid_edges == ()


def test_book_tree_and_gamma_star():
    tree = spanning_tree(4, LINKS[:4], [(2, 3), (3, 4)], root=1)
    assert tree.edges == ((1, 2), (2, 3), (3, 4))
    assert tree.rigid_edges == ((2, 3), (3, 4))
    assert tree.roots == (1,)
    assert tree.kind == ("root", "elastic", "rigid", "rigid")
    assert np.array_equal(tree.mobility, [1, 1, 0, 0])
    expected = [[1, 0, 0, 0], [-1, 1, 0, 0], [0, -1, 1, 0], [0, 0, -1, 1]]
    assert np.array_equal(gamma_star([(1, 2), (2, 3), (3, 4)], 4, 1), expected)
    # orientation and order of the links do not matter
    assert np.array_equal(gamma_star([(4, 3), (2, 1), (3, 2)], 4, 1), expected)


@pytest.mark.parametrize("seed", SEEDS)
def test_book_back_substitution(seed):
    inertia, c, d = draw(seed)
    model = fig31_model(inertia, c, d)
    red = eliminate(model, [(2, 3), (3, 4)])
    rng = np.random.default_rng(100 + seed)
    a2 = rng.normal(size=2)
    alpha = red.back_substitute(a2)
    # (3.17): the rigidly linked bodies turn together; α** are α1 and α2 − α1
    for j in (3, 4):
        assert_moves_together(alpha, 2, j, a2)
    assert_rel([alpha[0], alpha[1] - alpha[0]], a2)
    # energies are the same in both coordinate sets; S* Q is the reduced force
    assert_rel(alpha @ model.m @ alpha, a2 @ red.A_star @ a2)
    assert_rel(alpha @ model.C @ alpha, a2 @ red.C_star @ a2)
    Q = rng.normal(size=4)
    assert_rel(red.reduce_force(Q), [Q.sum(), Q[1:].sum()], scale=np.abs(Q).sum())
    # many time steps at once
    series = rng.normal(size=(2, 7))
    assert red.back_substitute(series).shape == (4, 7)
    assert_rel(red.back_substitute(series)[:, 3], red.back_substitute(series[:, 3]))


# ---------------------------------------------------------------------------------------
# The five exercise patterns a)–e), both readings
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("reading", READINGS)
@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("seed", SEEDS)
def test_patterns_against_hand_results(case, reading, seed):
    n_links = READINGS[reading]
    inertia, c, d = draw(seed, n_links)
    rigid, hand, tree_expected = CASES[case]
    red = eliminate(fig31_model(inertia, c, d, n_links), rigid)
    A, C = hand(inertia, six(c))
    _, D = hand(inertia, six(d))
    assert_rel(red.A_star, A)
    assert_rel(red.C_star, C, scale=c.max())
    assert_rel(red.D_star, D, scale=d.max())
    assert red.tree.parent == tuple(tree_expected[k][0] for k in range(1, 5))
    assert red.tree.kind == tuple(tree_expected[k][1] for k in range(1, 5))
    # rigidly linked bodies move together after back-substitution
    a2 = np.random.default_rng(seed).normal(size=red.n)
    alpha = red.back_substitute(a2)
    for i, j in rigid:
        assert_moves_together(alpha, i, j, a2)


# ---------------------------------------------------------------------------------------
# Pinocchio: the spanning tree as a kinematic tree
# ---------------------------------------------------------------------------------------

_LIMIT = '<limit lower="-1000" upper="1000" effort="1e12" velocity="1e6"/>'


def tree_urdf(inertias, tree):
    """URDF text: body k is link ``n<k>``; its joint ``node<k>`` comes from its tree parent.

    Root and elastic tree links are revolute joints about z (relative angle), rigid tree
    links fixed joints; all bodies coaxial at the origin with ixx = iyy = izz = I_k.
    """
    parts = ['<?xml version="1.0"?>', '<robot name="fig31">', '  <link name="world"/>']
    for k, inertia in enumerate(map(float, inertias), start=1):
        parts.append(
            f'  <link name="n{k}"><inertial><origin xyz="0 0 0" rpy="0 0 0"/>'
            f'<mass value="1"/><inertia ixx="{inertia!r}" ixy="0" ixz="0" iyy="{inertia!r}" '
            f'iyz="0" izz="{inertia!r}"/></inertial></link>'
        )
    for k, (parent, kind) in sorted(tree.items()):
        jtype = "fixed" if kind == "rigid" else "revolute"
        parent_link = "world" if parent == 0 else f"n{parent}"
        extra = '<axis xyz="0 0 1"/>' + _LIMIT if jtype == "revolute" else ""
        parts.append(
            f'  <joint name="node{k}" type="{jtype}"><parent link="{parent_link}"/>'
            f'<child link="n{k}"/><origin xyz="0 0 0" rpy="0 0 0"/>{extra}</joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts)


def pinocchio_reduced(inertias, tree, springs, dampers, q):
    """A*, C*, D* from Pinocchio alone, in Pinocchio's velocity order, and the joint names.

    C* = Σ C_s J_sᵀ J_s with J_s the row of (α_j − α_i): the difference of the angular z
    rows of the two bodies' frame Jacobians (LOCAL_WORLD_ALIGNED); likewise D*.
    """
    model = pin.buildModelFromXML(tree_urdf(inertias, tree))
    data = model.createData()
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)

    def jz(k):
        fid = model.getFrameId(f"n{k}")
        return pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[5]

    K = np.zeros((model.nv, model.nv))
    Dm = np.zeros((model.nv, model.nv))
    for ((i, j), cs), ds in zip(springs, dampers, strict=True):
        J = jz(j) - jz(i)
        K += cs * np.outer(J, J)
        Dm += ds * np.outer(J, J)
    index = {model.names[jid]: model.idx_vs[jid] for jid in range(1, model.njoints)}
    return M, K, Dm, index


@pytest.mark.parametrize("reading", READINGS)
@pytest.mark.parametrize("case", CASES)
def test_cases_against_pinocchio(case, reading):
    n_links = READINGS[reading]
    rigid, _, tree = CASES[case]
    for seed in SEEDS[:3]:
        inertia, c, d = draw(seed, n_links)
        red = eliminate(fig31_model(inertia, c, d, n_links), rigid)
        free = [k for k in range(1, 5) if tree[k][1] != "rigid"]
        for q_seed in (None, seed):
            nq = len(free)
            q = np.zeros(nq) if q_seed is None else np.random.default_rng(q_seed).uniform(-2, 2, nq)
            springs = list(zip(LINKS[:n_links], c, strict=True))
            M, K, Dm, index = pinocchio_reduced(inertia, tree, springs, d, q)
            perm = [index[f"node{k}"] for k in free]
            assert sorted(perm) == list(range(nq))
            sel = np.ix_(perm, perm)
            assert_rel(red.A_star, M[sel])
            assert_rel(red.C_star, K[sel], scale=c.max())
            assert_rel(red.D_star, Dm[sel], scale=d.max())


# ---------------------------------------------------------------------------------------
# Rigid loops, the ground, forests
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", SEEDS)
def test_rigid_cycle_is_dropped(seed):
    inertia, c, d = draw(seed)
    model = fig31_model(inertia, c, d)
    forest = eliminate(model, [(2, 3), (3, 4)])
    loop = eliminate(model, [(2, 3), (3, 4), (2, 4)])
    assert loop.dropped_rigid_edges == ((2, 4),)
    assert forest.dropped_rigid_edges == ()
    for name in ("gamma_star", "L", "f", "S", "S_star", "A_star", "C_star", "D_star"):
        assert np.array_equal(getattr(loop, name), getattr(forest, name)), name
    # a loop through the ground: 2 and 3 both clamped, 2–3 is redundant
    clamped = eliminate(model, [(0, 2), (0, 3), (2, 3)])
    assert clamped.dropped_rigid_edges == ((2, 3),)
    # the same rigid link twice is a loop too
    assert eliminate(model, [(2, 3), (3, 2)]).dropped_rigid_edges == ((3, 2),)


@pytest.mark.parametrize("seed", SEEDS)
def test_rigid_link_to_ground(seed):
    """Chain ground–1–2–3 with ground springs; body 1 clamped: its springs vanish."""
    rng = np.random.default_rng(seed)
    inertia, c = 10 ** rng.uniform(-1, 1, 3), 10 ** rng.uniform(0, 2, 4)
    model = from_graph(inertia, [(0, 1), (1, 2), (2, 3), (0, 3)], c)
    red = eliminate(model, [(0, 1)], root=1)
    assert red.tree.roots == ()
    assert red.tree.kind == ("rigid", "elastic", "elastic")
    # α** = [α2 − α1, α3 − α2] with α1 = 0: α = [0, x, x + y]
    assert_rel(red.A_star, [[inertia[1] + inertia[2], inertia[2]], [inertia[2], inertia[2]]])
    assert_rel(red.C_star, [[c[1] + c[3], c[3]], [c[3], c[2] + c[3]]])
    # clamping 1 directly equals deleting its row and column
    sub = from_graph(inertia[1:], [(0, 1), (1, 2), (0, 2)], c[1:])
    T = np.array([[1.0, 0.0], [1.0, 1.0]])  # [α2, α3] = T α**
    assert_rel(T.T @ sub.m @ T, red.A_star)
    assert_rel(T.T @ sub.C @ T, red.C_star)


def test_disconnected_graph_is_a_forest():
    model = from_graph([1.0, 2.0, 3.0, 4.0], [(1, 2), (3, 4)], [5.0, 6.0])
    red = eliminate(model, [])
    assert red.tree.roots == (1, 3)
    assert red.tree.parent == (0, 1, 0, 3)
    assert_rel(red.A_star, [[3.0, 2.0, 0, 0], [2.0, 2.0, 0, 0], [0, 0, 7.0, 4.0], [0, 0, 4.0, 4.0]])
    assert_rel(red.C_star, np.diag([0.0, 5.0, 0.0, 6.0]))


def test_no_rigid_links_is_a_change_of_coordinates():
    inertia, c, d = draw(7)
    model = fig31_model(inertia, c, d)
    red = eliminate(model, [])
    assert red.S_star.shape == (4, 4)
    assert_rel(red.S_star, red.L)
    eig_full = scipy.linalg.eigh(model.C, model.m, eigvals_only=True)
    eig_red = scipy.linalg.eigh(red.C_star, red.A_star, eigvals_only=True)
    assert_rel(eig_red, eig_full, scale=eig_full.max())


# ---------------------------------------------------------------------------------------
# 3-D point masses
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", SEEDS)
def test_point_masses_in_space(seed):
    """Three point masses, springs per axis, rigid 2–3: per axis the scalar reduction."""
    rng = np.random.default_rng(seed)
    masses = 10 ** rng.uniform(-1, 1, 3)
    edges = [(0, 1), (1, 2), (2, 3), (1, 3), (0, 3)]
    c = 10 ** rng.uniform(0, 2, (5, 3))
    d = 10 ** rng.uniform(-2, 0, (5, 3))
    model = from_graph(masses, edges, c, d, names=["p1", "p2", "p3"], dim=3)
    assert np.array_equal(model.gamma, np.kron(topology_matrix(edges, 3), np.eye(3)))
    assert model.names[:4] == ("p1_x", "p1_y", "p1_z", "p2_x")
    red = eliminate(model, [(2, 3)])
    assert red.names == ("p1_x", "p1_y", "p1_z", "p2_x-p1_x", "p2_y-p1_y", "p2_z-p1_z")
    assert red.gamma_star.shape == (9, 9)
    assert_rel(red.L, np.linalg.inv(red.gamma_star).T)
    for axis in range(3):
        scalar = eliminate(from_graph(masses, edges, c[:, axis], d[:, axis]), [(2, 3)])
        for name in ("gamma_star", "L", "f", "S_star", "A_star", "C_star", "D_star"):
            mat = getattr(red, name)
            rows = slice(axis, None, 3)
            scale = {"C_star": c[:, axis].max(), "D_star": d[:, axis].max()}.get(name)
            assert_rel(mat[rows, rows], getattr(scalar, name), scale=scale)
            for b in range(3):
                if b != axis:
                    assert not np.any(mat[rows, b::3]), name
    a2 = rng.normal(size=6)
    alpha = red.back_substitute(a2)
    assert_close(alpha[3:6], alpha[6:9], rel=MIN_REL, scale=np.abs(a2).sum())  # rigid 2–3


# ---------------------------------------------------------------------------------------
# Chapter 2: the RT-70 tables and their URDF scenes
# ---------------------------------------------------------------------------------------


def test_table_topologies():
    assert np.array_equal(azimuth_model("0").gamma, rt70_data.GAMMA_ALPHA)
    assert np.array_equal(elevation_model().gamma, rt70_data.GAMMA_BETA)
    assert edges_from_topology(np.array(rt70_data.GAMMA_BETA)) == [
        (1, 2),
        (1, 3),
        (2, 4),
        (2, 5),
        (4, 6),
    ]
    assert azimuth_model(90).m[2, 2] == 0.2141e6
    assert elevation_model().names[0] == "counterweight"


def spectrum_hz(model):
    lam = scipy.linalg.eigh(model.C, model.m, eigvals_only=True)
    return np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)


def test_elevation_scene_matches_tables():
    table = elevation_model()
    scene = from_scene(load_scene("rt70_elevation"))
    assert scene.names == table.names
    assert scene.edges == table.edges
    assert_rel(scene.m, KGF * table.m)
    assert_rel(scene.C, KGF * table.C)
    assert not np.any(scene.D)
    printed = [0.0, 3.2700, 4.2424, 6.3041, 7.2579, 19.6420]
    # to half a unit of the book's last printed digit
    assert_close(spectrum_hz(scene), printed, rel=0.5, scale=PRINTED_HZ)
    assert_close(spectrum_hz(table), printed, rel=0.5, scale=PRINTED_HZ)


@pytest.mark.parametrize("elevation, name", [("0", "rt70_azimuth"), ("90", "rt70_azimuth_el90")])
def test_azimuth_scenes_match_tables(elevation, name):
    table = azimuth_model(elevation)
    scene = from_scene(load_scene(name))
    assert scene.edges == table.edges
    assert_rel(scene.m, KGF * table.m)
    assert_rel(scene.C, KGF * table.C)


def test_proportional_damping_gives_book_ratio():
    model = elevation_model()
    lam, V = scipy.linalg.eigh(model.C, model.m)
    omega = np.sqrt(np.clip(lam, 0.0, None))
    delta = book_delta(omega[1])
    assert_close(delta, 0.1 / omega[1], rel=MIN_REL)
    damped = proportional_damping(model, delta)
    assert_rel(damped.D, delta * model.C)
    assert_rel(damped.d_links, delta * model.c_links)
    xi = np.diag(V.T @ damped.D @ V)[1:] / (2 * omega[1:])  # V is m-orthonormal
    assert_close(xi[0], 0.05, rel=RTOL)
    assert_rel(xi, 0.05 * omega[1:] / omega[1])


# ---------------------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: topology_matrix([(1, 5)], 4), TopologyError, "out of range"),
        (lambda: topology_matrix([(2, 2)], 4), TopologyError, "itself"),
        (lambda: topology_matrix([(1, 2.5)], 4), TopologyError, "pair of node numbers"),
        (lambda: topology_matrix([(1, 2)], 0), LinearModelError, "n_nodes"),
        (lambda: from_graph([1, 2], [(1, 2)], [1, 2]), LinearModelError, "shape"),
        (lambda: from_graph([1, 2], [(1, 2)], [-1]), LinearModelError, "non-negative"),
        (lambda: from_graph([1, np.nan], [(1, 2)], [1]), NonFiniteError, "NaN"),
        (lambda: from_graph([1, 2], [(1, 2)], [1], names=["x"]), LinearModelError, "names"),
        (lambda: gamma_star([(1, 2), (2, 3), (1, 3)], 3, 1), TopologyError, "spanning tree"),
        (lambda: gamma_star([(1, 2), (3, 4), (4, 3)], 4, 1), TopologyError, "does not reach"),
        (lambda: spanning_tree(4, LINKS[:4], [(2, 7)]), TopologyError, "rigid link 0"),
        (lambda: spanning_tree(4, LINKS[:4], [], root=5), TopologyError, "root 5"),
        (lambda: edges_from_topology([[1, 1, 0]]), TopologyError, "not one link"),
        (lambda: azimuth_model("45"), LinearModelError, "elevation"),
        (lambda: book_delta(0.0), LinearModelError, "positive"),
        (lambda: from_scene(load_scene("rt70")), LinearModelError, "chapter-2"),
        (lambda: from_scene(load_scene("three_masses")), LinearModelError, "revolute"),
    ],
)
def test_bad_input(call, error, words):
    with pytest.raises(error, match=words) as info:
        call()
    assert isinstance(info.value, Rt70Error)
    assert "\n" not in str(info.value)


def test_eliminate_needs_a_graph():
    model = fig31_model(*draw(0))
    bare = type(model)(model.m, model.C, model.D, model.names)
    with pytest.raises(LinearModelError, match="graph"):
        eliminate(bare, [(2, 3)])
    # Γ alone is enough
    with_gamma = type(model)(model.m, model.C, model.D, model.names, gamma=model.gamma)
    assert np.array_equal(eliminate(with_gamma, [(2, 3)]).A_star, eliminate(model, [(2, 3)]).A_star)
    with pytest.raises(Rt70Error, match="rows"):
        eliminate(model, [(2, 3)]).back_substitute(np.zeros(5))
