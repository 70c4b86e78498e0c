"""Craig–Bampton reduction of a finite-element model to its interface and a few modes.

Craig & Bampton, AIAA J. 6(7):1313–1319, 1968 (spec flexible-and-reflector.md §2). The
degrees of freedom split into boundary ``b`` (the interface nodes, where the body is
attached) and interior ``i``:

- constraint modes ``Ψ = −K_ii⁻¹ K_ib``: the interior's static response to a unit motion
  of each boundary DOF (Guyan's static condensation when nothing else is kept);
- fixed-interface modes ``Φ``: the ``k`` lowest of ``(K_ii − ω² M_ii) φ = 0``,
  mass-normalised;
- ``u = T [u_b; η]`` with ``T = [[1, 0], [Ψ, Φ]]``, and ``M_cb = Tᵀ M T``,
  ``K_cb = Tᵀ K T``.

``K_cb`` is block diagonal: the condensed boundary stiffness ``K_bb + K_bi Ψ`` and
``diag(ω²)``. Because the boundary block spans every static state of the interface, the
reduced body keeps the rigid-body modes and the static stiffness at the interface
exactly; the truncation to ``k`` modes only costs dynamics, and as a Rayleigh–Ritz
projection the reduced frequencies are upper bounds of the full model's.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rt70.errors import Rt70Error
from rt70.fe.modes import lowest_modes

#: A pivot of K_ii's LU below this fraction of the largest marks it singular: a rigid
#: motion's pivot is rounding (about 1e-16 of the largest), a stiff but held structure's
#: smallest pivot is far above it.
SINGULAR_PIVOT_RTOL = 1e-13
#: Largest interior for which every fixed-interface mode may be kept (a dense eigensolve).
MAX_DENSE_INTERIOR = 3000


@dataclass(frozen=True)
class CraigBampton:
    """A Craig–Bampton model: ``M_cb ẍ + K_cb x = Tᵀ f``, ``x = [u_b; η]``, ``u = T x``.

    Attributes
    ----------
    M, K : numpy.ndarray, shape (n_b + k, n_b + k)
        Reduced mass and stiffness; ``K`` is block diagonal, ``M[n_b:, n_b:] = 1``.
    T : numpy.ndarray, shape (N, n_b + k)
        The full DOFs from the reduced coordinates, rows in the model's order.
    boundary : numpy.ndarray, shape (n_b,)
        Rows of the full model that are the boundary DOFs, in the order of ``x``.
    omega2 : numpy.ndarray, shape (k,)
        ω² of the fixed-interface modes kept, (rad/s)².
    seconds : float
        Wall time of the reduction.
    """

    M: np.ndarray
    K: np.ndarray
    T: np.ndarray
    boundary: np.ndarray
    omega2: np.ndarray
    seconds: float

    @property
    def n_boundary(self) -> int:
        """Number of boundary DOFs."""
        return int(self.boundary.size)


def _fixed_interface_modes(M_ii, K_ii, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """ω² and mass-normalised Φ of the k lowest fixed-interface modes."""
    n_i = M_ii.shape[0]
    if n_modes == 0:
        return np.zeros(0), np.zeros((n_i, 0))
    if n_modes < n_i:
        modes = lowest_modes(M_ii, K_ii, n_modes)
        return modes.omega2, modes.shapes
    if n_i > MAX_DENSE_INTERIOR:
        raise Rt70Error(
            f"all {n_i} fixed-interface modes asked for: at most {MAX_DENSE_INTERIOR - 1} of "
            "an interior that large"
        )
    w, V = scipy.linalg.eigh(K_ii.toarray(), M_ii.toarray())
    return w, V


def craig_bampton(M: sp.sparray, K: sp.sparray, boundary, n_modes: int) -> CraigBampton:
    """Reduce (M, K) to the ``boundary`` DOFs and ``n_modes`` fixed-interface modes.

    Parameters
    ----------
    M, K : scipy.sparse array, shape (N, N)
        Symmetric mass and stiffness of the full model.
    boundary : sequence of int
        Rows of the boundary DOFs (e.g. every DOF of the interface nodes,
        :meth:`rt70.fe.neutral.FEModel.dofs_of`); they must hold the structure (``K_ii``
        nonsingular).
    n_modes : int
        Fixed-interface modes kept, 0 (Guyan) to the interior's size.

    Raises
    ------
    Rt70Error
        Boundary rows out of range or repeated, ``n_modes`` out of range, or an interior
        that the boundary does not hold (K_ii singular: a mechanism or a rigid motion
        left free).
    """
    start = time.perf_counter()
    n = M.shape[0]
    b = np.asarray(boundary, dtype=np.int64)
    if b.size == 0 or np.unique(b).size != b.size or b.min() < 0 or b.max() >= n:
        raise Rt70Error(f"boundary rows must be distinct rows of the model (0…{n - 1})")
    i = np.setdiff1d(np.arange(n), b)
    if not 0 <= n_modes <= i.size:
        raise Rt70Error(f"n_modes must be between 0 and the interior's {i.size}, got {n_modes}")
    Kc, Mc = sp.csc_array(K), sp.csc_array(M)
    K_ii, K_ib, K_bb = Kc[i][:, i], Kc[i][:, b], Kc[b][:, b]
    M_ii, M_ib, M_bb = Mc[i][:, i], Mc[i][:, b], Mc[b][:, b]
    singular = Rt70Error(
        "the boundary does not hold the structure: K_ii is singular (a rigid motion or a "
        "mechanism of the interior is left free; add interface DOFs)"
    )
    try:
        lu = spla.splu(sp.csc_array(K_ii))
    except RuntimeError:
        raise singular from None
    pivots = np.abs(lu.U.diagonal())
    if not pivots.min() > SINGULAR_PIVOT_RTOL * pivots.max():
        raise singular
    Psi = -lu.solve(K_ib.toarray())
    omega2, Phi = _fixed_interface_modes(M_ii, K_ii, n_modes)
    K_red = K_bb.toarray() + (K_ib.T @ Psi)
    M_ii_psi = M_ii @ Psi
    M_red = M_bb.toarray() + M_ib.T @ Psi + Psi.T @ M_ib.toarray() + Psi.T @ M_ii_psi
    M_b_eta = (M_ib.T @ Phi) + Psi.T @ (M_ii @ Phi)
    nb, k = b.size, omega2.size
    Mcb = np.zeros((nb + k, nb + k))
    Kcb = np.zeros((nb + k, nb + k))
    Mcb[:nb, :nb] = 0.5 * (M_red + M_red.T)
    Mcb[:nb, nb:], Mcb[nb:, :nb] = M_b_eta, M_b_eta.T
    Mcb[nb:, nb:] = np.eye(k)
    Kcb[:nb, :nb] = 0.5 * (K_red + K_red.T)
    Kcb[nb:, nb:] = np.diag(omega2)
    T = np.zeros((n, nb + k))
    T[b, np.arange(nb)] = 1.0
    T[np.ix_(i, np.arange(nb))] = Psi
    T[np.ix_(i, nb + np.arange(k))] = Phi
    return CraigBampton(Mcb, Kcb, T, b, omega2, time.perf_counter() - start)
