"""The KKT solve of the constrained equations (14) (rt70.kkt): range-space method."""

import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.kkt import solve_kkt


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
    np.testing.assert_allclose(sol.x, dense[:n], rtol=0, atol=1e-12)
    np.testing.assert_allclose(sol.lam, -dense[n:], rtol=0, atol=1e-12)
    # the KKT matrix is indefinite: m negative eigenvalues (erratum X.3.11)
    assert int((np.linalg.eigvalsh(K) < 0).sum()) == m


def test_redundant_rows_give_the_unique_acceleration_and_least_norm_reactions():
    A, B, f, g = _system(np.random.default_rng(2))
    B2 = np.vstack([B, B[0] + 2 * B[1]])
    g2 = np.append(g, g[0] + 2 * g[1])
    full, redundant = solve_kkt(A, B, f, g), solve_kkt(A, B2, f, g2)
    assert redundant.rank == 3
    np.testing.assert_allclose(redundant.x, full.x, atol=1e-12)
    np.testing.assert_allclose(B2.T @ redundant.lam, B.T @ full.lam, atol=1e-11)
    assert np.linalg.norm(redundant.lam) <= np.linalg.norm(full.lam) + 1e-12


def test_contradicting_rows_are_refused():
    A, B, f, g = _system(np.random.default_rng(3))
    B2 = np.vstack([B, B[0]])
    with pytest.raises(Rt70Error, match="contradict"):
        solve_kkt(A, B2, f, np.append(g, g[0] + 1.0))


def test_no_constraints_is_the_plain_solve_and_indefinite_a_is_refused():
    A, _, f, _ = _system(np.random.default_rng(4))
    sol = solve_kkt(A, np.zeros((0, 7)), f, np.zeros(0))
    np.testing.assert_allclose(A @ sol.x, f, atol=1e-12)
    with pytest.raises(Rt70Error, match="positive definite"):
        solve_kkt(-A, np.ones((1, 7)), f, np.zeros(1))
