"""scipy's BDF compiled with the equations (rt70.simulation.compiled_bdf, bdf_kernel) and
the compiled forward dynamics under it (rt70.textbook.forward_kernel).

The forward dynamics against Pinocchio's (the reference backend) on every scene the
kernels cover; its Jacobian against central differences of itself; a run against scipy's
BDF on the same scene, tolerance and start (the same algorithm: the same steps up to the
Jacobian's rounding, and the same accuracy against a tight reference); the samples at
output times against the run's own steps; the energy audit; the refusals and the
evaluation budget. No timing is asserted (``rt70 bench simulate`` measures it).
"""

from __future__ import annotations

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error, SimulationError
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes.rt70_state import start_state
from rt70.scenes.synthetic import elastic_chain, random_tree
from rt70.simulation import compiled_bdf
from rt70.simulation.backends import PinocchioBackend
from rt70.simulation.integrators import EvaluationBudget, evaluation_budget
from rt70.simulation.simulate import simulate
from rt70.testing import assert_close
from rt70.textbook import forward_kernel

METHOD = "compiled-BDF"
#: Every scene of urdf/ the kernels cover (no modal bodies, mimic joints or loops).
COVERED = ("rt70", "rt70_servo", "three_masses", "double_pendulum", "gear_reducer",
           "antenna_12m", "two_body_gravity", "rt70_flexible")  # fmt: skip


def _state(n, seed):
    rng = np.random.default_rng(seed)
    return 1e-2 * rng.standard_normal(n), 1e-1 * rng.standard_normal(n)


def _scene(name):
    """A scene of urdf/ or ``tree<seed>``: a random tree of every joint type, springs and
    bushings (:func:`rt70.scenes.synthetic.random_tree`, six bodies)."""
    if name.startswith("tree"):
        return scene_from_text(random_tree(int(name[4:]), 6), name)
    return load_scene(name)


@pytest.mark.parametrize("name", (*COVERED, "tree1", "tree3", "tree6"))
def test_accelerations_are_pinocchios(name):
    scene = _scene(name)
    model = scene.textbook
    data = forward_kernel.ForwardData.of(model)
    assert data is not None
    backend = PinocchioBackend(scene)
    for seed in (0, 1):
        q, v = _state(model.nv, seed)
        acc, sums = forward_kernel.accelerations(model, data, q, v)
        expected, _ = backend.accelerations(q, v, None)
        # q̈ = A⁻¹ (sum of forces): its scale is the largest term's, gravity or a spring's
        assert_close(acc, expected, rel=1e-9, what=f"{name} q̈")
        T, Ug, Uc = backend.energies(q, v)
        assert_close(sums[:3], [T, Ug, Uc], rel=1e-10, scale=max(abs(T), abs(Ug), abs(Uc)),
                     what=f"{name} energies")  # fmt: skip


@pytest.mark.parametrize("name", ("rt70", "double_pendulum", "gear_reducer", "tree3"))
def test_jacobian_is_the_difference_of_the_accelerations(name):
    scene = _scene(name)
    model = scene.textbook
    data = forward_kernel.ForwardData.of(model)
    q, v = _state(model.nv, 3)
    Jq, Jv = forward_kernel.jacobian(model, data, q, v)
    acc = forward_kernel.accelerations(model, data, q, v)[0]
    for J, which in ((Jq, 0), (Jv, 1)):
        central = np.empty_like(J)
        for j in range(model.nv):
            h = 1e-6
            x = [q.copy(), v.copy()]
            x[which][j] += h
            up = forward_kernel.accelerations(model, data, *x)[0]
            x[which][j] -= 2 * h
            down = forward_kernel.accelerations(model, data, *x)[0]
            central[:, j] = (up - down) / (2 * h)
        # forward differences of step h = √ε·max(|x|, 1): a truncation error of ½ h ∂²q̈/∂x²,
        # the curvature of q̈ over unit changes of the state being of the size of q̈ or of J
        scale = max(np.max(np.abs(central)), np.max(np.abs(acc)))
        assert_close(J, central, rel=1e-5, scale=scale, what=f"{name} ∂q̈/∂{'qv'[which]}")


@pytest.mark.parametrize("name", ("rt70", "tree3"))
def test_newtons_jacobian_is_the_springs_material_gains(name):
    from rt70.textbook.mass_kernel import KernelData, mass_matrix
    from rt70.textbook.static_kernel import StaticData, element_gains

    scene = _scene(name)
    model = scene.textbook
    q, v = _state(model.nv, 5)
    Jq, Jv = forward_kernel.jacobian(model, forward_kernel.ForwardData.of(model), q, v, False)
    A = mass_matrix(model, KernelData(model), q)
    K, D = element_gains(model, StaticData.of(model), q)
    for J, G, what in ((Jq, K, "∂q̈/∂q"), (Jv, D, "∂q̈/∂q̇")):
        # −A⁻¹ G: the solve's rounding grows with A's condition number (1e6 on the RT-70)
        assert_close(J, -np.linalg.solve(A, G), rel=1e-7, what=f"{name} material {what}")


@pytest.fixture(scope="module")
def chain():
    return scene_from_text(elastic_chain(5, hanging=True), "chain5")


def _final_error(run, reference):
    return float(np.max(np.abs(run.q[-1] - reference.q[-1])))


@pytest.mark.parametrize("rtol", (1e-5, 1e-7))
def test_a_run_takes_scipys_steps_to_scipys_accuracy(chain, rtol):
    x0 = (np.zeros(chain.textbook.nv), np.zeros(chain.textbook.nv))
    reference = simulate(chain, (0.0, 0.5), x0, method="BDF", rtol=1e-11)
    scipy_run = simulate(chain, (0.0, 0.5), x0, method="BDF", rtol=rtol)
    run = simulate(chain, (0.0, 0.5), x0, method=METHOD, rtol=rtol)
    assert run.success and run.side == "compiled" and run.method == METHOD
    # the same algorithm: steps within a few per cent (the Jacobians round differently)
    assert abs(run.n_steps - scipy_run.n_steps) <= 0.05 * scipy_run.n_steps + 2
    # and the same accuracy: its error within twice scipy's, plus rounding of the motion
    motion = float(np.max(np.abs(reference.q)))
    assert _final_error(run, reference) <= 2 * _final_error(scipy_run, reference) + 1e-12 * motion


def test_the_rt70_transient_matches_bdf_within_its_tolerance():
    scene = load_scene("rt70")
    x0 = start_state(scene)
    bdf = simulate(scene, (0.0, 1.0), x0, method="BDF", rtol=1e-8)
    run = simulate(scene, (0.0, 1.0), x0, method=METHOD, rtol=1e-8)
    assert run.success and not run.drift_flagged
    motion = np.max(np.abs(bdf.q - bdf.q[0]), axis=0)
    # both within rtol-scaled error of the exact motion: their difference is too
    assert_close(run.q[-1], bdf.q[-1], rel=1e-5, scale=np.maximum(motion, 1e-6), what="q(1 s)")
    assert run.relative_drift < 10 * 1e-8


@pytest.mark.parametrize("name", ("rt70", "tree3"))
def test_newtons_matrix_pair_local_and_dense_give_one_run(name, monkeypatch):
    scene = _scene(name)
    nv = scene.textbook.nv
    x0 = start_state(scene) if name == "rt70" else _state(nv, 6)
    assert forward_kernel.ForwardData.of(scene.textbook).motion.local
    local = simulate(scene, (0.0, 0.5), x0, method=METHOD, rtol=1e-8)
    monkeypatch.setattr(compiled_bdf, "pair_local", lambda data: False)
    dense = simulate(scene, (0.0, 0.5), x0, method=METHOD, rtol=1e-8)
    # the same Newton matrix factored two ways: the same steps, up to the rounding of the
    # factorisations in Newton's convergence test
    assert abs(local.n_steps - dense.n_steps) <= 0.02 * dense.n_steps + 2
    motion = np.maximum(np.max(np.abs(dense.q - dense.q[0]), axis=0), 1e-9)
    assert_close(local.q[-1], dense.q[-1], rel=1e-5, scale=motion, what=f"{name} q(0.5 s)")


def test_a_model_with_bushings_across_pairs_runs_dense():
    scene = _scene("tree6")
    data = forward_kernel.ForwardData.of(scene.textbook)
    assert not data.motion.local and not compiled_bdf.pair_local(data)
    nv = scene.textbook.nv
    x0 = _state(nv, 7)
    run = simulate(scene, (0.0, 0.5), x0, method=METHOD, rtol=1e-7)
    bdf = simulate(scene, (0.0, 0.5), x0, method="BDF", rtol=1e-7)
    motion = np.maximum(np.max(np.abs(bdf.q - bdf.q[0]), axis=0), 1e-9)
    assert_close(run.q[-1], bdf.q[-1], rel=1e-4, scale=motion, what="q(0.5 s)")


def test_output_times_are_the_dense_output_of_the_steps(chain):
    nv = chain.textbook.nv
    x0 = (np.zeros(nv), np.zeros(nv))
    every = simulate(chain, (0.0, 0.4), x0, method=METHOD, rtol=1e-9)
    t_eval = np.linspace(0.0, 0.4, 41)
    sampled = simulate(chain, (0.0, 0.4), x0, method=METHOD, rtol=1e-9, t_eval=t_eval)
    np.testing.assert_array_equal(sampled.t, t_eval)
    assert_close(sampled.q[0], x0[0], rel=1e-12, scale=1.0, what="q(t0)")
    from scipy.interpolate import CubicHermiteSpline

    spline = CubicHermiteSpline(every.t, every.q, every.qd, axis=0)
    motion = float(np.max(np.abs(every.q)))
    assert_close(sampled.q, spline(t_eval), rel=1e-6, scale=motion, what="q at t_eval")
    assert_close(sampled.kinetic[-1], every.kinetic[-1], rel=1e-5, what="T(t1)")


def test_a_full_sample_buffer_loses_nothing(chain, monkeypatch):
    nv = chain.textbook.nv
    x0 = (np.zeros(nv), np.zeros(nv))
    whole = simulate(chain, (0.0, 0.3), x0, method=METHOD, rtol=1e-6)
    t_eval = np.linspace(0.0, 0.3, 30)
    sampled = simulate(chain, (0.0, 0.3), x0, method=METHOD, rtol=1e-6, t_eval=t_eval)
    monkeypatch.setattr(compiled_bdf, "BUFFER_ROWS", 7)
    monkeypatch.setattr(compiled_bdf, "CHUNK_STEPS", 3)
    small = simulate(chain, (0.0, 0.3), x0, method=METHOD, rtol=1e-6)
    np.testing.assert_array_equal(small.t, whole.t)
    np.testing.assert_array_equal(small.q, whole.q)
    again = simulate(chain, (0.0, 0.3), x0, method=METHOD, rtol=1e-6, t_eval=t_eval)
    np.testing.assert_array_equal(again.q, sampled.q)


def test_energy_audit_of_a_damped_tree():
    scene = _scene("tree3")
    nv = scene.textbook.nv
    q0, v0 = _state(nv, 4)
    run = simulate(scene, (0.0, 1.0), (q0, v0), method=METHOD, rtol=1e-8)
    bdf = simulate(scene, (0.0, 1.0), (q0, v0), method="BDF", rtol=1e-8)
    assert run.success and not run.drift_flagged
    assert_close(run.dissipated[-1], bdf.dissipated[-1], rel=1e-5, scale=run.balance_scale,
                 what="dissipated energy")  # fmt: skip
    assert abs(run.balance[-1]) <= 1e-6 * run.balance_scale


def test_refusals_name_the_method():
    chain6 = scene_from_text(elastic_chain(3), "chain3")
    nv = chain6.textbook.nv
    with pytest.raises(Rt70Error, match="compiled-BDF.*inputs"):
        simulate(chain6, (0.0, 0.1), method=METHOD, inputs=lambda t, q, v: np.zeros(nv))
    event = lambda t, q, v: q[0] - 1.0  # noqa: E731
    with pytest.raises(Rt70Error, match="compiled-BDF.*events"):
        simulate(chain6, (0.0, 0.1), method=METHOD, events=[event])
    with pytest.raises(Rt70Error, match="closed loops"):
        simulate(load_scene("four_bar"), (0.0, 0.1), method=METHOD)
    with pytest.raises(Rt70Error, match="modal bodies"):
        simulate(load_scene("slewing_truss"), (0.0, 0.1), method=METHOD)


def test_the_evaluation_budget_stops_a_run(chain):
    with evaluation_budget(EvaluationBudget(minimum=50, per_second=0.0)):
        with pytest.raises(SimulationError, match="stopped after 50 right-hand-side"):
            simulate(chain, (0.0, 5.0), method=METHOD, rtol=1e-9)


def test_the_command_line_runs_it(capsys):
    assert main(["simulate", "rt70", "--t-end", "0.5", "--method", METHOD, "--rtol", "1e-5"]) == 0
    out = capsys.readouterr().out
    assert "compiled-BDF (compiled kernels)" in out and ": ok" in out


def test_a_long_load_says_the_kernels_compile_and_a_short_one_says_nothing(chain, monkeypatch,
                                                                         capsys):  # fmt: skip
    """The first run after an install compiles for about a minute: past a few seconds of
    loading, one line on stderr says so (a stand-in loop takes the time here)."""
    import time

    from rt70.simulation import bdf_kernel

    real = bdf_kernel.advance

    def slow(*args):
        time.sleep(1.0)
        return real(*args)

    monkeypatch.setattr(compiled_bdf, "COMPILE_NOTICE_S", 0.05)
    monkeypatch.setattr(bdf_kernel, "advance", slow)
    simulate(chain, (0.0, 0.01), method=METHOD)
    said = capsys.readouterr().err
    assert said.count("rt70: compiling the compiled-BDF kernels") == 1, said
    monkeypatch.setattr(compiled_bdf, "COMPILE_NOTICE_S", 30.0)
    simulate(chain, (0.0, 0.01), method=METHOD)
    assert "compiling" not in capsys.readouterr().err
