"""Points of bodies on the reference side: position, Jacobian, generalised force of a load.

All from Pinocchio's own kinematics. A URDF link is one of Pinocchio's ``BODY`` frames:
a parent joint and the link's placement in it. A point ``xyz`` of the link is placed at
``oMi[joint] · placement · xyz`` (``pin.forwardKinematics``); its velocity and the
link's angular velocity come from Pinocchio's Jacobian of the parent joint in the
joint's own frame (``pin.computeJointJacobian``), moved to the point and turned to
ground axes, then mapped to the book's coordinates by ``J`` of
:func:`rt70.reference.coordinates.to_pinocchio` (``v = J q̇``); a wrench acts as
``Q = Jᵀ f``. Independent of the textbook side's
:mod:`rt70.textbook.points`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from rt70.errors import UnknownLinkError
from rt70.guards.arrays import check_vector
from rt70.physics.loads import Wrench
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.model import ReferenceData, ReferenceModel
from rt70.urdf.modal_record import parse_node_point


def link_point(model: ReferenceModel, link: str, xyz) -> tuple[int, pin.SE3]:
    """Pinocchio's parent joint of ``link`` and the placement of the point in it.

    A modal body's node (``"<body>/node<n>"``, :func:`rt70.urdf.modal_record.node_point`)
    is its own translation joint here (:mod:`rt70.reference.modal_nodes`), whose frame
    has the body frame's axes and moves with the node: the point is ``xyz`` from it.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    link : str
        Name of a URDF link of the scene.
    xyz : array_like, shape (3,)
        The point in the link's frame, m.

    Raises
    ------
    UnknownLinkError
        If Pinocchio has no body frame called ``link`` and no node joint of that name.
    """
    m = model.pin_model
    if link in model.node_joints:
        offset = pin.SE3(np.eye(3), check_vector(f"point of node '{link}'", xyz, 3))
        return model.node_joints[link], offset
    node = parse_node_point(link)
    if node is not None and any(b.name == node[0] for b in model.modal_bodies):
        raise UnknownLinkError(
            f"{m.name}: node '{link}' is not placed on the reference side, which places "
            "only the nodes with mass (a node index past the file's, or a massless node)"
        )
    if link not in model.body_frames:
        raise UnknownLinkError(f"{m.name}: no link '{link}' among Pinocchio's body frames")
    frame = m.frames[model.body_frames[link]]
    offset = pin.SE3(np.eye(3), check_vector(f"point of link '{link}'", xyz, 3))
    return frame.parentJoint, frame.placement * offset


def point_positions(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    points: Sequence[tuple[str, np.ndarray]],
) -> np.ndarray:
    """Ground-axis positions (n, 3) of the points ``(link, xyz)`` at q, in m.

    One ``pin.forwardKinematics`` for all of them; each is ``(oMi[joint] · placement)``'s
    translation, the placement located once per ``data`` (:func:`link_point`).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    points : sequence of (str, array_like)
        The points: a link's name and the point in the link's frame (m).
    """
    located = [_located(model, data, link, xyz) for link, xyz in points]
    qp, _, _, _ = to_pinocchio(model, q)
    d = data.pin_data
    pin.forwardKinematics(model.pin_model, d, qp)
    out = np.empty((len(located), 3))
    for k, (joint, placement) in enumerate(located):
        out[k] = (d.oMi[joint] * placement).translation
    return out


def _located(model: ReferenceModel, data: ReferenceData, link: str, xyz) -> tuple[int, pin.SE3]:
    """:func:`link_point`, kept in ``data.placements`` (a point checked once is valid)."""
    try:
        key = (link, tuple(np.asarray(xyz, dtype=float).ravel().tolist()))
    except (TypeError, ValueError):
        return link_point(model, link, xyz)  # not numbers: its error names the point
    found = data.placements.get(key)
    if found is None:
        found = data.placements[key] = link_point(model, link, xyz)
    return found


def point_position(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, link: str, xyz
) -> np.ndarray:
    """Ground-axis position (3,) of the point ``xyz`` of ``link`` at q, in m.

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
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    return point_positions(model, data, q, [(link, xyz)])[0]


def point_jacobian_pinocchio(
    model: ReferenceModel, data: ReferenceData, qp: np.ndarray, link: str, xyz
) -> np.ndarray:
    """``[J_v; J_ω]``, 6 × nv of Pinocchio's v, in ground axes, at Pinocchio's ``qp``.

    Pinocchio's ``computeJointJacobian`` (the joint's velocity in its own frame, from
    the placements of the ancestors relative to the joint) moved to the point by the
    action of its placement, ``Ad(placement⁻¹)``, turned to ground axes by the point
    frame's rotation. It is Pinocchio's ``getFrameJacobian(..., LOCAL_WORLD_ALIGNED)``
    without passing through the ground origin: that form shifts velocities taken at the
    origin back to the point, which costs ε times the point's distance from the origin
    (1e-12 relative on the RT-70 in millimetres, against 1e-16 here).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    qp : numpy.ndarray, shape (nq,)
        Pinocchio's configuration (:func:`~rt70.reference.coordinates.to_pinocchio`).
    link : str
        Name of a URDF link of the scene.
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    joint, placement = link_point(model, link, xyz)
    m, d = model.pin_model, data.pin_data
    pin.forwardKinematics(m, d, qp)
    local = np.reshape(pin.computeJointJacobian(m, d, qp, joint), (6, m.nv))  # (6,) if nv = 1
    local = placement.inverse().action @ local  # [v_p; ω] in the point frame's axes
    R = (d.oMi[joint] * placement).rotation
    return np.vstack([R @ local[:3], R @ local[3:]])


def point_jacobian(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, link: str, xyz
) -> tuple[np.ndarray, np.ndarray]:
    """``(J_v, J_ω)``, 3 × nv each, in ground axes: ``v_p = J_v q̇``, ``ω = J_ω q̇``.

    :func:`point_jacobian_pinocchio` times ``J`` (book coordinates → Pinocchio's ``v``).

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
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    qp, _, J, _ = to_pinocchio(model, q)
    jac = point_jacobian_pinocchio(model, data, qp, link, xyz)
    if J is not None:
        jac = jac @ J
    return jac[:3], jac[3:]


def generalized_force(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray, wrench: Wrench
) -> np.ndarray:
    """Generalised force (nv,) of a wrench: ``Q = Jᵀ f``, ``f = [F; M]`` in ground axes.

    ``J`` is the point's ``LOCAL_WORLD_ALIGNED`` frame Jacobian in book coordinates
    (:func:`point_jacobian`); the result is what the load adds to the right-hand side.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    wrench : rt70.physics.loads.Wrench
        A force (N) at a point of a link and a torque (N·m) on it, ground axes.
    """
    Jv, Jw = point_jacobian(model, data, q, wrench.link, wrench.xyz)
    return Jv.T @ np.asarray(wrench.force) + Jw.T @ np.asarray(wrench.torque)
