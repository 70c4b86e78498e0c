"""Servo loops of the RT-70 around its linear plant: PI cascade against LQG (issue 10 item 4).

For both axes at elevations 10°, 45°, 80° on the ``rt70_servo`` scene: the margins of
the cascade's three loops (each broken at its error), the design position bandwidth the
PI cascade reaches with GM ≥ 6 dB and PM ≥ 30° in every loop (bisection), and the LQG
designed on a reduced plant and checked on the full plant (margins at the plant input,
bandwidth, step, wind-torque pointing error). Writes
validation/results/servo_loops.json and servo_loops_{open,closed}_{azimuth,elevation}.png.
Run: ``python validation/servo_loops.py [--quick | --figures]`` (about 7 minutes on 2
busy cores; --quick skips the bisection, --figures writes the figures only).
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from rt70.control import loop_measures, loops, lqg
from rt70.guards.atomic import atomic_write, atomic_write_text
from rt70.model.scene import load_scene
from rt70.plotting.servo_loops import plot_closed_loops, plot_open_loops
from rt70.reports import servo_loops as rs
from rt70.units import ARCSEC_PER_RAD

OUT = Path(__file__).resolve().parent / "results"
ELEVATIONS = (10.0, 45.0, 80.0)
AXES = ("azimuth", "elevation")
#: The pointing whose Bode diagrams are drawn (the worst case for azimuth: the dish
#: near the horizon, the largest inertia about the azimuth axis).
FIGURE_ELEVATION = 10.0


def _figures(scene, axis: str) -> dict[str, object]:
    ap = rs.axis_plant(scene, axis, FIGURE_ELEVATION)
    f = loop_measures.FREQ_HZ
    gains = loops.cascade_design(ap, rs.CASCADE_POSITION_HZ)
    ctrl = lqg.design(ap, weights=rs.LQG_WEIGHTS)
    open_loops = {f"cascade {k} loop": loops.loop_transfer(ap, gains, k) for k in loops.LOOPS}
    open_loops["LQG at the plant input"] = lqg.input_loop(ap, ctrl)
    responses = {k: loop_measures.siso_response(L) for k, L in open_loops.items()}
    margins = {k: loop_measures.margins(L) for k, L in open_loops.items()}
    where = f"RT-70 {axis}, elevation {FIGURE_ELEVATION:.0f}°"
    fig_open = plot_open_loops(
        f,
        responses,
        margins,
        f"{where}: open loops (cascade at {rs.CASCADE_POSITION_HZ} Hz design; LQG)",
    )
    cascade = loops.cascade_system(ap, gains)
    closed = lqg.lqg_system(ap, ctrl)
    # the pointing correction of the driven axis (4.159)–(4.163): Δα for azimuth, Δβ for
    # elevation; it is minus the beam's motion (arcsec per arcsec of reference)
    name, sym = ("pointing_da", "Δα") if axis == "azimuth" else ("pointing_db", "Δβ")
    curves = {
        "cascade: reference → axis angle": cascade["axis_angle", "reference"],
        "LQG: reference → axis angle": closed["axis_angle", "reference"],
        f"cascade: reference → −{sym} (pointing)": -cascade[name, "reference"] / ARCSEC_PER_RAD,
        f"LQG: reference → −{sym} (pointing)": -closed[name, "reference"] / ARCSEC_PER_RAD,
    }
    curves = {k: loop_measures.siso_response(T) for k, T in curves.items()}
    fig_closed = plot_closed_loops(
        f, curves, f"{where}: closed loops, PI cascade against LQG (full plant)"
    )
    return {
        f"servo_loops_open_{axis}.png": fig_open,
        f"servo_loops_closed_{axis}.png": fig_closed,
    }


def _finite(x):
    """The result with non-finite numbers as null (strict JSON): an infinite margin is none."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_finite(v) for v in x]
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--quick", action="store_true", help="skip the bisection")
    group.add_argument("--figures", action="store_true", help="write the figures only")
    args = parser.parse_args(argv)
    quick, figures_only = args.quick, args.figures
    start = time.perf_counter()

    def say(msg: str) -> None:
        print(f"  [{time.perf_counter() - start:6.1f} s] {msg}", file=sys.stderr, flush=True)

    scene = load_scene("rt70_servo")
    OUT.mkdir(exist_ok=True)
    for axis in AXES:
        for name, fig in _figures(scene, axis).items():
            path = atomic_write(
                OUT / name, lambda tmp, fig=fig: fig.savefig(tmp, dpi=110, format="png")
            )
            print(f"wrote {path}")
    if figures_only:
        return 0
    result: dict = {"scene": "rt70_servo", "min_gm_db": loop_measures.MIN_GM_DB}
    result["min_pm_deg"] = loop_measures.MIN_PM_DEG
    if not quick:
        plants = [rs.axis_plant(scene, a, e) for a in AXES for e in ELEVATIONS]
        say("bisection of the cascade's design position bandwidth")
        reach = loops.reachable_position_hz(plants, low=0.1, high=0.4, steps=6)
        result["cascade_reachable_position_hz"] = reach
        say(f"reachable design position bandwidth {reach:.3f} Hz")
    result["cases"] = []
    for axis in AXES:
        for elevation in ELEVATIONS:
            case = rs.compare(scene, axis, elevation)
            result["cases"].append(case)
            c, q = case["cascade"], case["lqg"]
            say(
                f"{axis} {elevation:.0f}°: cascade bw {c['bandwidth_hz']:.3f} Hz, "
                f"overshoot {c['overshoot_pct']:.1f} %, settling {c['settling_s']:.2f} s, "
                f"wind axis peak {c['wind_axis_peak_arcsec']:.0f}″ | LQG bw "
                f"{q['bandwidth_hz']:.3f} Hz, PM {q['input_margins']['pm_deg']:.0f}°, "
                f"overshoot {q['overshoot_pct']:.1f} %, settling {q['settling_s']:.2f} s, "
                f"wind axis peak {q['wind_axis_peak_arcsec']:.0f}″"
            )
    text = json.dumps(_finite(result), indent=1, allow_nan=False)
    print(f"wrote {atomic_write_text(OUT / 'servo_loops.json', text)}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
