"""Wind generalised forces on the textbook side (formalism §4.4, (4.132)–(4.136)).

For every ``<rt70:wind>`` of the model (:attr:`rt70.textbook.model.Model.winds`) the
link's pose comes from the book's forward pass (4.5)–(4.7); the shared
:func:`rt70.physics.aerodynamics.wind_wrench` gives the wind's force at the reference point
and its free moment in ground axes; the generalised force is ``Q_w = S W`` (4.129)–(4.131),
i.e. ``J_vᵀ F + J_ωᵀ M`` with the point's Jacobian ``(T(r))ᵀ (Sᵀ)_body`` (4.63) turned to
ground axes, all from one structure matrix S. The reference side computes the same from
Pinocchio (:mod:`rt70.reference.wind`); ``rt70 validate`` compares them (row ``wind``).
"""

from __future__ import annotations

import numpy as np

from rt70.guards.arrays import check_vector
from rt70.physics.aerodynamics import WindCondition, wind_wrench
from rt70.physics.loads import Wrench
from rt70.surface.pressure import nodal_forces
from rt70.textbook.data import Data
from rt70.textbook.kinematics import frame_pose, update_structure
from rt70.textbook.model import Model
from rt70.textbook.points import (
    ground_jacobian,
    link_point,
    located_jacobian,
    located_point,
    located_position,
)
from rt70.urdf.modal_record import node_point


def _force(model: Model, data: Data, wrench: Wrench) -> np.ndarray:
    """``Q = J_vᵀ F + J_ωᵀ M`` of a wrench from the S already in ``data`` (4.129)–(4.131)."""
    body, r = link_point(model, wrench.link, wrench.xyz)
    if body < 0:  # the ground does not move
        return np.zeros(model.nv)
    Jv, Jw = ground_jacobian(data, body, r)
    return Jv.T @ np.asarray(wrench.force) + Jw.T @ np.asarray(wrench.torque)


def _surface_force(model: Model, data: Data, q: np.ndarray, wrench: Wrench, body) -> np.ndarray:
    """``Q = Σ J_v,nᵀ f_n`` of the wrench spread over ``body``'s surface nodes (4.129)."""
    s = body.surface
    located = [located_point(model, node_point(body.name, int(n)), np.zeros(3)) for n in s.nodes]
    p = np.array([located_position(data, q, where) for where in located])
    point = located_position(data, q, located_point(model, wrench.link, wrench.xyz))
    forces = nodal_forces(wrench.force, wrench.torque, point, p, s.weights)
    Q = np.zeros(model.nv)
    for f, where in zip(forces, located, strict=True):
        Q += located_jacobian(data, q, where)[0].T @ f
    return Q


def wind_wrenches(
    model: Model, data: Data, q: np.ndarray, condition: WindCondition
) -> dict[str, Wrench]:
    """The wind's Wrench on every exposed body at q, by element name (ground axes).

    Runs the forward pass and fills S in ``data`` (:func:`update_structure`).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    condition : rt70.physics.aerodynamics.WindCondition
        The steady wind: speed (m/s), azimuth it blows from (degrees), air density.
    """
    update_structure(model, data, check_vector("q", q, model.nv))
    out = {}
    for w in model.winds:
        link_point(model, w.link, w.xyz)  # refuses a link without a frame
        body, r_link, c_link = model.link_frames[w.link]
        pose = frame_pose(data, body, r_link, c_link)
        out[w.name] = wind_wrench(w, pose, condition, model.air_density)
    return out


def wind_forces(
    model: Model, data: Data, q: np.ndarray, condition: WindCondition
) -> dict[str, np.ndarray]:
    """Generalised force (nv,) of each exposed body at q, by element name: ``S W_i``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    condition : rt70.physics.aerodynamics.WindCondition
        The steady wind: speed (m/s), azimuth it blows from (degrees), air density.
    """
    wrenches = wind_wrenches(model, data, q, condition)
    bodies = {m.name: m for m in model.modal}
    surfaces = {w.name: w.surface for w in model.winds}
    return {
        name: _force(model, data, w)
        if surfaces[name] is None
        else _surface_force(model, data, q, w, bodies[surfaces[name]])
        for name, w in wrenches.items()
    }


def wind_force(model: Model, data: Data, q: np.ndarray, condition: WindCondition) -> np.ndarray:
    """Generalised wind force (nv,) at q: ``Q_w = S W`` summed over the exposed bodies.

    Zero for a model without ``<rt70:wind>`` elements.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    condition : rt70.physics.aerodynamics.WindCondition
        The steady wind: speed (m/s), azimuth it blows from (degrees), air density.
    """
    Q = np.zeros(model.nv)
    for value in wind_forces(model, data, q, condition).values():
        Q += value
    return Q


def wind_force_function(model: Model, data: Data):
    """``(q, condition) ↦ Q_w``: :func:`wind_force`.

    The twin of :func:`rt70.reference.wind.wind_force_function`, which compiles it where
    it can; here it is :func:`wind_force` itself.
    """
    return lambda q, condition: wind_force(model, data, q, condition)
