"""The textbook model's record of a modal flexible body: placed on its pair, once.

One job: turn a ``<rt70:modal_body>`` (:class:`rt70.urdf.ModalBody`) into the constant
data the algorithms read (:mod:`rt70.textbook.modal_bodies`) — its pair, its nodes and
modes in the pair's body frame, their inertia invariants, its stiffness and damping and
where its coordinates sit in q.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.textbook.flexible import Invariants, inertia_invariants
from rt70.urdf.description import ModalBody
from rt70.urdf.modal_record import Surface


@dataclass(frozen=True)
class ModalModel:
    """A modal flexible body on ``body``: its invariants, stiffness and coordinates.

    The nodes and shapes of the file are placed in the body's frame (the link may be
    welded to it at ``(r, c)``: ``x ↦ r + c x``, ``Φ ↦ c Φ``), so the body's frame
    velocity is the pair's ``V = Sᵀ q̇`` (:mod:`rt70.textbook.modal_bodies`).

    Attributes
    ----------
    name : str
        The ``<rt70:modal_body>``'s name.
    body : int
        The pair it rides on (−1: the ground).
    r, c : numpy.ndarray
        The link's frame in the body's frame (the ground's for ``body = −1``).
    invariants : rt70.textbook.flexible.Invariants
        Its inertia invariants in the body's frame.
    stiffness, damping : numpy.ndarray, shape (k, k)
        ``K_η``, ``D_η``.
    start : int
        Index of its first modal coordinate in q.
    nodes : numpy.ndarray, shape (N, 3)
        The nodes ``x_n`` in the body's frame, m.
    shapes : numpy.ndarray, shape (N, 3, k)
        ``Φ_n`` in the body's axes.
    surface : rt70.urdf.modal_record.Surface or None
        Its reflecting surface (nodes, weights, F), as the file gives it.
    """

    name: str
    body: int
    r: np.ndarray
    c: np.ndarray
    invariants: Invariants
    stiffness: np.ndarray
    damping: np.ndarray
    start: int
    nodes: np.ndarray
    shapes: np.ndarray
    surface: Surface | None = None

    @property
    def modes(self) -> int:
        """k, the number of modal coordinates."""
        return self.invariants.modes

    @property
    def coords(self) -> slice:
        """Its modal coordinates' slice of q."""
        return slice(self.start, self.start + self.modes)


def place_modal_bodies(bodies: tuple[ModalBody, ...], link_frames: dict, start: int) -> tuple:
    """The modal bodies placed on their pairs, their coordinates numbered from ``start``.

    Parameters
    ----------
    bodies : tuple of rt70.urdf.ModalBody
        The description's modal bodies.
    link_frames : dict
        Each link's ``(body, r, c)``: its pair and its frame in the pair's body frame.
    start : int
        Index in q of the first modal coordinate (the pairs' independent ones come first).
    """
    out = []
    for b in bodies:
        body, r, c = link_frames[b.link]
        nodes = r + b.nodes @ c.T
        shapes = np.einsum("ab,nbj->naj", c, b.shapes)
        invariants = inertia_invariants(nodes, b.masses, shapes)
        out.append(
            ModalModel(
                b.name,
                body,
                r,
                c,
                invariants,
                b.stiffness,
                b.damping,
                start,
                nodes,
                shapes,
                b.surface,
            )  # fmt: skip
        )
        start += b.modes
    return tuple(out)
