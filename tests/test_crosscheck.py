"""The textbook algorithm agrees with Pinocchio on every scene."""

import json

import numpy as np
import pytest

from rt70 import reference
from rt70.cli.main import main
from rt70.crosscheck import validate
from rt70.crosscheck.compiled_check import ROWS as COMPILED_ROWS
from rt70.crosscheck.validate import QUANTITIES, cross_check, quantities
from rt70.model.scene import URDF_DIR, load_scene, scene_names
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import dynamics, forces

TOL = 1e-10


def test_every_scene_is_covered():
    assert {
        "rt70",
        "rt70_azimuth",
        "rt70_elevation",
        "double_pendulum",
        "three_masses",
        "two_body_gravity",
    } <= set(scene_names())


@pytest.mark.slow
@pytest.mark.parametrize("name", scene_names())
def test_scene_agrees_with_pinocchio(name):
    scene = load_scene(name)
    records = cross_check(scene, samples=5, seed=123, repeat=1)
    assert [r.quantity for r in records] == list(quantities(scene))
    # the wind row exactly where the scene has <rt70:wind>s: RT-70 control objects, antennas
    assert ("wind" in quantities(scene)) == bool(scene.description.winds)
    assert bool(scene.description.winds) == (
        name
        in (
            "rt70_servo",
            "rt70_flexible",
            "rt70_mirror",
            "antenna_12m",
            "antenna_12m_dish",
            "antenna_34m",
        )
    )
    for r in records:
        assert r.max_rel_err <= TOL, f"{name} {r.quantity}: {r.max_rel_err:.3g}"


def test_double_pendulum_reference_values():
    """Companion sources, test mechanism 1: q = (0.3, −0.5), q̇ = (1, 2), gravity −y."""
    scene = load_scene("double_pendulum")
    tm, td = scene.textbook, scene.textbook_data
    q, qd = np.array([0.3, -0.5]), np.array([1.0, 2.0])
    A = dynamics.mass_matrix(tm, td, q)
    # to the printed digits (eight decimals; six for 18.865003)
    assert_close(A, [[2.54424923, 0.77212461], [0.77212461, 0.33333333]], rel=1e-8)
    assert_close(dynamics.bias_force(tm, td, q, qd), [1.91770215, -0.23971277], rel=1e-8)
    # the companion source prints g(q) on the left-hand side; Q_g = −g(q)
    assert_close(-dynamics.gravity_force(tm, td, q), [18.865003, 4.80722656], rel=1e-7)
    # closed forms of the same source
    l1, lc, m, inertia = 1.0, 0.5, 1.0, 1.0 / 12.0
    c2 = np.cos(q[1])
    A00 = 2 * inertia + m * lc**2 + m * (l1**2 + lc**2 + 2 * l1 * lc * c2)
    assert_close(A[0, 0], A00, rel=1e-14)
    assert_close(A[0, 1], inertia + m * (lc**2 + l1 * lc * c2), rel=1e-14)
    assert_close(A[1, 1], inertia + m * lc**2, rel=1e-14)


def test_rt70_mass_matrix_spd_and_equal_to_crba():
    scene = load_scene("rt70")
    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    assert tm.nv == 42 and tm.nb == 7 and set(tm.kind) == {"euler6"}
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = rng.uniform(-0.5, 0.5, tm.nv)
        A = dynamics.mass_matrix(tm, td, q)
        assert_close(A, A.T, rel=MIN_REL, what="symmetry")
        assert np.linalg.eigvalsh(A).min() > 0.0
        A_ref = reference.mass_matrix(ref, rd, q)
        assert_close(A, A_ref, rel=TOL)


@pytest.mark.parametrize("name", ["rt70", "two_body_gravity", "double_pendulum"])
def test_energies_match_pinocchio(name):
    scene = load_scene(name)
    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    rng = np.random.default_rng(9)
    q, qd = rng.uniform(-0.5, 0.5, tm.nv), rng.uniform(-1, 1, tm.nv)
    T = dynamics.kinetic_energy(tm, td, q, qd)
    assert T > 0.0
    assert_close(T, reference.kinetic_energy(ref, rd, q, qd), rel=1e-12)
    # U_g sums the weights' moments m g·c, which cancel: their size is G₀ = Σ m |g| |c|
    Ug = dynamics.gravity_potential(tm, td, q)
    G0 = reference.weight_moment(ref, rd, q)
    assert_close(Ug, reference.gravity_potential(ref, rd, q), rel=1e-12, scale=G0)
    Us = forces.spring_potential(tm, td, q)  # a sum of positive terms (0 without springs)
    assert_close(Us, reference.spring_potential(ref, rd, q), rel=1e-12)


def test_power_balance_of_equations_of_motion():
    """d/dt (T + U) = q̇ᵀ Q_d along q̈ from the textbook equations (energy audit, (1.73))."""
    scene = load_scene("two_body_gravity")
    tm, td = scene.textbook, scene.textbook_data
    rng = np.random.default_rng(2)
    q, qd = rng.uniform(-0.3, 0.3, tm.nv), rng.uniform(-1, 1, tm.nv)

    def energy(q, qd):
        return (
            dynamics.kinetic_energy(tm, td, q, qd)
            + dynamics.gravity_potential(tm, td, q)
            + forces.spring_potential(tm, td, q)
        )

    Qc, Qd = forces.spring_damper_force(tm, td, q, qd)
    qdd = dynamics.forward_dynamics(tm, td, q, qd, Qc + Qd)
    h = 1e-6
    dE = (energy(q + h * qd, qd + h * qdd) - energy(q - h * qd, qd - h * qdd)) / (2 * h)
    assert_close(dE, qd @ Qd, rel=1e-6)


@pytest.mark.slow
def test_cli_validate_all_scenes_exit_0(capsys):
    assert main(["validate", "--samples", "2"]) == 0
    out = capsys.readouterr().out
    for name in scene_names():
        assert name in out


def test_cli_validate_json(capsys):
    assert main(["validate", "--json", "--samples", "2", str(URDF_DIR / "rt70.urdf")]) == 0
    records = json.loads(capsys.readouterr().out)
    assert [r["quantity"] for r in records] == list(QUANTITIES + COMPILED_ROWS)
    keys = {
        "target",
        "nv",
        "quantity",
        "max_abs_err",
        "max_rel_err",
        "t_textbook_s",
        "t_reference_s",
        "nonfinite",
        "unit",
    }
    for r in records:
        assert set(r) == keys
        assert r["unit"] == validate.QUANTITY_UNITS[r["quantity"]]
        assert r["nonfinite"] == ""
        assert r["target"] == "rt70" and r["nv"] == 42
        assert r["max_rel_err"] <= TOL


def test_every_row_states_its_unit():
    """Each row any scene can give (the loop and nonholonomic rows too) has a unit."""
    from rt70.crosscheck.loop_check import LOOP_QUANTITIES
    from rt70.crosscheck.samples import WIND
    from rt70.mechanics.nonholonomic_scene import ROWS

    rows = {*QUANTITIES, WIND, *LOOP_QUANTITIES, *ROWS, *COMPILED_ROWS}
    assert set(validate.QUANTITY_UNITS) == rows


def test_cli_validate_reports_disagreement(capsys):
    """A tolerance no floating-point computation can meet makes the check fail (exit 1)."""
    assert main(["validate", "--samples", "1", "--tolerance", "0", "rt70"]) == 1
