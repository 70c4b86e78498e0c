"""SUNDIALS CVODE as a method of simulate(): agreement, audit, t_eval, events, errors."""

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import SimulationError
from rt70.model.scene import load_scene
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.closed_chains import assemble
from rt70.simulation.simulate import DRIFT_FACTOR, METHODS, simulate
from rt70.testing import MIN_REL, assert_close

PENDULUM_X0 = (np.array([1.0, -0.5]), np.zeros(2))


def _assert_follows(a, ref, rel):
    """Positions and velocities of run ``a`` within ``rel`` of the reference's size."""
    assert_close(a.q, ref.q, rel=rel, what="q")
    assert_close(a.qd, ref.qd, rel=rel, what="q̇")


@pytest.fixture(scope="module")
def pendulum_reference():
    scene = load_scene("double_pendulum")
    t = np.linspace(0.0, 2.0, 21)
    return simulate(scene, (0.0, 2.0), PENDULUM_X0, method="Radau", rtol=1e-12, t_eval=t)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["CVODE", "CVODE_ADAMS"])
def test_cvode_follows_radau_on_the_double_pendulum(method, pendulum_reference):
    """Against Radau at rtol 1e-12: within DRIFT_FACTOR · rtol (measured ≤ 20 · rtol)."""
    scene, ref = load_scene("double_pendulum"), pendulum_reference
    t = ref.t
    r = simulate(scene, (0.0, 2.0), PENDULUM_X0, method=method, rtol=1e-8, t_eval=t)
    assert r.success and r.method == method
    assert np.array_equal(r.t, t) and r.n_steps == -1
    _assert_follows(r, ref, DRIFT_FACTOR * 1e-8)
    assert r.njev > 0 and r.nfev > r.njev and r.nlu == -1  # Newton with the analytic Jacobian


def test_cvode_follows_radau_on_the_rt70():
    """The RT-70 from the listing's state, 20 ms: CVODE at 1e-7 against Radau at 1e-9."""
    scene = load_scene("rt70")
    x0 = listing_initial_state(scene)
    t = np.linspace(0.0, 0.02, 5)
    ref = simulate(scene, (0.0, 0.02), x0, method="Radau", rtol=1e-9, t_eval=t)
    r = simulate(scene, (0.0, 0.02), x0, method="CVODE", rtol=1e-7, t_eval=t)
    assert r.success and ref.success
    _assert_follows(r, ref, DRIFT_FACTOR * 1e-7)
    assert not r.drift_flagged


def test_timing_splits_the_wall_time_for_every_family():
    scene = load_scene("two_body_gravity")
    x0 = (np.full(scene.textbook.nv, 0.02), np.zeros(scene.textbook.nv))
    for method in ("BDF", "CVODE", "DOP853"):
        r = simulate(scene, (0.0, 0.2), x0, method=method)
        assert set(r.timing) == {"rhs", "jacobian", "integrator"}
        assert r.timing["rhs"] > 0.0 and min(r.timing.values()) >= 0.0
        # the parts add up to the wall time: (wall − rhs − jacobian) + rhs + jacobian
        assert_close(sum(r.timing.values()), r.wall_time_s, rel=MIN_REL)
        assert (r.timing["jacobian"] > 0.0) == (method != "DOP853")  # analytic Jacobian
    # the textbook side has none: CVODE differences the right-hand side itself
    r = simulate(scene, (0.0, 0.2), x0, side="textbook", method="CVODE")
    assert r.success and r.timing["jacobian"] == 0.0 and r.njev > 0
    assert r.n_steps == len(r.t) - 1 > 0


def test_energy_audit_with_cvode():
    """The audit closes on a damped run; the flag is set exactly when the drift exceeds
    DRIFT_FACTOR · rtol (CVODE's BDF at rtol 1e-10 over 5 s of the double pendulum
    drifts 1.7e-8: flagged, where DOP853 drifts 5e-10)."""
    scene = load_scene("two_body_gravity")
    n = scene.textbook.nv
    r = simulate(scene, (0.0, 2.0), (np.full(n, 0.02), np.zeros(n)), method="CVODE", rtol=1e-9)
    assert r.success and r.dissipated[-1] > 0.1 * r.balance_scale
    assert_close(r.relative_drift, 0.0, rel=1e-6, scale=1.0)  # a relative drift: scale 1
    assert not r.drift_flagged
    pendulum = load_scene("double_pendulum")
    for method, flagged in (("DOP853", False), ("CVODE", True)):
        r = simulate(pendulum, (0.0, 5.0), PENDULUM_X0, method=method, rtol=1e-10)
        assert r.drift_flagged == flagged == (r.relative_drift > DRIFT_FACTOR * 1e-10)


def _shoulder_crossing(t, q, qd):
    return q[0]


_shoulder_crossing.direction = -1.0


@pytest.mark.parametrize("method", ["CVODE", "CVODE_ADAMS", "BDF"])
def test_events_locate_the_pendulum_crossing_zero(method):
    """The shoulder angle's first downward zero crossing against DOP853 at rtol 1e-12;
    a terminal event stops the run there."""
    scene = load_scene("double_pendulum")
    kw = dict(events=[_shoulder_crossing])
    ref = simulate(scene, (0.0, 3.0), PENDULUM_X0, method="DOP853", rtol=1e-12, **kw)
    r = simulate(scene, (0.0, 3.0), PENDULUM_X0, method=method, rtol=1e-9, **kw)
    assert len(ref.t_events) == len(r.t_events) == 1
    assert ref.t_events[0].size >= 1 and r.t_events[0].size == ref.t_events[0].size
    assert_close(r.t_events[0], ref.t_events[0], rel=1e-6)  # measured ≤ 7e-10 of 0.586 s

    def stop(t, q, qd):
        return q[0]

    stop.terminal, stop.direction = True, -1
    r = simulate(scene, (0.0, 3.0), PENDULUM_X0, method=method, rtol=1e-9, events=[stop])
    assert_close(r.t[-1], ref.t_events[0][0], rel=1e-6) and r.t_events[0].size == 1


def test_exception_in_the_right_hand_side_stops_cvode_with_the_time():
    scene = load_scene("double_pendulum")

    def inputs(t, q, qd):
        return np.full(2, np.nan if t > 0.01 else 0.0)

    with pytest.raises(SimulationError, match=r"integration stopped at t = 0\.01"):
        simulate(scene, (0, 0.1), inputs=inputs, method="CVODE")


def test_closed_chain_runs_with_cvode():
    scene = load_scene("crank_slider")
    x0 = assemble(scene, np.zeros(3), np.array([10.0, 0.0, 0.0]), keep=["crank_joint"])
    t = np.linspace(0.0, 0.2, 5)
    kw = dict(side="reference", t_eval=t)
    ref = simulate(scene, (0.0, 0.2), x0, method="DOP853", rtol=1e-10, atol=1e-12, **kw)
    r = simulate(scene, (0.0, 0.2), x0, method="CVODE", rtol=1e-8, atol=1e-10, **kw)
    assert r.success and r.timing["jacobian"] == 0.0  # constrained: difference quotients
    # |Φ| in m, on the loop's reach: crank and rod, 0.5 m (measured 1.2e-9 m)
    d = scene.description
    reach = sum(np.linalg.norm(j.xyz) for j in d.joints) + sum(
        np.linalg.norm(loop.frame1.xyz) + np.linalg.norm(loop.frame2.xyz) for loop in d.loops
    )
    residual = r.constraint_residual
    assert_close(residual, np.zeros_like(residual), rel=2e-8, scale=reach)
    assert_close(r.q, ref.q, rel=DRIFT_FACTOR * 1e-8)


def test_command_line_accepts_cvode(capsys):
    assert {"CVODE", "CVODE_ADAMS"} <= set(METHODS)
    assert main(["simulate", "double_pendulum", "--t-end", "0.1", "--method", "CVODE"]) == 0
    assert "CVODE" in capsys.readouterr().out


def test_each_integrator_family_is_imported_only_when_used():
    """scipy.integrate (~0.35 s) only on the solve_ivp path, sksundae (~0.45 s) only on
    CVODE's."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from rt70.model.scene import load_scene\n"
        "from rt70.simulation.simulate import simulate\n"
        "loaded = lambda: ['scipy.integrate' in sys.modules, 'sksundae' in sys.modules]\n"
        "print(loaded())\n"
        "simulate(load_scene('double_pendulum'), (0, 0.01), method='CVODE')\n"
        "print(loaded())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split("\n")[:2] == ["[False, False]", "[False, True]"]
