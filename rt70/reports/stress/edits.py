"""URDF rewriting for the stress cases: scene variants made from URDF text in memory.

The XML is rewritten with :mod:`xml.etree.ElementTree`; nothing is written to ``urdf/``.
Each function takes URDF text and returns the edited text (comments dropped).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterable

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.scene import load_scene
from rt70.scenes.urdf_writer import fmt_vec

#: Namespace of the rt70 URDF extension elements (docs/urdf-extensions.md).
RT70_NS = "urn:rt70:urdf-extensions:1"


def _q(tag: str) -> str:
    return f"{{{RT70_NS}}}{tag}"


def _parse(text: str) -> ET.Element:
    return ET.fromstring(text)


def _serialize(root: ET.Element) -> str:
    ET.register_namespace("rt70", RT70_NS)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _numbers(elem: ET.Element, attr: str) -> np.ndarray:
    return np.array([float(x) for x in elem.get(attr, "").split()], dtype=float)


def _scale_attr(elem: ET.Element | None, attr: str, factor) -> None:
    """Multiply the numbers of ``elem.attr`` by ``factor`` (scalar or per entry)."""
    if elem is None or elem.get(attr) is None:
        return
    elem.set(attr, fmt_vec(_numbers(elem, attr) * np.asarray(factor, dtype=float)))


def _gain_elements(root: ET.Element) -> list[tuple[ET.Element, str]]:
    """Every element carrying stiffness/damping: (element, "joint_spring" or "six")."""
    out = [(e, "joint_spring") for e in root.findall(_q("joint_spring"))]
    out += [(e, "six") for e in root.findall(_q("bushing"))]
    for package in root.findall(_q("strut_package")):
        out += [(e, "six") for e in package.findall(_q("strut"))]
    return out


def scale_springs(text: str, stiffness: float = 1.0, damping: float = 1.0) -> str:
    """Every spring's stiffness × ``stiffness`` and every damper × ``damping``.

    Parameters
    ----------
    text : str
        URDF text of the scene.
    stiffness, damping : float, optional
        Factors on every ``<rt70:joint_spring>``, ``<rt70:bushing>`` and
        ``<rt70:strut>``'s stiffness and damping (all entries), dimensionless.

    Returns
    -------
    str
        The rewritten URDF text.
    """
    root = _parse(text)
    for elem, _ in _gain_elements(root):
        _scale_attr(elem, "stiffness", stiffness)
        _scale_attr(elem, "damping", damping)
    return _serialize(root)


def _link(root: ET.Element, name: str) -> ET.Element:
    for link in root.findall("link"):
        if link.get("name") == name:
            return link
    raise Rt70Error(f"no link '{name}'")


def scale_link_inertia(text: str, link: str, factor: float) -> str:
    """Mass and rotational inertia of ``link`` × ``factor`` (centre of mass kept).

    Parameters
    ----------
    text : str
        URDF text of the scene.
    link : str
        Name of the link, which must have an ``<inertial>``.
    factor : float
        Factor on its mass and its six inertia entries, dimensionless.

    Returns
    -------
    str
        The rewritten URDF text.

    Raises
    ------
    Rt70Error
        If there is no such link or it has no ``<inertial>``.
    """
    root = _parse(text)
    inertial = _link(root, link).find("inertial")
    if inertial is None:
        raise Rt70Error(f"link '{link}' has no <inertial>")
    _scale_attr(inertial.find("mass"), "value", factor)
    for attr in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        _scale_attr(inertial.find("inertia"), attr, factor)
    return _serialize(root)


def _named(root: ET.Element, name: str) -> ET.Element:
    for elem, _ in _gain_elements(root):
        if elem.get("name") == name:
            return elem
    raise Rt70Error(f"no spring element '{name}'")


def set_spring_entry(text: str, name: str, index: int, stiffness: float, damping: float) -> str:
    """Set entry ``index`` (0..5: x, y, z, rx, ry, rz) of a bushing's stiffness and damping.

    Parameters
    ----------
    text : str
        URDF text of the scene.
    name : str
        Name of the ``<rt70:bushing>`` (or strut, or joint spring: then index 0).
    index : int
        The entry set: 0..2 translations, 3..5 rotations.
    stiffness : float
        The entry's new stiffness, N/m or N·m/rad.
    damping : float
        The entry's new damping, N·s/m or N·m·s/rad.

    Returns
    -------
    str
        The rewritten URDF text.
    """
    root = _parse(text)
    elem = _named(root, name)
    for attr, value in (("stiffness", stiffness), ("damping", damping)):
        values = _numbers(elem, attr)
        values[index * 7 if values.size == 36 else index] = value  # a 6 × 6's diagonal
        elem.set(attr, fmt_vec(values))
    return _serialize(root)


def remove_spring(text: str, name: str) -> str:
    """Drop the bushing or joint spring called ``name``."""
    root = _parse(text)
    elem = _named(root, name)
    root.remove(elem)
    return _serialize(root)


def set_gravity(text: str, xyz: Iterable[float]) -> str:
    """Replace (or add) ``<rt70:gravity>``."""
    root = _parse(text)
    elem = root.find(_q("gravity"))
    if elem is None:
        elem = ET.SubElement(root, _q("gravity"))
    elem.set("xyz", fmt_vec(xyz))
    return _serialize(root)


def convert_units(text: str, length: float = 1.0, mass: float = 1.0) -> str:
    """The same model in other units of length and mass (time kept in seconds).

    A number in the new units is the SI number times ``length`` (new length units per
    metre: 1e3 for mm) or ``mass`` (new mass units per kg: 1e3 for g, 1/9.80665 for the
    technical unit kgf·s²/m). From the dimensions: lengths, gravity × λ; masses × μ;
    inertias × μλ²; translational stiffness (N/m = kg/s²) and damping (kg/s) × μ;
    torsional stiffness (N·m/rad = kg·m²/s²) and damping × μλ²; the coupling terms of a
    6 × 6 (N/rad, N·m/m) × μλ; a force × μλ, a torque × μλ². So mm/g/s: lengths × 1e3,
    masses × 1e3, inertias × 1e9, N/m × 1e3, N·m/rad × 1e9; m/kgf/s: every mass,
    inertia, stiffness and damping ÷ 9.80665.
    Joint ``<dynamics>`` and mesh files are not touched (rt70 uses neither).

    Parameters
    ----------
    text : str
        URDF text of the scene, in SI units.
    length : float, optional
        λ, new length units per metre (1e3 for mm).
    mass : float, optional
        μ, new mass units per kilogram (1e3 for g, 1/9.80665 for kgf·s²/m).

    Returns
    -------
    str
        The rewritten URDF text.
    """
    lam, mu = float(length), float(mass)
    root = _parse(text)
    six = [mu] * 3 + [mu * lam**2] * 3
    joint_type = {j.get("name"): j.get("type") for j in root.findall("joint")}
    for joint in root.findall("joint"):
        _scale_attr(joint.find("origin"), "xyz", lam)
        limit = joint.find("limit")
        if joint.get("type") == "prismatic":
            for attr in ("lower", "upper", "velocity"):
                _scale_attr(limit, attr, lam)
            _scale_attr(limit, "effort", mu * lam)
            _scale_attr(joint.find("mimic"), "offset", lam)
        else:
            _scale_attr(limit, "effort", mu * lam**2)
    for link in root.findall("link"):
        inertial = link.find("inertial")
        if inertial is not None:
            _scale_attr(inertial.find("origin"), "xyz", lam)
            _scale_attr(inertial.find("mass"), "value", mu)
            for attr in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                _scale_attr(inertial.find("inertia"), attr, mu * lam**2)
        for shape in [*link.findall("visual"), *link.findall("collision")]:
            _scale_attr(shape.find("origin"), "xyz", lam)
            for geometry in shape.iter():
                for attr in ("size", "radius", "length"):
                    _scale_attr(geometry, attr, lam)
    known = {_q(t) for t in ("gravity", "joint_spring", "bushing", "strut_package")}
    known.add(_q("optical_point"))
    known.add(_q("mount"))  # angles only: the same in every unit system
    known.add(_q("optics"))  # names of links and points only
    for elem in root:
        if isinstance(elem.tag, str) and elem.tag.startswith(f"{{{RT70_NS}}}"):
            if elem.tag not in known:
                raise Rt70Error(f"convert_units: unknown extension element {elem.tag}")
    _scale_attr(root.find(_q("gravity")), "xyz", lam)
    for elem, kind in _gain_elements(root):
        if kind == "joint_spring":
            factor = mu if joint_type.get(elem.get("joint")) == "prismatic" else mu * lam**2
            _scale_attr(elem, "stiffness", factor)
            _scale_attr(elem, "damping", factor)
            continue
        _scale_attr(elem, "xyz", lam)
        for frame in ("frame1", "frame2"):
            _scale_attr(elem.find(_q(frame)), "xyz", lam)
        for attr in ("stiffness", "damping"):  # a 6 × 6's coupling (N/rad, N) scales by μλ
            count = len((elem.get(attr) or "").split())
            half = np.sqrt(six)
            _scale_attr(elem, attr, np.outer(half, half).ravel() if count == 36 else six)
    for elem in [*root.findall(_q("strut_package")), *root.findall(_q("optical_point"))]:
        _scale_attr(elem, "xyz", lam)
    return _serialize(root)


def float_root(text: str, body: str) -> str:
    """Replace ``body``'s six-joint elastic pair on the root link by a ``floating`` joint.

    The six joints ``<body>_x … <body>_rz`` (layout of :func:`rt70.scenes.synthetic.
    elastic_chain` and ``rt70.urdf``) become one URDF ``floating`` joint with the first
    joint's origin, the massless links between them are dropped, and so is every
    bushing between the root link and ``body``: the structure floats free.
    """
    root = _parse(text)
    joints = {j.get("name"): j for j in root.findall("joint")}
    names = [f"{body}_{axis}" for axis in ("x", "y", "z", "rx", "ry", "rz")]
    if any(n not in joints for n in names):
        raise Rt70Error(f"float_root: '{body}' is not on a six-joint pair")
    first = joints[names[0]]
    parent = first.find("parent").get("link")
    for name in names[1:]:
        root.remove(joints[name])
    for link in root.findall("link"):
        if link.get("name") in {f"{n}_link" for n in names[:-1]}:
            root.remove(link)
    first.set("type", "floating")
    first.set("name", f"{body}_floating")
    first.find("child").set("link", body)
    for tag in ("axis", "limit"):
        elem = first.find(tag)
        if elem is not None:
            first.remove(elem)
    for bushing in root.findall(_q("bushing")):
        links = {bushing.find(_q(f)).get("link") for f in ("frame1", "frame2")}
        if links == {parent, body}:
            root.remove(bushing)
    return _serialize(root)


def free_floating_text(n_bodies: int = 2, seed: int = 0) -> str:
    """A free-floating elastic chain without gravity.

    :func:`rt70.scenes.synthetic.elastic_chain` with ``body1`` on a ``floating`` joint
    (the textbook's euler6 pair, Pinocchio's free flyer), no bushing to the ground and
    ``<rt70:gravity xyz="0 0 0"/>``; the other bodies keep their six-joint elastic pairs
    and bushings. No external force acts: momentum and angular momentum are conserved
    ((1.75), (1.80)).
    """
    from rt70.scenes.synthetic import elastic_chain

    return set_gravity(float_root(elastic_chain(n_bodies, seed), "body1"), (0.0, 0.0, 0.0))


def rt70_text() -> str:
    """The URDF text of the 42-DOF RT-70 scene."""
    return load_scene("rt70").text
