"""Points of bodies, loads and outputs: the two sides agree, and each is what it claims.

The textbook side (:mod:`rt70.textbook.points`, from the book's S) and the reference side
(:mod:`rt70.reference.points`, from Pinocchio's joint Jacobians) compute point
positions, point Jacobians and the generalised force of a wrench (:mod:`rt70.physics.loads`);
they must agree to rounding on the RT-70, a floating-base scene, a planar scene and a
scene with mimic joints (book coordinates ≠ Pinocchio's v on the last three). Each is
also checked on its own: the Jacobian against finite differences of the position, the
load's generalised force against the virtual work ``F·δp + M·δθ``. The outputs seam
(:mod:`rt70.model.outputs`) evaluates the RT-70's optical points on either side and rides
along a simulation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70.errors import NonFiniteError, Rt70Error, ShapeError, UnknownLinkError
from rt70.linear import linearize as lin
from rt70.model import outputs
from rt70.model.scene import load_scene, scene_from_text
from rt70.physics.loads import Wrench
from rt70.reference import points as ref_points
from rt70.reports.stress.edits import free_floating_text
from rt70.scenes.synthetic import serial_chain
from rt70.simulation.simulate import simulate
from rt70.testing import MIN_REL, assert_close, close
from rt70.textbook import points as tb_points
from rt70.textbook.kinematics import frame_jacobian, frame_pose, update_structure
from rt70.urdf import read_urdf_string

ALL_TYPES = Path(__file__).parent / "data" / "all_joint_types.urdf"
TOL = 1e-12


def _scene(name: str):
    if name == "floating":
        return scene_from_text(free_floating_text(2), "free_floating_2")
    if name == "planar":
        return scene_from_text(serial_chain(3, 2, ("planar", "revolute", "prismatic")), "planar")
    if name == "mimic":
        return load_scene(ALL_TYPES)
    return load_scene(name)


@pytest.fixture(scope="module", params=["rt70", "floating", "planar", "mimic"])
def scene(request):
    return _scene(request.param)


@pytest.fixture(scope="module")
def rt70():
    return load_scene("rt70")


def test_scenes_are_what_they_claim():
    """The scenes exercise what they are named for (else agreement would prove less)."""
    kinds = {c.kind for c in _scene("floating").reference.coords}
    assert "floating" in kinds
    assert "planar" in _scene("planar").textbook.kind
    mimic = _scene("mimic")
    assert mimic.textbook.G is not None
    assert {"mimic", "mimic-continuous", "planar", "floating"} <= {
        c.kind for c in mimic.reference.coords
    }


def _sides(scene):
    tm, td = scene.textbook, scene.textbook_data
    rm, rd = scene.reference, scene.reference_data
    return (tm, td), (rm, rd)


def _moving_links(scene) -> list[str]:
    return [name for name, (body, _, _) in scene.textbook.link_frames.items() if body >= 0]


def test_sides_agree_on_positions_jacobians_and_loads(scene):
    (tm, td), (rm, rd) = _sides(scene)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = rng.uniform(-0.5, 0.5, tm.nv)
        links = list(tm.link_frames)
        located = [(link, rng.uniform(-1.0, 1.0, 3)) for link in links]
        p_tb = tb_points.point_positions(tm, td, q, located)
        p_ref = ref_points.point_positions(rm, rd, q, located)
        # positions are sums of the bodies' offsets: the largest distance from the origin
        reach = float(np.max(np.linalg.norm(p_ref, axis=1)))
        assert_close(p_tb, p_ref, rel=TOL, scale=reach, what="position")
        for link, xyz in located:
            Jv_tb, Jw_tb = tb_points.point_jacobian(tm, td, q, link, xyz)
            Jv_ref, Jw_ref = ref_points.point_jacobian(rm, rd, q, link, xyz)
            assert Jv_tb.shape == Jv_ref.shape == Jw_ref.shape == (3, tm.nv)
            # a link on the ground has no Jacobian and no load: both sides exactly 0
            assert_close(Jv_tb, Jv_ref, rel=TOL, what=f"Jv {link}")
            assert_close(Jw_tb, Jw_ref, rel=TOL, what=f"Jw {link}")
            wrench = Wrench(link, xyz, *rng.uniform(-1.0, 1.0, (2, 3)))
            Q_tb = tb_points.generalized_force(tm, td, q, wrench)
            Q_ref = ref_points.generalized_force(rm, rd, q, wrench)
            assert_close(Q_tb, Q_ref, rel=TOL, what=f"load {link}")


def test_point_position_is_one_of_point_positions(scene):
    (tm, td), (rm, rd) = _sides(scene)
    q = np.random.default_rng(1).uniform(-0.5, 0.5, tm.nv)
    link = _moving_links(scene)[-1]
    for side, (m, d) in (("tb", (tm, td)), ("ref", (rm, rd))):
        module = tb_points if side == "tb" else ref_points
        one = module.point_position(m, d, q, link, [0.1, 0.2, 0.3])
        both = module.point_positions(m, d, q, [(link, [0, 0, 0]), (link, [0.1, 0.2, 0.3])])
        # point_position is point_positions of one point, a loop over points: bit for bit
        assert np.array_equal(one, both[1]) and both.shape == (2, 3)


def _fd_position(module, model, data, q, link, xyz, h=1e-6):
    """Central differences of the point's position, one column per coordinate."""
    cols = []
    for i in range(q.size):
        e = np.zeros(q.size)
        e[i] = h
        cols.append(
            (
                module.point_position(model, data, q + e, link, xyz)
                - module.point_position(model, data, q - e, link, xyz)
            )
            / (2 * h)
        )
    return np.array(cols).T


@pytest.mark.parametrize("side", ["textbook", "reference"])
def test_jacobian_is_the_derivative_of_the_position(scene, side):
    """``J_v = ∂p/∂q`` (q̇ is the time derivative of the book's coordinates), and
    ``J_ω`` moves a second point of the link by ``ω × (p_b − p_a)``."""
    (tm, td), (rm, rd) = _sides(scene)
    module, model, data = (tb_points, tm, td) if side == "textbook" else (ref_points, rm, rd)
    rng = np.random.default_rng(7)
    q = rng.uniform(-0.4, 0.4, tm.nv)
    for link in _moving_links(scene):
        xyz = rng.uniform(-1.0, 1.0, 3)
        Jv, Jw = module.point_jacobian(model, data, q, link, xyz)
        fd = _fd_position(module, model, data, q, link, xyz)
        # the central difference rounds by ε |p| / h: the scale is |J_v| or the point's |p|
        p = module.point_position(model, data, q, link, xyz)
        scale = max(float(np.max(np.abs(Jv))), float(np.linalg.norm(p)))
        assert_close(Jv, fd, rel=1e-7, scale=scale, what=link)
        for axis in np.eye(3):
            Jv_b, Jw_b = module.point_jacobian(model, data, q, link, xyz + axis)
            r = module.point_position(model, data, q, link, xyz + axis) - p
            assert_close(Jv_b - Jv, np.cross(Jw.T, r).T, rel=1e-12, scale=scale, what=link)
            # ω is the link's, wherever the point: its rows never involve the point
            assert np.array_equal(Jw_b, Jw)


@pytest.mark.parametrize("side", ["textbook", "reference"])
def test_load_does_the_virtual_work_of_its_wrench(scene, side):
    """``Q·δq = F·δp + M·δθ``, δp and δθ from finite differences of point positions."""
    (tm, td), (rm, rd) = _sides(scene)
    module, model, data = (tb_points, tm, td) if side == "textbook" else (ref_points, rm, rd)
    rng = np.random.default_rng(11)
    q = rng.uniform(-0.4, 0.4, tm.nv)
    dq = rng.uniform(-1.0, 1.0, tm.nv)
    h = 1e-6
    for link in _moving_links(scene):
        xyz = rng.uniform(-1.0, 1.0, 3)
        wrench = Wrench(link, xyz, *rng.uniform(-1.0, 1.0, (2, 3)))
        Q = module.generalized_force(model, data, q, wrench)
        corners = [xyz, *(xyz + np.eye(3))]
        plus = module.point_positions(model, data, q + h * dq, [(link, c) for c in corners])
        minus = module.point_positions(model, data, q - h * dq, [(link, c) for c in corners])
        here = module.point_positions(model, data, q, [(link, c) for c in corners])
        dp = (plus - minus) / (2 * h)  # velocity of each corner for q̇ = δq
        # rigid body: d(p_k − p_0) = ω × r_k with r_k orthonormal, so ω = ½ Σ r_k × d_k
        r = here[1:] - here[0]
        omega = 0.5 * np.sum(np.cross(r, dp[1:] - dp[0]), axis=0)
        force, torque = np.asarray(wrench.force), np.asarray(wrench.torque)
        work = float(force @ dp[0] + torque @ omega)
        # on the scale of the work's terms, both sides
        scale = (
            np.abs(Q) @ np.abs(dq) + np.abs(force) @ np.abs(dp[0]) + np.abs(torque) @ np.abs(omega)
        )
        assert_close(Q @ dq, work, rel=1e-7, scale=scale, what=link)


# --- force_input and the linear outputs are unchanged by the seam ------------------------


def _old_point_jacobian(scene, q0, link, xyz):
    """The formula linearize.py used before the seam (kept here to compare)."""
    model, data = scene.textbook, scene.textbook_data
    body, r_link, c_link = model.link_frames[link]
    update_structure(model, data, q0)
    r = r_link + c_link @ np.asarray(xyz, dtype=float)
    J = frame_jacobian(data, body, r, np.eye(3))
    R, _ = frame_pose(data, body, np.zeros(3), np.eye(3))
    return R @ J[:3], R @ J[3:]


def test_force_input_and_outputs_unchanged(rt70):
    rng = np.random.default_rng(5)
    q0 = rng.uniform(-0.01, 0.01, rt70.textbook.nv)
    names = rt70.textbook.coordinate_names
    keep = [n for n in names if not n.endswith("_x")]  # some coordinates locked
    empty = np.zeros((0, 0))
    lm = lin.Linearization("rt70", q0, keep, empty, empty, empty, empty)
    idx = lin.coordinate_indices(rt70, keep)
    for link in ("platform", "counterweight", "main_mirror", "counterreflector"):
        direction = rng.uniform(-1.0, 1.0, 3)
        xyz = rng.uniform(-2.0, 2.0, 3)
        Jv, Jw = _old_point_jacobian(rt70, q0, link, xyz)
        unit = direction / np.linalg.norm(direction)
        # two code paths: unchanged to their rounding
        force = lin.force_input(lm, rt70, link, direction, xyz=xyz)
        assert_close(force, (Jv.T @ unit)[idx], rel=MIN_REL)
        torque = lin.force_input(lm, rt70, link, direction, torque=True, xyz=xyz)
        assert_close(torque, (Jw.T @ unit)[idx], rel=MIN_REL)
        assert_close(lin.point_output(lm, rt70, link, xyz), Jv[:, idx], rel=MIN_REL)
        _, Jw0 = _old_point_jacobian(rt70, q0, link, np.zeros(3))
        assert_close(lin.rotation_output(lm, rt70, link), Jw0[:, idx], rel=MIN_REL)


# --- bad requests -----------------------------------------------------------------------


@pytest.mark.parametrize("side", ["textbook", "reference"])
def test_unknown_link_is_a_clear_error(rt70, side):
    (tm, td), (rm, rd) = _sides(rt70)
    module, model, data = (tb_points, tm, td) if side == "textbook" else (ref_points, rm, rd)
    q = np.zeros(tm.nv)
    for call in (
        lambda: module.point_position(model, data, q, "no_such_link", np.zeros(3)),
        lambda: module.point_jacobian(model, data, q, "no_such_link", np.zeros(3)),
        lambda: module.generalized_force(model, data, q, Wrench("no_such_link")),
    ):
        with pytest.raises(UnknownLinkError, match="no link 'no_such_link'"):
            call()


def test_link_inside_a_six_dof_pair_is_named(rt70):
    """The textbook merges the massless links of a 6-DOF pair into its end link."""
    tm, td = rt70.textbook, rt70.textbook_data
    with pytest.raises(UnknownLinkError, match="platform_x_link.*merged into its end link"):
        tb_points.point_position(tm, td, np.zeros(tm.nv), "platform_x_link", np.zeros(3))


def test_wrench_checks_its_vectors():
    w = Wrench("l", [1, 2, 3], force=np.array([0.5, 0, 0]))
    assert w.xyz == (1.0, 2.0, 3.0) and w.torque == (0.0, 0.0, 0.0) and hash(w)
    with pytest.raises(ShapeError, match="wrench on 'l': force"):
        Wrench("l", force=[1, 2])
    with pytest.raises(NonFiniteError, match="torque contains NaN"):
        Wrench("l", torque=[0, np.nan, 0])


# --- outputs ----------------------------------------------------------------------------

OPTICAL = (
    "main_mirror_focus",
    "main_mirror_vertex",
    "counterreflector_focus",
    "counterreflector_vertex",
)


def test_rt70_optical_points_are_outputs(rt70):
    outs = outputs.optical_point_outputs(rt70)
    assert [o.name for o in outs] == list(OPTICAL)
    assert all(o.unit == "m" and o.size == 3 for o in outs)
    q = np.random.default_rng(2).uniform(-0.05, 0.05, rt70.textbook.nv)
    tb = outputs.evaluate(rt70, q, outs, "textbook")
    ref = outputs.evaluate(rt70, q, outs, "reference")
    assert list(tb) == list(OPTICAL)
    # positions on the scale of their distance from the ground origin (up to 89 m)
    reach = max(float(np.linalg.norm(ref[name])) for name in OPTICAL)
    for name in OPTICAL:
        assert tb[name].shape == (3,)
        assert_close(tb[name], ref[name], rel=TOL, scale=reach, what=name)
    # focus and vertex are points of one rigid body: 13 − 8 = 5 m apart, 1.2 − 0.8 = 0.4 m;
    # differences of positions, so on the positions' scale
    span = np.linalg.norm(tb["main_mirror_focus"] - tb["main_mirror_vertex"])
    assert_close(span, 5.0, rel=TOL, scale=reach)
    gap = np.linalg.norm(ref["counterreflector_focus"] - ref["counterreflector_vertex"])
    assert_close(gap, 0.4, rel=TOL, scale=reach)
    # at q = 0 the foci sit above the ground origin at the file's heights
    rest = outputs.evaluate(rt70, np.zeros(rt70.textbook.nv), outs)
    assert_close(rest["main_mirror_focus"], [0.0, 0.0, 89.0], rel=1e-14)


def test_an_output_is_a_formula_of_points(rt70):
    """What issue 10 adds: the main mirror's focal-axis direction (4.155) as an output."""
    focus, vertex = outputs.optical_point_outputs(rt70)[:2]

    def direction(p):
        d = p[0] - p[1]
        return d / np.linalg.norm(d)

    axis = outputs.Output("main_mirror_axis", "1", 3, focus.points + vertex.points, direction)
    q = np.random.default_rng(4).uniform(-0.05, 0.05, rt70.textbook.nv)
    values = outputs.evaluate(rt70, q, [focus, axis, vertex], "reference")
    assert_close(np.linalg.norm(values["main_mirror_axis"]), 1.0, rel=1e-14)
    reach = float(np.linalg.norm(values["main_mirror_focus"]))  # the points' scale
    span = values["main_mirror_focus"] - values["main_mirror_vertex"]
    assert_close(values["main_mirror_axis"] * 5.0, span, rel=TOL, scale=reach)
    assert outputs.column_labels("a", 3) == ["a:x", "a:y", "a:z"]
    assert outputs.column_labels("b", 2) == ["b:0", "b:1"]


def test_output_errors(rt70):
    focus = outputs.optical_point_outputs(rt70)[0]
    q = np.zeros(rt70.textbook.nv)
    with pytest.raises(Exception, match="named more than once: main_mirror_focus"):
        outputs.evaluate(rt70, q, [focus, focus])
    with pytest.raises(Rt70Error, match="side 'pinocchio' is now 'reference'"):
        outputs.evaluate(rt70, q, [focus], "pinocchio")
    with pytest.raises(Rt70Error, match="unknown side 'ref'"):
        outputs.evaluate(rt70, q, [focus], "ref")
    bad = outputs.Output("two", "m", 2, focus.points)  # the formula gives 3 components
    with pytest.raises(ShapeError, match="output 'two': expected shape"):
        outputs.evaluate(rt70, q, [bad])
    with pytest.raises(UnknownLinkError):
        outputs.evaluate(rt70, q, [outputs.position_output("x", "nowhere", [0, 0, 0])])


@pytest.mark.parametrize("side", ["reference", "textbook"])
def test_simulation_carries_outputs(tmp_path, side):
    scene = load_scene("double_pendulum")
    tip = outputs.position_output("tip", "link2", [0.0, 0.0, -1.0])
    t = np.linspace(0.0, 0.05, 6)
    x0 = (np.array([0.3, -0.2]), np.zeros(2))
    result = simulate(scene, (0.0, 0.05), x0, side=side, t_eval=t, outputs=[tip])
    assert result.outputs["tip"].shape == (6, 3)
    expected = outputs.evaluate_trajectory(scene, result.q, [tip], side)["tip"]
    assert np.array_equal(result.outputs["tip"], expected)  # the same function: bit for bit
    assert not close(result.outputs["tip"][0], result.outputs["tip"][-1], rel=1e-5)  # it moved
    with np.load(result.save(tmp_path / "run.npz")) as saved:
        assert np.array_equal(saved["output:tip"], result.outputs["tip"])
    text = result.save(tmp_path / "run.csv").read_text(encoding="utf-8").splitlines()
    header = text[0].split(",")
    assert header[-3:] == ["tip:x", "tip:y", "tip:z"]
    last = np.array([float(x) for x in text[-1].split(",")[-3:]])
    assert np.array_equal(last, result.outputs["tip"][-1])


def test_simulation_refuses_a_bad_output_before_running():
    scene = load_scene("double_pendulum")
    bad = outputs.position_output("tip", "link9", [0.0, 0.0, 0.0])
    with pytest.raises(UnknownLinkError, match="link9"):
        simulate(scene, (0.0, 1e3), outputs=[bad])  # would take long if it ran


def test_root_link_not_named_world():
    """Pinocchio keeps a body frame for a root link of any name; the ground does not move."""
    text = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""
    assert read_urdf_string(text).root == "base"
    scene = scene_from_text(text, "r")
    (tm, td), (rm, rd) = _sides(scene)
    q = np.array([0.4])
    for module, m, d in ((tb_points, tm, td), (ref_points, rm, rd)):
        assert_close(module.point_position(m, d, q, "base", [1, 2, 3]), [1, 2, 3], rel=MIN_REL)
        Jv, Jw = module.point_jacobian(m, d, q, "base", [1, 2, 3])
        assert not Jv.any() and not Jw.any()  # the ground: no Jacobian at all
        Jv, Jw = module.point_jacobian(m, d, q, "arm", [1, 0, 0])
        assert_close(Jw[:, 0], [0, 0, 1], rel=MIN_REL)
        assert_close(Jv[:, 0], [-np.sin(0.4), np.cos(0.4), 0], rel=1e-14)


def test_reference_points_are_located_once_per_data():
    """point_positions keeps each point's (joint, placement) in data.placements: a second
    call finds them and gives the same positions; a point that is not three numbers is
    the same clear error every time, and is not kept."""
    scene = load_scene("rt70")
    ref, data = scene.reference, scene.reference_data
    pts = [(p.link, p.xyz) for p in scene.description.optical_points]
    q = 0.01 * np.random.default_rng(5).standard_normal(scene.textbook.nv)
    first = ref_points.point_positions(ref, data, q, pts)
    assert len(data.placements) == len(set((lk, tuple(x)) for lk, x in pts)) > 0
    np.testing.assert_array_equal(ref_points.point_positions(ref, data, q, pts), first)
    kept = len(data.placements)
    for bad in ("abc", (1.0, 2.0)):
        with pytest.raises(ShapeError, match="point of link"):
            ref_points.point_positions(ref, data, q, [(pts[0][0], bad)])
    assert len(data.placements) == kept
