"""A scene drive's angle θ_d and generalised force on the reference side (formalism §4.5).

The same quantities as :mod:`rt70.textbook.drives`, from Pinocchio's own kinematics:

- a torque drive on a joint (4.143): the joint's torque enters Pinocchio's ``tau`` at
  the joint's velocity index and is mapped to the book's coordinates, ``Q = Jᵀ τ``
  (:func:`rt70.reference.coordinates.to_pinocchio`); θ_d is Pinocchio's joint
  configuration (an angle, or atan2 of the cos/sin of a continuous joint);
- a gear sector (4.150): the link's and the stator's placements ``oMi · placement``
  (``pin.forwardKinematics``) give the mesh angle of :class:`rt70.physics.loads.SectorMesh`;
  the mesh Wrenches become ``Q = Jᵀ f`` by :func:`rt70.reference.points.generalized_force`.

Independent of the textbook side.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rt70.physics.loads import Pose, SectorMesh
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.model import ReferenceData, ReferenceModel
from rt70.reference.points import generalized_force, link_point
from rt70.urdf.description import Drive


def link_pose(model: ReferenceModel, data: ReferenceData, q: np.ndarray, link: str) -> Pose:
    """Rotation and origin of ``link``'s frame in ground axes at q (Pinocchio's placements).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    link : str
        Name of a URDF link of the scene.
    """
    m, d = model.pin_model, data.pin_data
    joint, placement = link_point(model, link, np.zeros(3))
    qp = to_pinocchio(model, q)[0]
    pin.forwardKinematics(m, d, qp)
    placed = d.oMi[joint] * placement
    return placed.rotation.copy(), placed.translation.copy()


def sector_mesh(model: ReferenceModel, data: ReferenceData, drive: Drive) -> SectorMesh:
    """The sector's pitch circle in the stator frame, from Pinocchio's poses at q = 0.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: one with a gear sector.
    """
    s = drive.sector
    q0 = np.zeros(model.nv)
    link, stator = link_pose(model, data, q0, s.link), link_pose(model, data, q0, s.stator)
    where = f"drive '{drive.name}' <rt70:sector>"
    return SectorMesh.at_construction(s.xyz, s.direction, s.axis, s.radius, link, stator, where)


def _joint_torque(
    model: ReferenceModel, q: np.ndarray, joint: str, torque: float
) -> tuple[float, np.ndarray]:
    """θ_d and ``Q = Jᵀ τ`` of a torque on Pinocchio's joint ``joint``."""
    m = model.pin_model
    jm = m.joints[m.getJointId(joint)]
    qp, _, J, _ = to_pinocchio(model, q)
    if jm.nq == 2:  # continuous: (cos, sin)
        angle = float(np.arctan2(qp[jm.idx_q + 1], qp[jm.idx_q]))
    else:
        angle = float(qp[jm.idx_q])
    tau = np.zeros(m.nv)
    tau[jm.idx_v] = torque
    return angle, tau if J is None else J.T @ tau


def drive_angle(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, drive: Drive, mesh=None
) -> float:
    """θ_d at q, rad: the joint's configuration, or the sector's mesh angle.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: a torque on a joint's coordinate, or a gear sector.
    mesh : rt70.physics.loads.SectorMesh, optional
        The sector's pitch circle of :func:`sector_mesh`; computed here when None (pass it to
        save two placements per call).
    """
    if drive.sector is None:
        return _joint_torque(model, q, drive.joint, 0.0)[0]
    s = drive.sector
    mesh = sector_mesh(model, data, drive) if mesh is None else mesh
    link, stator = link_pose(model, data, q, s.link), link_pose(model, data, q, s.stator)
    return mesh.angle(s.xyz, link, stator)[0]


def drive_force(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    drive: Drive,
    torque: float = 1.0,
    mesh=None,
) -> tuple[float, np.ndarray]:
    """``(θ_d, Q)`` at q: the angle and the generalised force of the reducer torque K.

    ``Q = Jᵀ τ`` of the joint torque (4.143), or ``Jᵀ f`` of the mesh force and its
    reaction (4.150), ``K ∂θ_d/∂q``; with ``torque = 1`` Q is the gradient.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: a torque on a joint's coordinate, or a gear sector.
    torque : float
        The reducer torque K, N·m; 1 gives the gradient ``∂θ_d/∂q`` as Q.
    mesh : rt70.physics.loads.SectorMesh, optional
        The sector's pitch circle of :func:`sector_mesh`; computed here when None (pass it to
        save two placements per call).
    """
    if drive.sector is None:
        return _joint_torque(model, q, drive.joint, torque)
    s = drive.sector
    mesh = sector_mesh(model, data, drive) if mesh is None else mesh
    link, stator = link_pose(model, data, q, s.link), link_pose(model, data, q, s.stator)
    angle = mesh.angle(s.xyz, link, stator)[0]
    wrenches = mesh.wrenches(s.link, s.stator, s.xyz, torque, link, stator)
    return angle, sum(generalized_force(model, data, q, w) for w in wrenches)


def drive_force_function(model: ReferenceModel, data: ReferenceData, drive: Drive, mesh=None):
    """``q ↦ (θ_d, ∂θ_d/∂q)``: :func:`drive_force` at unit torque, compiled where it can.

    A gear sector's θ_d depends on its mesh point P in the stator's axes only, so
    ``∂θ_d/∂q = (∂θ_d/∂P)ᵀ ∂P/∂q`` with P and ∂P/∂q from the compiled joint walk between
    the two links, angle and gradient in one compiled call
    (:meth:`rt70.reference.element_kernels.RelativePoints.sector_angle`), instead of two
    placements and two point Jacobians from Pinocchio per evaluation; the same numbers
    (tested). A joint drive on a model in Pinocchio's own coordinates reads its
    coordinate, with the unit vector as gradient, as :func:`drive_force` gives them;
    mapped coordinates (continuous or mimic joints) or a path the kernels do not
    support keep :func:`drive_force`.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    drive : rt70.urdf.Drive
        The scene's ``<rt70:drive>``: a torque on a joint's coordinate, or a gear sector.
    mesh : rt70.physics.loads.SectorMesh, optional
        The sector's pitch circle of :func:`sector_mesh`; computed once here when None.
    """
    if drive.sector is None and model.identity_map:  # θ_d is the joint's coordinate
        m = model.pin_model
        k = m.joints[m.getJointId(drive.joint)].idx_q  # the book's order is Pinocchio's
        unit = np.zeros(model.nv)
        unit[k] = 1.0
        unit.flags.writeable = False
        return lambda q: (float(q[k]), unit)
    if drive.sector is None or not model.identity_map:
        return lambda q: drive_force(model, data, q, drive, 1.0, mesh)
    from rt70.reference.element_kernels import RelativePoints

    s = drive.sector
    mesh = sector_mesh(model, data, drive) if mesh is None else mesh
    mesh_point = link_point(model, s.link, s.xyz)  # (joint, placement); names a missing link
    stator = link_point(model, s.stator, np.zeros(3))
    points = RelativePoints.of(model, [stator], [mesh_point])
    if points is None:
        return lambda q: drive_force(model, data, q, drive, 1.0, mesh)
    centre, u, v = (np.ascontiguousarray(a, dtype=float) for a in (mesh.centre, mesh.u, mesh.v))
    return lambda q: points.sector_angle(q, centre, u, v)
