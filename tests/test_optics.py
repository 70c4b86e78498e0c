"""Outputs of the mirror system (book 4.1.8, :mod:`rt70.model.optics`): both sides, hand cases, C.

Each output is a formula of point positions that each side computes by its own
kinematics; the sides must agree to 1e-10. Hand-made cases check the readings: the
undeformed telescope has no error; turning the whole dish by a known small angle asks
for the opposite pointing correction; moving the counterreflector by a known distance
shows as that focal offset and asks for the opposite translation; tilting it asks for
the opposite turn. The linear rows C (exact point Jacobians, complex step through the
formula) match finite differences of the nonlinear outputs.
"""

from __future__ import annotations

import numpy as np
import pytest

from rt70.errors import Rt70Error, SingularConfigurationError
from rt70.linear.linearize import equilibrium
from rt70.model import optics, outputs
from rt70.model.scene import load_scene
from rt70.model.sides import SIDES
from rt70.scenes import rt70_optics, rt70_state
from rt70.simulation.simulate import simulate
from rt70.testing import MIN_REL, assert_close
from rt70.units import ARCSEC_PER_RAD, MM_PER_M

#: The scale of the quantities each output is formed from (unit vectors, positions of
#: order metres): 1 in its unit, 1 rad in arcsec, 1 m in mm.
NATURAL = {"1": 1.0, "arcsec": ARCSEC_PER_RAD, "mm": MM_PER_M}
#: An output known exactly (zero by geometry, or a known small angle) holds to this
#: fraction of its natural scale: the rounding of unit vectors and of positions some tens
#: of metres from the origin (up to 140 ulps measured).
ROUNDING_REL = 1e-12


def assert_zero(values, unit: str, what: str = "") -> None:
    """An output that the geometry makes zero: zero on its :data:`NATURAL` scale."""
    values = np.atleast_1d(values)
    assert_close(values, np.zeros_like(values), rel=ROUNDING_REL, scale=NATURAL[unit], what=what)


def assert_angle(actual, expected, what: str = "") -> None:
    """A misalignment (arcsec) of known size: formed from unit vectors, so it rounds on
    the scale of 1 rad, not of its own (small) value."""
    assert_close(actual, expected, rel=ROUNDING_REL, scale=ARCSEC_PER_RAD, what=what)


@pytest.fixture(scope="module")
def rt70():
    return load_scene("rt70")


def _q(scene, values: dict[str, float], base: np.ndarray | None = None) -> np.ndarray:
    names = scene.textbook.coordinate_names
    q = np.zeros(len(names)) if base is None else base.copy()
    for name, value in values.items():
        q[names.index(name)] += value
    return q


def _pointing(scene, elevation, azimuth, **extra):
    """The rigid pointing's coordinates, plus ``extra`` added to them."""
    return _q(scene, extra, _q(scene, rt70_state.rt70_pointing(elevation, azimuth)))


def _both(scene, q, outs):
    return outputs.evaluate(scene, q, outs, "textbook"), outputs.evaluate(
        scene, q, outs, "reference"
    )


@pytest.fixture(scope="module")
def states(rt70):
    """Listing state, two pointing equilibria, and a generic deformed pointing."""
    q_list, _ = rt70_state.listing_initial_state(rt70)
    names = rt70.textbook.coordinate_names
    listing = (
        90.0 - np.degrees(q_list[names.index("base_rx")]),
        np.degrees(q_list[names.index("platform_rz")]),
        q_list,
    )
    out = {"listing": listing}
    for e, a in ((30.0, 20.0), (75.0, -40.0)):
        out[f"equilibrium E{e:g} A{a:g}"] = (
            e,
            a,
            equilibrium(rt70, rt70_state.rt70_pointing(e, a)),
        )
    generic = _pointing(rt70, 50.0, 120.0) + np.random.default_rng(8).uniform(-2e-3, 2e-3, 42)
    out["generic"] = (50.0, 120.0, generic)
    return out


def test_sides_agree(rt70, states):
    """≤ 1e-10 relative to max(|value|, the scale it is formed from); ≤ 1e-10 relative to
    |value| itself where no output is zero by symmetry (the generic state)."""
    for label, (e, a, q) in states.items():
        outs = rt70_optics.rt70_mirror_outputs(rt70, e, a)
        tb, ref = _both(rt70, q, outs)
        for o in outs:
            size = float(np.max(np.abs(ref[o.name])))
            scale = max(size, NATURAL[o.unit])
            assert_close(tb[o.name], ref[o.name], rel=1e-10, scale=scale, what=f"{label} {o.name}")
            if label == "generic":
                assert size > 1e-3 * NATURAL[o.unit] * 1e-3, o.name  # not zero here
                assert_close(tb[o.name], ref[o.name], rel=1e-10, what=f"{label} {o.name}")


def test_listing_state_outputs_are_what_the_geometry_says(rt70, states):
    """The listing turns every mirror pair alike, so the two axes stay parallel."""
    e, a, q = states["listing"]
    values = outputs.evaluate(rt70, q, rt70_optics.rt70_mirror_outputs(rt70, e, a))
    assert_zero(values["counterreflector_misalignment"], "arcsec")
    assert values["main_mirror_misalignment"][0] > 100.0  # the listing's elastic turns
    assert_angle(
        values["counterreflector_source_misalignment"][0], values["main_mirror_misalignment"][0]
    )
    assert_close(np.linalg.norm(values["main_mirror_axis"]), 1.0, rel=1e-13)


def test_construction_is_the_design(rt70):
    """q = 0: axes along OK z, no misalignment, foci at their design offset, no correction;
    the pointing correction is undefined there (zenith: the azimuth axis is the source)."""
    system = rt70_optics.rt70_mirror_system(rt70)
    outs = optics.mirror_outputs(system, [0.0, 0.0, 1.0])
    without = [o for o in outs if o.name != "pointing_correction"]
    for side in SIDES:
        v = outputs.evaluate(rt70, np.zeros(42), without, side)
        assert_close(v["main_mirror_axis"], [0.0, 0.0, 1.0], rel=MIN_REL)
        assert_close(v["counterreflector_axis"], [0.0, 0.0, 1.0], rel=MIN_REL)
        for o in without[2:]:
            assert_zero(v[o.name], o.unit, o.name)
    with pytest.raises(SingularConfigurationError, match="zenith keyhole"):
        outputs.evaluate(rt70, np.zeros(42), outs)
    assert_close(rt70_optics.DESIGN_FOCAL_OFFSET, (0.0, 0.0, 1.2), rel=1e-12)


@pytest.mark.parametrize(("elevation", "azimuth"), [(40.0, 30.0), (10.0, -100.0), (89.0, 0.0)])
def test_rigid_pointing_has_no_error(rt70, elevation, azimuth):
    outs = rt70_optics.rt70_mirror_outputs(rt70, elevation, azimuth)
    v = outputs.evaluate(rt70, _pointing(rt70, elevation, azimuth), outs, "reference")
    for o in outs[2:]:
        assert_zero(v[o.name], o.unit, o.name)  # rounding only


@pytest.mark.parametrize("coordinate", ["platform_rz", "base_rx"])
def test_turning_the_dish_asks_for_the_opposite_correction(rt70, coordinate):
    """A rigid turn δ about the azimuth (elevation) axis → Δα = −δ (Δβ = −δ), to first
    order: the error is within δ² (δ = 10″ and 1″)."""
    elevation, azimuth = 35.0, 60.0
    outs = rt70_optics.rt70_mirror_outputs(rt70, elevation, azimuth)
    k = 0 if coordinate == "platform_rz" else 1
    for delta_arcsec in (10.0, 1.0):
        q = _pointing(rt70, elevation, azimuth, **{coordinate: delta_arcsec / ARCSEC_PER_RAD})
        v = outputs.evaluate(rt70, q, outs, "textbook")
        expected = np.zeros(2)
        expected[k] = -delta_arcsec
        # within the second-order bound δ² (in rad, shown in arcsec), at both sizes
        second_order = (delta_arcsec / ARCSEC_PER_RAD) ** 2 * ARCSEC_PER_RAD
        assert_close(v["pointing_correction"], expected, rel=1.0, scale=second_order)
        if coordinate == "base_rx":  # a turn in the source's vertical plane: the angle itself
            assert_angle(v["main_mirror_misalignment"][0], delta_arcsec)
            assert_angle(v["counterreflector_source_misalignment"][0], delta_arcsec)
        assert_zero(v["counterreflector_misalignment"], "arcsec")  # the dish turned as a whole


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_moving_the_counterreflector_shows_as_focal_offset(rt70, axis):
    """A pure translation of 1 mm along a rigel axis: offset +1 mm, translation −1 mm."""
    coordinate = ("counterreflector_x", "counterreflector_y", "counterreflector_z")[axis]
    outs = rt70_optics.rt70_mirror_outputs(rt70, 50.0, 10.0)
    q = _pointing(rt70, 50.0, 10.0, **{coordinate: 1e-3})
    tb, ref = _both(rt70, q, outs)
    expected = np.zeros(3)
    expected[axis] = 1.0
    for v in (tb, ref):
        assert_close(v["focal_offset"], expected, rel=1e-9)  # on the 1 mm move
        assert_close(v["counterreflector_translation"], -expected, rel=1e-9)
        assert_zero(v["counterreflector_rotation"], "arcsec")
        assert_zero(v["counterreflector_misalignment"], "arcsec")


@pytest.mark.parametrize(
    ("coordinate", "k"), [("counterreflector_rx", 0), ("counterreflector_ry", 1)]
)
def test_tilting_the_counterreflector_asks_for_the_opposite_turn(rt70, coordinate, k):
    """A tilt δ about its drive's x (y) axis: misalignment δ exactly, Δβ7 (Δθ7) = −δ, and
    no translation to first order (the turn back also brings the focus back)."""
    outs = rt70_optics.rt70_mirror_outputs(rt70, 50.0, 10.0)
    delta = 5.0  # arcsec
    q = _pointing(rt70, 50.0, 10.0, **{coordinate: delta / ARCSEC_PER_RAD})
    v = outputs.evaluate(rt70, q, outs, "reference")
    assert_angle(v["counterreflector_misalignment"][0], delta)
    assert_close(np.linalg.norm(v["counterreflector_error"]), delta, rel=1e-6)
    expected = np.zeros(3)
    expected[k] = -delta
    assert_close(v["counterreflector_rotation"], expected, rel=2e-7)  # on δ
    lever = 1.2e3 * delta / ARCSEC_PER_RAD  # mm the focus moved, 1.2 m from the pivot
    assert_close(abs(v["focal_offset"][1 - k]), lever, rel=1e-6)
    # second order only: the chord of the turn back, lever · δ/2
    translation = v["counterreflector_translation"]
    assert_close(translation, np.zeros(3), rel=1.0, scale=lever * delta / ARCSEC_PER_RAD)


def test_counterreflector_system_is_rank_two(rt70, states):
    """[erratum] (4.172): a turn about the focal axis does not move it; the minimum-norm
    reading gives Δα7 = 0 on the RT-70, where the optical points lie on the CR's z."""
    e, a, q = states["equilibrium E30 A20"]
    v = outputs.evaluate(rt70, q, rt70_optics.rt70_mirror_outputs(rt70, e, a))
    rotation = v["counterreflector_rotation"]
    assert_close(rotation[2], 0.0, rel=1e-9, scale=np.max(np.abs(rotation)))
    assert rotation[0] > 100.0


def _stack(values: dict[str, np.ndarray]) -> np.ndarray:
    return np.concatenate(list(values.values()))


def test_output_matrix_is_the_derivative(rt70, states):
    """C of both sides agree, and match central differences of the nonlinear outputs."""
    e, a, q = states["equilibrium E30 A20"]
    outs = [o for o in rt70_optics.rt70_mirror_outputs(rt70, e, a) if "misalignment" not in o.name]
    C_tb = outputs.output_matrix(rt70, q, outs, "textbook")
    C_ref = outputs.output_matrix(rt70, q, outs, "reference")
    assert C_tb.shape == (sum(o.size for o in outs), 42)
    scale = float(np.max(np.abs(C_ref)))
    assert_close(C_tb, C_ref, rel=1e-10, scale=scale)
    h = 1e-6
    columns = []
    for i in range(42):
        e_i = np.zeros(42)
        e_i[i] = h
        plus = _stack(outputs.evaluate(rt70, q + e_i, outs, "reference"))
        minus = _stack(outputs.evaluate(rt70, q - e_i, outs, "reference"))
        columns.append((plus - minus) / (2 * h))
    fd = np.array(columns).T
    assert_close(C_ref, fd, rel=1e-6, scale=scale)
    # the pointing correction needs the azimuth and elevation coordinates
    names = rt70.textbook.coordinate_names
    row = sum(o.size for o in outs[: [o.name for o in outs].index("pointing_correction")])
    assert_close(C_tb[row, names.index("platform_rz")], -ARCSEC_PER_RAD, rel=1e-3)
    assert_close(C_tb[row + 1, names.index("base_rx")], -ARCSEC_PER_RAD, rel=1e-3)


def test_output_matrix_refuses_what_has_no_derivative(rt70):
    q = _pointing(rt70, 40.0, 0.0)
    outs = rt70_optics.rt70_mirror_outputs(rt70, 40.0, 0.0)
    angle = next(o for o in outs if o.name == "main_mirror_misalignment")
    with pytest.raises(Rt70Error, match="'main_mirror_misalignment' has no derivative"):
        outputs.output_matrix(rt70, q, [angle])  # |s − n5| at 0: a cone, not a plane
    focus = outputs.optical_point_outputs(rt70)[0]
    hidden = outputs.Output("size", "m", 1, focus.points, lambda p: np.linalg.norm(p)[None])
    with pytest.raises(Rt70Error, match="'size' has no derivative"):
        outputs.output_matrix(rt70, q, [hidden])  # norm() drops the complex step: caught
    same = outputs.output_matrix(rt70, q, [focus])  # a position: C is J_v
    assert same.shape == (3, 42)
    assert_close(same[2, rt70.textbook.coordinate_names.index("platform_z")], 1.0, rel=MIN_REL)


def test_outputs_ride_along_a_simulation(rt70, states):
    e, a, _ = states["listing"]
    outs = rt70_optics.rt70_mirror_outputs(rt70, e, a)
    x0 = rt70_state.listing_initial_state(rt70)
    t = np.linspace(0.0, 0.02, 3)
    result = simulate(rt70, (0.0, 0.02), x0, side="textbook", t_eval=t, outputs=outs)
    assert result.outputs["pointing_correction"].shape == (3, 2)
    expected = outputs.evaluate_trajectory(rt70, result.q, outs, "textbook")
    for o in outs:  # the simulation evaluates the outputs by this very function: bit for bit
        assert np.array_equal(result.outputs[o.name], expected[o.name])
    moved = result.outputs["main_mirror_misalignment"][:, 0]
    assert abs(moved[-1] - moved[0]) > 1e-3  # arcsec: the structure vibrates


def test_bad_requests(rt70):
    system = rt70_optics.rt70_mirror_system(rt70)
    with pytest.raises(Rt70Error, match="source direction"):
        optics.mirror_outputs(system, [0.0, 0.0, 0.0])
    with pytest.raises(Rt70Error, match="no <rt70:optical_point> named main_mirror_focus"):
        rt70_optics.rt70_mirror_system(load_scene("double_pendulum"))
    # unit vectors: cos(π/2) rounds to 6e-17, not 0
    assert_close(optics.source_direction(0.0, np.pi / 2), [0.0, 0.0, 1.0], rel=MIN_REL)
    assert_close(rt70_optics.pointing_source(0.0, 90.0), [1.0, 0.0, 0.0], rel=MIN_REL)


@pytest.mark.parametrize("coordinate", ["main_mirror_rx", "mirror_base_rx"])
def test_tilting_the_mirror_or_its_ring(rt70, coordinate):
    """The main mirror tilted by δ on its ring (OK) turns its axis in OK; the ring tilted
    by δ carries the mirror with it, the axis stays put in OK and the source moves. Both
    ask for Δβ = −δ (the bearing's x is the ring's x here) within δ²."""
    outs = rt70_optics.rt70_mirror_outputs(rt70, 60.0, -30.0)
    delta = 20.0  # arcsec
    q = _pointing(rt70, 60.0, -30.0, **{coordinate: delta / ARCSEC_PER_RAD})
    v = outputs.evaluate(rt70, q, outs, "textbook")
    on_ring = coordinate == "main_mirror_rx"
    axis_turned = abs(v["main_mirror_axis"][1]) * ARCSEC_PER_RAD
    assert_close(axis_turned, delta if on_ring else 0.0, rel=5e-8, scale=delta)  # on the tilt
    assert_angle(v["main_mirror_misalignment"][0], delta)
    bound = (delta / ARCSEC_PER_RAD) ** 2 * ARCSEC_PER_RAD
    assert_close(v["pointing_correction"], [0.0, -delta], rel=1.0, scale=bound)
