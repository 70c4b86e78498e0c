"""The rt70 exception hierarchy.

Every error rt70 raises on bad input derives from :class:`Rt70Error`, so callers (and
the command line, which turns them into exit code 2 and one readable line) can catch
them in one place.
"""

from __future__ import annotations


class Rt70Error(Exception):
    """Base class of every error rt70 raises on bad input or an impossible request."""


class UrdfError(Rt70Error):
    """The URDF file is missing, unreadable or not well-formed XML, or breaks URDF rules."""


class TopologyError(UrdfError):
    """The kinematic tree is broken: unknown parent, two parents, a cycle, no root."""


class JointTypeError(UrdfError):
    """A joint type is unknown, or known but not supported by rt70."""


class InertiaError(UrdfError):
    """A body's inertia is physically impossible (mass, definiteness, triangle inequality)."""


class MasslessCoordinateError(InertiaError):
    """A generalised coordinate moves no mass: the mass matrix is singular."""


class NonFiniteError(UrdfError):
    """A number in the model, or a state passed to either side, is NaN or infinite."""


class MagnitudeError(UrdfError):
    """A number in the model is finite but beyond ``rt70.urdf.elements.MAX_MAGNITUDE``."""


class XacroError(UrdfError):
    """The file is a xacro template (xacro elements or substitutions), not a URDF."""


class DtdError(UrdfError):
    """The file declares DTD entities, which rt70 would expand and Pinocchio would not."""


class ExtensionError(UrdfError):
    """An rt70 extension element (spring, bushing, strut package, ...) is malformed."""


class LoopClosureError(ExtensionError):
    """The ``<rt70:loop>`` elements cannot close: no configuration satisfies ``Φ(q) = 0``.

    A loop whose frames cannot meet (lengths that do not reach, an offset no joint can
    take up), or loops that each close alone but contradict each other.
    """


class SingularConfigurationError(Rt70Error):
    """The configuration is singular for the chosen coordinates (Euler gimbal lock)."""


class SceneError(Rt70Error):
    """A scene name is unknown, or a scene lacks a declaration an analysis needs."""


class UnknownLinkError(Rt70Error):
    """A point, load or output names a link the model has no frame for."""


class Rt70Warning(UserWarning):
    """Something odd in the input that rt70 reads anyway, as Pinocchio does.

    The message is one line starting with the source file; the command line prints each
    as ``rt70: warning: <message>``.
    """


class ShapeError(Rt70Error, ValueError):
    """An array argument has the wrong shape (a ``ValueError`` too, for existing callers)."""


class ResourceError(Rt70Error):
    """The model is too large for this machine (memory) or for Pinocchio's URDF parser."""


class OutputError(Rt70Error):
    """An output path cannot be written (missing permission, a directory, a bad suffix)."""


class SimulationError(Rt70Error):
    """The equations of motion cannot be integrated from the given model and state."""
