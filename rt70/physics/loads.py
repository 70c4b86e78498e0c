"""Loads: a wrench on a body, or on a point of it, as one plain value both sides read.

A :class:`Wrench` is a force applied at a point of a link and a torque on that link,
both in ground axes. Each side turns it into a generalised force by its own
kinematics (formalism §4.4, (4.129)–(4.131)):

- textbook side, :func:`rt70.textbook.points.generalized_force`: ``Q = S U`` with the
  book's structure matrix, i.e. ``Q = J_vᵀ F + J_ωᵀ M`` with the point's Jacobian
  ``[J_v; J_ω] = (T(r)[c])ᵀ Sᵀ`` of :func:`rt70.textbook.points.point_jacobian`;
- reference side, :func:`rt70.reference.points.generalized_force`: ``Q = Jᵀ f`` with
  Pinocchio's Jacobian of the link's parent joint (``pin.computeJointJacobian``) moved
  to the point and turned to ground axes, mapped to the book's coordinates.

``Q`` is what the load adds to the right-hand side of ``A q̈ + B q̇ = Q_g + Q_c + Q_d +
Q_u`` (drives, wind, a probe force); its power is ``q̇ᵀ Q = F·v_p + M·ω``. A new load
(wind on a body, a drive's reaction) is a function returning Wrenches at a state;
nothing else changes.

The first such function is a drive's gear sector (:class:`SectorMesh`, (4.150)): the
pinion on the stator pushes the sector's link at the mesh point with ``F = K/ρ`` along
the pitch circle's tangent and the sector pushes back on the pinion, two Wrenches whose
generalised force is exactly ``K ∂θ_d/∂q`` for the mesh angle θ_d (docs/urdf-extensions.md,
``<rt70:drive>``). Each side hands in the link's and the stator's poses from its own
kinematics. This module sits below both sides: it imports nothing of rt70 but the errors
and the argument checks (tests/test_import_rules.py, ``SHARED``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector

Vector3 = tuple[float, float, float]

#: A frame's pose in ground axes: its rotation (3, 3) and its origin (3,).
Pose = tuple[np.ndarray, np.ndarray]


#: Relative accuracy to which a sector's pitch circle must survive the rounding of the
#: positions it is built from (:meth:`SectorMesh.at_construction`).
RADIUS_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Wrench:
    """A force at a point of a link and a torque on the link, in ground axes.

    Parameters
    ----------
    link : str
        Name of the URDF link the load acts on.
    xyz : 3 floats
        Point of application in the link's frame, m (default its origin).
    force : 3 floats
        Force F in ground axes, N.
    torque : 3 floats
        Torque M in ground axes, N·m (a free moment: it does not depend on the point).

    The vectors are stored as tuples of floats, so a Wrench is a hashable value.

    Raises
    ------
    ShapeError, NonFiniteError
        If a vector does not have 3 finite entries.
    """

    link: str
    xyz: Vector3 = (0.0, 0.0, 0.0)
    force: Vector3 = (0.0, 0.0, 0.0)
    torque: Vector3 = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        for name in ("xyz", "force", "torque"):
            x = check_vector(f"wrench on '{self.link}': {name}", getattr(self, name), 3)
            object.__setattr__(self, name, tuple(float(v) for v in x))


@dataclass(frozen=True, eq=False)
class SectorMesh:
    """A gear sector's pitch circle fixed in the stator frame, and the mesh angle θ_d.

    Built once from the construction (q = 0) by :meth:`at_construction`: the circle's
    centre ``centre``, the unit vector ``u`` from it to the mesh point and the unit
    tangent ``v = axis × u``, all in the stator's axes. At a state with the sector's
    mesh point at ``P`` (stator axes), ``d = P − centre`` and

        θ_d = atan2(v·d, u·d),

    zero at the construction; when only the driven axis turns (the structure otherwise
    undeformed) θ_d is that axis' angle. Valid for ``|θ_d| < π``.
    """

    centre: np.ndarray
    u: np.ndarray
    v: np.ndarray

    @classmethod
    def at_construction(
        cls, xyz, direction, axis, radius: float, link: Pose, stator: Pose, where: str = "sector"
    ) -> SectorMesh:
        """The circle from the sector's data (link axes) and both poses at q = 0.

        The centre lies at ``xyz + radius (axis × direction)`` in the link: the tangent
        ``direction`` turns positively about ``axis``.

        Parameters
        ----------
        xyz : array_like, shape (3,)
            The mesh point on the sector, in the sector link's frame, m.
        direction : array_like, shape (3,)
            The unit tangent of the pitch circle at the mesh point, link axes.
        axis : array_like, shape (3,)
            The unit axis the sector turns about, link axes (normal to ``direction``).
        radius : float
            The pitch radius r, m (positive).
        link, stator : Pose
            The poses ``(R, p)`` of the sector's link and of the stator (the link that
            carries the pinion) in ground axes at q = 0: R (3, 3), p (3,) in m.
        where : str
            The sector as messages name it.

        Raises
        ------
        Rt70Error
            (naming ``where``) If the radius is lost in the rounding of the positions:
            the centre and the mesh point, each rounded to ε of the positions' size, must
            lie ``radius`` apart to :data:`RADIUS_TOLERANCE`, or θ_d would be rounding
            noise (its gradient 1/ρ, a division by a rounded difference).
        """
        (R_l, p_l), (R_s, p_s) = link, stator
        xyz, t, a = (np.asarray(x, dtype=float) for x in (xyz, direction, axis))
        centre_link = xyz + radius * np.cross(a, t)
        centre = R_s.T @ (p_l + R_l @ centre_link - p_s)
        mesh = R_s.T @ (p_l + R_l @ xyz - p_s)
        distance = float(np.linalg.norm(mesh - centre))
        if not abs(distance - radius) <= RADIUS_TOLERANCE * radius:
            size = max(float(np.abs(np.concatenate([p_l, p_s, xyz])).max()), 1.0)
            raise Rt70Error(
                f"{where}: radius {radius:g} m is lost in the rounding of positions of "
                f"{size:.3g} m (the pitch circle's centre and mesh point lie {distance:.3g} m "
                "apart): no gear angle can be computed"
            )
        u = (mesh - centre) / radius
        a_s = R_s.T @ R_l @ a
        return cls(centre, u, np.cross(a_s, u))

    def angle(self, xyz, link: Pose, stator: Pose) -> tuple[float, np.ndarray, np.ndarray]:
        """``(θ_d, ∂θ_d/∂P in ground axes, P)`` at the poses of a state.

        ``P`` is the mesh point ``xyz`` of the link in stator axes (where the pinion
        touches it); ``∂θ_d/∂P = (x v − y u)/(x² + y²)`` with ``x = u·d``, ``y = v·d``,
        turned to ground axes.

        Parameters
        ----------
        xyz : array_like, shape (3,)
            The mesh point on the sector, in the sector link's frame, m.
        link, stator : Pose
            The poses ``(R, p)`` of the sector's link and of the stator in ground axes at
            the state: R (3, 3), p (3,) in m.

        Returns
        -------
        tuple
            θ_d (rad), ∂θ_d/∂P (rad/m, shape (3,), ground axes) and P (m, shape (3,),
            stator axes).
        """
        (R_l, p_l), (R_s, p_s) = link, stator
        P = R_s.T @ (p_l + R_l @ np.asarray(xyz, dtype=float) - p_s)
        d = P - self.centre
        x, y = float(self.u @ d), float(self.v @ d)
        grad = (x * self.v - y * self.u) / (x * x + y * y)
        return float(np.arctan2(y, x)), R_s @ grad, P

    def wrenches(
        self, link_name: str, stator_name: str, xyz, torque: float, link: Pose, stator: Pose
    ) -> list[Wrench]:
        """The mesh force of the reducer torque ``K`` on the link and on the stator (4.150).

        ``F = K ∂θ_d/∂P`` (magnitude K/ρ, ρ the mesh point's distance from the axis,
        ``r`` when undeformed) on the link at ``xyz``, ``−F`` on the stator at the same
        point ``P``: their generalised force is ``K ∂θ_d/∂q`` on either side.

        Parameters
        ----------
        link_name, stator_name : str
            The URDF links of the sector and of the stator (the wrenches' links).
        xyz : array_like, shape (3,)
            The mesh point on the sector, in the sector link's frame, m.
        torque : float
            The reducer torque K, N·m.
        link, stator : Pose
            The poses ``(R, p)`` of the two links in ground axes at the state.

        Returns
        -------
        list of Wrench
            ``F`` on the link at ``xyz`` and ``−F`` on the stator at ``P``, N.
        """
        _, grad, P = self.angle(xyz, link, stator)
        force = torque * grad
        return [
            Wrench(link_name, tuple(xyz), tuple(force)),
            Wrench(stator_name, tuple(P), tuple(-force)),
        ]
