"""The drive of one axis as a bond graph: DC motor, compliant reducer, load (§4.5).

The graph (power flows left to right; ``[..]`` are the elements on a junction)::

    Se:U → 1_el [I:L_a, R:R_a] → GY:c_m → 1_m [I:J_m, R:D_m] → TF:1/i_r → 0_shaft
    0_shaft → 1_twist [C:1/C_r, R:D_r]        (the reducer's twist rate, in parallel)
    0_shaft → 1_load [I:J_l, R:D_l] ← Se:tau_l (an external torque on the load)

The 0-junction ``0_shaft`` carries the common reducer torque; its flows split the
reducer's output speed ``ω_m/i_r`` into the twist rate and the load speed, so the
spring and the damper sit on one 1-junction of the *relative* velocity
(``ω_m/i_r − ω_l``): the standard Kelvin–Voigt arrangement. The twist state is
``q_C_r = α_m/i_r − α_l = −Δα`` of the book's (4.139), and the torque on the load
(the effort on bond ``load``) is the book's ``K_axis = −C_r Δα − D_r Δα̇`` (4.143).

With ``source="current"`` the armature is fed by a current source ``Sf:I_a`` and
the inductance is left out (in series with a current source it would be in derivative
causality): the mechanical two-mass model with the motor torque ``c_m I_a`` as input.
"""

from __future__ import annotations

from rt70.bondgraph.graph import BondGraph, BondGraphError
from rt70.bondgraph.parameters import DriveParameters

#: Named outputs of :func:`dc_motor_reducer_load`: (name, bond, "e" | "f").
DRIVE_OUTPUTS = [
    ("I_a", "R_a", "f"),
    ("omega_m", "J_m", "f"),
    ("omega_l", "J_l", "f"),
    ("motor_torque", "motor_out", "e"),
    ("axis_torque", "load", "e"),
]


def dc_motor_reducer_load(
    p: DriveParameters, source: str = "voltage", name: str = "drive"
) -> BondGraph:
    """Build the motor–reducer–load bond graph of one axis.

    Parameters
    ----------
    p : DriveParameters
        ``c_m`` must equal ``c_e`` (the gyrator (2.7) conserves power).
    source : {"voltage", "current"}
        Armature fed by ``Se:U`` (states p_L_a, p_J_m, q_C_r, p_J_l) or by ``Sf:I_a``
        (no inductance; states p_J_m, q_C_r, p_J_l).
    name : str
        The graph's name (in error messages).

    Returns
    -------
    BondGraph
        Inputs ``U`` (or ``I_a``) and ``tau_l``; outputs :data:`DRIVE_OUTPUTS` by bond.
    """
    if p.c_m != p.c_e:
        raise BondGraphError(
            f"bond graph '{name}': c_m = {p.c_m!r} and c_e = {p.c_e!r} differ; a DC motor "
            "is a gyrator only when they are equal in consistent units"
        )
    if source not in ("voltage", "current"):
        raise BondGraphError(f"bond graph '{name}': source must be 'voltage' or 'current'")
    g = BondGraph(name)
    if source == "voltage":
        g.source_effort("U", input="U")
    else:
        g.source_flow("I_src", input="I_a")
    g.one("1_el")
    if source == "voltage":
        g.inertia("L_a", p.L_a)
    g.resistor("R_a", p.R_a)
    g.gyrator("motor", p.c_m)
    g.one("1_m")
    g.inertia("J_m", p.J_m)
    g.transformer("reducer", 1.0 / p.i_r)
    g.zero("0_shaft")
    g.one("1_twist")
    g.compliance("C_r", stiffness=p.C_r)
    g.one("1_load")
    g.inertia("J_l", p.J_l)
    g.source_effort("tau_l", input="tau_l")

    g.bond("U" if source == "voltage" else "I_src", "1_el", "source")
    if source == "voltage":
        g.bond("1_el", "L_a", "L_a")
    g.bond("1_el", "R_a", "R_a")
    g.bond("1_el", "motor", "motor_in")
    g.bond("motor", "1_m", "motor_out")
    g.bond("1_m", "J_m", "J_m")
    g.bond("1_m", "reducer", "reducer_in")
    g.bond("reducer", "0_shaft", "reducer_out")
    g.bond("0_shaft", "1_twist", "twist")
    g.bond("1_twist", "C_r", "C_r")
    g.bond("0_shaft", "1_load", "load")
    g.bond("1_load", "J_l", "J_l")
    g.bond("tau_l", "1_load", "tau_l")
    for res, junction, value in (
        ("D_m", "1_m", p.D_m),
        ("D_r", "1_twist", p.D_r),
        ("D_l", "1_load", p.D_l),
    ):
        if value > 0.0:  # a zero damper is no element
            g.resistor(res, value)
            g.bond(junction, res, res)
    return g
