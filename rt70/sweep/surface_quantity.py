"""The sweep quantity ``surface``: the reflector surface at each point (docs/surface.md).

One job: register :func:`surface_quantity` — the surface error left by the best-fit
paraboloid and the best fit's defocus at a sweep point, for a scene with a reflecting
surface — and make it again with Ruze's efficiency at the frequencies a user asks for
(``rt70 sweep --frequency``, one field per frequency, so a sweep's key tells them apart).

At a point with wind (> 0) it is :mod:`rt70.telescope.surface_budget`'s reading of the
pointing budget (gravity from the rigging elevation, steady wind, gusts; drive-held
equilibria). Without wind it is gravity alone, at the point's equilibrium with the axes
held (:meth:`rt70.sweep.quantities.SweepPoint.equilibrium`) against the same at the
rigging elevation. The rigging elevation is the middle of the mount's elevation range
(:func:`rt70.telescope.surface_budget.default_rigging`).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from typing import Any

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.scene import Scene
from rt70.sweep.quantities import Field, Quantity, SweepPoint, register_quantity


def ruze_field(frequency_ghz: float) -> str:
    """The name of the Ruze-efficiency field at ``frequency_ghz``: ``surface_ruze_86GHz``."""
    return f"surface_ruze_{frequency_ghz:g}GHz"


def _surface(scene: Scene, point: SweepPoint, frequencies_ghz: tuple[float, ...]) -> dict[str, Any]:
    """The surface quantity's fields at one point (module docstring)."""
    from rt70.linear.linearize import equilibrium
    from rt70.model.antenna import pointing
    from rt70.model.outputs import evaluate
    from rt70.model.surface_outputs import surface_rms
    from rt70.surface.ruze import ruze_efficiency
    from rt70.telescope.pointing import PointingCase, budget_model
    from rt70.telescope.surface_budget import (
        PREFIX,
        case_surface,
        default_rigging,
        scene_surface_outputs,
    )

    rigging = default_rigging(scene)
    if point.wind > 0.0:
        case = PointingCase(point.elevation, point.azimuth, point.wind, point.direction)
        b = case_surface(budget_model(scene, case), rigging, [])
        rms = (b.gravity_rms_um, b.wind_rms_um, b.gust_rms_um, b.total_rms_um)
        focus, tilt = b.steady["focus_shift"], b.steady["axis_tilt"]
    else:
        surface, outs = scene_surface_outputs(scene)
        q_rig = equilibrium(scene, pointing(scene, rigging, point.azimuth))
        at = [evaluate(scene, q, outs, "reference") for q in (q_rig, point.equilibrium(scene))]
        change = {o.name: at[1][o.name] - at[0][o.name] for o in outs}
        gravity = float(surface_rms(surface, change[f"{PREFIX}_residual"]))
        rms = (gravity, 0.0, 0.0, gravity)
        focus, tilt = change[f"{PREFIX}_focus_shift"], change[f"{PREFIX}_axis_tilt"]
    out: dict[str, Any] = dict(zip(RMS_FIELDS, rms, strict=True))
    out["surface_focus_shift"], out["surface_axis_tilt"] = focus, tilt
    for f in frequencies_ghz:
        out[ruze_field(f)] = ruze_efficiency(rms[3] * 1e-6, f * 1e9)
    return out


def _check(scene: Scene) -> None:
    """Refuse a scene without one reflecting surface or without a mount, before any work."""
    from rt70.model.antenna import mount_of
    from rt70.telescope.surface_budget import scene_surface_outputs

    if scene_surface_outputs(scene) is None:
        raise Rt70Error(
            f"{scene.name}: no reflecting surface (a <rt70:modal_body> whose file has one, "
            "docs/surface.md)"
        )
    mount_of(scene)


#: The four RMS fields, µm: gravity, steady wind, gusts, all together.
RMS_FIELDS = ("surface_gravity_rms", "surface_wind_rms", "surface_gust_rms", "surface_rms")


def surface_quantity(frequencies_ghz: Sequence[float] = ()) -> Quantity:
    """The ``surface`` quantity with Ruze's efficiency at ``frequencies_ghz`` (GHz).

    Parameters
    ----------
    frequencies_ghz : sequence of float
        Frequencies, GHz (> 0, distinct); none by default.
    """
    freqs = tuple(float(f) for f in frequencies_ghz)
    if any(not (np.isfinite(f) and f > 0.0) for f in freqs) or len(set(freqs)) != len(freqs):
        raise Rt70Error(f"--frequency: distinct positive GHz values, got {list(freqs)}")
    fields = (
        Field(RMS_FIELDS[0], (), "um", "gravity: surface RMS from the rigging elevation"),
        Field(RMS_FIELDS[1], (), "um", "steady wind: surface RMS"),
        Field(RMS_FIELDS[2], (), "um", "gusts: ensemble surface RMS"),
        Field(RMS_FIELDS[3], (), "um", "surface RMS, all together"),
        Field("surface_focus_shift", (3,), "mm", "best-fit focus shift (lateral x, y; axial)"),
        Field("surface_axis_tilt", (2,), "arcsec", "best-fit axis tilt about x, y"),
        *(Field(ruze_field(f), (), "1", f"Ruze efficiency at {f:g} GHz") for f in freqs),
    )
    return Quantity(
        "surface",
        fields,
        partial(_surface, frequencies_ghz=freqs),
        check=_check,
        description="the reflector surface: RMS after the best fit, defocus (docs/surface.md)",
    )


register_quantity(surface_quantity())
