"""The RT-70's exposed bodies for the wind (``<rt70:wind>``, docs/wind.md) as plain data.

One job: derive each exposed body's reference point, axis, reference area and length
from the book's data, and say how. The book gives the bodies' masses and principal
moments (:data:`rt70.scenes.rt70_data.SERVO_BODIES`, the listing's values with erratum
11 applied) but not their outer shapes, so the shapes are equivalent uniform solids with
those inertias — except the main mirror, whose diameter is the telescope's 70 m. Every
body is taken in the free stream: shielding of one body by another is ignored
(conservative).

- ``main_mirror``: built-in ``dish``; D = 70 m (the telescope's diameter);
  S = π (D/2)² = π·35² ≈ 3848.45 m², l = D = 70 m; at the vertex [0, 0, 8] m of the
  link frame (the optical point ``main_mirror_vertex``), axis +z (the boresight, out of
  the concave face).
- ``counterreflector``: built-in ``dish``, concave face toward the main mirror, axis
  [0, 0, −1]; a thin disc with the listing's I_z = m R²/2: R = √(2 I_z/m) =
  √(2·4995/2300) ≈ 2.084 m, S = π R² ≈ 13.65 m², l = 2R ≈ 4.17 m; at its vertex
  [0, 0, 0.8] m (``counterreflector_vertex``).
- ``rigel`` (the quadripod carrying the counterreflector): built-in ``cylinder`` along
  z, the uniform solid cylinder with the listing's moments, I_z = m r²/2 and
  I_x = m (3 r² + L²)/12: r = √(2 I_z/m) = √(2·0.25e6/2e4) = 5 m (d = 10 m),
  L = √(12 I_x/m − 3 r²) = √(12·2.7e6/2e4 − 75) ≈ 39.3 m; S = L d ≈ 393 m² (an upper
  bound: the real quadripod is open), l = L; at the link origin (its centre of mass).
- ``mirror_base``: built-in ``cylinder`` along z, the same construction with the
  scene's moments (erratum 11: I_x = 0.6906e7, I_z = 0.2141e6 kg·m², m = 2.55e5 kg):
  r = √(2·2.141e5/2.55e5) ≈ 1.296 m (d ≈ 2.59 m), L = √(12·6.906e6/2.55e5 − 3 r²)
  ≈ 17.9 m, S = L d ≈ 46.4 m², l = L; at the link origin.

(The slender-rod form L = √(12 I_x/m) drops the 3 r² term: 40.2 m for the rigel; with
the listing's printed, swapped mirror-base moment 1.42e7 it would give 25.8 m.)
"""

from __future__ import annotations

import math

from rt70.scenes import rt70_data

#: Diameter of the RT-70 main mirror, m (the telescope's name).
MAIN_MIRROR_DIAMETER = 70.0


def _body(name: str) -> dict:
    return next(b for b in rt70_data.SERVO_BODIES if b["name"] == name)


def thin_disc_radius(mass: float, moment_z: float) -> float:
    """Radius of the thin uniform disc with ``I_z = m R²/2``: ``R = √(2 I_z/m)``."""
    return math.sqrt(2.0 * moment_z / mass)


def solid_cylinder(mass: float, moment_x: float, moment_z: float) -> tuple[float, float]:
    """``(L, d)`` of the uniform solid cylinder with these moments about its centre.

    ``I_z = m r²/2`` and ``I_x = m (3 r² + L²)/12``: ``r = √(2 I_z/m)``,
    ``L = √(12 I_x/m − 3 r²)``, ``d = 2 r``.

    Parameters
    ----------
    mass : float
        m, kg.
    moment_x : float
        I_x, the transverse moment about the centre, kg·m².
    moment_z : float
        I_z, the moment about the cylinder's axis, kg·m².

    Returns
    -------
    tuple of float
        The length L and the diameter d, m.
    """
    r = thin_disc_radius(mass, moment_z)
    return math.sqrt(12.0 * moment_x / mass - 3.0 * r * r), 2.0 * r


def wind_elements() -> tuple[dict, ...]:
    """The four ``<rt70:wind>`` elements of ``rt70_servo``, derived as the module says.

    Each a dict with ``name``, ``link``, ``shape``, ``area`` (m²), ``length`` (m),
    ``xyz`` and ``axis`` (link frame).
    """
    d = MAIN_MIRROR_DIAMETER
    cr = _body("counterreflector")
    radius = thin_disc_radius(cr["mass"], cr["moments"][2])
    out = [
        {
            "name": "main_mirror",
            "link": "main_mirror",
            "shape": "dish",
            "area": math.pi * (d / 2.0) ** 2,
            "length": d,
            "xyz": (0.0, 0.0, 8.0),
            "axis": (0.0, 0.0, 1.0),
        },
        {
            "name": "counterreflector",
            "link": "counterreflector",
            "shape": "dish",
            "area": math.pi * radius**2,
            "length": 2.0 * radius,
            "xyz": (0.0, 0.0, 0.8),
            "axis": (0.0, 0.0, -1.0),
        },
    ]
    for name in ("rigel", "mirror_base"):
        body = _body(name)
        length, diameter = solid_cylinder(body["mass"], body["moments"][0], body["moments"][2])
        out.append(
            {
                "name": name,
                "link": name,
                "shape": "cylinder",
                "area": length * diameter,
                "length": length,
                "xyz": (0.0, 0.0, 0.0),
                "axis": (0.0, 0.0, 1.0),
            }
        )
    return tuple(out)
