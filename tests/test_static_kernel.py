"""The compiled static forces (rt70.textbook.static_kernel) equal the textbook side's readable
form, and the large-model path of rt70.linear.linearize built on them gives the standard path's
equilibrium, linear model and modes on a chain Pinocchio can hold.

No timing is asserted (``rt70 bench large`` measures it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70.crosscheck.robots import load_robot
from rt70.errors import SingularConfigurationError
from rt70.linear import compiled, modal
from rt70.linear import linearize as lin
from rt70.linear.damped import damped_modes
from rt70.linear.damped_lowest import lowest_damped_modes
from rt70.model.scene import load_scene, scene_from_text, scene_names
from rt70.scenes.synthetic import elastic_chain, random_tree
from rt70.testing import assert_close
from rt70.textbook import dynamics, static_kernel

ALL_TYPES = Path(__file__).parent / "data" / "all_joint_types.urdf"


def _scenes():
    return [*scene_names(), str(ALL_TYPES)]


def _check_against_textbook(scene, seed=3, spread=0.05):
    """Static force, gravity, K, K_g and D of the kernel against the textbook side at a random q."""
    m = scene.textbook
    data = static_kernel.StaticData.of(m)
    q = spread * np.random.default_rng(seed).standard_normal(m.nv)
    # a sum of spring terms much larger than their result (the RT-70's preloads):
    # compared on the terms' scale, the largest |C δ| times its lever
    Q = lin.static_force(scene, q, side="textbook")
    weight = float(np.sum(np.reshape(m.Theta, (m.nb, 6, 6))[:, 0, 0])) * np.linalg.norm(m.gravity)
    terms = max(  # gravity's terms are a weight times a lever arm: at least the weight × 1 m
        np.abs(Q).max(), np.abs(dynamics.gravity_force(m, scene.textbook_data, q)).max(), weight
    )
    assert_close(static_kernel.static_force(m, data, q), Q, rel=1e-12, scale=terms)
    assert_close(
        static_kernel.static_force(m, data, q, springs=False),
        dynamics.gravity_force(m, scene.textbook_data, q),
        rel=1e-13,
        scale=terms,
    )
    K, K_g = static_kernel.stiffness_matrices(m, data, q)
    K_book = lin.stiffness_matrix(scene, q, side="textbook")
    # both central differences with h = 1e-6 round to ε·terms/h ≈ 2e-10 of the terms (per m)
    k_scale = max(np.abs(K_book).max(), terms / 1.0)
    assert_close(K, K_book, rel=1e-8, scale=k_scale, what="K")
    K_g_book = lin._gravity_stiffness(scene, q, side="textbook")
    assert_close(K_g, K_g_book, rel=1e-8, scale=k_scale, what="K_g")
    _, D = static_kernel.element_gains(m, data, q)
    assert_close(D, lin.damping_matrix(scene, q), rel=1e-13, scale=max(np.abs(D).max(), 1.0))


@pytest.mark.parametrize("target", _scenes(), ids=lambda t: Path(t).stem)
def test_kernel_equals_the_textbook_on_scenes(target):
    scene = load_scene(target)
    m = scene.textbook
    if m.modal or m.G is not None:  # not covered: None, and the standard path is kept
        assert static_kernel.StaticData.of(m) is None
        assert scene.static_kernels is None
        return
    _check_against_textbook(scene)


@pytest.mark.parametrize("seed", range(6))
def test_kernel_equals_the_textbook_on_random_trees(seed):
    """Bushings across branches (paths on both sides of the common ancestor), joint springs."""
    scene = scene_from_text(random_tree(seed, n_bodies=7), f"random_tree({seed})")
    if scene.textbook.G is not None:
        pytest.fail("random_tree writes no mimic joints")
    _check_against_textbook(scene, seed=seed, spread=0.3)


def test_robot_with_mimic_joints_is_not_covered():
    assert static_kernel.StaticData.of(load_robot("panda").textbook) is None


def test_hanging_chain_against_the_textbook():
    _check_against_textbook(scene_from_text(elastic_chain(4, seed=2, hanging=True), "chain4"))


def test_gimbal_lock_names_the_bushing():
    scene = scene_from_text(elastic_chain(2, seed=1), "chain2")
    m = scene.textbook
    q = np.zeros(m.nv)
    q[m.coordinate_names.index("body2_ry")] = np.pi / 2  # θ of the direct pair's angles
    with pytest.raises(SingularConfigurationError, match="bushing 'body1_body2'"):
        static_kernel.static_force(m, scene.static_kernels, q)


@pytest.fixture(scope="module")
def chain20():
    """A hanging chain of 20 bodies (120 coordinates): the large path forced below its size."""
    return scene_from_text(elastic_chain(20, seed=4, hanging=True), "chain20")


def test_large_path_equals_the_standard_path(chain20, monkeypatch):
    """Equilibrium, M, K, D and the modes of the compiled path against Pinocchio's (the standard
    path differences the reference side's forces)."""
    scene = chain20
    assert compiled.kernels_for(scene) is None  # 120 < LARGE_NV
    q0 = lin.equilibrium(scene)
    standard = lin.linearize(scene, q0)
    monkeypatch.setattr(compiled, "LARGE_NV", 1)
    assert compiled.kernels_for(scene) is not None
    q_large = lin.equilibrium(scene)
    # both solve the textbook's static force to tol 1e-10 of its scale: the positions agree
    # to the compliance times that residual (measured 2e-12 m or rad)
    assert_close(q_large, q0, rel=1e-9, scale=max(np.abs(q0).max(), 1.0))
    large = lin.linearize(scene, q0)
    assert_close(large.M, standard.M, rel=1e-13)
    for name in ("K", "K_gravity"):  # central differences of two sides: ~1e-10 each
        assert_close(getattr(large, name), getattr(standard, name), rel=1e-8, what=name,
                     scale=np.abs(standard.K).max())  # fmt: skip
    assert_close(large.D, standard.D, rel=1e-13)
    a, b = modal.modes(standard.M, standard.K), modal.modes(large.M, large.K)
    assert_close(b.freq_hz, a.freq_hz, rel=1e-7)


def test_lowest_damped_modes_equal_the_dense_ones(chain20):
    """ARPACK's shift-invert eigenvalues are the dense eig's nearest zero, to rounding."""
    scene = chain20
    lm = lin.linearize(scene, lin.equilibrium(scene))
    dense = damped_modes(lm.M, lm.K, lm.D)
    undamped = modal.modes(lm.M, lm.K)
    some = lowest_damped_modes(lm.M, lm.K, lm.D, 10, float(undamped.omega[0]))
    assert some.eigenvalues.size == 20
    assert_close(some.oscillatory, dense.oscillatory[: some.oscillatory.size], rel=1e-9)
    assert some.oscillatory.size == 10 and some.real.size == 0


def test_large_path_is_not_taken_with_loops_or_small_models():
    assert compiled.kernels_for(load_scene("four_bar")) is None
    assert compiled.kernels_for(load_scene("rt70")) is None  # 42 coordinates


def test_large_path_with_held_and_locked_coordinates(chain20, monkeypatch):
    """Held coordinates (a drive holding an axis) and locked ones take the same way."""
    scene, held = chain20, {"body1_rz": 0.1, "body3_x": -0.01}
    q0 = lin.equilibrium(scene, held)
    standard = lin.linearize(scene, q0, locked=tuple(held))
    monkeypatch.setattr(compiled, "LARGE_NV", 1)
    q_large = lin.equilibrium(scene, held)
    assert q_large[scene.textbook.coordinate_names.index("body1_rz")] == 0.1
    assert_close(q_large, q0, rel=1e-9, scale=max(np.abs(q0).max(), 1.0))
    large = lin.linearize(scene, q0, locked=tuple(held))
    assert large.coordinates == standard.coordinates and len(large.coordinates) == 118
    assert_close(large.K, standard.K, rel=1e-8)
    assert_close(large.M, standard.M, rel=1e-13)
