"""The two RT-70 plants the reduction report and its tests reduce (rt70.linear.reduce).

The control object ``rt70_servo`` at one pointing (default elevation 45°, azimuth 0):

- **locked**: both axes locked by the drives; inputs a wind-like force on the main
  mirror along ground y and x (kN), outputs the focal offset (mm) and the pointing
  corrections Δα, Δβ (arcsec) — 80 states;
- **free**: the axes free; inputs the axis torques (MN·m), outputs the axis angles
  (arcsec), the focal offset and the pointing corrections — 84 states.

Used by ``validation/plant_reduction.py`` and ``tests/test_reduce.py``.
"""

from __future__ import annotations

from rt70.linear import linearize as lin
from rt70.linear import plant as pl
from rt70.linear import reduce as rd
from rt70.linear.state_space import StateSpace
from rt70.model.scene import load_scene
from rt70.physics.loads import Wrench
from rt70.scenes.rt70_optics import rt70_mirror_outputs
from rt70.scenes.rt70_state import rt70_pointing
from rt70.units import RAD_PER_ARCSEC


def reduction_plants(elevation: float = 45.0, azimuth: float = 0.0) -> dict[str, StateSpace]:
    """``{"locked": …, "free": …}``: the two plants in the units of the module docstring."""
    scene = load_scene("rt70_servo")
    held = rt70_pointing(elevation, azimuth)
    q0 = lin.equilibrium(scene, held)
    mirror = [
        o
        for o in rt70_mirror_outputs(scene, elevation, azimuth)
        if o.name in ("focal_offset", "pointing_correction")
    ]
    wind = [
        pl.LoadInput("wind_y", Wrench("main_mirror", force=(0.0, 1.0, 0.0))),
        pl.LoadInput("wind_x", Wrench("main_mirror", force=(1.0, 0.0, 0.0))),
    ]
    locked = rd.rescaled(pl.plant(scene, q0, wind, mirror, locked=tuple(held)), 1.0, 1e3)
    torques = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
    angles = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
    free = pl.plant(scene, q0, torques, angles + mirror)
    per_rad = 1.0 / RAD_PER_ARCSEC  # rad → arcsec
    free = rd.rescaled(free, [per_rad, per_rad] + [1.0] * (free.noutputs - 2), 1e6)
    return {"locked": locked, "free": free}
