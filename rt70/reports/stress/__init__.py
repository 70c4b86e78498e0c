"""Stiff and extreme cases: the report ``validation/results/stress.md``.

Every case is a variant of a scene built from URDF text in memory and reports

- ``cond(A)``: the 2-norm condition number of the mass matrix ``A = S Θ Sᵀ`` at the
  case's initial state (``numpy.linalg.cond`` of the dense textbook A; for nv > 2000 the
  LAPACK ``dpocon`` 1-norm estimate from a Cholesky factor, marked ``≈``);
- the cross-check error: the largest relative error over the ten quantities of
  :func:`rt70.crosscheck.validate.cross_check` (textbook against Pinocchio) on a few random states;
- a short simulation (:func:`rt70.simulation.simulate.simulate`, reference side, BDF,
  ``rtol = 1e-6`` unless stated) with its outcome, accepted and rejected steps, the
  number of right-hand-side evaluations, the relative drift of the energy balance
  ``T + U_g + U_c + E_ψ`` and the wall time of the integration, capped in wall time.

Modules, one job each:

- :mod:`~rt70.reports.stress.edits`: URDF rewriting (scaled springs and inertias, units,
  a floating root, gravity);
- :mod:`~rt70.reports.stress.measures`: cond(A), spring frequencies, cross-check error,
  momenta;
- :mod:`~rt70.reports.stress.runs`: capped simulations and how rejected steps are
  counted; the report's sizes (:class:`~rt70.reports.stress.runs.Settings`);
- :mod:`~rt70.reports.stress.tables`: the report's tables and their markdown;
- :mod:`~rt70.reports.stress.rt70_cases`, :mod:`~rt70.reports.stress.gimbal_cases` and
  :mod:`~rt70.reports.stress.scaling_cases`: the families of cases;
- :mod:`~rt70.reports.stress.report`: the findings and the file
  (:func:`~rt70.reports.stress.report.write_report`).
"""
