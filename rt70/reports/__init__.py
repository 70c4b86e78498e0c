"""Reports and benchmarks built on the core; the core never imports them.

The book reproduction (:mod:`~rt70.reports.book`), the stress cases
(:mod:`~rt70.reports.stress`), the work–precision report of the integrators
(:mod:`~rt70.reports.work_precision`, its rows read back by
:mod:`~rt70.reports.work_precision_results`) and the mass-matrix benchmark
(:mod:`~rt70.reports.bench`, with :mod:`~rt70.reports.threads` and
:mod:`~rt70.reports.targets`). They use the core (URDF reading, both sides, scenes,
analyses, simulation) like any user would; of the package only ``rt70.cli.bench`` imports
them, inside its command function (tests/test_import_rules.py checks that no core module
does).
"""
