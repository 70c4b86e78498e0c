"""The work–precision report: quick run, files, convergence, references, the time cap.

No verdict here depends on the machine's speed: the quick run is given a cap far above
its longest run (a guard against a hang only), the RT-70 gets only the implicit methods
(the explicit ones are stiff-bound, a benchmark's finding), and the cap itself is tested
with a cap of 0 s and with a worker whose outcomes are given.
"""

import csv
import math
from dataclasses import replace

import numpy as np
import pytest

from rt70.model.scene import load_scene, scene_from_text
from rt70.reports import work_precision as wp
from rt70.reports import work_precision_results as wpr
from rt70.reports import work_precision_worker as wpw
from rt70.reports.work_precision_problems import QUICK_PROBLEMS, build_problem, light_damping_text
from rt70.testing import MIN_REL, assert_close

#: Cap of the quick run, s: its longest run takes ~0.3 s, so only a hang reaches it.
HANG_GUARD_S = 300.0
#: The quick problems, the RT-70 with the implicit methods only.
PROBLEMS = tuple(replace(p, stiff_only=True) if p.name == "rt70" else p for p in QUICK_PROBLEMS)


@pytest.fixture(scope="module")
def quick_rows():
    return wp.run(quick=True, problems=PROBLEMS, cap_s=HANG_GUARD_S)


def _com_scale(problem):
    """Largest centre-of-mass coordinate of the problem's bodies at its initial state, m."""
    scene, (q0, _), _ = build_problem(problem)
    return float(np.max(np.abs(wpw.com_positions(scene, q0[None, :]))))


@pytest.mark.slow
def test_quick_run_writes_files(quick_rows, tmp_path):
    paths = wpr.write_results(quick_rows, tmp_path)
    assert [p.name for p in paths] == ["work_precision.csv", "work_precision.png"]
    with open(tmp_path / "work_precision.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == len(quick_rows)
    assert {r["problem"] for r in table} == {p.name for p in QUICK_PROBLEMS}
    assert {r["method"] for r in table} == set(wp.METHODS)
    assert (tmp_path / "work_precision.png").stat().st_size > 10_000
    text = wpr.format_table(quick_rows)
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
                assert not ok  # explicit: not run on the stiff problem
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
        # the two references at rtol 1e-12 agree: a relative error, its scale is 1
        assert_close(r.reference_floor, 0.0, rel=1e-8, scale=1.0, what=r.problem)
        assert r.status == "ok" and r.error > 0 and r.time_s > 0 and not r.over_cap
        times = [float(t) for t in r.times_s.split(";")]
        # repeated unless the first attempt was long (times_s rounds to 0.1 ms: ≥, not >)
        assert len(times) == wp.QUICK_REPEATS or (
            len(times) == 1 and times[0] >= wp.REPEAT_BELOW_S
        ), r.times_s


class _GivenWorker:
    """A stand-in for :class:`~rt70.reports.work_precision_worker.Worker` whose attempts
    are given: ``outcomes[method]`` lists the statuses of its successive runs."""

    def __init__(self, outcomes):
        self.outcomes = {m: list(s) for m, s in outcomes.items()}
        self.calls = []
        self.nv, self.notes, self.threads = {}, {}, {}

    def run(self, problem, method, rtol, atol, cap):
        self.calls.append((method, rtol))
        self.nv[problem], self.notes[problem] = 2, "given"
        self.threads[problem] = (1, "openblas 2")
        status = self.outcomes[method].pop(0) if method in self.outcomes else "ok"
        if status != "ok":
            return wpw.Attempt(status)
        x = np.full((problem.t_eval.size, 4), 1.0 + rtol)
        com = np.zeros((problem.t_eval.size, 1, 3))
        return wpw.Attempt("ok", 0.01, 1e-3 * rtol, 10, 0, 0, x, com, 5)

    def close(self):
        pass


def test_a_run_over_the_cap_skips_the_tighter_tolerances(monkeypatch):
    """The cap's bookkeeping with given outcomes: a method over the cap is not run at the
    tighter tolerances; an attempt over it after good ones is dropped as noise."""
    worker = _GivenWorker({"RK45": ["over cap"], "BDF": ["ok", "over cap", "ok", "ok"]})
    monkeypatch.setattr(wp, "Worker", lambda: worker)
    pendulum = QUICK_PROBLEMS[1]
    rows = wp.run(quick=True, problems=(pendulum,), methods=("RK45", "BDF"), cap_s=1.0)
    by = {(r.method, r.rtol): r for r in rows}
    assert [by["RK45", t].status for t in wp.QUICK_RTOLS] == ["over cap", "over cap (not run)"]
    for t in wp.QUICK_RTOLS:
        row = by["RK45", t]
        assert row.over_cap and math.isnan(row.error) and math.isnan(row.com_error)
    assert [c for c in worker.calls if c[0] == "RK45"] == [("RK45", wp.QUICK_RTOLS[0])]
    assert [by["BDF", t].status for t in wp.QUICK_RTOLS] == ["ok", "ok"]
    assert by["BDF", wp.QUICK_RTOLS[0]].times_s == "0.0100"  # the attempt over the cap dropped
    assert by["BDF", wp.QUICK_RTOLS[1]].times_s == "0.0100;0.0100"


@pytest.mark.slow
def test_worker_abandons_a_run_over_a_zero_cap():
    """A cap of 0 s: over it whether the result comes back in time or the worker is
    killed waiting for it — the same outcome on any machine."""
    worker = wpw.Worker()
    try:
        got = worker.run(QUICK_PROBLEMS[1], "RK45", 1e-3, None, 0.0)
        assert got.status == "over cap" and got.x is None
        again = worker.run(QUICK_PROBLEMS[1], "DOP853", 1e-3, None, HANG_GUARD_S)
        assert again.status == "ok" and again.x.shape == (QUICK_PROBLEMS[1].t_eval.size, 4)
        uncapped = worker.run(QUICK_PROBLEMS[1], "DOP853", 1e-3, None, math.inf)
        assert uncapped.status == "ok" and np.array_equal(uncapped.x, again.x)
    finally:
        worker.close()


def test_light_damping_is_proportional():
    base = load_scene("rt70")
    delta = 0.05
    scene = scene_from_text(light_damping_text(base.text, delta), "rt70_light")
    old, new = base.description.bushings, scene.description.bushings
    assert [b.name for b in new] == [b.name for b in old] and len(new) == 11
    for a, b in zip(old, new, strict=True):
        np.testing.assert_array_equal(b.stiffness, a.stiffness)
        # δ·k written to the text and read back: rounding only
        assert_close(b.damping, delta * a.stiffness, rel=MIN_REL)
    assert scene.textbook.nv == base.textbook.nv == 42


def test_runs_are_timed_with_pinned_threads(quick_rows):
    from rt70.reports.threads import pools

    assert {r.threads for r in quick_rows} == {1}  # read back from the worker's pools
    unpinned = {r.threads_unpinned for r in quick_rows}
    assert len(unpinned) == 1 and "openblas" in unpinned.pop()
    assert "BLAS/OpenMP threads in the worker: 1 (unpinned: " in wpr.format_table(quick_rows)
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
    (check,) = wpr.check_targets(rows)
    assert check.target.startswith("rt70 (listing damping, T = 2 s) to state error ≤ 1e-06 in")
    assert "≤ 0.04 s of integration, i.e. ≥ 50× real time" in check.target
    assert check.measured.startswith("0.450 s, 4.4× real time (BDF, rtol 1e-07")
    assert check.met is False and check.line().endswith("— NOT met")
    fast = [_fake("rt70", "BDF", 1e-7, "ok", 4e-7, 0.039)]
    assert wpr.check_targets(fast)[0].met is True
    (none,) = wpr.check_targets(rows[:1] + rows[3:])
    assert none.met is False and "no method reached it" in none.measured
    assert wpr.check_targets(rows[-1:])[0].met is None
    quick = [_fake("rt70", "BDF", 1e-6, "ok", 4e-7, 0.0001, t_end=0.05)]  # 500× but 0.05 s
    assert wpr.check_targets(quick)[0].met is None
    assert wpr.check_targets(quick)[0].line().endswith("under the report's 2 s — not judged")
    text = wpr.format_table(rows)
    assert check.line() in text and "not measured by this report" in text


@pytest.mark.slow
def test_centre_of_mass_error_beside_the_state_error(quick_rows, tmp_path):
    size = {p.name: _com_scale(p) for p in PROBLEMS}
    for r in quick_rows:
        # the references' centres of mass agree, relative to the bodies' distances
        assert_close(r.com_floor, 0.0, rel=1e-8, scale=size[r.problem], what=r.problem)
        assert r.status == "ok" and r.com_error > 0 and math.isfinite(r.com_error)
        assert r.nfev > 0
        if r.method in ("RK45", "DOP853"):
            assert r.njev == r.nlu == 0
        if r.method in ("Radau", "BDF"):
            assert r.njev > 0 and r.nlu > 0
    for problem in QUICK_PROBLEMS:
        bdf = sorted(
            (r.rtol, r.com_error)
            for r in quick_rows
            if (r.problem, r.method) == (problem.name, "BDF")
        )
        assert bdf[0][1] < 0.1 * bdf[-1][1], (problem.name, bdf)
    wpr.write_results(quick_rows, tmp_path)
    with open(tmp_path / "work_precision.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert {"com_error", "com_floor", "n_steps", "rhs_s", "jacobian_s", "integrator_s"} <= set(
        table[0]
    )
    assert "COM m" in wpr.format_table(quick_rows)


class _FakeConn:
    """The worker's end of the pipe: ``requests`` in, each message sent to ``on_send``."""

    def __init__(self, requests, on_send):
        self.requests, self.send = [*requests, None], on_send

    def recv(self):
        return self.requests.pop(0)


def test_the_worker_loads_a_method_before_its_first_timed_run(monkeypatch):
    """A method's first call on a problem (a compiled method's compile) happens before the
    worker says "ready", outside the capped wait: once per (problem, method), a short
    span; a failure there is left to the timed run, which reports it."""
    import rt70.simulation.simulate as sim

    pendulum = QUICK_PROBLEMS[1]
    scene, x0, notes = build_problem(pendulum)
    calls, events, original = [], [], sim.simulate

    def simulate(scene, t_span, **kw):
        calls.append((kw["method"], t_span[1], kw["rtol"]))
        if t_span[1] < pendulum.t_end and kw["method"] == "LSODA":
            raise RuntimeError("not in the loading run")
        return original(scene, t_span, **kw)

    monkeypatch.setattr(sim, "simulate", simulate)
    monkeypatch.setattr(wpw, "_CACHE", {pendulum: (scene, x0, notes)})
    monkeypatch.setattr(wpw, "_LOADED", set())
    requests = [(pendulum, m, 1e-6, None) for m in ("BDF", "BDF", "LSODA")]
    wpw._serve(_FakeConn(requests, lambda msg: events.append((msg[0], len(calls)))), "none")
    short = wpw._LOAD_FRACTION * pendulum.t_end
    assert calls == [
        ("BDF", short, 1e-3), ("BDF", pendulum.t_end, 1e-6), ("BDF", pendulum.t_end, 1e-6),
        ("LSODA", short, 1e-3), ("LSODA", pendulum.t_end, 1e-6),
    ]  # fmt: skip
    # "ready" after the loading run, the timed run after "ready"
    assert events == [("ready", 1), ("result", 2), ("ready", 2), ("result", 3),
                      ("ready", 4), ("result", 5)]  # fmt: skip
