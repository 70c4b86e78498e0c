"""The LQG closed around the nonlinear RT-70 model: against its linear loop and the PI cascade.

Issue 10 item 4 (the simulation half of the model-based alternative). On ``rt70_servo``
at elevation 45°, the LQG of :mod:`rt70.control.lqg` on the azimuth
(:func:`rt70.reports.servo_lqg.lqg_drives`, the PI cascade on elevation) against

- its linear closed loop (full linear plant, elevation locked) on a 100″ azimuth step,
  small enough to stay off the voltage limit;
- the PI cascade of :func:`rt70.telescope.scenarios.servo_drives` on the same step and on 1°;

and the LQG on a 1° step (voltage limit active), sidereal tracking and a short hold.
Writes validation/results/servo_lqg.{json,png}. Run:
``python validation/servo_lqg.py`` (28 minutes on 2 busy cores: the runs go in two
processes; the LQG's fast estimator poles, ~6000 rad/s, make it stiff).
"""

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from rt70.guards.atomic import atomic_write, atomic_write_text

OUT = Path(__file__).resolve().parent / "results"
ELEVATION = 45.0
SMALL_ARCSEC = 100.0
#: (name, controller, scenario, length s)
RUNS = (
    ("lqg_step_100", "lqg", "small", 12.0),
    ("pi_step_100", "pi", "small", 25.0),
    ("lqg_step_1deg", "lqg", "step-azimuth", 25.0),
    ("pi_step_1deg", "pi", "step-azimuth", 25.0),
    ("lqg_track", "lqg", "track", 20.0),
    ("lqg_hold", "lqg", "hold", 3.0),
)


def _run(spec):
    """One scenario: its numbers and the curves the figure needs."""
    from rt70.model.scene import load_scene
    from rt70.reports import servo_lqg as sl
    from rt70.telescope.scenarios import run_scenario, scenario

    name, controller, what, t_end = spec
    scene = load_scene("rt70_servo")
    if what == "small":
        sc = sl.step_scenario(SMALL_ARCSEC, ELEVATION, t_end)
    else:
        sc = scenario(what, ELEVATION, 0.0, t_end)
    drives = sl.lqg_drives(ELEVATION) if controller == "lqg" else None
    run = run_scenario(scene, sc, drives, samples_per_s=50.0)
    t = run.result.t
    step = sc.step_deg[0] * 3600.0
    axis = step - run.axis_error["azimuth"] if step else -run.axis_error["azimuth"]
    out = {
        "metrics": {k: float(v) for k, v in run.metrics.items()},
        "t": t.tolist(),
        "azimuth_arcsec": axis.tolist(),
        "elevation_error_max_arcsec": float(np.abs(run.axis_error["elevation"]).max()),
        "peak_current_azimuth_A": float(np.abs(run.motor_current["azimuth"]).max()),
    }
    az = run.components[0]
    s = np.column_stack([run.result.states[n] for n in az.names])
    if hasattr(az, "voltage_of"):
        if controller == "lqg":
            u = [
                az.voltage_of(x, q, qd, y)
                for x, q, qd, y in zip(t, run.result.q, run.result.qd, s, strict=True)
            ]
        else:
            u = [az.voltage_of(x, q, y) for x, q, y in zip(t, run.result.q, s, strict=True)]
        out["peak_voltage_azimuth_V"] = float(np.abs(u).max())
    if step:
        out["step"] = sl.step_numbers(t, axis, step)
    return name, out


def _figure(results, linear, t_lin):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(9, 10), constrained_layout=True)
    small = results["lqg_step_100"], results["pi_step_100"]
    ax = axes[0]
    ax.plot(small[0]["t"], small[0]["azimuth_arcsec"], label="LQG, nonlinear model")
    ax.plot(t_lin, linear, "--", label="LQG, linear closed loop (elevation locked)")
    ax.plot(small[1]["t"], small[1]["azimuth_arcsec"], label="PI cascade (0.2 Hz), nonlinear")
    ax.axhline(SMALL_ARCSEC, color="0.6", lw=0.8)
    ax.set(xlabel="time, s", ylabel="azimuth angle change, arcsec", xlim=(0, 25))
    ax.set_title(f"RT-70 (rt70_servo), elevation {ELEVATION:g}°: {SMALL_ARCSEC:g}″ azimuth step")
    ax.legend()
    ax = axes[1]
    t = np.asarray(small[0]["t"])
    diff = np.asarray(small[0]["azimuth_arcsec"]) - np.interp(t, t_lin, linear)
    ax.plot(t, diff)
    ax.set(xlabel="time, s", ylabel="nonlinear − linear, arcsec")
    ax.set_title("LQG: nonlinear model minus its linear closed loop (100″ step)")
    ax = axes[2]
    for key, label in (("lqg_step_1deg", "LQG"), ("pi_step_1deg", "PI cascade (0.2 Hz)")):
        r = results[key]
        ax.plot(r["t"], np.asarray(r["azimuth_arcsec"]) / 3600.0, label=f"{label}, nonlinear")
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set(xlabel="time, s", ylabel="azimuth angle change, degrees")
    ax.set_title("1° azimuth step (voltage limit active; LQG: no current or rate limit)")
    ax.legend()
    return fig


def _finite(x):
    """The result with non-finite numbers as null (strict JSON)."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    from rt70.model.scene import load_scene
    from rt70.reports import servo_lqg as sl

    start = time.perf_counter()
    OUT.mkdir(exist_ok=True)
    with ProcessPoolExecutor(max_workers=2) as pool:
        results = dict(pool.map(_run, RUNS))
    scene = load_scene("rt70_servo")
    t_lin = np.linspace(0.0, 25.0, 1251)
    lin = sl.linear_step(scene, SMALL_ARCSEC, t_lin, ELEVATION)
    summary = {
        "scene": "rt70_servo",
        "elevation_deg": ELEVATION,
        "linear_lqg_step_100": sl.step_numbers(t_lin, lin["axis_arcsec"], SMALL_ARCSEC)
        | {"peak_voltage_V": float(np.abs(lin["voltage"]).max())}
        | {"peak_current_A": float(np.abs(lin["current"]).max())},
    }
    r = results["lqg_step_100"]
    t = np.asarray(r["t"])
    diff = np.asarray(r["azimuth_arcsec"]) - np.interp(t, t_lin, lin["axis_arcsec"])
    summary["lqg_step_100_vs_linear_max_arcsec"] = float(np.abs(diff).max())
    for name, res in results.items():
        summary[name] = {k: v for k, v in res.items() if k not in ("t", "azimuth_arcsec")}
    fig = _figure(results, lin["axis_arcsec"], t_lin)
    path = atomic_write(OUT / "servo_lqg.png", lambda tmp: fig.savefig(tmp, dpi=100, format="png"))
    print(f"wrote {path}")
    text = json.dumps(_finite(summary), indent=1, allow_nan=False)
    print(f"wrote {atomic_write_text(OUT / 'servo_lqg.json', text)}")
    print(text)
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
