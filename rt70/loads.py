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
nothing else changes. This module sits below both sides: it imports nothing of rt70
but the argument checks (tests/test_import_rules.py, ``SHARED``).
"""

from __future__ import annotations

from dataclasses import dataclass

from rt70.arrays import check_vector

Vector3 = tuple[float, float, float]


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
