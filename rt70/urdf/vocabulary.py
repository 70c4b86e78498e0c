"""rt70's vocabulary of URDF elements: what each kind may carry, declared once.

One job: the tables :mod:`rt70.urdf.schema` enforces — :data:`RT70`, rt70's extension
elements (docs/urdf-extensions.md, "What each element may carry"), and :data:`URDF`, the
standard elements rt70 checks — with the two small types they are written in
(:class:`Spec`, :class:`Child`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

from rt70.urdf.description import DRIVE_PARAMETERS
from rt70.urdf.text import RT70_NS


@dataclass(frozen=True)
class Spec:
    """What one element kind may carry.

    Attributes
    ----------
    required : tuple of str
        Attributes the element must have.
    optional : tuple of str
        Attributes it may have (each with a documented default).
    children : mapping of str to Child
        The child elements checked, by local name (rt70 children are in rt70's
        namespace, standard children in none).
    """

    required: tuple[str, ...] = ()
    optional: tuple[str, ...] = ()
    children: Mapping[str, Child] = field(default_factory=dict)

    @cached_property
    def attributes(self) -> tuple[str, ...]:
        """Every attribute the element knows: the required ones, then the optional."""
        return self.required + self.optional

    @cached_property
    def known(self) -> frozenset[str]:
        """:attr:`attributes` as a set."""
        return frozenset(self.attributes)

    @cached_property
    def rt70_children(self) -> dict[str, tuple[str, Child]]:
        """The children as rt70 elements: ``{RT70_NS}local`` to ``(local, Child)``."""
        return {f"{{{RT70_NS}}}{local}": (local, child) for local, child in self.children.items()}


@dataclass(frozen=True)
class Child:
    """A child element kind and how many of it its parent may have.

    Attributes
    ----------
    spec : Spec
        The child's own attributes and children.
    least : int
        Fewest children of this kind (enforced for rt70 elements).
    most : int or None
        Most children of this kind, None for any number (enforced for rt70 elements).
    """

    spec: Spec
    least: int = 0
    most: int | None = None


# --- rt70's extension elements (docs/urdf-extensions.md) -----------------------------

#: A frame on a link: ``<rt70:frame1>``/``<rt70:frame2>`` of a bushing or a loop.
_FRAME = Spec(required=("link",), optional=("xyz", "rpy"))
_TWO_FRAMES = {"frame1": Child(_FRAME, 1, 1), "frame2": Child(_FRAME, 1, 1)}

#: The rt70 elements of a scene: the children of ``<robot>`` in rt70's namespace. A
#: stiffness is required (a spring without one is a mistake, not a rigid joint: write
#: ``stiffness="0"`` for a damper alone); a damping defaults to 0, placements to zero.
RT70 = Spec(
    children={
        "gravity": Child(Spec(required=("xyz",)), most=1),
        "joint_spring": Child(Spec(required=("name", "joint", "stiffness"), optional=("damping",))),
        "bushing": Child(
            Spec(required=("name", "stiffness"), optional=("damping",), children=_TWO_FRAMES)
        ),
        "strut_package": Child(
            Spec(
                required=("name", "parent", "child"),
                optional=("xyz", "rpy"),
                children={
                    "strut": Child(
                        Spec(required=("name", "stiffness"), optional=("xyz", "rpy", "damping")),
                        least=1,
                    )
                },
            )
        ),
        "optical_point": Child(Spec(required=("name", "link", "xyz"))),
        "beam": Child(
            Spec(
                required=("name", "parent", "length", "E", "rho", "A", "Iy", "Iz", "J"),
                optional=(
                    "child",
                    "xyz",
                    "rpy",
                    "segments",
                    "G",
                    "nu",
                    "Asy",
                    "Asz",
                    "axial",
                    "damping",
                ),
            )
        ),
        "modal_body": Child(
            Spec(
                required=("name", "link", "file"),
                optional=("modes", "damping_ratio"),
                children={"interface": Child(Spec(required=("link", "node")))},
            )
        ),
        "drive": Child(
            Spec(
                required=("name", "joint", *DRIVE_PARAMETERS),
                children={
                    "sector": Child(
                        Spec(
                            required=("link", "stator", "direction", "axis", "radius"),
                            optional=("xyz",),
                        ),
                        most=1,
                    )
                },
            )
        ),
        "wind": Child(
            Spec(
                required=("name", "link", "axis", "area", "length"),
                optional=("xyz", "shape", "coefficients", "surface"),
            )
        ),
        "air": Child(Spec(required=("density",)), most=1),
        "loop": Child(Spec(required=("name",), optional=("type",), children=_TWO_FRAMES)),
        "no_slip": Child(
            Spec(
                required=("name", "link", "direction"),
                optional=("xyz", "frame", "radius", "normal"),
            )
        ),
        "mount": Child(
            Spec(
                required=("type",),
                children={
                    "axis": Child(
                        Spec(
                            required=("name", "joint"),
                            optional=("zero_deg", "sign", "min_deg", "max_deg"),
                            children={
                                "servo": Child(
                                    Spec(
                                        required=(
                                            "drive",
                                            "rate_limit_deg_s",
                                            "torque_limit",
                                            "voltage_limit",
                                        ),
                                        optional=(
                                            "position_bandwidth_hz",
                                            "loop_ratio",
                                            "nominal_torque",
                                            "reference_inertia",
                                            "static_friction",
                                            "top_speed_friction",
                                        ),
                                    ),
                                    most=1,
                                )
                            },
                        ),
                        least=1,
                    )
                },
            ),
            most=1,
        ),
        "optics": Child(
            Spec(
                required=("type", "reference_link"),
                children={
                    "reflector": Child(
                        Spec(required=("role", "focus", "vertex"), optional=("support",)),
                        least=1,
                        most=2,
                    )
                },
            ),
            most=1,
        ),
    }
)

# --- standard URDF (ROS URDF XML specification; urdfdom) ------------------------------

_ORIGIN = Child(Spec(optional=("xyz", "rpy")))
_GEOMETRY = Child(
    Spec(
        children={
            "box": Child(Spec(optional=("size",))),
            "cylinder": Child(Spec(optional=("radius", "length"))),
            "sphere": Child(Spec(optional=("radius",))),
            "mesh": Child(Spec(optional=("filename", "scale"))),
        }
    )
)
_MATERIAL = Child(
    Spec(
        optional=("name",),
        children={
            "color": Child(Spec(optional=("rgba",))),
            "texture": Child(Spec(optional=("filename",))),
        },
    )
)

#: The standard elements rt70 checks, from ``<robot>`` down. Besides the URDF
#: specification's attributes it knows the documented, harmless extensions real files
#: carry: a link's ``type`` (older URDF), visuals' and collisions' ``group`` (older
#: urdfdom), pybullet's collision filter ``group``/``mask`` and ``concave`` meshes, Isaac
#: Sim's ``dont_collapse`` on a fixed joint, a calibration's ``reference_position``
#: (older URDF). None of them changes the dynamics either side reads.
URDF = Spec(
    optional=("name", "version"),
    children={
        "link": Child(
            Spec(
                optional=("name", "type", "concave"),
                children={
                    "inertial": Child(
                        Spec(
                            children={
                                "origin": _ORIGIN,
                                "mass": Child(Spec(optional=("value",))),
                                "inertia": Child(
                                    Spec(optional=("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
                                ),
                            }
                        )
                    ),
                    "visual": Child(
                        Spec(
                            optional=("name", "group"),
                            children={
                                "origin": _ORIGIN,
                                "geometry": _GEOMETRY,
                                "material": _MATERIAL,
                            },
                        )
                    ),
                    "collision": Child(
                        Spec(
                            optional=("name", "group", "mask", "concave"),
                            children={"origin": _ORIGIN, "geometry": _GEOMETRY},
                        )
                    ),
                },
            )
        ),
        "joint": Child(
            Spec(
                optional=("name", "type", "dont_collapse"),
                children={
                    "origin": _ORIGIN,
                    "parent": Child(Spec(optional=("link",))),
                    "child": Child(Spec(optional=("link",))),
                    "axis": Child(Spec(optional=("xyz",))),
                    "calibration": Child(
                        Spec(optional=("rising", "falling", "reference_position"))
                    ),
                    "dynamics": Child(Spec(optional=("damping", "friction"))),
                    "limit": Child(Spec(optional=("lower", "upper", "effort", "velocity"))),
                    "mimic": Child(Spec(optional=("joint", "multiplier", "offset"))),
                    "safety_controller": Child(
                        Spec(
                            optional=(
                                "soft_lower_limit",
                                "soft_upper_limit",
                                "k_position",
                                "k_velocity",
                            )
                        )
                    ),
                },
            )
        ),
        "material": _MATERIAL,
        "transmission": Child(
            Spec(
                optional=("name", "type"),
                children={
                    "joint": Child(Spec(optional=("name",))),
                    "actuator": Child(Spec(optional=("name",))),
                },
            )
        ),
    },
)
