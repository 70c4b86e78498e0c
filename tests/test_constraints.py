"""The constraint seam (rt70/physics/constraints.py): mimic joints, locked coordinates and rigid
links are one kind of thing, ``q_full = T q + q₀``, eliminated by ``Tᵀ … T``."""

from __future__ import annotations

import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.linear import holonomic, topology
from rt70.linear import linearize as lin
from rt70.model.scene import load_scene, scene_from_text
from rt70.physics import constraints
from rt70.scenes.rt70_state import rt70_pointing
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import dynamics

MIMIC_URDF = """<robot name="mimic">
  <link name="base"/>
  <link name="a"><inertial><mass value="2"/><origin xyz="0.3 0 0"/>
    <inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><origin xyz="0 0.2 0"/>
    <inertia ixx="0.05" iyy="0.04" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><mass value="0.5"/><origin xyz="0 0 0.1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="c"/>
    <origin xyz="0 0.4 0"/><axis xyz="1 0 0"/><mimic joint="j1" multiplier="-1.5" offset="0.2"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"""


def test_mimic_map_is_the_textbook_models_g():
    """The textbook Model's G and offset are the mimic map's T and q₀."""
    model = scene_from_text(MIMIC_URDF, "mimic").textbook
    m = constraints.mimic_map(model.full_coordinate_names, {"j3": ("j1", -1.5, 0.2)})
    assert m.names == ("j1", "j2") and m.full_names == ("j1", "j2", "j3")
    assert np.array_equal(model.G, m.T) and np.array_equal(model.q_offset, m.offset)
    assert np.array_equal(m.T, [[1, 0], [0, 1], [-1.5, 0]])
    q = np.array([0.3, -0.7])
    assert_close(m.expand(q), [0.3, -0.7, -1.5 * 0.3 + 0.2], rel=MIN_REL)
    assert_close(m.expand(q, offset=False), [0.3, -0.7, -0.45], rel=MIN_REL)


def test_mimic_scene_agrees_with_pinocchio_through_the_map():
    """The reduced A = Tᵀ A_full T equals Pinocchio's (which maps mimics on its own)."""
    from rt70 import reference

    scene = scene_from_text(MIMIC_URDF, "mimic")
    q = np.array([0.4, -0.9])
    A_tb = dynamics.mass_matrix(scene.textbook, scene.textbook_data, q)
    A_ref = reference.mass_matrix(scene.reference, reference.ReferenceData(scene.reference), q)
    assert_close(A_tb, A_ref, rel=1e-12)


def test_locking_is_the_identity_without_the_locked_columns():
    # exact: products by 0 and 1 and sums with 0 round nothing, in any order
    m = constraints.locking(["a", "b", "c", "d"], {"b": 0.5, "d": -1.0})
    assert m.names == ("a", "c")
    assert np.array_equal(m.T, [[1, 0], [0, 0], [0, 1], [0, 0]])
    assert np.array_equal(m.expand(np.array([2.0, 3.0])), [2.0, 0.5, 3.0, -1.0])
    M = np.arange(16.0).reshape(4, 4)
    assert np.array_equal(m.reduce_matrix(M), M[np.ix_([0, 2], [0, 2])])
    assert np.array_equal(m.reduce_force(np.arange(4.0)), [0.0, 2.0])
    assert constraints.locking(["a", "b"], ["b"]).offset.tolist() == [0.0, 0.0]
    # the selection the map takes for its products is exactly the products with T
    general = constraints.HolonomicMap(m.T, m.offset, m.full_names, m.names)
    q, Q = np.array([2.0, 3.0]), np.arange(4.0)
    assert np.array_equal(m.expand(q), general.expand(q))
    assert np.array_equal(m.expand(q, offset=False), general.expand(q, offset=False))
    assert np.array_equal(m.reduce_force(Q), general.reduce_force(Q))
    assert np.array_equal(m.reduce_matrix(M), general.reduce_matrix(M))
    with pytest.raises(Rt70Error, match="no coordinate"):
        constraints.locking(["a"], ["z"])


def test_linearize_locked_equals_deleting_rows_and_columns():
    """Locking through the map gives exactly the rows and columns of the free model."""
    rt70_scene = load_scene("rt70")
    held = rt70_pointing(40.0, 20.0)
    q0 = lin.equilibrium(rt70_scene, held)
    for name, value in held.items():  # held values kept exactly
        assert q0[rt70_scene.coordinate_names.index(name)] == value
    free = lin.linearize(rt70_scene, q0)
    locked = lin.linearize(rt70_scene, q0, locked=tuple(held))
    keep = [i for i, n in enumerate(free.coordinates) if n not in held]
    assert locked.coordinates == [free.coordinates[i] for i in keep]
    ix = np.ix_(keep, keep)
    # exact: the same matrices computed again, reduced by a 0/1 map (nothing rounds)
    for attr in ("M", "K", "D", "K_gravity"):
        assert np.array_equal(getattr(locked, attr), getattr(free, attr)[ix]), attr
    with pytest.raises(Rt70Error, match="rt70.*no coordinate"):
        lin.linearize(rt70_scene, q0, locked=("no_such_axis",))


def test_rigid_links_reduce_through_their_map():
    """The book's Fig. 3.1 example: A* = S* m S*ᵀ is the map's Tᵀ m T, α = T α**."""
    model = topology.from_graph(
        [1.0, 2.0, 3.0, 4.0],
        edges=[(0, 1), (1, 2), (2, 3), (3, 4), (2, 4)],
        stiffness=[10.0, 20.0, 30.0, 40.0, 50.0],
    )
    red = holonomic.eliminate(model, rigid_edges=[(2, 3), (3, 4)])
    c = red.constraint
    assert np.array_equal(c.T, red.S_star.T) and c.names == red.names
    for full, reduced in ((model.m, red.A_star), (model.C, red.C_star), (model.D, red.D_star)):
        assert np.array_equal(c.reduce_matrix(full), reduced)
    x = np.array([0.1, -0.3])
    assert np.array_equal(c.expand(x), red.back_substitute(x))


def test_maps_compose():
    """Locking a coordinate of a model with mimic joints: one map, T = G E."""
    mimic = constraints.mimic_map(["j1", "j2", "j3"], {"j3": ("j1", 2.0, 0.1)})
    lock = constraints.locking(["j1", "j2"], {"j2": 0.25})
    both = mimic.then(lock)
    assert both.full_names == ("j1", "j2", "j3") and both.names == ("j1",)
    q = np.array([0.3])
    assert_close(both.expand(q), mimic.expand(lock.expand(q)), rel=MIN_REL)
    assert_close(both.expand(q), [0.3, 0.25, 0.7], rel=MIN_REL)
    with pytest.raises(Rt70Error, match="do not chain"):
        lock.then(mimic)
