"""Drives and their control.

DC drives, reducers, friction, gear trains, the servo cascade, anti-windup, LQG, and
the linear loops closed on a scene.
"""
