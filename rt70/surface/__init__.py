"""The reflector surface: path-length errors, the best-fit paraboloid, Ruze's efficiency.

The mathematics of a paraboloidal reflector's surface, shared by both sides of the
cross-check as post-processing of the surface nodes' displacements (docs/surface.md):

- :mod:`rt70.surface.paraboloid` — the nominal surface and the half-path-length error
  of a displaced node;
- :mod:`rt70.surface.best_fit` — the weighted least-squares best-fit paraboloid, its
  vertex, axis, focus and the residual RMS, and the same as exact linear maps;
- :mod:`rt70.surface.ruze` — the aperture efficiency of a surface error at a frequency.
"""
