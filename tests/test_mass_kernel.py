"""The compiled mass matrix equals the structured numpy form and the dense book form.

Every scene in urdf/ and the robots ur5, panda (mimic fingers) and talos_full (mimic
grippers, 44 bodies), at random configurations; plus the all-joint-types test URDF
(euler6, revolute, prismatic, planar pairs). No timing is asserted (``rt70 bench``
measures it).
"""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rt70.crosscheck.robots import load_robot
from rt70.errors import NonFiniteError, Rt70Error, ShapeError
from rt70.model.scene import load_scene, scene_names
from rt70.testing import assert_close
from rt70.textbook import dynamics, mass_kernel, structured

ALL_TYPES = Path(__file__).parent / "data" / "all_joint_types.urdf"
SCENES = [*scene_names(), str(ALL_TYPES)]
ROBOTS = ["ur5", "panda", "talos_full"]


def _check(scene, K=5, seed=7):
    m = scene.textbook
    Q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (K, m.nv))
    A_kernel = mass_kernel.mass_matrix_batch(m, mass_kernel.KernelData(m, K), Q).copy()
    A_numpy = structured.mass_matrix_batch(m, structured.BatchData(m, K), Q)
    assert A_kernel.shape == (K, m.nv, m.nv)
    # symmetric by construction: one value written to both triangles
    assert np.array_equal(A_kernel, np.swapaxes(A_kernel, 1, 2))
    one = mass_kernel.KernelData(m, 1)
    for k in range(K):
        assert_close(A_kernel[k], A_numpy[k], rel=1e-13)
        assert_close(A_kernel[k], dynamics.mass_matrix(m, scene.textbook_data, Q[k]), rel=1e-13)
        # the same compiled kernel on the same configuration: bit for bit
        assert np.array_equal(mass_kernel.mass_matrix(m, one, Q[k]), A_kernel[k])


@pytest.mark.parametrize("target", SCENES, ids=lambda t: Path(t).stem)
def test_kernel_equals_structured_and_dense_on_scenes(target):
    scene = load_scene(target)
    if scene.textbook.modal:  # rigid pairs only: the kernel refuses, naming the model
        with pytest.raises(Rt70Error, match="compiled mass kernel has no modal bodies"):
            mass_kernel.KernelModel.of(scene.textbook)
        return
    _check(scene)


@pytest.mark.parametrize("name", ROBOTS)
def test_kernel_equals_structured_and_dense_on_robots(name):
    scene = load_robot(name)
    _check(scene, K=3)
    if name != "ur5":  # the mimic reduction Gᵀ A_full G inside the kernel is exercised
        assert scene.textbook.G is not None


def test_kernel_model_arrays():
    m = load_robot("panda").textbook
    arrays = mass_kernel.KernelModel.of(m)
    G = np.zeros((m.n_full, m.nv))
    for a in range(m.n_full):
        for i in range(arrays.g_ptr[a], arrays.g_ptr[a + 1]):
            G[a, arrays.g_col[i]] = arrays.g_val[i]
    assert np.array_equal(G, m.G)  # the compressed rows are G
    assert [mass_kernel.KIND_CODE[k] for k in m.kind] == list(arrays.kind)


def test_bad_input_is_refused_with_its_name():
    m = load_scene("double_pendulum").textbook
    data = mass_kernel.KernelData(m, 2)
    with pytest.raises(ShapeError, match="Q: expected shape"):
        mass_kernel.mass_matrix_batch(m, data, np.zeros((2, m.nv + 1)))
    with pytest.raises(NonFiniteError, match="Q contains NaN"):
        mass_kernel.mass_matrix_batch(m, data, np.full((2, m.nv), np.nan))
    with pytest.raises(ShapeError, match="made for K = 2"):
        mass_kernel.mass_matrix_batch(m, data, np.zeros((3, m.nv)))
    with pytest.raises(ShapeError, match="KernelData of this model"):
        other = load_scene("three_masses").textbook
        mass_kernel.mass_matrix(other, data, np.zeros(other.nv))
    with pytest.raises(ShapeError, match="q"):
        mass_kernel.mass_matrix(m, mass_kernel.KernelData(m), np.zeros(m.nv + 1))
    with pytest.raises(NonFiniteError):
        mass_kernel.mass_matrix(m, mass_kernel.KernelData(m), np.array([np.inf] * m.nv))


@pytest.mark.slow
def test_a_second_process_loads_the_kernel_from_the_cache():
    """``cache=True``: after a first call has compiled it, another process pays no compiling."""
    code = (
        "import numpy as np\n"
        "from rt70.model.scene import load_scene\n"
        "from rt70.textbook import mass_kernel as k\n"
        "m = load_scene('double_pendulum').textbook\n"
        "k.mass_matrix(m, k.KernelData(m), np.zeros(m.nv))\n"
        "s = k._mass_matrix_many.stats\n"
        "print(sum(s.cache_hits.values()), sum(s.cache_misses.values()))\n"
    )
    for _ in range(2):  # the first run compiles if nothing is cached yet
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True
        ).stdout
    hits, misses = map(int, out.split())
    assert (hits, misses) == (1, 0)
