"""Mechanics on scenes beyond the open tree.

Nonholonomic constraints, the Chaplygin cart, locks that engage and their impacts.
"""
