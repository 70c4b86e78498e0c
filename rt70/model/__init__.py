"""A scene: one URDF file read once into both sides.

And what is computed from a state on either side: outputs, the mirror system, the
coupling of a drive's reducer to the structure.
"""
