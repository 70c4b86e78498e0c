"""``rt70 reactions``: the RT-70's bearing and reducer loads (joint reactions).

Its own module, as ``rt70 pointing``'s (rt70/cli/pointing.py). The loads:
:mod:`rt70.telescope.bearing_loads`; the reactions: :mod:`rt70.textbook.reactions` and
:mod:`rt70.reference.reactions` (docs: 'Joint reactions', docs/reactions.md).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from rt70.cli import options
from rt70.errors import OutputError, Rt70Error


def _elevations(text: str) -> tuple[float, ...]:
    """A comma-separated list of elevations, degrees (each within the scene's range)."""
    parts = [p.strip() for p in text.split(",")]
    if not all(parts):
        raise argparse.ArgumentTypeError(f"expected elevations like 0,45,90, got '{text}'")
    return tuple(options.elevation(p) for p in parts)


def _directions(text: str) -> tuple[float, ...]:
    """A comma-separated list of wind directions, degrees."""
    parts = [p.strip() for p in text.split(",")]
    if not all(parts):
        raise argparse.ArgumentTypeError(f"expected directions like 0,180, got '{text}'")
    return tuple(options.angle_deg(p) for p in parts)


def add_parser(sub) -> argparse.ArgumentParser:
    """The ``reactions`` subcommand."""
    rea = sub.add_parser(
        "reactions",
        help="bearing and reducer loads of an antenna (joint reactions) at rest",
        description="The wrenches across the azimuth and the elevation joints of the "
        "scene's <rt70:mount> (the RT-70's platform_rz and base_rx) and the drives' reducer "
        "torques at the static equilibrium the "
        "drives hold, under gravity and optionally a steady wind (front and back by "
        "default): source 004's joint reactions on both sides (docs: 'Joint reactions', "
        "docs/reactions.md).",
    )
    rea.add_argument("scene", metavar="SCENE", help="scene name or URDF path (rt70_servo)")
    rea.add_argument(
        "--elevation",
        type=_elevations,
        metavar="LIST",
        help="elevations, degrees, comma-separated (default: seven from the elevation axis's "
        "lowest to its highest; the RT-70: 0,15,30,45,60,75,90)",
    )
    rea.add_argument(
        "--azimuth", type=options.angle_deg, default=0.0, help="azimuth, degrees (default 0)"
    )
    rea.add_argument(
        "--wind",
        type=options.wind_speed,
        metavar="SPEED",
        help="also with a steady wind of SPEED m/s",
    )
    rea.add_argument(
        "--direction",
        type=_directions,
        metavar="LIST",
        help="with --wind: azimuths the wind blows from, degrees, comma-separated "
        "(default: front and back, the pointing's azimuth and the opposite)",
    )
    rea.add_argument("--output", metavar="FILE", help="write the table to FILE (.csv or .json)")
    rea.add_argument("--json", action="store_true", help="print JSON")
    rea.set_defaults(func=run)
    return rea


def _check_output(path: str) -> Path:
    """Refuse an output path the command could not write, before any work."""
    out = Path(path)
    if out.suffix not in (".csv", ".json") or out.is_dir():
        raise OutputError(f"{out}: --output must be a .csv or .json file")
    options.check_writable_directory(out.parent)
    return out


def run(args: argparse.Namespace) -> int:
    """Check the options and the scene, compute the loads, print (and write)."""
    from rt70.model.scene import load_scene
    from rt70.telescope import bearing_loads as bl

    if args.direction is not None and args.wind is None:
        raise Rt70Error("--direction needs --wind")
    out = None if args.output is None else _check_output(args.output)
    directions = (None, args.azimuth + 180.0) if args.direction is None else args.direction
    speed = 0.0 if args.wind is None else args.wind
    scene = load_scene(args.scene)
    bl.check_scene(scene, speed > 0.0)
    elevations = bl.default_elevations(scene) if args.elevation is None else args.elevation
    rows = bl.load_table(scene, elevations, args.azimuth, speed, directions)
    options.check_finite([b.to_dict() for b in rows], f"{scene.name}: reactions")
    if out is not None:
        bl.write_output(out, rows)
    if args.json:
        units = (
            "row keys by suffix: _kN kN, _kNm kN·m, _deg degrees, wind_speed m/s; *_wrench "
            "[Fx, Fy, Fz, Mx, My, Mz] N and N·m; mesh_force N; torques N·m; seconds_* s"
        )
        rows_out = [b.to_dict() for b in rows]
        print(json.dumps({"scene": scene.name, "units": units, "rows": rows_out}, indent=2))
    else:
        print(bl.format_table(scene.name, rows, bl.bearing_joints(scene)))
        seconds_tb = sum(b.seconds_textbook for b in rows) / len(rows)
        seconds_ref = sum(b.seconds_reference for b in rows) / len(rows)
        print(
            f"run time per case (loads and reactions, one side): textbook "
            f"{seconds_tb * 1e3:.1f} ms, Pinocchio {seconds_ref * 1e3:.1f} ms"
        )
    return 0
