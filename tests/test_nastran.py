"""Nastran files in (rt70.fe.nastran), on a superelement MSC Nastran wrote.

``tests/data/nastran/se_test_n11.{op4,pch}`` (README there): an external Craig–Bampton
superelement of 11 boundary grids and 39 modal scalar points. What its matrices must
satisfy if they are read right — symmetry, the Craig–Bampton blocks (a unit modal mass,
a diagonal modal stiffness, no stiffness between boundary and modes), the six rigid-body
motions in the stiffness's null space and one total mass in every direction — holds only
with every row, string, field and coordinate system where it belongs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70.errors import Rt70Warning
from rt70.fe import neutral
from rt70.fe.modes import lowest_modes
from rt70.fe.nastran import read_bulk, read_op4, read_superelement
from rt70.fe.neutral import FEModelError
from rt70.testing import assert_close

DATA = Path(__file__).parent / "data" / "nastran"
OP4, PCH = DATA / "se_test_n11.op4", DATA / "se_test_n11.pch"
N_BOUNDARY, N_MODES = 66, 39


@pytest.fixture(scope="module")
def matrices():
    return read_op4(OP4)


@pytest.fixture(scope="module")
def superelement():
    with pytest.warns(Rt70Warning, match="15 DOFs have neither mass nor stiffness"):
        return read_superelement(OP4, PCH)


def test_the_op4_matrices(matrices):
    assert matrices["KAA"].shape == matrices["MAA"].shape == (105, 105)
    assert matrices["VA"].shape == (105, 1) and matrices["MUG1"].shape == (66, 105)
    for name in ("KAA", "MAA"):
        X = matrices[name].toarray()
        assert_close(X, X.T, rel=1e-14, scale=np.abs(X).max(), what=name)


def test_the_craig_bampton_blocks(matrices):
    K, M = matrices["KAA"].toarray(), matrices["MAA"].toarray()
    b, q = slice(0, N_BOUNDARY), slice(N_BOUNDARY, None)
    assert_close(M[q, q], np.eye(N_MODES), rel=1e-14, scale=1.0)
    assert not K[b, q].any()
    omega2 = np.diag(K[q, q])
    # Nastran's own numerical noise off the diagonal: 7e-12 of the largest ω²
    assert_close(K[q, q], np.diag(omega2), rel=1e-10, scale=omega2.max())
    assert np.all(np.diff(omega2) > 0.0) and omega2[0] > 0.0
    assert_close(np.sqrt(omega2[0]) / (2 * np.pi), 365.2596, rel=1e-6)


def test_dense_sparse_and_bigmat_files_hold_the_same_matrices():
    """Nastran wrote one DMAP's nine matrices dense, sparse and BIGMAT (README there)."""
    files = [read_op4(DATA / f"mat_t_{form}.op4") for form in ("dn", "s1", "s2")]
    assert list(files[0]) == list(files[1]) == list(files[2])
    assert len(files[0]) == 9
    for name in files[0]:
        dense = files[0][name].toarray()
        for other in files[1:]:
            assert np.array_equal(other[name].toarray(), dense), name
    m = {name: matrix.toarray() for name, matrix in files[2].items()}
    assert np.array_equal(m["EYE10"], np.eye(10)) and not m["NULL"].any()
    # the deck's ADD with α = −1 + i: EYE5CD = α I, RND1Cx = α RND1Rx (single, double)
    alpha = complex(-1.0, 1.0)
    assert np.array_equal(m["EYE5CD"], alpha * np.eye(5))
    assert_close(m["RND1CS"], alpha * m["RND1RS"], rel=1e-6, scale=np.abs(m["RND1RS"]).max())
    assert_close(m["RND1CD"], alpha * m["RND1RD"], rel=1e-15, scale=np.abs(m["RND1RD"]).max())


def test_the_bulk_cards():
    bulk = read_bulk(PCH)
    assert sorted(bulk.systems) == [20110001, 20110002, 20110003]
    assert len(bulk.grids) == 11 and len(bulk.spoints) == N_MODES
    assert bulk.grids[20110038][1][1] == pytest.approx(7.271236428543e-4)  # "7.27…-4"
    assert bulk.grids[20110031][2] == 0 and bulk.grids[20110010][2] == 20110003
    assert sum(len(c) for c in bulk.aset.values()) == 105


def rigid_motions(fe) -> np.ndarray:
    """The six rigid-body motions (translations, rotations about the origin) of the rows."""
    index = {n: i for i, n in enumerate(fe.node_ids)}
    R = np.zeros((fe.n_dofs, 6))
    for r, (node, comp) in enumerate(zip(fe.dof_node, fe.dof_comp, strict=True)):
        if comp == 0:
            continue
        x = fe.node_xyz[index[node]]
        for j, e in enumerate(np.eye(6)):
            R[r, j] = (e[:3] + np.cross(e[3:], x))[comp - 1] if comp <= 3 else e[3 + comp - 4]
    return R


def test_rigid_motions_cost_no_stiffness(superelement):
    R = rigid_motions(superelement)
    K = superelement.K.toarray()
    assert_close(K @ R, np.zeros_like(R), rel=1e-9, scale=np.abs(K).max() * np.abs(R).max())
    masses = np.diag(R.T @ superelement.M.toarray() @ R)
    # one mass in x, y and z to 5e-12: the file's matrices are computed data, not exact
    assert_close(masses[:3], np.full(3, masses[0]), rel=1e-10)
    assert masses[0] == pytest.approx(20.1181, rel=1e-5)


def test_free_modes_and_neutral_round_trip(superelement, tmp_path):
    assert superelement.n_dofs == 105 - 15
    assert np.count_nonzero(superelement.dof_comp == 0) == N_MODES
    modes = lowest_modes(superelement.M, superelement.K, 8)
    assert np.all(modes.freq_hz[:6] < 1e-6 * modes.freq_hz[6])
    assert modes.freq_hz[6] == pytest.approx(113.131, rel=1e-5)
    back = neutral.read(neutral.write(superelement, tmp_path / "se.npz"))
    assert (back.M != superelement.M).nnz == 0 and (back.K != superelement.K).nnz == 0
    assert np.array_equal(back.dof_comp, superelement.dof_comp)
    assert back.dof_labels()[-1].endswith("scalar")


def test_small_and_free_field_cards(tmp_path):
    path = tmp_path / "cards.bdf"
    path.write_text(
        "$ a comment\n"
        "CORD2R  5       0       1.      2.      3.      1.      2.      4.      +\n"
        "+       2.      2.      3.\n"
        "GRID,7,5,1.5-3,2.0,-3.,0\n"
        "GRID    8       5       1.      0.      0.      5\n"
        "SPOINT  100     THRU    102\n"
        "ASET1   123     7       8\n"
    )
    bulk = read_bulk(path)
    assert bulk.grids[7][1] == pytest.approx([1.5e-3, 2.0, -3.0])
    assert bulk.grids[8][2] == 5 and bulk.spoints == {100, 101, 102}
    assert bulk.aset == {7: {1, 2, 3}, 8: {1, 2, 3}}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("CORD2C  5       0       0.      0.      0.      0.      0.      1.\n", "CORD2R"),
        ("GRID    7       0       abc     0.      0.\n", "not a number"),
    ],
)
def test_bad_cards_are_refused(tmp_path, text, message):
    path = tmp_path / "bad.bdf"
    path.write_text(text)
    with pytest.raises(FEModelError, match=message):
        read_bulk(path)


def test_bad_op4_files_are_refused(tmp_path):
    binary = tmp_path / "binary.op4"
    binary.write_bytes(b"\x18\x00\x00\x00" + b"\0" * 40)
    with pytest.raises(FEModelError, match="binary OUTPUT4"):
        read_op4(binary)
    other = tmp_path / "other.op4"
    other.write_text("       1       1       1       7CX      1P,3E22.15\n")
    with pytest.raises(FEModelError, match="precision type 7"):
        read_op4(other)
    with pytest.raises(FEModelError, match="no matrix KXX"):
        read_superelement(OP4, PCH, stiffness="KXX")
