"""A finite-element model as a modal body clamped to its frame: nodes, masses, modes.

One job: the arrays of the modal body file (docs/fe-models.md, ``rt70-modal/1``) from a
lumped-mass FE model of translational DOFs. The body's frame holds the ``clamped`` nodes
(where it is attached: they move with the frame), so its modes are the fixed-interface
modes of the Craig–Bampton reduction on those nodes (:func:`rt70.fe.craig_bampton`):
``u_i = Φ η`` on the interior, zero on the clamped nodes; mass-normalised, so the modal
mass is 1 and the modal stiffness ``diag(ω²)``.

Nodes where the body carries something (``interface``: a link hangs there,
``<rt70:interface>``) are best made boundary nodes too: their three constraint modes —
the body's static shape for a unit displacement of the node, the clamp held — come first
among the coordinates (the coordinate is the node's displacement itself), then the
fixed-interface modes with the clamp and those nodes held. This is the Craig–Bampton
basis on the clamp and the interface nodes with the clamp's own motion the frame's; it
holds the static stiffness at the node exactly, which modes of the bare structure do not
when a heavy body sits on a free node (docs/fe-models.md, "Links on the nodes").

Loads the body will carry (its weight, a wind pressure) are best in the basis too:
``loads`` are nodal force patterns whose static shapes ``K_ii⁻¹ f`` (the clamp and the
interface held) join the fixed-interface modes, and the basis is re-solved as a Ritz
basis (``Bᵀ K B``, ``Bᵀ M B``) so that the modal stiffness stays diagonal. The static
response to any combination of those patterns is then exact for any number of modes —
modal truncation augmentation (Dickens, Nakagawa & Wittbrodt, Comput. Struct. 62(6),
1997) — which modes alone reach only slowly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rt70.errors import Rt70Error
from rt70.fe.craig_bampton import craig_bampton
from rt70.fe.neutral import FEModel


@dataclass(frozen=True)
class ClampedModes:
    """A clamped modal body's arrays (the modal body file's, module docstring).

    Attributes
    ----------
    nodes : numpy.ndarray, shape (N, 3)
        Node positions in the model's frame, m.
    masses : numpy.ndarray, shape (N,)
        Lumped masses, kg.
    shapes : numpy.ndarray, shape (N, 3, k)
        Mode shapes, zero on the clamped nodes.
    stiffness : numpy.ndarray, shape (k, k)
        The modal stiffness: the interface nodes' condensed stiffness (N/m) in the first
        ``n_interface`` rows and columns, then ``diag(ω²)``, (rad/s)² per unit modal mass.
    edges : numpy.ndarray of int, shape (E, 2)
        The pairs of nodes K couples (a truss's bars, a mesh's element edges), for drawing.
    n_interface : int
        The constraint modes first among the coordinates (three per interface node).
    """

    nodes: np.ndarray
    masses: np.ndarray
    shapes: np.ndarray
    stiffness: np.ndarray
    edges: np.ndarray
    n_interface: int = 0

    @property
    def freq_hz(self) -> np.ndarray:
        """The fixed-interface modes' frequencies, Hz."""
        omega2 = np.diag(self.stiffness)[self.n_interface :]
        return np.sqrt(omega2) / (2.0 * np.pi)


def clamped_modes(
    model: FEModel,
    clamped: list[int],
    n_modes: int,
    interface: list[int] | tuple = (),
    loads: np.ndarray | None = None,
) -> ClampedModes:
    """The ``n_modes`` lowest modes of ``model`` with the ``clamped`` nodes held.

    Parameters
    ----------
    model : FEModel
        Three translations per node (components 1–3), a diagonal (lumped) mass matrix.
    clamped : list of int
        Node numbers of the nodes held by the body frame.
    n_modes : int
        Fixed-interface modes kept (the lowest).
    interface : sequence of int
        Node numbers of free nodes kept as boundary nodes: their constraint modes come
        first (module docstring); empty: none.
    loads : numpy.ndarray, shape (L, N, 3), optional
        Nodal force patterns (N, any scale) whose static shapes join the basis (module
        docstring): the coordinates are then ``n_modes + L`` Ritz vectors after the
        constraint modes.

    Raises
    ------
    Rt70Error
        A node without exactly its three translations, a mass matrix that is not
        diagonal or not equal on a node's three rows, an unknown clamped or interface
        node, an interface node that is clamped, or the reduction's own errors (a
        boundary that does not hold the structure).
    """
    ids = np.asarray(model.node_ids)
    node_rows = [model.dofs_of(int(n)) for n in ids.tolist()]
    if any(len(r) != 3 or list(model.dof_comp[r]) != [1, 2, 3] for r in node_rows):
        raise Rt70Error(f"{model.name}: a modal body needs three translations on every node")
    rows = np.array(node_rows, dtype=np.int64)  # (N, 3)
    M = sp.csr_array(model.M)
    diagonal = M.diagonal()
    if sp.csr_array(M - sp.diags_array(diagonal)).count_nonzero():
        raise Rt70Error(f"{model.name}: a modal body needs a lumped (diagonal) mass matrix")
    masses = diagonal[rows]
    if np.any(masses != masses[:, :1]):
        raise Rt70Error(f"{model.name}: a node's three translations have different masses")
    for kind, nodes in (("clamped", clamped), ("interface", interface)):
        unknown = sorted(set(nodes) - set(ids.tolist()))
        if unknown:
            raise Rt70Error(f"{model.name}: {kind} node {unknown[0]} is not in the node table")
    both = sorted(set(clamped) & set(interface))
    if both:
        raise Rt70Error(f"{model.name}: node {both[0]} is both clamped and an interface node")
    held = np.concatenate([model.dofs_of(int(n)) for n in clamped])
    free = [model.dofs_of(int(n)) for n in interface]
    cb = craig_bampton(model.M, model.K, np.concatenate([held, *free]), n_modes)
    keep = np.arange(held.size, cb.T.shape[1])  # the clamp's columns: the frame's motion
    shapes = cb.T[:, keep][rows]  # (N, 3, 3 n_s + k): zero on the clamped rows
    n_s = keep.size - cb.omega2.size
    flat = shapes[:, :, n_s:].reshape(-1, cb.omega2.size)
    sign = np.sign(flat[np.argmax(np.abs(flat), axis=0), np.arange(flat.shape[1])])
    shapes[:, :, n_s:] *= sign  # each mode's largest entry positive: one sign everywhere
    stiffness = cb.K[np.ix_(keep, keep)]
    if loads is not None:
        boundary = np.concatenate([held, *free])
        ritz, omega2 = _augmented(model, rows, boundary, shapes[:, :, n_s:], loads)
        shapes = np.concatenate([shapes[:, :, :n_s], ritz], axis=2)
        stiffness = scipy.linalg.block_diag(stiffness[:n_s, :n_s], np.diag(omega2))
    return ClampedModes(
        np.asarray(model.node_xyz, dtype=float),
        masses[:, 0].copy(),
        shapes,
        stiffness,
        coupled_nodes(model, rows),
        n_s,
    )


def _augmented(
    model: FEModel, rows: np.ndarray, boundary: np.ndarray, modes: np.ndarray, loads
) -> tuple[np.ndarray, np.ndarray]:
    """Ritz vectors (N, 3, k + L) and their ω² of the modes and the loads' static shapes."""
    f = np.asarray(loads, dtype=float)
    if f.ndim != 3 or f.shape[1:] != rows.shape or not np.all(np.isfinite(f)):
        raise Rt70Error(
            f"{model.name}: loads must be finite (L, {rows.shape[0]}, 3) patterns, got {f.shape}"
        )
    n = model.M.shape[0]
    interior = np.setdiff1d(np.arange(n), boundary)
    K = sp.csc_array(model.K)
    M = sp.csr_array(model.M)
    forces = np.zeros((n, f.shape[0]))
    forces[rows.ravel()] = f.reshape(f.shape[0], -1).T
    static = np.zeros((n, f.shape[0]))
    static[interior] = spla.splu(K[interior][:, interior]).solve(forces[interior])
    basis = np.zeros((n, modes.shape[2] + f.shape[0]))
    basis[rows.ravel(), : modes.shape[2]] = modes.reshape(-1, modes.shape[2])
    basis[:, modes.shape[2] :] = static
    q, _ = np.linalg.qr(basis)
    Kr, Mr = q.T @ (K @ q), q.T @ (M @ q)
    omega2, vectors = scipy.linalg.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
    ritz = q @ vectors  # mass-normalised: ritzᵀ M ritz = 1, ritzᵀ K ritz = diag(ω²)
    big = np.argmax(np.abs(ritz), axis=0)
    ritz *= np.sign(ritz[big, np.arange(ritz.shape[1])])
    return ritz[rows.ravel()].reshape(rows.shape[0], 3, -1), omega2


def coupled_nodes(model: FEModel, rows: np.ndarray) -> np.ndarray:
    """The node pairs (i < j, indices into the node table) that K couples, (E, 2).

    Parameters
    ----------
    model : FEModel
        The FE model.
    rows : numpy.ndarray of int, shape (N, 3)
        Each node's three rows.
    """
    node_of = np.empty(model.n_dofs, dtype=np.int64)
    node_of[rows.ravel()] = np.repeat(np.arange(rows.shape[0]), 3)
    K = sp.coo_array(model.K)
    a, b = node_of[K.row], node_of[K.col]
    keep = (a < b) & (K.data != 0.0)
    return np.unique(np.column_stack([a[keep], b[keep]]), axis=0).reshape(-1, 2)
