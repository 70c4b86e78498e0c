"""The textbook model: a tree of pairs as plain data (book §4.1).

Each pair j joins body j to its parent body ``parent[j]`` (−1 is the ground, body 0 of
the book). Its construction frame ``E_jc`` is placed in the parent's frame by the
constant ``r_c[j]``, ``c_c[j]``; the pair's own motion is one of

``euler6``
    the book's free elastic pair, ``q_j = [x, y, z, β, θ, α]`` (4.8), ``f_j = 1₆``;
``revolute`` / ``prismatic``
    one coordinate about / along the unit ``axis[j]`` (``f_j = [0; a]`` / ``[a; 0]``);
    URDF ``continuous`` joints are revolute pairs (the angle is the coordinate);
``planar``
    ``q_j = [x, y, α]``: translation in the construction frame's x–y plane, then rotation
    α about its z axis.

URDF ``fixed`` joints are no pairs: the child link's inertia is merged into the body
it is welded to (as Pinocchio does), and its frame is kept as a placement on that body.

A URDF chain of six joints (prismatic x, y, z, revolute x, y, z, zero origins after the
first, massless links between) is read as one ``euler6`` pair, exactly the layout of
formalism §5, and so is a URDF ``floating`` joint; every other joint is one pair.

URDF ``<mimic>`` joints are holonomic constraints ``q_m = k q_s + o`` (chapter 3): the
pairs keep their full coordinates ``q_full = G q + q_offset``, and the structure matrix
is reduced to the independent coordinates, ``S = Gᵀ S_full`` — the book's ``S = fᵀ L``
elimination with the constraint matrix G in place of the 0/1 mobility f.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rt70.physics.aerodynamics import DEFAULT_AIR_DENSITY
from rt70.textbook.coordinate_map import pair_coordinate_map
from rt70.textbook.modal_model import ModalModel, place_modal_bodies
from rt70.textbook.spatial import body_inertia, placement, rpy_matrix
from rt70.urdf.description import Joint, RobotDescription, Wind

PAIR_KINDS = ("euler6", "revolute", "prismatic", "planar")
_NDOF = {"euler6": 6, "revolute": 1, "prismatic": 1, "planar": 3}
_URDF_KIND = {
    "revolute": "revolute",
    "continuous": "revolute",
    "prismatic": "prismatic",
    "planar": "planar",
    "floating": "euler6",
}
_SUFFIXES = {"euler6": (":x", ":y", ":z", ":rx", ":ry", ":rz"), "planar": (":x", ":y", ":rz")}
_EULER6_PATTERN = (
    ("prismatic", (1.0, 0.0, 0.0)),
    ("prismatic", (0.0, 1.0, 0.0)),
    ("prismatic", (0.0, 0.0, 1.0)),
    ("revolute", (1.0, 0.0, 0.0)),
    ("revolute", (0.0, 1.0, 0.0)),
    ("revolute", (0.0, 0.0, 1.0)),
)


@dataclass(frozen=True)
class LoopModel:
    """A loop closure: frame 1 on ``body1`` coincides with frame 2 on ``body2``.

    Bodies are pair indices (−1 = ground); ``r``/``c`` place each frame in its body;
    ``rows`` is 3 (the origins coincide) or 6 (the frames coincide). docs/loops.md.
    """

    name: str
    rows: int
    body1: int
    r1: np.ndarray
    c1: np.ndarray
    body2: int
    r2: np.ndarray
    c2: np.ndarray


@dataclass(frozen=True)
class BushingModel:
    """A 6-D spring/damper between frame 1 on ``body1`` and frame 2 on ``body2``.

    Bodies are pair indices (−1 = ground); ``r``/``c`` place each frame in its body;
    ``stiffness`` and ``damping`` are the 6 × 6 matrices C and D of the deformation
    (frame 2's position in frame 1 and its 1–2–3 angles).
    """

    name: str
    body1: int
    r1: np.ndarray
    c1: np.ndarray
    body2: int
    r2: np.ndarray
    c2: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray


@dataclass(frozen=True)
class Model:
    """Plain model data of the textbook algorithm (no work buffers; see :class:`Data`).

    Constant once :func:`build_model` has made it (a frozen dataclass): every algorithm
    reads it, none writes it — the work buffers are in :class:`~rt70.textbook.data.Data`.

    Attributes
    ----------
    parent : numpy.ndarray
        Parent pair of each pair, −1 for the ground; parents precede children.
    kind : list of str
        Pair kind, one of :data:`PAIR_KINDS`.
    axis : numpy.ndarray
        Joint axis of 1-DOF pairs, shape (nb, 3).
    r_c, c_c : numpy.ndarray
        Construction frame of each pair in its parent's frame, shapes (nb, 3), (nb, 3, 3).
    Theta : numpy.ndarray
        Inertia matrix Θ of each body about its frame origin (4.77), shape (nb, 6, 6).
    mass, com : numpy.ndarray
        Mass and centre of mass (body frame) of each body.
    q_start, ndof : numpy.ndarray
        First index and number of each pair's coordinates in ``q_full``.
    coordinate_names : list of str
        Name of each independent coordinate (joint name; ``joint:x`` … for multi-DOF
        URDF joints).
    G, q_offset : numpy.ndarray or None
        Mimic constraints ``q_full = G q + q_offset``; None when there are none
        (``q_full = q``).
    winds, air_density : tuple of rt70.urdf.Wind, float
        The scene's exposed bodies and air density (:mod:`rt70.textbook.wind`).
    pair_joints : list of tuple of str
        The URDF joints of each pair: one, or the six of a merged euler6 chain
        (:mod:`rt70.textbook.reactions` reports the wrench across each).
    modal : tuple of ModalModel
        The modal flexible bodies; their coordinates η follow the pairs' independent
        coordinates in q (``q = [q_pairs; η]``), and move only the pairs of their
        interface chains.
    node_map : numpy.ndarray or None
        ``H`` (n_full, n_modal): the interface chains' pair coordinates per unit η
        (``q_full = G q_pairs + H η + q_offset``); None without interfaces (then G has
        no zero rows).
    """

    name: str
    parent: np.ndarray
    kind: list[str]
    axis: np.ndarray
    r_c: np.ndarray
    c_c: np.ndarray
    Theta: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    q_start: np.ndarray
    ndof: np.ndarray
    body_names: list[str]
    coordinate_names: list[str]
    gravity: np.ndarray
    full_coordinate_names: list[str] = field(default_factory=list)
    link_frames: dict[str, tuple[int, np.ndarray, np.ndarray]] = field(default_factory=dict)
    bushings: list[BushingModel] = field(default_factory=list)
    loops: list[LoopModel] = field(default_factory=list)
    spring_coords: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    spring_stiffness: np.ndarray = field(default_factory=lambda: np.zeros(0))
    spring_damping: np.ndarray = field(default_factory=lambda: np.zeros(0))
    G: np.ndarray | None = None
    q_offset: np.ndarray | None = None
    winds: tuple[Wind, ...] = ()
    air_density: float = DEFAULT_AIR_DENSITY
    pair_joints: list[tuple[str, ...]] = field(default_factory=list)
    modal: tuple[ModalModel, ...] = ()
    node_map: np.ndarray | None = None

    @property
    def nb(self) -> int:
        """Number of pairs (bodies)."""
        return len(self.kind)

    @property
    def n_full(self) -> int:
        """Number of pair coordinates, mimic joints included."""
        return int(self.ndof.sum())

    @property
    def n_pairs(self) -> int:
        """Number of independent coordinates of the pairs (q without the modal ones)."""
        return self.n_full if self.G is None else self.G.shape[1]

    @property
    def n_modal(self) -> int:
        """Number of modal coordinates of the modal bodies."""
        return sum(body.modes for body in self.modal)

    @property
    def nv(self) -> int:
        """Number of independent generalised coordinates."""
        return self.n_pairs + self.n_modal

    def expand(self, q: np.ndarray, offset: bool = True) -> np.ndarray:
        """``q_full = G q_p + H η + q_offset`` (no offset for velocities), q of shape (nv,).

        ``q_p`` are the pairs' independent coordinates, η the modal ones; ``H``
        (:attr:`node_map`) moves the interface chains' joints with η, and is absent
        without interfaces.
        """
        eta = q[..., self.n_pairs :]
        if self.modal:
            q = q[..., : self.n_pairs]
        if self.G is None:
            return q
        q_full = self.G @ q + self.q_offset if offset else self.G @ q
        return q_full if self.node_map is None else q_full + self.node_map @ eta

    def reduce(self, Q_full: np.ndarray) -> np.ndarray:
        """Generalised force on the independent coordinates, ``[Gᵀ; Hᵀ] Q_full``.

        ``Q_full`` (n_full, …) is on the pairs' coordinates; a modal coordinate's row is
        what the interface chains' joints take from it (zero without interfaces).
        """
        Q = Q_full if self.G is None else self.G.T @ Q_full
        if not self.modal:
            return Q
        if self.node_map is None:
            return np.concatenate([Q, np.zeros((self.n_modal,) + Q.shape[1:])])
        return np.concatenate([Q, self.node_map.T @ Q_full])

    def coords(self, j: int) -> slice:
        """Slice of pair j's coordinates in q."""
        return slice(int(self.q_start[j]), int(self.q_start[j] + self.ndof[j]))

    def ancestors(self, j: int) -> list[int]:
        """Pairs on the path from the ground to j, j included, root first."""
        path = []
        while j >= 0:
            path.append(j)
            j = int(self.parent[j])
        return path[::-1]


def _euler6_chain(
    desc: RobotDescription, first: Joint, referenced: set[str], children: dict[str, list[Joint]]
) -> list[Joint]:
    """Return the six joints of an euler6 pair starting at ``first``, or [] if none.

    ``children`` maps a link to its child joints in file order (:func:`_child_joints`).
    """
    chain = []
    joint = first
    for step, (jtype, axis) in enumerate(_EULER6_PATTERN):
        if joint.type != jtype or not np.array_equal(joint.axis, axis):
            return []
        if step > 0 and (np.any(joint.xyz != 0.0) or np.any(joint.rpy != 0.0)):
            return []
        chain.append(joint)
        if step == 5:
            return chain
        link = desc.links[joint.child]
        below = children.get(joint.child, [])
        if link.inertial is not None or len(below) != 1 or link.name in referenced:
            return []
        joint = below[0]
    return []


def _child_joints(desc: RobotDescription) -> dict[str, list[Joint]]:
    """Child joints of every link, in file order (one pass: linear in the joints)."""
    children: dict[str, list[Joint]] = {}
    for joint in desc.joints:
        children.setdefault(joint.parent, []).append(joint)
    return children


def build_model(desc: RobotDescription) -> Model:
    """Build the textbook :class:`Model` from a validated URDF description."""
    pairs = _read_pairs(desc)
    link_frames = pairs.link_frames
    masses = [float(t[0, 0]) for t in pairs.thetas]  # Θ = [[m 1, −m<p>], [m<p>, …]] (4.77)
    coms = [
        _unskew(t[3:, :3]) / m if m > 0 else np.zeros(3)
        for t, m in zip(pairs.thetas, masses, strict=True)
    ]
    ndof_arr = np.array(pairs.ndof, dtype=int)
    G, q_offset, independent, node_map = pair_coordinate_map(pairs.coord_names, desc)
    return Model(
        name=desc.name,
        parent=np.array(pairs.parent, dtype=int),
        kind=pairs.kind,
        axis=np.array(pairs.axis, dtype=float).reshape(-1, 3),
        r_c=np.array(pairs.r_c, dtype=float).reshape(-1, 3),
        c_c=np.array(pairs.c_c, dtype=float).reshape(-1, 3, 3),
        Theta=np.array(pairs.thetas, dtype=float).reshape(-1, 6, 6),
        mass=np.array(masses, dtype=float),
        com=np.array(coms, dtype=float).reshape(-1, 3),
        q_start=np.concatenate([[0], np.cumsum(ndof_arr)[:-1]]).astype(int),
        ndof=ndof_arr,
        body_names=pairs.body_names,
        coordinate_names=independent + [n for b in desc.modal_bodies for n in b.coordinate_names],
        gravity=np.array(desc.gravity, dtype=float),
        full_coordinate_names=list(pairs.coord_names),
        link_frames=link_frames,
        bushings=_bushings(desc, link_frames),
        loops=_loops(desc, link_frames),
        spring_coords=np.array([pairs.joint_coord[s.joint] for s in desc.joint_springs], dtype=int),
        spring_stiffness=np.array([s.stiffness for s in desc.joint_springs], dtype=float),
        spring_damping=np.array([s.damping for s in desc.joint_springs], dtype=float),
        G=G,
        q_offset=q_offset,
        winds=desc.winds,
        air_density=desc.air_density,
        pair_joints=pairs.pair_joints,
        modal=place_modal_bodies(desc.modal_bodies, link_frames, len(independent)),
        node_map=node_map,
    )


@dataclass
class _Pairs:
    """The pairs of a description as lists, in tree order, while :func:`_read_pairs` runs.

    One entry per pair in ``parent`` … ``pair_joints`` (the fields of :class:`Model`
    of the same names; ``thetas`` is Θ), one per pair coordinate in ``coord_names``;
    ``joint_coord`` maps a coordinate's name to its index, ``link_frames`` every link
    read so far to its ``(body, r, c)``.
    """

    link_frames: dict[str, tuple[int, np.ndarray, np.ndarray]]
    parent: list[int] = field(default_factory=list)
    kind: list[str] = field(default_factory=list)
    axis: list[np.ndarray] = field(default_factory=list)
    r_c: list[np.ndarray] = field(default_factory=list)
    c_c: list[np.ndarray] = field(default_factory=list)
    thetas: list[np.ndarray] = field(default_factory=list)
    ndof: list[int] = field(default_factory=list)
    body_names: list[str] = field(default_factory=list)
    coord_names: list[str] = field(default_factory=list)
    joint_coord: dict[str, int] = field(default_factory=dict)
    pair_joints: list[tuple[str, ...]] = field(default_factory=list)

    def weld(
        self, desc: RobotDescription, joint: Joint, body: int, r: np.ndarray, c: np.ndarray
    ) -> None:
        """A fixed ``joint``: its child link merged into ``body`` at ``(r, c)`` (as Pinocchio).

        The link's inertia is added to the body's Θ, moved by ``T(r)[c]`` (4.77); the
        ground (body −1) takes no inertia.
        """
        inertial = desc.links[joint.child].inertial
        if inertial is not None and body >= 0:
            theta = body_inertia(inertial.mass, inertial.com, inertial.inertia)
            X = placement(r, c)
            self.thetas[body] = self.thetas[body] + X @ theta @ X.T
        self.link_frames[joint.child] = (body, r, c)

    def add(
        self,
        desc: RobotDescription,
        joint: Joint,
        chain: list[Joint],
        body: int,
        r: np.ndarray,
        c: np.ndarray,
    ) -> str:
        """A new pair on ``body``, construction frame ``(r, c)``; returns its child link.

        The pair is ``joint``, or the six joints of ``chain`` read as one euler6 pair
        (:func:`_euler6_chain`; empty when it is not one).
        """
        if chain:
            jkind, child, names = "euler6", chain[-1].child, [j.name for j in chain]
        else:
            child, jkind = joint.child, _URDF_KIND[joint.type]
            suffixes = _SUFFIXES.get(jkind, ("",) * _NDOF[jkind])
            names = [joint.name + suffix for suffix in suffixes]
        inertial = desc.links[child].inertial
        j = len(self.kind)
        self.pair_joints.append(tuple(step.name for step in chain) if chain else (joint.name,))
        self.parent.append(body)
        self.kind.append(jkind)
        self.axis.append(joint.axis)
        self.r_c.append(r)
        self.c_c.append(c)
        if inertial is None:
            self.thetas.append(np.zeros((6, 6)))
        else:
            self.thetas.append(body_inertia(inertial.mass, inertial.com, inertial.inertia))
        for name in names:
            self.joint_coord[name] = len(self.coord_names)
            self.coord_names.append(name)
        self.ndof.append(_NDOF[jkind])
        self.body_names.append(child)
        self.link_frames[child] = (j, np.zeros(3), np.eye(3))
        return child


def _read_pairs(desc: RobotDescription) -> _Pairs:
    """The pairs of ``desc``: depth-first, parents before children, siblings in file order.

    An explicit stack of ``(joint, body, r_link, c_link)``, the joint's parent link
    sitting at ``(r_link, c_link)`` in body (a recursion would overflow Python's stack
    on chains of ~1000 bodies). A fixed joint welds its child link to the body
    (:meth:`_Pairs.weld`); any other joint, or a chain of six read as one euler6 pair,
    is a new pair (:meth:`_Pairs.add`).
    """
    referenced = {b.frame1.link for b in desc.bushings} | {b.frame2.link for b in desc.bushings}
    referenced |= {p.link for p in desc.optical_points} | {w.link for w in desc.winds}
    referenced |= {f.link for loop in desc.loops for f in (loop.frame1, loop.frame2)}
    children = _child_joints(desc)
    pairs = _Pairs(link_frames={desc.root: (-1, np.zeros(3), np.eye(3))})
    stack: list[tuple[Joint, int, np.ndarray, np.ndarray]] = []

    def visit(link: str, body: int, r_link: np.ndarray, c_link: np.ndarray) -> None:
        """Schedule the joints below ``link``, which sits at ``(r_link, c_link)`` in ``body``."""
        stack.extend((joint, body, r_link, c_link) for joint in children.get(link, [])[::-1])

    visit(desc.root, -1, np.zeros(3), np.eye(3))
    while stack:
        joint, body, r_link, c_link = stack.pop()
        r_joint = r_link + c_link @ joint.xyz
        c_joint = c_link @ rpy_matrix(joint.rpy)
        if joint.type == "fixed":
            pairs.weld(desc, joint, body, r_joint, c_joint)
            visit(joint.child, body, r_joint, c_joint)
            continue
        chain = _euler6_chain(desc, joint, referenced, children)
        child = pairs.add(desc, joint, chain, body, r_joint, c_joint)
        visit(child, len(pairs.kind) - 1, np.zeros(3), np.eye(3))
    return pairs


def _bushings(desc: RobotDescription, link_frames: dict) -> list[BushingModel]:
    """The description's bushings and struts with their frames placed on the bodies."""
    bushings = []
    for b in desc.bushings:
        body1, r1, c1 = _frame_on_body(link_frames, b.frame1.link, b.frame1.xyz, b.frame1.rpy)
        body2, r2, c2 = _frame_on_body(link_frames, b.frame2.link, b.frame2.xyz, b.frame2.rpy)
        bushings.append(BushingModel(b.name, body1, r1, c1, body2, r2, c2, b.stiffness, b.damping))
    return bushings


def _loops(desc: RobotDescription, link_frames: dict) -> list[LoopModel]:
    """The description's loop closures with their frames placed on the bodies."""
    return [
        LoopModel(
            loop.name,
            loop.rows,
            *_frame_on_body(link_frames, loop.frame1.link, loop.frame1.xyz, loop.frame1.rpy),
            *_frame_on_body(link_frames, loop.frame2.link, loop.frame2.xyz, loop.frame2.rpy),
        )
        for loop in desc.loops
    ]


def _unskew(m: np.ndarray) -> np.ndarray:
    """The vector x of a skew matrix ``<x>``."""
    return np.array([m[2, 1], m[0, 2], m[1, 0]])


def _frame_on_body(
    link_frames: dict, link: str, xyz: np.ndarray, rpy: np.ndarray
) -> tuple[int, np.ndarray, np.ndarray]:
    """``(body, r, c)`` of the frame ``(xyz, rpy)`` of ``link``, placed on the link's body."""
    body, r_link, c_link = link_frames[link]
    return body, r_link + c_link @ xyz, c_link @ rpy_matrix(rpy)
