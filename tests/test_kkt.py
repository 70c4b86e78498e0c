"""The KKT solve of the constrained equations (14) (rt70.physics.kkt): range-space method."""

import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.physics.kkt import solve_kkt
from rt70.testing import assert_close, tolerance

#: The systems are 7 × 7 with A ≥ 7·1: well conditioned, solved to this relative error.
RTOL = 1e-13


def _system(rng, n=7, m=3):
    X = rng.normal(size=(n, n))
    A = X @ X.T + n * np.eye(n)
    return A, rng.normal(size=(m, n)), rng.normal(size=n), rng.normal(size=m)


def test_full_rank_equals_the_dense_kkt_solve():
    A, B, f, g = _system(np.random.default_rng(1))
    n, m = A.shape[0], B.shape[0]
    K = np.block([[A, B.T], [B, np.zeros((m, m))]])
    dense = np.linalg.solve(K, np.concatenate([f, g]))
    sol = solve_kkt(A, B, f, g)
    assert sol.rank == m
    assert_close(sol.x, dense[:n], rel=RTOL)
    assert_close(sol.lam, -dense[n:], rel=RTOL)
    # the KKT matrix is indefinite: m negative eigenvalues (erratum X.3.11)
    assert int((np.linalg.eigvalsh(K) < 0).sum()) == m


def test_redundant_rows_give_the_unique_acceleration_and_least_norm_reactions():
    A, B, f, g = _system(np.random.default_rng(2))
    B2 = np.vstack([B, B[0] + 2 * B[1]])
    g2 = np.append(g, g[0] + 2 * g[1])
    full, redundant = solve_kkt(A, B, f, g), solve_kkt(A, B2, f, g2)
    assert redundant.rank == 3
    # the least-norm solve of the dependent rows rounds more: 32 ulps measured
    assert_close(redundant.x, full.x, rel=10 * RTOL)
    # the reaction forces Bᵀλ, on the scale of their terms |B_ij λ_i|
    terms = np.abs(B2.T) @ np.abs(redundant.lam)
    assert_close(B2.T @ redundant.lam, B.T @ full.lam, rel=10 * RTOL, scale=terms)
    least, unique = np.linalg.norm(redundant.lam), np.linalg.norm(full.lam)
    assert least <= unique + tolerance(RTOL, unique)


def test_contradicting_rows_are_refused():
    A, B, f, g = _system(np.random.default_rng(3))
    B2 = np.vstack([B, B[0]])
    with pytest.raises(Rt70Error, match="contradict"):
        solve_kkt(A, B2, f, np.append(g, g[0] + 1.0))


def test_no_constraints_is_the_plain_solve_and_indefinite_a_is_refused():
    A, _, f, _ = _system(np.random.default_rng(4))
    sol = solve_kkt(A, np.zeros((0, 7)), f, np.zeros(0))
    # the residual on the scale of the terms A_ij x_j
    assert_close(A @ sol.x, f, rel=RTOL, scale=np.abs(A) @ np.abs(sol.x))
    with pytest.raises(Rt70Error, match="positive definite"):
        solve_kkt(-A, np.ones((1, 7)), f, np.zeros(1))
