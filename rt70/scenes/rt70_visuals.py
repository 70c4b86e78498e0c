"""The RT-70 bodies' drawn shapes (``<visual>``), so URDF viewers show the telescope.

One job: a cylinder per listing body, for viewers only — neither side of the
cross-check reads ``<visual>``. The book gives masses and principal moments, not outer
shapes, so each body is drawn as the equivalent uniform solid of :mod:`rt70_wind` (a
solid cylinder along its z with its moments: ``r = √(2 I_z/m)``,
``L = √(12 I_x/m − 3 r²)``), centred on its frame; the two mirrors are drawn as discs
at their vertices (the optical points): the main mirror 70 m across (the telescope's
diameter), the counterreflector with the disc radius its ``I_z`` gives, 2.08 m. A body
whose moments admit no cylinder (``12 I_x/m < 3 r²``) is drawn as a disc of that radius.
"""

from __future__ import annotations

import math

from rt70.scenes import rt70_data
from rt70.scenes.rt70_wind import MAIN_MIRROR_DIAMETER, thin_disc_radius
from rt70.scenes.urdf_writer import Cylinder

#: Thickness drawn for the two mirrors' discs, m (a drawing choice).
DISC_THICKNESS = {"main_mirror": 1.0, "counterreflector": 0.2}


def body_visual(body: dict) -> Cylinder:
    """The drawn shape of one listing body (module docstring).

    Parameters
    ----------
    body : dict
        A body of :data:`rt70_data.LISTING_BODIES` (``name``, ``mass``, ``moments``).
    """
    name, mass, moments = body["name"], body["mass"], body["moments"]
    if name == "main_mirror":
        return Cylinder(MAIN_MIRROR_DIAMETER / 2.0, DISC_THICKNESS[name], _vertex(name))
    radius = thin_disc_radius(mass, moments[2])
    if name == "counterreflector":
        return Cylinder(radius, DISC_THICKNESS[name], _vertex(name))
    squared = 12.0 * moments[0] / mass - 3.0 * radius**2
    length = math.sqrt(squared) if squared > 0.0 else 0.1 * radius
    return Cylinder(radius, length)


def _vertex(link: str) -> tuple[float, float, float]:
    """The vertex of a mirror (its ``*_vertex`` optical point), in its frame."""
    point = next(p for p in rt70_data.LISTING_OPTICAL_POINTS if p["name"] == f"{link}_vertex")
    return tuple(point["xyz"])
