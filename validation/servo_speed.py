"""The servo-closed runs' speed: LSODA against CVODE, and the wind force per evaluation.

Measured in one process, BLAS/OpenMP pinned to one thread, rounds alternating between
the methods (best wall time of the rounds):

- ``rt70_servo``'s hold, track, step-elevation and step-azimuth scenarios, 10 s at 45°
  (:func:`rt70.telescope.scenarios.run_scenario` with the scene's drives, what ``rt70
  simulate rt70_servo --scenario S --t-end 10`` runs) with LSODA and with CVODE at rtol
  1e-6: wall time of the integration, evaluations, Jacobians, and the largest
  difference of the pointing error between the two methods (arc seconds);
- the wind's generalised force on ``rt70_servo`` (four exposed bodies) at a moved
  configuration: the compiled path the simulation uses
  (:func:`rt70.reference.wind.wind_force_function`) against Pinocchio's placements and
  point Jacobians (:func:`rt70.reference.wind.wind_force`), µs per call, and their
  difference.

Run: ``python validation/servo_speed.py [--rounds N]`` (about a minute). Writes
validation/results/servo_speed.md.
"""

import argparse
import time
from pathlib import Path

import numpy as np

from rt70.guards.atomic import atomic_write_text
from rt70.model.scene import load_scene
from rt70.physics.aerodynamics import WindCondition
from rt70.reference.wind import wind_force, wind_force_function
from rt70.reports.provenance import command_line, headed, run_header
from rt70.reports.threads import single_threaded
from rt70.telescope import scenarios as S
from rt70.telescope.scene_servo import choose_drives

OUT = Path(__file__).resolve().parent / "results" / "servo_speed.md"
SCENARIOS = ("hold", "track", "step-elevation", "step-azimuth")
METHODS = ("LSODA", "CVODE")
T_END = 10.0


def scenario_rows(scene, rounds: int) -> list[str]:
    """One table row per scenario: each method's best wall, evaluations, Jacobians."""
    rows = []
    drives, _ = choose_drives(scene, None)  # the scene's drives, as the command's default
    for name in SCENARIOS:
        sc = S.scenario(name, 45.0, 0.0, T_END)
        best: dict[str, tuple[float, object]] = {}
        for _ in range(rounds):
            for method in METHODS:
                run = S.run_scenario(scene, sc, drives=drives, method=method)
                wall = run.result.wall_time_s
                if method not in best or wall < best[method][0]:
                    best[method] = (wall, run)
        cells = []
        for method in METHODS:
            wall, run = best[method]
            r = run.result
            cells.append(f"{r.nfev}, {r.njev}, {wall:.3f} s ({T_END / wall:.0f}×)")
        a, b = (best[m][1].pointing_error_total for m in METHODS)
        rows.append(f"| {name} | {' | '.join(cells)} | {np.max(np.abs(a - b)):.1e}″ |")
        print(rows[-1], flush=True)
    return rows


def wind_row(scene, calls: int = 2000) -> str:
    """The wind force per call on both paths, and their largest difference."""
    ref, data = scene.reference, scene.reference_data
    fast = wind_force_function(ref, data)
    condition = WindCondition(10.0, 30.0)
    q = 0.01 * np.random.default_rng(0).standard_normal(scene.textbook.nv)
    times = {}
    for label, f in (("compiled", fast), ("pinocchio", lambda q, c: wind_force(ref, data, q, c))):
        f(q, condition)
        start = time.perf_counter()
        for _ in range(calls):
            f(q, condition)
        times[label] = (time.perf_counter() - start) / calls * 1e6
    a, b = fast(q, condition), wind_force(ref, data, q, condition)
    diff = np.max(np.abs(a - b)) / np.max(np.abs(b))
    return (
        f"wind force on rt70_servo (4 bodies, 10 m/s): compiled path {times['compiled']:.0f} µs "
        f"per call, Pinocchio path {times['pinocchio']:.0f} µs; largest difference {diff:.1e} "
        "of the largest entry"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="rounds per method (best of)")
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error("--rounds must be at least 1")
    scene = load_scene("rt70_servo")
    with single_threaded():
        rows = scenario_rows(scene, args.rounds)
        wind = wind_row(scene)
    print(wind)
    text = "\n".join(
        [
            "# Servo-closed runs: LSODA against CVODE",
            "",
            f"rt70_servo, {T_END:g} s at elevation 45°, rtol 1e-6, BLAS pinned, best of "
            f"{args.rounds} alternating rounds; integration wall time (× real time).",
            "",
            "| scenario | LSODA: evaluations, Jacobians, wall | CVODE: the same "
            "| largest pointing difference |",
            "|---|---|---|---|",
            *rows,
            "",
            wind + ".",
            "",
        ]
    )
    atomic_write_text(OUT, headed(text, run_header(command_line())))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
