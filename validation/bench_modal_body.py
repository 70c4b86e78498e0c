"""Cost of a modal body: the RT-70's right-hand side with a 30-mode flexible body (issue 24).

Target: a 30-mode flexible body adds at most 2× to the RT-70's right-hand-side cost. The
scene ``rt70_servo`` against the same scene with a modal body on the main mirror: the
slewing truss's space frame (24 nodes, rt70.scenes.modal_scenes.truss_arm) with k of its
modes, k = 8 and 30. On each side the simulation's right-hand side
(:mod:`rt70.simulation.backends`: q̈ with gravity, springs and dampers) is timed against
the same side's on ``rt70_servo``, interleaved, per round, BLAS threads pinned to one
(:mod:`rt70.reports.threads`); the median of the per-round ratios is reported with the
best time of each call.

    python validation/bench_modal_body.py [--rounds 9]

writes ``validation/results/bench_modal_body.md``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

from rt70.guards.atomic import atomic_write_text
from rt70.model.scene import load_scene, scene_from_text
from rt70.reports.bench import compare
from rt70.reports.provenance import command_line, headed, run_header
from rt70.reports.threads import single_threaded
from rt70.scenes import modal_scenes
from rt70.scenes.rt70_scenes import rt70_servo_scene
from rt70.simulation.backends import BACKENDS
from rt70.urdf.modal_file import write_modal_file

RESULTS = Path(__file__).resolve().parent / "results"
TARGET = 2.0
MODES = (8, 30)


def flexible_scene(modes: int, directory: Path):
    """``rt70_servo`` with the truss (``modes`` modes) as a modal body on the main mirror."""
    path = write_modal_file(directory / f"truss_{modes}.npz", modal_scenes.truss_arm(modes))
    body = f'<rt70:modal_body name="truss" link="main_mirror" file="{path}" damping_ratio="0.01"/>'
    return scene_from_text(rt70_servo_scene().replace("</robot>", body + "</robot>"), "rt70_modal")


def rhs(scene, side: str):
    """The simulation's q̈ on ``side`` at a small state (seed 0), as a call."""
    backend = BACKENDS[side](scene)
    rng = np.random.default_rng(0)
    q = rng.uniform(-1e-3, 1e-3, scene.textbook.nv)
    qd = rng.uniform(-1e-3, 1e-3, scene.textbook.nv)
    return lambda: backend.accelerations(q, qd, None)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9, help="interleaved rounds (default 9)")
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error("--rounds must be at least 1")
    rigid = load_scene("rt70_servo")
    rows = []
    with tempfile.TemporaryDirectory() as tmp, single_threaded() as pinning:
        for modes in MODES:
            scene = flexible_scene(modes, Path(tmp))
            for side in ("textbook", "reference"):
                t_flex, t_rigid, ratio = compare(
                    rhs(scene, side), rhs(rigid, side), rounds=args.rounds, budget_s=0.05
                )
                rows.append((modes, scene.textbook.nv, side, t_flex, t_rigid, ratio))
    lines = [
        "# The RT-70's right-hand side with a modal body",
        "",
        f"`python validation/bench_modal_body.py --rounds {args.rounds}`; {pinning.describe()}.",
        "Median of the per-round ratios; best time of each call.",
        "",
        "| modes | nv | side | with the body µs | rt70_servo µs | ratio |",
        "|---|---|---|---|---|---|",
    ]
    for modes, nv, side, t_flex, t_rigid, ratio in rows:
        lines.append(
            f"| {modes} | {nv} | {side} | {t_flex * 1e6:.0f} | {t_rigid * 1e6:.0f} | {ratio:.2f} |"
        )
    lines += ["", f"Target (issue 24): ratio ≤ {TARGET:g} with 30 modes."]
    for modes, _, side, _, _, ratio in rows:
        if modes == 30:
            verdict = "met" if ratio <= TARGET else "NOT met"
            lines.append(f"- {side}: {ratio:.2f} — {verdict}")
    report = "\n".join(lines) + "\n"
    RESULTS.mkdir(exist_ok=True)
    atomic_write_text(RESULTS / "bench_modal_body.md", headed(report, run_header(command_line())))
    sys.stdout.write(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
