"""The modes nearest zero by shift-invert Lanczos (rt70.linear.lowest_modes).

They must be the dense solution's lowest modes: the same ω² to the rounding of the
spectrum's largest ``|ω²|``, the same shapes (each mode's sign is fixed the same way),
the same rigid and unstable flags and damping ratios; and the inertia count must see an
unstable mode the modes found do not reach.
"""

from __future__ import annotations

import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.linear import modal
from rt70.linear.lowest_modes import lowest_modes
from rt70.testing import MIN_REL, assert_close

#: The backward error ``‖Kv − ω²Mv‖ / ((‖K‖ + |ω²| ‖M‖) ‖v‖)`` of Lanczos at its shift:
#: about ``ε (ω² − σ)/|σ|`` (rt70.linear.lowest_modes, 3), 1.7e-14 on this test's model
#: (the dense ``eigh``: 5e-16); a bound a hundred times above it, far below a mode that
#: has not converged or a shift at the rigid modes (2e-10).
LANCZOS_BACKWARD = 1e-12


def _model(n: int, rigid: int, unstable: list[float], seed: int = 3):
    """Random ``M`` (SPD), ``K`` with ``rigid`` zero and the given negative eigenvalues, and
    a block-sparse ``D`` (dampers on neighbouring coordinates)."""
    rng = np.random.default_rng(seed)
    X = rng.standard_normal((n, n))
    M = X @ X.T / n + np.eye(n)
    L = np.linalg.cholesky(M)
    lam = np.concatenate(
        [np.zeros(rigid), unstable, rng.uniform(1.0, 1e4, n - rigid - len(unstable))]
    )
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    K = L @ (Q * lam) @ Q.T @ L.T  # K v = λ M v has exactly the eigenvalues lam
    K = 0.5 * (K + K.T)
    D = np.zeros((n, n))
    for i in range(n - 1):
        c = rng.uniform(0.1, 1.0)
        D[i : i + 2, i : i + 2] += c * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return M, K, D


def test_the_lowest_modes_are_the_dense_solutions_lowest():
    M, K, D = _model(120, rigid=2, unstable=[-0.5])
    full = modal.modes(M, K, D)
    low, unstable = lowest_modes(M, K, D, 15)
    scale = float(np.max(np.abs(full.omega2)))
    assert low.n == 15 and low.shapes.shape == (120, 15)
    assert_close(low.omega2, full.omega2[:15], rel=1e3 * MIN_REL, scale=scale)
    assert_close(low.rigid_tol, full.rigid_tol, rel=1e-2)  # the scale is estimated to 1e-3
    assert np.array_equal(low.rigid, full.rigid[:15])
    assert np.array_equal(low.negative, full.negative[:15])
    assert unstable == int(full.negative.sum()) == 1
    assert low.rigid.sum() == 2
    elastic = ~(full.rigid | full.negative)[:15]
    shapes = np.max(np.abs(full.shapes))
    assert_close(low.shapes[:, elastic], full.shapes[:, :15][:, elastic], rel=1e-8, scale=shapes)
    assert_close(low.zeta[elastic], full.zeta[:15][elastic], rel=1e-8, scale=1.0)
    checks = modal.residuals(M, K, low)
    assert checks["eigen_backward"] < LANCZOS_BACKWARD
    assert checks["orthonormality"] < 1e3 * MIN_REL  # exact after Rayleigh–Ritz


def test_an_unstable_mode_beyond_those_found_is_counted():
    M, K, D = _model(80, rigid=0, unstable=[-5e3, -0.2])
    full = modal.modes(M, K, D)
    low, unstable = lowest_modes(M, K, D, 6)
    assert unstable == int(full.negative.sum()) == 2
    assert low.negative.sum() == 1  # the strongly unstable mode is not among the nearest zero
    order = np.argsort(np.abs(full.omega2))[:6]
    assert_close(np.sort(low.omega2), np.sort(full.omega2[order]), rel=1e3 * MIN_REL,
                 scale=float(np.max(np.abs(full.omega2))))  # fmt: skip


@pytest.mark.parametrize("count", [0, 79])
def test_a_count_arpack_cannot_find_is_refused(count):
    M, K, D = _model(80, rigid=0, unstable=[])
    with pytest.raises(Rt70Error, match="count must be between 1 and 78"):
        lowest_modes(M, K, D, count)
