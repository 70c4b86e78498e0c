"""Wind loads (``<rt70:wind>``, rt70.physics.aerodynamics): conventions, tables, refusals.

The wind's generalised force is computed independently by the textbook side (book
forward pass, S·W) and the reference side (Pinocchio placements, Jᵀf) from one shared
Wrench per exposed body; they must agree to rounding at random states and winds. The
wind frame must satisfy (4.132)/(4.133), the force must be exactly quadratic in the
speed, do the virtual work ``F·v_p + M·ω``, turn with the telescope, and the
coefficient ratios must be smooth through θ = 0 and 180°.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import rt70.cli.main
from rt70.errors import ExtensionError, UrdfError
from rt70.model.scene import load_scene, scene_from_text
from rt70.physics.aerodynamics import (
    DEFAULT_AIR_DENSITY,
    WindCondition,
    body_load,
    horizontal_direction,
    wind_frame,
)
from rt70.physics.coefficient_tables import CoefficientTable, WindError, builtin_table
from rt70.reference import points as ref_points
from rt70.reference import wind as ref_wind
from rt70.scenes import rt70_data
from rt70.scenes.rt70_state import rt70_pointing
from rt70.scenes.rt70_wind import solid_cylinder, thin_disc_radius, wind_elements
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import points as tb_points
from rt70.textbook import wind as tb_wind
from rt70.urdf import read_urdf_string

TURRET = Path(__file__).parent / "data" / "turret_drives.urdf"
TABLES = Path(__file__).resolve().parents[1] / "rt70" / "wind_tables"

WINDS = (
    '<rt70:wind name="dish" link="boom" shape="dish" area="2" length="1.6" '
    'xyz="0 0.2 0.5" axis="0 1 0"/>\n'
    '<rt70:wind name="mast" link="platform" shape="cylinder" area="1" length="2" '
    'axis="0 0 1"/>\n'
)


def _turret_text(extra: str = WINDS) -> str:
    return TURRET.read_text(encoding="utf-8").replace("</robot>", extra + "</robot>")


@pytest.fixture(scope="module")
def servo():
    return load_scene("rt70_servo")


@pytest.fixture(scope="module")
def turret():
    return scene_from_text(_turret_text(), "turret_wind")


def _both(scene, q, condition):
    tb = tb_wind.wind_force(scene.textbook, scene.textbook_data, q, condition)
    ref = ref_wind.wind_force(scene.reference, scene.reference_data, q, condition)
    return tb, ref


def _pointed(scene, elevation_deg, azimuth_deg, rng=None, size=0.0):
    names = scene.coordinate_names
    q = np.zeros(len(names)) if rng is None else size * rng.standard_normal(len(names))
    for name, value in rt70_pointing(elevation_deg, azimuth_deg).items():
        q[names.index(name)] = value
    return q


# --- conventions -----------------------------------------------------------------------


def test_wind_frame_satisfies_4_132_and_4_133():
    rng = np.random.default_rng(0)
    for _ in range(50):
        v = rng.normal(size=3) * rng.uniform(0.1, 30.0)
        alpha, beta, c = wind_frame(v)
        speed = np.linalg.norm(v)
        assert_close(c @ [0.0, speed, 0.0], v, rel=1e-13, scale=speed)
        assert_close(c.T @ c, np.eye(3), rel=1e-14) and np.linalg.det(c) > 0
        # angles on the range of the functions that give them (π)
        assert_close(beta, -math.asin(v[0] / speed), rel=1e-14, scale=math.pi)
        assert_close(alpha, math.atan2(v[2], v[1]), rel=1e-14, scale=math.pi)
    with pytest.raises(WindError):
        wind_frame(np.zeros(3))


def test_direction_is_the_azimuth_the_wind_blows_from(servo):
    """direction == azimuth: a front wind into the dish; v0 = −speed·h(direction)."""
    for A in (0.0, 37.0, -120.0):
        velocity = WindCondition(10.0, A).velocity()
        assert_close(velocity, -10.0 * horizontal_direction(A), rel=1e-14)
    assert_close(horizontal_direction(0.0), [0.0, -1.0, 0.0], rel=MIN_REL)
    # at elevation 0 a front wind hits the main mirror's concave face head-on: pure drag
    # 1.42 q S pushing the dish back along −boresight
    q = _pointed(servo, 0.0, 30.0)
    wrench = ref_wind.wind_wrenches(servo.reference, servo.reference_data, q, WindCondition(10, 30))
    main = wrench["main_mirror"]
    boresight = np.array([math.cos(0.0) * v for v in horizontal_direction(30.0)])
    qS = 0.5 * DEFAULT_AIR_DENSITY * 100.0 * math.pi * 35.0**2
    assert_close(main.force, -1.42 * qS * boresight, rel=1e-9, scale=qS)
    # no moment: on the size of one, q S times the element's length
    length = next(w.length for w in servo.description.winds if w.name == "main_mirror")
    assert_close(main.torque, np.zeros(3), rel=1e-9, scale=qS * length)


def test_coefficient_signs():
    """C_A > 0 pushes back, C_N > 0 along the cross-flow, C_M > 0 turns the face to the wind."""
    table = builtin_table("dish")
    a = np.array([0.0, 0.0, 1.0])
    theta = math.radians(50.0)
    u = -np.array([math.sin(theta), 0.0, math.cos(theta)])  # −u at θ from a
    F, M = body_load(table, a, u, 1.0, 1.0)
    c_a, c_n, c_m = table.coefficients(theta)
    cross = (u - (u @ a) * a) / np.linalg.norm(u - (u @ a) * a)
    size = np.linalg.norm(F)  # the components of F are parts of it
    assert_close(F @ a, -c_a, rel=1e-14, scale=size) and c_a > 0
    assert_close(F @ cross, c_n, rel=1e-14, scale=size) and c_n > 0
    # rotating a about M (C_M > 0) brings it toward −u: d(−u·a)/dt = −u·(M × a) > 0
    assert -u @ np.cross(M, a) > 0
    assert_close(np.linalg.norm(M), c_m, rel=1e-14)


# --- tables ----------------------------------------------------------------------------


def _dish(theta_deg):
    c = np.cos(np.radians(theta_deg))
    c[theta_deg == 90.0] = 0.0
    axial = np.where(theta_deg <= 90.0, 1.42 * c, 1.17 * c)
    return axial, 0.19 * np.sin(np.radians(theta_deg)) ** 2, 0.3 * axial * (1 - np.abs(c))


def test_builtin_tables_are_their_stated_formulas():
    dish, cyl = builtin_table("dish"), builtin_table("cylinder")
    theta = np.arange(0.0, 181.0, 5.0)
    assert np.array_equal(dish.theta_deg, theta) and np.array_equal(cyl.theta_deg, theta)
    for got, want in zip((dish.axial, dish.normal, dish.moment), _dish(theta), strict=True):
        assert_close(got, want, rel=MIN_REL)
    assert_close(cyl.normal, 1.2 * np.sin(np.radians(theta)) ** 2, rel=MIN_REL)
    assert not cyl.axial.any() and not cyl.moment.any()
    # the derived magnitudes docs/wind.md quotes: face-on drag 1.42, peak C_M 0.1065 at 60°
    assert_close(dish.axial[0], 1.42, rel=MIN_REL)
    assert_close(dish.moment.max(), 0.1065, rel=1e-14)  # 0.3 · 1.42 · ½ · ½
    assert dish.theta_deg[np.argmax(dish.moment)] == 60.0
    for name in ("dish", "cylinder"):  # each file states it is an estimate, and how
        text = (TABLES / f"{name}.csv").read_text(encoding="utf-8")
        assert "NOT A WIND-TUNNEL MEASUREMENT" in text and "Hoerner" in text


def test_spline_passes_through_the_rows():
    table = builtin_table("dish")
    size = np.abs(table.axial).max()  # the table's coefficients are this size (1.42)
    for k, th in enumerate(table.theta_deg):
        got = table.coefficients(math.radians(th))
        want = (table.axial[k], table.normal[k], table.moment[k])
        assert_close(got, want, rel=1e-14, scale=size)


@pytest.mark.parametrize("end", [0.0, math.pi])
def test_ratios_are_smooth_through_both_ends(end):
    """C/sin θ → the spline's derivative, with an O(θ²) approach, on both sides of the switch."""
    table = builtin_table("dish")
    size = np.abs(table.axial).max()  # the table's coefficients are this size (1.42)
    at_end = np.array(table.ratios(math.cos(end), 0.0))
    for x in (1e-2, 1e-3, 1e-5, 1e-7, 0.99e-8, 1.01e-8, 1e-9):
        th = end + x if end == 0.0 else end - x
        r = np.array(table.ratios(math.cos(th), math.sin(th)))
        # within 5 θ² (an O(θ²) approach), or rounding of the table's size where that is less
        assert_close(r, at_end, rel=5.0 * x * x / size, scale=size, what=f"θ − end = {x:g}")
    # and the odd ratio is the derivative: C_N'(0) of the spline, −C_N'(π) at π
    normal = table.splines[1]
    derivative = (1.0 if end == 0.0 else -1.0) * float(normal(end, 1))
    assert_close(at_end[1], derivative, rel=1e-14)


# --- both sides ------------------------------------------------------------------------


def test_sides_agree_at_random_states_and_winds(servo, turret):
    rng = np.random.default_rng(11)
    for scene in (servo, turret):
        for _ in range(8):
            q = rng.uniform(-0.5, 0.5, scene.textbook.nv)
            c = WindCondition(rng.uniform(1, 40), rng.uniform(0, 360), rng.uniform(0.9, 1.3))
            tb, ref = _both(scene, q, c)
            assert np.abs(ref).max() > 0
            assert_close(tb, ref, rel=1e-13, what=scene.name)


def test_breakdown_sums_to_the_total(servo):
    q = _pointed(servo, 40.0, 10.0, np.random.default_rng(2), 1e-3)
    c = WindCondition(15.0, 70.0)
    for side, model, data in (
        (tb_wind, servo.textbook, servo.textbook_data),
        (ref_wind, servo.reference, servo.reference_data),
    ):
        parts = side.wind_forces(model, data, q, c)
        assert list(parts) == ["main_mirror", "counterreflector", "rigel", "mirror_base"]
        size = max(np.abs(part).max() for part in parts.values())  # the terms of the sum
        assert_close(sum(parts.values()), side.wind_force(model, data, q, c), rel=1e-14, scale=size)


def test_force_is_exactly_quadratic_in_speed_and_linear_in_density(servo):
    q = _pointed(servo, 30.0, 0.0, np.random.default_rng(3), 1e-3)
    for side in (0, 1):
        base = _both(servo, q, WindCondition(7.0, 20.0))[side]
        double = _both(servo, q, WindCondition(14.0, 20.0))[side]
        dense = _both(servo, q, WindCondition(7.0, 20.0, density=2 * DEFAULT_AIR_DENSITY))[side]
        assert_close(double, 4.0 * base, rel=1e-14)
        assert_close(dense, 2.0 * base, rel=1e-14)
        assert not _both(servo, q, WindCondition(0.0, 20.0))[side].any()


def test_scene_air_density_is_used(turret):
    thin = scene_from_text(_turret_text(WINDS + '<rt70:air density="0.97"/>\n'), "thin_air")
    assert thin.description.air_density == 0.97
    q = np.full(turret.textbook.nv, 0.1)
    c = WindCondition(12.0, 80.0)
    want = 0.97 / DEFAULT_AIR_DENSITY * _both(turret, q, c)[1]
    assert want.any()
    assert_close(_both(thin, q, c)[1], want, rel=1e-14, scale=np.abs(want))  # entry by entry


def test_power_is_the_virtual_work_of_the_wrenches(servo):
    """q̇ᵀQ = Σ F·v_p + M·ω, the points' velocities from the other side's Jacobians."""
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd = rng.uniform(-0.3, 0.3, servo.textbook.nv), rng.uniform(-1, 1, servo.textbook.nv)
        c = WindCondition(rng.uniform(5, 30), rng.uniform(0, 360))
        tb, ref = _both(servo, q, c)
        wrenches = ref_wind.wind_wrenches(servo.reference, servo.reference_data, q, c)
        power = 0.0
        for w in wrenches.values():
            Jv, Jw = tb_points.point_jacobian(servo.textbook, servo.textbook_data, q, w.link, w.xyz)
            power += np.dot(w.force, Jv @ qd) + np.dot(w.torque, Jw @ qd)
        scale = (
            sum(np.abs(w.force).sum() + np.abs(w.torque).sum() for w in wrenches.values())
            * np.abs(qd).max()
        )
        assert_close(qd @ ref, power, rel=1e-12, scale=scale)
        assert_close(qd @ tb, power, rel=1e-12, scale=scale)
        Jv, _ = ref_points.point_jacobian(
            servo.reference, servo.reference_data, q, "main_mirror", [0, 0, 8]
        )
        Jv_tb, _ = tb_points.point_jacobian(
            servo.textbook, servo.textbook_data, q, "main_mirror", [0, 0, 8]
        )
        assert_close(Jv_tb @ qd, Jv @ qd, rel=1e-12, what="point velocity")


def test_turning_telescope_and_wind_together_changes_nothing_in_the_body(servo):
    """Azimuth and wind direction turned by the same angle: the same body-frame loads."""
    from rt70.reference.drives import link_pose

    model, data = servo.reference, servo.reference_data
    names = servo.coordinate_names
    rng = np.random.default_rng(9)
    deformation = 1e-3 * rng.standard_normal(len(names))
    deformation[:6] = 0.0  # the platform's bearing deformation is in ground axes
    for E in (15.0, 45.0, 80.0):
        loads, axes = [], []
        for turn in (0.0, 73.0, -140.0):
            q = deformation + _pointed(servo, E, 20.0 + turn)
            c = WindCondition(18.0, 50.0 + turn)
            body = {}
            for name, w in ref_wind.wind_wrenches(model, data, q, c).items():
                R = link_pose(model, data, q, w.link)[0]
                body[name] = np.concatenate([R.T @ w.force, R.T @ w.torque])
            loads.append(body)
            Q = _both(servo, q, c)[0]
            axes.append(Q[[names.index("base_rx"), names.index("platform_rz")]])
        for other in loads[1:]:
            for name in loads[0]:
                assert_close(other[name], loads[0][name], rel=1e-12, what=name)
        axes = np.array(axes)
        assert_close(axes[1:], np.broadcast_to(axes[0], axes[1:].shape), rel=1e-12)


# --- the RT-70 data --------------------------------------------------------------------


def test_rt70_servo_wind_elements_are_the_derived_ones(servo):
    winds = {w.name: w for w in servo.description.winds}
    assert list(winds) == ["main_mirror", "counterreflector", "rigel", "mirror_base"]
    for e in wind_elements():
        w = winds[e["name"]]
        assert (w.link, w.shape, w.area, w.length) == (
            e["link"],
            e["shape"],
            e["area"],
            e["length"],
        )
        assert w.xyz.tolist() == list(e["xyz"]) and w.axis.tolist() == list(e["axis"])
    assert_close(winds["main_mirror"].area, 3848.45, rel=3e-6)  # π 35², to its 2 decimals
    assert winds["counterreflector"].axis.tolist() == [0.0, 0.0, -1.0]
    bodies = {b["name"]: b for b in rt70_data.SERVO_BODIES}
    assert_close(thin_disc_radius(2300.0, 4995.0), 2.084, rel=5e-4)  # ±1 in its last digit
    assert bodies["counterreflector"]["moments"][2] == 4995.0
    L, d = solid_cylinder(2.0e4, 2.7e6, 0.25e6)
    assert_close(d, 10.0, rel=1e-14)
    assert_close(L, math.sqrt(1620.0 - 75.0), rel=1e-14)
    # the moments the cylinders come from are the scene's (erratum 11), not the printed
    assert bodies["mirror_base"]["moments"] == (0.6906e7, 0.6906e7, 0.2141e6)
    assert_close(winds["mirror_base"].length, 17.887, rel=6e-5)  # ±1 in its last digit
    assert servo.description.air_density == DEFAULT_AIR_DENSITY
    assert not load_scene("rt70").description.winds  # urdf/rt70.urdf left alone


# --- user tables and refusals ----------------------------------------------------------


def test_user_table_relative_to_the_urdf_file(tmp_path, turret):
    (tmp_path / "tables").mkdir()
    (tmp_path / "tables" / "mine.csv").write_text(
        (TABLES / "dish.csv").read_text(encoding="utf-8"), encoding="utf-8"
    )
    path = tmp_path / "turret.urdf"
    path.write_text(
        _turret_text(WINDS.replace('shape="dish"', 'coefficients="tables/mine.csv"')),
        encoding="utf-8",
    )
    scene = load_scene(path)
    assert scene.description.winds[0].shape == "tables/mine.csv"
    q = np.full(scene.textbook.nv, 0.2)
    c = WindCondition(9.0, 130.0)
    assert np.array_equal(_both(scene, q, c)[1], _both(turret, q, c)[1])


GOOD = "theta_deg,axial,normal,moment\n0,1,0,0\n90,0,0.5,0.1\n180,-1,0,0\n"

BAD_TABLES = {
    "header": ("theta,axial,normal,moment\n0,1,0,0\n90,0,0,0\n180,1,0,0\n", "expected the header"),
    "not-numbers": (GOOD.replace("0.5", "x"), "not a row of numbers"),
    "three-columns": (GOOD.replace("90,0,0.5,0.1", "90,0,0.5"), "expected 4 numbers"),
    "nan": (GOOD.replace("0.5", "nan"), "NaN or infinite"),
    "not-monotone": (GOOD.replace("90,", "190,"), "must increase strictly from 0 to 180"),
    "short-range": (GOOD.replace("180,", "170,"), "must increase strictly from 0 to 180"),
    "normal-at-0": (GOOD.replace("0,1,0,0", "0,1,0.01,0"), "normal coefficient must be 0"),
    "moment-at-180": (GOOD.replace("180,-1,0,0", "180,-1,0,1e-9"), "moment coefficient must"),
    "two-rows": ("theta_deg,axial,normal,moment\n0,1,0,0\n180,1,0,0\n", "at least 3 rows"),
    "empty": ("# nothing\n", "no header"),
}


@pytest.mark.parametrize("name", list(BAD_TABLES))
def test_bad_table_is_refused_naming_the_file(name, tmp_path, capsys):
    text, needle = BAD_TABLES[name]
    table = tmp_path / "t.csv"
    table.write_text(text, encoding="utf-8")
    with pytest.raises(WindError, match="t.csv"):
        CoefficientTable.from_csv(table)
    path = tmp_path / "scene.urdf"
    path.write_text(_turret_text(WINDS.replace('shape="dish"', 'coefficients="t.csv"')))
    with pytest.raises(ExtensionError) as excinfo:
        read_urdf_string(path.read_text(), source=str(path))
    message = str(excinfo.value)
    assert message.startswith(f"{path}: <rt70:wind name='dish'>: {table}") and needle in message
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", str(path)]) == 2
    assert capsys.readouterr().err.splitlines() == [f"rt70: error: {message}"]


def test_good_table_is_read():
    table = CoefficientTable.from_text(GOOD, "good")
    assert_close(table.coefficients(math.pi / 2), (0.0, 0.5, 0.1), rel=1e-14)  # a knot


BAD_ELEMENTS = {
    "twice": (WINDS + WINDS.split("\n")[0], "two <rt70:wind> elements named 'dish'"),
    "no-name": (WINDS.replace('name="dish" ', ""), "<rt70:wind> without a name"),
    "unknown-link": (WINDS.replace('"boom"', '"ghost"'), "link 'ghost' does not exist"),
    "no-link": (WINDS.replace('link="boom" ', ""), "lacks attribute 'link'"),
    "zero-axis": (WINDS.replace('axis="0 1 0"', 'axis="0 0 0"'), "zero-length axis"),
    "no-axis": (WINDS.replace(' axis="0 1 0"', ""), "lacks attribute 'axis'"),
    "zero-area": (WINDS.replace('area="2"', 'area="0"'), "area=0 must be positive"),
    "negative-length": (WINDS.replace('length="1.6"', 'length="-1"'), "length=-1 must be"),
    "nan-area": (WINDS.replace('area="2"', 'area="nan"'), "NaN or infinite"),
    "both": (
        WINDS.replace('shape="dish"', 'shape="dish" coefficients="x.csv"'),
        "exactly one of shape=",
    ),
    "neither": (WINDS.replace('shape="dish" ', ""), "exactly one of shape="),
    "unknown-shape": (WINDS.replace('"dish" area', '"sphere" area'), "unknown shape 'sphere'"),
    "missing-file": (
        WINDS.replace('shape="dish"', 'coefficients="nowhere.csv"'),
        "cannot read the coefficient table",
    ),
    "two-airs": (WINDS + '<rt70:air density="1"/><rt70:air density="1"/>', "more than one"),
    "zero-density": (WINDS + '<rt70:air density="0"/>', "must be positive"),
}


@pytest.mark.parametrize("name", list(BAD_ELEMENTS))
def test_bad_wind_element_is_refused_naming_file_and_element(name, tmp_path, capsys):
    extra, needle = BAD_ELEMENTS[name]
    path = tmp_path / f"{name}.urdf"
    path.write_text(_turret_text(extra + "\n"), encoding="utf-8")
    with pytest.raises(UrdfError) as excinfo:  # ExtensionError; NonFiniteError for NaN
        read_urdf_string(path.read_text(), source=str(path))
    message = str(excinfo.value)
    assert message.startswith(f"{path}: ") and needle in message, message
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", str(path)]) == 2
    assert capsys.readouterr().err.splitlines() == [f"rt70: error: {message}"]


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        ((-1.0, 0.0), "non-negative"),
        ((math.nan, 0.0), "finite"),
        ((1.0, math.inf), "finite"),
        ((1.0, 0.0, 0.0), "positive"),
        (("fast", 0.0), "must be a number"),
    ],
)
def test_bad_condition_is_refused(args, needle):
    with pytest.raises(WindError, match=needle):
        WindCondition(*args)


# --- the simulation component ----------------------------------------------------------


def test_wind_load_is_exact_in_the_gust_speed(servo):
    from rt70.wind.load import WindLoad

    q = _pointed(servo, 35.0, 10.0, np.random.default_rng(4), 1e-3)
    mean = WindCondition(10.0, 40.0)
    load = WindLoad(servo, mean, gust=lambda t: 3.0 * math.sin(t))
    # the component's reference path is the compiled one (rt70.reference.element_kernels)
    steady = ref_wind.wind_force_function(servo.reference, servo.reference_data)
    for t in (0.0, 0.7, 2.0):
        speed = 10.0 + 3.0 * math.sin(t)
        want = _both(servo, q, WindCondition(speed, 40.0))[1]
        got = load.force(t, q, None, np.zeros(0))
        assert np.array_equal(got, steady(q, WindCondition(speed, 40.0)))
        assert_close(got, want, rel=1e-13)
        # ½ρ(v̄ + v′)²: not the linearised 2 v̄ v′
        assert_close(want, (speed / 10.0) ** 2 * _both(servo, q, mean)[1], rel=1e-13)
    backwards = WindLoad(servo, mean, gust=lambda t: -15.0, side="textbook")
    want = _both(servo, q, WindCondition(5.0, 220.0))[0]
    assert_close(backwards.force(0.0, q, None, np.zeros(0)), want, rel=1e-14)
    assert backwards.names == () and backwards.initial.shape == (0,)


def test_wind_load_refuses_what_it_cannot_use(servo):
    from rt70.errors import Rt70Error
    from rt70.wind.load import WindLoad

    with pytest.raises(Rt70Error, match="no <rt70:wind> elements"):
        WindLoad(load_scene("two_body_gravity"), WindCondition(1.0, 0.0))
    with pytest.raises(Rt70Error, match="unknown side"):
        WindLoad(servo, WindCondition(1.0, 0.0), side="both")
    with pytest.raises(Rt70Error, match="callable"):
        WindLoad(servo, WindCondition(1.0, 0.0), gust=3.0)
    load = WindLoad(servo, WindCondition(1.0, 0.0), gust=lambda t: math.nan)
    with pytest.raises(Rt70Error, match="not finite"):
        load.force(0.0, np.zeros(servo.textbook.nv), None, np.zeros(0))


def _trapezoid_work(result, force) -> np.ndarray:
    power = np.array(
        [qd @ force(t, q) for t, q, qd in zip(result.t, result.q, result.qd, strict=True)]
    )
    steps = 0.5 * (power[1:] + power[:-1]) * np.diff(result.t)
    return np.concatenate([[0.0], np.cumsum(steps)])


@pytest.mark.slow
def test_simulated_wind_power_is_its_input_work(servo):
    """RT-70 (no drives) in a 20 m/s front wind: W_u = ∫ q̇ᵀQ_w dt and the energy balances."""
    from rt70.simulation.simulate import simulate
    from rt70.wind.load import WindLoad

    condition = WindCondition(20.0, 0.0)
    t = np.linspace(0.0, 0.1, 1001)
    result = simulate(servo, (0.0, 0.1), t_eval=t, components=[WindLoad(servo, condition)])
    assert result.success
    assert_close(result.relative_drift, 0.0, rel=1e-5, scale=1.0)  # a relative drift
    work = _trapezoid_work(result, lambda t, q: _both(servo, q, condition)[1])
    assert abs(result.input_work[-1]) > 1e3  # the wind did work (J)
    assert_close(work, result.input_work, rel=1e-4)


@pytest.mark.slow
def test_gusty_wind_on_the_textbook_side(turret):
    from rt70.simulation.simulate import simulate
    from rt70.wind.load import WindLoad

    mean = WindCondition(15.0, 60.0)
    gust = lambda t: 5.0 * math.sin(7.0 * t)  # noqa: E731
    load = WindLoad(turret, mean, gust=gust, side="textbook")
    t = np.linspace(0.0, 0.5, 1001)
    result = simulate(turret, (0.0, 0.5), side="textbook", t_eval=t, components=[load])
    assert result.success
    assert_close(result.relative_drift, 0.0, rel=1e-5, scale=1.0)  # a relative drift
    work = _trapezoid_work(result, lambda t, q: load.force(t, q, None, np.zeros(0)))
    assert abs(result.input_work[-1]) > 1.0
    assert_close(work, result.input_work, rel=1e-4)
