"""A scene drive's angle θ_d and generalised force on the textbook side (formalism §4.5).

A ``<rt70:drive>`` (:class:`rt70.urdf.Drive`) turns its reducer torque K into a
generalised force ``Q = K ∂θ_d/∂q`` through the angle θ_d(q) its reducer twist
``Δ = θ_d − α_m / i_r`` is measured on (docs/urdf-extensions.md):

- a torque drive on a joint (4.143): θ_d is the joint's coordinate, found in this
  model's own coordinates; ``Q = K e_k``;
- a gear sector (4.150): θ_d is the mesh angle of :class:`rt70.physics.loads.SectorMesh`, from
  the link's and the stator's poses of the book's forward pass (4.5)–(4.7); the force
  is the pair of mesh Wrenches turned into ``Q = S U`` (4.129)–(4.131), each as
  :func:`rt70.textbook.points.generalized_force` does, from one structure matrix S.

The reference side computes the same from Pinocchio (:mod:`rt70.reference.drives`);
``rt70 validate`` compares them (row ``drives``).
"""

from __future__ import annotations

import numpy as np

from rt70.errors import UnknownLinkError
from rt70.guards.arrays import check_vector
from rt70.physics.loads import Pose, SectorMesh
from rt70.textbook.data import Data
from rt70.textbook.kinematics import (
    forward_kinematics,
    frame_jacobian,
    frame_pose,
    update_structure,
)
from rt70.textbook.model import Model
from rt70.textbook.points import link_point
from rt70.urdf.description import Drive


def link_pose(model: Model, data: Data, q: np.ndarray, link: str) -> Pose:
    """Rotation and origin of ``link``'s frame in ground axes at q (one forward pass).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    link : str
        Name of a URDF link of the scene.
    """
    if link not in model.link_frames:
        raise UnknownLinkError(f"{model.name}: no link '{link}' with a frame in the textbook model")
    data.q_full = model.expand(check_vector("q", q, model.nv))
    forward_kinematics(model, data, data.q_full)
    return _pose(model, data, link)


def _pose(model: Model, data: Data, link: str) -> Pose:
    """``link``'s pose from the forward pass already in ``data``."""
    body, r_link, c_link = model.link_frames[link]
    return frame_pose(data, body, r_link, c_link)


def _wrench_force(model: Model, data: Data, link: str, xyz, force: np.ndarray) -> np.ndarray:
    """``Q = J_vᵀ F`` of a force at a point, from the S already in ``data`` (4.129)–(4.131).

    :func:`rt70.textbook.points.generalized_force` without its own forward pass: the
    point Jacobian ``(T(r))ᵀ (Sᵀ)_body`` (4.63) turned to ground axes.
    """
    body, r = link_point(model, link, xyz)
    if body < 0:  # the ground does not move
        return np.zeros(model.nv)
    R, _ = frame_pose(data, body, np.zeros(3), np.eye(3))
    return (R @ frame_jacobian(data, body, r, np.eye(3))[:3]).T @ force


def sector_mesh(model: Model, data: Data, drive: Drive) -> SectorMesh:
    """The sector's pitch circle in the stator frame, from this side's poses at q = 0.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: one with a gear sector.
    """
    s = drive.sector
    q0 = np.zeros(model.nv)
    link, stator = link_pose(model, data, q0, s.link), link_pose(model, data, q0, s.stator)
    where = f"drive '{drive.name}' <rt70:sector>"
    return SectorMesh.at_construction(s.xyz, s.direction, s.axis, s.radius, link, stator, where)


def drive_angle(model: Model, data: Data, q: np.ndarray, drive: Drive, mesh=None) -> float:
    """θ_d at q, rad: the joint's coordinate, or the sector's mesh angle.

    ``mesh`` is :func:`sector_mesh`'s circle, computed here when not given.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: a torque on a joint's coordinate, or a gear sector.
    mesh : rt70.physics.loads.SectorMesh, optional
        The sector's pitch circle of :func:`sector_mesh`; computed here when None (pass it
        to save two forward passes per call).
    """
    q = check_vector("q", q, model.nv)
    if drive.sector is None:
        return float(q[model.coordinate_names.index(drive.joint)])
    s = drive.sector
    mesh = sector_mesh(model, data, drive) if mesh is None else mesh
    link, stator = link_pose(model, data, q, s.link), link_pose(model, data, q, s.stator)
    return mesh.angle(s.xyz, link, stator)[0]


def drive_force(
    model: Model, data: Data, q: np.ndarray, drive: Drive, torque: float = 1.0, mesh=None
) -> tuple[float, np.ndarray]:
    """``(θ_d, Q)`` at q: the angle and the generalised force of the reducer torque K.

    ``Q = K e_k`` for a torque drive (4.143); for a sector, ``Q = S U`` of the mesh
    force on the link and its reaction on the stator (4.150), which is
    ``K ∂θ_d/∂q``. With the default ``torque = 1`` Q is the gradient ∂θ_d/∂q.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: a torque on a joint's coordinate, or a gear sector.
    torque : float
        The reducer torque K, N·m; 1 gives the gradient ``∂θ_d/∂q`` as Q.
    mesh : rt70.physics.loads.SectorMesh, optional
        The sector's pitch circle of :func:`sector_mesh`; computed here when None (pass it
        to save two forward passes per call).
    """
    q = check_vector("q", q, model.nv)
    if drive.sector is None:
        k = model.coordinate_names.index(drive.joint)
        Q = np.zeros(model.nv)
        Q[k] = torque
        return float(q[k]), Q
    s = drive.sector
    mesh = sector_mesh(model, data, drive) if mesh is None else mesh
    update_structure(model, data, q)  # the forward pass and S, once for both wrenches
    link, stator = _pose(model, data, s.link), _pose(model, data, s.stator)
    angle = mesh.angle(s.xyz, link, stator)[0]
    wrenches = mesh.wrenches(s.link, s.stator, s.xyz, torque, link, stator)
    return angle, sum(
        _wrench_force(model, data, w.link, w.xyz, np.asarray(w.force)) for w in wrenches
    )


def drive_force_function(model: Model, data: Data, drive: Drive, mesh=None):
    """``q ↦ (θ_d, ∂θ_d/∂q)``: :func:`drive_force` at unit torque.

    The twin of :func:`rt70.reference.drives.drive_force_function`, which compiles it
    where it can; here it is :func:`drive_force` itself.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: a torque on a joint's coordinate, or a gear sector.
    mesh : rt70.physics.loads.SectorMesh, optional
        The sector's pitch circle of :func:`sector_mesh` (computed at every call when None).
    """
    return lambda q: drive_force(model, data, q, drive, 1.0, mesh)
