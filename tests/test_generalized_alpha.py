"""The generalized-α method on the compiled kernels (rt70.simulation.generalized_alpha,
rt70.simulation.compiled_run) against BDF on the reference side, and its refusals.

The reference run is BDF at rtol 1e-10; a second-order method's global error is compared
on the scale of the motion, at two tolerances (it must fall as the tolerance does). No
timing is asserted (``rt70 bench large`` measures it).
"""

from __future__ import annotations

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes.synthetic import elastic_chain
from rt70.simulation.generalized_alpha import Coefficients
from rt70.simulation.simulate import simulate
from rt70.testing import MIN_REL, assert_close

GA = "generalized-alpha"


@pytest.fixture(scope="module")
def chain():
    return scene_from_text(elastic_chain(6, hanging=True), "chain6")


@pytest.fixture(scope="module")
def reference_run(chain):
    return simulate(chain, (0.0, 0.3), method="BDF", rtol=1e-10)


def _error(run, reference):
    """Largest |q − q_BDF| over the run's steps (BDF's dense output between its steps)."""
    from scipy.interpolate import CubicHermiteSpline

    spline = CubicHermiteSpline(reference.t, reference.q, reference.qd, axis=0)
    return float(np.max(np.abs(run.q - spline(run.t))))


def _free_vibration(rho, steps, w=1e6, h=1.0):
    """|q| after ``steps`` steps of the method on q̈ = −ω² q from q = 1 (Newton exact: linear)."""
    co = Coefficients.of(rho)
    k, c = 1.0 / (1.0 - co.alpha_m), (1.0 - co.alpha_f) / (1.0 - co.alpha_m)
    q, v, acc = 1.0, 0.0, -(w**2)
    a = acc
    for _ in range(steps):
        base_a = k * (co.alpha_f * acc - co.alpha_m * a)
        base_q = q + h * v + h * h * (0.5 - co.beta) * a
        acc = -(w**2) * (base_q + h * h * co.beta * base_a) / (1.0 + w**2 * co.beta * c * h * h)
        v = v + h * (1.0 - co.gamma) * a
        a = base_a + c * acc
        v += h * co.gamma * a
        q = base_q + h * h * co.beta * a
    return abs(q)


def test_coefficients_are_second_order_and_damp_what_the_step_cannot_resolve():
    co = Coefficients.of(0.9)
    # terms of order 1: a few roundings of ε each (MIN_REL)
    assert_close(co.gamma, 0.5 + co.alpha_f - co.alpha_m, rel=MIN_REL, scale=1.0, what="γ")
    assert_close(co.beta, 0.25 * (co.gamma + 0.5) ** 2, rel=MIN_REL, scale=1.0, what="β")
    # a mode of ωh = 10⁶: kept by ρ∞ = 1, damped by ρ∞ < 1, the more the smaller ρ∞
    kept, damped, strongly = (_free_vibration(rho, 100) for rho in (1.0, 0.9, 0.5))
    assert kept == pytest.approx(1.0, rel=1e-3)
    assert strongly < damped < 1e-2
    with pytest.raises(Rt70Error, match="spectral radius"):
        Coefficients.of(1.5)


def test_equals_bdf_on_a_chain_and_converges(chain, reference_run):
    scale = float(np.max(np.abs(reference_run.q)))
    assert scale > 1e-3  # the chain moves: the comparison compares something
    errors, drifts = [], []
    for rtol in (1e-5, 1e-7):
        run = simulate(chain, (0.0, 0.3), method=GA, rtol=rtol)
        assert run.success and run.side == "compiled"
        assert run.t[-1] == 0.3  # exactly: the last step ends at t1, not a rounding short
        assert np.isfinite(run.q).all() and np.isfinite(run.balance).all()
        errors.append(_error(run, reference_run))
        drifts.append(run.relative_drift)
    # the energy audit closes to the method's error: a second-order method's global error
    # falls as rtol^(2/3) under a local error test (measured: 2.1e-4, then 5.0e-6)
    assert drifts[0] < 100 * 1e-5
    assert drifts[1] < 0.1 * drifts[0]
    assert errors[0] < 1e-2 * scale  # rtol 1e-5: within 1 % of the motion
    assert errors[1] < 1e-3 * scale
    assert errors[1] < 0.2 * errors[0]  # a tighter tolerance is more accurate


def test_inputs_do_work_and_are_audited(chain):
    n = chain.textbook.nv
    force = np.zeros(n)
    force[2] = 50.0  # N on the first body's z

    def inputs(t, q, qd):
        return force * np.sin(20 * t)

    ga = simulate(chain, (0.0, 0.2), method=GA, rtol=1e-7, inputs=inputs)
    bdf = simulate(chain, (0.0, 0.2), method="BDF", rtol=1e-10, inputs=inputs)
    assert abs(ga.input_work[-1]) > 1e-3  # the input did work
    assert ga.input_work[-1] == pytest.approx(bdf.input_work[-1], rel=1e-3)
    assert _error(ga, bdf) < 1e-3 * float(np.max(np.abs(bdf.q)))


def test_output_times_and_outputs_equal_bdf(chain, reference_run):
    """At output times the steps' Hermite interpolants; outputs evaluated on them."""
    from rt70.model.outputs import position_output

    t_eval = np.linspace(0.0, 0.3, 31)
    tip = [position_output("tip", "body6", (0.0, 0.0, 0.0))]
    ga = simulate(chain, (0.0, 0.3), method=GA, rtol=1e-7, t_eval=t_eval, outputs=tip)
    bdf = simulate(chain, (0.0, 0.3), method="BDF", rtol=1e-10, t_eval=t_eval, outputs=tip)
    assert np.array_equal(ga.t, t_eval) and ga.q.shape == bdf.q.shape
    scale = float(np.max(np.abs(bdf.q)))
    assert float(np.max(np.abs(ga.q - bdf.q))) < 1e-3 * scale
    assert float(np.max(np.abs(ga.qd - bdf.qd))) < 1e-3 * float(np.max(np.abs(bdf.qd)))
    moved = float(np.ptp(bdf.outputs["tip"][:, 2]))
    assert moved > 1e-4  # the tip moves, m
    assert float(np.max(np.abs(ga.outputs["tip"] - bdf.outputs["tip"]))) < 1e-3 * moved
    # the audit at the output times: the same energies as BDF's at the same states
    assert ga.kinetic == pytest.approx(bdf.kinetic, rel=1e-2, abs=1e-3 * bdf.balance_scale)
    assert ga.dissipated[-1] == pytest.approx(bdf.dissipated[-1], rel=1e-3)


@pytest.mark.parametrize("extra", [{"components": ["x"]}, {"events": [lambda t, q, qd: t - 0.05]}])
def test_refuses_what_it_does_not_do(chain, extra):
    with pytest.raises(Rt70Error, match=f"method '{GA}' takes no"):
        simulate(chain, (0.0, 0.1), method=GA, **extra)


def test_bad_arguments_are_refused_as_for_every_method(chain):
    with pytest.raises(Rt70Error, match="rtol must lie"):
        simulate(chain, (0.0, 0.1), method=GA, rtol=2.0)
    with pytest.raises(Rt70Error, match="t_eval must be increasing"):
        simulate(chain, (0.0, 0.1), method=GA, t_eval=[0.05, 0.01])


def test_refuses_a_model_the_kernels_do_not_cover():
    with pytest.raises(Rt70Error, match="closed loops"):
        simulate(load_scene("four_bar"), (0.0, 0.1), method=GA)


def test_cli_runs_a_large_model_by_default_on_the_kernels(tmp_path, capsys):
    path = tmp_path / "chain.urdf"
    path.write_text(elastic_chain(34, hanging=True), encoding="utf-8")  # 204 coordinates
    assert main(["simulate", str(path), "--t-end", "0.02"]) == 0
    out = capsys.readouterr().out
    assert f"{GA} ρ∞=0.9 (compiled kernels)" in out and "balance drift" in out
    with pytest.raises(SystemExit) as stop:
        main(["simulate", str(path), "--t-end", "0.02", "--method", GA, "--rtol", "2"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "--rtol" in err and "Traceback" not in err


def test_the_evaluation_budget_stops_a_run(chain):
    from rt70.errors import SimulationError
    from rt70.simulation.integrators import EvaluationBudget, evaluation_budget

    with evaluation_budget(EvaluationBudget(minimum=100, per_second=10)):
        with pytest.raises(SimulationError, match="stopped after 110 right-hand-side"):
            simulate(chain, (0.0, 1.0), method=GA)


def test_a_run_too_long_for_memory_is_stopped_at_its_pace(chain):
    from rt70.errors import SimulationError

    with pytest.raises(SimulationError, match="at the pace of its first"):
        simulate(chain, (0.0, 1e9), method=GA)
