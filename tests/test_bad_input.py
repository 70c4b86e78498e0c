"""Bad input is rejected with a specific rt70 error, one readable line and exit code 2.

Every case is a small URDF (or a missing path / unknown scene name). For each, the
reader must raise the most specific :mod:`rt70.errors` class with a message naming the
file and the offending element, and ``rt70 validate`` must print exactly one
``rt70: error:`` line on stderr, no traceback, and return 2.
"""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import rt70.cli.main
import rt70.model.scene
import rt70.urdf
from rt70.errors import (
    ExtensionError,
    InertiaError,
    JointTypeError,
    NonFiniteError,
    Rt70Error,
    SceneError,
    SingularConfigurationError,
    TopologyError,
    UrdfError,
)
from rt70.testing import EPS, MIN_REL, assert_close
from rt70.textbook import dynamics, forces
from rt70.textbook.spatial import (
    euler123,
    euler123_angles,
    euler_matrix,
    euler_matrix_inverse,
)

# --- building blocks of the small URDFs --------------------------------------------

INERTIAL = (
    '<inertial><origin xyz="0.5 0 0"/><mass value="1"/>'
    '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
)


def robot(*parts: str, root: str = "robot") -> str:
    body = "\n  ".join(parts)
    return (
        f'<?xml version="1.0"?>\n<{root} name="t" xmlns:rt70="urn:rt70:urdf-extensions:1">\n'
        f"  {body}\n</{root}>\n"
    )


def link(name: str, inertial: str = INERTIAL) -> str:
    return f'<link name="{name}">{inertial}</link>'


def joint(
    name: str,
    parent: str,
    child: str,
    jtype: str = "revolute",
    origin: str = "0 0 0",
    axis: str = "0 0 1",
    extra: str = "",
) -> str:
    return (
        f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{origin}" rpy="0 0 0"/>'
        f'<axis xyz="{axis}"/>{extra}</joint>'
    )


def inertial(mass: str = "1", **moments: str) -> str:
    values = {"ixx": "0.1", "ixy": "0", "ixz": "0", "iyy": "0.1", "iyz": "0", "izz": "0.1"}
    values.update(moments)
    attrs = " ".join(f'{k}="{v}"' for k, v in values.items())
    return f'<inertial><mass value="{mass}"/><inertia {attrs}/></inertial>'


WORLD = '<link name="world"/>'
#: A valid two-link chain world -j1-> link1 -j2-> link2 to hang defects on.
CHAIN = (
    WORLD,
    joint("j1", "world", "link1"),
    link("link1"),
    joint("j2", "link1", "link2"),
    link("link2"),
)


def bushing(stiffness: str, link1: str = "link1", link2: str = "link2") -> str:
    return (
        f'<rt70:bushing name="b1" stiffness="{stiffness}" damping="1 1 1 1 1 1">'
        f'<rt70:frame1 link="{link1}"/><rt70:frame2 link="{link2}"/></rt70:bushing>'
    )


# --- the cases ---------------------------------------------------------------------

MISSING = object()  # a .urdf path that does not exist
SCENE = object()  # an unknown scene name


@dataclass(frozen=True)
class Case:
    source: object  # URDF text, MISSING or SCENE
    error: type[Rt70Error]
    #: substrings the message must contain (besides the path); a tuple: any one of them
    needles: tuple[str | tuple[str, ...], ...]


CASES = {
    "missing-file": Case(MISSING, UrdfError, ("file not found",)),
    "malformed-xml-unclosed-tag": Case(
        '<robot name="t">\n  <link name="world">\n</robot>\n',
        UrdfError,
        ("malformed XML", "line 3"),
    ),
    "root-not-robot": Case(robot(WORLD, root="model"), UrdfError, ("<model>", "<robot>")),
    "joint-parent-missing": Case(
        robot(WORLD, joint("j1", "ghost", "link1"), link("link1")),
        TopologyError,
        ("joint 'j1'", "parent link 'ghost'", "does not exist"),
    ),
    "joint-child-missing": Case(
        robot(WORLD, joint("j1", "world", "ghost"), link("link1")),
        TopologyError,
        ("joint 'j1'", "child link 'ghost'", "does not exist"),
    ),
    "link-with-two-parents": Case(
        robot(*CHAIN, joint("j3", "world", "link3"), link("link3"), joint("j4", "link3", "link2")),
        TopologyError,
        ("link 'link2'", "two parents", "'link1'", "'link3'"),
    ),
    "cycle-beside-a-root": Case(
        robot(
            WORLD,
            joint("j0", "world", "c"),
            link("c"),
            link("a"),
            link("b"),
            joint("ab", "a", "b"),
            joint("ba", "b", "a"),
        ),
        TopologyError,
        ("kinematic cycle", ("a -> b -> a", "b -> a -> b")),
    ),
    "pure-cycle-no-root": Case(
        robot(link("a"), link("b"), joint("ab", "a", "b"), joint("ba", "b", "a")),
        TopologyError,
        ("kinematic cycle", ("a -> b -> a", "b -> a -> b")),
    ),
    "two-roots": Case(
        robot(*CHAIN, link("orphan")),
        TopologyError,
        ("expected one root link, found 2", "world", "orphan"),
    ),
    "negative-mass": Case(
        robot(WORLD, joint("j1", "world", "link1"), link("link1", inertial(mass="-2"))),
        InertiaError,
        ("link 'link1'", "negative mass"),
    ),
    "zero-mass-nonzero-inertia": Case(
        robot(WORLD, joint("j1", "world", "link1"), link("link1", inertial(mass="0"))),
        InertiaError,
        ("link 'link1'", "zero mass", "non-zero inertia"),
    ),
    "inertia-negative-moment": Case(
        robot(WORLD, joint("j1", "world", "link1"), link("link1", inertial(ixx="-1"))),
        InertiaError,
        ("link 'link1'", "not positive definite"),
    ),
    "inertia-negative-eigenvalue": Case(  # diagonal fine, eigenvalues -1, 1, 3
        robot(
            WORLD,
            joint("j1", "world", "link1"),
            link("link1", inertial(ixx="1", iyy="1", izz="1", ixy="2")),
        ),
        InertiaError,
        ("link 'link1'", "not positive definite"),
    ),
    "inertia-triangle-inequality": Case(
        robot(
            WORLD, joint("j1", "world", "link1"), link("link1", inertial(ixx="1", iyy="1", izz="3"))
        ),
        InertiaError,
        ("link 'link1'", "triangle inequality"),
    ),
    "nan-in-origin": Case(
        robot(WORLD, joint("j1", "world", "link1", origin="nan 0 0"), link("link1")),
        NonFiniteError,
        ("<origin", "nan 0 0", "NaN or infinite"),
    ),
    "inf-in-mass": Case(
        robot(WORLD, joint("j1", "world", "link1"), link("link1", inertial(mass="inf"))),
        NonFiniteError,
        ("<mass", "inf", "NaN or infinite"),
    ),
    "nan-in-spring-stiffness": Case(
        robot(*CHAIN, '<rt70:joint_spring name="s1" joint="j1" stiffness="nan"/>'),
        NonFiniteError,
        ("<rt70:joint_spring", 'stiffness="nan"', "NaN or infinite"),
    ),
    "unknown-joint-type-banana": Case(
        robot(WORLD, joint("j1", "world", "link1", jtype="banana"), link("link1")),
        JointTypeError,
        ("joint 'j1'", "unknown joint type 'banana'"),
    ),
    "planar-joint-not-about-z": Case(
        robot(WORLD, joint("j1", "world", "link1", jtype="planar", axis="1 0 0"), link("link1")),
        JointTypeError,
        ("joint 'j1'", "planar joint with axis", "only the plane normal to z"),
    ),
    "mimic-of-missing-joint": Case(
        robot(
            WORLD,
            joint("j1", "world", "link1"),
            link("link1"),
            joint("j2", "link1", "link2", extra='<mimic joint="ghost" multiplier="2"/>'),
            link("link2"),
        ),
        TopologyError,
        ("joint 'j2'", "<mimic joint='ghost'>", "does not exist"),
    ),
    "mimic-of-a-mimic-joint": Case(
        robot(
            WORLD,
            joint("j1", "world", "link1"),
            link("link1"),
            joint("j2", "link1", "link2", extra='<mimic joint="j1" multiplier="2"/>'),
            link("link2"),
            joint("j3", "link2", "link3", extra='<mimic joint="j2"/>'),
            link("link3"),
        ),
        JointTypeError,
        ("joint 'j3' mimics 'j2'", "not an independent 1-DOF joint"),
    ),
    "mimic-on-a-floating-joint": Case(
        robot(
            WORLD,
            joint("j1", "world", "link1"),
            link("link1"),
            joint("j2", "link1", "link2", jtype="floating", extra='<mimic joint="j1"/>'),
            link("link2"),
        ),
        JointTypeError,
        ("joint 'j2'", "a floating joint cannot mimic"),
    ),
    "mimic-couples-revolute-and-prismatic": Case(
        robot(
            WORLD,
            joint("j1", "world", "link1"),
            link("link1"),
            joint("j2", "link1", "link2", jtype="prismatic", extra='<mimic joint="j1"/>'),
            link("link2"),
        ),
        JointTypeError,
        ("joint 'j2' (prismatic) mimics 'j1' (revolute)", "cannot be coupled"),
    ),
    "spring-on-missing-joint": Case(
        robot(*CHAIN, '<rt70:joint_spring name="s1" joint="ghost" stiffness="10"/>'),
        ExtensionError,
        ("<rt70:joint_spring name='s1'>", "joint 'ghost'", "does not exist"),
    ),
    "spring-on-fixed-joint": Case(
        robot(
            WORLD,
            joint("j1", "world", "link1", jtype="fixed"),
            link("link1"),
            '<rt70:joint_spring name="s1" joint="j1" stiffness="10"/>',
        ),
        ExtensionError,
        ("<rt70:joint_spring name='s1'>", "joint 'j1'", "not a 1-DOF joint"),
    ),
    "bushing-on-missing-link": Case(
        robot(*CHAIN, bushing("1 1 1 1 1 1", link2="ghost")),
        ExtensionError,
        ("<rt70:bushing name='b1'>", "<rt70:frame2>", "link 'ghost'"),
    ),
    "unknown-rt70-element": Case(
        robot(*CHAIN, '<rt70:foo name="x"/>'),
        ExtensionError,
        ("unknown rt70 element", "<rt70:foo>"),
    ),
    "negative-stiffness": Case(
        robot(*CHAIN, '<rt70:joint_spring name="s1" joint="j1" stiffness="-5"/>'),
        ExtensionError,
        ("<rt70:joint_spring name='s1'>", "negative stiffness"),
    ),
    "negative-bushing-stiffness": Case(
        robot(*CHAIN, bushing("1 1 1 1 -1 1")),
        ExtensionError,
        ("<rt70:bushing name='b1'>", "negative stiffness"),
    ),
    "five-stiffness-values": Case(
        robot(*CHAIN, bushing("1 2 3 4 5")),
        ExtensionError,
        ("<rt70:bushing", "1 2 3 4 5", "expected 6 numbers (the diagonal) or 36", "got 5"),
    ),
    "non-numeric-gravity": Case(
        robot(*CHAIN, '<rt70:gravity xyz="0 0 g"/>'),
        ExtensionError,
        ("<rt70:gravity", "0 0 g", "not a list of numbers"),
    ),
    "optical-point-lacks-xyz": Case(
        robot(*CHAIN, '<rt70:optical_point name="focus" link="link2"/>'),
        ExtensionError,
        ("<rt70:optical_point name='focus'>", "lacks attribute 'xyz'"),
    ),
    "spring-without-name": Case(
        robot(*CHAIN, '<rt70:joint_spring joint="j1" stiffness="1"/>'),
        ExtensionError,
        ("<rt70:joint_spring>", "without a name"),
    ),
    "non-numeric-xyz": Case(
        robot(WORLD, joint("j1", "world", "link1", origin="1 2 x"), link("link1")),
        UrdfError,
        ("<origin", "1 2 x", "not a list of numbers"),
    ),
    "zero-length-axis": Case(
        robot(WORLD, joint("j1", "world", "link1", axis="0 0 0"), link("link1")),
        UrdfError,
        ("joint 'j1'", "zero-length axis"),
    ),
    "unknown-scene-name": Case(SCENE, SceneError, ("no such scene",)),
}


def target_of(case: Case, name: str, tmp_path: Path) -> str:
    """The path (or scene name) the case hands to the reader and the CLI."""
    if case.source is SCENE:
        return "no_such_scene"
    path = tmp_path / f"{name}.urdf"
    if case.source is not MISSING:
        path.write_text(case.source, encoding="utf-8")
    return str(path)


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input(name, tmp_path, capsys):
    case = CASES[name]
    target = target_of(case, name, tmp_path)

    # (a) the reader raises exactly the expected class, message names file and element
    raisers = [rt70.model.scene.load_scene]
    if case.source is not SCENE:
        raisers.append(rt70.urdf.read_urdf)
    for read in raisers:
        with pytest.raises(Rt70Error) as excinfo:
            read(target)
        exc = excinfo.value
        assert type(exc) is case.error, f"{read.__name__}: {type(exc).__name__}: {exc}"
        message = str(exc)
        assert message.startswith(f"{target}: "), message
        for needle in case.needles:
            options = needle if isinstance(needle, tuple) else (needle,)
            assert any(n in message for n in options), f"{needle!r} not in {message!r}"
        assert "\n" not in message

    # (b) the CLI: exit code 2, one line on stderr, no traceback
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", target]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0] == f"rt70: error: {message}"


@pytest.mark.slow
@pytest.mark.parametrize(
    "name", ["malformed-xml-unclosed-tag", "link-with-two-parents", "unknown-scene-name"]
)
def test_cli_subprocess_bad_input(name, tmp_path):
    target = target_of(CASES[name], name, tmp_path)
    proc = subprocess.run(
        [sys.executable, "-m", "rt70", "validate", target],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=tmp_path,
    )
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("rt70: error:")
    assert target in lines[0]
    assert proc.stdout == ""


def test_good_file_passes_the_reader(tmp_path):
    """The building blocks themselves are valid: each case is bad only by its defect."""
    path = tmp_path / "good.urdf"
    path.write_text(
        robot(
            *CHAIN,
            '<rt70:joint_spring name="s1" joint="j1" stiffness="10"/>',
            bushing("1 1 1 1 1 1"),
            '<rt70:gravity xyz="0 0 -1"/>',
        ),
        encoding="utf-8",
    )
    desc = rt70.urdf.read_urdf(path)
    assert desc.root == "world"
    assert [j.name for j in desc.joints] == ["j1", "j2"]
    assert len(desc.joint_springs) == 1 and len(desc.bushings) == 1


# --- non-finite state -----------------------------------------------------------------


@pytest.fixture(scope="module")
def pendulum():
    scene = rt70.model.scene.load_scene("double_pendulum")
    return scene.textbook, scene.textbook_data


def _nan_at_0(n):
    x = np.zeros(n)
    x[0] = np.nan
    return x


def _inf_at_last(n):
    x = np.zeros(n)
    x[-1] = np.inf
    return x


@pytest.mark.parametrize(
    ("call", "bad"),
    [
        pytest.param(lambda m, d, x, z: dynamics.mass_matrix(m, d, x), "q", id="mass_matrix-q"),
        pytest.param(lambda m, d, x, z: dynamics.gravity_force(m, d, x), "q", id="gravity-q"),
        pytest.param(lambda m, d, x, z: dynamics.bias_force(m, d, x, z), "q", id="bias-q"),
        pytest.param(lambda m, d, x, z: dynamics.bias_force(m, d, z, x), "qd", id="bias-qd"),
        pytest.param(
            lambda m, d, x, z: dynamics.forward_dynamics(m, d, z, x, z),
            "qd",
            id="forward_dynamics-qd",
        ),
        pytest.param(
            lambda m, d, x, z: dynamics.forward_dynamics(m, d, z, z, x),
            "Q",
            id="forward_dynamics-Q",
        ),
        pytest.param(
            lambda m, d, x, z: forces.spring_damper_force(m, d, x, z),
            "q",
            id="spring_damper_force-q",
        ),
    ],
)
@pytest.mark.parametrize("make_bad", [_nan_at_0, _inf_at_last], ids=["nan", "inf"])
def test_non_finite_state_rejected(pendulum, call, bad, make_bad):
    model, data = pendulum
    x = make_bad(model.nv)
    with pytest.raises(NonFiniteError, match=rf"^{bad} contains NaN or infinite"):
        call(model, data, x, np.zeros(model.nv))


def test_mass_matrix_rejects_nan_q(pendulum):
    model, data = pendulum
    q = np.array([0.3, np.nan])
    with pytest.raises(NonFiniteError):
        dynamics.mass_matrix(model, data, q)
    # the model is still usable afterwards
    A = dynamics.mass_matrix(model, data, np.array([0.3, -0.2]))
    assert_close(A, A.T, rel=MIN_REL, what="mass matrix symmetry")


# --- gimbal lock ----------------------------------------------------------------------


def test_gimbal_lock_raises():
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        euler123_angles(euler123(np.array([0.1, np.pi / 2, 0.2])))
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        euler123_angles(euler123(np.array([0.1, -np.pi / 2, 0.2])))
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        euler_matrix_inverse(np.array([0.0, np.pi / 2, 0.0]))
    with pytest.raises(SingularConfigurationError, match="gimbal lock"):
        euler_matrix_inverse(np.array([0.0, -np.pi / 2, 0.0]))


@pytest.mark.parametrize("theta", [np.pi / 2 - 1e-3, -(np.pi / 2 - 1e-3)], ids=["+", "-"])
def test_near_gimbal_lock_works(theta):
    phi = np.array([0.1, theta, 0.2])
    angles = euler123_angles(euler123(phi))
    conditioning = 1.0 / np.cos(theta)  # the angles' sensitivity to rounding in the matrix
    assert_close(angles, phi, rel=16 * EPS * conditioning, what="angles")
    inverse, matrix = euler_matrix_inverse(phi), euler_matrix(phi)
    assert_close(
        inverse @ matrix,
        np.eye(3),
        rel=64 * EPS,
        scale=np.abs(inverse).max() * np.abs(matrix).max(),
        what="E⁻¹ E",
    )
