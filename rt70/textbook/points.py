"""Points of bodies on the textbook side: position, Jacobian, generalised force of a load.

All from the book's matrices (formalism §4.2, §4.4). A point ``xyz`` of a URDF link
sits at ``r = r_link + c_link · xyz`` in the frame of the link's body
(``Model.link_frames``: a link welded by fixed joints lies on its parent's body). Its
position comes from the absolute body poses of the forward pass; its velocity from the
stacked body Jacobian ``V⁰ = Sᵀ q̇`` (4.63) moved to the point, ``V_p = (T(r))ᵀ V_body``;
a wrench on it acts as ``Q = S U`` (4.129)–(4.131). All results are in ground axes. The
reference side computes the same from Pinocchio (:mod:`rt70.reference.points`);
``rt70 validate`` compares them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.errors import UnknownLinkError
from rt70.guards.arrays import check_vector
from rt70.physics.loads import Wrench
from rt70.textbook.data import Data
from rt70.textbook.kinematics import (
    forward_kinematics,
    frame_jacobian,
    frame_pose,
    update_structure,
)
from rt70.textbook.model import Model
from rt70.urdf.modal_record import parse_node_point


def link_point(model: Model, link: str, xyz) -> tuple[int, np.ndarray]:
    """Body of ``link`` and the point ``xyz`` (link frame) in that body's frame.

    Parameters
    ----------
    model : Model
        The textbook model.
    link : str
        Name of a URDF link of the scene.
    xyz : array_like, shape (3,)
        The point in the link's frame, m.

    Raises
    ------
    UnknownLinkError
        If the model has no frame for ``link``: an unknown name, or a massless link
        inside a 6-DOF pair (merged into the pair's body by the textbook model; take
        the point on the pair's end link instead).
    """
    if link not in model.link_frames:
        known = ", ".join(list(model.link_frames)[:8])
        raise UnknownLinkError(
            f"{model.name}: no link '{link}' with a frame in the textbook model (links: "
            f"{known}{', …' if len(model.link_frames) > 8 else ''}; the massless links "
            "inside a 6-DOF pair are merged into its end link)"
        )
    body, r_link, c_link = model.link_frames[link]
    return body, r_link + c_link @ check_vector(f"point of link '{link}'", xyz, 3)


def located_point(model: Model, link: str, xyz) -> tuple[int, np.ndarray, np.ndarray, slice]:
    """Body of a point and its place ``r = r0 + Φ η`` in the body's frame: ``(body, r0, Φ, η)``.

    A link's point (:func:`link_point`) has ``Φ`` of zero columns; a modal body's node
    (``"<body>/node<n>"``, :func:`rt70.urdf.modal_record.node_point`) is displaced by its
    shape ``Φ_n`` (3, k) on the body's coordinates ``η`` (a slice of q).

    Parameters
    ----------
    model : Model
        The textbook model.
    link : str
        Name of a URDF link of the scene, or a modal body's node.
    xyz : array_like, shape (3,)
        The point in the link's frame (a node's: from the node, in the body frame's
        axes), m.

    Raises
    ------
    UnknownLinkError
        If the model has no frame for ``link`` and no such node.
    """
    node = parse_node_point(link)
    flexible = {m.name: m for m in model.modal}
    if node is None or node[0] not in flexible or node[1] >= flexible[node[0]].nodes.shape[0]:
        body, r = link_point(model, link, xyz)
        return body, r, np.zeros((3, 0)), slice(0, 0)
    m = flexible[node[0]]
    r = m.nodes[node[1]] + m.c @ check_vector(f"point of node '{link}'", xyz, 3)
    return m.body, r, m.shapes[node[1]], m.coords


def point_positions(
    model: Model, data: Data, q: np.ndarray, points: Sequence[tuple[str, np.ndarray]]
) -> np.ndarray:
    """Ground-axis positions (n, 3) of the points ``(link, xyz)`` at q, in m.

    One forward pass (4.5)–(4.7) for all of them: ``p = p_body + c_0,body r``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    points : sequence of (str, array_like)
        The points: a link's name and the point in the link's frame (m).
    """
    located = [located_point(model, link, xyz) for link, xyz in points]
    q = check_vector("q", q, model.nv)
    data.q_full = model.expand(q)
    forward_kinematics(model, data, data.q_full)
    out = np.empty((len(located), 3))
    for k, where in enumerate(located):
        out[k] = located_position(data, q, where)
    return out


def located_position(
    data: Data, q: np.ndarray, located: tuple[int, np.ndarray, np.ndarray, slice]
) -> np.ndarray:
    """Ground-axis position (3,) of a located point (:func:`located_point`) from ``data``.

    Parameters
    ----------
    data : Data
        Work buffers holding the configuration's poses (:func:`forward_kinematics`).
    q : numpy.ndarray, shape (nv,)
        The configuration ``data`` holds (its modal coordinates place a node).
    located : (int, numpy.ndarray, numpy.ndarray, slice)
        ``(body, r0, Φ, η)`` of the point.
    """
    body, r0, Phi, eta = located
    return frame_pose(data, body, r0 + Phi @ q[eta], np.eye(3))[1]


def point_position(model: Model, data: Data, q: np.ndarray, link: str, xyz) -> np.ndarray:
    """Ground-axis position (3,) of the point ``xyz`` of ``link`` at q, in m.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    link : str
        Name of a URDF link of the scene, or a modal body's node (:func:`located_point`).
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    return point_positions(model, data, q, [(link, xyz)])[0]


def ground_jacobian(data: Data, body: int, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(J_v, J_ω)`` in ground axes of the point r (body frame) of ``body``, from ``data``.

    ``[v_p; ω]`` in the body's axes is the frame Jacobian ``(T(r))ᵀ (Sᵀ)_body`` (4.63);
    both rows are turned to ground axes by the body's rotation ``c_0,body``. For the
    configuration already in ``data`` (:func:`update_structure`); zero for the ground.

    Parameters
    ----------
    data : Data
        Work buffers holding the configuration's poses and S (:func:`update_structure`).
    body : int
        The body (pair index) the point is fixed to; −1 for the ground.
    r : numpy.ndarray, shape (3,)
        The point in the body's frame, m.
    """
    J = frame_jacobian(data, body, r, np.eye(3))  # [v_p; ω] in body axes (4.63)
    R, _ = frame_pose(data, body, np.zeros(3), np.eye(3))
    return R @ J[:3], R @ J[3:]


def ground_bias_acceleration(
    data: Data, body: int, r: np.ndarray, Vdot: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(a_p, ω̇)`` in ground axes of the point r of ``body`` at ``q̈ = 0``.

    With the body's twist ``[v; ω] = Sᵀ q̇`` (``data.V``, body axes) and its rate at
    q̈ = 0, ``Vdot = Ṡᵀ q̇`` (4.63), (4.81): ``a_p = c (v̇ + ω̇ × r + ω × (v + ω × r))``
    and ``ω̇ = c ω̇_body``, ``c = c_0,body``. Zero for the ground.

    Parameters
    ----------
    data : Data
        Work buffers holding the poses and the body velocities ``data.V`` of the state.
    body : int
        The body (pair index) the point is fixed to; −1 for the ground.
    r : numpy.ndarray, shape (3,)
        The point in the body's frame, m.
    Vdot : numpy.ndarray, shape (nb, 6)
        ``Ṡᵀ q̇`` of every body in its own axes, ``[v̇; ω̇]`` (m/s², rad/s²).
    """
    if body < 0:
        return np.zeros(3), np.zeros(3)
    v, w = data.V[body, :3], data.V[body, 3:]
    dv, dw = Vdot[body, :3], Vdot[body, 3:]
    R = data.R[body]
    return R @ (dv + np.cross(dw, r) + np.cross(w, v + np.cross(w, r))), R @ dw


def point_jacobian(
    model: Model, data: Data, q: np.ndarray, link: str, xyz
) -> tuple[np.ndarray, np.ndarray]:
    """``(J_v, J_ω)``, 3 × nv each, in ground axes: ``v_p = J_v q̇``, ``ω = J_ω q̇``.

    One forward pass at q, then :func:`ground_jacobian`; a modal body's node adds its
    own velocity ``c_0,body Φ_n η̇`` to ``J_v``'s columns of η.

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
    xyz : array_like, shape (3,)
        The point in the link's frame, m.
    """
    update_structure(model, data, q)
    return located_jacobian(data, q, located_point(model, link, xyz))


def located_jacobian(
    data: Data, q: np.ndarray, located: tuple[int, np.ndarray, np.ndarray, slice]
) -> tuple[np.ndarray, np.ndarray]:
    """``(J_v, J_ω)`` of a located point (:func:`located_point`) from the S in ``data``.

    Parameters
    ----------
    data : Data
        Work buffers holding the configuration's poses and S (:func:`update_structure`).
    q : numpy.ndarray, shape (nv,)
        The configuration ``data`` holds (its modal coordinates place a node).
    located : (int, numpy.ndarray, numpy.ndarray, slice)
        ``(body, r0, Φ, η)`` of the point.
    """
    body, r0, Phi, eta = located
    Jv, Jw = ground_jacobian(data, body, r0 + Phi @ q[eta])
    if Phi.shape[1]:
        c = frame_pose(data, body, np.zeros(3), np.eye(3))[0]
        Jv[:, eta] += c @ Phi
    return Jv, Jw


def generalized_force(model: Model, data: Data, q: np.ndarray, wrench: Wrench) -> np.ndarray:
    """Generalised force (nv,) of a wrench: ``Q = S U = J_vᵀ F + J_ωᵀ M`` (4.129)–(4.131).

    ``U`` is the wrench moved to the body frame; ``S U`` is the transposed point
    Jacobian times the force and the torque, both in ground axes. Its power is
    ``q̇ᵀ Q = F·v_p + M·ω``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    wrench : rt70.physics.loads.Wrench
        A force (N) at a point of a link and a torque (N·m) on it, ground axes.
    """
    Jv, Jw = point_jacobian(model, data, q, wrench.link, wrench.xyz)
    return Jv.T @ np.asarray(wrench.force) + Jw.T @ np.asarray(wrench.torque)
