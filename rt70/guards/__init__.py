"""Guards against bad input and lost output.

Array arguments, memory estimates made before any work, atomic output files.
"""
