"""The issue-13 targets of ``rt70 bench simulate`` and the centre-of-mass metric."""

import math

import numpy as np
import pinocchio as pin
import pytest

from rt70.errors import Rt70Error
from rt70.model.scene import load_scene
from rt70.reports import simulation_targets as st
from rt70.reports import work_precision as wp
from rt70.reports.work_precision_problems import PROBLEMS
from rt70.reports.work_precision_worker import com_positions
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation import simulate as sim
from rt70.testing import MIN_REL, assert_close


def test_centres_of_mass_average_to_pinocchio_centre_of_mass():
    scene = load_scene("rt70")
    q0, _ = listing_initial_state(scene)
    q = np.vstack([q0, 0.5 * q0])
    com = com_positions(scene, q)
    model, data = scene.reference.pin_model, scene.reference.pin_model.createData()
    masses = np.array([i.mass for i in model.inertias.tolist()[1:] if i.mass > 0.0])
    assert com.shape == (2, len(masses), 3) and len(masses) == 7  # the RT-70 bodies
    for k in range(2):
        total = pin.centerOfMass(model, data, q[k])
        # a mass-weighted mean of 7 positions against Pinocchio's sum: rounding of the
        # positions' size (measured < 1 ulp of it)
        average = masses @ com[k] / masses.sum()
        assert_close(average, total, rel=1e-14, scale=np.max(np.abs(com[k])))
    assert wp.com_error(com, com) == 0.0  # the same numbers on both sides
    moved = com.copy()
    moved[1, 3] += [3e-6, 0.0, 4e-6]
    # a difference of positions: rounding of their size, not of the 5 µm
    assert_close(wp.com_error(moved, com), 5e-6, rel=MIN_REL, scale=np.max(np.abs(com)))


def test_methods_come_from_simulate():
    assert wp.METHODS == tuple(m for m in sim.METHODS if m != "RK23")
    assert set(wp.STIFF_METHODS) == {
        "Radau",
        "BDF",
        "LSODA",
        "generalized-alpha",
        "compiled-BDF",
    } | {m for m in sim.METHODS if m.startswith("CVODE")}


def test_the_target_problem_is_the_commands_ten_second_transient():
    (p,) = [p for p in PROBLEMS if p.name == st.TRANSIENT_PROBLEM]
    assert p.t_end == 10.0 and p.stiff_only and p.rtols == (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
    assert {"rt70", "rt70_light"} <= {q.name for q in PROBLEMS}  # the 2 s problems stay


def _row(method, rtol, status, com_error, time_s):
    return wp.Row(
        st.TRANSIENT_PROBLEM, 42, 10.0, method, rtol, 1e-3 * rtol, status,
        status.startswith("over"), 1e-6, time_s, "", 0, 0, 0, 20.0, "", 1e-10, "", 1, "",
        com_error=com_error,
    )  # fmt: skip


def test_integration_target_takes_the_fastest_run_to_the_accuracy():
    rows = [
        _row("BDF", 1e-6, "ok", 2.2e-5, 0.9),  # fast but not accurate enough
        _row("BDF", 1e-7, "ok", 4.9e-6, 1.85),
        _row("Radau", 1e-7, "ok", 3e-6, 1.5),
        _row("RK45", 1e-3, "over cap", math.nan, math.nan),
    ]
    check, win = st.integration_target(rows)
    assert win is rows[2] and check.met is False
    assert check.measured.startswith("1.500 s, 6.7× real time (Radau, rtol 1e-07")
    assert "≤ 1e-05 m: integration ≤ 0.1 s (≥ 100× real time)" in check.target
    check, win = st.integration_target([_row("BDF", 1e-7, "ok", 9e-6, 0.099)])
    assert check.met is True and win.time_s == 0.099
    check, _ = st.integration_target([_row("BDF", 1e-7, "ok", 9e-6, 0.11)])
    assert check.met is False  # 91× real time
    check, win = st.integration_target(rows[:1])
    assert check.met is False and win is None and "least error 2.2e-05 m" in check.measured
    check, _ = st.integration_target([])
    assert check.met is None and check.line().endswith("— not judged")


def test_servo_target_and_quick_run():
    ref = dict(method="LSODA", rtol=1e-11, status="reference", com_error=0.0)
    runs = [
        ref,
        dict(method="LSODA", rtol=1e-5, status="ok", com_error=2e-5, wall_s=0.1, t_end=10.0),
        dict(
            method="LSODA", rtol=1e-6, status="ok", com_error=1e-6, wall_s=0.5, t_end=10.0,
            pointing_error=1e-3,
        ),
    ]  # fmt: skip
    check = st.servo_target(runs)
    assert check.met is False and check.measured.startswith("0.500 s for 10 s, 20.0× real")
    runs[2]["wall_s"] = 0.4
    assert st.servo_target(runs).met is True
    assert st.servo_target(runs[:2]).met is False
    assert st.servo_target(None).met is None


def test_command_failure_is_an_error():
    with pytest.raises(Rt70Error, match="exit 2"):
        st.command_seconds("NO-SUCH-METHOD", 1e-6, repeats=1)
    assert st.command_target(None, quick=True).met is None


def test_kernel_ratios_are_measured_against_pinocchio():
    """One short measurement: times and ratios are there (their values are the
    benchmark's, not a test's)."""
    got = st.kernel_ratios(rounds=1, budget_s=0.002)
    for key in ("rhs", "jacobian"):
        ours, theirs, ratio = got[key]
        assert ours > 0 and theirs > 0 and ratio > 0 and math.isfinite(ratio)
    assert "pinned to 1" in got["threads"]


def test_kernel_targets_are_judged_on_the_ratio(monkeypatch):
    """Given ratios: at or under 3 met, over it not — also where the printed ratio rounds
    to 3.0."""
    given = {
        "rhs": (2.9e-5, 1e-5, 2.9),
        "jacobian": (3.04e-4, 1e-4, 3.04),
        "threads": "BLAS/OpenMP threads pinned to 1 (unpinned: openblas 2)",
    }
    monkeypatch.setattr(st, "kernel_ratios", lambda rounds, budget_s: given)
    rhs, jac = st.kernel_targets(rounds=1, budget_s=0.002)
    assert rhs.target == "right-hand side ≤ 3× pin.aba on the RT-70"
    assert jac.target == "Jacobian ≤ 3× pin.computeABADerivatives on the RT-70"
    assert rhs.met is True and rhs.measured.startswith("2.9× (29.0 µs against 10.0 µs")
    assert jac.met is False and jac.measured.startswith("3.0× (304.0 µs against 100.0 µs")
    assert "pinned to 1" in rhs.measured and "median of 1 interleaved rounds" in jac.measured


def test_startup_target_times_the_version_command():
    check = st.version_target(repeats=1)
    assert check.met in (True, False)  # the verdict is the machine's; the test is not
    assert "best of 1" in check.measured and "rt70 --version" in check.target
    assert st.version_target(quick=True).met is None


def test_gust_target_runs_a_record_and_judges_its_pace():
    """A short record stands in for the 600 s one; the verdict is a bool either way."""
    assert st.gust_target(None).met is None
    check = st.gust_target(2.0)
    assert isinstance(check.met, bool)
    assert "for 2 s" in check.measured and "× real time (CVODE" in check.measured


def test_servo_commands_are_judged_on_their_real_time_factor(monkeypatch):
    """Given wall times: a hold of 60 s in 1.2 s is 50× (met), in 1.3 s not; the hold
    with friction is judged at 10×; a failing command is a failed row, not the end."""
    from rt70.reports import servo_commands as sc

    assert sc.command_args("hold", True)[-1] == "--friction"
    quick = sc.servo_command_targets(quick=True)
    assert len(quick) == len(sc.CASES) and all(c.met is None for c in quick)
    walls = {"hold": 1.2, "track": 0.9, "step-elevation": 1.0, "step-azimuth": 0.7}

    def fake(args, repeats, env=None):
        if env is not None:  # served warm: a tenth of the time
            return [w / 10.0 for w in fake(args, repeats)]
        if "--friction" in args:
            return [6.1, 5.9]
        if args[3] == "step-azimuth":
            raise Rt70Error("rt70 simulate: exit 2: rt70: error: stopped")
        return [walls[args[3]] + 0.1, walls[args[3]]]

    monkeypatch.setattr(sc, "wall_times", fake)
    hold, track, step_el, step_az, friction = sc.servo_command_targets()
    assert hold.met is True and "50.0× real time" in hold.measured
    assert track.met is False and "44.4×" in track.measured  # 40 s in 0.9 s
    assert step_el.met is False  # 25 s in 1.0 s
    assert step_az.met is False and step_az.measured.startswith("failed:")
    assert friction.met is True and "10.2×" in friction.measured
    assert "--friction" in friction.target and "≥ 10×" in friction.target
    walls["hold"] = 1.3
    assert sc.servo_command_targets()[0].met is False
    both = sc.servo_command_targets(warm={"RT70_WARM_SOCKET": "w.sock"})
    assert len(both) == 2 * len(sc.CASES)  # each case cold and warm, a failure each time
    assert [c.target.rsplit(", ", 1)[1] for c in both[:2]] == ["cold", "warm process"]
    assert both[0].met is False and both[1].met is True and "served by the warm" in both[1].measured
