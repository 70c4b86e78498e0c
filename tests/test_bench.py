"""The benchmark command: table, CSV and plot, pinned threads, targets, where it writes.

No timing is asserted (performance is measured by the benchmark, not by tests).
"""

import csv

import numpy as np
import pytest
from threadpoolctl import threadpool_info

from rt70.cli.main import main
from rt70.reports import bench
from rt70.reports.threads import pools, single_threaded


@pytest.mark.slow
def test_bench_quick_writes_results(tmp_path, capsys):
    assert main(["bench", "--quick", "--K", "20", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "per_call" in out and "batched" in out and "exponent" in out
    with open(tmp_path / "mass_matrix_bench.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    benchmarks = {r["benchmark"] for r in rows}
    assert {"per_call", "batched", "scaling_chain", "scaling_tree"} <= benchmarks
    assert {r["target"] for r in rows if r["benchmark"] == "per_call"} >= {"rt70", "talos_full"}
    assert (tmp_path / "mass_matrix_bench.png").stat().st_size > 10_000
    # timed with every thread pool pinned to one thread, and the default recorded
    assert {r["threads"] for r in rows} == {"1"}
    assert {r["threads_unpinned"] for r in rows} == {pools()}
    assert "BLAS/OpenMP threads during timing: 1 (unpinned: " in out
    # every target is printed with its verdict; a quick run does not judge K = 1000 or growth
    for goal in ("per-call ratio ≤ 10 on rt70", "per-call ratio ≤ 10 on talos_full"):
        assert any(
            line.startswith(f"target {goal} — measured ") and line.endswith(("— met", "— NOT met"))
            for line in out.splitlines()
        ), goal
    assert "target batched ratio ≤ 1 at K = 1000 on rt70 — measured " in out
    assert " at K = 20 — not judged" in out
    assert "(nv 10–50 only) — not judged" in out


def _row(benchmark, target, nv, ratio, t=1e-5, K=1):
    return bench.Row(benchmark, target, nv, K, t, t / ratio, ratio, 1, "openblas 2")


def _chain(exponent):
    """Chain rows whose time grows as nv^exponent from 100 up, flat below (overhead)."""
    rows = [_row("scaling_chain", "chain_10", 10, 1.0, t=1e-4)]
    return rows + [
        _row("scaling_chain", f"chain_{n}", n, 1.0, t=1e-4 * (n / 100) ** exponent)
        for n in (100, 200, 400)
    ]


def test_targets_are_judged_against_the_measured_values():
    rows = [
        _row("per_call", "rt70", 42, 7.5),
        _row("per_call", "talos_full", 32, 13.8),
        _row("batched", "rt70", 42, 0.9, K=1000),
    ]
    growth = "chain exponent ≤ 2.2 (fitted on nv ≥ 100)"
    checks = {c.target: c for c in bench.check_targets(rows + _chain(1.5))}
    assert checks["per-call ratio ≤ 10 on rt70"].met is True
    assert checks["per-call ratio ≤ 10 on talos_full"].met is False
    assert checks["batched ratio ≤ 1 at K = 1000 on rt70"].met is True
    assert checks[growth].met is True and checks[growth].measured == "1.50 (nv 100–400)"
    steep = {c.target: c for c in bench.check_targets(rows + _chain(2.5))}[growth]
    assert steep.met is False and steep.line().endswith("— NOT met")
    assert [c.met for c in bench.check_targets([])] == [None] * 4


def test_single_threaded_pins_every_pool_and_restores_it():
    with single_threaded() as pinning:
        inside = threadpool_info()
        a = np.random.default_rng(0).standard_normal((200, 200))
        np.linalg.solve(a, a)
    assert inside and all(p["num_threads"] == 1 for p in inside)
    assert pinning.pinned == 1
    assert pinning.unpinned == pools()  # restored on leaving
    assert pinning.describe() == f"BLAS/OpenMP threads pinned to 1 (unpinned: {pools()})"


def test_default_output_is_not_the_committed_results(tmp_path, monkeypatch, capsys):
    """`rt70 bench` inside a clone must not overwrite validation/results (issue 8)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(bench, "run", lambda **_kw: [_row("per_call", "rt70", 42, 7.5)])
    assert main(["bench"]) == 0
    assert sorted(p.name for p in (tmp_path / "rt70-results").iterdir()) == [
        "mass_matrix_bench.csv",
        "mass_matrix_bench.png",
    ]
    assert not (tmp_path / "validation").exists()
    assert "target per-call ratio ≤ 10 on rt70 — measured 7.50 — met" in capsys.readouterr().out


def test_validation_script_writes_the_committed_results(monkeypatch):
    """validation/bench_mass_matrix.py regenerates validation/results unless told otherwise."""
    import runpy
    from pathlib import Path

    import rt70.cli.main

    script = Path(__file__).parents[1] / "validation" / "bench_mass_matrix.py"
    calls = []
    monkeypatch.setattr(rt70.cli.main, "main", lambda argv: calls.append(argv) or 0)
    for argv in (["--quick"], ["--out", "elsewhere"]):
        monkeypatch.setattr("sys.argv", [str(script), *argv])
        with pytest.raises(SystemExit) as done:
            runpy.run_path(str(script), run_name="__main__")
        assert done.value.code == 0
    assert calls == [
        ["bench", "--quick", "--out", str(script.parent / "results")],
        ["bench", "--out", "elsewhere"],
    ]


def test_large_targets_time_a_subprocess_and_judge_it(tmp_path):
    """`rt70 bench large`'s pieces: a whole command's wall time and peak memory, and the verdict
    (a failed command is never met; a quick run is not judged)."""
    from rt70.reports import large_targets as lt

    wall, peak, code, last = lt.run_command(["--version"], tmp_path)
    assert code == 0 and last.startswith("rt70 ")
    assert wall > 0.0 and 0.0 < peak < lt.MEMORY_TARGET_GB
    ok = lt._judged(["modes", "x"], 5.0, (1.0, 0.5, 0, ""), 2004, quick=False)
    slow = lt._judged(["modes", "x"], 5.0, (9.0, 0.5, 0, ""), 2004, quick=False)
    big = lt._judged(["modes", "x"], 5.0, (1.0, 5.0, 0, ""), 2004, quick=False)
    failed = lt._judged(["simulate", "x"], 30.0, (0.1, 0.1, 2, "rt70: error: no"), 2004, False)
    assert (ok.met, slow.met, big.met, failed.met) == (True, False, False, False)
    assert "rt70: error: no" in failed.measured
    assert lt._judged(["modes", "x"], 5.0, (1.0, 0.5, 0, ""), 360, quick=True).met is None
    code = lt.run_command(["modes", str(tmp_path / "missing.urdf")], tmp_path)[2]
    assert code == 2
