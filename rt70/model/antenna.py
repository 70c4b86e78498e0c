"""The pointing axes a scene declares (``<rt70:mount>``) and the pointings they give.

One job: read a scene's mount — generic, no telescope's names — and turn an elevation and
an azimuth into the held coordinates of its axes (``held`` of
:func:`rt70.linear.linearize.equilibrium`), checking each angle against the axis's range.
A scene without ``<rt70:mount>`` is refused with one line naming the element
(docs/urdf-extensions.md, ``<rt70:mount>``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from rt70.errors import SceneError
from rt70.urdf.description import Mount

if TYPE_CHECKING:
    from rt70.model.scene import Scene


def mount_of(scene: Scene) -> Mount:
    """The scene's :class:`~rt70.urdf.description.Mount`.

    Raises
    ------
    SceneError
        If the scene declares no ``<rt70:mount>``.
    """
    mount = scene.description.mount
    if mount is None:
        raise SceneError(
            f"{scene.name}: declares no pointing axes: add an <rt70:mount> element "
            "(docs: 'rt70 URDF extensions', docs/urdf-extensions.md)"
        )
    return mount


def pointing(scene: Scene, elevation_deg: float, azimuth_deg: float = 0.0) -> dict[str, float]:
    """Held coordinates of an azimuth–elevation mount's axes for a pointing, rad.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        A scene with an ``az-el`` ``<rt70:mount>``.
    elevation_deg, azimuth_deg : float
        The pointing, degrees, each within its axis's ``min_deg`` … ``max_deg``.

    Returns
    -------
    dict of str to float
        The azimuth and elevation joints' coordinates, ``q = sign · (angle − zero)``.

    Raises
    ------
    SceneError
        If the scene declares no mount, its mount is not ``az-el``, or an angle lies
        outside its axis's range.
    """
    mount = mount_of(scene)
    if mount.type != "az-el":
        raise SceneError(
            f"{scene.name}: an elevation and an azimuth point an az-el mount, not '{mount.type}'"
        )
    held = {}
    for name, angle_deg in (("azimuth", azimuth_deg), ("elevation", elevation_deg)):
        axis = mount.axis(name)
        angle = math.radians(angle_deg)
        if not axis.lower <= angle <= axis.upper:
            raise SceneError(
                f"{scene.name}: {name} {angle_deg:g}° lies outside its axis's range "
                f"{math.degrees(axis.lower):g}…{math.degrees(axis.upper):g}° (<rt70:axis "
                f"name='{name}'>)"
            )
        held[axis.joint] = axis.coordinate(angle)
    return held
