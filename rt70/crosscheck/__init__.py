"""The cross-check of the two sides: ``rt70 validate`` and its rows.

Its rows for the scene's elements, and the robots of example-robot-data.
"""
