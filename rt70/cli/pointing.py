"""``rt70 pointing``: the wind pointing budget of a scene with drives and wind elements.

One module per command, as every command of ``rt70`` (rt70/cli/main.py dispatches). The
budget: :mod:`rt70.telescope.pointing`; the gust record check: :mod:`rt70.telescope.gust_run`
(docs: 'The wind pointing budget', docs/pointing.md).
"""

from __future__ import annotations

import argparse
import json
import sys

from rt70.cli import options
from rt70.cli.surface_options import add_frequency_argument, elevation_deg
from rt70.errors import Rt70Error

#: The listing as printed, and the scene that is its control object (docs/rt70-errata.md
#: item 12): what ``rt70 pointing rt70`` runs.
LISTING = "rt70"
SERVO_SCENE = "rt70_servo"


def add_parser(sub, add_pointing_arguments) -> argparse.ArgumentParser:
    """The ``pointing`` subcommand (``add_pointing_arguments``: ``--elevation``, ``--azimuth``)."""
    poi = sub.add_parser(
        "pointing",
        help="wind pointing budget: steady and gust errors with the servos closed",
        description="The pointing error a steady wind and its Davenport gusts cause at one "
        "pointing, with both drives' servos closed (rt70_servo): the main-mirror axis "
        "against the source, the counterreflector against the main mirror (arc seconds) "
        "and the focus offset (mm); the steady value and the gust rms (Lyapunov), and the "
        "three closed-loop modes that contribute most. --duration also runs that many "
        "seconds of gusts through the nonlinear model and compares (docs: 'The wind "
        "pointing budget', docs/pointing.md).",
    )
    poi.add_argument("scene", metavar="SCENE", help="scene name or URDF path (rt70_servo)")
    add_pointing_arguments(poi, default="45")
    poi.add_argument(
        "--wind",
        type=options.wind_speed,
        required=True,
        metavar="SPEED",
        help="mean wind speed at the antenna, m/s",
    )
    poi.add_argument(
        "--direction",
        type=options.angle_deg,
        help="azimuth the wind blows from, degrees (default: the pointing's azimuth, a "
        "front wind into the dish)",
    )
    poi.add_argument(
        "--duration",
        type=options.positive_float,
        metavar="T",
        help="also run T seconds of gusts through the nonlinear model and compare",
    )
    add_frequency_argument(poi, "the reflector surface's Ruze efficiency there")
    poi.add_argument(
        "--rigging-elevation",
        type=elevation_deg,
        metavar="DEG",
        help="elevation at which the surface's panels were set, degrees (default: the "
        "middle of the mount's elevation range; a scene with a reflecting surface)",
    )
    poi.add_argument("--seed", type=options.seed, default=0, help="gust record seed (default 0)")
    poi.add_argument("--progress", action="store_true", help="progress bar of the gust run")
    poi.add_argument("--json", action="store_true", help="print JSON")
    poi.set_defaults(func=run)
    return poi


def run(args: argparse.Namespace) -> int:
    """Check the options and the scene, compute the budget (and the gust record), print."""
    from rt70.model.scene import load_scene
    from rt70.telescope.pointing import (
        PointingCase,
        budget_model,
        check_case,
        check_scene,
        format_budget,
        pointing_budget,
    )

    case = PointingCase(
        45.0 if args.elevation is None else args.elevation,
        0.0 if args.azimuth is None else args.azimuth,
        args.wind,
        args.direction,
    )
    check_case(case)
    if args.duration is not None and args.duration < 1.0:
        raise Rt70Error(f"--duration {args.duration:g}: a gust record needs at least 1 s")
    scene = load_scene(args.scene)
    requested = scene.name
    if scene.name == LISTING and not scene.description.drives:
        print(
            f"rt70: note: {LISTING} is the listing as printed, which its drives cannot hold "
            f"(docs: 'RT-70 errata and data choices', docs/rt70-errata.md, item 12); the "
            f"budget is that of {SERVO_SCENE}, the "
            "control object (counterweight below the elevation axis, drives, wind elements)",
            file=sys.stderr,
        )
        scene = load_scene(SERVO_SCENE)
    check_scene(scene)
    has_surface = _check_surface_options(args, scene)
    if args.duration is not None:  # before the budget's work
        from rt70.telescope.gust_run import check_duration

        check_duration(scene, args.duration)
    model = budget_model(scene, case)
    budget = pointing_budget(scene, case, model)
    run = None
    if args.duration is not None:  # the same equilibria, loop and covariance
        from rt70.telescope.gust_run import gust_run

        run = gust_run(
            scene, case, args.duration, seed=args.seed, progress=args.progress, model=model
        )
    surface = _surface(args, scene, model) if has_surface else None
    out = {"scene": scene.name, "requested_scene": requested, **budget.to_dict()}
    if surface is not None:
        out["surface"] = surface.to_dict()
    if run is not None:
        out["gust_run"] = run.to_dict()
    options.check_finite(out, f"{scene.name}: pointing budget")
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(format_budget(scene.name, budget))
    if surface is not None:
        from rt70.telescope.surface_budget import format_surface

        print("\n".join(format_surface(surface)))
    if run is not None:
        print(
            f"  {run.duration:g} s of gusts (seed {run.seed}), rms of the record against the "
            f"ensemble (Lyapunov) rms ± its statistical error ({run.seconds:.0f} s nonlinear):"
        )
        for name in run.rms_lyapunov:
            print(
                f"    {name:<24} nonlinear {run.rms_nonlinear[name]:.4g}, linear same gusts "
                f"{run.rms_linear[name]:.4g}, Lyapunov {run.rms_lyapunov[name]:.4g} "
                f"± {run.rms_error[name]:.2g}"
            )
    return 0


def _check_surface_options(args: argparse.Namespace, scene) -> bool:
    """Whether the scene has a reflecting surface; refuse its options on one without."""
    from rt70.model.surface_outputs import has_surface

    found = has_surface(scene)
    if not found and (args.frequency or args.rigging_elevation is not None):
        option = "--frequency" if args.frequency else "--rigging-elevation"
        raise Rt70Error(
            f"{option}: {scene.name} has no reflecting surface (a <rt70:modal_body> whose "
            "file has one, docs/surface.md)"
        )
    return found


def _surface(args: argparse.Namespace, scene, model):
    """The surface part of the budget (:func:`rt70.telescope.surface_budget.case_surface`)."""
    from rt70.telescope.surface_budget import case_surface, default_rigging

    rigging = default_rigging(scene) if args.rigging_elevation is None else args.rigging_elevation
    return case_surface(model, rigging, [f * 1e9 for f in args.frequency or []])
