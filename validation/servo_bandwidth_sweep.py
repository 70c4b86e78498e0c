"""Which position-loop bandwidth the RT-70's PI cascade survives: steps on the nonlinear model.

Runs a small step (linear range) on one axis of rt70_servo at elevation 45° with
:class:`rt70.control.servo.ServoDrive` on both axes (the other axis held at 0.2 Hz, ratio 4) for
several (position bandwidth, ratio) pairs and prints the settling time to 1″, the
overshoot and the largest error of the last 5 s; an unstable loop ends in a solver
failure or an exception. The numbers of docs/servo-scenarios.md §"Choosing the
bandwidths" come from it.
Run: ``python validation/servo_bandwidth_sweep.py AXIS T_END STEP HZ,RATIO ...`` (AXIS
azimuth or elevation, T_END in s, STEP in arcsec), e.g. ``azimuth 25 100 0.2,5 0.3,3``.
"""

import argparse
import signal
import sys

import numpy as np

from rt70.control.servo import ServoDrive
from rt70.linear.linearize import equilibrium, static_force
from rt70.model.scene import load_scene
from rt70.scenes.rt70_drives import AZIMUTH_DRIVE, ELEVATION_DRIVE
from rt70.scenes.rt70_state import rt70_pointing
from rt70.simulation.simulate import simulate
from rt70.telescope import scenarios as S
from rt70.units import RAD_PER_ARCSEC


def run(scene, q0, Q, axis, hz, ratio, step, t_end):
    names = scene.coordinate_names
    comps = []
    for coord, drive in (("platform_rz", AZIMUTH_DRIVE), ("base_rx", ELEVATION_DRIVE)):
        p, k = S.drive_parameters(drive), names.index(coord)
        s = step if drive.name == axis else 0.0
        g = S.axis_gains(drive, *((hz, ratio) if drive.name == axis else (0.2, 4.0)))
        init = S.preset_servo_state(p, g, q0[k], -Q[k])
        comps.append(ServoDrive(drive.name, names, coord, p, g, lambda t, a=q0[k] + s: a, init))
    t = np.linspace(0, t_end, int(t_end * 20) + 1)
    signal.alarm(120)  # an unstable loop can take the solver forever
    try:
        r = simulate(scene, (0, t_end), (q0, np.zeros(len(names))), components=comps, t_eval=t)
    except Exception as exc:  # noqa: BLE001  (report, go on with the next)
        return f"EXC {exc}"
    finally:
        signal.alarm(0)
    if not r.success:
        return f"FAIL at {r.t[-1]}"
    k = names.index("platform_rz" if axis == "azimuth" else "base_rx")
    err = (q0[k] + step - r.q[:, k]) / RAD_PER_ARCSEC
    ts = S.settling_time(r.t, err)
    last = np.abs(err[r.t > t_end - 5]).max()
    return f'settle1 {ts:.2f} overshoot {(-err).max():.2f}" last5 max {last:.3f}"'


def _pair(text: str) -> tuple[float, float]:
    """``HZ,RATIO``: a position bandwidth (Hz) and the cascade's ratio."""
    try:
        hz, ratio = map(float, text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected HZ,RATIO (e.g. 0.2,5), got {text!r}") from None
    return hz, ratio


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "axis",
        choices=(AZIMUTH_DRIVE.name, ELEVATION_DRIVE.name),
        metavar="AXIS",
        help="the axis stepped: azimuth or elevation",
    )
    parser.add_argument("t_end", type=float, metavar="T_END", help="run length, s")
    parser.add_argument("step", type=float, metavar="STEP", help="step size, arcsec")
    parser.add_argument(
        "pairs", type=_pair, nargs="+", metavar="HZ,RATIO", help="position bandwidth and ratio"
    )
    args = parser.parse_args(argv)
    axis, t_end, step = args.axis, args.t_end, args.step * RAD_PER_ARCSEC
    scene = load_scene("rt70_servo")
    q0 = equilibrium(scene, rt70_pointing(45.0, 0.0), tol=S.EQUILIBRIUM_TOL)
    Q = static_force(scene, q0)
    for hz, ratio in args.pairs:
        print(axis, hz, ratio, run(scene, q0, Q, axis, hz, ratio, step, t_end), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
