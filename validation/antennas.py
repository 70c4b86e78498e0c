"""Every antenna scene through the servo engineer's chain: servo, step, wind, linear check.

For ``antenna_12m``, ``antenna_34m`` and the RT-70's ``rt70_servo``:

- the servo design on the scene's own model (``rt70 servo``): each axis's position
  bandwidth (declared or tuned), the least margins of its loops over the elevation range
  and the closed-loop bandwidth;
- a 1° elevation step and a 1° azimuth step at 45° with the scene's drives: the settling
  time measured against the one its bandwidth predicts, the overshoot, the peak torque
  against the limit (a figure per scene, of the elevation step);
- the steady pointing error under a front wind of 10 and 20 m/s at 30°: their ratio
  against the quadratic law's 4;
- a 20″ step on each axis, nonlinear against the linear closed loop
  (:mod:`rt70.telescope.step_check`).

Writes validation/results/antennas.{json,md} and antennas_<scene>_step.png. Run:
``python validation/antennas.py`` (about 3 minutes on this 2-core machine).
"""

import argparse
import json
import time
from pathlib import Path

from rt70.guards.atomic import atomic_write, atomic_write_text
from rt70.model.scene import load_scene
from rt70.plotting.servo import servo_figure
from rt70.reports.provenance import command_line, headed, run_header
from rt70.telescope import scenarios as S
from rt70.telescope.pointing import PointingCase, pointing_budget
from rt70.telescope.scene_servo import choose_drives
from rt70.telescope.servo_design import design
from rt70.telescope.step_check import small_step

OUT = Path(__file__).resolve().parent / "results"
SCENES = ("antenna_12m", "antenna_34m", "rt70_servo")
#: Length of the 1° steps, s, by scene (the 34-m and the RT-70 slew for seconds).
STEP_T_END = {"antenna_12m": 6.0, "antenna_34m": 15.0, "rt70_servo": 40.0}
#: Length of the 20″ steps, s.
SMALL_T_END = {"antenna_12m": 3.0, "antenna_34m": 6.0, "rt70_servo": 10.0}


def _scene_row(name: str) -> dict:
    scene = load_scene(name)
    row: dict = {"scene": name}
    servo = design(scene)
    row["servo"] = {
        axis: {
            "position_bandwidth_hz": hz,
            "tuned": servo.tuned[axis],
            "closed_loop_bandwidth_hz": servo.bandwidth_hz[axis],
            "margins": {k: [m.gm_db, m.pm_deg] for k, m in servo.margins[axis].items()},
        }
        for axis, (hz, _) in servo.tuning.items()
    }
    row["servo_adequate"], row["design_s"] = servo.adequate, servo.seconds
    drives, _ = choose_drives(scene, None)
    row["steps"] = {}
    for axis in ("elevation", "azimuth"):
        run = S.run_scenario(
            scene, S.scenario(f"step-{axis}", 45.0, 0.0, STEP_T_END[name]), drives=drives
        )
        m = run.metrics
        row["steps"][axis] = {
            k: m[k]
            for k in (
                "axis_settle_s",
                "predicted_settle_s",
                "overshoot_pct",
                "final_pointing_arcsec",
            )
        }
        row["steps"][axis]["peak_of_limit"] = m[f"peak_torque_{axis}_of_limit"]
        if axis == "elevation":
            fig = servo_figure(run)
            atomic_write(
                OUT / f"antennas_{name}_step.png",
                lambda tmp, f=fig: f.savefig(tmp, dpi=90, format="png"),
            )
    steady = [
        pointing_budget(scene, PointingCase(30.0, 0.0, v, 0.0)).steady["main_mirror_error"]
        for v in (10.0, 20.0)
    ]
    row["wind"] = {
        "steady_10_arcsec": steady[0],
        "steady_20_arcsec": steady[1],
        "ratio": steady[1] / steady[0],
    }
    row["small_step"] = {}
    for axis in ("azimuth", "elevation"):
        c = small_step(scene, axis, 45.0, SMALL_T_END[name])
        row["small_step"][axis] = {
            "difference": c.difference,
            "settle_nonlinear_s": c.settle_nonlinear_s,
            "settle_linear_s": c.settle_linear_s,
        }
    return row


def _markdown(rows: list[dict], header: str) -> str:
    lines = ["# Antennas through the servo engineer's chain", "", header, ""]
    lines += [
        "| scene | axis | position loop, Hz | closed loop, Hz | least GM / PM (position, rate) |"
        " 1° step: settle (predicted), s | overshoot | peak torque / limit |"
        " 20″ step: max |nonlinear − linear| / step |",
        "|---|---|---:|---:|---|---|---:|---:|---:|",
    ]
    for r in rows:
        for axis, s in r["servo"].items():
            how = "tuned" if s["tuned"] else "declared"
            gm = s["margins"]
            st = r["steps"][axis]
            lines.append(
                f"| {r['scene']} | {axis} | {s['position_bandwidth_hz']:.3g} ({how}) | "
                f"{s['closed_loop_bandwidth_hz']:.3g} | "
                f"{gm['position'][0]:.1f} dB / {gm['position'][1]:.0f}°, "
                f"{gm['rate'][0]:.1f} dB / {gm['rate'][1]:.0f}° | "
                f"{st['axis_settle_s']:.3g} ({st['predicted_settle_s']:.3g}) | "
                f"{st['overshoot_pct']:.1f} % | {st['peak_of_limit']:.2f} | "
                f"{r['small_step'][axis]['difference']:.1e} |"
            )
    lines += [
        "",
        "Steady main-mirror error under a front wind at elevation 30° (quadratic law: ratio 4):",
        "",
    ]
    lines += ["| scene | 10 m/s, ″ | 20 m/s, ″ | ratio |", "|---|---:|---:|---:|"]
    for r in rows:
        w = r["wind"]
        lines.append(
            f"| {r['scene']} | {w['steady_10_arcsec']:.4g} | {w['steady_20_arcsec']:.4g} | "
            f"{w['ratio']:.6f} |"
        )
    lines += ["", "Figures: " + ", ".join(f"`antennas_{r['scene']}_step.png`" for r in rows), ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    start = time.perf_counter()
    rows = []
    for name in SCENES:
        t = time.perf_counter()
        rows.append(_scene_row(name))
        print(f"{name}: {time.perf_counter() - t:.1f} s", flush=True)
    header = run_header(command_line())
    atomic_write_text(OUT / "antennas.json", json.dumps(rows, indent=1) + "\n")
    atomic_write_text(OUT / "antennas.md", headed(_markdown(rows, header), header))
    print(_markdown(rows, header))
    print(f"total {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
