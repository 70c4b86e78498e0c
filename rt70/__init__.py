"""rt70: models of large flexible mechanical structures as control objects.

Two independent implementations of the same dynamics are kept side by side and
cross-checked: the textbook's matrix algorithm (:mod:`rt70.textbook`, never imports
Pinocchio) and Pinocchio's recursive algorithms (:mod:`rt70.reference`).
"""

from rt70.errors import (
    DtdError,
    ExtensionError,
    InertiaError,
    JointTypeError,
    MagnitudeError,
    MasslessCoordinateError,
    NonFiniteError,
    Rt70Error,
    Rt70Warning,
    SceneError,
    SingularConfigurationError,
    TopologyError,
    UrdfError,
    XacroError,
)

__version__ = "0.1.0"

__all__ = [
    "DtdError",
    "ExtensionError",
    "InertiaError",
    "JointTypeError",
    "MagnitudeError",
    "MasslessCoordinateError",
    "NonFiniteError",
    "Rt70Error",
    "Rt70Warning",
    "SceneError",
    "SingularConfigurationError",
    "TopologyError",
    "UrdfError",
    "XacroError",
    "__version__",
]
