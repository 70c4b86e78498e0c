"""The reference side: Pinocchio's recursive algorithms on the same URDF scene.

Pinocchio parses the URDF text itself and provides CRBA, RNEA, ABA, gravity and
energies; the spring elements it lacks are computed from its own frame kinematics.
No textbook-side code is used for any of it; only the scene's extension data (gains,
attachment frames, gravity) comes from rt70's URDF description.

The convention is Pinocchio's (and the textbook side's): a constant
:class:`ReferenceModel`, its work buffers :class:`ReferenceData`, and algorithms
``algorithm(model, data, q, …)`` taking and returning the book's coordinates in the
user's order (:func:`rt70.urdf.coordinate_names`)::

    from rt70 import reference
    model = reference.ReferenceModel(desc, text)
    data = reference.ReferenceData(model)
    A = reference.mass_matrix(model, data, q)

Modules: :mod:`~rt70.reference.model` (Model, Data), :mod:`~rt70.reference.parse`
(Pinocchio's parser, its messages as rt70's), :mod:`~rt70.reference.coordinates` (book
coordinates ↔ Pinocchio's ``(q, v)``), :mod:`~rt70.reference.dynamics` (A, B q̇, gravity,
q̈, energies), :mod:`~rt70.reference.forces` (springs and dampers).
"""

from rt70.reference.coordinates import to_pinocchio
from rt70.reference.dynamics import (
    bias_force,
    forward_dynamics,
    gravity_force,
    gravity_potential,
    kinetic_energy,
    mass_matrix,
    newton_stiffness,
    weight_moment,
)
from rt70.reference.forces import (
    deformations,
    element_gains,
    element_torques,
    spring_damper_force,
    spring_damper_magnitudes,
    spring_potential,
)
from rt70.reference.model import ReferenceData, ReferenceModel

__all__ = [
    "ReferenceData",
    "ReferenceModel",
    "bias_force",
    "deformations",
    "element_gains",
    "element_torques",
    "forward_dynamics",
    "gravity_force",
    "gravity_potential",
    "kinetic_energy",
    "mass_matrix",
    "newton_stiffness",
    "spring_damper_force",
    "spring_damper_magnitudes",
    "spring_potential",
    "to_pinocchio",
    "weight_moment",
]
