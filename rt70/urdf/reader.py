"""Read and validate a URDF scene with the standard library's XML parser.

Every defect is reported as an :class:`~rt70.errors.UrdfError` subclass whose message
starts with the source file, so the command line can print it as one readable line.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from rt70.errors import (
    InertiaError,
    JointTypeError,
    TopologyError,
    UrdfError,
)
from rt70.physics.rotations import rpy_matrix
from rt70.urdf.description import (
    URDF_JOINT_TYPES,
    Inertial,
    InertiaRepair,
    Joint,
    Link,
    Mimic,
    RobotDescription,
)
from rt70.urdf.elements import ONE_DOF_JOINT_TYPES, ElementReader
from rt70.urdf.extensions import read_extensions
from rt70.urdf.generated import expand_generated
from rt70.urdf.inertia import balanced_moments, inertia_defect, principal_moments
from rt70.urdf.schema import check_scene
from rt70.urdf.text import (
    parse,
    prepare_text,
    read_source,
    refuse_entities,
    refuse_xacro,
    warn,
)

#: Joint types rt70 models on both sides (the others are rejected with a clear error).
SUPPORTED_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


def read_urdf(path: str | Path, balance_inertia: bool = False) -> RobotDescription:
    """Read a URDF file into a validated :class:`RobotDescription`.

    Parameters
    ----------
    path : str or Path
        The URDF file.
    balance_inertia : bool
        Repair the rotational inertia of moving links that is not positive definite or
        breaks the triangle inequality, instead of refusing it (see
        :func:`balanced_moments`); each repair is recorded in
        ``RobotDescription.inertia_repairs`` and reported as an
        :class:`~rt70.errors.Rt70Warning`.

    Raises
    ------
    UrdfError
        (or a subclass) if the file is missing, malformed, or describes an impossible
        or unsupported model; the message names the file and the offending element.
    """
    return read_urdf_string(read_source(path), source=str(path), balance_inertia=balance_inertia)


def read_urdf_string(
    text: str, source: str = "<string>", balance_inertia: bool = False
) -> RobotDescription:
    """Read URDF text into a validated :class:`RobotDescription` (see :func:`read_urdf`).

    The text is first normalised by :func:`prepare_text`; DTD entity declarations and
    xacro templates are refused (:class:`~rt70.errors.DtdError`,
    :class:`~rt70.errors.XacroError`) before anything else is read, and so is anything
    :func:`rt70.urdf.schema.check_scene` refuses (an unknown or missing attribute of an
    rt70 element, a namespace that looks like rt70's but is not it); unknown attributes
    of standard elements are warned about.

    Parameters
    ----------
    text : str
        The URDF document.
    source : str
        The name every message gives the text (a file's path, or ``<string>``); a
        relative ``coefficients`` file of ``<rt70:wind>`` is found beside it.
    balance_inertia : bool
        Repair an impossible rotational inertia of a moving link instead of refusing it
        (:func:`read_urdf`).

    Raises
    ------
    UrdfError
        (or a subclass) as :func:`read_urdf`.
    """
    text = expand_generated(prepare_text(text, source), source)
    refuse_entities(text, source)
    root, prefixes = parse(text, source)
    return _Reader(source, balance_inertia, prefixes).robot(root)


class _Reader(ElementReader):
    """One pass over the XML tree, with the source name for messages."""

    def __init__(
        self,
        source: str,
        balance_inertia: bool = False,
        prefixes: dict[str, set[str]] | None = None,
    ) -> None:
        super().__init__(source)
        self.balance_inertia = balance_inertia
        #: per namespace URI, the prefixes the document binds to it
        self.prefixes = prefixes or {}
        #: per link: what is wrong with its <inertial>, decided once the tree is known
        self.defects: dict[str, str] = {}

    def robot(self, root: ET.Element) -> RobotDescription:
        refuse_xacro(root, self.source)
        if root.tag != "robot":
            raise self.fail(UrdfError, f"root element is <{root.tag}>, expected <robot>")
        check_scene(root, self.source, self.prefixes)
        links: dict[str, Link] = {}
        for elem in root.findall("link"):
            link = self.link(elem)
            if link.name in links:
                raise self.fail(UrdfError, f"two links named '{link.name}'")
            links[link.name] = link
        if not links:
            raise self.fail(UrdfError, "no <link> elements")
        joints = [self.joint(elem) for elem in root.findall("joint")]
        root_link = self.check_tree(links, joints)
        self.check_mimics(joints)
        repairs = self.resolve_inertias(links, joints, root_link)
        desc = RobotDescription(
            name=root.get("name", ""),
            source=self.source,
            root=root_link,
            links=links,
            joints=joints,
            gravity=np.array([0.0, 0.0, -9.81]),
            inertia_repairs=repairs,
        )
        return read_extensions(self, root, desc)

    def link(self, elem: ET.Element) -> Link:
        name = self.name_of(elem)
        inertial = elem.find("inertial")
        return Link(name, None if inertial is None else self.inertial(name, inertial))

    def inertial(self, link: str, elem: ET.Element) -> Inertial | None:
        """The link's mass properties as written; what is impossible goes to ``defects``.

        Whether an impossible inertia is refused, repaired or ignored depends on where
        the link is in the tree (:meth:`resolve_inertias`).
        """
        owner = f"link '{link}' <inertial>"
        xyz, rpy = self.origin(elem, owner)
        mass_elem = elem.find("mass")
        mass = 0.0 if mass_elem is None else self.number(mass_elem, "value", owner=owner)
        ie = elem.find("inertia")
        if ie is None:
            tensor = np.zeros((3, 3))
        else:
            ixx, ixy, ixz, iyy, iyz, izz = (
                self.number(ie, key, 0.0, owner)
                for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            )
            tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        if mass < 0.0:
            self.defects[link] = f"negative mass {mass:g} kg"
            return None
        if mass == 0.0 and not np.any(tensor):
            return None
        if np.any(tensor):  # zero, or zero to rounding, with mass: a point mass (book §2.1)
            defect = inertia_defect(tensor, mass, xyz)
            if mass == 0.0:
                detail = f" ({defect})" if defect else ""
                defect = "zero mass but non-zero inertia tensor" + detail
            if defect:
                self.defects[link] = defect
        rot = rpy_matrix(rpy)
        return Inertial(mass=mass, com=xyz, inertia=rot @ tensor @ rot.T)

    def resolve_inertias(
        self, links: dict[str, Link], joints: list[Joint], root: str
    ) -> list[InertiaRepair]:
        """Refuse, repair, accept or ignore each impossible ``<inertial>`` (in place).

        - On the ground (the root link and links welded to it by fixed joints) an inertia
          never enters the dynamics: it is ignored with a warning (Pinocchio ignores it too).
        - A zero-mass link with a non-zero, physically possible tensor welded into a body
          that has mass adds its rotational inertia to that body, as Pinocchio does; warned.
        - Otherwise the tensor is refused (:class:`~rt70.errors.InertiaError`) unless
          ``balance_inertia`` is set and :func:`balanced_moments` can repair it.
        """
        if not self.defects:
            return []
        body = _rigid_bodies(links, joints, root)
        body_mass: dict[str, float] = {}
        for name, link in links.items():
            if link.inertial is not None:
                body_mass[body[name]] = body_mass.get(body[name], 0.0) + link.inertial.mass
        repairs = []
        for name, defect in self.defects.items():
            where = f"{self.source}: link '{name}'"
            inertial = links[name].inertial
            if body[name] == root:
                welded = "the root link" if name == root else f"welded to the root link '{root}'"
                warn(
                    f"{where}: {defect}: ignored, the link is {welded} (the ground), so its "
                    "inertia never enters the dynamics"
                )
                links[name] = Link(name, None)
            elif inertial is None:  # negative mass
                raise self.fail(InertiaError, f"link '{name}': {defect}")
            elif defect.startswith("zero mass") and "(" not in defect and body_mass[body[name]] > 0:
                warn(
                    f"{where}: {defect}: its rotational inertia is added to the rigid body of "
                    f"link '{body[name]}' it is welded to (as Pinocchio does)"
                )
            else:
                moments = principal_moments(inertial.inertia)
                balanced = balanced_moments(inertial.inertia) if self.balance_inertia else None
                if balanced is None or (inertial.mass == 0.0 and body_mass[body[name]] <= 0.0):
                    raise self.fail(InertiaError, f"link '{name}': {defect}")
                links[name] = Link(name, Inertial(inertial.mass, inertial.com, np.diag(balanced)))
                repairs.append(InertiaRepair(name, moments, balanced))
                why = "triangle inequality" if "triangle" in defect else "not positive definite"
                warn(
                    f"{where}: inertia repaired (balance inertia; {why}): principal moments "
                    f"{', '.join(f'{m:.6g}' for m in moments)} -> "
                    f"{', '.join(f'{m:.6g}' for m in balanced)}"
                )
        return repairs

    def joint(self, elem: ET.Element) -> Joint:
        name = self.name_of(elem)
        jtype = elem.get("type")
        if jtype is None:
            raise self.fail(UrdfError, f"joint '{name}' has no type")
        if jtype not in URDF_JOINT_TYPES:
            raise self.fail(JointTypeError, f"joint '{name}': unknown joint type '{jtype}'")
        if jtype not in SUPPORTED_JOINT_TYPES:
            raise self.fail(
                JointTypeError,
                f"joint '{name}': joint type '{jtype}' is not supported "
                f"(supported: {', '.join(SUPPORTED_JOINT_TYPES)})",
            )
        ends = {}
        for end in ("parent", "child"):
            sub = elem.find(end)
            if sub is None or not sub.get("link"):
                raise self.fail(UrdfError, f"joint '{name}' lacks <{end} link=...>")
            ends[end] = sub.get("link")
        xyz, rpy = self.origin(elem, f"joint '{name}'")
        axis_elem = elem.find("axis")
        axis = np.array([1.0, 0.0, 0.0])
        if axis_elem is not None:
            axis = self.numbers(axis_elem, "xyz", 3, owner=f"joint '{name}'")
        norm = float(np.linalg.norm(axis))
        if jtype != "fixed" and norm < 1e-12:
            raise self.fail(UrdfError, f"joint '{name}': zero-length axis")
        axis = axis / max(norm, 1e-300)
        if jtype == "planar" and not np.array_equal(axis, [0.0, 0.0, 1.0]):
            raise self.fail(
                JointTypeError,
                f"joint '{name}': planar joint with axis {axis.tolist()}: only the plane normal "
                "to z (axis 0 0 1) is supported (Pinocchio's planar joint)",
            )
        mimic = None
        mimic_elem = elem.find("mimic")
        # A fixed joint has no coordinate to couple: its <mimic> (left over when a model is
        # reduced by fixing joints) is ignored, as Pinocchio does; the joint stays fixed.
        if mimic_elem is not None and jtype != "fixed":
            owner = f"joint '{name}'"
            source = mimic_elem.get("joint")
            if not source:
                raise self.fail(UrdfError, f"{owner}: <mimic> lacks attribute 'joint'")
            if jtype not in ONE_DOF_JOINT_TYPES:
                raise self.fail(JointTypeError, f"{owner}: a {jtype} joint cannot mimic")
            mimic = Mimic(
                source,
                self.number(mimic_elem, "multiplier", 1.0, owner),
                self.number(mimic_elem, "offset", 0.0, owner),
            )
        return Joint(name, jtype, ends["parent"], ends["child"], xyz, rpy, axis, mimic)

    def check_mimics(self, joints: list[Joint]) -> None:
        by_name = {j.name: j for j in joints}
        for j in joints:
            if j.mimic is None:
                continue
            source = by_name.get(j.mimic.joint)
            if source is None:
                raise self.fail(
                    TopologyError,
                    f"joint '{j.name}': <mimic joint='{j.mimic.joint}'> does not exist",
                )
            if source.type not in ONE_DOF_JOINT_TYPES or source.mimic is not None:
                raise self.fail(
                    JointTypeError,
                    f"joint '{j.name}' mimics '{source.name}', which is not an independent "
                    "1-DOF joint",
                )
            if (j.type == "prismatic") != (source.type == "prismatic"):
                raise self.fail(
                    JointTypeError,
                    f"joint '{j.name}' ({j.type}) mimics '{source.name}' ({source.type}): "
                    "a revolute and a prismatic coordinate cannot be coupled",
                )

    def check_tree(self, links: dict[str, Link], joints: list[Joint]) -> str:
        names: set[str] = set()
        parent_of: dict[str, str] = {}
        for j in joints:
            if j.name in names:
                raise self.fail(UrdfError, f"two joints named '{j.name}'")
            names.add(j.name)
            for end, link in (("parent", j.parent), ("child", j.child)):
                if link not in links:
                    raise self.fail(
                        TopologyError, f"joint '{j.name}': {end} link '{link}' does not exist"
                    )
            if j.child in parent_of:
                raise self.fail(
                    TopologyError,
                    f"link '{j.child}' has two parents ('{parent_of[j.child]}' and '{j.parent}')",
                )
            parent_of[j.child] = j.parent
        reaches_root: set[str] = set()  # links already followed to a root (linear time)
        for start in parent_of:  # follow parents: a cycle never reaches a root
            seen = [start]
            on_path = {start}
            link = start
            while link in parent_of and link not in reaches_root:
                link = parent_of[link]
                if link in on_path:
                    cycle = " -> ".join([*seen[seen.index(link) :], link])
                    raise self.fail(TopologyError, f"kinematic cycle: {cycle}")
                seen.append(link)
                on_path.add(link)
            reaches_root.update(seen)
        roots = [name for name in links if name not in parent_of]
        if len(roots) != 1:
            raise self.fail(
                TopologyError,
                f"expected one root link, found {len(roots)}: {', '.join(roots[:5])}",
            )
        return roots[0]


def _rigid_bodies(links: dict[str, Link], joints: list[Joint], root: str) -> dict[str, str]:
    """The rigid body of every link, named by one of its links.

    That is the link it is welded to by fixed joints that itself moves (the child of a
    moving joint), or ``root`` for the ground.
    """
    parent_joint = {j.child: j for j in joints}
    body: dict[str, str] = {root: root}
    for name in links:
        path = []
        link = name
        while link not in body:
            joint = parent_joint[link]
            if joint.type != "fixed":
                body[link] = link
                break
            path.append(link)
            link = joint.parent
        for welded in path:
            body[welded] = body[link]
    return body
