"""The record of a ``<rt70:modal_body>``: a flexible body on a link, as plain data.

Read by :mod:`rt70.urdf.modal_body` (the element and its file,
:mod:`rt70.urdf.modal_file`); both sides build their own body from it
(:mod:`rt70.textbook.modal_model`, :mod:`rt70.reference.modal_nodes`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

#: A node of a modal body as a point carrier: ``"<body>/node<n>"`` (n from 0), the name
#: Pinocchio's joint of the node has on the reference side.
NODE_POINT = re.compile(r"(?P<body>.+)/node(?P<node>[0-9]+)")


def node_point(body: str, node: int) -> str:
    """The name of node ``node`` of the modal body ``body`` as a point carrier.

    A point ``(node_point(body, n), xyz)`` sits at ``xyz`` (the body frame's axes) from
    the node's displaced position ``x_n + Φ_n η``; both sides place it with their own
    kinematics (:mod:`rt70.textbook.points`, :mod:`rt70.reference.points`).

    Parameters
    ----------
    body : str
        The ``<rt70:modal_body>``'s name.
    node : int
        The node's index in the modal body file, from 0.
    """
    return f"{body}/node{int(node)}"


def parse_node_point(name: str) -> tuple[str, int] | None:
    """``(body, node)`` of a name made by :func:`node_point`; None for any other name.

    Parameters
    ----------
    name : str
        A point carrier's name (a link's or a node's).
    """
    match = NODE_POINT.fullmatch(name)
    return (match["body"], int(match["node"])) if match else None


@dataclass(frozen=True)
class Surface:
    """The reflecting surface of a modal body: some of its nodes on a paraboloid.

    The paraboloid is ``z = (x² + y²)/(4F)`` in the body frame: vertex at its origin,
    axis along its +z (docs/surface.md).

    Attributes
    ----------
    nodes : numpy.ndarray of int, shape (S,)
        The surface nodes' indices in the modal body file.
    weights : numpy.ndarray, shape (S,)
        Each node's share of the aperture (projected area, m², times an optional
        illumination taper); the best fit's weights.
    focal_length : float
        F, m.
    """

    nodes: np.ndarray
    weights: np.ndarray
    focal_length: float


@dataclass(frozen=True)
class Interface:
    """A link attached to a node of a modal body (``<rt70:interface>``).

    The link sits at the node, its axes the body frame's, and moves with the node:
    translated by ``u = Φ_n η`` and, when the file gives the node's rotations, turned by
    ``Rx(θ_x) Ry(θ_y) Rz(θ_z)`` with ``θ = Ψ_n η``. Both sides see it as a chain of
    one-coordinate joints from the body's link — prismatic x, y, z, then revolute x, y, z —
    whose coordinates are not free: joint i's is ``rows[i] · η``.

    Attributes
    ----------
    link : str
        The attached link (generated: the file's joints use it as a parent).
    node : int
        The node's index in the modal body file (from 0).
    joints : tuple of str
        The chain's joints, from the body's link to ``link``.
    rows : numpy.ndarray, shape (len(joints), k)
        Each chain joint's coordinate per unit modal coordinate.
    """

    link: str
    node: int
    joints: tuple[str, ...]
    rows: np.ndarray


@dataclass(frozen=True)
class ModalBody:
    """A modal flexible body on a link (``<rt70:modal_body>``), its arrays checked.

    Attributes
    ----------
    name : str
        The element's name; the body's modal coordinates are ``name:eta1`` … ``name:etak``.
    link : str
        The link whose frame is the body frame (the body moves rigidly with it and deforms
        by its modes).
    file : str
        The modal body file as resolved.
    nodes, masses, shapes : numpy.ndarray
        ``x_n`` (N, 3) in the link's frame, m; ``m_n`` (N,), kg; ``Φ_n`` (N, 3, k).
    stiffness, damping : numpy.ndarray
        ``K_η`` and ``D_η``, (k, k).
    edges : numpy.ndarray of int, shape (E, 2)
        Node index pairs drawn as lines (the mesh's edges; may be empty).
    interfaces : tuple of Interface
        The links attached to its nodes.
    surface : Surface or None
        Its reflecting surface, when the file declares one.
    """

    name: str
    link: str
    file: str
    nodes: np.ndarray
    masses: np.ndarray
    shapes: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    edges: np.ndarray
    interfaces: tuple[Interface, ...] = ()
    surface: Surface | None = None

    @property
    def modes(self) -> int:
        """k, the number of modal coordinates."""
        return self.shapes.shape[2]

    @property
    def coordinate_names(self) -> list[str]:
        """``name:eta1`` … ``name:etak``."""
        return [f"{self.name}:eta{i + 1}" for i in range(self.modes)]

    @property
    def node_joints(self) -> dict[str, np.ndarray]:
        """Every interface chain joint and its row: its coordinate is ``row · η``."""
        return {j: row for i in self.interfaces for j, row in zip(i.joints, i.rows, strict=True)}
