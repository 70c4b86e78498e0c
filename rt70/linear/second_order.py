"""The second-order model a state space is assembled from (formalism §2).

A plain record of matrices, without python-control, so that the modules that build or
read it stay light to import.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SecondOrder:
    """The second-order model ``M q̈ + D q̇ + K q = B_in u``, ``y = C_out q + C_vel q̇ + D_ff u``.

    Kept by :class:`rt70.linear.state_space.StateSpace` so that
    :func:`rt70.linear.responses.frequency_response` can solve ``(K − ω²M + jωD) X = B_in``
    directly and :func:`rt70.linear.reduce.modal_truncation` can reduce it.
    """

    M: np.ndarray
    K: np.ndarray
    D: np.ndarray
    B_in: np.ndarray
    C_out: np.ndarray
    C_vel: np.ndarray
    D_ff: np.ndarray
