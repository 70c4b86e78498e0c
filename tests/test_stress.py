"""Stress cases (rt70.reports.stress): gimbal lock, unit scaling, free-floating momentum."""

import itertools
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import rt70.urdf as rt70_urdf
from rt70 import SingularConfigurationError, reference
from rt70.model.scene import load_scene, scene_from_text
from rt70.reports.stress.edits import (
    convert_units,
    free_floating_text,
    rt70_text,
    scale_springs,
    set_gravity,
)
from rt70.reports.stress.gimbal_cases import (
    GIMBAL_BUSHING,
    GIMBAL_COORDINATE,
    gimbal_mass_matrix_cases,
    gimbal_spring_cases,
)
from rt70.reports.stress.measures import (
    frequencies_hz,
    momentum_pinocchio,
    momentum_textbook,
    translational,
)
from rt70.reports.stress.report import write_report
from rt70.reports.stress.runs import count_bdf_steps, run_capped
from rt70.reports.stress.scaling_cases import free_floating_state
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.simulate import simulate
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import forces
from rt70.textbook.spatial import GIMBAL_LOCK_COS


@pytest.fixture(scope="module")
def rt70():
    return load_scene("rt70")


def _gimbal_state(scene, theta):
    q, qd = listing_initial_state(scene)
    q = q.copy()
    q[scene.textbook.coordinate_names.index(GIMBAL_COORDINATE)] = theta
    return q, qd


# --- gimbal lock -----------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5, 6])
def test_spring_forces_agree_before_gimbal_threshold(rt70, k):
    q, qd = _gimbal_state(rt70, np.pi / 2 - 10.0**-k)
    assert abs(np.cos(q[rt70.textbook.coordinate_names.index(GIMBAL_COORDINATE)])) > (
        GIMBAL_LOCK_COS
    )
    Qc, Qd = forces.spring_damper_force(rt70.textbook, rt70.textbook_data, q, qd)
    Qc_ref, Qd_ref = reference.spring_damper_force(rt70.reference, rt70.reference_data, q, qd)
    assert np.all(np.isfinite(Qc)) and np.all(np.isfinite(Qd))
    assert_close(Qc, Qc_ref, rel=1e-10, what="spring forces")
    assert_close(Qd, Qd_ref, rel=1e-7, what="damper forces")


@pytest.mark.parametrize("theta", [np.pi / 2 - 1e-9, np.pi / 2, -np.pi / 2 + 1e-10])
def test_gimbal_lock_raises_clear_error(rt70, theta):
    q, qd = _gimbal_state(rt70, theta)
    with pytest.raises(SingularConfigurationError, match="gimbal lock") as info:
        forces.spring_damper_force(rt70.textbook, rt70.textbook_data, q, qd)
    assert GIMBAL_BUSHING in str(info.value)  # names the element
    assert "1e-08" in str(info.value)  # and the threshold
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        reference.spring_damper_force(rt70.reference, rt70.reference_data, q, qd)
    with pytest.raises(SingularConfigurationError):
        simulate(rt70, (0.0, 0.01), (q, qd))
    run = run_capped(rt70, (0.0, 0.01), (q, qd), cap_s=math.inf)
    assert run.status.startswith("error: SingularConfigurationError")


def test_gimbal_tables_report_threshold():
    springs = gimbal_spring_cases(quick=True)
    by_k = {r["k"]: r for r in springs.rows}
    assert by_k["4"]["springs"] == "computed"
    assert_close(by_k["4"]["qc"], 0.0, rel=1e-10, scale=1.0)  # a relative error: scale 1
    assert by_k["9"]["springs"].startswith("SingularConfigurationError")
    assert by_k["∞"]["springs"].startswith("SingularConfigurationError")
    mass = gimbal_mass_matrix_cases(quick=True)
    rows = {r["k"]: r for r in mass.rows}
    exact = rows["∞"]
    assert exact["cond"] > 1e16
    # every forward-dynamics path refuses a pair within DYNAMICS_GIMBAL_COS of gimbal lock
    for key in ("dense", "structured", "pinocchio"):
        assert exact[key].startswith("SingularConfigurationError"), (key, exact[key])


# --- units -------------------------------------------------------------------------------


def test_convert_units_factors():
    text = convert_units(rt70_text(), 1e3, 1e3)
    scene = scene_from_text(text, "mm")
    si = load_scene("rt70")
    # the text's numbers times the factors, written and read back: rounding only, entry by
    # entry (each number is its own quantity)
    gravity = np.array(si.description.gravity) * 1e3
    assert_close(scene.description.gravity, gravity, rel=MIN_REL, scale=np.abs(gravity))
    b_si = {b.name: b for b in si.description.bushings}
    for b in scene.description.bushings:
        factor = np.array([1e3] * 3 + [1e9] * 3)
        stiffness = b_si[b.name].stiffness * factor
        assert_close(b.stiffness, stiffness, rel=MIN_REL, scale=np.abs(stiffness))
        xyz = b_si[b.name].frame1.xyz * 1e3
        assert_close(b.frame1.xyz, xyz, rel=MIN_REL, scale=np.abs(xyz))
    mass = si.textbook.mass * 1e3
    assert_close(scene.textbook.mass, mass, rel=MIN_REL, scale=np.abs(mass))
    theta = si.textbook.Theta[:, 3:, 3:] * 1e9
    assert_close(scene.textbook.Theta[:, 3:, 3:], theta, rel=1e-14, scale=np.abs(theta))


@pytest.mark.parametrize(
    "length, mass", [(1e3, 1e3), (1.0, 1.0 / 9.80665)], ids=["mm-g-s", "m-kgf-s"]
)
def test_unit_scaling_invariance(rt70, length, mass):
    scene = scene_from_text(convert_units(rt70.text, length, mass), "units")
    f_si, f = frequencies_hz(rt70), frequencies_hz(scene)
    assert np.array_equal(f_si == 0.0, f == 0.0)  # the same rigid-body modes (2)
    elastic = f_si > 0
    assert_close(f[elastic], f_si[elastic], rel=1e-10, scale=f_si[elastic])  # each its own

    q0, v0 = listing_initial_state(rt70)
    mask = translational(scene)
    scale = np.where(mask, length, 1.0)
    grid = np.linspace(0.0, 0.05, 11)
    kw = {"method": "BDF", "rtol": 1e-9, "t_eval": grid}
    ref = simulate(rt70, (0.0, 0.05), (q0, v0), **kw)
    run = simulate(scene, (0.0, 0.05), (q0 * scale, v0 * scale), **kw)
    assert ref.success and run.success
    back = run.q / scale
    for part in (mask, ~mask):
        assert_close(back[:, part], ref.q[:, part], rel=1e-6)
    # energies scale as mass × length²
    assert_close(run.kinetic / (mass * length**2), ref.kinetic, rel=1e-6)


# --- free-floating structure -------------------------------------------------------------


@pytest.fixture(scope="module")
def floating():
    return scene_from_text(free_floating_text(2), "free_floating_2")


def test_free_floating_model(floating):
    model = floating.textbook
    assert model.kind == ["euler6", "euler6"] and model.nv == 12
    assert not model.gravity.any() and len(model.bushings) == 1
    assert int(np.sum(frequencies_hz(floating) == 0.0)) == 6  # 3 translations, 3 rotations
    q, qd = free_floating_state(floating)
    P, L = momentum_pinocchio(floating, q, qd)
    P_t, L_t = momentum_textbook(floating, q, qd)
    assert_close(P_t, P, rel=1e-13, what="momentum")
    assert_close(L_t, L, rel=1e-13, what="angular momentum")
    assert np.linalg.norm(P) > 0.1 and np.linalg.norm(L) > 0.1


@pytest.mark.slow
@pytest.mark.parametrize("side", ["reference", "textbook"])
def test_free_floating_momentum_conserved(floating, side):
    x0 = free_floating_state(floating)
    res = simulate(floating, (0.0, 0.1), x0, side=side, method="DOP853", rtol=1e-10)
    assert res.success
    moments = [momentum_pinocchio(floating, a, b) for a, b in zip(res.q, res.qd, strict=True)]
    P = np.array([m[0] for m in moments])
    L = np.array([m[1] for m in moments])
    assert_close(P, np.broadcast_to(P[0], P.shape), rel=1e-9, scale=np.linalg.norm(P[0]))
    assert_close(L, np.broadcast_to(L[0], L.shape), rel=1e-9, scale=np.linalg.norm(L[0]))
    assert_close(res.relative_drift, 0.0, rel=1e-8, scale=1.0)  # a relative drift: scale 1
    # the body moved and deformed: conservation is not trivial
    assert np.max(np.abs(res.q[-1] - res.q[0])) > 1e-3


@pytest.mark.slow
def test_momentum_changes_under_gravity():
    scene = scene_from_text(set_gravity(free_floating_text(2), (0.0, 0.0, -9.81)), "falling")
    x0 = free_floating_state(scene)
    res = simulate(scene, (0.0, 0.1), x0, method="DOP853", rtol=1e-10)
    P0, _ = momentum_pinocchio(scene, res.q[0], res.qd[0])
    P1, _ = momentum_pinocchio(scene, res.q[-1], res.qd[-1])
    total_mass = float(scene.textbook.mass.sum())
    # a difference of momenta: its scale is theirs (the integration's rtol is 1e-10)
    scale = max(np.linalg.norm(P0), np.linalg.norm(P1))
    assert_close(P1 - P0, [0.0, 0.0, -9.81 * total_mass * 0.1], rel=1e-9, scale=scale)


# --- helpers, fixes and the report ----------------------------------------------------------


def test_count_bdf_steps():
    # f0, the initial-step probe and the Jacobian at t0, then the attempts: 0.1 rejected
    # (retried at 0.05), 0.05 accepted, 0.15 rejected, 0.12 accepted, 0.2 accepted
    times = [0.0, 0.01, 0.0, 0.1, 0.1, 0.05, 0.05, 0.15, 0.12, 0.12, 0.2]
    assert count_bdf_steps(times, 0.0) == (3, 2)


def test_run_capped_counts_match_solver(rt70):
    run = run_capped(rt70, (0.0, 0.01), listing_initial_state(rt70), cap_s=math.inf)
    assert run.ok and run.result is not None
    assert run.n_steps == run.result.n_steps and run.n_rejected is not None


def test_run_capped_time_cap(rt70):
    """The cap is checked at every right-hand-side evaluation and the first one past it
    ends the run: on a clock that ticks once per evaluation, exactly the 51st of a 50 s cap."""
    text = scale_springs(rt70.text, 1e6, 0.0)  # undamped, f_max ~ 3e5 Hz
    scene = scene_from_text(text, "stiff")
    ticks = itertools.count()
    run = run_capped(
        scene,
        (0.0, 1.0),
        listing_initial_state(scene),
        cap_s=50.0,
        clock=lambda: float(next(ticks)),
    )
    assert run.status == "over cap" and run.nfev == 51 and run.result is None
    assert 0.0 < run.t_reached < 1.0


def test_run_capped_evaluation_budget():
    """The report's cap is a budget of evaluations: the first one past it ends the run,
    whatever the clock says."""
    scene = scene_from_text(scale_springs(load_scene("rt70").text, 1e6, 0.0), "stiff")
    run = run_capped(
        scene, (0.0, 1.0), listing_initial_state(scene), cap_s=math.inf, max_evaluations=40
    )
    assert run.status == "over cap" and run.nfev == 41 and 0.0 < run.t_reached < 1.0


def test_run_capped_starts_its_clock_after_the_kernels_are_warm(rt70, monkeypatch):
    """The cap measures the integration, not the compilation of the kernels: a short run
    that calls every kernel comes before the first reading of the cap's clock."""
    from rt70.reports.stress import runs

    events = []
    real = runs.simulate

    def recording(scene, t_span, *args, **kwargs):
        events.append(("simulate", t_span[1] - t_span[0]))
        return real(scene, t_span, *args, **kwargs)

    def clock():
        events.append(("clock", None))
        return 0.0

    monkeypatch.setattr(runs, "simulate", recording)
    run = run_capped(rt70, (0.0, 0.01), listing_initial_state(rt70), clock=clock)
    assert run.ok
    warm, first_clock = events.index(("simulate", 1e-9)), events.index(("clock", None))
    assert warm < first_clock and events[first_clock + 1] == ("simulate", 0.01)


def _lines_executed_in(package, call):
    """Python lines executed in ``package``'s files while ``call()`` runs, and its value:
    a count of operations, the same on any machine (``sys.settrace``)."""
    root = str(Path(package.__file__).parent)
    count = 0

    def in_package(frame, event, arg):
        nonlocal count
        if event == "line":
            count += 1
        return in_package

    def on_call(frame, event, arg):
        return in_package if frame.f_code.co_filename.startswith(root) else None

    previous = sys.gettrace()
    sys.settrace(on_call)
    try:
        value = call()
    finally:
        sys.settrace(previous)
    return count, value


@pytest.mark.slow
def test_long_chain_reads_in_linear_work():
    """The reader's cycle check was cubic (a 1000-body chain took 382 s to read): four
    times the bodies must cost four times the lines executed in rt70.urdf, not 16 or 64."""
    from rt70.scenes.synthetic import elastic_chain

    work = [
        _lines_executed_in(rt70_urdf, lambda n=n: scene_from_text(elastic_chain(n), "chain"))[0]
        for n in (100, 400)
    ]
    assert work[1] <= 4.4 * work[0], work  # linear, within 10 %


@pytest.mark.slow
def test_long_chain_reads_and_builds():
    from rt70.scenes.synthetic import elastic_chain

    scene = scene_from_text(elastic_chain(1000), "chain1000")
    model = scene.textbook  # build_model recursed once per body (RecursionError)
    assert model.nv == 6000 and model.parent[-1] == 998


@pytest.mark.slow
def test_write_report_quick(tmp_path):
    path = write_report(tmp_path, quick=True)
    assert path == tmp_path / "stress.md"
    text = path.read_text(encoding="utf-8")
    for title in (
        "## Findings",
        "## Stiffness",
        "## Mass ratio",
        "## Approach to gimbal lock: spring forces",
        "## Approach to gimbal lock: the mass matrix",
        "## Long chains",
        "## Units",
        "## Zero stiffness",
        "## Free-floating structure",
    ):
        assert title in text
    assert "quick" in text and "nan" not in text.split("## Findings")[1].split("##")[0]
