"""What a scene declares of itself as an antenna: its pointing axes and its reflectors.

One job: read a scene's ``<rt70:mount>`` and ``<rt70:optics>`` — generic, no telescope's
names — and give what the pointing analyses need: the held coordinates of a pointing
(``held`` of :func:`rt70.linear.linearize.equilibrium`, each angle checked against its
axis's range), the mirror system of :mod:`rt70.model.optics` with its points, frames and
axes, the direction the undeformed antenna looks at for a pointing, and the mirror
outputs for that source. A scene without the element a question needs is refused with
one line naming it (docs/urdf-extensions.md).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import SceneError
from rt70.model.optics import MirrorSystem, mirror_outputs
from rt70.model.outputs import Output, Point, evaluate
from rt70.physics.rotations import rpy_matrix
from rt70.urdf.mount_record import Mount, MountAxis, Optics

if TYPE_CHECKING:
    from rt70.model.scene import Scene

#: Rounding allowed at the ends of an axis's range, degrees (its bounds are read in
#: degrees and kept in radians).
RANGE_ROUNDING_DEG = 1e-9
#: The elevations any mount may be asked for, degrees: a quarter turn below the horizon
#: to the opposite horizon over the zenith. A scene's own range (:func:`range_deg`) is
#: checked once the scene is read; this bounds an option before then.
ELEVATION_SPAN_DEG = (-90.0, 180.0)


def range_deg(axis: MountAxis) -> tuple[float, float]:
    """An axis's pointing range, degrees."""
    return math.degrees(axis.lower), math.degrees(axis.upper)


def within_range(axis: MountAxis, angle_deg: float) -> bool:
    """Whether ``angle_deg`` lies in the axis's range, to :data:`RANGE_ROUNDING_DEG`."""
    low, high = range_deg(axis)
    return low - RANGE_ROUNDING_DEG <= angle_deg <= high + RANGE_ROUNDING_DEG


def mount_of(scene: Scene) -> Mount:
    """The scene's :class:`~rt70.urdf.mount_record.Mount`.

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
        if not within_range(axis, angle_deg):
            low, high = range_deg(axis)
            raise SceneError(
                f"{scene.name}: {name} {angle_deg:g}° lies outside its axis's range "
                f"{low:g}…{high:g}° (<rt70:axis "
                f"name='{name}'>)"
            )
        held[axis.joint] = axis.coordinate(angle)
    return held


def optics_of(scene: Scene) -> Optics:
    """The scene's :class:`~rt70.urdf.mount_record.Optics`.

    Raises
    ------
    SceneError
        If the scene declares no ``<rt70:optics>``.
    """
    optics = scene.description.optics
    if optics is None:
        raise SceneError(
            f"{scene.name}: declares no reflector system: add an <rt70:optics> element "
            "(docs: 'rt70 URDF extensions', docs/urdf-extensions.md)"
        )
    return optics


def _point(scene: Scene, name: str) -> Point:
    """An optical point as ``(link, xyz)`` (its name was checked by the reader)."""
    found = next(p for p in scene.description.optical_points if p.name == name)
    return found.link, tuple(float(x) for x in found.xyz)


def _joint_axis(scene: Scene, joint: str) -> tuple[str, tuple[float, float, float]]:
    """A mount joint's axis as a unit vector of a link frame both sides place.

    The child link's frame when it has one (a joint's own rotation leaves its axis
    alone); otherwise the parent's, walking up through joints that do not turn
    (prismatic, fixed) to the first link the textbook model gives a frame — the body
    the bearing sits in (the massless links inside a 6-DOF pair have none).

    Raises
    ------
    SceneError
        If no such link is reached without crossing a turning joint.
    """
    desc = scene.description
    framed = scene.textbook.link_frames
    j = desc.joint(joint)
    if j.child in framed:
        return j.child, tuple(float(x) for x in j.axis)
    by_child = {k.child: k for k in desc.joints}
    axis = rpy_matrix(j.rpy) @ j.axis
    link = j.parent
    while link not in framed:
        up = by_child.get(link)
        if up is None or up.type not in ("prismatic", "fixed"):
            raise SceneError(
                f"{scene.name}: the axis of joint '{joint}' is on no body with a frame "
                "(its child link is massless and a turning joint lies above it)"
            )
        axis = rpy_matrix(up.rpy) @ axis
        link = up.parent
    return link, tuple(float(x) for x in axis)


def _value(scene: Scene, points, formula, q: np.ndarray | None = None) -> np.ndarray:
    """``formula`` of the ground positions of ``points``, textbook side, at ``q`` (or q = 0)."""
    q = np.zeros(len(scene.coordinate_names)) if q is None else q
    out = Output("value", "1", 3, tuple(points), formula)
    return evaluate(scene, q, [out], "textbook")["value"]


def _frame_points(link: str) -> list[Point]:
    """A link's origin and the tips of its unit axes: columns of its rotation by difference."""
    return [(link, (0.0, 0.0, 0.0))] + [(link, tuple(e)) for e in np.eye(3)]


def mirror_system(scene: Scene) -> MirrorSystem:
    """The scene's :class:`~rt70.model.optics.MirrorSystem`, read from its declarations.

    Points from ``<rt70:optics>``, the drive axes from ``<rt70:mount>`` (each joint's
    axis), and the design offset of the two foci from the construction (q = 0): the
    secondary focus minus the primary one in the reference frame's axes, zero for a
    single reflector.

    Raises
    ------
    SceneError
        If the scene declares no mount or no optics.
    """
    mount, optics = mount_of(scene), optics_of(scene)
    axes = {a.name: _joint_axis(scene, a.joint) for a in mount.axes}
    primary = optics.primary
    secondary = optics.secondary
    cr = (None, None, None, None)
    if secondary is not None:
        cr_focus = _point(scene, secondary.focus)
        cr = (cr_focus, _point(scene, secondary.vertex), secondary.support, cr_focus[0])
    system = MirrorSystem(
        main_focus=_point(scene, primary.focus),
        main_vertex=_point(scene, primary.vertex),
        cr_focus=cr[0],
        cr_vertex=cr[1],
        ok_link=optics.reference_link,
        azimuth_axis=axes["azimuth"],
        elevation_axis=axes["elevation"],
        cr_support_link=cr[2],
        cr_link=cr[3],
    )
    _check_reference_frame(scene, system)
    if secondary is None:
        return system
    return dataclasses.replace(system, design_offset=_design_offset(scene, system))


#: How far (a unit vector's components) the primary's focal axis at construction may lie
#: off the reference frame's z axis.
FOCAL_AXIS_TOLERANCE = 1e-6


def _check_reference_frame(scene: Scene, system: MirrorSystem) -> None:
    """Refuse a reference frame whose z is not the primary's focal axis at construction.

    The pointing corrections (4.159)–(4.163) solve the frame's x and y rows: they are
    the transverse components only when z is the focal axis.
    """

    def chord_in_frame(p: np.ndarray) -> np.ndarray:
        return (p[3:6] - p[2]) @ (p[0] - p[1])  # the frame's axes are the rows

    points = (system.main_focus, system.main_vertex, *_frame_points(system.ok_link))
    chord = _value(scene, points, chord_in_frame)
    length = float(np.linalg.norm(chord))
    if not length > 0.0:
        return  # no focal axis: refused where one is needed (source, the sweep's check)
    n = chord / length
    if not np.max(np.abs(n - np.array([0.0, 0.0, 1.0]))) <= FOCAL_AXIS_TOLERANCE:
        raise SceneError(
            f"{scene.name}: <rt70:optics reference_link='{system.ok_link}'>: the frame's z axis "
            f"is not the primary's focal axis at construction (which lies along "
            f"{np.array2string(n, precision=3)} in it): give the reflector a frame whose z "
            "is its boresight"
        )


def _design_offset(scene: Scene, system: MirrorSystem) -> tuple[float, float, float]:
    """Secondary focus − primary focus at construction (q = 0), m, reference-frame axes."""

    def offset(p: np.ndarray) -> np.ndarray:
        return (p[3:6] - p[2]) @ (p[1] - p[0])  # the frame's axes are the rows

    points = (system.main_focus, system.cr_focus, *_frame_points(system.ok_link))
    return tuple(float(x) for x in _value(scene, points, offset))


def source(scene: Scene, elevation_deg: float, azimuth_deg: float = 0.0) -> np.ndarray:
    """Unit direction, ground axes, that the undeformed antenna looks at for a pointing.

    The primary's focal axis (vertex → focus, (4.155)) at the pointing's held
    coordinates (:func:`pointing`) with every other coordinate zero: the source the
    pointing aims at (4.153).

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        A scene with ``<rt70:mount>`` and ``<rt70:optics>``.
    elevation_deg, azimuth_deg : float
        The pointing, degrees.

    Raises
    ------
    SceneError
        If the scene declares no mount or no optics, or an angle is out of range.
    """
    optics = optics_of(scene)
    held = pointing(scene, elevation_deg, azimuth_deg)
    names = scene.coordinate_names
    q = np.zeros(len(names))
    for joint, value in held.items():
        q[names.index(joint)] = value
    focus, vertex = _point(scene, optics.primary.focus), _point(scene, optics.primary.vertex)
    chord = _value(scene, (focus, vertex), lambda p: p[0] - p[1], q)
    length = float(np.linalg.norm(chord))
    if not length > 0.0:  # NaN or zero: no focal axis
        raise SceneError(
            f"{scene.name}: the primary reflector's focus and vertex are at one place "
            f"({optics.primary.focus}, {optics.primary.vertex}): it has no focal axis to point"
        )
    return chord / length


def pointing_outputs(scene: Scene, elevation_deg: float, azimuth_deg: float = 0.0) -> list[Output]:
    """The mirror-system outputs (book §4.1.8) for the source of a pointing.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        A scene with ``<rt70:mount>`` and ``<rt70:optics>``.
    elevation_deg, azimuth_deg : float
        The pointing, degrees (:func:`source`).

    Returns
    -------
    list of rt70.model.outputs.Output
        :func:`rt70.model.optics.mirror_outputs` of :func:`mirror_system`.
    """
    return mirror_outputs(mirror_system(scene), source(scene, elevation_deg, azimuth_deg))


@dataclass(frozen=True)
class SkyFrame:
    """How an az–el mount's pointing angles are read off a direction in ground axes.

    ``up`` is the local vertical (against gravity; the azimuth axis in a scene without
    gravity), ``azimuth_axis`` the azimuth joint's axis at construction, ``north`` the
    horizontal direction the antenna looks at for azimuth 0 and ``sign`` the azimuth
    axis's (``<rt70:axis sign>``): a direction's elevation is its angle above the
    horizon, its azimuth the turn about ``azimuth_axis`` from ``north`` to its
    horizontal part, times ``sign`` (the turn the azimuth joint makes).
    """

    up: np.ndarray
    azimuth_axis: np.ndarray
    north: np.ndarray
    sign: int

    def angles(self, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Elevation E and azimuth A (rad) of unit directions (rows, ground axes)."""
        d = np.atleast_2d(directions)
        elevation = np.arcsin(np.clip(d @ self.up, -1.0, 1.0))
        turn = np.arctan2(np.cross(self.north, d) @ self.azimuth_axis, d @ self.north)
        return elevation, self.sign * turn


def sky_frame(scene: Scene) -> SkyFrame:
    """The :class:`SkyFrame` of a scene's mount and optics.

    ``north`` is the horizontal part of :func:`source` at azimuth 0 and the elevation of
    the axis's range nearest the horizon.

    Raises
    ------
    SceneError
        If the scene declares no mount or no optics, or its azimuth 0 looks at the zenith.
    """
    mount = mount_of(scene)
    az = mount.axis("azimuth")
    axis_link, local = _joint_axis(scene, az.joint)
    axis = _value(scene, [(axis_link, (0.0, 0.0, 0.0)), (axis_link, local)], lambda p: p[1] - p[0])
    g = np.asarray(scene.description.gravity, dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0.0 else axis
    el = mount.axis("elevation")
    low, high = range_deg(el)
    look = source(scene, min(max(0.0, low), high), 0.0)
    horizontal = look - (look @ up) * up
    if np.linalg.norm(horizontal) <= 1e-9:
        raise SceneError(f"{scene.name}: at azimuth 0 the antenna looks at the zenith")
    return SkyFrame(up, axis, horizontal / np.linalg.norm(horizontal), az.sign)


#: How far (a unit vector's components) a mount's azimuth directions may lie from the
#: wind's convention (:func:`check_wind_convention`).
WIND_CONVENTION_TOLERANCE = 1e-6


def check_wind_convention(scene: Scene) -> None:
    """Refuse a mount whose azimuths are not the wind's compass.

    A wind's direction is an azimuth on the same compass as the pointing's
    (:func:`rt70.physics.aerodynamics.horizontal_direction`): azimuth 0
    looks along −y and azimuth 90° along +x (z up). A mount that counts its azimuth
    otherwise would put a "front" wind anywhere else, so it is refused, saying where its
    azimuths 0 and 90° look.

    Raises
    ------
    SceneError
        If the horizontal directions of the undeformed antenna at azimuths 0 and 90°
        are not the wind's.
    """
    from rt70.physics.aerodynamics import horizontal_direction

    frame = sky_frame(scene)
    el = mount_of(scene).axis("elevation")
    low, high = range_deg(el)
    elevation = min(max(0.0, low), high)
    looks = []
    for azimuth in (0.0, 90.0):
        d = source(scene, elevation, azimuth)
        h = d - (d @ frame.up) * frame.up
        looks.append(h / np.linalg.norm(h))
    wanted = [horizontal_direction(0.0), horizontal_direction(90.0)]
    if max(float(np.max(np.abs(a - b))) for a, b in zip(looks, wanted, strict=True)) > (
        WIND_CONVENTION_TOLERANCE
    ):
        raise SceneError(
            f"{scene.name}: its azimuths 0° and 90° look along {np.round(looks[0], 3)} and "
            f"{np.round(looks[1], 3)}; the wind's compass has them along -y and +x: set "
            "<rt70:axis name='azimuth'> zero_deg and sign so (docs/urdf-extensions.md)"
        )
