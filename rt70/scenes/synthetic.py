"""Seeded synthetic scenes: URDF text of random chains, trees and elastic chains.

The generators here feed property tests of the cross-check (textbook against
Pinocchio) with models nobody wrote by hand. Each returns the URDF text of one scene
(root link ``world``, rt70 extension namespace declared, ``<limit>`` on every revolute
and prismatic joint because Pinocchio's URDF parser requires it) and is deterministic:
the same arguments give the same text, byte for byte. Numbers are written with
``repr`` (17 significant digits at most), so both readers see exactly the same floats.

Generators
----------
:func:`serial_chain`
    n bodies in series.
:func:`balanced_tree`
    n bodies in a breadth-first balanced tree.
:func:`elastic_chain`
    n bodies, each on the book's 6-DOF elastic pair (the layout of ``urdf/rt70.urdf``)
    with a direct bushing.
:func:`random_tree`
    a random tree with random joint types, axes, origins, inertias, massless links,
    joint springs, bushings and gravity.

Joint types
-----------
``revolute`` and ``prismatic`` joints get wide ``<limit>`` elements that never bind;
``continuous``, ``floating`` and ``planar`` joints get none (Pinocchio does not need
one). ``floating`` and ``fixed`` joints get no ``<axis>``. A ``planar`` joint is always
written with ``<axis xyz="0 0 1"/>``: URDF defines the plane of motion as the one normal
to ``<axis>``, but Pinocchio's URDF parser ignores the axis and always builds
``JointModelPlanar`` (translation along x and y and rotation about z of the joint
frame), so a planar joint with any other axis would be a different mechanism on the
two sides. The orientation of the plane is varied through the joint's ``<origin rpy>``
instead.

Massless links
--------------
A mass matrix ``A = S Θ Sᵀ`` is singular when some non-zero ``q̇`` leaves every body
with mass at rest, i.e. when some coordinate moves no mass. A massless leaf on a
moving joint is the obvious case; so is a massless link whose only massive child is on
a joint that can undo the link's own motion (a coaxial revolute joint, a parallel
prismatic joint, a floating or planar joint). :func:`random_tree` therefore makes a
link massless only if it is not a leaf, its own joint is ``fixed`` or 1-DOF, and one
of its children has mass and hangs on a ``fixed`` joint or on a 1-DOF joint whose axis
makes at least 30° with the link's own axis. Then, going from the root outwards, a
state in which every massive body is at rest has ``q̇ = 0`` at every joint, so ``A``
is positive definite.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from rt70.physics.rotations import rpy_matrix, rpy_of_matrix
from rt70.scenes.pairs import PAIR_JOINTS
from rt70.scenes.urdf_writer import ROOT_LINK, RT70_NS, fmt, fmt_vec

#: Every joint type of the URDF standard, as :func:`random_tree` draws them.
ALL_JOINT_TYPES = ("revolute", "prismatic", "fixed", "continuous", "floating", "planar")

#: Joint types with one coordinate.
ONE_DOF_JOINT_TYPES = ("revolute", "prismatic", "continuous")

#: Joint types that get a random ``<rt70:joint_spring>`` (the reader accepts 1-DOF joints).
SPRING_JOINT_TYPES = ONE_DOF_JOINT_TYPES

# Joint types whose child may be massless (see the module docstring).
_MASSLESS_JOINT_TYPES = ("fixed", *ONE_DOF_JOINT_TYPES)
# |cos| of the smallest angle between a massless link's axis and its witness child's.
_MAX_AXIS_COS = math.cos(math.radians(30.0))
# Wide limits that never bind (Pinocchio's URDF parser requires <limit>).
_LIMIT = 'lower="-1000" upper="1000" effort="1e+12" velocity="1e+06"'
_ZERO3 = (0.0, 0.0, 0.0)


# ---------------------------------------------------------------------------------------
# Numbers, rotations and XML
# ---------------------------------------------------------------------------------------


def _pose(xyz: Sequence[float], rpy: Sequence[float]) -> np.ndarray:
    """Homogeneous 4 × 4 transform of a URDF origin."""
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = xyz
    return out


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A rotation matrix uniform on SO(3) (normalised Gaussian quaternion)."""
    w, x, y, z = rng.normal(size=4)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _random_rpy(rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(-math.pi, math.pi, 3)


def _random_axis(rng: np.random.Generator, aligned: float = 0.3) -> np.ndarray:
    """A unit axis: with probability ``aligned`` exactly ±x, ±y or ±z, else any direction."""
    if rng.random() < aligned:
        axis = np.zeros(3)
        axis[rng.integers(3)] = rng.choice((-1.0, 1.0))
        return axis
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _log_uniform(rng: np.random.Generator, low: float, high: float, size=None):
    return np.exp(rng.uniform(math.log(low), math.log(high), size))


class _Writer:
    """Line-oriented XML writer with two-space indentation."""

    def __init__(self, name: str, comment: str) -> None:
        self.lines = [
            '<?xml version="1.0"?>',
            f"<!-- {comment} -->",
            "<!-- Generated by rt70.scenes.synthetic; do not edit by hand. -->",
            f'<robot name="{name}" xmlns:rt70="{RT70_NS}">',
            f'  <link name="{ROOT_LINK}"/>',
        ]

    def add(self, line: str, depth: int = 1) -> None:
        self.lines.append("  " * depth + line)

    def text(self) -> str:
        return "\n".join([*self.lines, "</robot>"]) + "\n"


# ---------------------------------------------------------------------------------------
# Bodies
# ---------------------------------------------------------------------------------------


class _Body:
    """One generated link and the joint that carries it."""

    def __init__(self, name: str, joint: str, jtype: str, parent: str) -> None:
        self.name = name
        self.joint = joint
        self.jtype = jtype
        self.parent = parent
        self.xyz = np.zeros(3)
        self.rpy = np.zeros(3)
        self.axis = np.array([0.0, 0.0, 1.0])
        # (mass, com xyz, com rpy, inertia tensor in the rotated COM frame) or None
        self.inertial: tuple[float, np.ndarray, np.ndarray, np.ndarray] | None = None

    def axis_in_link_frame(self) -> np.ndarray:
        """The joint axis in the parent link's frame."""
        return rpy_matrix(self.rpy) @ self.axis


def _random_inertial(rng: np.random.Generator) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Mass in [0.1, 10] kg (log-uniform), COM and its frame random, valid inertia tensor.

    Principal moments ``b + c, a + c, a + b`` with ``a, b, c > 0`` satisfy the triangle
    inequality strictly; a random rotation gives the tensor off-diagonal terms.
    """
    mass = float(_log_uniform(rng, 0.1, 10.0))
    a, b, c = mass * rng.uniform(0.005, 0.2, 3)
    rot = _random_rotation(rng)
    tensor = rot @ np.diag([b + c, a + c, a + b]) @ rot.T
    tensor = 0.5 * (tensor + tensor.T)
    return mass, rng.uniform(-0.3, 0.3, 3), _random_rpy(rng), tensor


def _random_joint_geometry(rng: np.random.Generator, body: _Body, reach: float = 0.6) -> None:
    """Random origin (xyz, rpy) and, for the joint types that use one, a random axis."""
    body.xyz = rng.uniform(-reach, reach, 3)
    body.rpy = _random_rpy(rng)
    if body.jtype in ONE_DOF_JOINT_TYPES:
        body.axis = _random_axis(rng)
    else:
        body.axis = np.array([0.0, 0.0, 1.0])  # planar: Pinocchio's plane; unused otherwise


def _write_joint(w: _Writer, body: _Body) -> None:
    w.add(f'<joint name="{body.joint}" type="{body.jtype}">')
    w.add(f'<parent link="{body.parent}"/>', 2)
    w.add(f'<child link="{body.name}"/>', 2)
    w.add(f'<origin xyz="{fmt_vec(body.xyz)}" rpy="{fmt_vec(body.rpy)}"/>', 2)
    if body.jtype in (*ONE_DOF_JOINT_TYPES, "planar"):
        w.add(f'<axis xyz="{fmt_vec(body.axis)}"/>', 2)
    if body.jtype in ("revolute", "prismatic"):
        w.add(f"<limit {_LIMIT}/>", 2)
    w.add("</joint>")


def _write_link(w: _Writer, body: _Body) -> None:
    if body.inertial is None:
        w.add(f'<link name="{body.name}"/>')
        return
    mass, com, com_rpy, t = body.inertial
    w.add(f'<link name="{body.name}">')
    w.add("<inertial>", 2)
    w.add(f'<origin xyz="{fmt_vec(com)}" rpy="{fmt_vec(com_rpy)}"/>', 3)
    w.add(f'<mass value="{fmt(mass)}"/>', 3)
    w.add(
        f'<inertia ixx="{fmt(t[0, 0])}" ixy="{fmt(t[0, 1])}" ixz="{fmt(t[0, 2])}" '
        f'iyy="{fmt(t[1, 1])}" iyz="{fmt(t[1, 2])}" izz="{fmt(t[2, 2])}"/>',
        3,
    )
    w.add("</inertial>", 2)
    w.add("</link>")


def _write_bodies(w: _Writer, bodies: Sequence[_Body]) -> None:
    for body in bodies:
        _write_joint(w, body)
        _write_link(w, body)


def _write_gravity(w: _Writer, gravity: Sequence[float]) -> None:
    w.add(f'<rt70:gravity xyz="{fmt_vec(gravity)}"/>')


def _write_joint_spring(w: _Writer, joint: str, stiffness: float, damping: float) -> None:
    w.add(
        f'<rt70:joint_spring name="{joint}_spring" joint="{joint}" '
        f'stiffness="{fmt(stiffness)}" damping="{fmt(damping)}"/>'
    )


def _write_bushing(
    w: _Writer,
    name: str,
    frame1: tuple[str, Sequence[float], Sequence[float]],
    frame2: tuple[str, Sequence[float], Sequence[float]],
    stiffness: Sequence[float],
    damping: Sequence[float],
) -> None:
    gains = f'stiffness="{fmt_vec(stiffness)}" damping="{fmt_vec(damping)}"'
    w.add(f'<rt70:bushing name="{name}" {gains}>')
    for tag, (link, xyz, rpy) in (("frame1", frame1), ("frame2", frame2)):
        w.add(f'<rt70:{tag} link="{link}" xyz="{fmt_vec(xyz)}" rpy="{fmt_vec(rpy)}"/>', 2)
    w.add("</rt70:bushing>")


def _random_joint_springs(
    w: _Writer, rng: np.random.Generator, bodies: Sequence[_Body], probability: float
) -> None:
    """A ``<rt70:joint_spring>`` on each 1-DOF joint with ``probability``."""
    for body in bodies:
        if body.jtype in SPRING_JOINT_TYPES and rng.random() < probability:
            stiffness = float(_log_uniform(rng, 1.0, 1.0e3))
            damping = float(_log_uniform(rng, 0.01, 10.0))
            _write_joint_spring(w, body.joint, stiffness, damping)


def _bodies(n: int) -> str:
    return f"{n} body" if n == 1 else f"{n} bodies"


def _check_joint_types(joint_types: Sequence[str]) -> tuple[str, ...]:
    types = tuple(joint_types)
    if not types:
        raise ValueError("joint_types must name at least one joint type")
    unknown = [t for t in types if t not in ALL_JOINT_TYPES]
    if unknown:
        raise ValueError(f"unknown joint types {unknown} (known: {', '.join(ALL_JOINT_TYPES)})")
    return types


def _massive_tree(
    name: str,
    comment: str,
    parents: Sequence[int],
    seed: int,
    joint_types: Sequence[str],
) -> str:
    """Every body massive; random types, axes, origins, inertias; springs on ~40 % of joints."""
    types = _check_joint_types(joint_types)
    rng = np.random.default_rng(seed)
    bodies = []
    for i, p in enumerate(parents):
        parent = ROOT_LINK if p < 0 else f"b{p + 1}"
        body = _Body(f"b{i + 1}", f"j{i + 1}", str(rng.choice(types)), parent)
        _random_joint_geometry(rng, body, reach=0.4)
        body.inertial = _random_inertial(rng)
        bodies.append(body)
    w = _Writer(name, comment)
    _write_bodies(w, bodies)
    _write_gravity(w, (0.0, 0.0, -9.81))
    _random_joint_springs(w, rng, bodies, 0.4)
    return w.text()


# ---------------------------------------------------------------------------------------
# Public generators
# ---------------------------------------------------------------------------------------


def serial_chain(n_bodies: int, seed: int = 0, joint_types: Sequence[str] = ("revolute",)) -> str:
    """URDF text of a serial chain of ``n_bodies`` massive bodies.

    Body ``b1`` hangs on ``world`` by joint ``j1``, body ``b<k+1>`` on ``b<k>`` by
    ``j<k+1>``. Joint types are drawn uniformly from ``joint_types``; axes are random
    unit vectors (some exactly ±x, ±y, ±z), joint origins random (xyz within ±0.4 m,
    any rpy), inertias random (see :func:`random_tree`). About 40 % of the 1-DOF joints
    carry a ``<rt70:joint_spring>``; gravity is ``0 0 -9.81``.

    Parameters
    ----------
    n_bodies : int
        Number of bodies (≥ 1).
    seed : int, optional
        Seed of the random generator; the text is a function of the arguments.
    joint_types : sequence of str, optional
        Joint types to draw from, a subset of :data:`ALL_JOINT_TYPES`.

    Returns
    -------
    str
        The URDF text.

    Raises
    ------
    ValueError
        If ``n_bodies < 1`` or a joint type is unknown.
    """
    if n_bodies < 1:
        raise ValueError(f"n_bodies must be at least 1, got {n_bodies}")
    parents = list(range(-1, n_bodies - 1))
    return _massive_tree(
        f"serial_chain_{n_bodies}_s{seed}",
        f"Serial chain of {_bodies(n_bodies)}, seed {seed}",
        parents,
        seed,
        joint_types,
    )


def balanced_tree(
    n_bodies: int,
    branching: int = 2,
    seed: int = 0,
    joint_types: Sequence[str] = ("revolute",),
) -> str:
    """URDF text of a breadth-first balanced tree of ``n_bodies`` massive bodies.

    Body ``b1`` hangs on ``world``; body ``b<k>`` (k ≥ 2) hangs on body
    ``b<(k - 2) // branching + 1>``, so the tree is filled level by level with
    ``branching`` children per body. Geometry, inertias, springs and gravity as in
    :func:`serial_chain`.

    Parameters
    ----------
    n_bodies : int
        Number of bodies (≥ 1).
    branching : int, optional
        Children per body (≥ 1; 1 gives a serial chain).
    seed : int, optional
        Seed of the random generator.
    joint_types : sequence of str, optional
        Joint types to draw from, a subset of :data:`ALL_JOINT_TYPES`.

    Returns
    -------
    str
        The URDF text.

    Raises
    ------
    ValueError
        If ``n_bodies < 1``, ``branching < 1`` or a joint type is unknown.
    """
    if n_bodies < 1:
        raise ValueError(f"n_bodies must be at least 1, got {n_bodies}")
    if branching < 1:
        raise ValueError(f"branching must be at least 1, got {branching}")
    parents = [-1] + [(i - 1) // branching for i in range(1, n_bodies)]
    return _massive_tree(
        f"balanced_tree_{n_bodies}_{branching}_s{seed}",
        f"Balanced tree of {_bodies(n_bodies)}, branching {branching}, seed {seed}",
        parents,
        seed,
        joint_types,
    )


def elastic_chain(n_bodies: int, seed: int = 0) -> str:
    """URDF text of a chain of bodies on the book's 6-DOF elastic pairs (as ``rt70.urdf``).

    Body ``body<k>`` is joined to its parent (``world`` for k = 1, else ``body<k-1>``) by
    six 1-DOF joints in series — prismatic x, y, z, then revolute x, y, z, named
    ``body<k>_x`` … ``body<k>_rz`` — with massless intermediate links
    ``body<k>_x_link`` … ``body<k>_ry_link``. Only the first joint has an origin, the
    construction frame ``E_jc`` (random: x, y within ±0.2 m, z in [0.5, 2] m, rpy
    within ±0.3 rad); the other five origins are zero, so the textbook reads the six
    joints as one ``euler6`` pair. A ``<rt70:bushing>`` joins the construction frame
    (frame 1) to the body frame (frame 2), so its deformation is exactly the pair's
    coordinates ``[x, y, z, β, θ, α]`` (the book's direct elastic pair). Stiffnesses are
    log-uniform in [1e4, 1e5] N/m and [1e3, 1e4] N·m/rad, damping 1 % of them. Body
    inertias are random (see :func:`random_tree`); gravity is ``0 0 -9.81`` (z up).

    Parameters
    ----------
    n_bodies : int
        Number of bodies (≥ 1); the scene has ``6 n_bodies`` coordinates.
    seed : int, optional
        Seed of the random generator.

    Returns
    -------
    str
        The URDF text.

    Raises
    ------
    ValueError
        If ``n_bodies < 1``.
    """
    if n_bodies < 1:
        raise ValueError(f"n_bodies must be at least 1, got {n_bodies}")
    rng = np.random.default_rng(seed)
    w = _Writer(
        f"elastic_chain_{n_bodies}_s{seed}",
        f"Chain of {_bodies(n_bodies)} on 6-DOF elastic pairs, seed {seed}",
    )
    pairs = []
    parent = ROOT_LINK
    for k in range(1, n_bodies + 1):
        body = f"body{k}"
        offset = np.array([*rng.uniform(-0.2, 0.2, 2), rng.uniform(0.5, 2.0)])
        offset_rpy = rng.uniform(-0.3, 0.3, 3)
        w.add(f"<!-- {body}: 6-DOF pair on {parent}, construction offset [{fmt_vec(offset)}] -->")
        previous = parent
        for step, (suffix, jtype, axis) in enumerate(PAIR_JOINTS):
            last = step == len(PAIR_JOINTS) - 1
            child = body if last else f"{body}_{suffix}_link"
            link = _Body(child, f"{body}_{suffix}", jtype, previous)
            if step == 0:
                link.xyz, link.rpy = offset, offset_rpy
            link.axis = np.array(axis)
            if last:
                link.inertial = _random_inertial(rng)
            _write_joint(w, link)
            _write_link(w, link)
            previous = link.name
        stiffness = np.concatenate(
            [_log_uniform(rng, 1.0e4, 1.0e5, 3), _log_uniform(rng, 1.0e3, 1.0e4, 3)]
        )
        pairs.append((parent, body, offset, offset_rpy, stiffness))
        parent = body
    _write_gravity(w, (0.0, 0.0, -9.81))
    for parent, body, offset, offset_rpy, stiffness in pairs:
        _write_bushing(
            w,
            f"{parent}_{body}",
            (parent, offset, offset_rpy),
            (body, _ZERO3, _ZERO3),
            stiffness,
            0.01 * stiffness,
        )
    return w.text()


def random_tree(
    seed: int,
    n_bodies: int | None = None,
    joint_types: Sequence[str] = ALL_JOINT_TYPES,
) -> str:
    """URDF text of a random tree of bodies, springs and bushings.

    Drawn from ``numpy.random.default_rng(seed)``:

    - the number of bodies, uniform in 2..8 unless ``n_bodies`` is given;
    - the tree: body ``b<k>`` (joint ``j<k>``) hangs on a parent uniform among
      ``world`` and the bodies ``b1 … b<k-1>``;
    - each joint's type, uniform over the entries of ``joint_types``; a ``floating``
      joint's body always has mass; if every drawn joint is ``fixed``, the first body's
      joint becomes the first moving type of ``joint_types`` (new origin and axis), so
      the tree has a degree of freedom to check;
    - joint origins (xyz within ±0.6 m, rpy uniform in ±π); axes of 1-DOF joints: with
      probability 0.3 exactly ±x, ±y or ±z, else a uniformly random unit vector; planar
      joints always ``0 0 1`` (see the module docstring: Pinocchio ignores the planar
      axis, the plane is oriented by the origin's rpy);
    - inertials: mass log-uniform in [0.1, 10] kg, centre of mass within ±0.3 m,
      ``<inertial><origin rpy>`` uniform in ±π, principal moments ``b + c, a + c, a + b``
      (``a, b, c`` uniform in [0.005, 0.2] · mass) rotated by a uniform random rotation;
    - massless links (no ``<inertial>``): each non-leaf link with probability 0.4, kept
      only where it cannot make the mass matrix singular (module docstring) — about
      a third of the non-leaf links with the basic joint types, a sixth with all types;
    - a ``<rt70:joint_spring>`` on each 1-DOF joint (revolute, prismatic, continuous)
      with probability 0.4 (stiffness log-uniform in [1, 1e3], damping in [0.01, 10]);
    - 0 to 2 ``<rt70:bushing>`` elements between random pairs of links (``world``
      included) that are not welded together by fixed joints: frame 1 at a random
      placement (xyz within ±0.5 m, any rpy) on its link, frame 2 on its link where
      frame 1 is at q = 0 up to a small random pre-stress (±0.05 m, ±0.1 rad), so that
      the Euler angles of the deformation stay far from gimbal lock; six stiffnesses
      log-uniform in [1, 1e3], damping in [0.01, 10];
    - gravity: a Gaussian vector with standard deviation 5 m/s² per component.

    Parameters
    ----------
    seed : int
        Seed of the random generator; the text is a function of the arguments.
    n_bodies : int, optional
        Number of bodies (≥ 1); random in 2..8 if omitted.
    joint_types : sequence of str, optional
        Joint types to draw from, a subset of :data:`ALL_JOINT_TYPES` (default: all);
        a type listed twice is drawn twice as often.

    Returns
    -------
    str
        The URDF text.

    Raises
    ------
    ValueError
        If ``n_bodies < 1`` or a joint type is unknown.
    """
    types = _check_joint_types(joint_types)
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 9)) if n_bodies is None else int(n_bodies)
    if n < 1:
        raise ValueError(f"n_bodies must be at least 1, got {n}")
    parents = [int(rng.integers(-1, i)) for i in range(n)]
    children: list[list[int]] = [[] for _ in range(n)]
    for i, p in enumerate(parents):
        if p >= 0:
            children[p].append(i)
    bodies = []
    for i, p in enumerate(parents):
        parent = ROOT_LINK if p < 0 else f"b{p + 1}"
        body = _Body(f"b{i + 1}", f"j{i + 1}", str(rng.choice(types)), parent)
        _random_joint_geometry(rng, body)
        body.inertial = _random_inertial(rng)
        bodies.append(body)
    moving = [t for t in types if t != "fixed"]
    if moving and all(b.jtype == "fixed" for b in bodies):  # a model that moves at all
        bodies[0].jtype = moving[0]
        _random_joint_geometry(rng, bodies[0])

    # Massless links: non-leaf, fixed or 1-DOF joint, and a massive "witness" child on a
    # fixed joint or on a 1-DOF joint at least 30° off the link's own axis.
    massless = [
        bool(children[i]) and bodies[i].jtype in _MASSLESS_JOINT_TYPES and rng.random() < 0.4
        for i in range(n)
    ]
    for i in range(n):
        if not massless[i]:
            continue
        witnesses = [
            c for c in children[i] if not massless[c] and bodies[c].jtype in _MASSLESS_JOINT_TYPES
        ]
        if not witnesses:
            massless[i] = False
            continue
        witness = bodies[witnesses[0]]
        if bodies[i].jtype != "fixed" and witness.jtype != "fixed":
            own = bodies[i].axis
            while abs(float(own @ witness.axis_in_link_frame())) > _MAX_AXIS_COS:
                _random_joint_geometry(rng, witness)
        bodies[i].inertial = None

    w = _Writer(f"random_tree_s{seed}", f"Random tree of {_bodies(n)}, seed {seed}")
    _write_bodies(w, bodies)
    _write_gravity(w, rng.normal(0.0, 5.0, 3))
    _random_joint_springs(w, rng, bodies, 0.4)

    # World placement of every link at q = 0 (every joint at its zero / neutral), and the
    # rigid group of every link (links welded by fixed joints move as one body).
    world = {ROOT_LINK: np.eye(4)}
    rigid = {ROOT_LINK: ROOT_LINK}
    for body in bodies:  # parents precede children
        world[body.name] = world[body.parent] @ _pose(body.xyz, body.rpy)
        rigid[body.name] = rigid[body.parent] if body.jtype == "fixed" else body.name
    links = [ROOT_LINK, *(b.name for b in bodies)]
    # a bushing inside one rigid group would have a constant deformation and no force
    pairs = [(a, b) for a in links for b in links if a != b and rigid[a] != rigid[b]]
    for k in range(int(rng.integers(0, 3)) if pairs else 0):
        link1, link2 = pairs[int(rng.integers(len(pairs)))]
        xyz1, rpy1 = rng.uniform(-0.5, 0.5, 3), _random_rpy(rng)
        pre_stress = _pose(rng.uniform(-0.05, 0.05, 3), rng.uniform(-0.1, 0.1, 3))
        frame2 = np.linalg.solve(world[link2], world[link1] @ _pose(xyz1, rpy1) @ pre_stress)
        _write_bushing(
            w,
            f"bushing{k + 1}",
            (link1, xyz1, rpy1),
            (link2, frame2[:3, 3], rpy_of_matrix(frame2[:3, :3])),
            _log_uniform(rng, 1.0, 1.0e3, 6),
            _log_uniform(rng, 0.01, 10.0, 6),
        )
    return w.text()
