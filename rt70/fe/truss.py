"""A 3-D truss from bar elements: rt70's own small FE assembly for the test structures.

A bar between nodes 1 and 2 (axial stiffness EA, mass per length ρA, length L, unit
direction n) has, on the six translations ``[u₁; u₂]``, the textbook element matrices

    K_e = (EA / L) [[n nᵀ, −n nᵀ], [−n nᵀ, n nᵀ]],    M_e = (ρ A L / 2) 1₆

(stiffness: e.g. Przemieniecki, *Theory of Matrix Structural Analysis*, §5; the mass
lumped half to each end). :func:`assemble` adds them into sparse global matrices, all
bars at once; :func:`space_frame` builds a two-layer grid of the kind that carries a
reflector's panels, with as many nodes as a benchmark needs.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from rt70.errors import Rt70Error
from rt70.fe.neutral import FEModel


def bar_matrices(p1: np.ndarray, p2: np.ndarray, EA: float, rho_A: float):
    """``(K_e, M_e)`` of one bar on ``[u₁; u₂]`` (6 × 6 each), N/m and kg.

    Parameters
    ----------
    p1, p2 : array_like, shape (3,)
        The bar's end nodes, m.
    EA : float
        Axial stiffness, N.
    rho_A : float
        Mass per length, kg/m.
    """
    d = np.asarray(p2, dtype=float) - np.asarray(p1, dtype=float)
    L = float(np.linalg.norm(d))
    if not L > 0.0:
        raise Rt70Error("a bar of zero length")
    nn = np.outer(d, d) / L**2
    K = (EA / L) * np.block([[nn, -nn], [-nn, nn]])
    return K, 0.5 * rho_A * L * np.eye(6)


def assemble(
    xyz: np.ndarray, bars: np.ndarray, EA: float | np.ndarray, rho_A: float | np.ndarray
) -> tuple[sp.csr_array, sp.csr_array]:
    """Sparse ``(M, K)`` of a truss, 3 translations per node (rows ``3 i + c``).

    Parameters
    ----------
    xyz : numpy.ndarray, shape (n, 3)
        Node positions, m.
    bars : numpy.ndarray of int, shape (m, 2)
        The two nodes (indices into ``xyz``) of each bar.
    EA, rho_A : float or numpy.ndarray, shape (m,)
        Axial stiffness, N, and mass per length, kg/m, of each bar.
    """
    xyz, bars = np.asarray(xyz, dtype=float), np.asarray(bars, dtype=np.int64)
    d = xyz[bars[:, 1]] - xyz[bars[:, 0]]
    L = np.linalg.norm(d, axis=1)
    if np.any(L <= 0.0):
        raise Rt70Error(f"bar {int(np.argmin(L))} has zero length")
    EA = np.broadcast_to(np.asarray(EA, dtype=float), L.shape)
    rho_A = np.broadcast_to(np.asarray(rho_A, dtype=float), L.shape)
    nn = np.einsum("bi,bj->bij", d, d) / L[:, None, None] ** 2
    k = (EA / L)[:, None, None] * nn  # (m, 3, 3)
    blocks = np.concatenate(
        [np.concatenate([k, -k], axis=2), np.concatenate([-k, k], axis=2)], axis=1
    )  # (m, 6, 6)
    dofs = (3 * bars[:, :, None] + np.arange(3)).reshape(-1, 6)  # (m, 6)
    rows = np.repeat(dofs, 6, axis=1).ravel()
    cols = np.tile(dofs, (1, 6)).ravel()
    n = 3 * xyz.shape[0]
    K = sp.csr_array(sp.coo_array((blocks.ravel(), (rows, cols)), shape=(n, n)))
    lumped = np.zeros(xyz.shape[0])
    np.add.at(lumped, bars.ravel(), np.repeat(0.5 * rho_A * L, 2))
    M = sp.diags_array(np.repeat(lumped, 3)).tocsr()
    return M, K


def space_frame(
    nx: int, ny: int, spacing: float = 1.0, depth: float = 1.0, EA: float = 2e8,
    rho_A: float = 20.0,
) -> FEModel:  # fmt: skip
    """A two-layer space frame of ``nx × ny`` nodes per layer (3 translations each).

    Chords along x and y and one diagonal of each square in both layers, verticals, and
    diagonals from each bottom node to the four top nodes around it: no mechanism, so
    six rigid-body modes when free. Steel tubes by default: EA = 2e8 N (≈ 10 cm²,
    E = 200 GPa), 20 kg/m. The interface nodes are the four bottom corners
    (``corner_1`` … ``corner_4``).

    Parameters
    ----------
    nx, ny : int
        Nodes a layer along x and y (at least 2 each).
    spacing : float
        Distance between neighbouring nodes of a layer, m.
    depth : float
        Distance between the layers, m.
    EA : float
        Axial stiffness of every bar, N.
    rho_A : float
        Mass per length of every bar, kg/m.
    """
    if nx < 2 or ny < 2:
        raise Rt70Error(f"a space frame needs at least 2 × 2 nodes a layer, got {nx} × {ny}")
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    layer = np.column_stack([i.ravel() * spacing, j.ravel() * spacing, np.zeros(i.size)])
    xyz = np.vstack([layer, layer + [0.0, 0.0, depth]])
    node = np.arange(nx * ny).reshape(nx, ny)
    top = nx * ny
    bars = []
    for offset in (0, top):  # chords along x and y, and one diagonal of each square
        bars.append(np.column_stack([node[:-1, :].ravel(), node[1:, :].ravel()]) + offset)
        bars.append(np.column_stack([node[:, :-1].ravel(), node[:, 1:].ravel()]) + offset)
        bars.append(np.column_stack([node[:-1, :-1].ravel(), node[1:, 1:].ravel()]) + offset)
    bars.append(np.column_stack([node.ravel(), node.ravel() + top]))  # verticals
    for di, dj in ((1, 0), (0, 1), (-1, 0), (0, -1)):  # bottom node to the top neighbours
        ok = (i + di >= 0) & (i + di < nx) & (j + dj >= 0) & (j + dj < ny)
        bars.append(np.column_stack([node[ok], node[(i + di)[ok], (j + dj)[ok]] + top]))
    bars = np.vstack(bars)
    M, K = assemble(xyz, bars, EA, rho_A)
    ids = np.arange(1, xyz.shape[0] + 1)
    corners = [node[0, 0], node[-1, 0], node[-1, -1], node[0, -1]]
    return FEModel(
        M,
        K,
        ids,
        xyz,
        np.repeat(ids, 3),
        np.tile(np.arange(1, 4), xyz.shape[0]),
        {f"corner_{k + 1}": int(ids[c]) for k, c in enumerate(corners)},
        name=f"space frame {nx} × {ny} × 2",
    )
