"""Linearisation of the nonlinear model: equilibrium, K with geometric stiffness, locking."""

import numpy as np
import pinocchio as pin
import pytest

from rt70 import reference
from rt70.linear import linearize as lin
from rt70.linear.sag import sag
from rt70.model.scene import load_scene
from rt70.scenes import rt70_state
from rt70.testing import assert_close


@pytest.fixture(scope="module")
def rt70():
    return load_scene("rt70")


def test_equilibrium_balances_gravity_and_springs(rt70):
    held = rt70_state.rt70_pointing(45.0, 30.0)
    q0 = lin.equilibrium(rt70, held)
    free = np.setdiff1d(np.arange(rt70.textbook.nv), lin.coordinate_indices(rt70, list(held)))
    Q = lin.static_force(rt70, q0)
    g_scale = np.abs(lin.static_force(rt70, np.where(np.isin(np.arange(42), free), 0.0, q0))).max()
    assert_close(Q[free], np.zeros(len(free)), rel=1e-10, scale=g_scale)
    for name, value in held.items():
        assert q0[rt70.textbook.coordinate_names.index(name)] == value


def test_gravity_stiffness_matches_pinocchio_analytic(rt70):
    """The finite-difference geometric stiffness equals −∂Q_g/∂q from Pinocchio's derivatives."""
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.3, 0.3, rt70.textbook.nv)
    K_g = lin._gravity_stiffness(rt70, q, side="textbook")
    ref, pd = rt70.reference, rt70.reference_data.pin_data
    qp, _, J, _ = reference.to_pinocchio(ref, q)
    dg = pin.computeGeneralizedGravityDerivatives(ref.pin_model, pd, qp)  # ∂g/∂q, g = −Q_g
    K_ref = dg if J is None else J.T @ dg @ J
    K_ref = 0.5 * (K_ref + K_ref.T)
    assert_close(K_g, K_ref, rel=1e-7)  # a finite difference against the analytic


def test_spring_stiffness_at_rest_is_sum_jt_c_j(rt70):
    """At q = 0 (δ = 0) the springs' stiffness is exactly Σ Jᵀ C J."""
    from rt70.textbook import forces
    from rt70.textbook.kinematics import update_structure

    tm, td = rt70.textbook, rt70.textbook_data
    q = np.zeros(tm.nv)
    K = lin.stiffness_matrix(rt70, q) - lin._gravity_stiffness(rt70, q)
    update_structure(tm, td, q)
    exact = np.zeros((tm.nv, tm.nv))
    for b in tm.bushings:
        J = forces.bushing_deformation(td, b).jacobian
        exact += J.T @ b.stiffness @ J
    assert_close(K, exact, rel=1e-8)


def test_damping_matrix_is_exact(rt70):
    from rt70.textbook import forces

    q = np.random.default_rng(1).uniform(-0.2, 0.2, 42)
    D = lin.damping_matrix(rt70, q)
    qd = np.random.default_rng(2).uniform(-1, 1, 42)
    _, Qd = forces.spring_damper_force(rt70.textbook, rt70.textbook_data, q, qd)
    assert_close(D @ qd, -Qd, rel=1e-12)


def test_locked_coordinates_equal_pinocchio_reduced_model(rt70):
    """Locking coordinates (f in 3-D) equals Pinocchio's buildReducedModel."""
    locked = [n for n in rt70.textbook.coordinate_names if not n.endswith("_rz")]
    q0 = np.zeros(42)
    model = lin.linearize(rt70, q0, locked=tuple(locked))
    assert len(model.coordinates) == 7
    ref = rt70.reference
    lock_ids = [ref.pin_model.getJointId(n) for n in locked]
    reduced = pin.buildReducedModel(ref.pin_model, lock_ids, pin.neutral(ref.pin_model))
    M_pin = pin.crba(reduced, reduced.createData(), pin.neutral(reduced))
    M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
    order = [reduced.names[i] for i in range(1, reduced.njoints)]
    idx = [order.index(n) for n in model.coordinates]
    assert_close(model.M, M_pin[np.ix_(idx, idx)], rel=1e-12, scale=np.abs(M_pin).max())


def test_sag_reports_mm_and_arcsec(rt70):
    held = rt70_state.rt70_pointing(90.0)
    q0 = lin.equilibrium(rt70, held)
    sags = {s.body: s for s in sag(rt70, q0, held)}
    assert set(sags) == set(rt70.textbook.body_names)
    # gravity pushes the platform down: its origin sinks (z < 0) by m g / C_z
    expected = -sum(rt70.textbook.mass) * 9.81 / 5.0e10 * 1e3
    assert_close(sags["platform"].displacement_mm[2], expected, rel=1e-9)


def test_unknown_coordinate_is_a_clear_error(rt70):
    from rt70.errors import Rt70Error

    with pytest.raises(Rt70Error, match="no coordinate"):
        lin.equilibrium(rt70, {"nope": 0.0})


def test_inputs_and_outputs_of_the_rt70(rt70):
    """Drive torque in, mirror focus out: B and C from the textbook Jacobians, checked."""
    from rt70.linear import responses

    held = rt70_state.rt70_pointing(60.0)
    q0 = lin.equilibrium(rt70, held)
    lm = lin.linearize(rt70, q0, locked=(rt70_state.ELEVATION_COORDINATE,))
    # azimuth drive: a torque about the ground z axis on the platform acts on platform_rz
    b = lin.force_input(lm, rt70, "platform", [0, 0, 1], torque=True)
    # 1 to the cosine of the sagged platform's tilt (1 − 7.4e-9 measured)
    assert_close(b[lm.coordinates.index("platform_rz")], 1.0, rel=1e-6)
    # elevation drive force on the counterweight along y (formalism §4.5)
    b_el = lin.force_input(lm, rt70, "counterweight", [0, 1, 0])
    assert np.abs(b_el).max() > 0
    # focus of the main mirror: a rigid azimuth rotation moves it by ω × r
    focus = next(p for p in rt70.description.optical_points if p.name == "main_mirror_focus")
    C = lin.point_output(lm, rt70, focus.link, focus.xyz)
    dq = np.zeros(len(lm.coordinates))
    dq[lm.coordinates.index("platform_rz")] = 1e-6
    tm, td = rt70.textbook, rt70.textbook_data
    from rt70.textbook.kinematics import frame_pose, update_structure

    def focus_position(q):
        update_structure(tm, td, q)
        body, r, c = tm.link_frames[focus.link]
        return frame_pose(td, body, r + c @ focus.xyz, np.eye(3))[1]

    q1 = q0.copy()
    q1[lin.coordinate_indices(rt70, lm.coordinates)] += dq
    moved = focus_position(q1) - focus_position(q0)
    # first order in θ = 1e-6: the second-order θ² r / 2 ≈ 1e-11 m is 1e-6 of the move
    assert_close(C @ dq, moved, rel=1e-5)
    # a state-space model from the drive torque to the focus displacement
    ss = responses.state_space(lm.M, lm.K, lm.D, b, C)
    assert ss.A.shape == (2 * len(lm.coordinates),) * 2 and ss.C.shape[0] == 3


@pytest.mark.parametrize("elevation", [30.0, 90.0])
def test_equilibrium_stops_at_the_rounding_floor(elevation):
    """rt70_servo at 30°: the residual stalls at 1.2e-10 of its scale (rounding of the
    strut forces), above the default tol; Newton stops when its step is below STEP_TOL.
    At the zenith, a start already in equilibrium has no force scale (1 N): same stop."""
    from rt70.scenes.rt70_state import rt70_pointing

    scene = load_scene("rt70_servo")
    held = rt70_pointing(elevation)
    q = lin.equilibrium(scene, held)
    again = lin.equilibrium(scene, held, q_start=q)  # from a converged start
    hold = lin.locking_map(scene, held)
    scale = np.abs(lin.static_force(scene, hold.expand(np.zeros(hold.T.shape[1])))).max()
    for x in (q, again):
        residual = hold.reduce_force(lin.static_force(scene, x))
        assert_close(residual, np.zeros_like(residual), rel=3e-10, scale=scale)
    # at most one Newton step below STEP_TOL, on the scale its stop test uses
    assert_close(again, q, rel=lin.STEP_TOL, scale=max(1.0, np.abs(q).max()))


def test_no_equilibrium_names_the_coordinates_without_stiffness():
    """A boom on a sprung hinge and a free slewing base: gravity is balanced on the hinge,
    and the slew has no stiffness at all, so Newton's K is singular along it alone."""
    from rt70.errors import Rt70Error
    from rt70.model.scene import scene_from_text

    text = """<robot name="free_slew" xmlns:rt70="urn:rt70:urdf-extensions:1">
  <link name="world"/>
  <link name="base"><inertial><mass value="100"/>
    <inertia ixx="10" iyy="10" izz="10" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="slew" type="continuous"><parent link="world"/><child link="base"/>
    <axis xyz="0 0 1"/></joint>
  <link name="boom"><inertial><mass value="50"/><origin xyz="1 0 0"/>
    <inertia ixx="1" iyy="5" izz="5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="boom"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <rt70:joint_spring name="hinge_spring" joint="hinge" stiffness="1e5"/>
</robot>"""
    scene = scene_from_text(text, "free_slew")
    with pytest.raises(Rt70Error, match=r"no stiffness along 'slew' \(hold or lock"):
        lin.equilibrium(scene)
    q = lin.equilibrium(scene, {"slew": 0.3})  # held: the hinge's sag alone
    assert q[0] == 0.3 and q[1] != 0.0


def test_newton_stiffness_is_the_stiffness_without_the_springs_preload_term(monkeypatch):
    """Newton's matrix (gravity exact, springs Σ JᵀCJ) is the differenced K but for the
    springs' geometric term, small on rt70_servo; it steers Newton, not the answer, and
    a scene whose coordinates are not Pinocchio's gets the differenced K itself."""
    servo = load_scene("rt70_servo")
    held = rt70_state.rt70_pointing(30.0, 20.0)
    q0 = lin.equilibrium(servo, held)
    K = lin.stiffness_matrix(servo, q0)
    K_newton = lin.newton_stiffness(servo, q0)
    assert np.abs(K_newton - K).max() > 0.0  # the preload term is left out, not zero
    assert_close(K_newton, K, rel=1e-6, scale=np.abs(K).max())
    gear = load_scene("gear_reducer")
    q = np.zeros(gear.textbook.nv)
    assert reference.newton_stiffness(gear.reference, gear.reference_data, q) is None
    np.testing.assert_array_equal(lin.newton_stiffness(gear, q), lin.stiffness_matrix(gear, q))
    differenced = lambda scene, x, side="reference": lin.stiffness_matrix(scene, x, side=side)  # noqa: E731
    monkeypatch.setattr(lin, "newton_stiffness", differenced)
    q_differenced = lin.equilibrium(servo, held)
    assert_close(q0, q_differenced, rel=1e-9, scale=1.0)
