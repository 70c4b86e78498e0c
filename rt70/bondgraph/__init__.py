"""Bond graphs: a second, independent way to the equations of drives.

A small, generic linear bond-graph layer after the companion source 003 (Kuzmin 2008):
elements and bonds (:mod:`.graph`), causality by SCAP (:mod:`.causality`), the state
equations ``ẋ = A x + B u`` with energy and power budget (:mod:`.equations`); the axis
drive (:mod:`.drive`) and the Example-1a gear reducer (:mod:`.reducer`) as bond graphs;
the same two in Lagrange form, written independently (:mod:`.lagrange`). Imports
neither side of the rigid-body cross-check; numpy only. See docs/bond-graphs.md.
"""

from rt70.bondgraph.causality import Causality, assign_causality
from rt70.bondgraph.drive import DRIVE_OUTPUTS, dc_motor_reducer_load
from rt70.bondgraph.equations import PowerBalance, StateEquations, state_equations
from rt70.bondgraph.graph import BondGraph, BondGraphError, CausalityError
from rt70.bondgraph.lagrange import SecondOrder, drive_lagrange, reducer_lagrange
from rt70.bondgraph.parameters import DriveParameters, GearReducerParameters, ParameterError
from rt70.bondgraph.reducer import gear_reducer, reducer_outputs

__all__ = [
    "DRIVE_OUTPUTS",
    "BondGraph",
    "BondGraphError",
    "Causality",
    "CausalityError",
    "DriveParameters",
    "GearReducerParameters",
    "ParameterError",
    "PowerBalance",
    "SecondOrder",
    "StateEquations",
    "assign_causality",
    "dc_motor_reducer_load",
    "drive_lagrange",
    "gear_reducer",
    "reducer_lagrange",
    "reducer_outputs",
    "state_equations",
]
