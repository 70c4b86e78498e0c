"""Locks of a scene that engage suddenly — brakes and stow pins — and their impact.

A lock is described in Python (no URDF element: a ``<rt70:loop>`` closure may later be
engaged the same way):

- :class:`Brake` ``(joint)`` holds a 1-DOF joint (an axis brake, a drive's holding
  brake): one row, ``q̇_joint = 0``;
- :class:`StowPin` ``(link, xyz)`` fixes the point ``xyz`` (link frame, m) of a link to
  the ground: three rows, the point's velocity in ground axes.

Each side builds the rows on its own (:mod:`rt70.textbook.locks`,
:mod:`rt70.reference.locks`); :func:`engage` solves the impact (15) with the textbook's
A and rows through :func:`rt70.physics.impact.solve_impact`, or with Pinocchio's
``impulseDynamics``. The command line is ``rt70 impact`` (:mod:`rt70.cli.impact`);
docs/impacts.md.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from rt70.errors import Rt70Error, UnknownLinkError
from rt70.model.scene import Scene, require_coordinates
from rt70.model.sides import check_side, side_of
from rt70.physics.impact import Impact, check_restitution, impact_energies, solve_impact

#: Largest coordinate of a stow pin's point, m: the bound of every number rt70 reads
#: from a model (``rt70.urdf.elements.MAX_MAGNITUDE``).
MAX_POINT = 1e30

#: URDF joint types a brake can hold.
BRAKE_JOINT_TYPES = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class Brake:
    """A brake on the 1-DOF joint ``joint``: ``q̇_joint⁺ = −e q̇_joint⁻`` (one row)."""

    joint: str

    @property
    def rows(self) -> int:
        """Number of constraint rows (1)."""
        return 1

    def labels(self) -> list[str]:
        """Names of the impulses: ``brake:<joint>``."""
        return [f"brake:{self.joint}"]


@dataclass(frozen=True)
class StowPin:
    """A stow pin fixing the point ``xyz`` (link frame, m) of ``link`` to the ground."""

    link: str
    xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        xyz = np.asarray(self.xyz, dtype=float)
        if xyz.shape != (3,) or not np.isfinite(xyz).all():
            raise Rt70Error(f"stow pin on '{self.link}': xyz must be 3 finite numbers")
        object.__setattr__(self, "xyz", xyz)

    @property
    def rows(self) -> int:
        """Number of constraint rows (3)."""
        return 3

    def labels(self) -> list[str]:
        """Names of the impulses: ``pin:<link>:x`` … (ground axes)."""
        return [f"pin:{self.link}:{a}" for a in "xyz"]


Lock = Brake | StowPin


def parse_pin(text: str) -> StowPin:
    """``LINK:x,y,z`` (or ``LINK`` for its origin) as a :class:`StowPin`."""
    link, _, point = text.rpartition(":") if ":" in text else (text, "", "")
    if not link:
        raise Rt70Error(f"stow pin '{text}': expected LINK:x,y,z")
    if not point:
        return StowPin(link)
    try:
        xyz = [float(v) for v in point.split(",")]
    except ValueError:
        raise Rt70Error(f"stow pin '{text}': the point must be three numbers x,y,z") from None
    if len(xyz) != 3:
        raise Rt70Error(f"stow pin '{text}': the point must be three numbers x,y,z")
    if not all(math.isfinite(v) and abs(v) <= MAX_POINT for v in xyz):
        raise Rt70Error(
            f"--pin {text}: the point must be finite, of magnitude at most {MAX_POINT:g} m "
            "(the largest number rt70 reads, docs/urdf-reader.md)"
        )
    return StowPin(link, np.array(xyz))


def labels(locks: Sequence[Lock]) -> list[str]:
    """Names of the impulses of ``locks``, in the order of Λ."""
    return [name for lock in locks for name in lock.labels()]


def check_locks(scene: Scene, locks: Sequence[Lock]) -> None:
    """Refuse locks the scene cannot take, naming the file and the element.

    Raises
    ------
    Rt70Error
        No lock; a brake on a joint that does not exist or is not 1-DOF (a mimic joint
        is fine; a fixed, floating or planar joint is not, nor a joint of an interface
        chain).
    UnknownLinkError
        A stow pin on a link without a frame on the textbook side, or on the ground.
    """
    require_coordinates(scene)
    if not locks:
        raise Rt70Error(f"{scene.path}: no lock to engage (a brake or a stow pin)")
    joints = {j.name: j for j in scene.description.joints}
    frames = scene.textbook.link_frames
    for lock in locks:
        if isinstance(lock, Brake):
            joint = joints.get(lock.joint)
            if joint is None:
                known = ", ".join(n for n, j in joints.items() if j.type in BRAKE_JOINT_TYPES)
                raise Rt70Error(
                    f"{scene.path}: brake on joint '{lock.joint}': no such joint "
                    f"(1-DOF joints: {known[:200]})"
                )
            if joint.type not in BRAKE_JOINT_TYPES:
                raise Rt70Error(
                    f"{scene.path}: brake on joint '{lock.joint}': it is {joint.type}, "
                    "not a 1-DOF joint"
                )
            if lock.joint in scene.description.node_joints:
                raise Rt70Error(
                    f"{scene.path}: brake on joint '{lock.joint}': it carries a link on a "
                    "modal body's node (<rt70:interface>) and moves with the modes"
                )
        elif isinstance(lock, StowPin):
            if lock.link not in frames or frames[lock.link][0] < 0:
                moving = [n for n, (b, _, _) in frames.items() if b >= 0]
                raise UnknownLinkError(
                    f"{scene.path}: stow pin on link '{lock.link}': not a moving link of "
                    f"the scene (links: {', '.join(moving)[:200]})"
                )
        else:
            raise Rt70Error(f"not a lock: {lock!r}")


def constraint_rows(scene: Scene, q: np.ndarray, locks: Sequence[Lock], side: str) -> np.ndarray:
    """The locks' rows ``B_c`` (m, nv) in the book's coordinates, computed by ``side``.

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates in the book's order, m or rad.
    locks : sequence of Lock
        The brakes and stow pins, rows in this order (:func:`labels`).
    side : {"textbook", "reference"}
        Whose kinematics (and, for :func:`engage`, whose impact solve).
    """
    s = side_of(scene, side)
    brakes, pins = _split(locks)
    return s.locks.book_rows(s.model, s.data, q, brakes, pins)[_order(locks)]


def engage(
    scene: Scene,
    q: np.ndarray,
    qd: np.ndarray,
    locks: Sequence[Lock],
    side: str = "textbook",
    restitution: float = 0.0,
    gamma: np.ndarray | None = None,
) -> Impact:
    """The impact (15) of ``locks`` engaging at ``(q, q̇⁻)``, solved by ``side``.

    ``"textbook"``: the book's A (S Θ Sᵀ) and the textbook's rows through
    :func:`rt70.physics.impact.solve_impact`; ``"reference"``: Pinocchio's ``impulseDynamics``
    (:func:`rt70.reference.locks.impulse_dynamics`), its energies from Pinocchio's A.
    Impulses are in the order of :func:`labels`.

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates in the book's order, m or rad.
    qd : numpy.ndarray, shape (nv,)
        ``q̇⁻``, the velocities just before the engagement, m/s or rad/s.
    locks : sequence of Lock
        The brakes and stow pins, rows in this order (:func:`labels`).
    side : {"textbook", "reference"}
        Whose kinematics (and, for :func:`engage`, whose impact solve).
    restitution : float
        e in [0, 1]; 0 (plastic) for brakes and stow pins.
    gamma : numpy.ndarray, shape (nv,), optional
        Known impulses Γ of external forces in the coordinates, N·s or N·m·s (sign:
        :mod:`rt70.physics.impact`); none by default.

    Raises
    ------
    Rt70Error
        On an unknown side, a lock the scene cannot take (:func:`check_locks`) or a
        restitution outside [0, 1].
    """
    check_side(side)
    check_locks(scene, locks)
    e = check_restitution(restitution)
    B_c = constraint_rows(scene, q, locks, side)
    s = side_of(scene, side)
    if s.name == "textbook":  # the book's A and rows through the shared solve of (15)
        A = s.dynamics.mass_matrix(s.model, s.data, q)
        return solve_impact(A, B_c, qd, e, gamma)
    brakes, pins = _split(locks)  # Pinocchio solves (15) itself
    qd1, lam = s.locks.impulse_dynamics(s.model, s.data, q, qd, brakes, pins, e, gamma)
    lam = lam[_order(locks)]
    A = s.dynamics.mass_matrix(s.model, s.data, q)
    rank = int(np.linalg.matrix_rank(B_c)) if B_c.size else 0
    return impact_energies(A, B_c, np.asarray(qd, dtype=float), qd1, lam, rank, e, gamma)


def _split(locks: Sequence[Lock]) -> tuple[list[str], list[tuple[str, np.ndarray]]]:
    """The reference side's arguments: the braked joints and the pins, each in order."""
    brakes = [lock.joint for lock in locks if isinstance(lock, Brake)]
    pins = [(lock.link, lock.xyz) for lock in locks if isinstance(lock, StowPin)]
    return brakes, pins


def _order(locks: Sequence[Lock]) -> np.ndarray:
    """Indices that put the reference side's rows (brakes, then pins) in ``locks``' order."""
    n_brakes = sum(isinstance(lock, Brake) for lock in locks)
    brake_at, pin_at, order = 0, n_brakes, []
    for lock in locks:
        if isinstance(lock, Brake):
            order.append(brake_at)
            brake_at += 1
        else:
            order.extend(range(pin_at, pin_at + 3))
            pin_at += 3
    return np.array(order, dtype=int)


def joint_impulses(
    scene: Scene, q: np.ndarray, impact: Impact, locks: Sequence[Lock], side: str = "textbook"
) -> dict[str, np.ndarray]:
    """Reaction impulses across every URDF joint during the impact (source 004 (16)).

    The two-stage kinetostatics of the impact: the velocity jump ``Δq̇ = q̇⁺ − q̇⁻`` in
    place of q̈ (no velocity products, gravity's impulse neglected), the pins' impulses
    Λ as forces on their points (ground axes), computed by ``side``'s
    ``reaction_impulses`` (:mod:`rt70.textbook.reactions`: R = L W of the body
    impulses; :mod:`rt70.reference.reactions`: ``rnea(q, 0, Δv, fext)`` with gravity
    off). A brake's impulse is the braked joint's own: its axis component. Per joint
    ``[F; M]`` in N·s and N·m·s, the joint's axes, about its origin (docs/reactions.md).

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q : numpy.ndarray, shape (nv,)
        The configuration of the impact, m or rad.
    impact : Impact
        The impact of ``locks`` there (:func:`engage`).
    locks : sequence of Lock
        The brakes and stow pins, rows in this order (:func:`labels`).
    side : {"textbook", "reference"}
        Whose kinetostatics.
    """
    from rt70.physics.loads import Wrench

    s = side_of(scene, side)
    dqd = impact.qd_after - impact.qd_before
    pins, at = [], 0
    for lock in locks:
        if isinstance(lock, StowPin):
            pins.append(Wrench(lock.link, lock.xyz, impact.impulses[at : at + 3], np.zeros(3)))
            at += 3
        else:
            at += 1
    return s.reactions.reaction_impulses(s.model, s.data, q, dqd, pins)
