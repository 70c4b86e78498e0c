"""The beam element ``<rt70:beam>``: a slender member as rigid finite elements.

One job: turn each ``<rt70:beam>`` of a URDF text into the links, joints and joint
springs of the rigid finite element method (RFEM; Wittbrodt, Adamiec-Wójcik & Wojciech,
*Dynamics of Flexible Multibody Systems: Rigid Finite Element Method*, Springer 2006,
ch. 2), written into the text before either side parses it, so the textbook side and
Pinocchio read the beam as ordinary bodies and springs (docs/beams.md).

The division (the book's "primary" and "secondary" division): the member of length L is
cut into ``n`` equal primary segments of length ``ℓ = L/n``; a spring-damping element
(sde) sits at the middle of each, at ``x_i = (i − ½) ℓ``; the rigid finite elements
(rfe) are the pieces between them — rfe 0 the half segment ``[0, ℓ/2]`` fixed to the
parent (the clamp), rfe 1 … n−1 full segments, rfe n the half segment at the free end.
Each rfe carries the mass and inertia of its piece of the beam,

    m = ρ A ℓ_e,  I_xx = ρ (I_y + I_z) ℓ_e,  I_yy = ρ I_y ℓ_e + m ℓ_e²/12,
    I_zz = ρ I_z ℓ_e + m ℓ_e²/12                         (about its centre),

and each sde the stiffness of one primary segment on each of its coordinates (the
relative motion of the two rfes at ``x_i``, in the beam frame of the proximal rfe):

    axial EA/ℓ,  shear G A_sy/ℓ and G A_sz/ℓ,  torsion GJ/ℓ,  bending EI_y/ℓ and EI_z/ℓ,

a damper ``β`` times each (stiffness-proportional, Rayleigh's ``D = β C``). The sde is a
chain of one-coordinate joints at ``x_i`` — prismatic x (axial, unless ``axial="false"``),
prismatic y and z (only for a given shear area: Timoshenko; without one the section does
not shear: Euler–Bernoulli), revolute x, y, z — joined by massless links, each joint with
its ``<rt70:joint_spring>``.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np

from rt70.errors import ExtensionError
from rt70.urdf.beam_record import Beam
from rt70.urdf.elements import ElementReader
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

#: Primary segments of a beam without a ``segments`` attribute (docs/beams.md: the
#: cantilever's and the free–free beam's first three frequencies at this division).
DEFAULT_SEGMENTS = 10


#: The comment that marks a beam already written into a text (the expansion is idempotent).
_MARK = "rt70:beam '{name}' as rigid finite elements"


def read_beam(reader: ElementReader, elem: ET.Element) -> Beam:
    """The :class:`Beam` of one ``<rt70:beam>`` element (its attributes checked).

    Raises
    ------
    ExtensionError
        For a missing or non-positive property, both or neither of ``G`` and ``nu``, a
        Poisson's ratio outside (−1, ½], a ``segments`` that is not a whole number ≥ 1,
        an ``axial`` other than true or false; NonFiniteError or MagnitudeError for a
        number that is NaN, infinite or too large.
    """
    name = reader.name_of(elem)
    where = f"<rt70:beam name='{name}'>"

    def positive(attr: str, default: float | None = None) -> float:
        value = reader.number(elem, attr, default)
        if not value > 0.0:
            raise reader.fail(ExtensionError, f'{where}: {attr}="{elem.get(attr)}" must be > 0')
        return value

    if ("G" in elem.attrib) == ("nu" in elem.attrib):
        raise reader.fail(
            ExtensionError, f"{where}: give the shear modulus G or Poisson's ratio nu (one of them)"
        )
    E = positive("E")
    if "G" in elem.attrib:
        G = positive("G")
    else:
        nu = reader.number(elem, "nu")
        if not -1.0 < nu <= 0.5:
            raise reader.fail(ExtensionError, f'{where}: nu="{elem.get("nu")}" is not in (-1, 0.5]')
        G = E / (2.0 * (1.0 + nu))
    raw = elem.get("segments", str(DEFAULT_SEGMENTS))
    if not re.fullmatch(r"\s*[0-9]+\s*", raw) or int(raw) < 1:
        raise reader.fail(
            ExtensionError, f'{where}: segments="{raw}" is not a whole number of at least 1'
        )
    axial = elem.get("axial", "true").strip()
    if axial not in ("true", "false"):
        raise reader.fail(ExtensionError, f'{where}: axial="{axial}" is not true or false')
    beta = reader.number(elem, "damping", 0.0)
    if beta < 0.0:
        raise reader.fail(ExtensionError, f'{where}: damping="{elem.get("damping")}" is negative')
    return Beam(
        name=name,
        parent=elem.get("parent", ""),
        child=elem.get("child"),
        xyz=reader.numbers(elem, "xyz", 3, np.zeros(3)),
        rpy=reader.numbers(elem, "rpy", 3, np.zeros(3)),
        length=positive("length"),
        segments=int(raw),
        E=E,
        G=G,
        rho=positive("rho"),
        A=positive("A"),
        Iy=positive("Iy"),
        Iz=positive("Iz"),
        J=positive("J"),
        Asy=positive("Asy") if "Asy" in elem.attrib else None,
        Asz=positive("Asz") if "Asz" in elem.attrib else None,
        axial=axial == "true",
        beta=beta,
    )


def expand_beams(text: str, source: str = "<string>") -> str:
    """The text with each ``<rt70:beam>`` written out as rfes, sdes and joint springs.

    The beam elements stay (the reader records them); the generated elements are
    inserted before ``</robot>`` after a comment naming the beam, and a beam whose comment
    is already there is left alone, so the expansion is idempotent. A text without beams
    is returned as it is, unparsed.

    Raises
    ------
    ExtensionError
        As :func:`read_beam`, or when a generated name is taken by a link or joint of the
        file.
    UrdfError
        If the text is not well-formed XML (and what :func:`rt70.urdf.schema.check_scene`
        refuses).
    """
    if "beam" not in text or not re.search(r"<[\w.-]+:beam\b", text):
        return text
    refuse_entities(text, source)
    root, prefixes = parse(text, source)
    refuse_xacro(root, source)
    beams = root.findall(f"{{{RT70_NS}}}beam")
    pending = [e for e in beams if _MARK.format(name=e.get("name", "")) not in text]
    if not pending:
        return text
    check_scene(root, source, prefixes)
    reader = ElementReader(source)
    taken = link_and_joint_names(root)
    prefix = min((p for p in prefixes.get(RT70_NS, ()) if p), default="rt70")
    blocks = [_beam_xml(read_beam(reader, e), prefix, taken, reader) for e in pending]
    return insert_before_robot_end(text, blocks)


def _beam_xml(beam: Beam, prefix: str, taken: set[str], reader: ElementReader) -> str:
    """The URDF elements of one beam (links, joints, joint springs), after its comment.

    Parameters
    ----------
    beam : Beam
        The beam, its attributes checked.
    prefix : str
        The prefix the document binds to rt70's namespace (for the joint springs).
    taken : set of str
        The link and joint names already in the document; the beam's are added.
    reader : ElementReader
        The file's reader, for the error naming the file.
    """
    where = f"<rt70:beam name='{beam.name}'>"
    out = [f"\n  <!-- {_MARK.format(name=beam.name)} (docs/beams.md) -->\n"]
    names: list[str] = []

    def name(new: str) -> str:
        if new in taken:
            raise reader.fail(
                ExtensionError, f"{where}: the generated name '{new}' is taken by the file"
            )
        names.append(new)
        return new

    lengths = beam.element_lengths()
    for i, ell in enumerate(lengths):
        out.append(_rfe_link(name(beam.links[i]), beam, ell))
    out.append(
        _joint(name(f"{beam.name}_clamp"), "fixed", beam.parent, beam.links[0], beam.xyz, beam.rpy)
    )
    coordinates = beam.coordinates()
    for i in range(1, beam.segments + 1):
        previous = beam.links[i - 1]
        offset = np.array([lengths[i - 1], 0.0, 0.0])  # proximal rfe's frame → sde point
        for k, (coord, jtype, axis, stiffness) in enumerate(coordinates):
            last = k == len(coordinates) - 1
            child = beam.links[i] if last else name(f"{beam.name}_sde{i}_{coord}_link")
            if not last:
                out.append(f'  <link name="{child}"/>\n')
            joint = name(f"{beam.name}_sde{i}_{coord}")
            out.append(
                _joint(joint, jtype, previous, child, offset if k == 0 else np.zeros(3), None, axis)
            )
            out.append(
                f'  <{prefix}:joint_spring name="{joint}" joint="{joint}" '
                f'stiffness="{float(stiffness)!r}" damping="{float(beam.beta * stiffness)!r}"/>\n'
            )
            previous = child
    out.append(f'  <link name="{name(beam.end_link)}"/>\n')
    tip = np.array([lengths[-1], 0.0, 0.0])
    out.append(_joint(name(f"{beam.name}_end_joint"), "fixed", beam.links[-1], beam.end_link, tip))
    if beam.child is not None:
        out.append(
            _joint(
                name(f"{beam.name}_child_joint"), "fixed", beam.end_link, beam.child, np.zeros(3)
            )
        )
    taken.update(names)
    return "".join(out)


def _rfe_link(link: str, beam: Beam, ell: float) -> str:
    """A rigid finite element of length ``ell``: its frame at its proximal end.

    Its ``<visual>`` (for URDF viewers; neither side reads it) is a cylinder along the
    element of radius ``sqrt((I_y + I_z)/A)``, the section's polar radius of gyration — a
    thin tube's radius.
    """
    ell = float(ell)
    m = beam.rho * beam.A * ell
    bending = m * ell**2 / 12.0
    ixx = beam.rho * (beam.Iy + beam.Iz) * ell
    iyy = beam.rho * beam.Iy * ell + bending
    izz = beam.rho * beam.Iz * ell + bending
    radius = float(np.sqrt((beam.Iy + beam.Iz) / beam.A))
    return (
        f'  <link name="{link}"><inertial><origin xyz="{ell / 2!r} 0 0"/>'
        f'<mass value="{m!r}"/><inertia ixx="{ixx!r}" ixy="0" ixz="0" iyy="{iyy!r}" iyz="0" '
        f'izz="{izz!r}"/></inertial><visual><origin xyz="{ell / 2!r} 0 0" '
        f'rpy="0 {np.pi / 2!r} 0"/><geometry><cylinder radius="{radius!r}" length="{ell!r}"/>'
        f"</geometry></visual></link>\n"
    )


def _joint(
    name: str,
    jtype: str,
    parent: str,
    child: str,
    xyz: np.ndarray,
    rpy: np.ndarray | None = None,
    axis: str | None = None,
) -> str:
    """One generated ``<joint>`` (with wide limits when it moves)."""
    origin = " ".join(repr(float(v)) for v in xyz)
    rot = "" if rpy is None else ' rpy="' + " ".join(repr(float(v)) for v in rpy) + '"'
    moving = "" if axis is None else f'<axis xyz="{axis}"/>{GENERATED_LIMIT}'
    return (
        f'  <joint name="{name}" type="{jtype}"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{origin}"{rot}/>{moving}</joint>\n'
    )
