"""The servo scenarios with the book's dry friction on the full structure.

``rt70_servo`` with its scene drives and both servos closed, the book's dry friction on
both axes (:class:`rt70.control.friction.AxisFriction`, the linear zone of 10⁻⁶ of top
speed; what ``rt70 simulate rt70_servo --scenario S --friction`` runs), each scenario at
its default length and 45° elevation, rtol 1e-6, on CVODE (the scenarios' method) and,
for the steps, on LSODA too. Per run: integration wall time, evaluations, Jacobians,
the settling and the pointing error, or where and why the run stopped. BLAS/OpenMP
pinned to one thread; one run each (the failures are the result, not the speed).

Run: ``python validation/friction_runs.py`` (about a minute). Writes
validation/results/friction_runs.md.
"""

import argparse
from pathlib import Path

from rt70.errors import Rt70Error
from rt70.guards.atomic import atomic_write_text
from rt70.model.scene import load_scene
from rt70.reports.provenance import command_line, headed, run_header
from rt70.reports.threads import single_threaded
from rt70.telescope import scenarios as S
from rt70.telescope.scene_servo import SceneServoFactory

OUT = Path(__file__).resolve().parent / "results" / "friction_runs.md"
#: (scenario, method) of each run.
RUNS = (
    ("hold", "CVODE"),
    ("track", "CVODE"),
    ("step-elevation", "CVODE"),
    ("step-elevation", "LSODA"),
    ("step-azimuth", "CVODE"),
)


def result_cell(run) -> str:
    """What the run measured (:func:`rt70.telescope.servo_metrics.measure`)."""
    m = run.metrics
    parts = [f"final pointing error {m['final_pointing_arcsec']:.3g}″"]
    settle = m.get("axis_settle_s", m["settle_s"])
    parts.append(f"inside 1″ from {settle:.3g} s" if settle == settle else "not inside 1″")
    if "overshoot_pct" in m:
        parts.append(f"overshoot {m['overshoot_pct']:.3g} %")
    if "tracking_rms_arcsec" in m:
        parts.append(f"tracking rms {m['tracking_rms_arcsec']:.3g}″ after settling")
    return "; ".join(parts)


def rows(scene) -> list[str]:
    """One table row per run of :data:`RUNS`."""
    out = []
    for name, method in RUNS:
        sc = S.scenario(name, 45.0, 0.0)
        try:
            run = S.run_scenario(scene, sc, SceneServoFactory(friction=True), method=method)
        except Rt70Error as exc:
            out.append(f"| {name} {sc.t_end:g} s | {method} | — | stopped: {exc} |")
        else:
            r = run.result
            speed = f"{r.wall_time_s:.3g} s ({r.real_time_factor:.1f}×)"
            out.append(
                f"| {name} {sc.t_end:g} s | {method} | {r.nfev}, {r.njev}, {speed} "
                f"| {result_cell(run)} |"
            )
        print(out[-1], flush=True)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args()
    scene = load_scene("rt70_servo")
    with single_threaded():
        table = rows(scene)
    text = "\n".join(
        [
            "# Servo scenarios with dry friction",
            "",
            "rt70_servo, scene drives, the book's dry friction on both axes (zone 10⁻⁶ of "
            "top speed), 45°, default lengths, rtol 1e-6, BLAS pinned, one run each; "
            "integration wall time (× real time). docs/servo-scenarios.md explains the "
            "stops and the spread of the final errors.",
            "",
            "| scenario | method | evaluations, Jacobians, wall | result |",
            "|---|---|---|---|",
            *table,
            "",
        ]
    )
    atomic_write_text(OUT, headed(text, run_header(command_line())))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
