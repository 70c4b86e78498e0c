"""The work–precision report: quick run, files, convergence, references, the time cap."""

import csv
import math

import numpy as np
import pytest

from rt70.reports import work_precision as wp
from rt70.reports.work_precision_problems import QUICK_PROBLEMS, light_damping_text
from rt70.scene import load_scene, scene_from_text


@pytest.fixture(scope="module")
def quick_rows():
    return wp.run(quick=True)


def test_quick_run_writes_files(quick_rows, tmp_path):
    paths = wp.write_results(quick_rows, tmp_path)
    assert [p.name for p in paths] == ["work_precision.csv", "work_precision.png"]
    with open(tmp_path / "work_precision.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == len(quick_rows)
    assert {r["problem"] for r in table} == {p.name for p in QUICK_PROBLEMS}
    assert {r["method"] for r in table} == set(wp.METHODS)
    assert (tmp_path / "work_precision.png").stat().st_size > 10_000
    text = wp.format_table(quick_rows)
    assert "fastest to error" in text and "references" in text


def test_errors_decrease_with_tolerance(quick_rows):
    for problem in QUICK_PROBLEMS:
        for method in ("DOP853", "BDF"):
            ok = sorted(
                (r.rtol, r.error)
                for r in quick_rows
                if r.problem == problem.name and r.method == method and r.status == "ok"
            )
            if problem.name == "rt70" and method == "DOP853":
                assert not ok  # stiff: over the cap
                continue
            assert len(ok) == len(wp.QUICK_RTOLS), (problem.name, method)
            errors = [e for _, e in ok]  # tightest tolerance first
            assert all(np.isfinite(errors))
            assert errors == sorted(errors), (problem.name, method, ok)
            assert errors[0] < 0.1 * errors[-1]


def test_reference_is_another_method(quick_rows):
    for r in quick_rows:
        ref_method, ref_rtol = r.reference.split()[:2]
        assert ref_method != r.method
        assert ref_rtol == f"rtol={wp.REFERENCE_RTOL:g}"
        assert r.reference_floor < 1e-8  # the two references agree
        if r.status == "ok":
            assert r.error > 0 and r.time_s > 0 and not r.over_cap
            assert len(r.times_s.split(";")) == wp.QUICK_REPEATS


def test_stiff_explicit_runs_are_abandoned_at_the_cap(quick_rows):
    rk = [r for r in quick_rows if r.problem == "rt70" and r.method == "RK45"]
    assert [r.status for r in rk] == ["over cap", "over cap (not run)"]
    assert all(r.over_cap and math.isnan(r.error) for r in rk)


def test_light_damping_is_proportional():
    base = load_scene("rt70")
    delta = 0.05
    scene = scene_from_text(light_damping_text(base.text, delta), "rt70_light")
    old, new = base.description.bushings, scene.description.bushings
    assert [b.name for b in new] == [b.name for b in old] and len(new) == 11
    for a, b in zip(old, new, strict=True):
        np.testing.assert_array_equal(b.stiffness, a.stiffness)
        np.testing.assert_allclose(b.damping, delta * a.stiffness, rtol=1e-15)
    assert scene.textbook.nv == base.textbook.nv == 42


def test_runs_are_timed_with_pinned_threads(quick_rows):
    from rt70.reports.threads import pools

    assert {r.threads for r in quick_rows} == {1}  # read back from the worker's pools
    unpinned = {r.threads_unpinned for r in quick_rows}
    assert len(unpinned) == 1 and "openblas" in unpinned.pop()
    assert "BLAS/OpenMP threads in the worker: 1 (unpinned: " in wp.format_table(quick_rows)
    assert pools()  # the parent's pools are left as they were


def _fake(problem, method, rtol, status, error, time_s, t_end=2.0):
    return wp.Row(
        problem, 42, t_end, method, rtol, 1e-3 * rtol, status, status.startswith("over"),
        error, time_s, "", 0, 0, 0, 20.0, "", 1e-10, "", 1, "openblas 2",
    )  # fmt: skip


def test_real_time_target_is_judged_on_the_fastest_run_to_the_error():
    rows = [
        _fake("rt70", "BDF", 1e-6, "ok", 3e-6, 0.30),  # not accurate enough
        _fake("rt70", "BDF", 1e-7, "ok", 4e-7, 0.45),
        _fake("rt70", "Radau", 1e-7, "ok", 5e-7, 0.50),
        _fake("rt70", "RK45", 1e-3, "over cap", math.nan, math.nan),
        _fake("chain", "RK45", 1e-3, "ok", 1e-9, 0.001),  # another problem: ignored
    ]
    (check,) = wp.check_targets(rows)
    assert check.target.startswith("rt70 (listing damping, T = 2 s) to state error ≤ 1e-06 in")
    assert "≤ 0.04 s of integration, i.e. ≥ 50× real time" in check.target
    assert check.measured.startswith("0.450 s, 4.4× real time (BDF, rtol 1e-07")
    assert check.met is False and check.line().endswith("— NOT met")
    fast = [_fake("rt70", "BDF", 1e-7, "ok", 4e-7, 0.039)]
    assert wp.check_targets(fast)[0].met is True
    (none,) = wp.check_targets(rows[:1] + rows[3:])
    assert none.met is False and "no method reached it" in none.measured
    assert wp.check_targets(rows[-1:])[0].met is None
    quick = [_fake("rt70", "BDF", 1e-6, "ok", 4e-7, 0.0001, t_end=0.05)]  # 500× but 0.05 s
    assert wp.check_targets(quick)[0].met is None
    assert wp.check_targets(quick)[0].line().endswith("under the report's 2 s — not judged")
    text = wp.format_table(rows)
    assert check.line() in text and "not measured by this report" in text


def test_centre_of_mass_error_beside_the_state_error(quick_rows, tmp_path):
    for r in quick_rows:
        assert r.com_floor < 1e-8  # the references' centres of mass agree
        if r.status == "ok":
            assert r.com_error > 0 and math.isfinite(r.com_error)
            assert r.nfev > 0
            if r.method in ("RK45", "DOP853"):
                assert r.njev == r.nlu == 0
            if r.method in ("Radau", "BDF"):
                assert r.njev > 0 and r.nlu > 0
        else:
            assert math.isnan(r.com_error)
    for problem in QUICK_PROBLEMS:
        bdf = sorted(
            (r.rtol, r.com_error)
            for r in quick_rows
            if (r.problem, r.method) == (problem.name, "BDF")
        )
        assert bdf[0][1] < 0.1 * bdf[-1][1], (problem.name, bdf)
    wp.write_results(quick_rows, tmp_path)
    with open(tmp_path / "work_precision.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert {"com_error", "com_floor", "n_steps", "rhs_s", "jacobian_s", "integrator_s"} <= set(
        table[0]
    )
    assert "COM m" in wp.format_table(quick_rows)
