"""Outputs of a two-mirror system (book 4.1.8, formalism §4.6) as formulas of points.

One job: turn the positions of a few points of bodies — the main mirror's focus and
vertex, the counterreflector's focus and vertex, and unit offsets that give the axes of
a few link frames — into the book's control errors of the mirror system, each an
:class:`rt70.model.outputs.Output`. Each side of the cross-check computes the positions with
its own kinematics, so ``outputs.evaluate(scene, q, outs, side)`` and
``simulate(..., outputs=outs)`` work unchanged. :func:`rt70.model.outputs.output_matrix` gives their
rows of the linear plant (C) at q0.

Frames (ground axes are the base frame of (4.153)): the reference ring (OK) frame is a
link's frame (the book's mirror base, body 4); a frame's rotation ``R`` (columns = its
axes in ground axes) is read from the positions of the link's origin and of the three
unit offsets ``e_x, e_y, e_z``. Everything is then a plain formula; the outputs are:

==================================  ======  ====  ==========================================
name                                unit    size  formula
==================================  ======  ====  ==========================================
``main_mirror_axis``                1       3     n5 = Rᵀ(r5f − r5v)/‖r5f − r5v‖ (4.155)
``counterreflector_axis``           1       3     n7 likewise through the CR points (4.164)
``main_mirror_misalignment``        arcsec  1     2 arcsin(‖s − n5‖/2) (4.157)
``main_mirror_error``               arcsec  3     s − n5 in OK, small-angle vector (4.156)
``counterreflector_misalignment``   arcsec  1     2 arcsin(‖n7 − n5‖/2) (4.166)
``counterreflector_error``          arcsec  3     n7 − n5 in OK, small-angle vector (4.165)
``counterreflector_source_...``     arcsec  1     2 arcsin(‖s − n7‖/2) (φ7 КИР of 4.1.8)
``focal_offset``                    mm      3     Rᵀ(r7f − r5f) − d (4.152)
``pointing_correction``             arcsec  2     [Δα, Δβ] from the x, y rows (4.159)–(4.163)
``counterreflector_rotation``       arcsec  3     [Δβ7, Δθ7, Δα7] (4.168)–(4.172)
``counterreflector_translation``    mm      3     Δr7 = Z4 − Z1Δβ7 − Z2Δθ7 − Z3Δα7 (4.173)–(4.175)
==================================  ======  ====  ==========================================

``s`` is the unit source direction (4.153), ``R`` the OK frame, ``d`` the design offset
of the counterreflector's focus from the main mirror's in OK axes (zero for a confocal
system, the book's (4.173); a scene whose optical points are not confocal at
construction passes its own). The readings of the book where it is ambiguous or wrong
are in the docstrings of the formulas and in docs/mirror-outputs.md.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error, SingularConfigurationError
from rt70.model.outputs import Output, Point
from rt70.units import ARCSEC_PER_RAD, MM_PER_M

#: Smallest ``|det|`` (relative) of the pointing system (4.163) and smallest σ₂/σ₁ of the
#: counterreflector system (4.172) before the correction is refused as undefined.
SINGULAR = 1e-9

_E = np.eye(3)


def source_direction(azimuth: float, elevation: float) -> np.ndarray:
    """Unit direction to the source in ground axes (4.153), angles in radians.

    ``[cos α0 cos β0, sin α0 cos β0, sin β0]``: azimuth α0 from x toward y, elevation β0
    above the x–y plane.
    """
    ca, sa, cb, sb = np.cos(azimuth), np.sin(azimuth), np.cos(elevation), np.sin(elevation)
    return np.array([ca * cb, sa * cb, sb])


@dataclass(frozen=True)
class MirrorSystem:
    """Where a scene's mirror system is: its optical points, frames and drive axes.

    Attributes
    ----------
    main_focus, main_vertex, cr_focus, cr_vertex : (link, xyz)
        Focus and vertex of the main mirror's paraboloid and of the counterreflector's
        ellipsoid (xyz in the link's frame, m).
    ok_link : str
        The link whose frame is the reference ring (OK) frame (the book's body 4).
    azimuth_axis, elevation_axis : (link, axis)
        The pointing drives' axes as unit vectors of a link's frame: the platform's z
        (Δα, (4.159)) and the platform's x, the elevation bearing (Δβ).
    cr_support_link : str
        The link carrying the counterreflector drive's construction frame 7c (the
        rigel): its axes are the drive's translation axes and its x the first rotation
        axis (β7) of (4.168); the frame 7c is taken parallel to this link's frame.
    cr_link : str
        The counterreflector: the drive turns it about its frame origin, last about its
        own z (α7); the middle axis (θ7) is perpendicular to the first and the last.
    design_offset : (3,) array
        Design offset (m, OK axes) of the counterreflector's focus from the main
        mirror's; zero for the book's confocal system.
    """

    main_focus: Point
    main_vertex: Point
    cr_focus: Point | None
    cr_vertex: Point | None
    ok_link: str
    azimuth_axis: tuple[str, tuple[float, float, float]]
    elevation_axis: tuple[str, tuple[float, float, float]]
    cr_support_link: str | None
    cr_link: str | None
    design_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        secondary = (self.cr_focus, self.cr_vertex, self.cr_support_link, self.cr_link)
        if any(x is None for x in secondary) and any(x is not None for x in secondary):
            raise Rt70Error(
                "a mirror system's counterreflector needs its focus, vertex, support link "
                "and link, or none of them (a single reflector)"
            )

    @property
    def has_counterreflector(self) -> bool:
        """Whether the system has a second reflector (its outputs and corrections)."""
        return self.cr_link is not None

    def points(self) -> tuple[Point, ...]:
        """The points every output of the system is computed from, in a fixed order."""
        zero = (0.0, 0.0, 0.0)

        def frame(link: str) -> list[Point]:
            return [(link, zero)] + [(link, tuple(e)) for e in _E]

        def axis(link_axis: tuple[str, tuple[float, float, float]]) -> list[Point]:
            link, a = link_axis
            return [(link, zero), (link, tuple(float(x) for x in a))]

        primary = (
            self.main_focus,
            self.main_vertex,
            *frame(self.ok_link),
            *axis(self.azimuth_axis),
            *axis(self.elevation_axis),
        )
        if not self.has_counterreflector:
            return primary
        return (
            *primary,
            self.cr_focus,
            self.cr_vertex,
            *frame(self.cr_support_link),
            *frame(self.cr_link),
        )


def _norm(v: np.ndarray) -> np.ndarray:
    """|v| without abs or conjugation, so the formulas take a complex step (see C)."""
    return np.sqrt(np.sum(v * v))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product a × b of two 3-vectors (faster than numpy.cross for one pair)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _unit(v: np.ndarray) -> np.ndarray:
    return v / _norm(v)


def _frame(p: np.ndarray) -> np.ndarray:
    """Rotation (columns = axes in ground axes) from origin, origin + e_x, + e_y, + e_z."""
    return np.stack([p[1] - p[0], p[2] - p[0], p[3] - p[0]], axis=1)


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between unit vectors, 2 arcsin(|a − b|/2) (4.157), (4.166)."""
    return 2.0 * np.arcsin(_norm(a - b) / 2.0)


class _Geometry:
    """The ground-axis vectors of the mirror system at one set of positions."""

    def __init__(self, p: np.ndarray, system: MirrorSystem):
        self.p5f, self.p5v = p[0], p[1]
        self.R_ok = _frame(p[2:6])
        self.z_az = p[7] - p[6]  # azimuth axis (the mount's), ground axes
        self.x_el = p[9] - p[8]  # elevation axis
        self.n5 = _unit(self.p5f - self.p5v)  # main mirror's focal axis (4.155)
        if system.has_counterreflector:
            self.p7f, self.p7v = p[10], p[11]
            self.R_support = _frame(p[12:16])  # the counterreflector drive's frame 7c
            self.o7, self.R7 = p[16], _frame(p[16:20])
            self.n7 = _unit(self.p7f - self.p7v)  # counterreflector's focal axis (4.164)
        self.design = np.asarray(system.design_offset, dtype=float)

    def in_ok(self, v: np.ndarray) -> np.ndarray:
        """Ground-axis vector ``v`` expressed in the OK frame (its column ``v^OK``)."""
        return self.R_ok.T @ v

    def cr_axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Axes of Δβ7, Δθ7, Δα7 (4.169) in ground axes.

        First: x of the frame 7c; last: the counterreflector's own z; middle: the
        intermediate y of the 1–2–3 sequence, ``c1(β7) e_y``, which is perpendicular to
        both: ``(a3 × a1)/|a3 × a1|`` (equal to the book's ``c7 c3ᵀ(α7) e_y``).
        """
        a1 = self.R_support[:, 0]
        a3 = self.R7[:, 2]
        return a1, _unit(_cross(a3, a1)), a3


def _pointing_correction(g: _Geometry, source: np.ndarray) -> np.ndarray:
    """[Δα, Δβ] (rad) that bring the main mirror's axis onto the source (4.159)–(4.163).

    Turning the dish by Δα about the azimuth axis z1 and by Δβ about the elevation
    axis x1 (right-handed, the senses of the coordinates they add to) turns the source
    as seen in OK by ``−Y1 Δα − Y2 Δβ`` with ``Y1 = c42ᵀ<e_z>c11ᵀ s = Rᵀ(z1 × s)``,
    ``Y2 = Rᵀ(x1 × s)`` (4.160)–(4.162); the book's last step of (4.160) turns
    ``c2,1(β)<e_x>ᵀc2,1ᵀ(β)`` into ``<e_x>ᵀ``, which is exact (c1 leaves e_x alone).
    ``Y1 Δα + Y2 Δβ = s^OK − n5^OK`` (4.162), solved from its x, y rows (4.163): the OK z
    axis is the focal axis at construction, so those are the transverse components.
    """
    Y = np.stack([g.in_ok(_cross(g.z_az, source)), g.in_ok(_cross(g.x_el, source))], axis=1)
    A, b = Y[:2], (g.in_ok(source) - g.in_ok(g.n5))[:2]
    scale = float(np.max(np.abs(Y.real))) ** 2
    if abs(np.linalg.det(A.real)) <= SINGULAR * scale:
        raise SingularConfigurationError(
            "pointing correction (4.163) undefined: the 2×2 system is singular (the source "
            "is along the azimuth axis — the zenith keyhole — or the axes are degenerate)"
        )
    return np.linalg.solve(A, b)


def _cr_rotation(g: _Geometry) -> np.ndarray:
    """[Δβ7, Δθ7, Δα7] (rad) that turn the counterreflector's axis onto n5 (4.168)–(4.172).

    Turning by Δ_k about the axes a_k of :meth:`_Geometry.cr_axes` changes n7 by
    ``(a_k × n7) Δ_k``, so ``X_k = −Rᵀ(a_k × n7)`` (the book's ``<·>ᵀ`` form of (4.171))
    and ``Σ X_k Δ_k = n7^OK − n5^OK`` (4.171). **[erratum]** Every column is
    perpendicular to n7 (a turn about the focal axis does not move it), so the 3 × 3
    matrix of (4.172) has rank 2 and cannot be inverted as printed; we take the
    minimum-norm solution, ``X⁺ b = Xᵀ (X Xᵀ + m mᵀ)⁻¹ b`` with m = n7^OK the unit left
    null vector (exact: the pseudo-inverse of the rank-2 X). On the RT-70 (both
    optical points on the counterreflector's z) a3 = n7, so Δα7 = 0.
    """
    n7 = g.in_ok(g.n7)
    X = np.stack([-g.in_ok(_cross(a, g.n7)) for a in g.cr_axes()], axis=1)
    s = np.linalg.svd(X.real, compute_uv=False)
    if s[1] <= SINGULAR * s[0]:
        raise SingularConfigurationError(
            "counterreflector correction (4.172) undefined: its drive axes are degenerate "
            "(gimbal lock, θ7 = ±90°)"
        )
    b = n7 - g.in_ok(g.n5)
    return X.T @ np.linalg.solve(X @ X.T + np.outer(n7, n7), b)


def _cr_translation(g: _Geometry, rotation: np.ndarray) -> np.ndarray:
    """Δr7 (m, axes of the frame 7c) that puts the foci at their design offset (4.173)–(4.175).

    After the rotation corrections the focus is at ``o7 + R6 Δr + R6 c7* r7f`` with
    ``c7* ≈ c7 + <e_x>c7 Δβ7 + c7<c3ᵀe_y> Δθ7 + c7<e_z> Δα7`` (4.169); the translation
    that puts it at ``r5f + R d`` is ``Δr = Z4 − Z1 Δβ7 − Z2 Δθ7 − Z3 Δα7`` (4.175) with
    ``Z_k = R6ᵀ(a_k × (r7f − o7))`` and ``Z4 = R6ᵀ(r5f + R d − r7f)`` (the book's chain
    of construction offsets written as positions; d = 0 is the book).
    """
    lever = g.p7f - g.o7
    Z = [g.R_support.T @ _cross(a, lever) for a in g.cr_axes()]
    Z4 = g.R_support.T @ (g.p5f + g.R_ok @ g.design - g.p7f)
    return Z4 - Z[0] * rotation[0] - Z[1] * rotation[1] - Z[2] * rotation[2]


def mirror_outputs(system: MirrorSystem, source: Sequence[float]) -> list[Output]:
    """The outputs of the mirror system (table in the module docstring), in that order.

    Parameters
    ----------
    system : MirrorSystem
        The scene's optical points, OK frame and drive axes.
    source : (3,) array
        Direction to the source in ground axes (:func:`source_direction`); normalised.

    Returns
    -------
    list of rt70.model.outputs.Output
        Evaluate with :func:`rt70.model.outputs.evaluate` on either side. A system
        without a counterreflector has the main mirror's four: ``main_mirror_axis``,
        ``main_mirror_misalignment``, ``main_mirror_error``, ``pointing_correction``.
    """
    s = np.asarray(source, dtype=float).reshape(3)
    if not np.isfinite(s).all() or np.linalg.norm(s) == 0.0:
        raise Rt70Error(f"source direction must be a finite nonzero vector, got {s}")
    s = s / np.linalg.norm(s)
    points = system.points()

    def out(name: str, unit: str, size: int, f: Callable[[_Geometry], np.ndarray]) -> Output:
        return Output(name, unit, size, points, lambda p: f(_Geometry(p, system)))

    primary = [
        out("main_mirror_axis", "1", 3, lambda g: g.in_ok(g.n5)),
        out(
            "main_mirror_misalignment",
            "arcsec",
            1,
            lambda g: ARCSEC_PER_RAD * np.atleast_1d(_angle(s, g.n5)),
        ),
        out("main_mirror_error", "arcsec", 3, lambda g: ARCSEC_PER_RAD * g.in_ok(s - g.n5)),
        out(
            "pointing_correction",
            "arcsec",
            2,
            lambda g: ARCSEC_PER_RAD * _pointing_correction(g, s),
        ),
    ]
    if not system.has_counterreflector:
        return primary
    return [
        primary[0],
        out("counterreflector_axis", "1", 3, lambda g: g.in_ok(g.n7)),
        primary[1],
        primary[2],
        out(
            "counterreflector_misalignment",
            "arcsec",
            1,
            lambda g: ARCSEC_PER_RAD * np.atleast_1d(_angle(g.n7, g.n5)),
        ),
        out("counterreflector_error", "arcsec", 3, lambda g: ARCSEC_PER_RAD * g.in_ok(g.n7 - g.n5)),
        out(
            "counterreflector_source_misalignment",
            "arcsec",
            1,
            lambda g: ARCSEC_PER_RAD * np.atleast_1d(_angle(s, g.n7)),
        ),
        out("focal_offset", "mm", 3, lambda g: MM_PER_M * (g.in_ok(g.p7f - g.p5f) - g.design)),
        primary[3],
        out("counterreflector_rotation", "arcsec", 3, lambda g: ARCSEC_PER_RAD * _cr_rotation(g)),
        out(
            "counterreflector_translation",
            "mm",
            3,
            lambda g: MM_PER_M * _cr_translation(g, _cr_rotation(g)),
        ),
    ]
