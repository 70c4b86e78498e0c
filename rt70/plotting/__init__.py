"""Figures of rt70's results, one module per subject (matplotlib is imported only here).

- :mod:`rt70.plotting.modal` — Bode diagram, step responses and mode shapes of the
  linear analyses (:mod:`rt70.linear.modal`, :mod:`rt70.linear.responses`);
- :mod:`rt70.plotting.structure` — mode shapes drawn on the structure in 3-D, still or
  animated (:mod:`rt70.linear.mode_shapes`);
- :mod:`rt70.plotting.simulation` — coordinates, energies and the energy-balance
  residual of a simulation (:mod:`rt70.simulation.simulate`).

Every helper returns a :class:`matplotlib.figure.Figure` (no pyplot state, safe with the
Agg backend); saving files is left to the caller. The analyses themselves never import
matplotlib (checked by ``tests/test_import_rules.py``).
"""
