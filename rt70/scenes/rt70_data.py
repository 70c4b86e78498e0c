"""RT-70 data of the textbook (Dubarenko et al. 2007) as plain Python data.

Two groups:

* the chapter-2 torsional models (§2.3 azimuth, 7 masses; §2.4 elevation, 6 masses):
  Tables 2.1–2.4 and the topology matrices (2.14), (2.26), in the book's technical
  units (inertia kgf·s²·m, stiffness kgf·m/rad); :data:`KGF` converts them to SI;
* the 42-DOF nonlinear model of the §4.2.3 listing (SI units), with the listing's
  initial state :data:`LISTING_Q0`, :data:`LISTING_V0`.

Numbers are as printed; every departure from the print is marked ``erratum`` here and
explained in ``docs/rt70-errata.md``. Nodes and bodies are numbered from 1 as in the
book; 0 is the ground.
"""

from __future__ import annotations

import math

import numpy as np

#: One kilogram-force in newtons (standard gravity, m/s²).
KGF = 9.80665

# ---------------------------------------------------------------------------------------
# §2.3 azimuth model, 7 masses (Tables 2.1, 2.2, eq. 2.14)
# ---------------------------------------------------------------------------------------

#: Table 2.1: node name, reduced moment of inertia about the azimuth axis (kgf·s²·m) at
#: elevation 0° and at elevation 90°.
AZIMUTH_NODES: tuple[dict, ...] = (
    {"name": "platform", "I_el0": 0.2100e8, "I_el90": 0.2100e8},
    {"name": "base", "I_el0": 0.4000e7, "I_el90": 0.2162e7},
    {"name": "mirror_base", "I_el0": 0.9472e7, "I_el90": 0.2141e6},
    {"name": "main_mirror", "I_el0": 0.1600e8, "I_el90": 0.1537e8},
    {"name": "rigel", "I_el0": 0.3200e7, "I_el90": 0.2481e6},
    {"name": "counterreflector", "I_el0": 0.1060e5, "I_el90": 0.4995e4},
    {"name": "counterweight", "I_el0": 0.4700e7, "I_el90": 0.4071e6},
)

#: Table 2.2: link name, torsional stiffness (kgf·m/rad) at elevation 0° and 90°.
AZIMUTH_LINKS: tuple[dict, ...] = (
    {"name": "platform_base", "C_el0": 0.5350e10, "C_el90": 0.5350e10},
    {"name": "base_mirror_base", "C_el0": 0.5050e10, "C_el90": 0.8395e9},
    {"name": "mirror_base_main_mirror", "C_el0": 0.8395e9, "C_el90": 0.5050e10},
    {"name": "base_rigel", "C_el0": 0.2280e10, "C_el90": 0.1765e10},
    {"name": "rigel_counterreflector", "C_el0": 0.6480e7, "C_el90": 0.6480e7},
    {"name": "mirror_base_counterweight", "C_el0": 0.2850e10, "C_el90": 0.2074e10},
)

#: Topology matrix Γα (2.14) as read from the OCR: one row per link of Table 2.2, one
#: column per node of Table 2.1; −1 at the first node of the link, +1 at the second.
#: There is no link to the ground (the azimuth bearing is free: a zero frequency).
GAMMA_ALPHA: tuple[tuple[int, ...], ...] = (
    (-1, 1, 0, 0, 0, 0, 0),
    (0, -1, 1, 0, 0, 0, 0),
    (0, 0, -1, 1, 0, 0, 0),
    (0, -1, 0, 0, 1, 0, 0),
    (0, 0, 0, 0, -1, 1, 0),
    (0, 0, -1, 0, 0, 0, 1),
)

#: Spectrum printed for the azimuth model at elevation 0° (Hz). NOT reproduced by the
#: tables and Γα above (they give 0, 1.265, 2.729, 3.813, 4.020, 5.286, 9.628 Hz): an
#: open finding of the validation, kept as printed.
AZIMUTH_SPECTRUM_EL0_HZ: tuple[float, ...] = (
    0.0,
    1.2512,
    3.0281,
    3.5985,
    3.7730,
    4.1964,
    10.2493,
)

# ---------------------------------------------------------------------------------------
# §2.4 elevation model, 6 masses (Tables 2.3, 2.4, eq. 2.26)
# ---------------------------------------------------------------------------------------

#: Table 2.3: node name, reduced moment of inertia about the elevation axis (kgf·s²·m).
ELEVATION_NODES: tuple[dict, ...] = (
    {"name": "counterweight", "I": 0.7500e7},
    {"name": "base", "I": 0.3000e7},
    {"name": "main_mirror", "I": 0.1420e8},
    {"name": "rigel", "I": 0.2700e7},
    {"name": "mirror_base", "I": 0.6906e7},
    {"name": "counterreflector", "I": 0.3122e4},
)

#: Table 2.4: link name, torsional stiffness (kgf·m/rad).
ELEVATION_LINKS: tuple[dict, ...] = (
    {"name": "counterweight_base", "C": 0.2861e11},
    {"name": "counterweight_main_mirror", "C": 0.4760e10},
    {"name": "base_rigel", "C": 0.1960e10},
    {"name": "base_mirror_base", "C": 0.4672e10},
    {"name": "rigel_counterreflector", "C": 0.6480e7},
)

#: Topology matrix Γβ (2.26).
GAMMA_BETA: tuple[tuple[int, ...], ...] = (
    (-1, 1, 0, 0, 0, 0),
    (-1, 0, 1, 0, 0, 0),
    (0, -1, 0, 1, 0, 0),
    (0, -1, 0, 0, 1, 0),
    (0, 0, 0, -1, 0, 1),
)

#: Spectrum printed for the elevation model (Hz); reproduced by eig(ΓᵀCΓ, I).
ELEVATION_SPECTRUM_HZ: tuple[float, ...] = (0.0, 3.2700, 4.2424, 6.3041, 7.2579, 19.6420)

#: Mass given to every chapter-2 node in the URDF (kg). The nodes only rotate about a
#: fixed axis through their origin, so the mass never enters the dynamics.
CHAPTER2_NODE_MASS = 1.0

# ---------------------------------------------------------------------------------------
# §4.2.3 listing: the 42-DOF nonlinear model
# ---------------------------------------------------------------------------------------

#: Gravity of the listing, corrected (erratum 2): z up, g0 = [0, 0, −9.81] m/s².
LISTING_GRAVITY: tuple[float, float, float] = (0.0, 0.0, -9.81)

#: The seven bodies in pair order 1..7. ``offset`` is the construction offset r_jc^i in
#: the parent frame (m), ``mass`` kg, ``moments`` the principal moments at the centre of
#: mass (kg·m²) used by the scene, ``printed_moments`` the listing's I_j1, I_j2, I_j3,
#: ``com`` the centre-of-mass offset p_cm (m).
#:
#: erratum 11 (found while writing the scenes, not in the spec's list): the listing gives
#: the mirror base I41 = I42 = 0.142e8 and the main mirror I51 = I52 = 0.6906e7 — the
#: main mirror then violates the triangle inequality (0.1537e8 > 2 × 0.6906e7), i.e.
#: no rigid body has those moments. Table 2.3 (elevation axis) names 0.1420e8 the main
#: mirror and 0.6906e7 the mirror base; with the two transverse pairs swapped back to
#: Table 2.3's assignment both bodies are physically possible. The scene uses the swap.
LISTING_BODIES: tuple[dict, ...] = (
    {
        "name": "platform",
        "parent": "world",
        "offset": (0.0, 0.0, 25.0),
        "mass": 300.0e3,
        "moments": (0.21e8, 0.21e8, 0.21e8),
        "printed_moments": (0.21e8, 0.21e8, 0.21e8),
        "com": (0.0, 0.0, 0.0),
    },
    {
        "name": "base",
        "parent": "platform",
        "offset": (0.0, 0.0, 20.0),
        "mass": 450.0e3,
        "moments": (0.31e7, 0.31e7, 0.22e7),
        "printed_moments": (0.31e7, 0.31e7, 0.22e7),
        "com": (0.0, 0.0, 0.0),
    },
    {
        "name": "counterweight",
        "parent": "base",
        "offset": (0.0, 0.0, 16.0),
        "mass": 480.0e3,
        "moments": (0.75e7, 0.75e7, 0.41e6),
        "printed_moments": (0.75e7, 0.75e7, 0.41e6),
        "com": (0.0, 0.0, 0.0),
    },
    {
        "name": "mirror_base",
        "parent": "base",
        "offset": (0.0, 0.0, 11.0),
        "mass": 255.0e3,
        "moments": (0.6906e7, 0.6906e7, 0.2141e6),  # erratum 11
        "printed_moments": (0.142e8, 0.142e8, 0.2141e6),
        "com": (0.0, 0.0, 0.0),
    },
    {
        "name": "main_mirror",
        "parent": "mirror_base",
        "offset": (0.0, 0.0, 20.0),
        "mass": 62.6e3,
        "moments": (0.142e8, 0.142e8, 0.1537e8),  # erratum 11
        "printed_moments": (0.6906e7, 0.6906e7, 0.1537e8),
        "com": (0.0, 0.0, 0.0),
    },
    {
        "name": "rigel",
        "parent": "base",
        "offset": (0.0, 0.0, 38.0),
        "mass": 20.0e3,
        "moments": (0.27e7, 0.27e7, 0.25e6),
        "printed_moments": (0.27e7, 0.27e7, 0.25e6),
        "com": (0.0, 0.0, 0.0),
    },
    {
        "name": "counterreflector",
        "parent": "rigel",
        "offset": (0.0, 0.0, 6.0),
        "mass": 2.3e3,
        "moments": (0.3122e4, 0.3122e4, 0.4995e4),
        "printed_moments": (0.3122e4, 0.3122e4, 0.4995e4),
        "com": (0.0, 0.0, 0.0),
    },
)

#: The listing's bodies with the counterweight below the elevation axis, offset
#: ``[0, 0, −16]`` m instead of the printed ``[0, 0, 16]`` (errata item 12): the
#: ``rt70_servo`` scene, the control object the drives can hold. Nothing else changes.
SERVO_BODIES: tuple[dict, ...] = tuple(
    {**body, "offset": (0.0, 0.0, -16.0)} if body["name"] == "counterweight" else body
    for body in LISTING_BODIES
)

#: Direct elastic pairs: a 6-D spring/damper acting on the pair coordinates of ``child``
#: (diagonal entries x, y, z, rx, ry, rz; N/m, N·m/rad, N·s/m, N·m·s/rad). The zero rz
#: stiffness of the platform is the free azimuth bearing.
LISTING_DIRECT_PAIRS: tuple[dict, ...] = (
    {
        "name": "ground_platform",
        "child": "platform",
        "stiffness": (5.0e10, 5.0e10, 5.0e10, 0.535e12, 0.535e10, 0.0),
        "damping": (5.0e9, 5.0e9, 5.0e9, 0.5e11, 0.5e9, 0.0),
    },
    {
        "name": "base_counterweight",
        "child": "counterweight",
        "stiffness": (1.0e9, 1.0e9, 5.0e9, 0.2861e11, 0.2861e11, 0.2074e10),
        "damping": (1.0e8, 1.0e8, 5.0e8, 0.2861e10, 0.2861e10, 0.2074e9),
    },
    {
        "name": "base_mirror_base",
        "child": "mirror_base",
        "stiffness": (1.0e9, 1.0e9, 1.0e9, 0.4672e10, 0.4672e10, 0.8395e9),
        "damping": (1.0e8, 1.0e8, 1.0e8, 0.4672e9, 0.4672e9, 0.8395e8),
    },
    {
        "name": "mirror_base_main_mirror",
        "child": "main_mirror",
        "stiffness": (1.0e9, 1.0e9, 1.0e9, 0.4672e10, 0.4672e10, 0.505e10),
        "damping": (1.0e8, 1.0e8, 1.0e8, 0.4672e9, 0.4672e9, 0.505e9),
    },
    {
        "name": "rigel_counterreflector",
        "child": "counterreflector",
        "stiffness": (1.0e7, 1.0e7, 1.0e7, 0.648e7, 0.648e7, 0.648e7),
        "damping": (1.0e6, 1.0e6, 1.0e6, 0.648e6, 0.648e6, 0.648e6),
    },
)

_PLATFORM_BASE_STRUT_C = (0.5e9, 0.5e9, 2.5e10, 0.0, 0.2675e10, 0.2675e10)
_PLATFORM_BASE_STRUT_D = (0.5e8, 0.5e8, 2.5e9, 0.0, 0.2675e9, 0.2675e9)
_BASE_RIGEL_STRUT_C = (5.0e6, 5.0e6, 5.0e6, 0.648e7, 0.648e7, 0.648e7)
_BASE_RIGEL_STRUT_D = (5.0e4, 5.0e4, 5.0e4, 0.648e5, 0.648e5, 0.648e5)

#: Strut packages joining ``child`` to ``parent``: attachment point ``xyz`` of each strut
#: in the child frame (R_jg) and its inclination ``rpy`` (1–2–3 angles a_g, here one
#: axis each). The zero rx stiffness of the platform–base struts is the free elevation
#: bearing.
#:
#: erratum 7: the listing prints both members of each pair at the same point
#: (R2g1 = R2g2 = [13.45 0 0], R6g1 = R6g2 = [3 0 0.5], R6g3 = R6g4 = [0 3 0.5]; the
#: OCR even shows a blank where the minus of R2g1 was); the scene mirrors the second
#: member (−13.45, −3). The inclinations are kept as printed for both members.
#: erratum 5: the fourth rigel strut uses ag14 (the listing builds it from ag11).
LISTING_STRUT_PACKAGES: tuple[dict, ...] = (
    {
        "name": "platform_base",
        "child": "base",
        "struts": (
            {
                "name": "left",
                "xyz": (13.45, 0.0, 0.0),
                "rpy": (0.0, 0.0, 0.0),
                "stiffness": _PLATFORM_BASE_STRUT_C,
                "damping": _PLATFORM_BASE_STRUT_D,
            },
            {
                "name": "right",
                "xyz": (-13.45, 0.0, 0.0),
                "rpy": (0.0, 0.0, 0.0),
                "stiffness": _PLATFORM_BASE_STRUT_C,
                "damping": _PLATFORM_BASE_STRUT_D,
            },
        ),
    },
    {
        "name": "base_rigel",
        "child": "rigel",
        "struts": (
            {
                "name": "left",
                "xyz": (3.0, 0.0, 0.5),
                "rpy": (math.pi / 3, 0.0, 0.0),
                "stiffness": _BASE_RIGEL_STRUT_C,
                "damping": _BASE_RIGEL_STRUT_D,
            },
            {
                "name": "right",
                "xyz": (-3.0, 0.0, 0.5),
                "rpy": (math.pi / 3, 0.0, 0.0),
                "stiffness": _BASE_RIGEL_STRUT_C,
                "damping": _BASE_RIGEL_STRUT_D,
            },
            {
                "name": "front",
                "xyz": (0.0, 3.0, 0.5),
                "rpy": (0.0, math.pi / 3, 0.0),
                "stiffness": _BASE_RIGEL_STRUT_C,
                "damping": _BASE_RIGEL_STRUT_D,
            },
            {
                "name": "back",
                "xyz": (0.0, -3.0, 0.5),
                "rpy": (0.0, math.pi / 3, 0.0),
                "stiffness": _BASE_RIGEL_STRUT_C,
                "damping": _BASE_RIGEL_STRUT_D,
            },
        ),
    },
)

#: Optical points (§4.1.8, listing R5f, R5v, R7f, R7v), in the body frames (m).
LISTING_OPTICAL_POINTS: tuple[dict, ...] = (
    {"name": "main_mirror_focus", "link": "main_mirror", "xyz": (0.0, 0.0, 13.0)},
    {"name": "main_mirror_vertex", "link": "main_mirror", "xyz": (0.0, 0.0, 8.0)},
    {"name": "counterreflector_focus", "link": "counterreflector", "xyz": (0.0, 0.0, 1.2)},
    {"name": "counterreflector_vertex", "link": "counterreflector", "xyz": (0.0, 0.0, 0.8)},
)

#: Pair coordinate names, in the book's order [x, y, z, β, θ, α].
PAIR_AXES: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")


def _state(*pairs: tuple[float, ...]) -> np.ndarray:
    values = np.array([v for pair in pairs for v in pair], dtype=float)
    if values.shape != (42,):
        raise ValueError(f"a listing state has 42 entries, got {values.shape}")
    values.setflags(write=False)
    return values


#: The listing's initial coordinates Q_NU (pairs 1..7, each [x, y, z, β, θ, α]).
#: Note the large values: platform α = 0.8 rad (azimuth), base β = 0.8 rad (elevation),
#: counterweight θ = 0.03 rad.
LISTING_Q0: np.ndarray = _state(
    (0.01, 0.01, 0.01, 0.003, 0.003, 0.8),
    (0.01, 0.01, 0.01, 0.8, 0.003, 0.003),
    (0.01, 0.01, 0.01, 0.003, 0.03, 0.003),
    (0.01, 0.01, 0.01, 0.003, 0.003, 0.003),
    (0.01, 0.01, 0.01, 0.003, 0.003, 0.003),
    (0.01, 0.01, 0.01, 0.003, 0.003, 0.003),
    (0.01, 0.01, 0.01, 0.003, 0.003, 0.003),
)

#: The listing's initial velocities dQ_NU (same order as :data:`LISTING_Q0`).
LISTING_V0: np.ndarray = _state(
    (0.01, 0.01, 0.01, 0.0015, 0.0015, 0.003),
    (0.01, 0.01, 0.01, 0.003, 0.0015, 0.0015),
    (0.01, 0.01, 0.01, 0.0015, 0.0015, 0.0015),
    (0.01, 0.01, 0.01, 0.0015, 0.0015, 0.0015),
    (0.01, 0.01, 0.01, 0.0015, 0.0015, 0.0015),
    (0.01, 0.01, 0.01, 0.0015, 0.0015, 0.0015),
    (0.1, 0.01, 0.01, 0.0015, 0.0015, 0.0015),
)


def _column_tube(diameter: float, lateral: float, length: float, E: float) -> dict[str, float]:
    """A circular tube of outer ``diameter`` whose cantilever tip stiffness is ``lateral``.

    ``I = lateral · L³ / (3 E)``; the bore ``d = (D⁴ − 64 I/π)^¼``. Returns the wall (m)
    and the section: A, I_y = I_z, J = 2 I (m², m⁴).
    """
    second = lateral * length**3 / (3.0 * E)
    inner = (diameter**4 - 64.0 * second / np.pi) ** 0.25
    area = np.pi / 4.0 * (diameter**2 - inner**2)
    return {
        "wall": float((diameter - inner) / 2.0),
        "A": float(area),
        "Iy": float(second),
        "Iz": float(second),
        "J": float(2.0 * second),
    }


#: The counterreflector on a flexible column instead of the listing's direct pair
#: ``rigel_counterreflector`` (scene ``rt70_flexible``, docs/beams.md "On the RT-70"). The
#: book gives no section, only the pair's stiffness: the column is a steel tube 6 m long
#: (the pair's offset) of 1 m diameter whose wall is chosen so that, clamped to the rigel,
#: its tip's lateral stiffness ``3 E I / L³`` is the pair's 1.0e7 N/m: ``I = k L³ / (3 E)``
#: = 3.43e-3 m⁴, wall 9.0 mm (:func:`_column_tube`). Its other stiffnesses follow from
#: the tube (not the
#: book's), and its stiffness-proportional damping is the book's law ``ξ_i = 0.05 Ω_i/Ω1``
#: (§2.3): β = 0.1/Ω1 with Ω1 = 2π · 1.2512 Hz, the printed first resonance.
COUNTERREFLECTOR_COLUMN: dict[str, float] = {
    "length": 6.0,
    "segments": 4,
    "E": 2.1e11,
    "G": 8.1e10,
    "rho": 7850.0,
    **_column_tube(1.0, 1.0e7, 6.0, 2.1e11),
    "damping": 0.1 / (2.0 * np.pi * 1.2512),
}
