"""A fill-reducing order of a sparse FE matrix: METIS nested dissection on its nodes.

One job: the permutation under which the factor of ``K − σ M`` stays sparse. Nested
dissection (George 1973; METIS, Karypis & Kumar 1998, through ``pymetis``) cuts the
mesh's graph into halves by small separators and numbers the separators last, so a 2-D
mesh of n nodes factors with O(n log n) fill instead of the O(n^1.5) of a column
ordering: on the 101 400-DOF space frame of docs/fe-models.md the factor has 33 M
entries against SuperLU's own COLAMD order's 72 M (``python validation/bench_sparse_modes.py``).

METIS orders the graph of the nodes, not of the DOFs: an FE matrix couples every DOF of a
node with every DOF of its neighbours, so consecutive DOFs in dense diagonal blocks of
b = 6, 3 or 2 are taken as one node (:func:`dof_block_size`), which makes the graph b²
times smaller and the ordering several times faster; a matrix without such blocks is
ordered DOF by DOF.
"""

from __future__ import annotations

import numpy as np
import pymetis
import scipy.sparse as sp

#: Node sizes tried, largest first: 6 DOFs (beams, shells), 3 (solids, trusses), 2.
NODE_SIZES = (6, 3, 2)
#: A node size b is taken when at least this fraction of the b × b diagonal blocks'
#: entries are stored (a few DOFs without mass or stiffness may leave holes).
DENSE_FRACTION = 0.5


def dof_block_size(A: sp.sparray) -> int:
    """The node size b of ``A``: consecutive DOFs ``b i … b i + b − 1`` that form dense blocks.

    Parameters
    ----------
    A : scipy.sparse array, shape (N, N)
        A symmetric FE matrix (its pattern is what counts).

    Returns
    -------
    int
        The first of :data:`NODE_SIZES` that divides N and whose diagonal blocks hold at
        least :data:`DENSE_FRACTION` of their entries; 1 if none does.
    """
    n = A.shape[0]
    C = sp.coo_array(A)
    for b in NODE_SIZES:
        if n % b == 0 and np.count_nonzero(C.row // b == C.col // b) >= DENSE_FRACTION * n * b:
            return b
    return 1


def nested_dissection(A: sp.sparray) -> np.ndarray:
    """A fill-reducing permutation ``p`` of ``A``: factor ``A[p][:, p]`` in that order.

    Parameters
    ----------
    A : scipy.sparse array, shape (N, N)
        A symmetric FE matrix.

    Returns
    -------
    numpy.ndarray of int, shape (N,)
        ``p[k]`` is the row of ``A`` that comes k-th; the DOFs of a node stay together.
    """
    b = dof_block_size(A)
    n = A.shape[0]
    csr = sp.csr_array(A)
    pattern = sp.csr_array((np.ones(csr.nnz), csr.indices, csr.indptr), shape=A.shape)
    group = sp.csr_array((np.ones(n), (np.arange(n) // b, np.arange(n))), shape=(n // b, n))
    graph = sp.csr_array(group @ pattern @ group.T)
    graph.setdiag(0)
    graph.eliminate_zeros()
    graph.sort_indices()
    if graph.nnz == 0:  # no coupling: any order is fill-free
        return np.arange(n)
    adjacency = pymetis.CSRAdjacency(graph.indptr, graph.indices)
    order, _ = pymetis.nested_dissection(adjacency=adjacency)
    return (b * np.asarray(order, dtype=np.int64)[:, None] + np.arange(b)).ravel()
