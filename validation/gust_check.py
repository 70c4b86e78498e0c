"""The gust pointing error of the linear budget against the nonlinear model (issue 11 target 2).

For one mean wind speed (front wind, elevation 45°, azimuth 0 on ``rt70_servo``) one
Davenport gust record (seed 1) is run through the nonlinear model — structure, both drives
with their servo cascades, the wind load exact in the speed — and through the budget's
linear closed loop (:mod:`rt70.telescope.gust_run`). Writes
validation/results/gust_check_<speed>.json (rms values, statistical error, run time) and
.npz (the records). ``--figure`` draws validation/results/gust_check.png from the files
already written.

Run: ``python validation/gust_check.py --speed 5 --duration 600`` (the runs of issue 11:
5 and 15 m/s, 600 s each; on 2026-11-27 their nonlinear simulations took 76 s and 124 s
of one core each, side by side on the 2-core machine), then ``--figure``.
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from rt70.guards.atomic import atomic_write, atomic_write_text
from rt70.model.scene import load_scene
from rt70.telescope.gust_run import gust_run
from rt70.telescope.pointing import PointingCase

OUT = Path(__file__).resolve().parent / "results"
ELEVATION = 45.0
SEED = 1


def run(speed: float, duration: float) -> dict:
    scene = load_scene("rt70_servo")
    with threadpool_limits(1):
        r = gust_run(scene, PointingCase(ELEVATION, 0.0, speed), duration, seed=SEED)
    out = {"scene": scene.name, "elevation_deg": ELEVATION, "wind_speed": speed, **r.to_dict()}
    stem = OUT / f"gust_check_{speed:g}"
    atomic_write_text(stem.with_suffix(".json"), json.dumps(out, indent=2) + "\n")
    arrays = {"t": r.t, "gust": r.gust}
    for k in r.nonlinear:
        arrays[f"nonlinear_{k}"] = r.nonlinear[k]
        arrays[f"linear_{k}"] = r.linear[k]
        arrays[f"linear_exact_load_{k}"] = r.linear_exact_load[k]
    atomic_write(stem.with_suffix(".npz"), lambda tmp: np.savez_compressed(tmp, **arrays))
    return out


def figure() -> Path:
    from rt70.plotting.wind import gust_check_figure

    runs = []
    paths = OUT.glob("gust_check_*.json")
    for path in sorted(paths, key=lambda p: float(p.stem.removeprefix("gust_check_"))):
        info = json.loads(path.read_text())
        records = dict(np.load(path.with_suffix(".npz")))
        runs.append((info, records))
    if not runs:
        sys.exit("no gust_check_*.json in validation/results: run a speed first")
    fig = gust_check_figure(runs)
    target = OUT / "gust_check.png"
    atomic_write(target, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    return target


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--speed", type=float, help="mean wind speed, m/s")
    p.add_argument("--duration", type=float, default=600.0, help="record length, s")
    p.add_argument("--figure", action="store_true", help="draw the figure from the results")
    args = p.parse_args()
    if args.figure:
        print(f"wrote {figure()}")
        return
    if args.speed is None:
        p.error("--speed or --figure")
    out = run(args.speed, args.duration)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
