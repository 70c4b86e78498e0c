"""The reflector surface's mathematics (rt70.surface): path errors, best fit, Ruze.

Synthetic deformations with known answers (issue 25's targets): a rigid motion of the
dish plus a focal-length change is a paraboloid, so the best fit leaves nothing (≤ 1e-12
m) and gives back its parameters; an astigmatism, orthogonal to every paraboloid on
rings of equally spaced nodes, keeps its own RMS (1e-9 relative). The path error agrees
with the geometry of the surface: nothing for a displacement along it, ``cos(θ/2)`` of a
displacement along its normal.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from rt70.errors import Rt70Error
from rt70.surface.best_fit import best_fit, fit_maps
from rt70.surface.paraboloid import half_path_errors, surface_height
from rt70.surface.ruze import ruze_efficiency
from rt70.testing import assert_close

F = 21.0  # m: a 70 m dish with F/D = 0.3
RNG = np.random.default_rng(20261127)


def dish(rings: int = 8, per_ring: int = 24, radius: float = 35.0):
    """Nodes on rings of equally spaced points and each one's share of the aperture."""
    edges = np.linspace(0.0, radius, rings + 1)
    nodes, weights = [], []
    for k in range(rings):
        r = 0.5 * (edges[k] + edges[k + 1])
        phi = 2.0 * np.pi * (np.arange(per_ring) + 0.5 * (k % 2)) / per_ring
        x, y = r * np.cos(phi), r * np.sin(phi)
        nodes.append(np.column_stack([x, y, surface_height(x, y, F)]))
        weights.append(np.full(per_ring, np.pi * (edges[k + 1] ** 2 - edges[k] ** 2) / per_ring))
    return np.vstack(nodes), np.concatenate(weights)


def paraboloid_motion(nodes: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Displacements that move the nominal paraboloid to the one of parameters β."""
    u, v, w, phi_x, phi_y, dF = beta
    x, y = nodes[:, 0], nodes[:, 1]
    rigid = np.array([u, v, w]) + np.cross(np.array([phi_x, phi_y, 0.0]), nodes)
    focal = np.column_stack([0 * x, 0 * y, -(x**2 + y**2) / (4 * F**2) * dF])
    return rigid + focal


def test_a_paraboloid_is_fitted_exactly_and_its_parameters_come_back():
    nodes, weights = dish()
    for _ in range(5):
        beta = RNG.normal(0.0, 1.0, 6) * [2e-3, 2e-3, 2e-3, 1e-4, 1e-4, 3e-3]
        fit = best_fit(nodes, paraboloid_motion(nodes, beta), F, weights)
        assert np.abs(fit.residual).max() <= 1e-12 and fit.rms <= 1e-12
        assert_close(fit.parameters, beta, rel=1e-9, scale=np.abs(beta).max())
        u, v, w, phi_x, phi_y, dF = beta
        assert_close(fit.focus_shift, [u + F * phi_y, v - F * phi_x, w + dF], rel=1e-9,
                     scale=np.abs(beta).max() * F)  # fmt: skip


def test_an_astigmatism_keeps_its_rms():
    nodes, weights = dish()
    r = np.hypot(nodes[:, 0], nodes[:, 1])
    phi = np.arctan2(nodes[:, 1], nodes[:, 0])
    h = 50e-6 * (r / 35.0) ** 2 * np.cos(2.0 * phi)  # a known half-path-length error
    H = fit_maps(nodes, F, weights).H
    delta = H * (h / np.sum(H * H, axis=1))[:, None]  # displacements with exactly this h
    assert_close(half_path_errors(nodes, delta, F), h, rel=1e-12, scale=50e-6)
    expected = np.sqrt(np.sum(weights * h**2) / weights.sum())
    fit = best_fit(nodes, delta, F, weights)
    assert_close(fit.rms, expected, rel=1e-9)
    assert np.abs(fit.parameters).max() <= 1e-12 * F  # orthogonal to every paraboloid


def test_a_paraboloid_plus_an_aberration_leaves_the_aberration():
    nodes, weights = dish(rings=6, per_ring=16)
    r = np.hypot(nodes[:, 0], nodes[:, 1])
    phi = np.arctan2(nodes[:, 1], nodes[:, 0])
    h = 30e-6 * (r / 35.0) ** 3 * np.cos(3.0 * phi)  # trefoil
    H = fit_maps(nodes, F, weights).H
    aberration = H * (h / np.sum(H * H, axis=1))[:, None]
    beta = np.array([1e-3, -2e-3, 5e-4, 3e-5, -2e-5, 4e-3])
    fit = best_fit(nodes, paraboloid_motion(nodes, beta) + aberration, F, weights)
    assert_close(fit.parameters, beta, rel=1e-9, scale=np.abs(beta).max())
    assert_close(fit.residual, h, rel=1e-9, scale=30e-6)


def test_the_path_error_follows_the_surface_geometry():
    nodes, _ = dish(rings=3, per_ring=7)
    gradient = np.column_stack(
        [-nodes[:, 0] / (2 * F), -nodes[:, 1] / (2 * F), np.ones(len(nodes))]
    )
    normal = gradient / np.linalg.norm(gradient, axis=1)[:, None]
    tangent = np.cross(normal, RNG.normal(size=nodes.shape))
    assert_close(half_path_errors(nodes, 1e-3 * tangent, F), np.zeros(len(nodes)), rel=1e-15,
                 scale=1e-3)  # fmt: skip
    cos_half = 1.0 / np.sqrt(1.0 + (nodes[:, 0] ** 2 + nodes[:, 1] ** 2) / (4 * F**2))
    assert_close(half_path_errors(nodes, 1e-3 * normal, F), 1e-3 * cos_half, rel=1e-14)


def test_ruze_at_300_ghz_and_80_micrometres():
    assert ruze_efficiency(80e-6, 300e9) == pytest.approx(
        np.exp(-((4 * np.pi * 80e-6 * 300e9 / 299_792_458.0) ** 2)), rel=1e-15
    )
    assert 0.35 < ruze_efficiency(80e-6, 300e9) < 0.37  # the spec's η_s ≈ 0.36
    assert ruze_efficiency(0.0, 86e9) == 1.0


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda n, w: fit_maps(n, -1.0, w), "focal length must be a positive"),
        (lambda n, w: fit_maps(n[:, :2], F, w), r"\(N, 3\) array"),
        (lambda n, w: fit_maps(n, F, w[:-1]), "weights have shape"),
        (lambda n, w: fit_maps(n, F, -w), "weights must be finite, ≥ 0"),
        (lambda n, w: fit_maps(n[:5], F, w[:5]), "do not fix the best-fit"),
        (lambda n, w: best_fit(n, np.full(n.shape, np.nan), F, w), "finite"),
        (lambda n, w: ruze_efficiency(-1e-6, 1e9), "RMS surface error must be ≥ 0"),
        (lambda n, w: ruze_efficiency(1e-6, 0.0), "frequency must be a positive"),
    ],
)
def test_bad_input_is_refused(call, message):
    nodes, weights = dish(rings=2, per_ring=6)
    with pytest.raises(Rt70Error, match=message):
        call(nodes, weights)


def test_the_parametric_dish_is_a_stable_truss_with_its_mass_and_aperture():
    from rt70.fe.modes import lowest_modes
    from rt70.fe.reflector import paraboloid_dish

    dish_ = paraboloid_dish(70.0, F, hub_radius=5.0, depth=3.0, EA=2e8, rho_A=20.0,
                            panel_mass=15.0, rings=4, ribs=12)  # fmt: skip
    fe = dish_.fe
    front = fe.node_xyz[dish_.surface]
    assert_close(front[:, 2], surface_height(front[:, 0], front[:, 1], F), rel=1e-15)
    assert_close(dish_.weights.sum(), np.pi * (35.0**2 - 5.0**2), rel=1e-13)
    i, j = sp.triu(fe.K, k=1).nonzero()  # the node pairs K couples are the bars
    pairs = np.unique(np.sort(np.column_stack([i // 3, j // 3]), axis=1), axis=0)
    bars = [(a, b) for a, b in pairs if a != b]
    length = sum(np.linalg.norm(fe.node_xyz[a] - fe.node_xyz[b]) for a, b in bars)
    assert_close(fe.M.diagonal().sum() / 3.0, 20.0 * length + 15.0 * dish_.weights.sum(),
                 rel=1e-12)  # fmt: skip
    free = lowest_modes(fe.M, fe.K, 8)
    assert int(free.rigid.sum()) == 6 and free.freq_hz[6] > 0.1  # no mechanism
    assert sorted(fe.interfaces.values()) == sorted(dish_.hub) and len(dish_.hub) == 24


def test_the_dish_sagging_at_zenith_is_mostly_a_paraboloid():
    """Gravity along the axis bends a radial-rib dish symmetrically: the best fit takes
    most of it as a focal change and a vertex shift along the axis, none sideways."""
    import scipy.sparse.linalg as spla

    from rt70.fe.reflector import paraboloid_dish

    d = paraboloid_dish(70.0, F, 5.0, 3.0, 2e8, 20.0, 15.0, rings=4, ribs=12)
    fe = d.fe
    held = np.concatenate([fe.dofs_of(n) for n in d.hub])
    free = np.setdiff1d(np.arange(fe.n_dofs), held)
    load = np.zeros(fe.n_dofs)
    load[2::3] = -9.81 * fe.M.diagonal()[2::3]
    u = np.zeros(fe.n_dofs)
    u[free] = spla.spsolve(sp.csc_array(fe.K)[free][:, free], load[free])
    nodes, delta = fe.node_xyz[d.surface], u.reshape(-1, 3)[d.surface]
    fit = best_fit(nodes, delta, F, d.weights)
    h = half_path_errors(nodes, delta, F)
    raw = np.sqrt(np.sum(d.weights * h**2) / d.weights.sum())
    assert fit.rms < 0.5 * raw
    assert fit.focal_change > 0.0 and fit.vertex_shift[2] < 0.0
    assert np.abs(fit.parameters[[0, 1, 3, 4]]).max() <= 1e-9 * np.abs(fit.parameters).max()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"diameter": -70.0}, "diameter must be a positive"),
        ({"hub_radius": 40.0}, "hub_radius must be between 0 and D/2"),
        ({"panel_mass": -1.0}, "panel_mass must be ≥ 0"),
        ({"ribs": 2}, "at least 1 ring and 3 ribs"),
    ],
)
def test_a_wrong_dish_is_refused(change, message):
    from rt70.fe.reflector import paraboloid_dish

    args = {"diameter": 70.0, "focal_length": F, "hub_radius": 5.0, "depth": 3.0,
            "EA": 2e8, "rho_A": 20.0, "panel_mass": 15.0} | change  # fmt: skip
    with pytest.raises(Rt70Error, match=message):
        paraboloid_dish(**args)
