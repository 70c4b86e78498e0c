"""``<rt70:interface>``: a link attached to a node of a modal body.

One job: the links and joints that carry an interface link on its node, written into the
text before either side parses it (like :mod:`rt70.urdf.beams`), and the
:class:`~rt70.urdf.modal_record.Interface` records that say how their coordinates follow
the body's modal coordinates (docs/fe-models.md, "Links on the nodes").

An element ``<rt70:interface link="tip" node="12"/>`` inside ``<rt70:modal_body>``
becomes a chain from the body's link: a prismatic joint along x at the node's position
``x_n``, prismatic y and z, and — when the modal body file gives the nodes' rotations —
revolute x, y and z (joints ``tip__x`` … ``tip__rz``), joined by massless links
(``tip__x_link`` …), the last of them the link ``tip``. The
chain's coordinates are not free: the three translations are ``Φ_n η`` (the node's
displacement) and the three angles ``Ψ_n η`` (its small rotation), so ``tip`` moves as
the node does: ``T = T_b · Trans(x_n + Φ_n η) · Rx(θ_x) Ry(θ_y) Rz(θ_z)``. To first order
in η the three angles are the rotation vector; the product is exact on both sides, so
they agree to rounding at any η. The file's joints then hang what they carry on ``tip``.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from rt70.errors import ExtensionError
from rt70.urdf.elements import ElementReader
from rt70.urdf.modal_file import ModalArrays, read_modal_file
from rt70.urdf.modal_record import Interface
from rt70.urdf.schema import check_scene
from rt70.urdf.text import (
    GENERATED_LIMIT,
    RT70_NS,
    insert_before_robot_end,
    link_and_joint_names,
    parse,
    refuse_entities,
    refuse_xacro,
)

#: The chain's joints: name suffix, type and axis, translations first.
CHAIN = (
    ("x", "prismatic", "1 0 0"),
    ("y", "prismatic", "0 1 0"),
    ("z", "prismatic", "0 0 1"),
    ("rx", "revolute", "1 0 0"),
    ("ry", "revolute", "0 1 0"),
    ("rz", "revolute", "0 0 1"),
)


#: The comment that marks an interface already written into a text (idempotent).
_MARK = "rt70:interface '{link}' on a node of modal body '{body}'"


def chain_joints(link: str, rotations: bool) -> tuple[str, ...]:
    """The chain joints of interface ``link``: ``link__x`` … (``link__rz`` with rotations)."""
    return tuple(f"{link}__{sfx}" for sfx, _, _ in CHAIN[: 6 if rotations else 3])


def body_file(reader: ElementReader, elem: ET.Element) -> Path:
    """The modal body file an element names, beside the URDF file when relative."""
    path = Path(elem.get("file", ""))
    if not path.is_absolute() and Path(reader.source).is_file():
        path = Path(reader.source).parent / path
    return path


def read_interfaces(
    reader: ElementReader, elem: ET.Element, arrays: ModalArrays, keep: int, where: str
) -> tuple[Interface, ...]:
    """The :class:`Interface` records of a ``<rt70:modal_body>`` element's children.

    Parameters
    ----------
    reader : ElementReader
        The file's reader.
    elem : xml.etree.ElementTree.Element
        The ``<rt70:modal_body>`` element.
    arrays : ModalArrays
        Its file's arrays.
    keep : int
        The modes kept (the rows are over the first ``keep``).
    where : str
        The element, for the messages.

    Raises
    ------
    ExtensionError
        A node that is not a whole number indexing the file's nodes, or two interfaces
        with one link.
    """
    out: list[Interface] = []
    for sub in elem.findall(f"{{{RT70_NS}}}interface"):
        link, node = sub.get("link", ""), _node(sub, arrays, where)
        if any(i.link == link for i in out):
            raise ExtensionError(f"{where}: two <rt70:interface> elements with link '{link}'")
        rows = arrays.shapes[node, :, :keep]
        if arrays.rotations is not None:
            rows = np.vstack([rows, arrays.rotations[node, :, :keep]])
        out.append(Interface(link, node, chain_joints(link, arrays.rotations is not None), rows))
    return tuple(out)


def _node(sub: ET.Element, arrays: ModalArrays, where: str) -> int:
    """The ``node`` attribute of an interface: an index into the file's nodes."""
    raw, count = sub.get("node", ""), arrays.nodes.shape[0]
    if not re.fullmatch(r"\s*[0-9]+\s*", raw) or int(raw) >= count:
        raise ExtensionError(
            f"{where}: <rt70:interface link='{sub.get('link', '')}'> node=\"{raw}\" is not "
            f"a node of the file (0 … {count - 1})"
        )
    return int(raw)


def expand_interfaces(text: str, source: str = "<string>") -> str:
    """The text with each ``<rt70:interface>`` written out as its chain of links and joints.

    The elements stay (the reader records them); the generated links and joints go before
    ``</robot>`` after a comment naming the interface, and an interface whose comment is
    there already is left alone. A text without interfaces is returned unparsed.

    Raises
    ------
    ExtensionError
        A missing or wrong modal body file or node, or a generated name that the file's
        links or joints already use.
    UrdfError
        If the text is not well-formed XML (and what
        :func:`rt70.urdf.schema.check_scene` refuses).
    """
    if "interface" not in text or not re.search(r"<[\w.-]+:interface\b", text):
        return text
    refuse_entities(text, source)
    root, prefixes = parse(text, source)
    refuse_xacro(root, source)
    bodies = root.findall(f"{{{RT70_NS}}}modal_body")
    pending = [
        (body, sub)
        for body in bodies
        for sub in body.findall(f"{{{RT70_NS}}}interface")
        if _MARK.format(link=sub.get("link", ""), body=body.get("name", "")) not in text
    ]
    if not pending:
        return text
    check_scene(root, source, prefixes)
    reader = ElementReader(source)
    taken = link_and_joint_names(root)
    blocks, files = [], {}
    for body, sub in pending:
        name = body.get("name", "")
        where = f"{source}: <rt70:modal_body name='{name}'>"
        if name not in files:
            files[name] = read_modal_file(body_file(reader, body), where)
        arrays = files[name]
        blocks.append(_chain_xml(body.get("link", ""), name, sub.get("link", ""),
                                 arrays.nodes[_node(sub, arrays, where)],
                                 arrays.rotations is not None, taken, where))  # fmt: skip
    return insert_before_robot_end(text, blocks)


def _chain_xml(
    parent: str, body: str, link: str, at: np.ndarray, rotations: bool, taken: set[str],
    where: str,
) -> str:  # fmt: skip
    """The links and joints of one interface's chain, after its comment."""
    out = [f"\n  <!-- {_MARK.format(link=link, body=body)} (docs/fe-models.md) -->\n"]
    joints = chain_joints(link, rotations)
    links = [f"{j}_link" for j in joints[:-1]] + [link]
    for new in (*joints, *links):
        if new in taken or not new:
            raise ExtensionError(f"{where}: the generated name '{new}' is taken by the file")
        taken.add(new)
    xyz = " ".join(repr(float(v)) for v in at)
    for i, (joint, child) in enumerate(zip(joints, links, strict=True)):
        _, kind, axis = CHAIN[i]
        origin = xyz if i == 0 else "0 0 0"
        out.append(f'  <link name="{child}"/>\n')
        out.append(
            f'  <joint name="{joint}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{origin}" rpy="0 0 0"/>'
            f'<axis xyz="{axis}"/>{GENERATED_LIMIT}</joint>\n'
        )
        parent = child
    return "".join(out)
