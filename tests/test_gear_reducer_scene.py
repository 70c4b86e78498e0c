"""The §1.4 non-rigid gear reducer (Example 1a) as a URDF scene, against its Lagrange form."""

from __future__ import annotations

import numpy as np
import pytest

from rt70.bondgraph.lagrange import reducer_lagrange
from rt70.bondgraph.parameters import GearReducerParameters
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.scene import load_scene
from rt70.scenes import mechanisms
from rt70.testing import assert_close


@pytest.fixture(scope="module")
def both():
    d = mechanisms.GEAR_REDUCER
    p = GearReducerParameters(
        inertia=d["inertia"],
        stiffness=d["stiffness"],
        damping=d["damping"],
        radii=d["radii"],
        load_inertia=d["load_inertia"],
    )
    lagrange = reducer_lagrange(p)  # the motor angle held at zero: its input unused
    scene = load_scene("gear_reducer")
    lm = lin.linearize(scene, np.zeros(scene.textbook.nv))
    order = [lm.coordinates.index(name) for name in lagrange.coordinates]
    return lagrange, lm, np.ix_(order, order)


@pytest.mark.parametrize("matrix", ["M", "K", "D"])
def test_scene_equals_the_lagrange_form(both, matrix):
    """M, K (the shafts' and meshes' springs, on both sides' bushings) and D, to 1e-9."""
    lagrange, lm, order = both
    expected = getattr(lagrange, matrix)
    got = getattr(lm, matrix)[order]
    assert_close(got, expected, rel=1e-9)


def test_spectrum_and_the_ideal_ratio(both):
    """The same eigenfrequencies; with rigid shafts and meshes the load follows the motor
    through the overall ratio R1 R3 / (R2 R4) = 15 (the book's rigid limit)."""
    lagrange, lm, _ = both
    f_scene = modal.modes(lm.M, lm.K).freq_hz
    f_lagrange = modal.modes(lagrange.M, lagrange.K).freq_hz
    assert_close(f_scene, f_lagrange, rel=1e-9)
    # statics of the free load: turning the motor by 1 rad turns it by 1/15 rad whatever
    # the stiffnesses (here 10⁶ times larger) — the book's rigid limit, the ideal ratio
    d = mechanisms.GEAR_REDUCER
    R1, R2, R3, R4 = d["radii"]
    p = GearReducerParameters(
        inertia=d["inertia"],
        stiffness=tuple(1e6 * c for c in d["stiffness"]),
        damping=d["damping"],
        radii=d["radii"],
        load_inertia=d["load_inertia"],
    )
    stiff = reducer_lagrange(p)
    beta = np.linalg.solve(stiff.K, stiff.B[:, 0])  # static response to β_motor = 1
    out = beta[stiff.coordinates.index("beta_out")]
    assert_close(abs(out), R2 * R4 / (R1 * R3), rel=1e-9)
