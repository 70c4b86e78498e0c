"""The benchmark command runs and writes its table, CSV and plot (no timing asserted)."""

import csv

from rt70.cli import main


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
