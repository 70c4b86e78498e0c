"""Read and check rt70's extension elements of a URDF file (docs/urdf-extensions.md).

One job: once the links and joints of the tree are read (:mod:`rt70.urdf.reader`), turn
the ``<rt70:...>`` elements at the top of ``<robot>`` into the description's gravity,
joint springs, bushings and strut packages, loops, drives, winds, air density, no-slip
constraints, the mount, the optics and optical points and the modal bodies, refusing
what is wrong with an :class:`~rt70.errors.ExtensionError` naming the file and the
element. The drives, winds,
no-slip constraints, the mount and the optics have modules of their own
(:mod:`rt70.urdf.drives`, :mod:`rt70.urdf.wind`, :mod:`rt70.urdf.no_slip`,
:mod:`rt70.urdf.mount`, :mod:`rt70.urdf.optics`); the others are read here.
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

from rt70.errors import ExtensionError
from rt70.physics.rotations import rpy_matrix, rpy_of_matrix
from rt70.urdf.beams import read_beam
from rt70.urdf.description import (
    Bushing,
    FrameRef,
    Joint,
    JointSpring,
    Loop,
    OpticalPoint,
    RobotDescription,
)
from rt70.urdf.drives import read_drive
from rt70.urdf.elements import ZERO3, ElementReader
from rt70.urdf.modal_body import read_modal_body
from rt70.urdf.mount import read_mount
from rt70.urdf.no_slip import read_no_slip
from rt70.urdf.optics import read_optics
from rt70.urdf.text import RT70_NS
from rt70.urdf.wind import check_wind_surfaces, read_air, read_wind

#: Kinds of ``<rt70:loop>`` and their number of constraint rows.
LOOP_TYPES = {"point": 3, "frame": 6}


def read_extensions(
    reader: ElementReader, root: ET.Element, desc: RobotDescription
) -> RobotDescription:
    """The description with the rt70 extension elements of ``root`` read into it.

    The lists of ``desc`` (springs, bushings, loops, drives, optical points) and its
    gravity are filled in place; the other elements are set on a copy when the file has any.

    Parameters
    ----------
    reader : ElementReader
        The reader of the file (its name for messages, the attribute readers).
    root : xml.etree.ElementTree.Element
        The file's ``<robot>`` element, checked by :func:`rt70.urdf.schema.check_scene`.
    desc : RobotDescription
        The links and joints already read and checked (the tree).

    Raises
    ------
    ExtensionError
        If an element is wrong (a missing or unknown link or joint, a negative gain, two
        elements of one kind with one name, …); NonFiniteError or MagnitudeError for a
        number that is NaN, infinite or too large.
    """
    ns = "{" + RT70_NS + "}"
    winds, air, no_slips, mount, optics, beams, modal = [], [], [], [], [], [], []  # copied
    joints = {j.name: j for j in desc.joints}  # one lookup per spring: linear time
    for elem in root:
        if not isinstance(elem.tag, str) or not elem.tag.startswith(ns):
            continue
        kind = elem.tag[len(ns) :]  # one of rt70.urdf.vocabulary.RT70's, checked
        if kind == "gravity":
            desc.gravity[:] = reader.numbers(elem, "xyz", 3)
        elif kind == "joint_spring":
            desc.joint_springs.append(_joint_spring(reader, elem, joints))
        elif kind == "bushing":
            desc.bushings.append(_bushing(reader, elem, desc))
        elif kind == "loop":
            desc.loops.append(_loop(reader, elem, desc))
        elif kind == "strut_package":
            desc.bushings.extend(_strut_package(reader, elem, desc))
        elif kind == "drive":
            desc.drives.append(read_drive(reader, elem, desc, joints))
        elif kind == "wind":
            winds.append(read_wind(reader, elem, desc, winds))
        elif kind == "air":
            air.append(read_air(reader, elem))
        elif kind == "no_slip":
            no_slips.append(read_no_slip(reader, elem, desc, no_slips))
        elif kind == "mount":
            mount.append(elem)  # read once every drive of the file is known
        elif kind == "optics":
            optics.append(elem)  # read once every optical point of the file is known
        elif kind == "beam":
            beams.append(read_beam(reader, elem))  # its elements read as any other
        elif kind == "modal_body":
            modal.append(read_modal_body(reader, elem, desc))
        elif kind == "optical_point":
            name = reader.name_of(elem)
            link = reader.link_ref(elem, "link", desc, f"<rt70:optical_point name='{name}'>")
            desc.optical_points.append(OpticalPoint(name, link, reader.numbers(elem, "xyz", 3)))
        else:  # a kind declared in RT70 must be read here, never skipped
            raise NotImplementedError(f"<rt70:{kind}> is declared but not read")
    _check_unique_names(reader, desc)
    check_wind_surfaces(reader, winds, tuple(modal))
    if not (winds or air or no_slips or mount or optics or beams or modal):
        return desc
    return dataclasses.replace(
        desc,
        winds=tuple(winds),
        air_density=air[0] if air else desc.air_density,
        no_slips=tuple(no_slips),
        mount=read_mount(reader, mount[0], joints, desc.drives) if mount else None,
        optics=read_optics(reader, optics[0], desc) if optics else None,
        beams=tuple(beams),
        modal_bodies=_unique_bodies(reader, modal),
    )


def _unique_bodies(reader: ElementReader, bodies: list) -> tuple:
    """The modal bodies, refusing two of one name (their coordinates are named by it)."""
    names = [b.name for b in bodies]
    for name in names:
        if names.count(name) > 1:
            raise reader.fail(ExtensionError, f"two <rt70:modal_body> elements named '{name}'")
    return tuple(bodies)


def _check_unique_names(reader: ElementReader, desc: RobotDescription) -> None:
    """Refuse two elements of one kind with one name: results are named by them.

    Springs, bushings (a strut is ``package/strut``) and optical points each name an
    output, a row or a column; a second one of a name would silently shadow the
    first. (Drives, winds and loops are checked where they are read.)
    """
    for kind, elements in (
        ("<rt70:joint_spring>", desc.joint_springs),
        ("<rt70:bushing> or <rt70:strut>", desc.bushings),
        ("<rt70:optical_point>", desc.optical_points),
    ):
        seen: set[str] = set()
        for element in elements:
            if element.name in seen:
                raise reader.fail(ExtensionError, f"two {kind} elements named '{element.name}'")
            seen.add(element.name)


def _joint_spring(reader: ElementReader, elem: ET.Element, joints: dict[str, Joint]) -> JointSpring:
    """``<rt70:joint_spring>``: a spring and damper on one 1-DOF joint."""
    name = reader.name_of(elem)
    where = f"<rt70:joint_spring name='{name}'>"
    joint = reader.one_dof_joint(elem, joints, where)
    k, d = reader.gains(elem, 1, where)
    return JointSpring(name, joint.name, float(k[0]), float(d[0]))


def _frame(
    reader: ElementReader, elem: ET.Element, tag: str, desc: RobotDescription, where: str
) -> FrameRef:
    """The frame ``<rt70:{tag}>`` of ``elem``: a link and a pose in it."""
    sub = elem.find(f"{{{RT70_NS}}}{tag}")  # exactly one (RT70)
    link = reader.link_ref(sub, "link", desc, f"{where} <rt70:{tag}>")
    return FrameRef(
        link, reader.numbers(sub, "xyz", 3, ZERO3), reader.numbers(sub, "rpy", 3, ZERO3)
    )


def _bushing(reader: ElementReader, elem: ET.Element, desc: RobotDescription) -> Bushing:
    """``<rt70:bushing>``: six-axis stiffness and damping between two frames."""
    name = reader.name_of(elem)
    where = f"<rt70:bushing name='{name}'>"
    f1 = _frame(reader, elem, "frame1", desc, where)
    f2 = _frame(reader, elem, "frame2", desc, where)
    k, d = reader.gain_matrices(elem, where)
    return Bushing(name, f1, f2, k, d)


def _loop(reader: ElementReader, elem: ET.Element, desc: RobotDescription) -> Loop:
    """``<rt70:loop>``: two frames that coincide (docs/loops.md)."""
    name = reader.name_of(elem)
    where = f"<rt70:loop name='{name}'>"
    if any(loop.name == name for loop in desc.loops):
        raise reader.fail(ExtensionError, f"{where}: two loops named '{name}'")
    kind = elem.get("type", "point")
    if kind not in LOOP_TYPES:
        raise reader.fail(
            ExtensionError,
            f"{where}: type '{kind}' is not one of {', '.join(LOOP_TYPES)}",
        )
    f1 = _frame(reader, elem, "frame1", desc, where)
    sub = elem.find(f"{{{RT70_NS}}}frame2")
    if sub is not None and sub.get("link") == "world" and "world" not in desc.links:
        f2 = FrameRef(  # the ground: the root link, whatever its name
            desc.root, reader.numbers(sub, "xyz", 3, ZERO3), reader.numbers(sub, "rpy", 3, ZERO3)
        )
    else:
        f2 = _frame(reader, elem, "frame2", desc, where)
    if f1.link == f2.link:
        raise reader.fail(
            ExtensionError, f"{where}: frame1 and frame2 are both on link '{f1.link}'"
        )
    return Loop(name, kind, f1, f2)


def _strut_package(
    reader: ElementReader, elem: ET.Element, desc: RobotDescription
) -> list[Bushing]:
    name = reader.name_of(elem)
    where = f"<rt70:strut_package name='{name}'>"
    parent = reader.link_ref(elem, "parent", desc, where)
    child = reader.link_ref(elem, "child", desc, where)
    origin_xyz = reader.numbers(elem, "xyz", 3, ZERO3)
    origin_rot = rpy_matrix(reader.numbers(elem, "rpy", 3, ZERO3))
    struts = []
    for sub in elem.findall(f"{{{RT70_NS}}}strut"):
        sname = reader.name_of(sub)
        r_s = reader.numbers(sub, "xyz", 3, ZERO3)
        rpy_s = reader.numbers(sub, "rpy", 3, ZERO3)
        k, d = reader.gain_matrices(sub, f"{where} <rt70:strut name='{sname}'>")
        # frame 1 = package origin ∘ (r_s, c_s), expressed in the parent link
        f1_xyz = origin_xyz + origin_rot @ r_s
        f1_rpy = rpy_of_matrix(origin_rot @ rpy_matrix(rpy_s))
        struts.append(
            Bushing(
                f"{name}/{sname}",
                FrameRef(parent, f1_xyz, f1_rpy),
                FrameRef(child, r_s, rpy_s),
                k,
                d,
                package=name,
            )
        )
    return struts
