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

from rt70.physics.rotations import rpy_of_matrix
from rt70.scenes.pairs import PAIR_JOINTS
from rt70.scenes.synthetic_draws import (
    ONE_DOF_JOINT_TYPES,
    Body,
    log_uniform,
    pose,
    random_inertial,
    random_joint_geometry,
    random_rpy,
)
from rt70.scenes.synthetic_xml import (
    Writer,
    write_bodies,
    write_bushing,
    write_gravity,
    write_joint,
    write_joint_spring,
    write_link,
)
from rt70.scenes.urdf_writer import ROOT_LINK, fmt_vec

#: Every joint type of the URDF standard, as :func:`random_tree` draws them.
ALL_JOINT_TYPES = ("revolute", "prismatic", "fixed", "continuous", "floating", "planar")

#: Joint types that get a random ``<rt70:joint_spring>`` (the reader accepts 1-DOF joints).
SPRING_JOINT_TYPES = ONE_DOF_JOINT_TYPES

# Joint types whose child may be massless (see the module docstring).
_MASSLESS_JOINT_TYPES = ("fixed", *ONE_DOF_JOINT_TYPES)
# |cos| of the smallest angle between a massless link's axis and its witness child's.
_MAX_AXIS_COS = math.cos(math.radians(30.0))
_ZERO3 = (0.0, 0.0, 0.0)


def _random_joint_springs(
    w: Writer, rng: np.random.Generator, bodies: Sequence[Body], probability: float
) -> None:
    """A ``<rt70:joint_spring>`` on each 1-DOF joint with ``probability``."""
    for body in bodies:
        if body.jtype in SPRING_JOINT_TYPES and rng.random() < probability:
            stiffness = float(log_uniform(rng, 1.0, 1.0e3))
            damping = float(log_uniform(rng, 0.01, 10.0))
            write_joint_spring(w, body.joint, stiffness, damping)


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
        body = Body(f"b{i + 1}", f"j{i + 1}", str(rng.choice(types)), parent)
        random_joint_geometry(rng, body, reach=0.4)
        body.inertial = random_inertial(rng)
        bodies.append(body)
    w = Writer(name, comment)
    write_bodies(w, bodies)
    write_gravity(w, (0.0, 0.0, -9.81))
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


def elastic_chain(n_bodies: int, seed: int = 0, hanging: bool = False) -> str:
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
    hanging : bool, optional
        Hang the chain from the world: each construction frame straight below its
        parent's (z negated, x, y and the rotation dropped; the same draws otherwise),
        so that gravity stretches the chain instead of buckling it. A standing chain of
        more than some ten bodies has no stable equilibrium at these stiffnesses (nor
        has one whose random frame rotations curl it upwards), and a crooked hanging
        one sags by tens of degrees per pair; a straight hanging one hangs near its
        drawn shape at any length.

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
    how = "hanging " if hanging else ""
    w = Writer(
        f"elastic_chain_{n_bodies}_s{seed}" + ("_hanging" if hanging else ""),
        f"Chain of {_bodies(n_bodies)} on 6-DOF elastic pairs, {how}seed {seed}",
    )
    pairs = []
    parent = ROOT_LINK
    for k in range(1, n_bodies + 1):
        body = f"body{k}"
        offset = np.array([*rng.uniform(-0.2, 0.2, 2), rng.uniform(0.5, 2.0)])
        offset_rpy = rng.uniform(-0.3, 0.3, 3)
        if hanging:
            offset, offset_rpy = np.array([0.0, 0.0, -offset[2]]), np.zeros(3)
        w.add(f"<!-- {body}: 6-DOF pair on {parent}, construction offset [{fmt_vec(offset)}] -->")
        _write_pair(w, rng, parent, body, offset, offset_rpy)
        stiffness = np.concatenate(
            [log_uniform(rng, 1.0e4, 1.0e5, 3), log_uniform(rng, 1.0e3, 1.0e4, 3)]
        )
        pairs.append((parent, body, offset, offset_rpy, stiffness))
        parent = body
    write_gravity(w, (0.0, 0.0, -9.81))
    for parent, body, offset, offset_rpy, stiffness in pairs:
        write_bushing(
            w,
            f"{parent}_{body}",
            (parent, offset, offset_rpy),
            (body, _ZERO3, _ZERO3),
            stiffness,
            0.01 * stiffness,
        )
    return w.text()


def _write_pair(
    w: Writer,
    rng: np.random.Generator,
    parent: str,
    body: str,
    offset: np.ndarray,
    offset_rpy: np.ndarray,
) -> None:
    """The six joints and links of ``body``'s elastic pair on ``parent`` (:func:`elastic_chain`).

    Parameters
    ----------
    w : Writer
        The URDF text being written.
    rng : numpy.random.Generator
        Draws the body's inertial.
    parent, body : str
        The pair's two links.
    offset, offset_rpy : numpy.ndarray
        The construction frame's origin (m) and rotation (rad) in ``parent``.
    """
    previous = parent
    for step, (suffix, jtype, axis) in enumerate(PAIR_JOINTS):
        last = step == len(PAIR_JOINTS) - 1
        child = body if last else f"{body}_{suffix}_link"
        link = Body(child, f"{body}_{suffix}", jtype, previous)
        if step == 0:
            link.xyz, link.rpy = offset, offset_rpy
        link.axis = np.array(axis)
        if last:
            link.inertial = random_inertial(rng)
        write_joint(w, link)
        write_link(w, link)
        previous = link.name


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
    bodies = _random_bodies(rng, parents, types)
    _make_massless(rng, bodies, parents)
    w = Writer(f"random_tree_s{seed}", f"Random tree of {_bodies(n)}, seed {seed}")
    write_bodies(w, bodies)
    write_gravity(w, rng.normal(0.0, 5.0, 3))
    _random_joint_springs(w, rng, bodies, 0.4)
    _random_bushings(w, rng, bodies)
    return w.text()


def _random_bodies(
    rng: np.random.Generator, parents: Sequence[int], types: tuple[str, ...]
) -> list[Body]:
    """Every body massive, joint type drawn from ``types``; one moving joint at least."""
    bodies = []
    for i, p in enumerate(parents):
        parent = ROOT_LINK if p < 0 else f"b{p + 1}"
        body = Body(f"b{i + 1}", f"j{i + 1}", str(rng.choice(types)), parent)
        random_joint_geometry(rng, body)
        body.inertial = random_inertial(rng)
        bodies.append(body)
    moving = [t for t in types if t != "fixed"]
    if moving and all(b.jtype == "fixed" for b in bodies):  # a model that moves at all
        bodies[0].jtype = moving[0]
        random_joint_geometry(rng, bodies[0])
    return bodies


def _make_massless(rng: np.random.Generator, bodies: list[Body], parents: Sequence[int]) -> None:
    """Drop the inertia of links that cannot make the mass matrix singular (module docstring).

    Each non-leaf link on a fixed or 1-DOF joint is a candidate with probability 0.4; it
    is kept if a massive "witness" child hangs on a fixed joint or on a 1-DOF joint at
    least 30° off the link's own axis (the witness's joint is redrawn until it is).
    """
    n = len(bodies)
    children: list[list[int]] = [[] for _ in range(n)]
    for i, p in enumerate(parents):
        if p >= 0:
            children[p].append(i)
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
                random_joint_geometry(rng, witness)
        bodies[i].inertial = None


def _random_bushings(w: Writer, rng: np.random.Generator, bodies: Sequence[Body]) -> None:
    """0 to 2 bushings between links not welded together, slightly pre-stressed at q = 0."""
    # World placement of every link at q = 0 (every joint at its zero / neutral), and the
    # rigid group of every link (links welded by fixed joints move as one body).
    world = {ROOT_LINK: np.eye(4)}
    rigid = {ROOT_LINK: ROOT_LINK}
    for body in bodies:  # parents precede children
        world[body.name] = world[body.parent] @ pose(body.xyz, body.rpy)
        rigid[body.name] = rigid[body.parent] if body.jtype == "fixed" else body.name
    links = [ROOT_LINK, *(b.name for b in bodies)]
    # a bushing inside one rigid group would have a constant deformation and no force
    pairs = [(a, b) for a in links for b in links if a != b and rigid[a] != rigid[b]]
    for k in range(int(rng.integers(0, 3)) if pairs else 0):
        link1, link2 = pairs[int(rng.integers(len(pairs)))]
        xyz1, rpy1 = rng.uniform(-0.5, 0.5, 3), random_rpy(rng)
        pre_stress = pose(rng.uniform(-0.05, 0.05, 3), rng.uniform(-0.1, 0.1, 3))
        frame2 = np.linalg.solve(world[link2], world[link1] @ pose(xyz1, rpy1) @ pre_stress)
        write_bushing(
            w,
            f"bushing{k + 1}",
            (link1, xyz1, rpy1),
            (link2, frame2[:3, 3], rpy_of_matrix(frame2[:3, :3])),
            log_uniform(rng, 1.0, 1.0e3, 6),
            log_uniform(rng, 0.01, 10.0, 6),
        )
