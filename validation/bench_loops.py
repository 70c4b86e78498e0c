"""Cost of the constrained forward dynamics: the RT-70 with one closed loop (issue 12).

Target: the constrained forward dynamics of the RT-70 with one loop added costs no more
than 3× the unconstrained call. The scene is ``rt70_jack`` (the 42-DOF RT-70 and an
elevation jack closing one loop on the counterweight, 44 coordinates, 3 rows); on each
side the constrained call (``constrained_forward_dynamics``: gravity, springs, dampers,
the KKT system with the default Baumgarte stabilisation) is timed against the same
side's unconstrained forward dynamics of the same scene (the tree: ``forward_dynamics``
with the same springs and dampers), interleaved, per round, with BLAS threads pinned to
one (:mod:`rt70.reports.threads`); the median of the per-round ratios is reported with
the best time of each call. The four-bar and the crank–slider are timed the same way.

    python validation/bench_loops.py [--rounds 9]

writes ``validation/results/bench_loops.{md,csv}``.
"""

from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path

import numpy as np

from rt70 import reference
from rt70.guards.atomic import atomic_write_text
from rt70.model.scene import load_scene
from rt70.physics.baumgarte import DEFAULT_STABILIZATION
from rt70.reference import loops as ref_loops
from rt70.reports.bench import compare
from rt70.reports.provenance import command_line, headed, run_header
from rt70.reports.threads import single_threaded
from rt70.simulation.closed_chains import assemble
from rt70.textbook import dynamics, forces
from rt70.textbook import loops as tb_loops

RESULTS = Path(__file__).resolve().parent / "results"
TARGET = 3.0
SCENES = ("rt70_jack", "four_bar", "crank_slider")


def _state(scene) -> tuple[np.ndarray, np.ndarray]:
    """A closed state with small random deflections and rates (seed 0)."""
    rng = np.random.default_rng(0)
    n = scene.textbook.nv
    return assemble(scene, rng.uniform(-0.01, 0.01, n), rng.uniform(-0.01, 0.01, n))


def timings(name: str, rounds: int) -> list[dict]:
    """Constrained against unconstrained forward dynamics on each side of one scene."""
    scene = load_scene(name)
    q, qd = _state(scene)
    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    gains = DEFAULT_STABILIZATION

    def tb_free():
        Qc, Qd = forces.spring_damper_force(tm, td, q, qd)
        return dynamics.forward_dynamics(tm, td, q, qd, Qc + Qd)

    def tb_closed():
        return tb_loops.constrained_forward_dynamics(tm, td, q, qd, stabilization=gains)

    def ref_free():
        return reference.forward_dynamics(ref, rd, q, qd)

    def ref_closed():
        return ref_loops.constrained_forward_dynamics(ref, rd, q, qd, stabilization=gains)

    rows = []
    sides = (("textbook", tb_closed, tb_free), ("reference", ref_closed, ref_free))
    for side, closed, free in sides:
        t_closed, t_free, ratio = compare(closed, free, rounds=rounds, budget_s=0.05)
        rows.append(
            {
                "scene": name,
                "nv": tm.nv,
                "rows": tb_loops.loop_rows(tm),
                "side": side,
                "constrained_us": t_closed * 1e6,
                "unconstrained_us": t_free * 1e6,
                "ratio": ratio,
            }
        )
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9, help="interleaved rounds (default 9)")
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error("--rounds must be at least 1")
    rows = []
    with single_threaded() as pinning:
        for name in SCENES:
            rows.extend(timings(name, args.rounds))
    lines = [
        "# Constrained forward dynamics against the unconstrained call",
        "",
        f"`python validation/bench_loops.py --rounds {args.rounds}`; {pinning.describe()}.",
        "Median of the per-round ratios; best time of each call.",
        "",
        "| scene | nv | loop rows | side | constrained µs | unconstrained µs | ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['nv']} | {r['rows']} | {r['side']} | "
            f"{r['constrained_us']:.1f} | {r['unconstrained_us']:.1f} | {r['ratio']:.2f} |"
        )
    jack = [r for r in rows if r["scene"] == "rt70_jack"]
    lines += ["", f"Target (issue 12): ratio ≤ {TARGET:g} on rt70_jack."]
    for r in jack:
        verdict = "met" if r["ratio"] <= TARGET else "NOT met"
        lines.append(f"- {r['side']}: {r['ratio']:.2f} — {verdict}")
    report = "\n".join(lines) + "\n"
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    RESULTS.mkdir(exist_ok=True)
    atomic_write_text(RESULTS / "bench_loops.md", headed(report, run_header(command_line())))
    atomic_write_text(RESULTS / "bench_loops.csv", buffer.getvalue())
    sys.stdout.write(report)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
