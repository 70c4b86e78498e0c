"""The structure-exploiting, batched algorithm equals the dense textbook form."""

from pathlib import Path

import numpy as np
import pytest

from rt70.model.scene import load_scene
from rt70.reference import weight_moment
from rt70.testing import assert_close
from rt70.textbook import dynamics, structured

ALL_TYPES = Path(__file__).parent / "data" / "all_joint_types.urdf"
TARGETS = ["rt70", "two_body_gravity", "double_pendulum", "three_masses", str(ALL_TYPES)]


@pytest.mark.parametrize("target", TARGETS, ids=lambda t: Path(t).stem)
def test_structured_equals_dense(target):
    scene = load_scene(target)
    m, d = scene.textbook, scene.textbook_data
    rng = np.random.default_rng(4)
    Q, Qd = rng.uniform(-0.5, 0.5, (4, m.nv)), rng.uniform(-1, 1, (4, m.nv))
    data = structured.BatchData(m, 4)
    A_batch = structured.mass_matrix_batch(m, data, Q).copy()
    b_batch = structured.bias_force_batch(m, data, Q, Qd)
    g_batch = structured.gravity_force_batch(m, data, Q)
    assert A_batch.shape == (4, m.nv, m.nv)
    for k in range(4):
        A = dynamics.mass_matrix(m, d, Q[k])
        assert_close(A_batch[k], A, rel=1e-13, what="A")
        # bias and gravity on the size of their terms (rt70.crosscheck.scales.natural_scales): the
        # velocity products ‖A‖ ‖q̇‖², the weights' moment G₀
        b = dynamics.bias_force(m, d, Q[k], Qd[k])
        b_scale = np.abs(A).max() * np.abs(Qd[k]).max() ** 2 + np.abs(b).max()
        assert_close(b_batch[k], b, rel=1e-12, scale=b_scale, what="B q̇")
        g = dynamics.gravity_force(m, d, Q[k])
        g_scale = weight_moment(scene.reference, scene.reference_data, Q[k]) + np.abs(g).max()
        assert_close(g_batch[k], g, rel=1e-13, scale=g_scale, what="S G")
        # the same kernel on a batch of one: bit for bit
        assert np.array_equal(structured.mass_matrix(m, structured.BatchData(m), Q[k]), A_batch[k])


def test_data_of_another_model_or_size_is_refused():
    from rt70.errors import ShapeError

    m = load_scene("double_pendulum").textbook
    other = load_scene("three_masses").textbook
    with pytest.raises(ShapeError, match="K = 1"):
        structured.mass_matrix_batch(m, structured.BatchData(m, 1), np.zeros((3, m.nv)))
    with pytest.raises(ShapeError, match="BatchData of this model"):
        structured.mass_matrix(m, structured.BatchData(other), np.zeros(m.nv))


def test_all_joint_types_scene_agrees_with_pinocchio():
    from rt70.crosscheck.validate import cross_check

    for r in cross_check(load_scene(ALL_TYPES), samples=3, seed=1, repeat=1):
        # relative to the natural scale already: its scale is 1
        assert_close(r.max_rel_err, 0.0, rel=1e-10, scale=1.0, what=r.quantity)


def test_model_is_constant_after_build():
    """Model constant, Data the work buffers: no algorithm may write into the Model."""
    import dataclasses

    scene = load_scene("double_pendulum")
    m = scene.textbook
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.G = None
    before = {k: np.copy(v) for k, v in vars(m).items() if isinstance(v, np.ndarray)}
    data = structured.BatchData(m, 3)
    structured.mass_matrix_batch(m, data, np.zeros((3, m.nv)))
    dynamics.forward_dynamics(m, scene.textbook_data, np.ones(m.nv), np.ones(m.nv), np.zeros(m.nv))
    assert "_topology" not in vars(m)
    for k, v in before.items():
        assert np.array_equal(getattr(m, k), v), k
