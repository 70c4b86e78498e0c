"""Time simulation of a scene with its energy audit.

The integrators, the extra states integrated with the mechanics, closed chains.
"""
