"""``rt70 validate``: the textbook side cross-checked against the reference on random states.

The rows: :mod:`rt70.crosscheck.validate`; the robots of example-robot-data:
:mod:`rt70.crosscheck.robots` (docs: 'Validation', docs/validation.md).
Robots rt70 cannot load are listed as ``not loaded: <name>: <reason>`` lines, no error by
themselves.
"""

from __future__ import annotations

import argparse
import json
import sys

from rt70.cli import options
from rt70.errors import Rt70Error


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``validate`` subcommand: the cross-check of the two sides (run by :func:`run`)."""
    val = sub.add_parser(
        "validate",
        help="cross-check the textbook algorithm against Pinocchio",
        description="Compare mass matrix, bias, gravity, spring/damper forces, forward "
        "dynamics and energies of the textbook algorithm and Pinocchio on random states.",
    )
    val.add_argument(
        "targets",
        nargs="*",
        metavar="TARGET",
        help="scene name, URDF path, 'robots' (every robot of example-robot-data that "
        "loads) or 'robot:NAME' (default: every scene in urdf/)",
    )
    val.add_argument(
        "--samples", type=options.positive_int, default=10, help="random states per target"
    )
    val.add_argument("--seed", type=options.seed, default=0, help="random seed (≥ 0)")
    val.add_argument(
        "--tolerance", type=options.non_negative_float, default=1e-10, help="relative tolerance"
    )
    val.add_argument("--json", action="store_true", help="print the records as JSON")
    val.add_argument(
        "--balance-inertia",
        action="store_true",
        help="repair rotational inertias of moving links that are not positive definite or "
        "break the triangle inequality (principal moments set to their mean, as MuJoCo's "
        "balanceinertia) instead of refusing them; each repair is reported",
    )
    val.set_defaults(func=run)
    return val


def run(args: argparse.Namespace) -> int:
    """Cross-check every target on random states; 0 if every row agrees, 1 if not."""
    from rt70.crosscheck.robots import UNEXPECTED, survey
    from rt70.crosscheck.validate import cross_check, format_table
    from rt70.model.scene import URDF_DIR, load_scene, require_coordinates, scene_names

    targets = args.targets or scene_names()
    if not targets:
        raise Rt70Error(f"no target to check: no scene files in {URDF_DIR}")
    balance = args.balance_inertia
    scenes, not_loaded = [], {}
    for t in targets:  # read everything first: bad input exits 2
        if t == "robots" or t.startswith("robot:"):  # example-robot-data (rt70.crosscheck.robots)
            names = None if t == "robots" else [t.removeprefix("robot:")]
            loaded, failed = survey(names, balance_inertia=balance)
            scenes += loaded
            not_loaded.update(failed)
        else:
            scenes.append(load_scene(t, balance_inertia=balance))
    bug = any(reason.startswith(UNEXPECTED) for reason in not_loaded.values())
    if not scenes:  # every robot asked for failed to load: nothing was checked
        reasons = "; ".join(f"{name}: {why}" for name, why in not_loaded.items())
        if bug:
            print(f"rt70: no target could be checked, a bug in rt70: {reasons}", file=sys.stderr)
            return 1
        raise Rt70Error(f"no target could be checked ({reasons})")
    for scene in scenes:  # build both sides first: a model rt70 refuses exits 2
        scene.reference  # noqa: B018  Pinocchio's guards first: cheaper than the mass check
        scene.textbook  # noqa: B018
        require_coordinates(scene)
    records = [r for scene in scenes for r in cross_check(scene, args.samples, args.seed)]
    if args.json:
        print(json.dumps([r.as_dict() for r in records], indent=2))
    else:
        print(format_table(records, args.tolerance))
        print(
            f"\n{len(scenes)} target(s), {args.samples} random states each, seed {args.seed}; "
            f"tolerance {args.tolerance:g} relative to the reference's max-norm."
        )
    for name, reason in not_loaded.items():  # reported, not an error by itself
        print(f"not loaded: {name}: {reason}", file=sys.stderr if args.json else sys.stdout)
    return 0 if all(r.passed(args.tolerance) for r in records) and not bug else 1
