"""Dense matrices that are mostly zero, multiplied in sparse storage.

The linear models are assembled dense (n × n), but some of their matrices are mostly
zero: the damping ``ΣJᵀDJ`` of dampers that each act across one pair is block-diagonal
in the pairs' coordinates. A product with such a matrix in CSR storage costs its
non-zeros instead of n².
"""

from __future__ import annotations

import numpy as np
import scipy.sparse

#: Below this fraction of non-zero entries a matrix is multiplied in sparse storage.
SPARSE_DENSITY = 0.05


def sparse_if_sparse(X: np.ndarray):
    """``X`` in CSR storage when under :data:`SPARSE_DENSITY` of it is non-zero, else ``X``.

    A damping matrix ``ΣJᵀDJ`` of local dampers is block-sparse (0.3 % non-zero on the
    2004-coordinate chain): its product then costs its non-zeros, not n².

    Parameters
    ----------
    X : numpy.ndarray
        A dense matrix.
    """
    if np.count_nonzero(X) >= SPARSE_DENSITY * X.size:
        return X
    return scipy.sparse.csr_array(X)
