"""What real URDF files contain: read with a warning when it does not change the dynamics,
refused with a clear error (file and element named, exit 2, one stderr line) when it
would otherwise be read wrongly (docs/urdf-reader.md).

Accepted cases are checked on both sides: the textbook model and Pinocchio must read the
same dynamics (``cross_check`` within 1e-10) and Pinocchio must read what it reads
without rt70 (same mass matrix and potential as Pinocchio on the raw text).
"""

from __future__ import annotations

import subprocess
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import rt70.cli.main
from rt70 import reference
from rt70.crosscheck.validate import cross_check
from rt70.errors import (
    DtdError,
    InertiaError,
    MagnitudeError,
    MasslessCoordinateError,
    NonFiniteError,
    Rt70Error,
    Rt70Warning,
    UrdfError,
    XacroError,
)
from rt70.model.scene import load_scene, scene_from_text
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import massless
from rt70.textbook.spatial import body_inertia, placement, rpy_matrix
from rt70.urdf import read_urdf_string
from rt70.urdf.elements import MAX_MAGNITUDE

TOL = 1e-10
XACRO_NS = "http://www.ros.org/wiki/xacro"


def inertial(mass="1", com="0.5 0.1 0", rpy="0 0 0", ixx="0.1", iyy="0.2", izz="0.25", **off):
    products = {"ixy": "0", "ixz": "0", "iyz": "0", **off}
    return (
        f'<inertial><origin xyz="{com}" rpy="{rpy}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="{products["ixy"]}" ixz="{products["ixz"]}" iyy="{iyy}" '
        f'iyz="{products["iyz"]}" izz="{izz}"/></inertial>'
    )


def link(name: str, body: str = "") -> str:
    return f'<link name="{name}">{body}</link>'


def joint(
    name, parent, child, jtype="continuous", xyz="0 0 0", rpy="0 0 0", axis="0 0 1", extra=""
):
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>' if jtype == "prismatic" else ""
    return (
        f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}{extra}</joint>'
    )


def robot(*parts: str, head: str = '<?xml version="1.0"?>\n', attrs: str = "") -> str:
    body = "\n  ".join(parts)
    return (
        f'{head}<robot name="t" xmlns:rt70="urn:rt70:urdf-extensions:1"{attrs}>\n  {body}\n'
        "</robot>\n"
    )


#: A valid pendulum pair to hang the oddities on: base -j1-> l1 -j2-> l2.
PAIR = (
    joint("j1", "base", "l1", xyz="0 0 0.3", rpy="0.1 0 0"),
    link("l1", inertial()),
    joint("j2", "l1", "l2", xyz="1 0 0", axis="1 0 0"),
    link("l2", inertial(com="0.5 0.2 0.1", ixx="0.1", iyy="0.1", izz="0.1")),
)


def read(text: str, name: str = "t.urdf", **kw):
    """``scene_from_text`` recording warnings: ``(scene, [warning messages])``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", Rt70Warning)
        scene = scene_from_text(text, name, **kw)
        scene.textbook  # noqa: B018
        scene.reference  # noqa: B018
    return scene, [str(w.message) for w in caught if issubclass(w.category, Rt70Warning)]


def assert_agrees(scene) -> None:
    for r in cross_check(scene, samples=3, seed=1, repeat=0):
        # relative to the natural scale already: its scale is 1
        assert_close(r.max_rel_err, 0.0, rel=TOL, scale=1.0, what=r.quantity)


def raw_pinocchio(text: str, q: np.ndarray) -> tuple[np.ndarray, float]:
    """Mass matrix and gravity potential of Pinocchio alone on ``text`` (continuous joints)."""
    model = pin.buildModelFromXML(text)
    data = model.createData()
    qp = np.concatenate([[np.cos(x), np.sin(x)] for x in q])
    A = pin.crba(model, data, qp)
    return np.triu(A) + np.triu(A, 1).T, float(pin.computePotentialEnergy(model, data, qp))


# --- accepted with a warning ----------------------------------------------------------

Q = np.array([0.3, -0.7])


@pytest.mark.parametrize(
    "root_inertial",
    [
        inertial(ixx="0", iyy="1", izz="1"),  # random_urdfs: moments 0, 1, 1
        inertial(mass="0"),  # kuka_iiwa, tables: zero mass, non-zero tensor
        inertial(mass="-3"),
        inertial(ixx="1", iyy="1", izz="3"),  # triangle inequality
    ],
    ids=["not-positive-definite", "zero-mass", "negative-mass", "triangle"],
)
def test_impossible_root_inertia_is_ignored(root_inertial):
    plain = robot(link("base"), *PAIR)
    text = robot(link("base", root_inertial), *PAIR)
    scene, caught = read(text)
    assert len(caught) == 1 and "link 'base'" in caught[0] and "root link" in caught[0]
    assert caught[0].startswith("t.urdf: ")
    assert scene.description.links["base"].inertial is None
    assert_agrees(scene)
    # Pinocchio reads it the same: the root's inertia enters neither A nor the potential
    A_raw, U_raw = raw_pinocchio(text, Q)
    A_plain, U_plain = raw_pinocchio(plain, Q)
    assert_close(A_raw, A_plain, rel=MIN_REL)
    weights = reference.weight_moment(scene.reference, scene.reference_data, Q)  # U's terms
    assert_close(U_raw, U_plain, rel=MIN_REL, scale=weights)
    A = reference.mass_matrix(scene.reference, scene.reference_data, Q)
    assert_close(A, A_raw, rel=MIN_REL)


def test_valid_root_inertia_never_enters_the_dynamics():
    """A massive root (a table, cartpole's rail) is the ground: no mass, no potential."""
    plain = scene_from_text(robot(link("base"), *PAIR), "plain")
    heavy, caught = read(robot(link("base", inertial(mass="50", com="1 2 3")), *PAIR))
    assert caught == []
    tm, td = heavy.textbook, heavy.textbook_data
    from rt70.textbook import dynamics

    pm, pd = plain.textbook, plain.textbook_data
    np.testing.assert_array_equal(dynamics.mass_matrix(tm, td, Q), dynamics.mass_matrix(pm, pd, Q))
    assert dynamics.gravity_potential(tm, td, Q) == dynamics.gravity_potential(pm, pd, Q)
    U_heavy = reference.gravity_potential(heavy.reference, heavy.reference_data, Q)
    assert U_heavy == reference.gravity_potential(plain.reference, plain.reference_data, Q)
    assert_agrees(heavy)


def test_impossible_inertia_welded_to_the_root_is_ignored():
    text = robot(
        link("base"),
        joint("weld", "base", "plate", jtype="fixed", xyz="0 0 0.1"),
        link("plate", inertial(ixx="0", iyy="0", izz="1e-6")),
        *PAIR,
    )
    scene, caught = read(text)
    assert len(caught) == 1 and "link 'plate'" in caught[0]
    assert "welded to the root link 'base'" in caught[0]
    assert_agrees(scene)


DUMMY = inertial(mass="0.0", com="0.3 0 0", rpy="0.2 0 0", ixx="0.3", iyy="0.1", izz="0.25")


def test_zero_mass_dummy_inertia_merged_like_pinocchio():
    """panda_link8: mass 0, a dummy tensor, welded by a fixed joint to a body with mass.

    Pinocchio adds its rotational inertia to the body (spatial inertia with m = 0); the
    textbook side must read the same dynamics.
    """
    weld = joint("j8", "l2", "l8", jtype="fixed", xyz="0 0 0.1", rpy="0 0 0.7")
    plain = robot(link("base"), *PAIR, weld, link("l8"))
    text = robot(link("base"), *PAIR, weld, link("l8", DUMMY))
    scene, caught = read(text)
    assert len(caught) == 1 and "link 'l8'" in caught[0] and "link 'l2'" in caught[0]
    assert "zero mass but non-zero inertia" in caught[0]
    assert_agrees(scene)
    A_raw, _ = raw_pinocchio(text, Q)
    A_plain, _ = raw_pinocchio(plain, Q)
    added = A_raw - A_plain
    assert np.max(np.abs(added)) > 0.05  # Pinocchio does add it
    A = reference.mass_matrix(scene.reference, scene.reference_data, Q)
    assert_close(A, A_raw, rel=1e-14)
    # the textbook body l2 carries exactly the dummy's rotational inertia, placed by j8
    base = scene_from_text(plain, "plain").textbook.Theta[1]
    X = placement(np.array([0, 0, 0.1]), rpy_matrix(np.array([0, 0, 0.7])))
    rot = rpy_matrix(np.array([0.2, 0, 0]))
    theta = body_inertia(0.0, np.array([0.3, 0, 0]), rot @ np.diag([0.3, 0.1, 0.25]) @ rot.T)
    moved = X @ theta @ X.T
    scale = np.abs(base).max() + (np.abs(X) @ np.abs(theta) @ np.abs(X.T)).max()  # the terms
    assert_close(scene.textbook.Theta[1], base + moved, rel=1e-14, scale=scale)


def test_zero_mass_dummy_merged_before_the_mass_of_its_body():
    """The body's own link is massless; the dummy is welded on before the link with mass."""
    text = robot(
        link("base"),
        joint("j1", "base", "a", xyz="0 0 0.2"),
        link("a"),
        joint("fd", "a", "d", jtype="fixed", xyz="0.1 0 0", rpy="0.3 0 0"),
        link("d", DUMMY),
        joint("fb", "a", "b", jtype="fixed", xyz="0.5 0 0"),
        link("b", inertial()),
        joint("j2", "b", "c", axis="1 0 0"),
        link("c", inertial()),
    )
    scene, caught = read(text)
    assert len(caught) == 1 and "link 'd'" in caught[0] and "link 'a'" in caught[0]
    assert_agrees(scene)


def test_zero_mass_dummy_on_a_massless_body_is_refused(tmp_path):
    text = robot(link("base"), *PAIR, joint("j3", "l2", "l3"), link("l3", DUMMY))
    with pytest.raises(InertiaError, match=r"link 'l3': zero mass but non-zero inertia"):
        scene_from_text(text, "t.urdf")


@pytest.mark.parametrize(
    ("head", "warned"),
    [
        ('\n\n  <?xml version="1.0"?>\n', True),  # diff_ring, biped2d
        ('\ufeff<?xml version="1.0"?>\n', False),  # a byte-order mark is legal
        ('\ufeff\n<?xml version="1.0"?>\n', True),
        ("\n\n", False),  # no declaration: leading whitespace is legal XML
    ],
    ids=["whitespace", "bom", "bom-whitespace", "no-declaration"],
)
def test_text_before_the_declaration(head, warned):
    scene, caught = read(robot(link("base"), *PAIR, head=head))
    assert [("whitespace before the XML declaration" in c) for c in caught] == (
        [True] if warned else []
    )
    assert scene.text == robot(
        link("base"), *PAIR, head=head.lstrip("\ufeff" if not warned else "\ufeff \n")
    )
    assert_agrees(scene)


def test_trailing_nul_is_ignored():
    """humanoid.urdf ends in a NUL byte, where TinyXML (Pinocchio's parser) stops."""
    scene, caught = read(robot(link("base"), *PAIR) + "\x00")
    assert len(caught) == 1 and "NUL characters after the document" in caught[0]
    assert "\x00" not in scene.text
    assert_agrees(scene)


def test_xacro_namespace_declaration_alone_is_accepted():
    """Expanded files often keep ``xmlns:xacro`` on <robot> (diff_ring, a1)."""
    scene, caught = read(robot(link("base"), *PAIR, attrs=f' xmlns:xacro="{XACRO_NS}"'))
    assert caught == []
    assert_agrees(scene)


def test_cli_prints_one_warning_line_each(tmp_path, capsys):
    path = tmp_path / "odd.urdf"
    path.write_text(
        robot(link("base", inertial(mass="0")), *PAIR, head='\n<?xml version="1.0"?>\n')
    )
    assert rt70.cli.main.main(["validate", str(path), "--samples", "2"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and all(line.startswith(f"rt70: warning: {path}: ") for line in err)


# --- balance_inertia ------------------------------------------------------------------

BAD_MOVING = robot(link("base"), *PAIR[:3], link("l2", inertial(ixx="1", iyy="1", izz="3")))


def test_impossible_moving_inertia_is_refused_by_default(tmp_path, capsys):
    with pytest.raises(InertiaError, match="link 'l2'.*triangle inequality"):
        scene_from_text(BAD_MOVING, "t.urdf")


@pytest.mark.parametrize(
    ("moments", "offdiag"),
    [(("1", "1", "3"), {}), (("1", "1", "1"), {"ixy": "2"}), (("0", "0.2", "0.2"), {})],
    ids=["triangle", "indefinite", "rod"],
)
def test_balance_inertia_repairs_both_sides_alike(moments, offdiag):
    ixx, iyy, izz = moments
    bad = inertial(com="0.5 0.2 0.1", rpy="0.3 0.2 0.1", ixx=ixx, iyy=iyy, izz=izz, **offdiag)
    text = robot(link("base"), *PAIR[:3], link("l2", bad))
    scene, caught = read(text, balance_inertia=True)
    (repair,) = scene.description.inertia_repairs
    mean = (float(ixx) + float(iyy) + float(izz)) / 3.0
    assert repair.link == "l2"
    assert_close(repair.new_moments, [mean] * 3, rel=MIN_REL)
    ixy = float(offdiag.get("ixy", 0))
    tensor = np.array([[float(ixx), ixy, 0], [ixy, float(iyy), 0], [0, 0, float(izz)]])
    assert_close(repair.old_moments, np.linalg.eigvalsh(tensor), rel=1e-12)
    assert len(caught) == 1 and "link 'l2': inertia repaired" in caught[0]
    assert f"-> {mean:.6g}, {mean:.6g}, {mean:.6g}" in caught[0]
    inertia = scene.description.links["l2"].inertial.inertia  # rotated by <origin rpy>
    assert_close(inertia, mean * np.eye(3), rel=1e-14)  # R (mean 1) Rᵀ: rounding of R
    # Pinocchio reads the repaired text, and the textbook reads exactly what it says
    assert f'ixx="{mean!r}"' in scene.text and f'izz="{mean!r}"' in scene.text
    again = read_urdf_string(scene.text, "again")
    assert again.inertia_repairs == []
    np.testing.assert_array_equal(
        again.links["l2"].inertial.inertia, scene.description.links["l2"].inertial.inertia
    )
    assert_agrees(scene)


def test_balance_inertia_cannot_repair_a_zero_trace():
    text = robot(
        link("base"), *PAIR[:3], link("l2", inertial(ixx="0", iyy="0", izz="0", ixz="1e-9"))
    )
    with pytest.raises(InertiaError, match="link 'l2': inertia tensor not positive definite"):
        scene_from_text(text, "t.urdf", balance_inertia=True)


def test_cli_balance_inertia(tmp_path, capsys):
    path = tmp_path / "bad.urdf"
    path.write_text(BAD_MOVING)
    assert rt70.cli.main.main(["validate", str(path)]) == 2
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", str(path), "--balance-inertia", "--samples", "2"]) == 0
    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line.startswith(f"rt70: warning: {path}: link 'l2': inertia repaired")
    assert "1, 1, 3 -> 1.66667, 1.66667, 1.66667" in line


# --- what moves no mass ---------------------------------------------------------------

POINT = (
    '<inertial><origin xyz="{}"/><mass value="2"/>'
    '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>'
)


@pytest.mark.parametrize(
    ("parts", "expected"),
    [
        # a mesh-only link on a revolute joint: nothing to move
        ((joint("j1", "base", "l1"), link("l1")), (["j1"], [])),
        # a prismatic joint moving a subtree without mass
        (
            (
                joint("p", "base", "l1", jtype="prismatic"),
                link("l1"),
                joint("j2", "l1", "l2"),
                link("l2"),
            ),
            (["p", "j2"], []),
        ),
        # a point mass on the revolute axis (com on z, axis z)
        ((joint("j1", "base", "l1"), link("l1", POINT.format("0 0 0.5"))), (["j1"], [])),
        # ... and off the axis: it moves
        ((joint("j1", "base", "l1"), link("l1", POINT.format("0.5 0 0"))), ([], [])),
        # a point mass on its joint's axis, moved off j1's axis by j2: j1 moves it
        (
            (
                joint("j1", "base", "l1"),
                link("l1"),
                joint("j2", "l1", "l2", xyz="1 0 0", axis="1 0 0"),
                link("l2", POINT.format("0.4 0 0")),
            ),
            (["j2"], []),
        ),
        # a point mass at the origin of a floating joint: its rotations move nothing
        (
            (joint("f", "base", "l1", jtype="floating"), link("l1", POINT.format("0 0 0"))),
            (["f:rx", "f:ry", "f:rz"], []),
        ),
        # two coaxial joints with nothing between them: q̇1 = −q̇2 moves nothing
        (
            (
                joint("j1", "base", "l1"),
                link("l1"),
                joint("j2", "l1", "l2"),
                link("l2", inertial()),
            ),
            ([], ["j1", "j2"]),
        ),
        # a mimic source that moves no mass itself but through its follower
        (
            (
                joint("j1", "base", "l1"),
                link("l1"),
                joint(
                    "j2",
                    "l1",
                    "l2",
                    xyz="1 0 0",
                    axis="0 1 0",
                    extra='<mimic joint="j1" multiplier="2"/>',
                ),
                link("l2", inertial()),
            ),
            ([], []),
        ),
    ],
    ids=[
        "mesh-only",
        "prismatic-massless-subtree",
        "point-mass-on-axis",
        "point-mass-off-axis",
        "point-mass-on-child-axis",
        "floating-point-mass",
        "coaxial",
        "mimic-moves-mass",
    ],
)
def test_what_moves_no_mass(parts, expected):
    from rt70.textbook.model import build_model

    desc = read_urdf_string(robot(link("base"), *parts), "t")
    assert massless.singular_coordinates(build_model(desc)) == expected


# --- refused: what would otherwise be read wrongly -------------------------------------

SPRING = '<rt70:joint_spring name="s" joint="j1" stiffness="{}"/>'


@dataclass(frozen=True)
class Refusal:
    text: str
    error: type[Rt70Error]
    needles: tuple[str, ...]  # the message names the element
    at_build: bool = False  # raised when the model is built (Scene.textbook), not read


def _entity_robot() -> str:
    doctype = '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY m "7">]>\n'
    return robot(link("base"), *PAIR[:3], link("l2", inertial(mass="&m;")), head=doctype)


REFUSALS = {
    "xacro-element": Refusal(
        robot(
            link("base"), f'<xacro:property xmlns:xacro="{XACRO_NS}" name="a" value="1"/>', *PAIR
        ),
        XacroError,
        ("<xacro:property>", "xacro template", "expand it with xacro first"),
    ),
    "xacro-macro-call": Refusal(
        robot(
            link("base"), *PAIR, '<xacro:arm prefix="left"/>', attrs=f' xmlns:xacro="{XACRO_NS}"'
        ),
        XacroError,
        ("<xacro:arm>", "expand it with xacro first"),
    ),
    "xacro-property-substitution": Refusal(
        robot(link("base"), *PAIR[:3], link("l2", inertial(mass="${m}"))),
        XacroError,
        ('<mass value="${m}">', "xacro substitution"),
    ),
    "xacro-optenv-substitution": Refusal(  # husky.urdf
        robot(
            link("base"),
            joint("j1", "base", "l1", xyz="$(optenv X 0.19 0 0.149)"),
            link("l1", inertial()),
        ),
        XacroError,
        ('<origin xyz="$(optenv X 0.19 0 0.149)">', "xacro substitution"),
    ),
    "xacro-prefix-undeclared": Refusal(
        robot(link("base"), *PAIR, '<xacro:include filename="arm.xacro"/>'),
        XacroError,
        ("xacro elements without the xacro namespace", "expand it with xacro first"),
    ),
    "dtd-entity": Refusal(
        _entity_robot(), DtdError, ("<!ENTITY m>", "Pinocchio's parser does not", "xmllint")
    ),
    "dtd-parameter-entity": Refusal(
        robot(link("base"), *PAIR, head='<!DOCTYPE robot [<!ENTITY % p "">]>\n'),
        DtdError,
        ("<!ENTITY %p>",),
    ),
    "mesh-only-moving-link": Refusal(
        robot(link("base"), *PAIR, joint("j3", "l2", "l3"), link("l3")),
        MasslessCoordinateError,
        ("joint coordinate(s) j3 move no mass", "mass matrix is singular"),
        at_build=True,
    ),
    "point-mass-on-the-axis": Refusal(
        robot(link("base"), joint("j1", "base", "l1"), link("l1", POINT.format("0 0 2"))),
        MasslessCoordinateError,
        ("joint coordinate(s) j1 move no mass",),
        at_build=True,
    ),
    "coaxial-redundant-joints": Refusal(
        robot(
            link("base"),
            joint("j1", "base", "l1"),
            link("l1"),
            joint("j2", "l1", "l2"),
            link("l2", inertial()),
        ),
        MasslessCoordinateError,
        ("combination of joint coordinates j1, j2 moves no mass",),
        at_build=True,
    ),
    "huge-mass": Refusal(
        robot(link("base"), *PAIR[:3], link("l2", inertial(mass="1e308"))),
        MagnitudeError,
        ("link 'l2' <inertial> <mass", 'value="1e308"', f"magnitude above {MAX_MAGNITUDE:g}"),
    ),
    "huge-stiffness": Refusal(
        robot(link("base"), *PAIR, SPRING.format("1e308")),
        MagnitudeError,
        ("<rt70:joint_spring", 'stiffness="1e308"', "magnitude above"),
    ),
    "huge-mimic-multiplier": Refusal(
        robot(
            link("base"),
            *PAIR[:2],
            joint("j2", "l1", "l2", axis="1 0 0", extra='<mimic joint="j1" multiplier="1e200"/>'),
            link("l2", inertial()),
        ),
        MagnitudeError,
        ("joint 'j2' <mimic", 'multiplier="1e200"', "magnitude above"),
    ),
    "axis-whose-norm-overflows": Refusal(
        robot(
            link("base"), joint("j1", "base", "l1", axis="1e200 1e200 0"), link("l1", inertial())
        ),
        MagnitudeError,
        ("joint 'j1' <axis", 'xyz="1e200 1e200 0"', "magnitude above"),
    ),
    "overflowing-number": Refusal(  # float("1e400") is inf: not a silent zero or infinity
        robot(link("base"), *PAIR[:3], link("l2", inertial(mass="1e400"))),
        NonFiniteError,
        ('value="1e400"', "NaN or infinite"),
    ),
    "nul-inside-the-document": Refusal(
        robot(link("base"), *PAIR).replace("</robot>", "\x00</robot>"),
        UrdfError,
        ("NUL character in the document, line",),
    ),
    "pinocchio-refuses-a-revolute-without-limits": Refusal(
        robot(link("base"), joint("j1", "base", "l1", jtype="revolute"), link("l1", inertial())),
        UrdfError,
        ("Pinocchio cannot load it", "Joint [j1]", "does not specify limits"),
        at_build=True,
    ),
}


def _build(path: Path) -> None:
    scene = load_scene(path)
    scene.textbook  # noqa: B018
    scene.reference  # noqa: B018


@pytest.mark.parametrize("name", list(REFUSALS))
def test_refused(name, tmp_path, capsys):
    case = REFUSALS[name]
    path = tmp_path / f"{name}.urdf"
    path.write_text(case.text, encoding="utf-8")
    if not case.at_build:
        with pytest.raises(Rt70Error) as excinfo:
            load_scene(path)
    else:
        scene = load_scene(path)  # read fine ...
        with pytest.raises(Rt70Error) as excinfo:  # ... refused when the model is built
            scene.textbook  # noqa: B018
            scene.reference  # noqa: B018
    exc = excinfo.value
    assert type(exc) is case.error, f"{type(exc).__name__}: {exc}"
    message = str(exc)
    assert message.startswith(f"{path}: ") and "\n" not in message
    for needle in case.needles:
        assert needle in message, f"{needle!r} not in {message!r}"
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.splitlines() == [f"rt70: error: {message}"]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["pinocchio-refuses-a-revolute-without-limits", "dtd-entity"])
def test_refused_in_a_subprocess(name, tmp_path):
    """One stderr line, nothing from Pinocchio's C++ parser, no traceback."""
    path = tmp_path / f"{name}.urdf"
    path.write_text(REFUSALS[name].text, encoding="utf-8")
    proc = subprocess.run(
        [sys.executable, "-m", "rt70", "validate", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and proc.stdout == ""
    (line,) = proc.stderr.splitlines()
    assert line.startswith(f"rt70: error: {path}: ")


def test_every_number_at_the_limit_stays_finite_and_agrees():
    """MAX_MAGNITUDE is safe: masses, inertias, gains, mimic factor, gravity and axis at it."""
    big = f"{MAX_MAGNITUDE:g}"
    text = robot(
        link("base"),
        joint("j1", "base", "l1", axis=f"{big} {big} 0"),
        link("l1", inertial(mass=big, ixx=big, iyy=big, izz=big)),
        joint(
            "j2",
            "l1",
            "l2",
            xyz="1 0 0",
            axis="0 1 0",
            extra=f'<mimic joint="j1" multiplier="{big}" offset="0.1"/>',
        ),
        link("l2", inertial(mass=big, ixx=big, iyy=big, izz=big)),
        joint("j3", "l2", "l3", jtype="prismatic", xyz="1 0 0", axis="1 0 0"),
        link("l3", inertial(mass=big, ixx=big, iyy=big, izz=big)),
        SPRING.format(big),
        f'<rt70:bushing name="b" stiffness="{" ".join([big] * 6)}" damping="{" ".join([big] * 6)}">'
        '<rt70:frame1 link="base"/><rt70:frame2 link="l3"/></rt70:bushing>',
        f'<rt70:gravity xyz="0 0 -{big}"/>',
    )
    scene = scene_from_text(text, "limit")
    for r in cross_check(scene, samples=3, seed=2, repeat=0):
        assert np.isfinite(r.max_abs_err), r
        assert_close(r.max_rel_err, 0.0, rel=TOL, scale=1.0, what=r.quantity)
