"""The surface beside the pointing: gravity, steady wind and gusts on the reflector.

One job: for a pointing case whose scene has a reflecting surface (a modal body with
one, docs/surface.md), what the wind budget (:mod:`rt70.telescope.pointing`) does to the
surface, and what gravity does at that elevation:

- **gravity** — the surface at the calm drive-held equilibrium against the one at the
  rigging elevation (:mod:`rt70.telescope.homology`'s reading, held by the drives);
- **steady wind** — the windy equilibrium against the calm one (the wind spread over the
  surface, ``<rt70:wind surface=...>``);
- **gusts** — the ensemble covariance of the residual's rows through the same closed
  loop and gust filter as the pointing's (one Lyapunov solution), so the mean square of
  the weighted RMS is ``Σ w_n var(r_n)``.

The deterministic parts add as residual vectors (gravity and steady wind at once), the
gusts in quadrature: ``ε² = rms(r_g + r_w)² + Σ w_n var(r_n)``, and Ruze's efficiency is
that of ε at each frequency asked for.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.model.outputs import Output, evaluate
from rt70.model.scene import Scene
from rt70.model.surface_outputs import ReflectorSurface, surface_outputs, surface_rms
from rt70.surface.ruze import ruze_efficiency

#: The prefix of the surface outputs in the budget's loop.
PREFIX = "surface"
#: The surface outputs the budget carries (names after the prefix), their units.
SURFACE_OUTPUTS = {
    "focus_shift": "mm",
    "axis_tilt": "arcsec",
    "beam_deviation": "arcsec",
    "residual": "um",
}


def budget_surface_outputs(surface: ReflectorSurface) -> list[Output]:
    """The surface outputs of :data:`SURFACE_OUTPUTS`, named ``surface_<name>``.

    Parameters
    ----------
    surface : ReflectorSurface
        The scene's surface (:func:`rt70.model.surface_outputs.reflector_surface`).
    """
    found = {o.name: o for o in surface_outputs(surface, PREFIX)}
    return [found[f"{PREFIX}_{n}"] for n in SURFACE_OUTPUTS]


@dataclass(frozen=True)
class SurfaceBudget:
    """The surface of one pointing case (module docstring).

    Attributes
    ----------
    rigging_deg : float
        The elevation at which the surface is the design paraboloid, degrees.
    gravity_rms_um, wind_rms_um, gust_rms_um, total_rms_um : float
        The weighted RMS half-path error left by the best fit: gravity from the rigging
        elevation, the steady wind, the gusts' ensemble rms, and all together, µm.
    steady : dict of str to numpy.ndarray
        Gravity plus steady wind: the best fit's focus shift (mm), axis tilt and beam
        deviation (arc seconds), by name.
    gust : dict of str to float
        The gusts' ensemble rms of the magnitude of each of those, by name.
    ruze : dict of float to float
        Ruze's efficiency of ``total_rms_um`` at each frequency (Hz).
    """

    rigging_deg: float
    gravity_rms_um: float
    wind_rms_um: float
    gust_rms_um: float
    total_rms_um: float
    steady: dict
    gust: dict
    ruze: dict

    def to_dict(self) -> dict:
        """Plain JSON-ready values."""
        return {
            "rigging_elevation_deg": self.rigging_deg,
            "rms_um": {
                "gravity": self.gravity_rms_um,
                "steady_wind": self.wind_rms_um,
                "gust": self.gust_rms_um,
                "total": self.total_rms_um,
            },
            "units": {k: v for k, v in SURFACE_OUTPUTS.items() if k != "residual"},
            "steady": {k: v.tolist() for k, v in self.steady.items()},
            "gust_rms": self.gust,
            "ruze_efficiency": {f"{f / 1e9:g} GHz": e for f, e in self.ruze.items()},
        }


def surface_budget(
    scene: Scene,
    surface: ReflectorSurface,
    q_rigging: np.ndarray,
    q_calm: np.ndarray,
    q_wind: np.ndarray,
    gust_covariance: np.ndarray,
    rigging_deg: float,
    frequencies_hz: list[float],
) -> SurfaceBudget:
    """The surface budget from the equilibria and the gust covariance (module docstring).

    Parameters
    ----------
    scene : Scene
        The scene.
    surface : ReflectorSurface
        Its reflecting surface.
    q_rigging, q_calm, q_wind : numpy.ndarray, shape (nv,)
        The drive-held equilibria at the rigging elevation, at the case without wind and
        with its steady wind.
    gust_covariance : numpy.ndarray, shape (m, m)
        The ensemble covariance of the :func:`budget_surface_outputs`' components, in
        their order.
    rigging_deg : float
        The rigging elevation, degrees.
    frequencies_hz : list of float
        Where Ruze's efficiency is wanted, Hz.
    """
    outs = budget_surface_outputs(surface)
    at = {
        key: evaluate(scene, q, outs, "reference")
        for key, q in (("rig", q_rigging), ("calm", q_calm), ("wind", q_wind))
    }
    residual = f"{PREFIX}_residual"
    r_gravity = at["calm"][residual] - at["rig"][residual]
    r_wind = at["wind"][residual] - at["calm"][residual]
    rows, start = {}, 0
    for o in outs:
        rows[o.name] = slice(start, start + o.size)
        start += o.size
    variance = np.clip(np.diag(gust_covariance)[rows[residual]], 0.0, None)
    gust = float(np.sqrt(surface.maps.weights @ variance))
    steady_rms = float(surface_rms(surface, r_gravity + r_wind))
    total = float(np.hypot(steady_rms, gust))
    names = [o.name for o in outs if o.name != residual]
    return SurfaceBudget(
        float(rigging_deg),
        float(surface_rms(surface, r_gravity)),
        float(surface_rms(surface, r_wind)),
        gust,
        total,
        {n.removeprefix(f"{PREFIX}_"): at["wind"][n] - at["rig"][n] for n in names},
        {
            n.removeprefix(f"{PREFIX}_"): float(
                np.sqrt(np.trace(gust_covariance[rows[n], rows[n]]))
            )
            for n in names
        },
        {f: ruze_efficiency(total * 1e-6, f) for f in frequencies_hz},
    )


def format_surface(b: SurfaceBudget) -> list[str]:
    """The surface budget's lines of ``rt70 pointing``'s table."""
    lines = [
        f"  reflector surface (best-fit paraboloid removed; panels set at elevation "
        f"{b.rigging_deg:g}°), RMS half-path error, µm:",
        f"    gravity {b.gravity_rms_um:.4g}, steady wind {b.wind_rms_um:.4g}, gust rms "
        f"{b.gust_rms_um:.4g}; all together {b.total_rms_um:.4g}",
    ]
    for name, unit in SURFACE_OUTPUTS.items():
        if name in b.steady:
            v = ", ".join(f"{x:+.4g}" for x in b.steady[name])
            lines.append(
                f"    {name.replace('_', ' '):<15} steady ({v}) {unit}, gust rms "
                f"{b.gust[name]:.4g} {unit}"
            )
    if b.ruze:
        eff = ", ".join(f"{e:.4g} at {f / 1e9:g} GHz" for f, e in b.ruze.items())
        lines.append(f"    Ruze efficiency of the surface: {eff}")
    return lines


def scene_surface_outputs(scene: Scene) -> tuple[ReflectorSurface, list[Output]] | None:
    """The scene's one reflecting surface and its budget outputs, or None without one.

    Parameters
    ----------
    scene : Scene
        The scene.
    """
    from rt70.model.surface_outputs import has_surface, reflector_surface

    if not has_surface(scene):
        return None
    surface = reflector_surface(scene)
    return surface, budget_surface_outputs(surface)


def default_rigging(scene: Scene) -> float:
    """The middle of the mount's elevation range, degrees: the rigging angle by default.

    A reflector's panels are usually set near the middle of its elevation range, which
    halves the largest gravity deformation; the real rigging angle is the antenna's.
    """
    from rt70.model.antenna import mount_of, range_deg

    axis = next(a for a in mount_of(scene).axes if a.name == "elevation")
    low, high = range_deg(axis)
    return 0.5 * (low + high)


def case_surface(model, rigging_deg: float, frequencies_hz: list[float]) -> SurfaceBudget:
    """The surface budget of a pointing case's :class:`rt70.telescope.pointing.BudgetModel`.

    Parameters
    ----------
    model : rt70.telescope.pointing.BudgetModel
        The case's model, built with the scene's surface outputs in its loop.
    rigging_deg : float
        The rigging elevation, degrees.
    frequencies_hz : list of float
        Where Ruze's efficiency is wanted, Hz.
    """
    from rt70.model.antenna import pointing
    from rt70.telescope.scene_servo import SceneServoFactory, scene_equilibrium

    scene = model.windy.scene
    surface, outs = model.surface
    couplings = SceneServoFactory(side="reference").couplings(scene)
    held = pointing(scene, rigging_deg, model.case.azimuth_deg)
    q_rig, _, _ = scene_equilibrium(scene, couplings, held)
    return surface_budget(
        scene, surface, q_rig, model.state.q_calm, model.state.q_wind,
        model.output_covariance(outs), rigging_deg, frequencies_hz,
    )  # fmt: skip
