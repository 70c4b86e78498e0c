"""A mistake in a model must not pass silently (issue 21 §2; rt70/urdf/schema.py).

rt70's extension elements are checked against one table, :data:`rt70.urdf.vocabulary.RT70`:
an unknown or misspelt attribute, a missing required one, an unknown child, a child too
many or too few, text content, a misplaced rt70 element, a namespace that looks like
rt70's and an undeclared ``rt70:`` prefix are each an :class:`~rt70.errors.ExtensionError`
naming the file, the element and the attribute. The parametrized tests walk the table,
so a new element kind is covered as soon as it is declared. Standard URDF keeps its
tolerance: an unknown attribute is one :class:`~rt70.errors.Rt70Warning` and changes
nothing.
"""

from __future__ import annotations

import re
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

import rt70.cli.main
from rt70.errors import ExtensionError, Rt70Warning
from rt70.model.scene import URDF_DIR, scene_from_text
from rt70.reference import dynamics as reference
from rt70.scenes import synthetic
from rt70.textbook import dynamics
from rt70.urdf import read_urdf, read_urdf_string
from rt70.urdf.schema import RT70, Spec, check_scene
from rt70.urdf.text import RT70_NS

DOCS = Path(__file__).resolve().parents[1] / "docs"
DATA = Path(__file__).resolve().parent / "data"
PENDULUM = URDF_DIR / "double_pendulum.urdf"
GRAVITY = '<rt70:gravity xyz="0 -9.81 0"/>'


def pendulum_with(element: str, old: str = GRAVITY) -> str:
    """The double pendulum scene with ``old`` (its gravity element) replaced."""
    text = PENDULUM.read_text(encoding="utf-8")
    assert old in text
    return text.replace(old, element)


def refusal(text: str, source: str = "scene.urdf") -> str:
    """The one-line message of the :class:`ExtensionError` reading ``text`` raises."""
    with pytest.raises(ExtensionError) as excinfo:
        read_urdf_string(text, source=source)
    message = str(excinfo.value)
    assert message.startswith(f"{source}: ") and "\n" not in message, message
    return message


def read_warnings(text: str, source: str = "scene.urdf") -> list[str]:
    """The :class:`Rt70Warning` messages reading ``text`` gives."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", Rt70Warning)
        read_urdf_string(text, source=source)
    return [str(w.message) for w in caught if issubclass(w.category, Rt70Warning)]


# --- the issue's case -------------------------------------------------------------------


def test_misspelt_stiffness_is_refused_with_the_nearest_name():
    """``stifness="7e8"`` used to be read as stiffness 0: a rigid 0 Hz "mode"."""
    message = refusal(
        pendulum_with('<rt70:joint_spring name="s" joint="joint1" stifness="7e8"/>'),
        source="typo.urdf",
    )
    assert message.startswith("typo.urdf: <rt70:joint_spring name='s'>: ")
    assert "unknown attribute 'stifness'" in message
    assert "did you mean 'stiffness'?" in message


def test_a_spring_without_stiffness_is_refused():
    message = refusal(pendulum_with('<rt70:joint_spring name="s" joint="joint1" damping="3"/>'))
    assert "<rt70:joint_spring name='s'> lacks attribute 'stiffness'" in message


def test_an_explicit_zero_stiffness_is_a_damper_alone():
    desc = read_urdf_string(
        pendulum_with('<rt70:joint_spring name="s" joint="joint1" stiffness="0" damping="3"/>')
    )
    assert [(s.stiffness, s.damping) for s in desc.joint_springs] == [(0.0, 3.0)]


@pytest.mark.parametrize(
    ("kind", "first", "second"),
    [
        (
            "<rt70:optical_point>",
            '<rt70:optical_point name="f" link="link1" xyz="0 0 0"/>',
            '<rt70:optical_point name="f" link="link2" xyz="0 0 1"/>',
        ),
        (
            "<rt70:joint_spring>",
            '<rt70:joint_spring name="s" joint="joint1" stiffness="1"/>',
            '<rt70:joint_spring name="s" joint="joint2" stiffness="2"/>',
        ),
    ],
    ids=["optical_point", "joint_spring"],
)
def test_two_elements_of_one_kind_and_name_are_refused(kind, first, second):
    """A second element of a name would shadow the first in every named result."""
    message = refusal(pendulum_with(GRAVITY + first + second))
    assert f"two {kind} elements named" in message


# --- every kind of the table ------------------------------------------------------------


def kinds(spec: Spec = RT70, path: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], Spec]]:
    """Every rt70 element kind of the table, as (path of local names from <robot>, spec)."""
    for local, child in spec.children.items():
        yield (*path, local), child.spec
        yield from kinds(child.spec, (*path, local))


KINDS = dict(kinds())
ATTRIBUTES = [(path, attr) for path, spec in KINDS.items() for attr in spec.attributes]
REQUIRED = [(path, attr) for path, spec in KINDS.items() for attr in spec.required]
COUNTED = [
    (path, local, child)
    for path, spec in [((), RT70), *KINDS.items()]
    for local, child in spec.children.items()
    if child.least > 0 or child.most is not None
]


def _ids(cases) -> list[str]:
    return ["/".join(case[0]) + (f"@{case[1]}" if len(case) > 1 else "") for case in cases]


Edit = Callable[[dict[str, str], list[str]], None]


def minimal(target: tuple[str, ...], edit: Edit | None = None, count: int | None = None) -> str:
    """A scene holding the rt70 element kind at ``target``, built from the table alone.

    Every element has its required attributes (placeholder values: the table is checked
    before any value is read) and its required children, and the path to ``target`` is
    there; the element at ``target`` is passed to ``edit(attributes, children)`` first,
    and written ``count`` times (default once).
    """

    def elements(path: tuple[str, ...], local: str, child) -> list[str]:
        here = (*path, local)
        n = max(child.least, int(target[: len(here)] == here))
        if here == target and count is not None:
            n = count
        return [element(here, child.spec) for _ in range(n)]

    def element(path: tuple[str, ...], spec: Spec) -> str:
        attrs = {a: "1" for a in spec.required}
        children = [e for local, c in spec.children.items() for e in elements(path, local, c)]
        if path == target and edit is not None:
            edit(attrs, children)
        written = "".join(f' {k}="{v}"' for k, v in attrs.items())
        return f"<rt70:{path[-1]}{written}>{''.join(children)}</rt70:{path[-1]}>"

    top = "".join(e for local, c in RT70.children.items() for e in elements((), local, c))
    return f'<robot name="t" xmlns:rt70="{RT70_NS}"><link name="world"/>{top}</robot>'


def label(path: tuple[str, ...]) -> str:
    """How messages name the element at ``path`` of :func:`minimal` (its name is "1")."""
    return f"<rt70:{path[-1]} name='1'>" if "name" in KINDS[path].required else f"<rt70:{path[-1]}>"


def test_the_table_has_every_kind_the_reader_reads():
    top = {path[0] for path in KINDS}
    assert top == {
        "gravity",
        "joint_spring",
        "bushing",
        "strut_package",
        "optical_point",
        "drive",
        "wind",
        "air",
        "loop",
        "no_slip",
        "mount",
        "optics",
        "beam",
        "modal_body",
    }
    assert set(KINDS) > {("bushing", "frame1"), ("strut_package", "strut"), ("drive", "sector")}


@pytest.mark.parametrize("target", list(KINDS), ids=["/".join(p) for p in KINDS])
def test_the_minimal_element_of_every_kind_passes_the_check(target):
    """The generator of the cases below is right: each case is wrong only by its edit."""
    root = ET.fromstring(minimal(target))
    check_scene(root, "scene.urdf", {RT70_NS: {"rt70"}})


@pytest.mark.parametrize(("target", "attr"), ATTRIBUTES, ids=_ids(ATTRIBUTES))
def test_every_misspelt_attribute_is_refused_with_the_nearest_name(target, attr):
    misspelt = attr + attr[-1]

    def edit(attrs, children):
        attrs.pop(attr, None)
        attrs[misspelt] = "1"

    message = refusal(minimal(target, edit))
    assert label(target) in message or (attr == "name" and f"<rt70:{target[-1]}" in message)
    assert f"unknown attribute '{misspelt}'" in message
    assert f"did you mean '{attr}'?" in message


@pytest.mark.parametrize("target", list(KINDS), ids=["/".join(p) for p in KINDS])
def test_an_unknown_attribute_of_every_kind_is_refused_listing_the_known(target):
    message = refusal(minimal(target, lambda attrs, children: attrs.update(colour="red")))
    assert label(target) in message and "unknown attribute 'colour'" in message
    assert "known: " + ", ".join(KINDS[target].attributes) in message


@pytest.mark.parametrize(("target", "attr"), REQUIRED, ids=_ids(REQUIRED))
def test_every_missing_required_attribute_is_refused(target, attr):
    message = refusal(minimal(target, lambda attrs, children: attrs.pop(attr)))
    if attr == "name":
        assert f"<rt70:{target[-1]}> without a name" in message
    else:
        assert f"{label(target)} lacks attribute '{attr}'" in message


@pytest.mark.parametrize("target", list(KINDS), ids=["/".join(p) for p in KINDS])
def test_an_unknown_child_of_every_kind_is_refused(target):
    message = refusal(minimal(target, lambda attrs, children: children.append("<rt70:bogus/>")))
    assert label(target) in message and "unknown child <rt70:bogus>" in message


@pytest.mark.parametrize("target", list(KINDS), ids=["/".join(p) for p in KINDS])
def test_text_content_of_every_kind_is_refused(target):
    """``<rt70:gravity>0 0 -9.81</rt70:gravity>`` would be read as no gravity element."""
    message = refusal(minimal(target, lambda attrs, children: children.insert(0, "0 0 -9.81")))
    assert label(target) in message and "text '0 0 -9.81' is not read" in message


@pytest.mark.parametrize(("parent", "local", "child"), COUNTED, ids=_ids(COUNTED))
def test_every_child_count_is_enforced(parent, local, child):
    where = label(parent) if parent else "<robot>"
    if child.most is not None:
        message = refusal(minimal((*parent, local), count=child.most + 1))
        many = "more than one" if child.most == 1 else f"more than {child.most}"
        assert f"{where} has {many} <rt70:{local}>" in message
    if child.least > 0:
        message = refusal(minimal((*parent, local), count=child.least - 1))
        assert f"{where} lacks <rt70:{local}>" in message


@pytest.mark.parametrize(
    ("written", "meant"),
    [("joint_sprng", "joint_spring"), ("optical_pont", "optical_point"), ("bushings", "bushing")],
)
def test_a_misspelt_element_is_refused_with_the_nearest_kind(written, meant):
    message = refusal(pendulum_with(f'<rt70:{written} name="x"/>'))
    assert f"unknown rt70 element <rt70:{written}>" in message
    assert f"did you mean <rt70:{meant}>?" in message


def test_a_child_without_the_prefix_is_refused_with_the_prefixed_name():
    text = pendulum_with(
        '<rt70:bushing name="b" stiffness="1 1 1 1 1 1">'
        '<rt70:frame1 link="link1"/><frame2 link="link2"/></rt70:bushing>'
    )
    message = refusal(text)
    assert "<rt70:bushing name='b'>: unknown child <frame2>" in message
    assert "did you mean <rt70:frame2>?" in message


def test_an_rt70_element_inside_a_link_is_refused():
    text = PENDULUM.read_text(encoding="utf-8").replace(
        '<link name="link2">', '<link name="link2"><rt70:optical_point name="p" xyz="0 0 0"/>'
    )
    message = refusal(text)
    assert "<rt70:optical_point name='p'> inside <link name='link2'>" in message


def test_an_rt70_attribute_on_a_standard_element_is_refused():
    text = PENDULUM.read_text(encoding="utf-8").replace(
        '<joint name="joint2" type="revolute">',
        '<joint name="joint2" type="revolute" rt70:stiffness="4">',
    )
    message = refusal(text)
    assert "<joint name='joint2'> attribute 'rt70:stiffness'" in message


def test_the_table_is_the_documented_one():
    """docs/urdf-extensions.md's table of attributes is the table the check enforces."""
    text = (DOCS / "urdf-extensions.md").read_text(encoding="utf-8")
    section = text[text.index("## What each element may carry") :]
    counts = {
        "any": (0, None),
        "at most one": (0, 1),
        "exactly one": (1, 1),
        "one or more": (1, None),
        "one or two": (1, 2),
    }
    documented = {}
    for row in re.findall(r"^\| `<rt70:.*$", section, flags=re.M):
        cells = [c.strip() for c in row.strip("|").split("|")]
        for local in re.findall(r"<rt70:(\w+)>", cells[0]):
            for parent in re.findall(r"<(rt70:\w+|robot)>", cells[1]):
                documented[(parent.removeprefix("rt70:"), local)] = (
                    counts[cells[2]],
                    tuple(re.findall(r"`(\w+)`", cells[3])),
                    tuple(re.findall(r"`(\w+)`", cells[4])),
                )
    declared = {
        (path[-2] if len(path) > 1 else "robot", path[-1]): (
            (parent_child.least, parent_child.most),
            spec.required,
            spec.optional,
        )
        for path, spec in KINDS.items()
        for parent_child in [(KINDS[path[:-1]] if len(path) > 1 else RT70).children[path[-1]]]
    }
    assert documented == declared


# --- namespaces -------------------------------------------------------------------------


LOOK_ALIKES = [
    "urn:rt70:urdf-extension:1",  # the issue's: a letter short
    "urn:rt70:urdf-extensions:2",  # another version
    "URN:RT70:URDF-EXTENSIONS:1",  # case
    "urn:rt70:urdf-extensions:1/",  # a trailing slash
    " urn:rt70:urdf-extensions:1",  # a space
    "http://rt70.org/urdf-extensions",  # another scheme
]


def spring_scene(uri: str, prefix: str = "rt70") -> str:
    text = PENDULUM.read_text(encoding="utf-8").replace(
        f'xmlns:rt70="{RT70_NS}"', f'xmlns:{prefix}="{uri}"'
    )
    return text.replace(
        GRAVITY, f'<{prefix}:joint_spring name="s" joint="joint1" stiffness="7e8"/>'
    )


@pytest.mark.parametrize("uri", LOOK_ALIKES)
def test_a_namespace_that_looks_like_rt70s_is_refused(uri):
    """Every spring in it used to be dropped without a word."""
    message = refusal(spring_scene(uri))
    assert f"<joint_spring> is in the namespace '{uri}', not rt70's '{RT70_NS}'" in message
    assert f'declare xmlns:rt70="{RT70_NS}"' in message


def test_any_namespace_bound_to_the_rt70_prefix_is_refused():
    message = refusal(spring_scene("urn:example:extensions"))
    assert "<joint_spring> is in the namespace 'urn:example:extensions'" in message


def test_an_attribute_in_a_look_alike_namespace_is_refused():
    text = pendulum_with(
        '<rt70:joint_spring name="s" joint="joint1" stiffness="1" xmlns:r="urn:rt70:x" '
        'r:damping="3"/>'
    )
    message = refusal(text)
    assert "attribute 'damping' is in the namespace 'urn:rt70:x'" in message


def test_rt70s_namespace_under_another_prefix_is_rt70s():
    desc = read_urdf_string(spring_scene(RT70_NS, prefix="ext"))
    assert [s.stiffness for s in desc.joint_springs] == [7e8]


def test_an_undeclared_rt70_prefix_is_one_clear_line():
    text = PENDULUM.read_text(encoding="utf-8").replace(f' xmlns:rt70="{RT70_NS}"', "")
    message = refusal(text, source="bare.urdf")
    line = 1 + text[: text.index("<rt70:gravity")].count("\n")
    assert message == (
        f"bare.urdf: line {line}: {GRAVITY}: the prefix 'rt70:' is not declared: "
        f'add xmlns:rt70="{RT70_NS}" to <robot>'
    )


def test_other_namespaces_stay_accepted_without_a_word():
    text = PENDULUM.read_text(encoding="utf-8").replace(
        '<link name="link2">',
        '<link name="link2" xmlns:g="http://gazebosim.org/schema" g:colour="red">'
        '<g:sensor name="cam" type="camera"/>',
    )
    text = text.replace("</robot>", '<gz:plugin xmlns:gz="urn:gz" filename="x.so"/></robot>')
    assert read_warnings(text) == []


# --- standard URDF: warned, read the same -----------------------------------------------


ODD = {  # element as written -> with unknown attributes
    '<axis xyz="0 0 1"/>': '<axis xyz="0 0 1" rpy="0 0 1"/>',
    '<mass value="1"/>': '<mass value="1" units="kg"/>',
    'ixy="0" ixz="0"': 'ixy="0" ixz="0" ixy_="5"',
    '<link name="link1">': '<link name="link1" colour="red">',
}


def odd_pendulum() -> str:
    text = PENDULUM.read_text(encoding="utf-8")
    for plain, odd in ODD.items():
        assert plain in text
        text = text.replace(plain, odd)
    return text


def test_unknown_standard_attributes_are_one_warning_each_and_change_nothing():
    odd, plain = odd_pendulum(), PENDULUM.read_text(encoding="utf-8")
    caught = read_warnings(odd, source="odd.urdf")
    assert sorted(caught) == sorted(
        [
            "odd.urdf: <joint name='joint1'> <axis>: attribute 'rpy' is not URDF, ignored "
            "(also on 1 more <axis>)",
            "odd.urdf: <link name='link1'> <inertial> <mass>: attribute 'units' is not URDF, "
            "ignored (also on 1 more <mass>)",
            "odd.urdf: <link name='link1'> <inertial> <inertia>: attribute 'ixy_' is not URDF, "
            "ignored (did you mean 'ixy'?) (also on 1 more <inertia>)",
            "odd.urdf: <link name='link1'>: attribute 'colour' is not URDF, ignored",
        ]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Rt70Warning)
        scenes = [scene_from_text(t) for t in (odd, plain)]
    q = np.array([0.3, -0.7])
    for side, module in (("textbook", dynamics), ("reference", reference)):
        A = [module.mass_matrix(getattr(s, side), getattr(s, f"{side}_data"), q) for s in scenes]
        g = [module.gravity_force(getattr(s, side), getattr(s, f"{side}_data"), q) for s in scenes]
        assert np.array_equal(A[0], A[1]) and np.array_equal(g[0], g[1]), side  # same numbers


KNOWN = {  # attributes of real files that are standard, or harmless documented extensions
    '<robot name="double_pendulum"': '<robot name="double_pendulum" version="1.0"',
    '<link name="link1">': (
        '<link name="link1" type="camera"><visual name="v" group="g"><origin xyz="0 0 0"/>'
        '<geometry><mesh filename="m.stl" scale="1 1 1"/></geometry>'
        '<material name="grey"><color rgba="1 1 1 1"/><texture filename="t.png"/></material>'
        '</visual><collision name="c" group="1" mask="1"><geometry><cylinder radius="1" '
        'length="1"/></geometry></collision>'
    ),
    '<joint name="joint2" type="revolute">': (
        '<joint name="joint2" type="revolute"><dynamics damping="0" friction="0"/>'
        '<calibration rising="0" falling="0"/><safety_controller soft_lower_limit="-1" '
        'soft_upper_limit="1" k_position="1" k_velocity="1"/>'
    ),
    "</robot>": (
        '<material name="blue"><color rgba="0 0 1 1"/></material><transmission name="t" '
        'type="x"><joint name="joint1"/><actuator name="m"/></transmission>'
        '<gazebo reference="link1"><mu1 value="1"/></gazebo></robot>'
    ),
}


def test_the_attributes_real_files_carry_are_known():
    text = PENDULUM.read_text(encoding="utf-8")
    for plain, known in KNOWN.items():
        text = text.replace(plain, known, 1)
    assert read_warnings(text) == []


# --- rt70's own files -------------------------------------------------------------------


OWN = sorted(URDF_DIR.glob("*.urdf")) + sorted(DATA.glob("*.urdf"))


@pytest.mark.parametrize("path", OWN, ids=[p.name for p in OWN])
def test_rt70s_own_scenes_read_without_a_warning(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", Rt70Warning)
        read_urdf(path)


def test_generated_trees_read_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error", Rt70Warning)
        for seed in range(10):
            read_urdf_string(synthetic.random_tree(seed))
        read_urdf_string(synthetic.elastic_chain(3))
        read_urdf_string(synthetic.balanced_tree(7))


# --- the command line -------------------------------------------------------------------


CLI_CASES = {
    "typo": (
        pendulum_with('<rt70:joint_spring name="s" joint="joint1" stifness="7e8"/>'),
        "did you mean 'stiffness'?",
    ),
    "look-alike": (spring_scene("urn:rt70:urdf-extension:1"), "not rt70's"),
    "undeclared": (
        PENDULUM.read_text(encoding="utf-8").replace(f' xmlns:rt70="{RT70_NS}"', ""),
        "the prefix 'rt70:' is not declared",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CLI_CASES))
def test_cli_refuses_in_one_line_with_exit_2(name, tmp_path):
    text, needle = CLI_CASES[name]
    path = tmp_path / f"{name}.urdf"
    path.write_text(text, encoding="utf-8")
    proc = subprocess.run(
        [sys.executable, "-m", "rt70", "validate", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"rt70: error: {path}: ") and needle in lines[0]


def test_cli_warns_in_one_line_per_attribute_and_checks(tmp_path, capsys):
    path = tmp_path / "odd.urdf"
    path.write_text(odd_pendulum(), encoding="utf-8")
    assert rt70.cli.main.main(["validate", str(path), "--samples", "1"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == len(ODD)
    assert all(line.startswith(f"rt70: warning: {path}: ") for line in err)
