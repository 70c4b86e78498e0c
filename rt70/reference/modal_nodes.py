"""The modal bodies on the reference side: their nodes as point masses in Pinocchio.

One job: an independent formulation of ``<rt70:modal_body>`` (docs/fe-models.md). Each
node with mass becomes a point mass ``m_n`` on a 3-DOF translation joint placed at
``x_n`` on the link's body frame: Pinocchio's own rigid-body algorithms then give the
nodes' inertia, velocity products and weight exactly. The nodes' displacements are tied
to the modal coordinates, ``u_n = Φ_n η`` — a constant linear map, carried by the
coordinate map (:func:`rt70.reference.coordinates.to_pinocchio`, kind ``"modal"``), so
``A = Jᵀ M_nodes J`` and so on. With lumped masses this is exactly the body the textbook
side writes from its inertia invariants (a change of variables), for any number of modes.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rt70.urdf.description import ModalBody
from rt70.urdf.modal_record import node_point

#: Pinocchio's velocity coordinates per node.
NODE_DOFS = 3


def node_count(body: ModalBody) -> int:
    """Nodes of ``body`` that carry mass (those the reference side adds)."""
    return int(np.count_nonzero(body.masses > 0.0))


def with_nodes(
    model: pin.Model, bodies: dict, modal_bodies: tuple[ModalBody, ...]
) -> tuple[pin.Model, list[list[tuple[int, np.ndarray]]]]:
    """Pinocchio's ``model`` rebuilt with every modal body's nodes with mass as joints.

    Each node is a point mass on a translation joint placed at ``x_n`` on its body's
    link, inserted right after the link's parent joint: Pinocchio's algorithms need each
    joint's subtree to be one contiguous range of velocities (CRBA fills ``M`` block by
    block over ``nvSubtree``), which appending the nodes at the end would break on a tree
    whose later branches are not below the body (the RT-70's rigel after its main mirror).
    The file's joints keep their names, placements, limits and inertias, the frames
    theirs.

    Parameters
    ----------
    model : pinocchio.Model
        Pinocchio's model of the scene, parsed from the URDF text.
    bodies : dict of str to pinocchio.Frame
        The body frame of every link.
    modal_bodies : tuple of ModalBody
        The modal bodies.

    Returns
    -------
    (pinocchio.Model, list of list of (int, numpy.ndarray))
        The new model, and per body each added node's joint index and shape ``Φ_n``.
    """
    after: dict[int, list] = {}
    for b, body in enumerate(modal_bodies):
        frame = bodies[body.link]
        for n in np.flatnonzero(body.masses > 0.0):
            after.setdefault(frame.parentJoint, []).append((b, int(n), frame.placement))
    new = pin.Model()
    new.name = model.name
    new.gravity = model.gravity
    index = {0: 0}
    added: list[list[tuple[int, np.ndarray]]] = [[] for _ in modal_bodies]

    def add_nodes_of(parent_old: int) -> None:
        for b, n, placement in after.get(parent_old, []):
            body = modal_bodies[b]
            joint = new.addJoint(
                index[parent_old],
                pin.JointModelTranslation(),
                placement * pin.SE3(np.eye(3), body.nodes[n]),
                node_point(body.name, n),
            )
            new.appendBodyToJoint(
                joint, pin.Inertia(float(body.masses[n]), np.zeros(3), np.zeros((3, 3))),
                pin.SE3.Identity(),
            )  # fmt: skip
            added[b].append((joint, body.shapes[n]))

    add_nodes_of(0)
    for i in range(1, model.njoints):
        j = model.joints[i]
        v, q = slice(j.idx_v, j.idx_v + j.nv), slice(j.idx_q, j.idx_q + j.nq)
        index[i] = new.addJoint(
            index[model.parents[i]], j, model.jointPlacements[i], model.names[i],
            model.effortLimit[v], model.velocityLimit[v],
            model.lowerPositionLimit[q], model.upperPositionLimit[q],
        )  # fmt: skip
        new.appendBodyToJoint(index[i], model.inertias[i], pin.SE3.Identity())
        add_nodes_of(i)
    for f in list(model.frames)[1:]:
        frame = pin.Frame(
            f.name, index[f.parentJoint], f.parentFrame, f.placement, f.type, f.inertia
        )
        new.addFrame(frame, False)  # the inertias are the joints' already
    return new, added


def elastic_force(model, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(−K_η η, −D_η η̇)`` of every modal body in book coordinates, each (nv,).

    Parameters
    ----------
    model : rt70.reference.ReferenceModel
        The reference model.
    q, qd : numpy.ndarray, shape (nv,)
        Book coordinates and velocities.
    """
    Qc, Qd = np.zeros(model.nv), np.zeros(model.nv)
    for body, eta in model.modal_slices:
        Qc[eta] -= body.stiffness @ q[eta]
        Qd[eta] -= body.damping @ qd[eta]
    return Qc, Qd


def elastic_potential(model, q: np.ndarray) -> float:
    """``Σ ½ ηᵀ K_η η`` of the modal bodies, J."""
    return float(sum(0.5 * q[eta] @ body.stiffness @ q[eta] for body, eta in model.modal_slices))


def modal_slices(bodies, names: list[str]) -> list[tuple[ModalBody, slice]]:
    """Each modal body and its coordinates' slice of the book coordinates ``names``."""
    out = []
    for body in bodies:
        start = names.index(body.coordinate_names[0])
        out.append((body, slice(start, start + body.modes)))
    return out
