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

#: Pinocchio's velocity coordinates per node.
NODE_DOFS = 3


def node_count(body: ModalBody) -> int:
    """Nodes of ``body`` that carry mass (those the reference side adds)."""
    return int(np.count_nonzero(body.masses > 0.0))


def add_nodes(model: pin.Model, bodies: dict, body: ModalBody) -> list[tuple[int, np.ndarray]]:
    """Add ``body``'s nodes with mass to ``model``; their joints and shapes ``Φ_n``.

    Parameters
    ----------
    model : pinocchio.Model
        Pinocchio's model of the scene, changed in place.
    bodies : dict of str to pinocchio.Frame
        The body frame of every link.
    body : ModalBody
        The modal body.

    Returns
    -------
    list of (int, numpy.ndarray)
        Each added node's joint index and its shape ``Φ_n`` (3, k).
    """
    frame = bodies[body.link]
    added = []
    for n in np.flatnonzero(body.masses > 0.0):
        placement = frame.placement * pin.SE3(np.eye(3), body.nodes[n])
        joint = model.addJoint(
            frame.parentJoint, pin.JointModelTranslation(), placement, f"{body.name}/node{n}"
        )
        model.appendBodyToJoint(
            joint,
            pin.Inertia(float(body.masses[n]), np.zeros(3), np.zeros((3, 3))),
            pin.SE3.Identity(),
        )
        added.append((joint, body.shapes[n]))
    return added


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
