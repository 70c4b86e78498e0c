"""The options of a reflector's surface: an observing frequency, a rigging elevation.

One job: the argparse types and arguments ``rt70 pointing`` and ``rt70 sweep`` share
for a scene with a reflecting surface (docs/surface.md), checked before any work.
"""

from __future__ import annotations

import argparse

from rt70.cli.options import _number, positive_float

#: The highest frequency Ruze's law is asked at, Hz: 3 THz, a wavelength of 0.1 mm, past
#: which no radio telescope works (a larger number is a unit slip: Hz for GHz).
MAX_FREQUENCY_GHZ = 3000.0


def frequency_ghz(text: str) -> float:
    """An observing frequency in GHz: ``0 < f ≤`` :data:`MAX_FREQUENCY_GHZ`."""
    value = positive_float(text)
    if value > MAX_FREQUENCY_GHZ:
        raise argparse.ArgumentTypeError(
            f"at most {MAX_FREQUENCY_GHZ:g} GHz (the value is in GHz), got {text}"
        )
    return value


def elevation_deg(text: str) -> float:
    """An elevation in degrees, 0 to 90."""
    value = _number(text)
    if not 0.0 <= value <= 90.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 90] degrees, got {text}")
    return value


def add_frequency_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """``--frequency GHZ`` (repeatable): where Ruze's efficiency of the surface is wanted.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The command's parser.
    what : str
        What the frequency adds, for the help text.
    """
    parser.add_argument(
        "--frequency",
        type=frequency_ghz,
        action="append",
        metavar="GHZ",
        help=f"observing frequency, GHz: {what} (repeatable; a scene with a reflecting "
        "surface, docs/surface.md)",
    )
