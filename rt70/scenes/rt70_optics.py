"""The RT-70's mirror system: which of its points and frames the book's outputs use.

What :mod:`rt70.model.optics` (generic) needs to know of the RT-70 (book 4.1.8, rt70-data):

- the four ``<rt70:optical_point>`` elements by name (the listing's R5f, R5v, R7f, R7v);
- the reference ring (OK) frame: the mirror base (body 4); the pointing axes: the
  platform's z (azimuth, ``platform_rz``) and x (elevation bearing, ``base_rx``); the
  counterreflector drive: frame 7c on the rigel (body 6), the counterreflector (body 7);
- the design offset of the two foci, :data:`DESIGN_FOCAL_OFFSET`, derived from the
  listing's data (the listing's foci are not confocal);
- the source a pointing looks at, :func:`pointing_source`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.optics import MirrorSystem, mirror_outputs, source_direction
from rt70.scenes import rt70_data

if TYPE_CHECKING:
    from rt70.model.outputs import Output
    from rt70.model.scene import Scene

#: Names of the optical points in urdf/rt70.urdf: main focus, main vertex, CR focus, CR vertex.
OPTICAL_POINTS = (
    "main_mirror_focus",
    "main_mirror_vertex",
    "counterreflector_focus",
    "counterreflector_vertex",
)


def _construction_position(link: str, xyz) -> np.ndarray:
    """Ground position (m) of a point of a listing body at q = 0 (offsets are pure shifts)."""
    bodies = {b["name"]: b for b in rt70_data.LISTING_BODIES}
    p = np.asarray(xyz, dtype=float)
    while link in bodies:
        p = p + np.asarray(bodies[link]["offset"])
        link = bodies[link]["parent"]
    return p


def _design_focal_offset() -> np.ndarray:
    """Counterreflector focus − main mirror focus at construction (m), from the listing.

    The main focus sits at 25 + 20 + 11 + 20 + 13 = 89 m, the counterreflector's at
    25 + 20 + 38 + 6 + 1.2 = 90.2 m; every construction frame is parallel to the ground,
    so the OK axes are the ground axes and the offset is [0, 0, 1.2] m.
    """
    points = {p["name"]: p for p in rt70_data.LISTING_OPTICAL_POINTS}
    focus = [_construction_position(points[n]["link"], points[n]["xyz"]) for n in OPTICAL_POINTS]
    return focus[2] - focus[0]


#: Design offset of the counterreflector's focus from the main mirror's (m, OK axes):
#: the listing's optical points put them 1.2 m apart along the axis at construction
#: (not confocal), so the corrections are measured from that design state.
DESIGN_FOCAL_OFFSET = tuple(float(x) for x in _design_focal_offset())


def rt70_mirror_system(scene: Scene) -> MirrorSystem:
    """The RT-70's :class:`rt70.model.optics.MirrorSystem`, its points read from the scene.

    Raises
    ------
    Rt70Error
        If the scene lacks one of :data:`OPTICAL_POINTS`.
    """
    found = {p.name: p for p in scene.description.optical_points}
    missing = [n for n in OPTICAL_POINTS if n not in found]
    if missing:
        raise Rt70Error(f"{scene.name}: no <rt70:optical_point> named {', '.join(missing)}")
    mf, mv, cf, cv = (
        (found[n].link, tuple(float(x) for x in found[n].xyz)) for n in OPTICAL_POINTS
    )
    return MirrorSystem(
        main_focus=mf,
        main_vertex=mv,
        cr_focus=cf,
        cr_vertex=cv,
        ok_link="mirror_base",
        azimuth_axis=("platform", (0.0, 0.0, 1.0)),
        elevation_axis=("platform", (1.0, 0.0, 0.0)),
        cr_support_link="rigel",
        cr_link="counterreflector",
        design_offset=DESIGN_FOCAL_OFFSET,
    )


def pointing_source(elevation_deg: float, azimuth_deg: float = 0.0) -> np.ndarray:
    """Unit direction (ground axes) the undeformed RT-70 looks at for a pointing.

    With :func:`rt70.scenes.rt70_state.rt70_pointing` (``platform_rz = A``,
    ``base_rx = π/2 − E``) the mirror axis ``Rz(A) Rx(π/2 − E) e_z`` is the book's source
    (4.153) of elevation β0 = E and azimuth α0 = A − 90°.
    """
    return source_direction(np.radians(azimuth_deg - 90.0), np.radians(elevation_deg))


def rt70_mirror_outputs(
    scene: Scene, elevation_deg: float, azimuth_deg: float = 0.0
) -> list[Output]:
    """The mirror-system outputs of the RT-70 for the source of a pointing (§4.1.8).

    Parameters
    ----------
    scene : Scene
        A scene of the RT-70 with the listing's optical points (``rt70``, ``rt70_servo``).
    elevation_deg : float
        Elevation of the pointing, degrees: the source's β0 (4.153).
    azimuth_deg : float, optional
        Azimuth of the pointing, degrees: the source's α0 = A − 90°.

    Returns
    -------
    list of Output
        :func:`rt70.model.optics.mirror_outputs` of the scene's mirror system.
    """
    return mirror_outputs(rt70_mirror_system(scene), pointing_source(elevation_deg, azimuth_deg))
