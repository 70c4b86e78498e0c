"""``rt70 cart``: the two-wheeled cart of companion source 002 steered by program constraints.

Its own module, as ``rt70 pointing``'s (rt70/cli/pointing.py). The servo:
:mod:`rt70.mechanics.chaplygin_cart`
(docs: 'Nonholonomic systems and program constraints', docs/nonholonomic.md).
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from rt70.cli import options
from rt70.errors import Rt70Error
from rt70.guards.resources import check_time_series

#: Longest run accepted, s (the cart reaches the target's neighbourhood in about 10 s).
MAX_DURATION = 100.0

#: Interval of the grid on which the obstacle function g is sampled, s.
GRID = 0.01

#: Values kept per sample: the state (8) and a printed row's seven Python floats (about
#: four float64 each: a float object and its list slot).
CHANNELS = 8 + 7 * 4


def add_parser(sub) -> argparse.ArgumentParser:
    """The ``cart`` subcommand."""
    car = sub.add_parser(
        "cart",
        help="the two-wheeled cart of source 002 steered round an obstacle",
        description="Steer the two-wheeled cart (urdf/two_wheeled_cart.urdf) from a start "
        "to the origin round the ellipse (x−2)² + 4y² = 1 by program constraints "
        "(companion source 002, physically consistent formulation): print the initial "
        "wheel torques and lateral reaction, the state at every --step, the smallest "
        "obstacle function g along the path and the largest constraint residual "
        "(docs: 'Nonholonomic systems and program constraints', docs/nonholonomic.md).",
    )
    car.add_argument(
        "scene", nargs="?", default="two_wheeled_cart", help="scene (two_wheeled_cart)"
    )
    car.add_argument(
        "--start",
        nargs=2,
        type=options.physical_float,
        default=(4.0, 0.5),
        metavar=("X", "Y"),
        help="start of M, m (default 4 0.5)",
    )
    car.add_argument(
        "--heading-error",
        type=options.angle_error,
        default=0.0,
        metavar="RAD",
        help="heading off the programmed one at the start, rad (default 0)",
    )
    car.add_argument(
        "--speed-error",
        type=options.finite_float,
        default=0.0,
        metavar="FRACTION",
        help="speed off the programmed one at the start, fraction (default 0)",
    )
    car.add_argument(
        "--duration", type=options.positive_float, default=6.0, help="seconds (default 6)"
    )
    car.add_argument(
        "--step", type=options.positive_float, default=1.0, help="print step, s (default 1)"
    )
    options.add_side_argument(car)
    car.add_argument("--json", action="store_true", help="print JSON")
    car.set_defaults(func=run)
    return car


#: The units of ``--json``'s numbers: the columns, the initial torques and reaction, the
#: obstacle function g (4.5) and the perturbations (c, f1, ḟ1, f4) of (4.3), (4.10), (4.13).
UNITS = {
    "t": "s",
    "x": "m",
    "y": "m",
    "theta": "rad",
    "xd": "m/s",
    "yd": "m/s",
    "thetad": "rad/s",
    "M1": "N·m",
    "M2": "N·m",
    "lateral": "N",
    "min_g": "m²",
    "perturbations": ["m/s", "m/s", "m/s²", "m/s"],
    "stopped_at": "s",
}


def run(args: argparse.Namespace) -> int:
    """Check the options and the scene, run the servo, print."""
    from rt70.mechanics import chaplygin_cart as cart
    from rt70.model.scene import load_scene

    if args.duration > MAX_DURATION:
        raise Rt70Error(f"--duration {args.duration:g}: at most {MAX_DURATION:g} s")
    if args.step > args.duration:
        raise Rt70Error(f"--step {args.step:g} is longer than --duration {args.duration:g}")
    if args.speed_error <= -1.0:
        raise Rt70Error(f"--speed-error {args.speed_error:g}: the speed must stay positive")
    check_time_series(
        args.duration / args.step + args.duration / GRID + 2,
        CHANNELS,
        f"the states every --step and every {GRID:g} s over {args.duration:g} s",
        f"--step {args.step:g}",
    )
    scene = load_scene(args.scene)
    cart.check_scene(scene)
    with options.option_at_fault(f"--start {args.start[0]:g} {args.start[1]:g}"):
        q, qd = cart.on_manifold_start(*args.start)
    q[2] += args.heading_error
    speed = (1.0 + args.speed_error) * float(np.hypot(qd[0], qd[1]))
    qd[:2] = speed * np.cos(q[2]), speed * np.sin(q[2])  # along the heading: (4.3) holds
    with options.option_at_fault("the start state (--start, --heading-error, --speed-error)"):
        first = cart.servo(scene, q, qd, side=args.side)
    n = int(np.floor(args.duration / args.step + 1e-9))
    shown = np.unique(np.round(np.append(np.arange(n + 1) * args.step, args.duration), 12))
    grid = np.linspace(0.0, args.duration, int(np.ceil(args.duration / GRID)) + 1)
    sol = cart.simulate(
        scene, q, qd, np.unique(np.concatenate([shown, grid])), side=args.side, stop_radius=0.01
    )
    g_min = float(np.min(cart.obstacle(sol.y[0], sol.y[1])))  # on the GRID
    picked = [i for i, t in enumerate(sol.t) if np.min(np.abs(shown - t)) < 1e-9]
    if picked[-1] != sol.t.size - 1:
        picked.append(sol.t.size - 1)  # where a stopped run ended
    end = cart.servo(scene, sol.y[:5, -1], sol.y[5:, -1], side=args.side).residuals
    stopped = sol.status == 1
    rows = [[float(sol.t[i]), *map(float, sol.y[[0, 1, 2, 5, 6, 7], i])] for i in picked]
    out = {
        "scene": scene.name,
        "side": args.side,
        "initial": {"M1": first.M1, "M2": first.M2, "lateral": first.lateral},
        "columns": ["t", "x", "y", "theta", "xd", "yd", "thetad"],
        "rows": rows,
        "min_g": g_min,
        "perturbations_start": first.residuals.tolist(),
        "perturbations_end": end.tolist(),
        "stopped_at": float(sol.t_events[0][0]) if stopped else None,
        "units": UNITS,
    }
    options.check_finite(out, f"{scene.name}: cart")
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(
        f"{scene.name} ({args.side} side): start ({args.start[0]:g}, {args.start[1]:g}), "
        f"θ0 = {q[2]:.6f} rad, speed {speed:.6f} m/s"
    )
    print(
        f"  initial wheel torques M1 = {first.M1:.6f} N·m, M2 = {first.M2:.6f} N·m, "
        f"lateral reaction {first.lateral:.6f} N"
    )
    heads = ("x m", "y m", "θ rad", "ẋ m/s", "ẏ m/s", "θ̇ rad/s")
    print(f"  {'t s':>6} " + " ".join(f"{h:>10}" for h in heads))
    for r in rows:
        print(f"  {r[0]:6.2f} " + " ".join(f"{v:10.6f}" for v in r[1:]))
    if stopped:
        print(f"  stopped at t = {sol.t_events[0][0]:.3f} s: M within 0.01 m of the origin")
    inside = " (the path is inside the obstacle)" if g_min < 0.0 else ""
    print(f"  min g along the path (0.01-s grid) {g_min:.4f}{inside}")
    print(
        "  perturbations (c, f1, ḟ1, f4): start "
        + " ".join(f"{v:.2e}" for v in first.residuals)
        + ", end "
        + " ".join(f"{v:.2e}" for v in end)
    )
    return 0
