"""Bushings and struts with full symmetric 6 × 6 stiffness and damping (issue 24, part 1).

A bushing's ``stiffness`` and ``damping`` take 6 numbers (the diagonal) or 36 (the
symmetric positive semi-definite matrix, row by row). Checked here: what the reader keeps
and refuses; the stiffness the structure gets from it against the matrix itself (a body
on six joints whose coordinates are the bushing's deformation); and the cross-check of
both sides on a chain with a coupled bushing. The numba kernels' equality with the
Python path on a coupled bushing is in tests/test_element_kernels.py, the products of
each side against central differences in tests/test_elements.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_elements import chain

from rt70.cli.main import main
from rt70.crosscheck.validate import cross_check
from rt70.errors import ExtensionError
from rt70.linear import linearize as lin
from rt70.model.scene import scene_from_text
from rt70.testing import assert_close

RNG = np.random.default_rng(24)
L = RNG.uniform(-1.0, 1.0, (6, 6))
C = 1e4 * (L @ L.T + 0.1 * np.eye(6))
C = 0.5 * (C + C.T)
D = 0.01 * C

INERTIA = '<inertia ixx="0.4" iyy="0.5" izz="0.6" ixy="0" ixz="0" iyz="0"/>'
LIMIT = '<limit lower="-3" upper="3" effort="1" velocity="1"/>'


def _numbers(matrix: np.ndarray) -> str:
    return " ".join(f"{x:.17g}" for x in np.ravel(matrix))


def six_joint_body(stiffness: str, damping: str) -> str:
    """A body on prismatic x, y, z then revolute x, y, z from the ground, and a bushing
    from the ground's origin to the body's: its deformation is the six coordinates
    (position, then the 1–2–3 angles)."""
    links = ["world", "p1", "p2", "p3", "r1", "r2", "body"]
    joints = ""
    for i, (kind, axis) in enumerate(
        [("prismatic", "1 0 0"), ("prismatic", "0 1 0"), ("prismatic", "0 0 1"),
         ("revolute", "1 0 0"), ("revolute", "0 1 0"), ("revolute", "0 0 1")]
    ):  # fmt: skip
        joints += (
            f'<joint name="j{i}" type="{kind}"><parent link="{links[i]}"/>'
            f'<child link="{links[i + 1]}"/><axis xyz="{axis}"/>{LIMIT}</joint>'
        )
    massless = "".join(f'<link name="{n}"/>' for n in links[1:-1])
    return (
        '<robot name="six" xmlns:rt70="urn:rt70:urdf-extensions:1"><link name="world"/>'
        f'{massless}<link name="body"><inertial><mass value="5"/>{INERTIA}</inertial></link>'
        f"{joints}"
        '<rt70:gravity xyz="0 0 0"/>'
        f'<rt70:bushing name="mount" stiffness="{stiffness}" damping="{damping}">'
        '<rt70:frame1 link="world"/><rt70:frame2 link="body"/></rt70:bushing></robot>'
    )


def test_the_reader_keeps_the_matrix_and_reads_six_numbers_as_its_diagonal():
    coupled = scene_from_text(six_joint_body(_numbers(C), _numbers(D)), "coupled")
    assert_close(coupled.description.bushings[0].stiffness, C, rel=1e-15)
    assert_close(coupled.description.bushings[0].damping, D, rel=1e-15)
    diagonal = scene_from_text(six_joint_body("1 2 3 4 5 6", "0 0 0 0 0 1"), "diagonal")
    bushing = diagonal.description.bushings[0]
    assert np.array_equal(bushing.stiffness, np.diag([1.0, 2, 3, 4, 5, 6]))
    assert bushing.diagonal and not coupled.description.bushings[0].diagonal


@pytest.mark.parametrize("side", ["textbook", "reference"])
def test_the_structure_gets_the_bushings_matrix_as_its_stiffness(side):
    """At q = 0 the six coordinates are the deformation, so K = C and D = D exactly
    (K by central differences of each side's forces: on C's scale to 1e-6)."""
    scene = scene_from_text(six_joint_body(_numbers(C), _numbers(D)), "coupled")
    q0 = np.zeros(6)
    K = lin.stiffness_matrix(scene, q0, side=side)
    assert_close(K, C, rel=1e-6, scale=np.abs(C).max())
    assert_close(lin.damping_matrix(scene, q0), D, rel=1e-12, scale=np.abs(D).max())


def test_both_sides_agree_on_a_chain_with_a_coupled_bushing():
    scene = scene_from_text(chain(mimic=False), "coupled_chain")
    assert any(not b.diagonal for b in scene.description.bushings)
    records = cross_check(scene, samples=3)
    assert records and all(r.passed() for r in records), [
        (r.quantity, r.max_rel_err) for r in records if not r.passed()
    ]


def _refused(stiffness: str, damping: str = "0 0 0 0 0 0") -> str:
    with pytest.raises(ExtensionError) as info:
        scene_from_text(six_joint_body(stiffness, damping), "bad")
    return str(info.value)


def test_a_matrix_that_is_not_symmetric_is_refused_naming_the_entries():
    bad = C.copy()
    bad[0, 3] *= 1.001
    message = _refused(_numbers(bad))
    assert "<rt70:bushing name='mount'>: stiffness is not symmetric" in message
    assert "entry (1, 4)" in message and "entry (4, 1)" in message


def test_a_matrix_with_a_negative_eigenvalue_is_refused():
    w, V = np.linalg.eigh(C)
    w[0] = -0.01 * w[-1]
    message = _refused(_numbers(C), _numbers(V @ np.diag(w) @ V.T))
    assert "damping is not positive semi-definite: its smallest eigenvalue is" in message


def test_a_singular_semi_definite_matrix_is_accepted():
    """A rank-deficient matrix (no stiffness along one combination of axes) is allowed."""
    u = np.ones(6) / np.sqrt(6.0)
    P = np.eye(6) - np.outer(u, u)
    singular = P @ C @ P
    text = six_joint_body(_numbers(0.5 * (singular + singular.T)), "0 0 0 0 0 0")
    scene = scene_from_text(text, "singular")
    assert np.linalg.matrix_rank(scene.description.bushings[0].stiffness, tol=1e-6) == 5


@pytest.mark.parametrize("count", [1, 7, 21])
def test_other_counts_are_refused_saying_which_are_accepted(count):
    message = _refused(" ".join(["1"] * count))
    expected = "expected 6 numbers (the diagonal) or 36 (the symmetric 6×6 matrix, row by row)"
    assert f"{expected}, got {count}" in message


def test_the_command_line_refuses_it_in_one_line(tmp_path, capsys):
    bad = C.copy()
    bad[2, 5] = -bad[2, 5]
    path = tmp_path / "bad.urdf"
    path.write_text(six_joint_body(_numbers(bad), "0 0 0 0 0 0"), encoding="utf-8")
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "not symmetric" in err


def test_a_change_of_units_scales_the_coupling_terms_by_their_dimension():
    """mm and g: N/m × 1e3, N·m/rad × 1e9 and the coupling (N/rad, N·m/m) × 1e6, so the
    converted structure's stiffness is the matrix in the new units."""
    from rt70.reports.stress.edits import convert_units

    text = convert_units(six_joint_body(_numbers(C), _numbers(D)), length=1e3, mass=1e3)
    scene = scene_from_text(text, "mm_g")
    half = np.sqrt([1e3] * 3 + [1e9] * 3)
    assert_close(scene.description.bushings[0].stiffness, np.outer(half, half) * C, rel=1e-14)
    assert_close(scene.description.bushings[0].damping, np.outer(half, half) * D, rel=1e-14)
