"""Craig–Bampton reduction (rt70.fe.craig_bampton) on a free space frame.

Independent answers: the full model's static solution and its dense eigenproblem. The
reduced body keeps the six rigid-body modes and the interface's static stiffness
exactly at any number of modes, equals the full model with every mode kept, and its
frequencies fall towards the full model's from above as modes are added.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse.linalg as spla

from rt70.errors import Rt70Error
from rt70.fe.craig_bampton import craig_bampton
from rt70.fe.truss import space_frame
from rt70.testing import assert_close

FRAME = space_frame(6, 5)  # 60 nodes, 180 DOF, free
CORNERS = np.concatenate([FRAME.dofs_of(n) for n in FRAME.interfaces.values()])  # 12 DOF


def _frequencies(M, K) -> np.ndarray:
    return np.sqrt(np.abs(scipy.linalg.eigh(K, M, eigvals_only=True))) / (2 * np.pi)


FULL = _frequencies(FRAME.M.toarray(), FRAME.K.toarray())


@pytest.mark.parametrize("n_modes", [0, 7])
def test_the_reduced_matrices_are_the_projection_and_block_diagonal(n_modes):
    cb = craig_bampton(FRAME.M, FRAME.K, CORNERS, n_modes)
    T = cb.T
    scale_k, scale_m = np.abs(FRAME.K).max(), np.abs(FRAME.M).max()
    assert_close(cb.K, T.T @ (FRAME.K @ T), rel=1e-10, scale=scale_k)
    assert_close(cb.M, T.T @ (FRAME.M @ T), rel=1e-10, scale=scale_m)
    nb = cb.n_boundary
    assert np.array_equal(cb.K[:nb, nb:], np.zeros((nb, n_modes)))
    if n_modes:
        assert_close(cb.M[nb:, nb:], np.eye(n_modes), rel=1e-12)


@pytest.mark.parametrize("n_modes", [0, 3, 20])
def test_the_six_rigid_body_modes_are_kept_at_any_number_of_modes(n_modes):
    cb = craig_bampton(FRAME.M, FRAME.K, CORNERS, n_modes)
    w = scipy.linalg.eigh(cb.K, cb.M, eigvals_only=True)
    rigid = np.abs(w) <= 1e-10 * w.max()
    assert rigid.sum() == 6 and np.all(w[~rigid] > 0.0)


def test_the_interface_stiffness_is_exact():
    """Three corners held, a force on the fourth: the reduced body (any mode count) moves
    that corner exactly as the full model does."""
    held, loaded = CORNERS[:9], CORNERS[9:]
    force = np.array([1e4, -2e4, 3e4])
    free = np.setdiff1d(np.arange(FRAME.n_dofs), held)
    f = np.zeros(FRAME.n_dofs)
    f[loaded] = force
    u = spla.spsolve(FRAME.K[free][:, free].tocsc(), f[free])
    full = u[np.searchsorted(free, loaded)]
    cb = craig_bampton(FRAME.M, FRAME.K, CORNERS, 5)
    reduced = np.linalg.solve(cb.K[9:12, 9:12], force)
    assert_close(reduced, full, rel=1e-10)


def test_every_mode_kept_gives_the_full_model_back():
    cb = craig_bampton(FRAME.M, FRAME.K, CORNERS, FRAME.n_dofs - CORNERS.size)
    reduced = _frequencies(cb.M, cb.K)
    # the flexible ones (the six rigid are rounding, ~1e-6 Hz, on both)
    assert_close(reduced[6:], FULL[6:], rel=1e-9, scale=FULL.max())


def test_frequencies_fall_to_the_full_models_from_above_as_modes_are_added():
    """The six lowest flexible frequencies (all a Guyan model of 12 DOF has)."""
    target = FULL[6:12]
    errors = []
    for k in (0, 5, 10, 20, 40, 80):
        cb = craig_bampton(FRAME.M, FRAME.K, CORNERS, k)
        reduced = _frequencies(cb.M, cb.K)[6:12]
        assert np.all(reduced >= target * (1.0 - 1e-12))  # Rayleigh–Ritz: upper bounds
        errors.append(float(np.max((reduced - target) / target)))
    assert all(a > b for a, b in zip(errors, errors[1:], strict=False)), errors
    assert errors[-1] < 1e-3


def test_a_boundary_that_does_not_hold_the_structure_is_refused():
    one_node = FRAME.dofs_of(next(iter(FRAME.interfaces.values())))
    with pytest.raises(Rt70Error, match="does not hold the structure"):
        craig_bampton(FRAME.M, FRAME.K, one_node, 3)
    with pytest.raises(Rt70Error, match="distinct rows"):
        craig_bampton(FRAME.M, FRAME.K, [0, 0, 1], 3)
    with pytest.raises(Rt70Error, match="n_modes must be between 0"):
        craig_bampton(FRAME.M, FRAME.K, CORNERS, 1000)
