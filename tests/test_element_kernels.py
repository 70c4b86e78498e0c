"""The compiled elements (rt70.reference.element_kernels) against the Python path.

The kernels walk the joints between each bushing's frames instead of asking Pinocchio
for frame placements and Jacobians; both must give the same forces, gains and
potential (:mod:`rt70.reference.forces` is the path ``rt70 validate`` cross-checks
against the textbook side), on every scene and on a tree whose bushings join siblings
through unaligned revolute, prismatic and continuous joints.
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin
import pytest

from rt70.errors import SingularConfigurationError
from rt70.model.scene import load_scene, scene_from_text
from rt70.reference import forces
from rt70.reference.element_kernels import ElementKernels
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close

SCENES = ("rt70", "rt70_servo", "rt70_azimuth", "rt70_elevation", "three_masses",
          "two_body_gravity", "rt70_jack")  # fmt: skip

SIBLINGS = """<?xml version="1.0"?>
<robot name="siblings" xmlns:rt70="urn:rt70:urdf-extensions:1">
  <link name="world"/>
  <joint name="hub" type="revolute"><parent link="world"/><child link="a"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.2 -0.1 0.4"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <link name="a"><inertial><mass value="3"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="2.5"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.5 0 0" rpy="0 0.3 0"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <link name="b"><inertial><mass value="2"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="wheel" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="0 0.4 0" rpy="0.1 0 0"/><axis xyz="1 0 0"/></joint>
  <link name="c"><inertial><mass value="1"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="arm" type="revolute"><parent link="a"/><child link="d"/>
    <origin xyz="0 0 0.7" rpy="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <link name="d"><inertial><mass value="1.5"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <rt70:bushing name="across" stiffness="10 20 30 40 50 60" damping="1 2 3 4 5 6">
    <rt70:frame1 link="c" xyz="0.1 0 0.2" rpy="0.3 0.2 0.1"/>
    <rt70:frame2 link="d" xyz="0 0.1 0" rpy="0 0 0.2"/>
  </rt70:bushing>
  <rt70:bushing name="to_ground" stiffness="5 5 5 7 7 7" damping="0.5 0.5 0.5 1 1 1">
    <rt70:frame1 link="world" xyz="0 0 1"/>
    <rt70:frame2 link="c"/>
  </rt70:bushing>
  <rt70:bushing name="coupled" stiffness="{stiffness}" damping="{damping}">
    <rt70:frame1 link="b" xyz="0.2 0 0.1" rpy="0.1 0.2 0"/>
    <rt70:frame2 link="d" xyz="0 0 0.1"/>
  </rt70:bushing>
</robot>
"""


def _coupled(scale: float, seed: int) -> str:
    """A full symmetric positive definite 6 × 6, row by row: every axis coupled."""
    L = np.random.default_rng(seed).uniform(-1.0, 1.0, (6, 6))
    C = scale * (L @ L.T + np.eye(6))
    return " ".join(f"{x:.17g}" for x in (0.5 * (C + C.T)).ravel())


SIBLINGS = SIBLINGS.format(stiffness=_coupled(30.0, 1), damping=_coupled(2.0, 2))


def _states(model, n: int, seed: int):
    rng = np.random.default_rng(seed)
    m = model.pin_model
    for _ in range(n):
        qp = pin.normalize(m, 0.4 * rng.standard_normal(m.nq))
        yield qp, rng.standard_normal(m.nv)


def _check(scene) -> None:
    ref, rd = scene.reference, scene.reference_data
    kernels = ElementKernels.of(ref)
    assert kernels is not None
    for qp, vp in _states(ref, 4, seed=len(scene.name)):
        tau_c, tau_d = forces.element_torques(ref, rd, qp, vp)
        K, D = forces.element_gains(ref, rd, qp)
        U = sum(0.5 * e.squares(e.stiffness) for e in forces.elements(ref, rd, qp, False))
        assert np.max(np.abs(tau_c)) > 0.0 and U > 0.0  # something to compare
        fast = kernels.torques_and_gains(qp, vp)
        # a scene without dampers: exactly zero on both sides
        for name, want, got in zip(
            ("τ_c", "τ_d", "K", "D"), (tau_c, tau_d, K, D), fast, strict=True
        ):
            assert_close(got, want, rel=1e-13, what=name)
        torques = np.array(kernels.torques(qp, vp))
        assert_close(torques[0], tau_c, rel=1e-13, what="τ_c")
        assert_close(torques[1], tau_d, rel=1e-13, what="τ_d")
        assert_close(kernels.potential(qp), U, rel=1e-13)  # a sum of positive energies


@pytest.mark.parametrize("name", SCENES)
def test_kernels_equal_the_python_path_on_the_scenes(name):
    _check(load_scene(name))


def test_kernels_on_siblings_through_unaligned_prismatic_and_continuous_joints():
    """Also a bushing whose 6 × 6 gains couple every axis ("coupled")."""
    scene = scene_from_text(SIBLINGS, "siblings")
    kinds = set(ElementKernels.of(scene.reference).tables.kind.tolist())
    assert kinds == {0, 1, 2}  # revolute, prismatic and continuous all walked
    _check(scene)


def test_a_mimic_model_keeps_the_python_path():
    """The simulation's backend uses the kernels only where the book's coordinates are
    Pinocchio's (q, v); the gear reducer's mimic joints map them."""
    from rt70.simulation.backends import BACKENDS

    scene = load_scene("gear_reducer")
    assert not scene.reference.identity_map
    assert BACKENDS["reference"](scene).kernels is None
    assert BACKENDS["reference"](load_scene("rt70")).kernels is not None


def test_a_model_with_a_free_flyer_on_the_path_is_not_supported():
    text = SIBLINGS.replace('name="hub" type="revolute"', 'name="hub" type="floating"')
    scene = scene_from_text(text, "floating")
    assert ElementKernels.of(scene.reference) is None


def test_gimbal_lock_is_refused_like_the_python_path():
    """Frame 2 turned by π/2 in pitch relative to frame 1: rpy of c12ᵀ is singular."""
    text = SIBLINGS.replace('<rt70:frame2 link="d" xyz="0 0.1 0" rpy="0 0 0.2"/>',
                            '<rt70:frame2 link="c" rpy="0 1.5707963267948966 0"/>')  # fmt: skip
    text = text.replace('<rt70:frame1 link="c" xyz="0.1 0 0.2" rpy="0.3 0.2 0.1"/>',
                        '<rt70:frame1 link="c"/>')  # fmt: skip
    scene = scene_from_text(text, "locked")
    ref, rd = scene.reference, scene.reference_data
    qp, v = pin.neutral(ref.pin_model), np.zeros(ref.pin_model.nv)
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        forces.element_torques(ref, rd, qp, v)
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        ElementKernels.of(ref).torques(qp, v)


def test_simulation_with_kernels_equals_the_python_path(monkeypatch):
    """The RT-70 from the listing's state: the fast path's trajectory is the Python path's
    to within the integration tolerance (same method, same rtol)."""
    from rt70.simulation.backends import BACKENDS

    scene = load_scene("rt70")
    x0 = listing_initial_state(scene)
    t = np.linspace(0.0, 0.3, 31)
    runs = []
    backend = BACKENDS["reference"]
    for kernels in (True, False):
        monkeypatch.setitem(BACKENDS, "reference", functools.partial(backend, kernels=kernels))
        runs.append(simulate(scene, (0.0, 0.3), x0, rtol=1e-8, t_eval=t))
    fast, slow = runs
    assert_close(fast.q, slow.q, rel=1e-6)
    assert_close(fast.elastic, slow.elastic, rel=1e-6)


def test_compiled_drive_angle_and_force_equal_pinocchios():
    """θ_d and ∂θ_d/∂q of every drive: the compiled mesh point against Pinocchio's two
    placements and point Jacobians (rt70.reference.drives.drive_force)."""
    from rt70.reference import drives as kin

    scene = load_scene("rt70_servo")  # a joint drive (azimuth) and a gear sector (elevation)
    ref, rd = scene.reference, scene.reference_data
    assert {d.sector is None for d in scene.description.drives} == {True, False}
    rng = np.random.default_rng(7)
    for drive in scene.description.drives:
        mesh = None if drive.sector is None else kin.sector_mesh(ref, rd, drive)
        fast = kin.drive_force_function(ref, rd, drive, mesh)
        for _ in range(4):
            q = 0.05 * rng.standard_normal(scene.textbook.nv)
            angle, Q = kin.drive_force(ref, rd, q, drive, 1.0, mesh)
            got_angle, got_Q = fast(q)
            # an angle from unit rotations: its rounding is absolute, on the scale of π
            assert_close(got_angle, angle, rel=1e-14, scale=np.pi)
            assert_close(got_Q, Q, rel=1e-13)


def test_a_new_element_kind_turns_the_kernels_off(monkeypatch):
    """A kind added to the reference side's ELEMENTS but not to the kernels must not be
    left out silently: the backend falls back to the Python path."""
    from rt70.reference import element_tables

    scene = load_scene("rt70")
    assert tuple(forces.ELEMENTS) == element_tables.COVERED
    assert ElementKernels.of(scene.reference) is not None
    monkeypatch.setitem(forces.ELEMENTS, "new_kind", lambda *a: None)
    assert ElementKernels.of(scene.reference) is None


@pytest.mark.parametrize("direction", (0.0, 90.0, 210.0))
def test_compiled_wind_force_equals_pinocchios(direction):
    """The wind's generalised force from the compiled poses and point Jacobians against
    Pinocchio's placements and point Jacobians (rt70.reference.wind.wind_force)."""
    from rt70.physics.aerodynamics import WindCondition
    from rt70.reference import wind as kin

    scene = load_scene("rt70_servo")
    ref, rd = scene.reference, scene.reference_data
    assert ref.winds
    fast = kin.wind_force_function(ref, rd)
    rng = np.random.default_rng(int(direction))
    condition = WindCondition(20.0, direction)
    for _ in range(3):
        q = 0.05 * rng.standard_normal(scene.textbook.nv)
        want = kin.wind_force(ref, rd, q, condition)
        assert np.max(np.abs(want)) > 0.0
        assert_close(fast(q, condition), want, rel=1e-13)
