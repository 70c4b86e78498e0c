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


def __getattr__(name: str) -> str:
    """``rt70.__version__``: the installed distribution's version (pyproject.toml's).

    Read from the package metadata on first use, so that importing rt70 stays cheap.
    """
    if name == "__version__":
        from importlib.metadata import version

        return version("rt70")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
