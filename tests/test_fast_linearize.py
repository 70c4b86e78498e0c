"""The fast linearisation path (stiffness differenced on the reference side, damping in one
pass) gives the plant of the textbook path (rt70.linear.linearize, side="textbook")."""

from __future__ import annotations

import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.linear import plant as pl
from rt70.model.scene import load_scene
from rt70.scenes.rt70_state import rt70_pointing
from rt70.testing import assert_close
from rt70.textbook import forces


@pytest.fixture(scope="module")
def servo():
    scene = load_scene("rt70_servo")
    held = rt70_pointing(45.0, 0.0)
    return scene, held, lin.equilibrium(scene, held, side="textbook")


def test_equilibrium_is_the_textbook_one(servo):
    """Newton's direction changes, the textbook residual does not: the same q0."""
    scene, held, q0 = servo
    q_fast = lin.equilibrium(scene, held)
    assert_close(q_fast, q0, rel=1e-12)  # measured 7.1e-15 rad or m (max|q0| = 0.79)


@pytest.mark.parametrize("locked", [(), ("platform_rz", "base_rx")])
def test_linearization_matches_the_textbook_path(servo, locked):
    """K to 1e-9 of max|K| (measured 1.9e-11; the central differences' rounding is
    ~1e-10), K_gravity likewise (measured 6.3e-11), M and D identical."""
    scene, _, q0 = servo
    slow = lin.linearize(scene, q0, locked=locked, side="textbook")
    fast = lin.linearize(scene, q0, locked=locked)
    assert fast.coordinates == slow.coordinates
    np.testing.assert_array_equal(fast.M, slow.M)  # one code, one q0: the same numbers
    for name in ("K", "K_gravity"):
        assert_close(getattr(fast, name), getattr(slow, name), rel=1e-9, what=name)
    assert_close(fast.D, slow.D, rel=1e-14)


def test_damping_matrix_equals_its_columns(servo):
    """One pass of the element Jacobians = the columns −Q_d(q, e_i), one force each."""
    scene, _, q0 = servo
    model, data = scene.textbook, scene.textbook_data
    columns = np.column_stack(
        [-forces.spring_damper_force(model, data, q0, e)[1] for e in np.eye(model.nv)]
    )
    D = lin.damping_matrix(scene, q0)
    assert_close(D, 0.5 * (columns + columns.T), rel=1e-14, scale=np.abs(columns).max())


def test_plant_is_unchanged(servo, monkeypatch):
    """The plant's A matrix through the fast path equals the textbook path's to 1e-8."""
    scene, held, q0 = servo
    inputs = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
    outputs = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
    fast = pl.plant(scene, q0, inputs, outputs)
    textbook_linearize = lin.linearize
    monkeypatch.setattr(
        lin, "linearize", lambda *a, **k: textbook_linearize(*a, **k, side="textbook")
    )
    slow = pl.plant(scene, q0, inputs, outputs)
    for name in ("A", "B", "C", "D"):
        assert_close(getattr(fast, name), getattr(slow, name), rel=1e-8, what=name)


def test_unknown_side_is_refused(servo):
    scene, held, q0 = servo
    with pytest.raises(Rt70Error, match="'pinocchio' is now 'reference'"):
        lin.stiffness_matrix(scene, q0, side="pinocchio")
    with pytest.raises(Rt70Error, match="unknown side"):
        lin.equilibrium(scene, held, side="")
