"""The RT-70's wind pointing budget: the table, the error against wind speed, the maps (issue 11).

On ``rt70_servo`` (both servos closed, front wind unless said):

- the budget table, wind 5, 10, 15, 20 m/s × elevation 15°, 45°, 90°, with each case's
  modes (``rt70.reports.pointing_budget``);
- the main mirror's steady and gust error against wind speed for six elevations (a sweep
  on a local Dask cluster, quantity ``pointing``);
- maps over elevation × wind direction at 10 m/s of the first locked-rotor frequency
  (with the wind's aerodynamic stiffness) and of the pointing error (the same sweep
  machinery);
- the modes' shares of the gust variance at 10 m/s, 45°.

Writes validation/results/pointing_budget.{json,md} and pointing_vs_speed.png,
pointing_maps.png, pointing_modes.png. Run: ``python validation/pointing_budget.py``
(about 6 minutes on this 2-core machine).
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np
from distributed import Client

from rt70.guards.atomic import atomic_write, atomic_write_text
from rt70.model.scene import load_scene
from rt70.plotting.wind import error_vs_speed_figure, maps_figure, mode_shares_figure
from rt70.reports.pointing_budget import TARGET_ARCSEC, budget_table, format_table
from rt70.reports.provenance import command_line, headed, run_header
from rt70.sweep.cluster import local_cluster, on_dask
from rt70.sweep.run import make_grid, plan, run
from rt70.telescope.pointing import PointingCase, pointing_budget

OUT = Path(__file__).resolve().parent / "results"
SPEEDS = (2.0, 3.0, 5.0, 7.0, 10.0, 14.0, 20.0, 25.0)
ELEVATIONS = (15.0, 30.0, 45.0, 60.0, 75.0, 90.0)
MAP_ELEVATIONS = tuple(float(e) for e in range(0, 91, 10))
MAP_DIRECTIONS = tuple(float(d) for d in range(0, 360, 30))
MAP_SPEED = 10.0
#: The cases whose mode shares are drawn: (elevation, wind direction, what it is).
MODE_CASES = ((45.0, 0.0, "front wind"), (90.0, 0.0, "horizontal wind"), (30.0, 90.0, "side wind"))


def _save(fig, name: str) -> None:
    atomic_write(OUT / name, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    scene = load_scene("rt70_servo")
    start = time.perf_counter()
    budgets = budget_table(scene)
    table_s = time.perf_counter() - start
    table = format_table(budgets)
    print(table)
    with local_cluster(2) as cluster, Client(cluster) as client:
        speed = run(
            plan("rt70_servo", make_grid({"elevation": ELEVATIONS, "wind": SPEEDS}), ["pointing"]),
            on_dask(client),
            workers=2,
            progress=True,
        )
        maps = run(
            plan(
                "rt70_servo",
                make_grid(
                    {"elevation": MAP_ELEVATIONS, "wind": (MAP_SPEED,), "direction": MAP_DIRECTIONS}
                ),
                ["pointing"],
            ),
            on_dask(client),
            workers=2,
            progress=True,
        )
    for r in (speed, maps):
        if r.errors:
            raise SystemExit(f"failed points: {r.errors}")
    a = speed.arrays
    steady = {e: a["pointing_steady"][i, 0, :, 0] for i, e in enumerate(ELEVATIONS)}
    gust = {e: a["pointing_gust"][i, 0, :, 0] for i, e in enumerate(ELEVATIONS)}
    _save(
        error_vs_speed_figure(
            SPEEDS, steady, gust, target=TARGET_ARCSEC,
            title="rt70_servo, front wind, servos closed: main-mirror axis error vs wind speed",
        ),
        "pointing_vs_speed.png",
    )  # fmt: skip
    m = maps.arrays
    total = np.hypot(m["pointing_steady"], m["pointing_gust"])[:, 0, 0, :]
    _save(
        maps_figure(
            MAP_ELEVATIONS,
            MAP_DIRECTIONS,
            m["first_frequency_wind"][:, 0, 0, :],
            total,
            MAP_SPEED,
            title="rt70_servo at azimuth 0, 10 m/s: first locked-rotor frequency with the wind's "
            "stiffness, and √(steady² + gust rms²) of the main-mirror axis",
        ),
        "pointing_maps.png",
    )
    cases = []
    for e, d, what in MODE_CASES:
        b = pointing_budget(scene, PointingCase(e, 0.0, 10.0, d))
        shares = [("quasi-static", None, b.extra["quasi_static_share"])]
        shares += [(md.label, md.frequency_hz, md.share) for md in b.modes]
        cases.append((f"{what}, elevation {e:g}°", shares))
    _save(
        mode_shares_figure(
            cases, title="10 m/s: shares of the main-mirror axis's gust variance (servos closed)"
        ),
        "pointing_modes.png",
    )
    exponents = {e: float(np.polyfit(np.log(SPEEDS), np.log(steady[e]), 1)[0]) for e in ELEVATIONS}
    out = {
        "scene": scene.name,
        "table": [b.to_dict() for b in budgets],
        "table_seconds": table_s,
        "steady_exponent_by_elevation": exponents,
        "speed_sweep": {
            "speeds": list(SPEEDS),
            "elevations": list(ELEVATIONS),
            "steady": {str(e): steady[e].tolist() for e in ELEVATIONS},
            "gust": {str(e): gust[e].tolist() for e in ELEVATIONS},
            "wall_time_s": speed.metadata["wall_time_s"],
        },
        "maps": {
            "elevations": list(MAP_ELEVATIONS),
            "directions": list(MAP_DIRECTIONS),
            "first_frequency_range_hz": [
                float(np.nanmin(m["first_frequency_wind"])),
                float(np.nanmax(m["first_frequency_wind"])),
            ],
            "pointing_range_arcsec": [float(total.min()), float(total.max())],
            "wall_time_s": maps.metadata["wall_time_s"],
        },
    }
    atomic_write_text(OUT / "pointing_budget.json", json.dumps(out, indent=2) + "\n")
    page = "# RT-70 wind pointing budget (rt70_servo, front wind, servos closed)\n\n" + table
    atomic_write_text(OUT / "pointing_budget.md", headed(page, run_header(command_line())) + "\n")
    print(f"steady-error exponents (fit over {SPEEDS[0]:g}–{SPEEDS[-1]:g} m/s): {exponents}")
    print(f"sweeps: {speed.metadata['wall_time_s']:.0f} s and {maps.metadata['wall_time_s']:.0f} s")


if __name__ == "__main__":
    main()
