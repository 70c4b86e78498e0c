"""The non-rigid gear reducer of Example 1a (book §1.4, Fig. 1.3) as a bond graph.

Four gears on three shafts, two meshes. Each shaft and each mesh is a spring and a
damper on a 1-junction of its deformation rate, fed by a 0-junction that splits the
flows (as in :mod:`rt70.bondgraph.drive`). The deformations, with all gear angles
``β_i`` about the common x axis of the book's frame E0:

    shafts  δ1 = β_out − β1,  δ2 = β3 − β2,  δ3 = β4 − β_motor
    meshes  δ4 = β1 + (R2/R1) β2,  δ5 = β3 + (R4/R3) β4

A mesh is the 0-junction of the two gears' tooth speeds, gear 2 (gear 4) entering
through a transformer of modulus ``R2/R1`` (``R4/R3``), so ``C4, D4`` are referred to
gear 1's angle and ``C5, D5`` to gear 3's. The mesh torques are the book's: on gear 1
``−C4 δ4``, on gear 2 ``−C4 (R2/R1) δ4`` (ratio ``R2/R1``, the book's ``K_j/K_{j+1}``).
The book prints the mesh deformation as ``β1 + β2``, which is consistent with those
torques (conservative) only for ``R1 = R2``; the ratio is restored here (see
docs/bond-graphs.md).

Inputs: the motor-shaft speed ``omega_motor`` (flow source) and either the output
speed ``omega_out`` (flow source, the book's prescribed ``β_out``) or a free load
inertia on the output shaft. Outputs: the gear speeds and the two shaft torques.
"""

from __future__ import annotations

from rt70.bondgraph.graph import BondGraph
from rt70.bondgraph.parameters import GearReducerParameters


def reducer_outputs(p: GearReducerParameters) -> list[tuple[str, str, str]]:
    """Named outputs of :func:`gear_reducer`: gear speeds, ``K_out``-side torque, etc."""
    outs = [(f"omega_{i}", f"I{i}", "f") for i in range(1, 5)]
    outs += [("tau_shaft1", "s1_gear", "e"), ("tau_shaft3", "s3_gear", "e")]
    if p.load_inertia is not None:
        outs.append(("omega_out", "J_out", "f"))
    return outs


def gear_reducer(p: GearReducerParameters, name: str = "gear reducer") -> BondGraph:
    """Build the Example-1a bond graph (see the module docstring)."""
    I1, I2, I3, I4 = p.inertia
    R1, R2, R3, R4 = p.radii
    g = BondGraph(name)
    g.source_flow("Sf_motor", input="omega_motor")

    def spring(label: str, k: float, d: float) -> None:
        """A 1-junction of a deformation rate with its spring and damper."""
        g.one(f"1_{label}")
        g.compliance(f"C_{label}", stiffness=k)
        g.bond(f"1_{label}", f"C_{label}", f"C_{label}")
        if d > 0.0:
            g.resistor(f"D_{label}", d)
            g.bond(f"1_{label}", f"D_{label}", f"D_{label}")

    def gear(i: int, inertia: float) -> None:
        g.one(f"1_g{i}")
        g.inertia(f"I{i}", inertia)
        g.bond(f"1_g{i}", f"I{i}", f"I{i}")

    C, D = p.stiffness, p.damping
    # motor shaft (δ3): flow of 1_s3 is ω_motor − ω4
    g.zero("0_s3")
    g.bond("Sf_motor", "0_s3", "motor")
    spring("s3", C[2], D[2])
    g.bond("0_s3", "1_s3", "s3")
    gear(4, I4)
    g.bond("0_s3", "1_g4", "s3_gear")
    # mesh 3-4 (δ5): flow ω3 + (R4/R3) ω4
    g.zero("0_m5")
    g.transformer("TF_43", R4 / R3)
    g.bond("1_g4", "TF_43", "g4_mesh")
    g.bond("TF_43", "0_m5", "m5_4")
    gear(3, I3)
    g.bond("1_g3", "0_m5", "m5_3")
    spring("m5", C[4], D[4])
    g.bond("0_m5", "1_m5", "m5")
    # intermediate shaft (δ2): flow ω3 − ω2
    g.zero("0_s2")
    g.bond("1_g3", "0_s2", "g3_shaft")
    spring("s2", C[1], D[1])
    g.bond("0_s2", "1_s2", "s2")
    gear(2, I2)
    g.bond("0_s2", "1_g2", "s2_gear")
    # mesh 1-2 (δ4): flow ω1 + (R2/R1) ω2
    g.zero("0_m4")
    g.transformer("TF_21", R2 / R1)
    g.bond("1_g2", "TF_21", "g2_mesh")
    g.bond("TF_21", "0_m4", "m4_2")
    gear(1, I1)
    g.bond("1_g1", "0_m4", "m4_1")
    spring("m4", C[3], D[3])
    g.bond("0_m4", "1_m4", "m4")
    # output shaft (δ1): flow ω_out − ω1
    g.zero("0_s1")
    if p.load_inertia is None:
        g.source_flow("Sf_out", input="omega_out")
        g.bond("Sf_out", "0_s1", "out")
    else:
        g.one("1_out")
        g.inertia("J_out", p.load_inertia)
        g.bond("1_out", "J_out", "J_out")
        g.bond("1_out", "0_s1", "out")
    spring("s1", C[0], D[0])
    g.bond("0_s1", "1_s1", "s1")
    g.bond("0_s1", "1_g1", "s1_gear")
    return g
