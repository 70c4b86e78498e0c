"""Linear models: topology (chapter 2), holonomic elimination (chapter 3), modal analysis.

- :mod:`rt70.linear.topology` — the topology matrix Γ and ``m q̈ + ΓᵀDΓq̇ + ΓᵀCΓq = Q``;
  :mod:`rt70.linear.torsion_scene` reads such a model back from a torsional URDF scene;
- :mod:`rt70.linear.holonomic` — rigid links eliminated through a spanning tree
  (Γ*, ``L = Γ*⁻ᵀ``, mobility f, ``S = fᵀL``, reduced A*, C*, D*);
- :mod:`rt70.linear.modal` — eigenfrequencies, mode shapes, damping, principal coordinates;
- :mod:`rt70.linear.responses` — state space, frequency and step responses;
- :mod:`rt70.linear.checks` — the input checks both share;
- :mod:`rt70.linear.linearize` — equilibrium and M, K, D of a nonlinear URDF scene;
- :mod:`rt70.linear.manifold` — constraints Φ(q) = 0 as callables of q, the row and null
  space of their Jacobian, the stiffness of a force and of the multipliers;
- :mod:`rt70.linear.constrained_equilibrium` — the static equilibrium on the manifold;
- :mod:`rt70.linear.constrained` — linearisation (with the multipliers' geometric
  stiffness) and modes on a constraint manifold Φ(q) = 0; wired to a scene's
  closed chains by :mod:`rt70.linear.constrained_scene`, its rows by
  :mod:`rt70.linear.mode_table` (docs/constrained-modes.md);
- :mod:`rt70.linear.covariance` — stationary covariances under white noise (Lyapunov),
  shaping filters in series, the variance split over modes, the statistical error of a
  record's mean square.
"""
