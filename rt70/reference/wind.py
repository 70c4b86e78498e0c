"""Wind generalised forces on the reference side (formalism §4.4, (4.132)–(4.136)).

The same quantities as :mod:`rt70.textbook.wind`, from Pinocchio's own kinematics: each
exposed body's link pose is its placement ``oMi · placement`` (``pin.forwardKinematics``,
:func:`rt70.reference.drives.link_pose`); the shared
:func:`rt70.physics.aerodynamics.wind_wrench` gives the wind's Wrench, and ``Q = Jᵀ f`` with
the point's ``LOCAL_WORLD_ALIGNED`` Jacobian in book coordinates
(:func:`rt70.reference.points.generalized_force`). Independent of the textbook side.
"""

from __future__ import annotations

import numpy as np

from rt70.physics.aerodynamics import WindCondition, wind_load, wind_wrench
from rt70.physics.loads import Wrench
from rt70.reference.drives import link_pose
from rt70.reference.model import ReferenceData, ReferenceModel
from rt70.reference.points import generalized_force, link_point, point_jacobian, point_positions
from rt70.surface.pressure import nodal_forces
from rt70.urdf.modal_record import node_point


def wind_wrenches(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, condition: WindCondition
) -> dict[str, Wrench]:
    """The wind's Wrench on every exposed body at q, by element name (ground axes).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    condition : rt70.physics.aerodynamics.WindCondition
        The steady wind: speed (m/s), azimuth it blows from (degrees), air density.
    """
    return {
        w.name: wind_wrench(w, link_pose(model, data, q, w.link), condition, model.air_density)
        for w in model.winds
    }


def wind_forces(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, condition: WindCondition
) -> dict[str, np.ndarray]:
    """Generalised force (nv,) of each exposed body at q, by element name: ``Jᵀ f_i``.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    condition : rt70.physics.aerodynamics.WindCondition
        The steady wind: speed (m/s), azimuth it blows from (degrees), air density.
    """
    wrenches = wind_wrenches(model, data, q, condition)
    bodies = {b.name: b for b in model.modal_bodies}
    surfaces = {w.name: w.surface for w in model.winds}
    return {
        name: generalized_force(model, data, q, w)
        if surfaces[name] is None
        else _surface_force(model, data, q, w, bodies[surfaces[name]])
        for name, w in wrenches.items()
    }


def _surface_force(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, wrench: Wrench, body
) -> np.ndarray:
    """``Q = Σ J_nᵀ f_n`` of the wrench spread over ``body``'s surface nodes.

    The nodes are Pinocchio's node joints (:mod:`rt70.reference.modal_nodes`); their
    positions and Jacobians are Pinocchio's; :func:`rt70.surface.pressure.nodal_forces`
    spreads the wrench.
    """
    s = body.surface
    points = [(node_point(body.name, int(n)), np.zeros(3)) for n in s.nodes]
    p = point_positions(model, data, q, [*points, (wrench.link, wrench.xyz)])
    forces = nodal_forces(wrench.force, wrench.torque, p[-1], p[:-1], s.weights)
    Q = np.zeros(model.nv)
    for f, (link, xyz) in zip(forces, points, strict=True):
        Q += point_jacobian(model, data, q, link, xyz)[0].T @ f
    return Q


def wind_force(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, condition: WindCondition
) -> np.ndarray:
    """Generalised wind force (nv,) at q: ``Q_w = Jᵀ f`` summed over the exposed bodies.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    condition : rt70.physics.aerodynamics.WindCondition
        The steady wind: speed (m/s), azimuth it blows from (degrees), air density.
    """
    Q = np.zeros(model.nv)
    for value in wind_forces(model, data, q, condition).values():
        Q += value
    return Q


def wind_force_function(model: ReferenceModel, data: ReferenceData):
    """``(q, condition) ↦ Q_w``: :func:`wind_force`, compiled where it can.

    Each exposed body's pose and the Jacobian of its load point come from the compiled
    joint walk from the ground to the link (:class:`rt70.reference.element_kernels.
    RelativePoints`, frame 1 the ground) instead of Pinocchio's placements and point
    Jacobians per body and evaluation; :func:`rt70.physics.aerodynamics.wind_load` gives the
    force and moment of :func:`~rt70.physics.aerodynamics.wind_wrench` from the link's
    rotation (a uniform flow does not read its origin), and ``Q = J_vᵀ F + J_ωᵀ M``
    (tested equal to :func:`wind_force`). Mapped coordinates, a wind spread over a surface or an
    unsupported path keep :func:`wind_force`.
    """
    slow = lambda q, condition: wind_force(model, data, q, condition)  # noqa: E731
    if not model.identity_map or not model.winds or any(w.surface for w in model.winds):
        return slow
    import pinocchio as pin

    from rt70.reference.element_kernels import RelativePoints

    if not all(w.link in model.body_frames for w in model.winds):
        return slow  # its error names the link
    points = [link_point(model, w.link, w.xyz) for w in model.winds]
    ground = [(0, pin.SE3.Identity())] * len(points)
    frames = RelativePoints.of(model, ground, points)
    if frames is None:
        return slow

    def force(q: np.ndarray, condition: WindCondition) -> np.ndarray:
        C, _, J = frames.frames(q)
        Q = np.zeros(model.nv)
        velocity, density = condition.velocity(), condition.air_density(model.air_density)
        for i, w in enumerate(model.winds):  # a uniform flow reads the link's rotation only
            load = wind_load(w, C[i], velocity, density)
            if load is not None:
                Q += J[i, :3].T @ load[0] + J[i, 3:].T @ load[1]
        return Q

    return force
