"""Finite-element models (rt70.fe): the neutral file, bar assembly and sparse modes.

Independent answers: the textbook bar element; the closed-form modes of a fixed–free
chain of bars (lumped masses, the end node half); the dense generalised eigensolver
(:func:`rt70.linear.modal.modes`) on a space frame small enough for it.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rt70.fe import neutral
from rt70.fe.modes import lowest_modes
from rt70.fe.neutral import FEModel, FEModelError
from rt70.fe.ordering import dof_block_size, nested_dissection
from rt70.fe.truss import assemble, bar_matrices, space_frame
from rt70.linear import modal
from rt70.testing import assert_close


def test_the_bar_element_is_the_textbook_one():
    """Along x: EA/L on the axial DOFs only; mass ρAL/2 on each end's translations."""
    K, M = bar_matrices([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], EA=4.0, rho_A=3.0)
    expected = np.zeros((6, 6))
    expected[np.ix_([0, 3], [0, 3])] = 2.0 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    assert np.array_equal(K, expected)
    assert np.array_equal(M, 3.0 * np.eye(6))
    # inclined: the same element turned, K = Tᵀ K_local T
    K_inclined, _ = bar_matrices([0.0, 0.0, 0.0], [0.0, 1.2, 1.6], EA=4.0, rho_A=3.0)
    n = np.array([0.0, 0.6, 0.8])
    u = np.concatenate([n, np.zeros(3)])  # stretch along the bar: force EA/L on each end
    assert_close(K_inclined @ u, 2.0 * np.concatenate([n, -n]), rel=1e-15)


def test_a_free_space_frame_has_six_rigid_modes_and_no_mechanism():
    frame = space_frame(4, 3)
    K = frame.K.toarray()
    x, y, z = frame.node_xyz.T
    rigid = []
    for axis in np.eye(3):  # translations and small rotations
        rigid.append(np.tile(axis, x.size))
        rigid.append(np.cross(axis, frame.node_xyz).ravel())
    R = np.array(rigid).T
    assert_close(K @ R, np.zeros_like(R), rel=1e-15, scale=np.abs(K).max())
    eig = np.linalg.eigvalsh(K)
    assert np.sum(eig < 1e-9 * eig[-1]) == 6


def test_sparse_modes_equal_the_dense_solvers_on_a_space_frame():
    frame = space_frame(10, 8)  # 480 DOF, free: six rigid modes
    sparse = lowest_modes(frame.M, frame.K, 20)
    dense = modal.modes(frame.M.toarray(), frame.K.toarray())
    assert sparse.rigid.sum() == 6 and dense.rigid.sum() == 6
    # frequencies: measured 1.4e-14 of the largest apart
    top = dense.freq_hz[19]
    assert_close(sparse.freq_hz, dense.freq_hz[:20], rel=1e-12, scale=top)
    assert np.all(sparse.residual < 1e-8)  # the vectors: measured 2.4e-11
    Vt_M_V = sparse.shapes.T @ (frame.M @ sparse.shapes)
    assert_close(Vt_M_V, np.eye(20), rel=1e-12)


def test_sparse_modes_of_a_fixed_free_chain_have_the_closed_form():
    """N equal bars along x, node 0 held, axial DOFs only: lumped masses m (the free end
    m/2) and springs k give ω_j² = (4k/m) sin²((2j − 1)π / 4N) exactly."""
    N, L, EA, rho_A = 3000, 0.5, 2e8, 20.0
    xyz = np.column_stack([np.arange(N + 1) * L, np.zeros(N + 1), np.zeros(N + 1)])
    bars = np.column_stack([np.arange(N), np.arange(1, N + 1)])
    M, K = assemble(xyz, bars, EA, rho_A)
    axial = 3 * np.arange(1, N + 1)  # x of nodes 1…N
    M, K = M[axial][:, axial], K[axial][:, axial]
    modes = lowest_modes(M, K, 8)
    j = np.arange(1, 9)
    k, m = EA / L, rho_A * L
    exact = 4.0 * k / m * np.sin((2 * j - 1) * np.pi / (4 * N)) ** 2
    assert not modes.rigid.any()
    assert_close(modes.omega2, exact, rel=1e-10)


def test_the_neutral_file_keeps_everything(tmp_path):
    frame = space_frame(5, 4)
    path = neutral.write(frame, tmp_path / "frame.npz")
    back = neutral.read(path)
    assert (back.M != frame.M).nnz == 0 and (back.K != frame.K).nnz == 0
    for attr in ("node_ids", "node_xyz", "dof_node", "dof_comp"):
        assert np.array_equal(getattr(back, attr), getattr(frame, attr)), attr
    assert back.interfaces == frame.interfaces and len(back.interfaces) == 4
    assert back.dof_labels()[:2] == ["node 1 x", "node 1 y"]
    assert back.dofs_of(2).tolist() == [3, 4, 5]


def _model(**changes) -> dict:
    frame = space_frame(3, 2)
    fields = dict(
        M=frame.M, K=frame.K, node_ids=frame.node_ids, node_xyz=frame.node_xyz,
        dof_node=frame.dof_node, dof_comp=frame.dof_comp, interfaces=dict(frame.interfaces),
        name="bad.npz",
    )  # fmt: skip
    fields.update(changes)
    return fields


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"K": "asymmetric"}, "bad.npz: K is not symmetric: entries (0, 3) and (3, 0)"),
        ({"dof_comp": "seven"}, "bad.npz: component 7 (components are 0 to 6)"),
        ({"dof_node": "unknown"}, "bad.npz: DOFs on node 999, which is not in the table"),
        ({"dof_comp": "twice"}, "bad.npz: a node's component is listed twice"),
        ({"interfaces": {"hub": 999}}, "bad.npz: interface 'hub' is node 999, not in the"),
        ({"M": "negative"}, "bad.npz: M has a negative diagonal entry (row 1)"),
    ],
)
def test_an_inconsistent_model_is_refused_naming_the_fault(changes, message):
    fields = _model()
    key, how = next(iter(changes.items()))
    if how == "asymmetric":
        K = fields["K"].toarray()
        K[0, 3] += 1.0
        fields["K"] = sp.csr_array(K)
    elif how == "seven":
        fields["dof_comp"] = fields["dof_comp"].copy()
        fields["dof_comp"][4] = 7
    elif how == "unknown":
        fields["dof_node"] = fields["dof_node"].copy()
        fields["dof_node"][-1] = 999
    elif how == "twice":
        fields["dof_comp"] = fields["dof_comp"].copy()
        fields["dof_comp"][1] = 1
    elif how == "negative":
        M = fields["M"].toarray()
        M[1, 1] = -1.0
        fields["M"] = sp.csr_array(M)
    else:
        fields[key] = how
    with pytest.raises(FEModelError) as info:
        FEModel(**fields)
    assert message in str(info.value)


def test_a_file_that_is_not_the_neutral_format_is_refused(tmp_path):
    with pytest.raises(FEModelError, match="no such file"):
        neutral.read(tmp_path / "missing.npz")
    other = tmp_path / "other.npz"
    np.savez(other, format=np.array("something/2"))
    with pytest.raises(FEModelError, match="format 'something/2', expected 'rt70-fe/1'"):
        neutral.read(other)
    partial = tmp_path / "partial.npz"
    np.savez(partial, format=np.array(neutral.FORMAT))
    with pytest.raises(FEModelError, match="partial.npz: missing entry 'M_data'"):
        neutral.read(partial)


def test_the_nested_dissection_order_keeps_nodes_and_cuts_the_fill():
    frame = space_frame(12, 12)
    A = sp.csc_array(frame.K + frame.M)
    assert dof_block_size(A) == 3
    p = nested_dissection(A)
    assert np.array_equal(np.sort(p), np.arange(A.shape[0]))
    assert np.all(p.reshape(-1, 3) % 3 == [0, 1, 2])  # a node's three DOFs stay together
    fill = {}
    for name, order in (("natural", np.arange(A.shape[0])), ("nested", p)):
        lu = spla.splu(sp.csc_array(A[order][:, order]), permc_spec="NATURAL",
                       diag_pivot_thresh=0.0, options={"SymmetricMode": True})  # fmt: skip
        fill[name] = lu.L.nnz + lu.U.nnz
    assert fill["nested"] < 0.8 * fill["natural"]
    assert dof_block_size(sp.eye_array(7).tocsc()) == 1
    assert np.array_equal(nested_dissection(sp.eye_array(6).tocsc()), np.arange(6))
