"""``rt70 servo``: the servo a scene's axes declare, designed or checked on its own model.

Each axis's ``<rt70:servo>``: a declared position bandwidth is checked, a missing one
tuned (:mod:`rt70.telescope.servo_design`) — the margins of every loop at the
elevation range's ends and middle, and the closed-loop bandwidth (docs: 'rt70 URDF
extensions', docs/urdf-extensions.md, ``<rt70:servo>``).
"""

from __future__ import annotations

import argparse
import json


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``servo`` subcommand (run by :func:`run`)."""
    ser = sub.add_parser(
        "servo",
        help="design or check each axis's servo on the scene's own linear model",
        description="For each axis of the scene's <rt70:mount>: its servo's position "
        "bandwidth (declared, or tuned to the highest with GM >= 6 dB and PM >= 30 deg over "
        "the elevation range), the margins of its position, rate and current loops and "
        "the closed-loop bandwidth, on the structure with every drive, reducer and gear "
        "sector (docs: 'rt70 URDF extensions', docs/urdf-extensions.md).",
    )
    ser.add_argument("scene", metavar="SCENE", help="scene name or URDF path")
    ser.add_argument("--json", action="store_true", help="print JSON (units in 'units')")
    ser.set_defaults(func=run)
    return ser


def run(args: argparse.Namespace) -> int:
    """Design (or check) and print."""
    from rt70.model.scene import load_scene
    from rt70.telescope.axis_servos import axis_servos
    from rt70.telescope.servo_design import design

    scene = load_scene(args.scene)
    axis_servos(scene)  # one line naming an axis without its <rt70:servo>
    result = design(scene)
    if args.json:
        info = {
            "scene": scene.name,
            "units": {
                "position_bandwidth_hz": "Hz", "closed_loop_bandwidth_hz": "Hz",
                "gm_db": "dB", "pm_deg": "deg", "elevations_deg": "deg", "seconds": "s",
            },
            "elevations_deg": list(result.elevations_deg),
            "stable": result.stable,
            "adequate": result.adequate,
            "seconds": result.seconds,
            "axes": {
                axis: {
                    "position_bandwidth_hz": hz,
                    "loop_ratio": ratio,
                    "tuned": result.tuned[axis],
                    "closed_loop_bandwidth_hz": result.bandwidth_hz[axis],
                    "margins": {
                        loop: {"gm_db": m.gm_db, "pm_deg": m.pm_deg}
                        for loop, m in result.margins[axis].items()
                    },
                }
                for axis, (hz, ratio) in result.tuning.items()
            },
        }  # fmt: skip
        print(json.dumps(info, indent=2, default=str))
        return 0
    print(f"{scene.name}: servo design ({result.seconds:.1f} s)")
    for line in result.lines():
        print(f"  {line}")
    if not result.adequate:
        print("  NOT ADEQUATE: a loop has GM < 6 dB or PM < 30° (a declared bandwidth too high?)")
    return 0
