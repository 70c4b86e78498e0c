"""Joint reactions (issue 12, part 1): the cross-check per scene and the RT-70's loads.

- The ``reactions`` row of ``rt70 validate`` for every scene in urdf/ (10 random states,
  seed 0): the largest relative error and both sides' mean time per evaluation.
- The two sides' time for the RT-70's reactions alone (rt70_servo, at the 45° calm
  equilibrium, with the wind's Wrenches at 20 m/s): median of 200 calls, one thread.
- The RT-70's bearing and reducer loads (:mod:`rt70.telescope.bearing_loads`) at elevations 0–90°
  every 15° — calm, 20 m/s front, back and from the side (azimuth 90°) — as the table
  of docs/reactions.md, and every 5° for the figure.

Writes validation/results/joint_reactions.{json,md,csv} and joint_reactions.png.
Run: ``python validation/joint_reactions.py`` (about a minute on this 2-core machine).
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from rt70.crosscheck.validate import cross_check
from rt70.guards.atomic import atomic_write, atomic_write_text
from rt70.model.scene import load_scene, scene_names
from rt70.physics.aerodynamics import WindCondition
from rt70.plotting.reactions import bearing_loads_figure
from rt70.reference import reactions as ref_reactions
from rt70.reference import wind as ref_wind
from rt70.reports.provenance import command_line, headed, run_header
from rt70.telescope import bearing_loads as bl
from rt70.textbook import reactions as tb_reactions
from rt70.textbook import wind as tb_wind

OUT = Path(__file__).resolve().parent / "results"
TABLE_ELEVATIONS = tuple(float(e) for e in range(0, 91, 15))
FIGURE_ELEVATIONS = tuple(float(e) for e in range(0, 91, 5))
SPEED = 20.0
#: wind direction (azimuth it blows from, the pointing at azimuth 0) → label
WINDS = {None: "calm", 0.0: "front", 180.0: "back", 90.0: "side (from 90°)"}


def _case(elevation: float, direction: float | None) -> bl.LoadCase:
    if direction is None:
        return bl.LoadCase(elevation)
    return bl.LoadCase(elevation, 0.0, SPEED, direction)


def _median_time(fn, repeat: int = 200) -> float:
    fn()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def validate_rows() -> list[dict]:
    rows = []
    for name in scene_names():
        scene = load_scene(name)
        records = cross_check(scene, samples=10, seed=0)
        record = next(r for r in records if r.quantity == "reactions")
        rows.append(
            {
                "scene": name,
                "nv": record.nv,
                "max_rel_err": record.max_rel_err,
                "max_abs_err": record.max_abs_err,
                "textbook_us": record.t_textbook_s * 1e6,
                "pinocchio_us": record.t_reference_s * 1e6,
            }
        )
        print(f"{name:<20} reactions max rel {record.max_rel_err:.2e}")
    return rows


def timing(scene) -> dict:
    case = bl.LoadCase(45.0)
    from rt70.scenes.rt70_state import rt70_pointing
    from rt70.telescope.scene_servo import SceneServoFactory, scene_equilibrium

    couplings = SceneServoFactory(side="reference").couplings(scene)
    q, _, _ = scene_equilibrium(scene, couplings, rt70_pointing(case.elevation_deg))
    zero = np.zeros(q.size)
    condition = WindCondition(SPEED, 0.0)
    tm, td, ref, rd = scene.textbook, scene.textbook_data, scene.reference, scene.reference_data
    tb_loads = list(tb_wind.wind_wrenches(tm, td, q, condition).values())
    ref_loads = list(ref_wind.wind_wrenches(ref, rd, q, condition).values())
    with threadpool_limits(1):
        t_tb = _median_time(lambda: tb_reactions.joint_reactions(tm, td, q, zero, zero, tb_loads))
        t_ref = _median_time(
            lambda: ref_reactions.joint_reactions(ref, rd, q, zero, zero, ref_loads)
        )
    return {"textbook_ms": t_tb * 1e3, "pinocchio_ms": t_ref * 1e3, "ratio": t_tb / t_ref}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    OUT.mkdir(exist_ok=True)
    checks = validate_rows()
    scene = load_scene("rt70_servo")
    times = timing(scene)
    print(f"reactions of rt70_servo: {times}")
    start = time.perf_counter()
    table = [bl.bearing_loads(scene, _case(e, d)) for e in TABLE_ELEVATIONS for d in WINDS]
    curves = {
        label if d is None else f"{SPEED:g} m/s {label}": [
            bl.bearing_loads(scene, _case(e, d)).row() for e in FIGURE_ELEVATIONS
        ]
        for d, label in WINDS.items()
    }
    loads_s = time.perf_counter() - start
    text = bl.format_table(scene.name, table, bl.bearing_joints(scene))
    print(text)
    bl.write_output(OUT / "joint_reactions.csv", table)
    fig = bearing_loads_figure(
        FIGURE_ELEVATIONS,
        curves,
        title="rt70_servo at rest, drives holding the pointing (azimuth 0): bearing and "
        "reducer loads",
    )
    atomic_write(OUT / "joint_reactions.png", lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    worst = max(b.sides_difference for b in table)
    out = {
        "validate_reactions": checks,
        "rt70_servo_reaction_times": times,
        "loads": [b.to_dict() for b in table],
        "loads_seconds": loads_s,
        "sides_max_rel_difference": worst,
    }
    atomic_write_text(OUT / "joint_reactions.json", json.dumps(out, indent=2) + "\n")
    lines = [
        "# Joint reactions: the cross-check and the RT-70's bearing and reducer loads",
        "",
        "Written by `python validation/joint_reactions.py`.",
        "",
        "## `rt70 validate`, row `reactions` (10 random states, seed 0)",
        "",
        "| scene | nv | max rel. error | max abs. error | textbook µs | Pinocchio µs |",
        "|---|---|---|---|---|---|",
        *(
            f"| {r['scene']} | {r['nv']} | {r['max_rel_err']:.2e} | {r['max_abs_err']:.2e} | "
            f"{r['textbook_us']:.0f} | {r['pinocchio_us']:.0f} |"
            for r in checks
        ),
        "",
        f"Reactions of rt70_servo alone (42 coordinates, 20 m/s wind Wrenches), median of 200 "
        f"calls, one thread: textbook {times['textbook_ms']:.2f} ms, Pinocchio "
        f"{times['pinocchio_ms']:.2f} ms ({times['ratio']:.1f}×).",
        "",
        "## RT-70 loads (rt70_servo, azimuth 0, kN and kN·m)",
        "",
        "```",
        text,
        "```",
        "",
    ]
    page = headed("\n".join(lines), run_header(command_line()))
    atomic_write_text(OUT / "joint_reactions.md", page)


if __name__ == "__main__":
    main()
