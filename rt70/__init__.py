"""rt70: models of large flexible mechanical structures as control objects.

Two independent implementations of the same dynamics are kept side by side and
cross-checked: the textbook's matrix algorithm (:mod:`rt70.textbook`, never imports
Pinocchio) and Pinocchio's recursive algorithms (:mod:`rt70.reference`).

The names a user starts with are exported here and imported on first use::

    import rt70

    scene = rt70.load_scene("rt70_servo")  # a scene name or the path of a URDF file
    records = rt70.cross_check(scene, samples=3)  # textbook against Pinocchio
    q0 = rt70.equilibrium(scene, rt70.rt70_pointing(45.0))  # held at 45° elevation
    lm = rt70.linearize(scene, q0)  # M, K, D about q0
    spectrum = rt70.modes(lm.M, lm.K, lm.D)
    run = rt70.simulate(scene, (0.0, 1.0))  # with the energy audit
"""

from rt70._version import __version__
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

#: The names a user starts with, and the module each is defined in. They are imported
#: on first use (PEP 562), so ``import rt70`` loads nothing above :mod:`rt70.errors`.
_EXPORTS = {
    "Scene": "rt70.model.scene",
    "load_scene": "rt70.model.scene",
    "scene_from_text": "rt70.model.scene",
    "scene_names": "rt70.model.scene",
    "cross_check": "rt70.crosscheck.validate",
    "simulate": "rt70.simulation.simulate",
    "equilibrium": "rt70.linear.linearize",
    "linearize": "rt70.linear.linearize",
    "modes": "rt70.linear.modal",
    "plant": "rt70.linear.plant",
    "CoordinateInput": "rt70.linear.plant",
    "CoordinateOutput": "rt70.linear.plant",
    "rt70_pointing": "rt70.scenes.rt70_state",
}


def __getattr__(name: str):
    """The exported names of :data:`_EXPORTS`, imported on first use."""
    if name in _EXPORTS:
        from importlib import import_module

        value = getattr(import_module(_EXPORTS[name]), name)
        globals()[name] = value  # later look-ups skip this function
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The module's names with the lazy exports, which are not loaded yet."""
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "CoordinateInput",
    "CoordinateOutput",
    "DtdError",
    "ExtensionError",
    "InertiaError",
    "JointTypeError",
    "MagnitudeError",
    "MasslessCoordinateError",
    "NonFiniteError",
    "Rt70Error",
    "Rt70Warning",
    "Scene",
    "SceneError",
    "SingularConfigurationError",
    "TopologyError",
    "UrdfError",
    "XacroError",
    "__version__",
    "cross_check",
    "equilibrium",
    "linearize",
    "load_scene",
    "modes",
    "plant",
    "rt70_pointing",
    "scene_from_text",
    "scene_names",
    "simulate",
]
