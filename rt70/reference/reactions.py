"""Joint reaction wrenches from Pinocchio: ``pin.rnea`` and its transmitted forces ``data.f``.

Pinocchio's RNEA backward pass is source 004's kinetostatics (9)–(13) (the spec's
verification, 004.1): after ``rnea(q, v, a, fext)`` ``data.f[i]`` is the wrench joint i's
parent exerts on its subtree, ``[F; M]`` about the joint origin in the joint's frame —
the convention of :mod:`rt70.textbook.reactions`. Gravity enters as the base
acceleration ``−g`` (the model without gravity when it is off); loads enter as
``fext``, each moved into its link's parent joint frame; the book's ``(q, q̇, q̈)`` are
mapped to Pinocchio's ``(q, v, a = J q̈ + J̇ q̇)`` by
:func:`rt70.reference.coordinates.to_pinocchio` (mimic joints included). Independent of
the textbook side.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pinocchio as pin

from rt70.guards.arrays import check_vector
from rt70.physics.loads import Wrench
from rt70.reference.coordinates import to_pinocchio
from rt70.reference.model import ReferenceData, ReferenceModel
from rt70.reference.points import link_point


def joint_reactions(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    wrenches: Iterable[Wrench] = (),
    gravity: bool = True,
) -> dict[str, np.ndarray]:
    """Wrench across every joint, ``[F; M]`` in the joint's axes about its origin.

    ``pin.rnea(q, v, a, fext)`` and ``data.f[i]`` per Pinocchio joint (in Pinocchio's
    joint order; URDF ``fixed`` joints are frames, not joints). Arguments as
    :func:`rt70.textbook.reactions.joint_reactions`.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q, qd, qdd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m), velocities (rad/s or m/s) and accelerations
        (rad/s² or m/s²) in the book's order (:func:`rt70.urdf.coordinate_names`).
    wrenches : iterable of rt70.physics.loads.Wrench
        Loads on links (ground axes, at a point of the link); a load on the ground link
        is carried by no joint and ignored.
    gravity : bool
        Include gravity (the base accelerates by −g).
    """
    qdd = check_vector("qdd", qdd, model.nv)
    qp, vp, J, Jdqd = to_pinocchio(model, q, qd)
    ap = qdd if J is None else J @ qdd + Jdqd
    pm = model.pin_model if gravity else model.pin_model_no_gravity
    pd = data.pin_data if gravity else data.pin_data_no_gravity
    pin.forwardKinematics(pm, pd, qp)
    fext = external_forces(model, pd, wrenches)
    pin.rnea(pm, pd, qp, vp, ap, fext)
    return {pm.names[i]: pd.f[i].vector.copy() for i in model.urdf_joints}


def reaction_impulses(
    model: ReferenceModel,
    data: ReferenceData,
    q: np.ndarray,
    dqd: np.ndarray,
    impulses: Iterable[Wrench] = (),
) -> dict[str, np.ndarray]:
    """Reaction impulses for a velocity jump Δq̇: ``rnea(q, 0, J Δq̇, fext = impulses)``.

    Gravity off (source 004 (16), Algorithm 004-D's Pinocchio equivalent).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    dqd : numpy.ndarray, shape (nv,)
        The velocity jump Δq̇, rad/s or m/s.
    impulses : iterable of rt70.physics.loads.Wrench
        Impulses on links (ground axes; N·s and N·m·s in the force and torque fields).
    """
    zero = np.zeros(model.nv)
    return joint_reactions(model, data, q, zero, dqd, impulses, gravity=False)


def external_forces(
    model: ReferenceModel, pin_data: pin.Data, wrenches: Iterable[Wrench]
) -> list[pin.Force]:
    """Pinocchio's ``fext``: each load as a force in its link's parent joint frame.

    The force and torque (ground axes) are turned to the point frame's axes by its
    rotation ``(oMi · placement).rotation`` and moved to the joint by the placement's
    action — never through the ground origin. Needs ``oMi`` (a forward pass).

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    pin_data : pinocchio.Data
        Pinocchio's data after a forward pass (its ``oMi``).
    wrenches : iterable of rt70.physics.loads.Wrench
        Loads on links, ground axes; those on the ground link are left out.
    """
    fext = [pin.Force.Zero() for _ in range(model.pin_model.njoints)]
    for w in wrenches:
        joint, placement = link_point(model, w.link, w.xyz)
        if joint == 0:  # on the ground: no joint carries it
            continue
        R = (pin_data.oMi[joint] * placement).rotation
        local = pin.Force(R.T @ np.asarray(w.force, float), R.T @ np.asarray(w.torque, float))
        fext[joint] += placement.act(local)
    return fext


def joint_frames(
    model: ReferenceModel, data: ReferenceData, q: np.ndarray
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Ground rotation and origin of every joint frame at q (``oMi``), for ground-axis reports.

    Parameters
    ----------
    model : ReferenceModel
        The reference model (Pinocchio's, mapped to the book's coordinates).
    data : ReferenceData
        Its work buffers (Pinocchio's ``Data``).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the book's order
        (:func:`rt70.urdf.coordinate_names`).
    """
    qp, _, _, _ = to_pinocchio(model, q)
    pm, pd = model.pin_model, data.pin_data
    pin.forwardKinematics(pm, pd, qp)
    return {
        pm.names[i]: (pd.oMi[i].rotation.copy(), pd.oMi[i].translation.copy())
        for i in model.urdf_joints
    }
