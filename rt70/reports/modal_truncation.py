"""A modal body's truncation error against its nodal model, as the number of modes grows.

One job: the free–free frequencies of an FE component written as a floating-frame modal
body (:mod:`rt70.textbook.flexible`) with k modes, against the same FE model's own
(validation/modal_truncation.py; docs/fe-models.md). The body's frame is held to the
component by a statically determinate 3-2-1 support (one node fixed in x, y, z, a second
in the two directions across the line between them, a third in the one direction off
their plane), so the modes Φ are the component's modes with the frame held — its
fixed-interface modes when the frame is the interface — and the frame's six coordinates
carry the rigid motion. The linear body about rest: ``M(0)`` over ``[v; ω; η̇]``,
stiffness ``diag(0₆, Φᵀ K Φ)``. With every mode (k = 3N − 6) it is the FE model in other
coordinates, so the frequencies agree to rounding; with fewer they lie above.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.fe.neutral import FEModel
from rt70.textbook.flexible import body_mass_matrix, inertia_invariants


@dataclass(frozen=True)
class HeldModes:
    """An FE model's modes with its frame held by a 3-2-1 support.

    Attributes
    ----------
    origin : numpy.ndarray, shape (3,)
        The frame's origin (the first support node), m.
    nodes : numpy.ndarray, shape (N, 3)
        The nodes relative to the origin, m.
    masses : numpy.ndarray, shape (N,)
        The lumped nodal masses, kg.
    shapes : numpy.ndarray, shape (N, 3, n_free)
        Every held mode, lowest first, mass-normalised.
    omega2 : numpy.ndarray, shape (n_free,)
        Their ω², (rad/s)².
    """

    origin: np.ndarray
    nodes: np.ndarray
    masses: np.ndarray
    shapes: np.ndarray
    omega2: np.ndarray


def held_modes(fe: FEModel, support: tuple[int, int, int]) -> HeldModes:
    """Every mode of a lumped-mass FE model of translational nodes with a 3-2-1 support.

    Parameters
    ----------
    fe : FEModel
        Three translations a node, a diagonal (lumped) mass matrix.
    support : (int, int, int)
        Indices of the three support nodes (not collinear); the second is held across
        the line from the first, the third off the plane of the first two's line and z.
    """
    n = fe.node_xyz.shape[0]
    a, b, c = (fe.node_xyz[i] for i in support)
    along = (b - a) / np.linalg.norm(b - a)
    normal = np.cross(along, c - a)
    normal /= np.linalg.norm(normal)
    across = np.cross(normal, along)
    # constraints as rows on u (3N): node a all three, node b across and normal, node c normal
    rows = [np.eye(3)[k] for k in range(3)]
    places = [support[0]] * 3 + [support[1]] * 2 + [support[2]]
    rows += [across, normal, normal]
    G = np.zeros((6, 3 * n))
    for r, (node, direction) in enumerate(zip(places, rows, strict=True)):
        G[r, 3 * node : 3 * node + 3] = direction
    basis = scipy.linalg.null_space(G)  # u = basis · y, the motions the support allows
    M, K = fe.M.toarray(), fe.K.toarray()
    omega2, y = scipy.linalg.eigh(basis.T @ K @ basis, basis.T @ M @ basis)
    shapes = (basis @ y).reshape(n, 3, -1)
    masses = np.diag(M).reshape(n, 3)[:, 0]
    return HeldModes(a.copy(), fe.node_xyz - a, masses, shapes, omega2)


def body_frequencies(held: HeldModes, k: int) -> np.ndarray:
    """The free–free frequencies (Hz) of the modal body with the lowest k held modes.

    Parameters
    ----------
    held : HeldModes
        The component's held modes.
    k : int
        How many are kept.
    """
    inv = inertia_invariants(held.nodes, held.masses, held.shapes[:, :, :k])
    M = body_mass_matrix(inv, np.zeros(k))
    K = np.zeros_like(M)
    K[6:, 6:] = np.diag(held.omega2[:k])  # Φᵀ K Φ of mass-normalised held modes
    omega2 = scipy.linalg.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(omega2, 0.0, None)) / (2 * np.pi)


def nodal_frequencies(fe: FEModel) -> np.ndarray:
    """The FE model's own free–free frequencies, Hz (dense: small models)."""
    omega2 = scipy.linalg.eigh(fe.K.toarray(), fe.M.toarray(), eigvals_only=True)
    return np.sqrt(np.clip(omega2, 0.0, None)) / (2 * np.pi)
