"""The RT-70's own studies.

Servo scenarios, the wind pointing budget, gust runs and bearing loads.
"""
