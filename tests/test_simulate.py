"""Time simulation: the two sides agree, energy audit, outputs, bad input."""

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.model.scene import load_scene
from rt70.scenes.rt70_state import listing_initial_state, start_state
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close


def test_backends_agree_on_trajectories():
    scene = load_scene("two_body_gravity")
    n = scene.textbook.nv
    rng = np.random.default_rng(0)
    x0 = (rng.uniform(-0.05, 0.05, n), rng.uniform(-0.1, 0.1, n))
    t = np.linspace(0.0, 0.5, 51)
    runs = {
        s: simulate(scene, (0.0, 0.5), x0, side=s, method="DOP853", rtol=1e-10, t_eval=t)
        for s in ("reference", "textbook")
    }
    a, b = runs["reference"], runs["textbook"]
    assert a.success and b.success
    scale = np.abs(a.q).max() + np.abs(a.qd).max()  # the state's size
    assert_close(b.q, a.q, rel=1e-8, scale=scale)
    assert_close(b.qd, a.qd, rel=1e-8, scale=scale)


@pytest.mark.slow
def test_rt70_backends_agree_from_the_listing_state():
    scene = load_scene("rt70")
    t = np.linspace(0.0, 0.05, 11)
    x0 = listing_initial_state(scene)
    a = simulate(scene, (0.0, 0.05), x0, side="reference", method="BDF", rtol=1e-8, t_eval=t)
    b = simulate(scene, (0.0, 0.05), x0, side="textbook", method="BDF", rtol=1e-8, t_eval=t)
    assert a.success and b.success
    assert_close(b.q, a.q, rel=1e-6)


def test_energy_balance_of_a_conservative_model():
    """Double pendulum (no springs, no dampers): T + U_g constant to the tolerance."""
    scene = load_scene("double_pendulum")
    r = simulate(
        scene, (0.0, 5.0), (np.array([1.0, -0.5]), np.zeros(2)), method="DOP853", rtol=1e-10
    )
    assert r.success and np.all(r.dissipated == 0.0)  # no damper: a sum of no terms
    assert_close(r.relative_drift, 0.0, rel=1e-8, scale=1.0)  # a relative drift: scale 1
    assert not r.drift_flagged


@pytest.mark.slow
def test_energy_balance_of_a_damped_model_closes_with_dissipation():
    scene = load_scene("two_body_gravity")
    n = scene.textbook.nv
    x0 = (np.full(n, 0.02), np.zeros(n))
    r = simulate(scene, (0.0, 2.0), x0, method="Radau", rtol=1e-9)
    assert r.success
    assert r.dissipated[-1] > 0.1 * r.balance_scale  # the damper took a real share
    decrease = np.maximum(-np.diff(r.dissipated), 0.0)  # E_ψ never decreases
    assert_close(decrease, np.zeros_like(decrease), rel=1e-9, scale=r.balance_scale)
    assert_close(r.relative_drift, 0.0, rel=1e-6, scale=1.0)
    assert not r.drift_flagged


def test_input_work_enters_the_balance():
    scene = load_scene("double_pendulum")

    def torque(t, q, qd):
        return np.array([np.sin(3.0 * t), 0.0])

    r = simulate(
        scene, (0.0, 2.0), (np.zeros(2), np.zeros(2)), method="DOP853", rtol=1e-10, inputs=torque
    )
    assert abs(r.input_work[-1]) > 0
    assert_close(r.relative_drift, 0.0, rel=1e-8, scale=1.0)


def test_listing_initial_state_is_the_command_lines_start_for_the_rt70(capsys):
    """simulate() starts at rest unless told; ``rt70 simulate`` gives the RT-70 the listing's."""
    scene = load_scene("rt70")
    q0, qd0 = listing_initial_state(scene)
    i = scene.textbook.coordinate_names.index("platform_rz")
    assert q0[i] == 0.8 and qd0[i] == 0.003
    start = start_state(scene)
    assert start is not None and np.array_equal(start[0], q0) and np.array_equal(start[1], qd0)
    assert start_state(load_scene("double_pendulum")) is None
    with pytest.raises(Rt70Error, match="for the rt70 scene"):
        listing_initial_state(load_scene("double_pendulum"))
    r = simulate(scene, (0.0, 0.01), method="BDF")
    assert not r.q[0].any() and not r.qd[0].any()
    assert main(["simulate", "rt70", "--t-end", "0.01"]) == 0
    # the listing's state: 10898.2 J of kinetic energy (at rest it would be 0)
    assert "T0 = 10898.2 J" in capsys.readouterr().out


def test_cli_simulate_writes_outputs_atomically(tmp_path, capsys):
    out = tmp_path / "run.csv"
    assert main(["simulate", "two_body_gravity", "--t-end", "0.2", "--out", str(out)]) == 0
    text = out.read_text()
    header = text.splitlines()[0].split(",")
    assert header[0] == "t" and "balance" in header and len(header) == 1 + 2 * 12 + 6
    assert (tmp_path / "run.png").stat().st_size > 10_000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files left
    assert "balance drift" in capsys.readouterr().out
    npz = tmp_path / "run.npz"
    assert (
        main(["simulate", "two_body_gravity", "--t-end", "0.1", "--out", str(npz), "--no-plot"])
        == 0
    )
    assert set(np.load(npz).files) >= {"t", "q", "qd", "balance", "dissipated"}


def test_bad_simulation_input():
    scene = load_scene("double_pendulum")
    with pytest.raises(Rt70Error, match="unknown method"):
        simulate(scene, (0, 1), method="Euler")
    with pytest.raises(Rt70Error, match="time span"):
        simulate(scene, (1, 0))
    with pytest.raises(Rt70Error, match="initial state"):
        simulate(scene, (0, 1), (np.array([np.nan, 0.0]), np.zeros(2)))
    assert main(["simulate", "double_pendulum", "--out", "/tmp/x.txt", "--t-end", "0.01"]) == 2


def test_rhs_jacobian_for_implicit_methods_is_checked():
    """The Pinocchio backend's Jacobian (computeABADerivatives + ΣJᵀCJ, ΣJᵀDJ) against
    central differences of the textbook right-hand side (scipy's alternative)."""
    from rt70.simulation.backends import BACKENDS

    scene = load_scene("two_body_gravity")
    n = scene.textbook.nv
    analytic = BACKENDS["reference"](scene)
    textbook = BACKENDS["textbook"](scene)

    def rhs(x):
        return np.r_[x[n:], textbook.accelerations(x[:n], x[n:], None)[0]]

    def fd_jacobian(x, h=1e-6):
        return np.column_stack([(rhs(x + h * e) - rhs(x - h * e)) / (2 * h) for e in np.eye(2 * n)])

    # at rest the springs' ∂J/∂q terms vanish (δ = 0, q̇ = 0): the Jacobian is exact
    x = np.zeros(2 * n)
    J = analytic.jacobian(x[:n], x[n:], None)
    assert_close(fd_jacobian(x), J, rel=1e-8)
    # away from rest it omits the (∂J/∂q)ᵀCδ terms (Gauss–Newton): small for small δ
    rng = np.random.default_rng(4)
    x = np.r_[rng.uniform(-0.02, 0.02, n), rng.uniform(-0.1, 0.1, n)]
    J = analytic.jacobian(x[:n], x[n:], None)
    assert_close(fd_jacobian(x), J, rel=1e-6)  # measured 5e-10
