"""Choosing a side: one accessor that gives a scene's side its model, data and functions.

Every analysis that can run on either side of the cross-check takes ``side``, one of
:data:`SIDES`: ``"reference"`` (Pinocchio's algorithms, :mod:`rt70.reference`) or
``"textbook"`` (the book's matrix algorithm, :mod:`rt70.textbook`). It asks
:func:`side_of` for that side of the scene and calls the side's functions through it::

    s = side_of(scene, side)
    positions = s.points.point_positions(s.model, s.data, q, points)

The two sides keep their mirrored modules under one name (:data:`TWINS`: the module and
the functions both provide, with the same parameters), so the caller writes each call
once. The side's name is checked here, once (:func:`check_side`); the modules are
imported on first use, so the textbook side never loads Pinocchio.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any, TypeVar

from rt70.errors import Rt70Error

if TYPE_CHECKING:
    from rt70.model.scene import Scene

#: The two sides: Pinocchio's algorithms (the reference) and the book's matrix algorithm.
SIDES = ("reference", "textbook")

#: The mirrored modules, ``rt70/reference/<name>.py`` and ``rt70/textbook/<name>.py``, with
#: the functions both provide under one name and one parameter list, doing the same thing
#: (tests/test_sides.py). Each side has more of its own (the textbook's intermediate
#: matrices, Pinocchio's compiled paths), and the elements' functions of ``forces`` take
#: each side's own arguments (``forces.ELEMENTS``, docs/architecture.md).
TWINS: dict[str, tuple[str, ...]] = {
    "dynamics": (
        "mass_matrix",
        "bias_force",
        "gravity_force",
        "kinetic_energy",
        "gravity_potential",
    ),
    "forces": ("spring_damper_force", "spring_potential"),
    "points": (
        "link_point",
        "point_position",
        "point_positions",
        "point_jacobian",
        "generalized_force",
    ),
    "drives": ("link_pose", "sector_mesh", "drive_angle", "drive_force", "drive_force_function"),
    "wind": ("wind_wrenches", "wind_forces", "wind_force", "wind_force_function"),
    "reactions": ("joint_reactions", "reaction_impulses", "joint_frames"),
    "loops": (
        "loop_residual",
        "loop_jacobian",
        "loop_bias",
        "loop_terms",
        "constrained_forward_dynamics",
    ),
    "no_slip": ("constraint_matrix", "constraint_bias", "reduced_terms"),
    "locks": ("book_rows",),
}


def check_side(side: str) -> str:
    """``side`` if it names a side (:data:`SIDES`), else an Rt70Error naming the choices.

    ``"pinocchio"``, the simulation's former name of the reference side, is refused with
    the name it now has.

    Raises
    ------
    Rt70Error
        If ``side`` is not ``"reference"`` or ``"textbook"``.
    """
    if isinstance(side, str) and side in SIDES:
        return side
    if isinstance(side, str) and side.lower() == "pinocchio":
        raise Rt70Error(
            "side 'pinocchio' is now 'reference' (the Pinocchio side): choose 'reference' "
            "or 'textbook'"
        )
    raise Rt70Error(f"unknown side {side!r} (choose 'reference' = Pinocchio, or 'textbook')")


def _twin(name: str) -> property:
    """The property of :class:`Side` that imports and returns its module ``name``."""

    def module(self: Side) -> ModuleType:
        return self.module(name)

    module.__doc__ = f"The side's ``{name}`` module (``rt70.<side>.{name}``, imported on use)."
    return property(module)


@dataclass(frozen=True)
class Side:
    """One side of a scene: its name, its model and work buffers, and its modules.

    Attributes
    ----------
    name : {"reference", "textbook"}
        The side (:data:`SIDES`).
    model : rt70.reference.ReferenceModel or rt70.textbook.model.Model
        The scene's model on this side (``scene.reference`` or ``scene.textbook``).
    data : rt70.reference.ReferenceData or rt70.textbook.data.Data
        Its work buffers (``scene.reference_data`` or ``scene.textbook_data``).
    """

    name: str
    model: Any
    data: Any

    dynamics = _twin("dynamics")
    forces = _twin("forces")
    points = _twin("points")
    drives = _twin("drives")
    wind = _twin("wind")
    reactions = _twin("reactions")
    loops = _twin("loops")
    no_slip = _twin("no_slip")
    locks = _twin("locks")

    def module(self, twin: str) -> ModuleType:
        """The side's module ``twin`` (a key of :data:`TWINS`), imported on first use.

        Raises
        ------
        Rt70Error
            If ``twin`` is not one of the mirrored modules.
        """
        if twin not in TWINS:
            raise Rt70Error(f"no mirrored module '{twin}' (one of {', '.join(TWINS)})")
        return importlib.import_module(f"rt70.{self.name}.{twin}")


def side_of(scene: Scene, side: str) -> Side:
    """The side ``side`` of ``scene`` (:func:`check_side`), its model and data built.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        The scene, its two sides built from one file.
    side : {"reference", "textbook"}
        Which side: Pinocchio's algorithms or the book's.

    Raises
    ------
    Rt70Error
        If ``side`` is not a side (:func:`check_side`).
    """
    if check_side(side) == "textbook":
        return Side("textbook", scene.textbook, scene.textbook_data)
    return Side("reference", scene.reference, scene.reference_data)


F = TypeVar("F", bound=Callable[..., Any])


def refuses_backend(function: F) -> F:
    """``function``, refusing the keyword ``backend=`` (now ``side=``) with a TypeError.

    For the functions that took ``backend="pinocchio" | "textbook"`` before the choice
    was called ``side`` everywhere: a call with the old keyword is told the new one.
    """

    @functools.wraps(function)
    def checked(*args: Any, **kwargs: Any) -> Any:
        if "backend" in kwargs:
            raise TypeError(
                f"{function.__name__}(): backend= is now side= (side='reference' is "
                "Pinocchio's, side='textbook' the book's)"
            )
        return function(*args, **kwargs)

    return checked  # type: ignore[return-value]
