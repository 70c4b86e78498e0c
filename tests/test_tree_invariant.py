"""ΠC·ΣI/ΠI is the product of the non-zero ω² of every free torsional tree.

The proof is in docs/tree-invariant.md; here it is checked against eigh.
"""

import math

import numpy as np
import pytest
import scipy.linalg

from rt70.errors import NonFiniteError
from rt70.linear import topology
from rt70.linear.topology import LinearModelError
from rt70.linear.tree_invariant import (
    free_tree_check,
    free_tree_omega2_product,
    model_omega2_product,
    printed_omega2_product,
)
from rt70.scenes import rt70_chapter2
from rt70.testing import assert_close, close

#: Relative agreement asked of eigh's product. The values span two decades: eigh's error
#: is absolute (ε·λ_max), so a wider spread costs the smallest eigenvalues relative digits
#: (the eigensolver's, not the invariant's; four decades give 3e-9).
RTOL = 1e-10


def random_tree(rng, n):
    """Edges of a uniformly labelled random spanning tree of bodies 1..n, random directions."""
    label = rng.permutation(n) + 1
    edges = []
    for v in range(1, n):
        e = (int(label[rng.integers(0, v)]), int(label[v]))
        edges.append(e if rng.random() < 0.5 else e[::-1])
    return [edges[k] for k in rng.permutation(n - 1)]


def eig_product(inertias, edges, stiffness, gamma=None):
    """Product of the non-zero eigenvalues of K v = ω² M v by eigh, and the spectrum."""
    model = topology.from_graph(inertias, edges, stiffness)
    G = model.gamma if gamma is None else gamma
    K = G.T @ np.diag(np.asarray(stiffness, dtype=float)) @ G
    w = scipy.linalg.eigh(K, model.m, eigvals_only=True)
    order = np.argsort(np.abs(w))
    assert_close(w[order[0]], 0.0, rel=1e-12, scale=np.abs(w).max())  # one rigid mode …
    assert abs(w[order[1]]) > 1e-6 * abs(w).max()  # … and only one
    rest = w[order[1:]]
    assert np.all(rest > 0)
    return math.exp(math.fsum(np.log(rest))), np.sort(rest)


@pytest.mark.parametrize("seed", range(60))
def test_product_of_nonzero_eigenvalues_on_random_trees(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 31))
    inertias = 10 ** rng.uniform(-1, 1, n)
    stiffness = 10 ** rng.uniform(-1, 1, n - 1)
    edges = random_tree(rng, n)
    product, _ = eig_product(inertias, edges, stiffness)
    expected = free_tree_omega2_product(inertias, stiffness)
    # the formula, evaluated here directly: rounding of its ~60 factors
    assert_close(expected, np.prod(stiffness) * inertias.sum() / np.prod(inertias), rel=1e-13)
    assert_close(product, expected, rel=RTOL)


@pytest.mark.parametrize("seed", range(5))
def test_invariant_under_rewiring_and_permutations(seed):
    rng = np.random.default_rng(100 + seed)
    n = 8
    inertias = 10 ** rng.uniform(-1, 1, n)
    stiffness = 10 ** rng.uniform(-1, 1, n - 1)
    edges = random_tree(rng, n)
    base, spectrum = eig_product(inertias, edges, stiffness)
    variants = {
        "rewired": (inertias, random_tree(rng, n), stiffness),
        "C permuted": (inertias, edges, rng.permutation(stiffness)),
        "I permuted": (rng.permutation(inertias), edges, stiffness),
        "all three": (rng.permutation(inertias), random_tree(rng, n), rng.permutation(stiffness)),
    }
    for name, (i, e, c) in variants.items():
        product, other = eig_product(i, e, c)
        assert_close(product, base, rel=RTOL, what=name)
        assert_close(free_tree_omega2_product(i, c), base, rel=RTOL, what=name)
        # the spectra themselves differ: the test is not comparing a model with itself
        assert np.max(np.abs(other - spectrum) / spectrum) > 1e-3, name


def test_changing_a_value_or_the_graph_changes_the_product():
    rng = np.random.default_rng(7)
    inertias, stiffness = 10 ** rng.uniform(-1, 1, 6), 10 ** rng.uniform(-1, 1, 5)
    edges = random_tree(rng, 6)
    base = free_tree_omega2_product(inertias, stiffness)
    c = stiffness.copy()
    c[2] *= 1.5  # one changed stiffness: the product scales by exactly its factor
    assert_close(eig_product(inertias, edges, c)[0], 1.5 * base, rel=RTOL)
    i, c = inertias.copy(), stiffness.copy()
    i[0], c[0] = c[0], i[0]  # an inertia swapped with a stiffness
    assert not close(free_tree_omega2_product(i, c), base, rel=1e-3)


def test_rows_scaled_by_a_ratio_act_as_stiffness_times_its_square():
    """A link deforming by r_s(α_j − α_i) (gear, lever) has the effective stiffness r_s² C_s."""
    rng = np.random.default_rng(11)
    n = 9
    inertias, stiffness = 10 ** rng.uniform(-1, 1, n), 10 ** rng.uniform(-1, 1, n - 1)
    edges = random_tree(rng, n)
    r = rng.uniform(0.3, 3.0, n - 1) * rng.choice([-1, 1], n - 1)
    gamma = r[:, None] * topology.topology_matrix(edges, n)
    product, _ = eig_product(inertias, edges, stiffness, gamma=gamma)
    assert_close(product, free_tree_omega2_product(inertias, r**2 * stiffness), rel=RTOL)


@pytest.mark.parametrize("key", rt70_chapter2.AZIMUTH_ELEVATIONS)
def test_book_azimuth_model_is_a_free_tree_and_obeys_it(key):
    model = rt70_chapter2.azimuth_model(key)
    w = np.sort(scipy.linalg.eigh(model.C, model.m, eigvals_only=True))
    assert_close(model_omega2_product(model), math.prod(w[1:]), rel=1e-12)
    free_tree_check(rt70_chapter2.elevation_model())


def test_units_cancel():
    rng = np.random.default_rng(3)
    inertias, stiffness = 10 ** rng.uniform(-1, 1, 7), 10 ** rng.uniform(-1, 1, 6)
    kgf = 9.80665  # technical units to SI: I and C both scale by g
    si = free_tree_omega2_product(kgf * inertias, kgf * stiffness)
    assert_close(si, free_tree_omega2_product(inertias, stiffness), rel=1e-14)


def test_printed_product():
    printed = printed_omega2_product([0.0, 1 / (2 * math.pi), 2 / (2 * math.pi)])
    assert_close(printed, 4.0, rel=1e-14)  # (2π f)² of 1 and 2 rad/s: rounding of 2π


@pytest.mark.parametrize(
    ("inertias", "edges", "stiffness", "message"),
    [
        ([1.0, 2.0, 3.0], [(1, 2), (0, 3)], [1.0, 1.0], "tied to the ground"),
        ([1.0, 2.0, 3.0, 4.0], [(1, 2), (2, 1), (3, 4)], [1.0, 1.0, 1.0], "closes a loop"),
        ([1.0, 2.0, 3.0], [(1, 2)], [1.0], "1 links for 3 bodies"),
        ([1.0, 2.0, 3.0], [(1, 2), (2, 3), (1, 3)], [1.0, 1.0, 1.0], "3 links for 3 bodies"),
    ],
)
def test_models_that_are_not_free_trees_are_refused(inertias, edges, stiffness, message):
    model = topology.from_graph(inertias, edges, stiffness)
    with pytest.raises(LinearModelError, match=message):
        model_omega2_product(model)


@pytest.mark.parametrize(
    ("inertias", "stiffness", "error", "message"),
    [
        ([1.0, 2.0], [1.0, 1.0], LinearModelError, "has 1 springs, got 2"),
        ([1.0, 0.0], [1.0], LinearModelError, "inertias must be positive"),
        ([1.0, 2.0], [-1.0], LinearModelError, "stiffnesses must be positive"),
        ([1.0, np.nan], [1.0], NonFiniteError, "inertias contain NaN"),
        ([1.0, 2.0], [np.inf], NonFiniteError, "stiffnesses contain NaN"),
        ([1.0] * 101, [1e300] * 100, LinearModelError, "overflows a float"),
    ],
)
def test_bad_values_are_refused(inertias, stiffness, error, message):
    with pytest.raises(error, match=message):
        free_tree_omega2_product(inertias, stiffness)
