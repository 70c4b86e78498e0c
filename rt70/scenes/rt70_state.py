"""States of the RT-70 scene: its pointing axes and the §4.2.3 listing's start state.

What the generic analyses need to know about the RT-70 beyond its URDF file, given to
them as arguments by whoever chooses the RT-70 (the command line, the reports):

- the coordinates the drives turn (:data:`AZIMUTH_COORDINATE`,
  :data:`ELEVATION_COORDINATE`, rt70-data §D) and :func:`rt70_pointing`, the held
  coordinates of a pointing (``held`` of :func:`rt70.linear.linearize.equilibrium`);
- the listing's initial state Q_NU, dQ_NU (:func:`listing_initial_state`, ``x0`` of
  :func:`rt70.simulation.simulate.simulate`), and :func:`start_state`, the one the command line
  starts a scene from.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import Rt70Error
from rt70.scenes import rt70_data
from rt70.scenes.pairs import pair_joint_names

if TYPE_CHECKING:
    from rt70.model.scene import Scene

#: RT-70 pointing axes: the coordinates the drives turn (rt70-data §D).
AZIMUTH_COORDINATE = "platform_rz"
ELEVATION_COORDINATE = "base_rx"


#: Both pointing axes, azimuth first.
POINTING_AXES = (AZIMUTH_COORDINATE, ELEVATION_COORDINATE)


def missing_axes(coordinates) -> list[str]:
    """The RT-70 pointing axes (:data:`POINTING_AXES`) not among ``coordinates``."""
    return [a for a in POINTING_AXES if a not in coordinates]


def rt70_pointing(elevation_deg: float, azimuth_deg: float = 0.0) -> dict[str, float]:
    """Held coordinates of the RT-70 drives for a pointing.

    q = 0 is the listing's construction, the dish looking at the zenith (the mirror axis
    along z): elevation E sets the base's rotation ``base_rx = π/2 − E``, azimuth A the
    platform's ``platform_rz = A``.
    """
    return {
        AZIMUTH_COORDINATE: np.radians(azimuth_deg),
        ELEVATION_COORDINATE: np.pi / 2 - np.radians(elevation_deg),
    }


def listing_initial_state(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The §4.2.3 listing's Q_NU, dQ_NU for the RT-70 scene (by coordinate name).

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        A scene with the listing's 42 coordinates, in any order.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        q0, q̇0 in the scene's coordinate order.

    Raises
    ------
    Rt70Error
        If the scene's coordinates are not the listing's.
    """
    names = [n for body in rt70_data.LISTING_BODIES for n in pair_joint_names(body["name"])]
    model = scene.textbook
    if sorted(names) != sorted(model.coordinate_names):
        raise Rt70Error(f"{scene.name}: the listing's initial state is for the rt70 scene")
    order = [names.index(c) for c in model.coordinate_names]
    return np.asarray(rt70_data.LISTING_Q0)[order], np.asarray(rt70_data.LISTING_V0)[order]


def start_state(scene: Scene) -> tuple[np.ndarray, np.ndarray] | None:
    """The state ``rt70 simulate`` starts a scene from: the listing's for the RT-70.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray) or None
        :func:`listing_initial_state` when the scene has the listing's coordinates,
        the assembled start of the four-bar and the crank–slider
        (:func:`rt70.scenes.loop_scenes.start_state`), else None
        (:func:`rt70.simulation.simulate.simulate` then starts at rest).
    """
    from rt70.scenes.loop_scenes import start_state as loop_start

    closed = loop_start(scene)  # the closed chains' mechanisms, assembled (docs/loops.md)
    if closed is not None:
        return closed
    try:
        return listing_initial_state(scene)
    except Rt70Error:
        return None


#: Range of the RT-70's elevation axis, degrees: horizon to zenith (the book's tables
#: are given at 0° and 90°; :func:`rt70_pointing`).
ELEVATION_RANGE = (0.0, 90.0)
