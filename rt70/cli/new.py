"""``rt70 new antenna``: write an editable URDF of an az-el antenna from engineering numbers.

The file comes from :func:`rt70.scenes.antenna.antenna_urdf` (every derived number says
how it was derived); ``--tune`` designs its servo on the written model
(:mod:`rt70.telescope.servo_design`) and writes the bandwidths in (docs: 'Model your own
antenna', docs/own-antenna.md).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from rt70.cli import options
from rt70.errors import OutputError, Rt70Error


def _pair(text: str) -> tuple[float, float]:
    """``AZ,EL`` (or one value for both): two positive finite numbers."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) == 1:
        parts *= 2
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected AZ,EL or one value, got '{text}'")
    values = tuple(options.positive_float(p) for p in parts)
    return values[0], values[1]


def _range(text: str) -> tuple[float, float]:
    """``LOW,HIGH`` degrees, finite, LOW below HIGH."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected LOW,HIGH in degrees, got '{text}'")
    low, high = (options.angle_deg(p) for p in parts)
    if not low < high:
        raise argparse.ArgumentTypeError(f"{low:g} is not below {high:g}")
    return low, high


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``new`` subcommand (``rt70 new antenna ...``, run by :func:`run`)."""
    new = sub.add_parser(
        "new",
        help="write a new scene: an az-el antenna from a few engineering numbers",
        description="Write an editable, documented URDF of an az-el antenna (its axes, "
        "optics, drives, servos and wind) from a few engineering numbers; every derived "
        "number says how it was derived (docs: 'Model your own antenna', docs/own-antenna.md).",
    )
    new.add_argument("kind", choices=("antenna",), help="what to write (antenna)")
    new.add_argument("--name", required=True, help="the scene's name (letters, digits, _)")
    new.add_argument("--diameter", type=options.positive_float, required=True, help="D, m")
    new.add_argument(
        "--masses", type=_pair, required=True, metavar="AZ,EL",
        help="mass of the alidade and of the elevation structure, kg",
    )  # fmt: skip
    new.add_argument(
        "--locked-rotor", type=_pair, required=True, metavar="AZ,EL",
        help="target lowest locked-rotor frequencies, Hz",
    )  # fmt: skip
    new.add_argument(
        "--rate", type=_pair, required=True, metavar="AZ,EL", help="rate limits, deg/s"
    )
    new.add_argument(
        "--acceleration", type=_pair, required=True, metavar="AZ,EL",
        help="acceleration limits, deg/s^2",
    )  # fmt: skip
    new.add_argument(
        "--optics", choices=("prime_focus", "cassegrain", "beam_waveguide"),
        default="cassegrain", help="reflector system (default cassegrain)",
    )  # fmt: skip
    new.add_argument("--focal-ratio", type=options.positive_float, default=0.4, help="f/D (0.4)")
    new.add_argument(
        "--elevation-range", type=_range, default=(0.0, 90.0), metavar="LOW,HIGH",
        help="elevation range, deg (default 0,90)",
    )  # fmt: skip
    new.add_argument(
        "--azimuth-range", type=_range, default=(-270.0, 270.0), metavar="LOW,HIGH",
        help="azimuth range, deg (default -270,270)",
    )  # fmt: skip
    new.add_argument(
        "--wind", type=options.positive_float, default=20.0,
        help="design wind the drives are sized for, m/s (default 20)",
    )  # fmt: skip
    new.add_argument(
        "--bandwidth", type=_pair, metavar="AZ,EL",
        help="position-loop bandwidths, Hz (default: none, the servo is tuned on the model)",
    )  # fmt: skip
    new.add_argument(
        "--tune", action="store_true",
        help="tune the servo now and write its bandwidths into the file",
    )  # fmt: skip
    new.add_argument("--out", required=True, help="the URDF file to write (.urdf)")
    new.set_defaults(func=run)
    return new


def run(args: argparse.Namespace) -> int:
    """Check everything, build the spec and the text, tune if asked, write atomically."""
    from rt70.guards.atomic import atomic_write_text
    from rt70.scenes.antenna import AntennaSpec, antenna_urdf

    out = Path(args.out)
    if out.suffix != ".urdf":
        raise OutputError(f"--out must be a .urdf file, got '{out}'")
    if args.tune and args.bandwidth is not None:
        raise Rt70Error("--tune designs the bandwidths: give it or --bandwidth, not both")
    try:
        spec = AntennaSpec(
            name=args.name, diameter=args.diameter, azimuth_mass=args.masses[0],
            elevation_mass=args.masses[1], locked_rotor_hz=args.locked_rotor,
            rate_limit_deg_s=args.rate, acceleration_deg_s2=args.acceleration,
            optics=args.optics, focal_ratio=args.focal_ratio,
            elevation_range_deg=args.elevation_range, azimuth_range_deg=args.azimuth_range,
            design_wind=args.wind, position_bandwidth_hz=args.bandwidth,
        )  # fmt: skip
    except ValueError as exc:
        raise Rt70Error(f"rt70 new antenna: {exc}") from None
    text = antenna_urdf(spec)
    if args.tune:
        from dataclasses import replace

        from rt70.model.scene import scene_from_text
        from rt70.telescope.servo_design import design

        result = design(scene_from_text(text, spec.name))
        tuned = tuple(
            math.floor(result.tuning[a][0] * 1000) / 1000 for a in ("azimuth", "elevation")
        )
        text = antenna_urdf(replace(spec, position_bandwidth_hz=tuned))
        for line in result.lines():
            print(f"  {line}")
    atomic_write_text(out, text)
    print(f"wrote {out}: {spec.diameter:g}-m {spec.optics} antenna '{spec.name}'")
    return 0
