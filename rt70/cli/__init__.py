"""The ``rt70`` command line: one module per command.

The options are checked before any work (:mod:`rt70.cli.options`).
"""
