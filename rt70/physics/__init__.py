"""The mathematics both sides of the cross-check share.

Rotations, loads, holonomic constraints, the KKT system, Baumgarte stabilisation,
impacts, nonholonomic constraints and the aerodynamic law of the wind.
"""
