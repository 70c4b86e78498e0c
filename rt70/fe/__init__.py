"""Finite-element models: the neutral file format and the lowest modes of sparse models.

- :mod:`rt70.fe.neutral` — sparse M and K with the node table, the DOF map and named
  interface nodes, in one ``.npz`` file (docs/fe-models.md);
- :mod:`rt70.fe.modes` — the lowest modes of a large sparse model by shift-invert
  Lanczos, with each mode's backward error;
- :mod:`rt70.fe.craig_bampton` — the reduction to interface DOFs and fixed-interface
  modes (Guyan's static condensation with none);
- :mod:`rt70.fe.truss` — a 3-D truss assembled from bar elements, the test structure
  whose matrices are checked against the textbook element.
"""
