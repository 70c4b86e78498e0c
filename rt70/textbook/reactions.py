"""Joint reaction wrenches by the book's matrices: kinetostatics of source 004 (9)–(13), (16).

Cut the tree across pair k and write d'Alembert's equilibrium of the part cut off (the
subtree of k, (9)–(10)): the wrench the parent exerts on it across the pair is the sum
over the subtree of every body's inertial wrench less its gravity and external loads,
each moved to pair k's frame. In the book's notation (formalism §4.2–§4.4) the body
wrench of body j, in its own frame about its origin, is

    W_j = Θ_j V̇_j + Φ(V_j) Θ_j V_j − G_j − U_j,        (4.77)–(4.82), (4.113), (4.131)

with ``V = Sᵀ q̇`` (4.63), ``V̇ = Sᵀ q̈ + Ṡᵀ q̇`` (4.81), ``G_j = Θ_j [g_j; 0]`` and
``U_j`` the given loads moved to the body; and the reactions of all pairs are the
configuration matrix (4.64) applied to the stacked wrenches,

    R = L W,    R_k = Σ_{j in subtree(k)} L_k^j W_j,

summed here once from the leaves to the root in reverse topological order
(``R_k = W_k + Σ_children L_k^c R_c``: 004 (12)–(13) as corrected by errata X.3.12 — the
literal leaf-to-root walks of (13) double count on a branched tree). Projected on the
pair's mobility, ``(M_k f_k)ᵀ R_k``, it is the generalised force of the pair, and
``S W = [f]ᵀ Mᵀ L W`` is the (11) projection: ``Q = A q̈ + B q̇ − S G − S U`` of the
equations of motion.

Convention (the reference side, :mod:`rt70.reference.reactions`, returns the same): for
every URDF joint of the scene (``fixed`` joints excepted: the textbook merges their
links), the wrench ``[F; M]`` the parent side exerts on the child side across that
joint, the force F and the moment M about the joint's origin, both in the joint's
(child link's) axes — Pinocchio's ``data.f``. A pair of the book that is a chain of six
URDF joints (an euler6 pair, :mod:`rt70.textbook.model`) transmits one wrench through
its massless intermediate links; it is reported in each of the six joint frames. What
the joint "transmits" is everything between the parent and the child that is not a
given load: the bearing, a joint spring or drive torque (the axis component), and the
bushings and strut packages of the scene (which act between bodies, so they are part of
the reaction of every pair they bridge). Pass a load as ``wrenches`` to take it out.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from rt70.guards.arrays import check_vector
from rt70.physics.loads import Wrench
from rt70.textbook import modal_bodies
from rt70.textbook.data import Data
from rt70.textbook.dynamics import body_velocities, structure_matrix_rate
from rt70.textbook.kinematics import forward_kinematics, update_structure
from rt70.textbook.model import Model
from rt70.textbook.points import link_point
from rt70.textbook.spatial import c1, c2, c3, crf, placement


def joint_reactions(
    model: Model,
    data: Data,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    wrenches: Iterable[Wrench] = (),
    gravity: bool = True,
) -> dict[str, np.ndarray]:
    """Wrench across every URDF joint, ``[F; M]`` in the joint's axes about its origin.

    Forward pass: the poses, L and S (4.5)–(4.7), (4.64), (4.66), the body velocities
    ``V = Sᵀ q̇`` and accelerations ``V̇ = Sᵀ q̈ + Ṡᵀ q̇`` (4.63), (4.81). Backward pass:
    the pair reactions ``R = L W`` of the body wrenches (source 004 (9)–(13),
    :func:`pair_reactions`), each moved to the frames of the pair's URDF joints
    (:func:`joint_wrenches`).

    Parameters
    ----------
    model, data : Model, Data
        The textbook model and its work buffers.
    q, qd, qdd : numpy.ndarray
        State and accelerations in the model's coordinates (nv,).
    wrenches : iterable of rt70.physics.loads.Wrench
        Loads on links (ground axes, at a point of the link); a load on the ground
        link acts on no pair and is ignored.
    gravity : bool
        Include the weights ``G_j = Θ_j [g_j; 0]`` (4.113).

    Returns
    -------
    dict of str to numpy.ndarray
        Per URDF joint name, in pair order, the wrench (6,) ``[F; M]`` (N, N·m) the
        parent exerts on the child across the joint.
    """
    R = pair_reactions(model, data, q, qd, qdd, wrenches, gravity)
    return joint_wrenches(model, data, R)


def reaction_impulses(
    model: Model, data: Data, q: np.ndarray, dqd: np.ndarray, impulses: Iterable[Wrench] = ()
) -> dict[str, np.ndarray]:
    """Reaction impulses across every URDF joint for a velocity jump Δq̇ (source 004 (16)).

    The impact form of :func:`joint_reactions`: positions unchanged, no velocity
    products, the impulses of finite forces (gravity) neglected, ``q̈ → Δq̇`` and the
    loads → their impulses ``impulses`` (N·s, N·m·s; e.g. the impact multipliers Λ as
    equal and opposite wrenches). Per URDF joint ``[F; M]`` impulse in the joint's axes.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    dqd : numpy.ndarray, shape (nv,)
        The velocity jump Δq̇, rad/s or m/s.
    impulses : iterable of rt70.physics.loads.Wrench
        Impulses on links (ground axes; N·s and N·m·s in the force and torque fields).
    """
    zero = np.zeros(model.nv)
    return joint_reactions(model, data, q, zero, dqd, impulses, gravity=False)


def gravity_wrenches(model: Model, data: Data) -> np.ndarray:
    """``G_j = Θ_j [c_{0j}ᵀ g₀; 0]`` of every body (4.113), shape (nb, 6); poses in ``data``."""
    accel = np.zeros((model.nb, 6))
    accel[:, :3] = np.einsum("kji,j->ki", data.R, model.gravity)
    return np.einsum("kij,kj->ki", model.Theta, accel)


def load_wrenches(model: Model, data: Data, wrenches: Iterable[Wrench]) -> np.ndarray:
    """``U_j``: the loads moved to their bodies, ``[c_{0j}ᵀ F; r × c_{0j}ᵀ F + c_{0j}ᵀ M]``.

    Shape (nb, 6), each in its body's frame about its origin (4.129)–(4.131); ``r`` is
    the point in the body frame (:func:`rt70.textbook.points.link_point`). Poses in
    ``data``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Work buffers holding the configuration's poses.
    wrenches : iterable of rt70.physics.loads.Wrench
        Loads on links, ground axes; those on the ground link are ignored.
    """
    U = np.zeros((model.nb, 6))
    for w in wrenches:
        body, r = link_point(model, w.link, w.xyz)
        if body < 0:
            continue
        F = data.R[body].T @ np.asarray(w.force, dtype=float)
        M = data.R[body].T @ np.asarray(w.torque, dtype=float)
        U[body, :3] += F
        U[body, 3:] += np.cross(r, F) + M
    return U


def subtree_sums(model: Model, data: Data, W: np.ndarray) -> np.ndarray:
    """Pair reactions ``R = L W`` (4.64) by one backward pass, shape (nb, 6).

    ``R_k = W_k + Σ_{c child of k} L_pair[c] R_c``, the pairs visited once from the last
    to the first (parents precede children): source 004 (12)–(13) in reverse
    topological order, which adds each subtree's total to its parent once (errata
    X.3.12). ``L_pair[c] = T(r) [c]`` moves a wrench from the child's frame to the
    parent's (the transpose of the velocity map (4.5)–(4.7)).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Work buffers holding the configuration's pair transforms ``L_pair``.
    W : numpy.ndarray, shape (nb, 6)
        Each body's wrench ``[F; M]`` (N, N·m) in its own frame about its origin.
    """
    R = np.array(W, dtype=float, copy=True)
    for c in range(model.nb - 1, -1, -1):
        k = int(model.parent[c])
        if k >= 0:
            R[k] += data.L_pair[c] @ R[c]
    return R


def pair_reactions(
    model: Model,
    data: Data,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    wrenches: Iterable[Wrench] = (),
    gravity: bool = True,
) -> np.ndarray:
    """Reaction ``R_k`` of every pair in its body frame about its origin, shape (nb, 6).

    Source 004 (9)–(10) with the book's matrices: the body wrenches
    ``W = Θ V̇ + Φ(V) Θ V − G − U`` (forward pass) summed over the subtrees,
    ``R = L W`` (:func:`subtree_sums`); :func:`projection` of R is the generalised force
    ``S W`` (004 (11)). A modal body adds to its pair's W what its frame exerts on it
    (:func:`rt70.textbook.modal_bodies.frame_wrenches`).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd, qdd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m), velocities (rad/s or m/s) and accelerations
        (rad/s² or m/s²) in the model's order (``Model.coordinate_names``).
    wrenches : iterable of rt70.physics.loads.Wrench
        Loads on links (ground axes, at a point of the link); a load on the ground link
        acts on no pair and is ignored.
    gravity : bool
        Include the weights ``G_j = Θ_j [g_j; 0]`` (4.113).
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    qdd = check_vector("qdd", qdd, model.nv)
    S = update_structure(model, data, q)  # forward pass: poses, L, S
    V = body_velocities(model, data, qd)
    moving = bool(qd.any())  # at rest (statics, impulses) Ṡᵀ q̇ and Φ(V) Θ V vanish
    Vdot = S.T @ qdd
    if moving:
        data.S_dot = structure_matrix_rate(model, data, q, qd)
        Vdot += data.S_dot.T @ qd
    W = np.einsum("kij,kj->ki", model.Theta, Vdot.reshape(model.nb, 6))
    if model.modal:  # each modal body's wrench on its pair (its frame rows)
        frames = modal_bodies.dense_frames(model, data, qd if moving else None)
        for body, wrench in modal_bodies.frame_wrenches(model, frames, q, qd, qdd, gravity):
            if body >= 0:
                W[body] += wrench
    if moving:
        momentum = np.einsum("kij,kj->ki", model.Theta, V)
        W += np.array([crf(v) @ h for v, h in zip(V, momentum, strict=True)])
    if gravity:
        W -= gravity_wrenches(model, data)
    W -= load_wrenches(model, data, wrenches)
    return subtree_sums(model, data, W)


def projection(model: Model, data: Data, R: np.ndarray) -> np.ndarray:
    """``Q = Gᵀ [(M_k f_k)ᵀ R_k]``: the generalised force of the pair reactions (004 (11)).

    Equals ``S W`` (4.66), the right-hand side the reactions balance:
    ``A q̈ + B q̇ − S G − S U``. ``M_k f_k`` from the last forward pass in ``data``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Work buffers holding the configuration's ``M_k f_k`` (the last forward pass).
    R : numpy.ndarray, shape (nb, 6)
        The pair reactions ``[F; M]`` (N, N·m), each in its body's frame about its origin
        (:func:`pair_reactions`).
    """
    Q_full = np.concatenate([data.Mf[k].T @ R[k] for k in range(model.nb)])
    return model.reduce(Q_full)


def joint_wrenches(model: Model, data: Data, R: np.ndarray) -> dict[str, np.ndarray]:
    """The pair reactions ``R`` (body frames) per URDF joint, in each joint's frame.

    A pair of one URDF joint: its body frame is the joint's. An euler6 chain of six
    joints: the same wrench moved to each joint's child frame in the construction
    frame, ``T(r)[c]`` of the body frame seen from it (:func:`chain_frames`).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Work buffers holding the configuration's pair coordinates ``q_full``.
    R : numpy.ndarray, shape (nb, 6)
        The pair reactions ``[F; M]`` (N, N·m), each in its body's frame about its origin
        (:func:`pair_reactions`).
    """
    out: dict[str, np.ndarray] = {}
    for k, names in enumerate(model.pair_joints):
        if len(names) == 1:
            out[names[0]] = R[k].copy()
            continue
        frames = chain_frames(data.q_full[model.coords(k)])
        r_b, c_b = frames[-1]
        for name, (r, c) in zip(names, frames, strict=True):
            out[name] = placement(c.T @ (r_b - r), c.T @ c_b) @ R[k]
    return out


def chain_frames(qk: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Child frames ``(r, c)`` of the six joints of an euler6 pair in its construction frame.

    ``q_k = [x, y, z, β, θ, α]`` (4.8): translations along x, y, z, then rotations
    ``c1(β)``, ``c1 c2(θ)``, ``c1 c2 c3(α)`` — the last is the body frame of
    :func:`rt70.textbook.kinematics.pair_motion`.
    """
    x, y, z, beta, theta, alpha = qk
    r = np.array([x, y, z])
    eye = np.eye(3)
    c_beta = c1(beta)
    c_theta = c_beta @ c2(theta)
    return [
        (np.array([x, 0.0, 0.0]), eye),
        (np.array([x, y, 0.0]), eye),
        (r, eye),
        (r, c_beta),
        (r, c_theta),
        (r, c_theta @ c3(alpha)),
    ]


def joint_frames(
    model: Model, data: Data, q: np.ndarray
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Ground rotation and origin of every URDF joint's frame at q, for ground-axis reports.

    ``F₀ = c F``, ``M₀ = c M`` (about the same origin).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    data.q_full = model.expand(q)
    forward_kinematics(model, data, data.q_full)
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for k, names in enumerate(model.pair_joints):
        if len(names) == 1:
            out[names[0]] = (data.R[k].copy(), data.p[k].copy())
            continue
        i = int(model.parent[k])
        R_i, p_i = (np.eye(3), np.zeros(3)) if i < 0 else (data.R[i], data.p[i])
        R_c, p_c = R_i @ model.c_c[k], p_i + R_i @ model.r_c[k]
        frames = chain_frames(data.q_full[model.coords(k)])
        for name, (r, c) in zip(names, frames, strict=True):
            out[name] = (R_c @ c, p_c + R_c @ r)
    return out
