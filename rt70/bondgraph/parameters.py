"""Parameters of the two bond-graph examples, as plain checked dataclasses.

Shared by the bond-graph builders (:mod:`rt70.bondgraph.drive`,
:mod:`rt70.bondgraph.reducer`) and the independent Lagrange forms
(:mod:`rt70.bondgraph.lagrange`); this module holds numbers only, no equations. It is
not the project's drive parameter table (docs/drives.md): the values are the caller's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from rt70.errors import Rt70Error


class ParameterError(Rt70Error):
    """A drive or reducer parameter is not finite, or not positive where it must be."""


def _check(obj: object, positive: tuple[str, ...]) -> None:
    for f in fields(obj):  # type: ignore[arg-type]
        value = getattr(obj, f.name)
        values = value if isinstance(value, tuple) else (value,)
        for v in values:
            if v is None:
                continue
            if not math.isfinite(v) or v < 0.0 or (f.name in positive and v == 0.0):
                need = "positive" if f.name in positive else "non-negative"
                raise ParameterError(
                    f"{type(obj).__name__}.{f.name} must be finite and {need}, got {value!r}"
                )


@dataclass(frozen=True)
class DriveParameters:
    """A DC motor, a compliant reducer and the load it turns (formalism §4.5, (4.137)).

    Any consistent units (SI: H, Ω, N·m/A, V·s/rad, kg·m², N·m·s/rad, N·m/rad).

    Attributes
    ----------
    L_a, R_a : float
        Armature inductance and resistance.
    c_m, c_e : float
        Torque constant (torque = c_m I) and back-EMF constant (EMF = c_e ω_m); equal in
        consistent units (a power-conserving motor, the gyrator (2.7)).
    J_m, D_m : float
        Rotor inertia and viscous friction on the motor shaft.
    i_r : float
        Reducer ratio, motor speed / load speed (the book's ``i_r``: Δα = α − α_m/i_r).
    C_r, D_r : float
        Reducer stiffness and damping on the load side (torque = C_r Δα + D_r Δα̇).
    J_l, D_l : float
        Load inertia about the axis and its viscous damping to ground.
    """

    L_a: float
    R_a: float
    c_m: float
    c_e: float
    J_m: float
    D_m: float
    i_r: float
    C_r: float
    D_r: float
    J_l: float
    D_l: float

    def __post_init__(self) -> None:
        _check(self, ("L_a", "R_a", "c_m", "c_e", "J_m", "i_r", "C_r", "J_l"))


@dataclass(frozen=True)
class GearReducerParameters:
    """The non-rigid gear reducer of Example 1a (book §1.4, Fig. 1.3).

    Attributes
    ----------
    inertia : tuple of 4 floats
        ``I1..I4`` of gears 1–4 (gear 1 on the output shaft, gear 4 on the motor shaft).
    stiffness : tuple of 5 floats
        ``C1..C5``: output shaft, intermediate shaft (gears 2–3), motor shaft, mesh 1–2
        (referred to gear 1's angle), mesh 3–4 (referred to gear 3's angle).
    damping : tuple of 5 floats
        ``D1..D5`` alongside (same reference angles).
    radii : tuple of 4 floats
        Pitch radii ``R1..R4``.
    load_inertia : float or None
        None: the output angle is prescribed (the book's ``β_out``, an input); a number:
        the output shaft turns a free load of that inertia.
    """

    inertia: tuple[float, float, float, float]
    stiffness: tuple[float, float, float, float, float]
    damping: tuple[float, float, float, float, float]
    radii: tuple[float, float, float, float]
    load_inertia: float | None = None

    def __post_init__(self) -> None:
        sizes = {"inertia": 4, "stiffness": 5, "damping": 5, "radii": 4}
        for name, n in sizes.items():
            if len(getattr(self, name)) != n:
                raise ParameterError(f"GearReducerParameters.{name} needs {n} values")
        _check(self, ("inertia", "stiffness", "radii", "load_inertia"))
