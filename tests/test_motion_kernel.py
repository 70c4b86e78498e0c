"""The compiled equations of motion (rt70.textbook.motion_kernel) equal the textbook side's
readable form and Pinocchio's, on every scene it covers and on random trees.

The residual ``A q̈ + B q̇ − Q_g − Q_c − Q_d`` against the structured algorithm's A, B and
the textbook's forces, and against Pinocchio's RNEA; the energies against the textbook's;
the articulated solve of ``(A + X) x = r`` against the dense matrix. No timing is asserted.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70.model.scene import load_scene, scene_from_text, scene_names
from rt70.scenes.synthetic import elastic_chain, random_tree
from rt70.testing import assert_close
from rt70.textbook import (
    articulated_kernel,
    dynamics,
    forces,
    mass_kernel,
    motion_kernel,
    structured,
)

ALL_TYPES = Path(__file__).parent / "data" / "all_joint_types.urdf"


def _state(n, seed, spread):
    rng = np.random.default_rng(seed)
    return spread * rng.standard_normal(n), rng.standard_normal(n), rng.standard_normal(n)


def _dense(model, blocks):
    X = np.zeros((model.nv, model.nv))
    for j in range(model.nb):
        s, d = model.q_start[j], model.ndof[j]
        X[s : s + d, s : s + d] = blocks[j, :d, :d]
    return X


def _check(scene, seed=2, spread=0.1):
    m = scene.textbook
    data = motion_kernel.MotionData.of(m)
    q, v, a = _state(m.nv, seed, spread)
    r, (T, U_g_kernel, U_c, P_d) = motion_kernel.residual(m, data, q, v, a)
    A = mass_kernel.mass_matrix(m, mass_kernel.KernelData(m), q)
    B = structured.bias_force(m, structured.BatchData(m, 1), q, v)
    Qc, Qd = forces.spring_damper_force(m, scene.textbook_data, q, v)
    Qg = dynamics.gravity_force(m, scene.textbook_data, q)
    terms = (A @ a, B, Qg, Qc, Qd)
    scale = max(np.abs(t).max() for t in terms)  # the largest of the summed terms
    assert_close(r, A @ a + B - Qg - Qc - Qd, rel=1e-12, scale=scale, what="residual")
    kinetic = 0.5 * v @ A @ v
    assert_close(T, kinetic, rel=1e-12, scale=kinetic, what="T")
    U_book = forces.spring_potential(m, scene.textbook_data, q)
    assert_close(U_c, U_book, rel=1e-12, scale=max(abs(U_book), 1e-300), what="U_c")
    assert_close(P_d, -v @ Qd, rel=1e-12, scale=max(abs(v @ Qd), 1e-300), what="P_d")
    U_g = dynamics.gravity_potential(m, scene.textbook_data, q)
    weight = float(np.sum(np.reshape(m.Theta, (m.nb, 6, 6))[:, 0, 0])) * np.linalg.norm(m.gravity)
    assert_close(U_g_kernel, U_g, rel=1e-12,
                 scale=max(abs(U_g), weight), what="U_g")  # fmt: skip
    K_loc, D_loc = motion_kernel.pair_gains(m, data, q)
    blocks = 0.3 * K_loc + 0.7 * D_loc
    X = _dense(m, blocks)
    if data.local:  # every bushing on one pair: the blocks are all of Σ JᵀCJ and Σ JᵀDJ
        from rt70.textbook.static_kernel import element_gains

        Kc, Dc = element_gains(m, scene.static_kernels, q)
        g_scale = max(np.abs(Kc).max(), np.abs(Dc).max(), 1e-300)
        assert_close(X, 0.3 * Kc + 0.7 * Dc, rel=1e-13, scale=g_scale, what="pair gains")
    articulated_kernel.articulated_factor(m, data, q, blocks)
    x = articulated_kernel.articulated_solve(m, data, r)
    S = A + X
    # a solve's residual is ε times ‖S‖ ‖x‖ (backward stability), not ε ‖r‖
    assert_close(S @ x, r, rel=1e-12, scale=np.abs(S).max() * np.abs(x).max(), what="solve")


@pytest.mark.parametrize("target", [*scene_names(), str(ALL_TYPES)], ids=lambda t: Path(t).stem)
def test_kernel_equals_the_textbook_on_scenes(target):
    scene = load_scene(target)
    if scene.static_kernels is None:  # modal bodies or mimic joints: no kernel
        assert motion_kernel.MotionData.of(scene.textbook) is None
        return
    _check(scene)


@pytest.mark.parametrize("seed", range(6))
def test_kernel_equals_the_textbook_on_random_trees(seed):
    """Every pair kind, bushings across branches, joint springs; at large angles."""
    scene = scene_from_text(random_tree(seed, n_bodies=7), f"random_tree({seed})")
    _check(scene, seed=seed, spread=0.5)


def test_kernel_equals_pinocchio_rnea():
    """τ = A q̈ + B q̇ − Q_g on a hanging chain, against Pinocchio's RNEA (springs off)."""
    import pinocchio as pin

    scene = scene_from_text(elastic_chain(8, hanging=True), "chain")
    m, ref = scene.textbook, scene.reference
    assert ref.identity_map
    data = motion_kernel.MotionData.of(m)
    q, v, a = _state(m.nv, 5, 0.2)
    r = motion_kernel.residual(m, data, q, v, a)[0]
    Qc, Qd = forces.spring_damper_force(m, scene.textbook_data, q, v)
    tau = pin.rnea(ref.pin_model, scene.reference_data.pin_data, q, v, a)
    assert_close(r + Qc + Qd, tau, rel=1e-12, scale=np.abs(tau).max(), what="RNEA")


def test_a_singular_pair_is_refused():
    scene = scene_from_text(elastic_chain(2), "chain")
    m = scene.textbook
    data = motion_kernel.MotionData.of(m)
    X = np.zeros((m.nb, 6, 6))
    X[0] = -1e12 * np.eye(6)  # A + X not positive definite on pair 0
    with pytest.raises(Exception, match="singular"):
        articulated_kernel.articulated_factor(m, data, np.zeros(m.nv), X)
