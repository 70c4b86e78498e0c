"""Plain, validated data read from a URDF scene (no algorithms here)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rt70.physics.aerodynamics import DEFAULT_AIR_DENSITY
from rt70.physics.coefficient_tables import CoefficientTable
from rt70.urdf.beam_record import Beam
from rt70.urdf.modal_record import ModalBody
from rt70.urdf.mount_record import Mount, Optics

#: Joint types of the URDF standard.
URDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass(frozen=True)
class Inertial:
    """Mass properties of a link, expressed in the link frame.

    Attributes
    ----------
    mass : float
        Mass, kg.
    com : numpy.ndarray
        Centre of mass in the link frame, m, shape (3,).
    inertia : numpy.ndarray
        Rotational inertia about the centre of mass, axes of the link frame, kg·m²,
        shape (3, 3) (the URDF ``<inertial><origin rpy>`` rotation already applied).
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class InertiaRepair:
    """A rotational inertia repaired on request (``balance_inertia``), for the report.

    Attributes
    ----------
    link : str
        The link whose ``<inertia>`` was replaced.
    old_moments, new_moments : numpy.ndarray
        Principal moments before and after, kg·m², shape (3,).
    """

    link: str
    old_moments: np.ndarray
    new_moments: np.ndarray


@dataclass(frozen=True)
class Link:
    """A URDF link: a name and, if it has mass, its inertial."""

    name: str
    inertial: Inertial | None


@dataclass(frozen=True)
class Mimic:
    """URDF ``<mimic>``: ``q = multiplier · q_joint + offset`` (a holonomic constraint)."""

    joint: str
    multiplier: float
    offset: float


@dataclass(frozen=True)
class Joint:
    """A URDF joint.

    Attributes
    ----------
    name, type, parent, child : str
        As in URDF; ``parent``/``child`` are link names.
    xyz, rpy : numpy.ndarray
        Origin of the joint frame in the parent link frame (URDF convention).
    axis : numpy.ndarray
        Unit axis in the joint frame (meaningful for revolute, continuous, prismatic).
    mimic : Mimic or None
        The joint's ``<mimic>`` coupling, if any.
    """

    name: str
    type: str
    parent: str
    child: str
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray
    mimic: Mimic | None = None


@dataclass(frozen=True)
class FrameRef:
    """A frame rigidly attached to a link: placement ``(xyz, rpy)`` in the link frame."""

    link: str
    xyz: np.ndarray
    rpy: np.ndarray


@dataclass(frozen=True)
class Bushing:
    """A 6-D linear spring/damper between two frames (see docs/urdf-extensions.md).

    Attributes
    ----------
    stiffness, damping : numpy.ndarray
        C and D, symmetric positive semi-definite, shape (6, 6), rows and columns in the
        order x, y, z, rx, ry, rz of the deformation; given as 6 numbers, the diagonal.
    package : str or None
        Name of the strut package this bushing is a strut of, if any.
    """

    name: str
    frame1: FrameRef
    frame2: FrameRef
    stiffness: np.ndarray
    damping: np.ndarray
    package: str | None = None

    def __post_init__(self) -> None:
        for attr in ("stiffness", "damping"):
            value = np.asarray(getattr(self, attr), dtype=float)
            object.__setattr__(self, attr, np.diag(value) if value.shape == (6,) else value)

    @property
    def diagonal(self) -> bool:
        """Whether C and D are both diagonal (each axis on its own)."""
        return all(not np.any(m - np.diag(np.diag(m))) for m in (self.stiffness, self.damping))


@dataclass(frozen=True)
class Loop:
    """A loop closure by "coincidence of bases" (source 004 (14); docs/loops.md).

    The origins of the two frames coincide (``type="point"``: 3 rows) or the two frames
    coincide (``type="frame"``: 6 rows, the position rows then the orientation rows).
    ``frame2.link`` is the root link when the file says ``world``.
    """

    name: str
    type: str
    frame1: FrameRef
    frame2: FrameRef

    @property
    def rows(self) -> int:
        """Number of constraint rows: 3 (point) or 6 (frame)."""
        return 3 if self.type == "point" else 6


@dataclass(frozen=True)
class JointSpring:
    """A scalar spring and damper on the coordinate of one 1-DOF joint."""

    name: str
    joint: str
    stiffness: float
    damping: float


@dataclass(frozen=True)
class NoSlip:
    """A linear velocity constraint ``A(q) q̇ = 0`` (``<rt70:no_slip>``, source 002 (1.1)).

    The material point of ``link`` at ``xyz`` (link frame), or, for a wheel of
    ``radius`` a > 0, the material point at ``xyz − a n`` (``n`` the ground's unit
    ``normal`` in ground axes: the wheel's contact point), has no velocity along the
    unit ``direction`` fixed in the axes of link ``frame``:
    ``dᵀ (v_p + a n × ω) = 0`` — see :mod:`rt70.urdf.no_slip` and docs/nonholonomic.md.
    """

    name: str
    link: str
    xyz: np.ndarray
    direction: np.ndarray
    frame: str
    radius: float = 0.0
    normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))


@dataclass(frozen=True)
class OpticalPoint:
    """A named point of a link (mirror focus or vertex)."""

    name: str
    link: str
    xyz: np.ndarray


#: Mount types and the axes each one has, in order (``<rt70:mount type>``).
MOUNT_AXES = {"az-el": ("azimuth", "elevation")}


#: Motor and reducer parameters of a ``<rt70:drive>``, in the order of
#: :class:`rt70.bondgraph.parameters.DriveParameters` (without the load's ``J_l``, ``D_l``).
DRIVE_PARAMETERS = ("L_a", "R_a", "c_m", "c_e", "J_m", "D_m", "i_r", "C_r", "D_r")


@dataclass(frozen=True)
class DriveSector:
    """Where an elevation-type drive acts: a gear sector on a link, a pinion on a stator.

    The sector belongs to ``link``; it meshes with a pinion carried by ``stator`` at the
    mesh point ``xyz`` (``link`` frame, in the construction q = 0). ``direction`` is the
    unit tangent of the pitch circle there and ``axis`` the unit axis of the circle,
    both in the ``link`` frame; ``radius`` its radius r. The circle's centre is
    ``xyz + r (axis × direction)`` (docs/urdf-extensions.md, ``<rt70:drive>``).
    """

    link: str
    xyz: np.ndarray
    direction: np.ndarray
    axis: np.ndarray
    radius: float
    stator: str


@dataclass(frozen=True)
class Drive:
    """A DC motor and compliant reducer driving one axis (formalism §4.5, (4.137)–(4.150)).

    Attributes
    ----------
    name : str
        The drive's name.
    joint : str
        The driven axis' 1-DOF joint (its coordinate is the axis angle a servo reads).
    L_a, R_a, c_m, c_e, J_m, D_m, i_r, C_r, D_r : float
        Armature inductance and resistance, torque and back-EMF constants, rotor inertia
        and viscous friction, reducer ratio (motor / axis angle), reducer stiffness and
        damping (axis side); as :class:`rt70.bondgraph.parameters.DriveParameters`.
    sector : DriveSector or None
        None: the reducer torque acts about the joint's axis (on the joint's child, its
        reaction on the parent), a generalised force on the joint's coordinate (4.143);
        a sector: the torque K acts as the force K/r at the mesh (4.150).
    """

    name: str
    joint: str
    L_a: float
    R_a: float
    c_m: float
    c_e: float
    J_m: float
    D_m: float
    i_r: float
    C_r: float
    D_r: float
    sector: DriveSector | None = None


@dataclass(frozen=True, eq=False)
class Wind:
    """An exposed body the wind acts on (``<rt70:wind>``, formalism §4.4, (4.132)–(4.136)).

    Attributes
    ----------
    name : str
        The element's name (unique in the scene).
    link : str
        The URDF link the load acts on.
    xyz : numpy.ndarray
        Reference point in the link frame, m: where the force acts and the moment is
        taken about, shape (3,).
    axis : numpy.ndarray
        Unit symmetry axis of the body in the link frame (a dish: its boresight, out of
        the concave face), shape (3,).
    area, length : float
        Reference area S_ref, m², and reference length l_ref, m.
    shape : str
        The built-in table's name (``dish``, ``cylinder``) or the ``coefficients`` file
        as written in the URDF.
    table : rt70.physics.coefficient_tables.CoefficientTable
        The coefficients C_A, C_N, C_M against θ (:mod:`rt70.physics.aerodynamics`).
    surface : str or None
        A modal body with a reflecting surface over whose nodes the wrench is spread as
        a pressure (:mod:`rt70.surface.pressure`); None: the wrench acts at ``xyz``.
    """

    name: str
    link: str
    xyz: np.ndarray
    axis: np.ndarray
    area: float
    length: float
    shape: str
    table: CoefficientTable
    surface: str | None = None


@dataclass(frozen=True)
class RobotDescription:
    """Everything rt70 reads from one URDF scene.

    Attributes
    ----------
    name : str
        The robot's name.
    source : str
        The file path (or ``"<string>"``) for error messages.
    root : str
        Name of the root link (the ground).
    links : dict of str to Link
        All links, in document order.
    joints : list of Joint
        All joints, in document order.
    gravity : numpy.ndarray
        Gravitational acceleration in the ground frame, m/s².
    bushings : list of Bushing
        6-D elastic elements, strut packages expanded into their struts.
    joint_springs : list of JointSpring
        Scalar springs on joint coordinates.
    optical_points : list of OpticalPoint
        Named output points.
    inertia_repairs : list of InertiaRepair
        Inertias repaired on request (``balance_inertia``), in document order.
    drives : list of Drive
        Motor drives of the axes (``<rt70:drive>``), in document order.
    winds : tuple of Wind
        Exposed bodies the wind acts on (``<rt70:wind>``), in document order.
    air_density : float
        Air density ρ of ``<rt70:air>``, kg/m³ (default: ISA sea level, 1.225).
    loops : list of Loop
        Loop closures (``<rt70:loop>``), in document order.
    no_slips : tuple of NoSlip
        Linear velocity constraints (``<rt70:no_slip>``), in document order.
    mount : Mount or None
        The pointing axes (``<rt70:mount>``), if the file declares them.
    optics : Optics or None
        The reflector system (``<rt70:optics>``), if the file declares it.
    beams : tuple of Beam
        The members written as rigid finite elements (``<rt70:beam>``), in document order.
    modal_bodies : tuple of ModalBody
        The modal flexible bodies (``<rt70:modal_body>``), in document order; their modal
        coordinates follow the joints' (:func:`rt70.urdf.coordinate_names`).
    """

    name: str
    source: str
    root: str
    links: dict[str, Link]
    joints: list[Joint]
    gravity: np.ndarray
    bushings: list[Bushing] = field(default_factory=list)
    joint_springs: list[JointSpring] = field(default_factory=list)
    optical_points: list[OpticalPoint] = field(default_factory=list)
    inertia_repairs: list[InertiaRepair] = field(default_factory=list)
    drives: list[Drive] = field(default_factory=list)
    winds: tuple[Wind, ...] = ()
    air_density: float = DEFAULT_AIR_DENSITY
    loops: list[Loop] = field(default_factory=list)
    no_slips: tuple[NoSlip, ...] = ()
    mount: Mount | None = None
    optics: Optics | None = None
    beams: tuple[Beam, ...] = ()
    modal_bodies: tuple[ModalBody, ...] = ()

    @property
    def node_joints(self) -> dict[str, tuple[int, np.ndarray]]:
        """The interface chains' joints (``<rt70:interface>``): ``{joint: (body, row)}``.

        Not coordinates: joint ``j``'s coordinate is ``row · η`` of modal body ``body``
        (an index into :attr:`modal_bodies`).
        """
        return {
            j: (b, row)
            for b, body in enumerate(self.modal_bodies)
            for j, row in body.node_joints.items()
        }

    def joint(self, name: str) -> Joint:
        """Return the joint called ``name`` (KeyError if there is none)."""
        for joint in self.joints:
            if joint.name == name:
                return joint
        raise KeyError(name)

    def child_joints(self, link: str) -> list[Joint]:
        """Return the joints whose parent is ``link``, in document order."""
        return [j for j in self.joints if j.parent == link]
