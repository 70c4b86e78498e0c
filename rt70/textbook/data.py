"""Work buffers of the textbook algorithms, kept apart from the model (as in Pinocchio)."""

from __future__ import annotations

import numpy as np

from rt70.textbook.model import Model


class Data:
    """Buffers filled by the textbook algorithms for one :class:`~rt70.textbook.model.Model`.

    Attributes
    ----------
    L_pair : numpy.ndarray
        Pair transformations ``L_{i}^{j}`` of each pair w.r.t. its parent (4.5)–(4.7),
        shape (nb, 6, 6).
        For a root pair the parent is the ground frame E0.
    R, p : numpy.ndarray
        Absolute orientation ``c_{0j}`` and origin of every body frame in E0.
    Mf : list of numpy.ndarray
        ``M_j f_j`` of each pair (6 × k_j), (4.13).
    dMf_qd : numpy.ndarray
        ``Ṁ_j f_j q̇_j`` of each pair, shape (nb, 6) (from (4.82)).
    L : numpy.ndarray
        Configuration matrix (4.64), shape (6 nb, 6 nb).
    S : numpy.ndarray
        Structure matrix ``S = [f]ᵀ Mᵀ L`` (4.66), shape (nv, 6 nb); ``S_full`` before
        the mimic reduction ``S = Gᵀ S_full``.
    q_full : numpy.ndarray
        Pair coordinates of the last configuration, ``G q + q_offset``.
    Theta : numpy.ndarray
        Block-diagonal inertia ``Θ = diag(Θ_k)``, shape (6 nb, 6 nb).
    V : numpy.ndarray
        Absolute body velocities ``V⁰ = Sᵀ q̇`` (4.63), shape (nb, 6).
    S_dot : numpy.ndarray
        Structure rate Ṡ (4.81) of the last bias evaluation, shape of S.
    A : numpy.ndarray
        Mass matrix ``S Θ Sᵀ`` (4.79).
    """

    def __init__(self, model: Model) -> None:
        nb, nv = model.nb, model.nv
        self.L_pair = np.zeros((nb, 6, 6))
        self.R = np.zeros((nb, 3, 3))
        self.p = np.zeros((nb, 3))
        self.Mf: list[np.ndarray] = [np.zeros((6, int(k))) for k in model.ndof]
        self.dMf_qd = np.zeros((nb, 6))
        self.L = np.zeros((6 * nb, 6 * nb))
        self.S_full = np.zeros((model.n_full, 6 * nb))
        self.S = self.S_full if model.G is None and not model.modal else np.zeros((nv, 6 * nb))
        self.q_full = np.zeros(model.n_full)
        self.Theta = np.zeros((6 * nb, 6 * nb))
        for j in range(nb):
            self.Theta[6 * j : 6 * j + 6, 6 * j : 6 * j + 6] = model.Theta[j]
        self.V = np.zeros((nb, 6))
        self.S_dot = np.zeros_like(self.S)
        self.A = np.zeros((nv, nv))
