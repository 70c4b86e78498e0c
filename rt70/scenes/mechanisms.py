"""Small test mechanisms as plain Python data (SI units).

* :data:`DOUBLE_PENDULUM` — the planar 2R arm of the companion sources (test mechanism
  1), with its reference values :data:`DOUBLE_PENDULUM_REFERENCE`;
* :data:`THREE_MASSES` — the book's §2.1 system of three point masses with elastic
  links (Fig. 2.1, topology matrix (2.3)), reduced to motion along x;
* :data:`TWO_BODY_GRAVITY` — the two 6-DOF bodies of §4.2.3, exercises 1–2;
* :data:`GEAR_REDUCER` — the non-rigid gear reducer of §1.4 (Fig. 1.3, formalism
  Example 1a) turning a free load, motor shaft held.

The book gives no numbers for the last three; the values here are this project's choice.
"""

from __future__ import annotations

# ---------------------------------------------------------------------------------------
# Planar 2R arm (companion-sources.md, "Double pendulum / planar 2R arm")
# ---------------------------------------------------------------------------------------

#: Two uniform slender rods, both joints revolute about z, the arm in the x–y plane,
#: gravity along −y. ``com`` is measured along the link's +x from its joint; ``I_c`` is
#: the moment about the centre of mass about z (m l²/12). The rod's moment about its own
#: axis (x) is a small non-zero ``I_axial`` so the inertia is positive definite; it does
#: not enter planar motion.
DOUBLE_PENDULUM: dict = {
    "links": (
        {"name": "link1", "joint": "joint1", "mass": 1.0, "length": 1.0},
        {"name": "link2", "joint": "joint2", "mass": 1.0, "length": 1.0},
    ),
    "I_axial": 1.0e-3,
    "gravity": (0.0, -9.81, 0.0),
}

#: Reference values at q = (0.3, −0.5) rad, v = (1, 2) rad/s, gravity (0, −9.81, 0):
#: A = crba, B = nonLinearEffects − generalizedGravity, G = generalizedGravity.
DOUBLE_PENDULUM_REFERENCE: dict = {
    "q": (0.3, -0.5),
    "v": (1.0, 2.0),
    "A": ((2.54424923, 0.77212461), (0.77212461, 0.33333333)),
    "B": (1.91770215, -0.23971277),
    "G": (18.865003, 4.80722656),
}

# ---------------------------------------------------------------------------------------
# §2.1: three point masses with elastic links (Fig. 2.1, eq. 2.3)
# ---------------------------------------------------------------------------------------

#: The book's topology (2.3): link 0 ground–mass 1, link 1 mass 1–mass 2, link 2
#: mass 1–mass 3, link 3 mass 2–mass 3 (rows [1 0 0], [−1 1 0], [−1 0 1], [0 −1 1]).
#: Masses, stiffnesses and rest positions are not given in the book; chosen here:
#: m = 1, 2, 3 kg; C0..C3 = 100, 200, 300, 400 N/m; rest positions x = 1, 2, 3 m on the
#: x axis; damping D = 1 % of C (N·s/m). Only motion along x is modelled (one prismatic
#: joint per mass), so each link keeps only its x stiffness.
THREE_MASSES: dict = {
    "masses": (
        {"name": "mass1", "joint": "x1", "mass": 1.0, "rest": (1.0, 0.0, 0.0)},
        {"name": "mass2", "joint": "x2", "mass": 2.0, "rest": (2.0, 0.0, 0.0)},
        {"name": "mass3", "joint": "x3", "mass": 3.0, "rest": (3.0, 0.0, 0.0)},
    ),
    "gamma": (
        (1, 0, 0),
        (-1, 1, 0),
        (-1, 0, 1),
        (0, -1, 1),
    ),
    "stiffness": (100.0, 200.0, 300.0, 400.0),
    "damping_ratio": 0.01,
    # A point mass still needs a valid rotational inertia in URDF: tiny equal moments.
    "point_moment": 1.0e-6,
    "gravity": (0.0, 0.0, -9.81),
}

# ---------------------------------------------------------------------------------------
# §4.2.3, exercises 1–2: two 6-DOF bodies in gravity
# ---------------------------------------------------------------------------------------

#: Body 1 hangs on the ground by a spring/damper C01, D01 (here: one joint spring per
#: pair coordinate), body 2 on body 1 by C12, D12 (a 6-D bushing). Construction offsets
#: r1c, r2c; non-zero centre-of-mass offsets (exercise 2) and a rotated inertia on body 2.
#: Numbers are this project's choice; damping is 1 % of stiffness.
TWO_BODY_GRAVITY: dict = {
    "bodies": (
        {
            "name": "body1",
            "parent": "world",
            "offset": (0.0, 0.0, 2.0),
            "mass": 100.0,
            "moments": (8.0, 10.0, 12.0),
            "com": (0.05, -0.02, 0.1),
            "inertia_rpy": (0.0, 0.0, 0.0),
        },
        {
            "name": "body2",
            "parent": "body1",
            "offset": (0.3, -0.2, 1.5),
            "mass": 40.0,
            "moments": (2.0, 3.0, 4.0),
            "com": (-0.03, 0.04, 0.2),
            "inertia_rpy": (0.1, 0.2, 0.3),
        },
    ),
    "ground_springs": {
        "body": "body1",
        "stiffness": (1.0e5, 1.0e5, 1.0e5, 1.0e4, 1.0e4, 1.0e4),
    },
    "bushing": {
        "name": "body1_body2",
        "child": "body2",
        "stiffness": (2.0e4, 2.0e4, 2.0e4, 3.0e3, 3.0e3, 3.0e3),
    },
    "damping_ratio": 0.01,
    "gravity": (0.0, 0.0, -9.81),
}


# ---------------------------------------------------------------------------------------
# The non-rigid gear reducer (book §1.4, Fig. 1.3; formalism Example 1a)
# ---------------------------------------------------------------------------------------

#: Four gears (inertias I1..I4 about their own x axes, kg·m²; gear 1 on the output
#: shaft, gear 4 on the motor shaft), shafts C1 (output), C2 (gears 2–3), C3 (motor) and
#: meshes C4 (gears 1–2, referred to gear 1's angle), C5 (gears 3–4, referred to gear 3's
#: angle) in N·m/rad, dampers D1..D5 alongside (N·m·s/rad), pitch radii R1..R4 (m), and
#: a free load on the output shaft. Overall ratio R1 R3 / (R2 R4) = 15. The same values
#: are the test values of tests/test_bondgraph.py (the bond graph and Lagrange forms).
GEAR_REDUCER: dict = {
    "inertia": (4.0, 1.0, 2.0, 0.1),
    "stiffness": (1e5, 4e4, 1e4, 2e5, 5e4),
    "damping": (10.0, 5.0, 2.0, 20.0, 8.0),
    "radii": (0.3, 0.1, 0.25, 0.05),
    "load_inertia": 10.0,
    #: shafts' axial spacing (m): the gears of one shaft sit this far apart along x
    "spacing": 0.5,
}
