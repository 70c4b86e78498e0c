"""The reference side's constant Model and its work buffers (Data), as in Pinocchio.

:class:`ReferenceModel` is built once from a scene (Pinocchio parses the URDF text
itself) and never changed afterwards: Pinocchio's model, a copy without gravity (for
the velocity-product force), the map of every Pinocchio joint to the book's
coordinates, and the scene's spring elements. :class:`ReferenceData` holds Pinocchio's
``Data`` objects that the algorithms fill (:mod:`rt70.reference.dynamics`,
:mod:`rt70.reference.forces`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from rt70.errors import Rt70Error
from rt70.reference.limits import check_reference
from rt70.reference.modal_nodes import modal_slices, with_nodes
from rt70.reference.parse import parse_urdf
from rt70.urdf.coordinates import SUFFIXES, coordinate_names
from rt70.urdf.description import FrameRef, RobotDescription
from rt70.urdf.generated import expand_generated
from rt70.urdf.inertia import balanced_text
from rt70.urdf.text import prepare_text


@dataclass(frozen=True)
class Bushing:
    """A bushing's two frames, each as (parent joint, placement in it), and its 6 × 6 gains."""

    frame1: tuple[int, pin.SE3]
    frame2: tuple[int, pin.SE3]
    stiffness: np.ndarray
    damping: np.ndarray


@dataclass(frozen=True)
class FrameStack:
    """Frames fixed to links, as arrays: what Pinocchio's frame algorithms read, stacked.

    Built once from ``(parent joint, placement)`` pairs so that the placements and
    Jacobians of tens of thousands of frames (bushings) are a few array products of
    Pinocchio's per-joint results rather than a Pinocchio call each
    (:func:`rt70.reference.forces.deformations`).

    Attributes
    ----------
    joints : numpy.ndarray
        Parent joint of each frame, (n,).
    rotations, translations : numpy.ndarray
        Each placement in its joint, (n, 3, 3) and (n, 3).
    act_inverse : numpy.ndarray
        Pinocchio's ``placement.toActionMatrixInverse()`` of each, (n, 6, 6): a joint's
        ``LOCAL`` Jacobian to the frame's (``getFrameJacobian``'s ``placement.actInv``).
    """

    joints: np.ndarray
    rotations: np.ndarray
    translations: np.ndarray
    act_inverse: np.ndarray

    @classmethod
    def of(cls, frames: list[tuple[int, pin.SE3]]) -> FrameStack:
        """The stack of ``frames`` (parent joint, placement), in order."""
        return cls(
            np.array([joint for joint, _ in frames], dtype=int),
            np.array([placement.rotation for _, placement in frames]).reshape(-1, 3, 3),
            np.array([placement.translation for _, placement in frames]).reshape(-1, 3),
            np.array([p.toActionMatrixInverse() for _, p in frames]).reshape(-1, 6, 6),
        )


@dataclass(frozen=True)
class Coordinate:
    """One Pinocchio joint seen in book coordinates."""

    joint: int
    kind: str  # "1dof", "continuous", "floating", "planar", "mimic", "mimic-continuous", "modal"
    names: tuple[str, ...]
    iq: int
    iv: int
    book: int  # first book coordinate (for a mimic joint: the source's book coordinate)
    multiplier: float = 1.0
    offset: float = 0.0
    shape: np.ndarray | None = None  # a modal body's node: u = shape @ q[book : book + k]


class ReferenceModel:
    """Pinocchio's model of one scene and its spring elements; constant once built.

    Parameters
    ----------
    desc : RobotDescription
        The scene as read by :func:`rt70.urdf.read_urdf` (validated).
    urdf_text : str
        The URDF text itself, handed to Pinocchio's own parser.

    Attributes
    ----------
    pin_model, pin_model_no_gravity : pinocchio.Model
        Pinocchio's model with the scene's gravity, and a copy without gravity.
    body_frames : dict of str to int
        Index in ``pin_model.frames`` of each link's body frame (by link name).
    coords : list of Coordinate
        Every Pinocchio joint's book coordinates, in Pinocchio's joint order.
    coordinate_names : list of str
        The book coordinates in the user's order (:func:`rt70.urdf.coordinate_names`).
    identity_map : bool
        True when book coordinates are Pinocchio's ``(q, v)`` unchanged.
    bushings : list of Bushing
        Attachment frames and gains of every bushing and strut.
    spring_v, spring_k, spring_d : numpy.ndarray
        Velocity index, stiffness and damping of every joint spring.
    winds, air_density : tuple of rt70.urdf.Wind, float
        The scene's exposed bodies and air density (:mod:`rt70.reference.wind`).
    frames1, frames2 : list of (int, pinocchio.SE3)
        Each bushing's frames 1 and 2 (parent joint, placement); ``stack1``, ``stack2``
        the same as :class:`FrameStack` arrays.
    loops : list of (int, (int, pinocchio.SE3), (int, pinocchio.SE3))
        Rows and the two frames (parent joint, placement) of every loop closure.
    modal_bodies : tuple of rt70.urdf.ModalBody
        The modal bodies, whose nodes are point masses on joints of their own
        (:mod:`rt70.reference.modal_nodes`).
    urdf_joints : list of int
        Pinocchio's joints that are the file's, in Pinocchio's order (all but the nodes').
    modal_slices : list of (rt70.urdf.ModalBody, slice)
        Each modal body and its coordinates' slice of the book coordinates.
    """

    def __init__(self, desc: RobotDescription, urdf_text: str) -> None:
        check_reference(desc)  # parser depth and memory, before Pinocchio sees the model
        model = parse_urdf(expand_generated(urdf_text, desc.source), desc.source)
        self.body_frames = {}  # Pinocchio's getBodyId, without its scan of every frame
        for index, frame in enumerate(model.frames):
            if frame.type == pin.BODY:
                self.body_frames.setdefault(frame.name, index)
        bodies = {name: model.frames[i] for name, i in self.body_frames.items()}
        nodes: list = []
        if desc.modal_bodies:  # the frames keep their indices; their joints are renumbered
            model, nodes = with_nodes(model, bodies, desc.modal_bodies)
            bodies = {name: model.frames[i] for name, i in self.body_frames.items()}
        model.gravity.linear = np.asarray(desc.gravity, dtype=float)
        model.armature[:] = 0.0
        self.pin_model = model
        self.pin_model_no_gravity = model.copy()
        self.pin_model_no_gravity.gravity.setZero()
        self.modal_bodies = desc.modal_bodies  # their stiffness and damping on η
        node_joints = {joint for added in nodes for joint, _ in added}
        self.node_joints = {model.names[j]: j for j in node_joints}  # "<body>/node<n>"
        self.urdf_joints = [  # Pinocchio's joints that are the file's (not modal nodes)
            i for i in range(1, model.njoints) if i not in node_joints
        ]
        self.bushings = [
            Bushing(
                _attachment(bodies, b.frame1),
                _attachment(bodies, b.frame2),
                np.asarray(b.stiffness),
                np.asarray(b.damping),
            )
            for b in desc.bushings
        ]
        self.loops = [  # (rows, frame 1, frame 2): rt70.reference.loops
            (loop.rows, _attachment(bodies, loop.frame1), _attachment(bodies, loop.frame2))
            for loop in desc.loops
        ]
        self.frames1 = [b.frame1 for b in self.bushings]
        self.frames2 = [b.frame2 for b in self.bushings]
        self.stack1, self.stack2 = FrameStack.of(self.frames1), FrameStack.of(self.frames2)
        self.stiffness = np.array([b.stiffness for b in self.bushings]).reshape(-1, 6, 6)
        self.damping = np.array([b.damping for b in self.bushings]).reshape(-1, 6, 6)
        self.coords, self.coordinate_names = _coordinates(model, desc, nodes)
        self.identity_map = all(c.kind == "1dof" and c.book == c.iv for c in self.coords)
        self.modal_slices = modal_slices(desc.modal_bodies, self.coordinate_names)
        joint_id = {name: i for i, name in enumerate(model.names)}
        self.spring_v = np.array(
            [model.idx_vs[joint_id[s.joint]] for s in desc.joint_springs], dtype=int
        )
        self.spring_k = np.array([s.stiffness for s in desc.joint_springs], dtype=float)
        self.spring_d = np.array([s.damping for s in desc.joint_springs], dtype=float)
        self.winds = desc.winds  # exposed bodies (rt70.reference.wind)
        self.air_density = desc.air_density
        self._built = True

    def __setattr__(self, name: str, value: object) -> None:
        """Refuse to rebind an attribute once built: the Model is constant (as the textbook's)."""
        if getattr(self, "_built", False):
            raise AttributeError(f"ReferenceModel is constant once built: cannot set '{name}'")
        object.__setattr__(self, name, value)

    @classmethod
    def from_file(cls, desc: RobotDescription, path: str | Path) -> ReferenceModel:
        """Build from a URDF file already read into ``desc`` (its repairs written in)."""
        text = Path(path).read_text(encoding="utf-8")
        if desc.inertia_repairs:  # read the repaired inertias, as the textbook side does
            text = balanced_text(prepare_text(text, desc.source), desc.inertia_repairs)
        return cls(desc, text)

    @property
    def nv(self) -> int:
        """Number of book coordinates (independent generalised coordinates)."""
        return len(self.coordinate_names)

    def coordinate_index(self, names: list[str]) -> np.ndarray:
        """Index among this model's book coordinates of each named coordinate."""
        position = {n: i for i, n in enumerate(self.coordinate_names)}
        return np.array([position[n] for n in names], dtype=int)


class ReferenceData:
    """Work buffers of the reference algorithms for one :class:`ReferenceModel`.

    Attributes
    ----------
    pin_data, pin_data_no_gravity : pinocchio.Data
        Pinocchio's buffers for ``model.pin_model`` and ``model.pin_model_no_gravity``.
    placements : dict
        Points located once: ``(link, xyz) ↦ (joint, placement)`` of
        :func:`rt70.reference.points.link_point`, kept by
        :func:`~rt70.reference.points.point_positions` for a trajectory's samples.
    """

    def __init__(self, model: ReferenceModel) -> None:
        self.pin_data = model.pin_model.createData()
        self.pin_data_no_gravity = model.pin_model_no_gravity.createData()
        self.placements: dict[tuple, tuple[int, pin.SE3]] = {}


def _attachment(bodies: dict, ref: FrameRef) -> tuple[int, pin.SE3]:
    """Parent joint and placement in it of a frame fixed to a link.

    Kept as (joint, placement) rather than added to the model: ``Model.addFrame``
    searches every frame for a duplicate name, quadratic in the number of bushings.
    """
    if ref.link not in bodies:
        raise Rt70Error(f"Pinocchio has no frame for link '{ref.link}'")
    body = bodies[ref.link]
    offset = pin.SE3(pin.rpy.rpyToMatrix(*ref.rpy), np.asarray(ref.xyz, dtype=float))
    return body.parentJoint, body.placement * offset


def _coordinates(
    m: pin.Model, desc: RobotDescription, nodes: list[list[tuple[int, np.ndarray]]]
) -> tuple[list[Coordinate], list[str]]:
    """Book coordinates of every Pinocchio joint, numbered in the user's order.

    Pinocchio numbers sibling joints its own way; every result of the reference side is
    in the order of :func:`rt70.urdf.coordinate_names` (the file's depth-first order,
    the same as the textbook side's), so ``c.book`` is the user index of the joint's
    first coordinate. The modal bodies' node joints (``nodes``: joint and shape of each,
    per body) and their interface chains' joints map to the body's modal coordinates.
    """
    mimics = {j.name: j.mimic for j in desc.joints if j.mimic is not None}
    names = coordinate_names(desc)
    user = {n: i for i, n in enumerate(names)}
    coords: list[Coordinate] = []
    seen: list[str] = []
    node_of = {}
    for body, added in zip(desc.modal_bodies, nodes, strict=True):
        seen.extend(body.coordinate_names)
        for joint, shape in added:
            node_of[joint] = (user[body.coordinate_names[0]], shape)
        for joint, row in body.node_joints.items():  # an interface chain's: row · η
            node_of[m.getJointId(joint)] = (user[body.coordinate_names[0]], row[None, :])
    for i in range(1, m.njoints):
        if i in node_of:
            first, shape = node_of[i]
            jm = m.joints[i]
            coords.append(Coordinate(i, "modal", (), jm.idx_q, jm.idx_v, first, shape=shape))
            continue
        name, jm = m.names[i], m.joints[i]
        short = jm.shortname()
        if short == "JointModelFreeFlyer":
            kind = "floating"
        elif short == "JointModelPlanar":
            kind = "planar"
        elif jm.nq == 2 and jm.nv == 1:
            kind = "continuous"
        elif jm.nq == 1 and jm.nv == 1:
            kind = "1dof"
        else:
            raise Rt70Error(f"{desc.source}: joint '{name}': Pinocchio joint {short} unsupported")
        if name in mimics:
            mimic = mimics[name]
            coords.append(
                Coordinate(
                    i,
                    "mimic-continuous" if kind == "continuous" else "mimic",
                    (),
                    jm.idx_q,
                    jm.idx_v,
                    user[mimic.joint],
                    mimic.multiplier,
                    mimic.offset,
                )
            )
            continue
        labels = tuple(name + sfx for sfx in SUFFIXES.get(kind, ("",)))
        first = user.get(labels[0], -1)
        if [user.get(label) for label in labels] != list(range(first, first + len(labels))):
            raise Rt70Error(
                f"{desc.source}: joint '{name}': Pinocchio's coordinates "
                f"{', '.join(labels)} are not those rt70 reads from the file"
            )
        coords.append(Coordinate(i, kind, labels, jm.idx_q, jm.idx_v, first))
        seen.extend(labels)
    if sorted(seen) != sorted(names):
        raise Rt70Error(
            f"{desc.source}: Pinocchio's coordinates differ from the file's: "
            f"{', '.join(sorted(set(seen) ^ set(names))[:5])}"
        )
    return coords, names
