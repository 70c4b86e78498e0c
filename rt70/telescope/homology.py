"""Gravity homology: the reflector's surface against elevation, set at a rigging angle.

One job: the surface outputs (:mod:`rt70.model.surface_outputs`) at the static
equilibrium under gravity (:func:`rt70.linear.linearize.equilibrium`) at each elevation,
relative to the rigging elevation ``E_r`` at which the panels were set: there the
surface is the design paraboloid, elsewhere it is deformed by the change of the weight's
components in the dish, ``g (cos E − cos E_r)`` across the axis and ``g (sin E − sin
E_r)`` along it (von Hoerner 1967; spec flexible-and-reflector.md §5). The best fit
takes what is a paraboloid (a focus and axis that move with elevation: the feed or the
subreflector follows them); the rest is the surface error, zero at ``E_r``.

Everything is linear in the deformation, so the relative surface is the outputs'
difference. :func:`homology` evaluates it on either side of the cross-check.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rt70.linear.linearize import equilibrium
from rt70.model.antenna import pointing
from rt70.model.outputs import evaluate
from rt70.model.scene import Scene
from rt70.model.surface_outputs import ReflectorSurface, surface_outputs, surface_rms
from rt70.surface.ruze import ruze_efficiency


@dataclass(frozen=True)
class Homology:
    """The surface against elevation, relative to the rigging elevation.

    Attributes
    ----------
    elevations_deg : numpy.ndarray, shape (n,)
        The elevations, degrees.
    rigging_deg : float
        The elevation at which the surface is the design paraboloid, degrees.
    rms_um : numpy.ndarray, shape (n,)
        The weighted RMS half-path error left by the best fit, µm.
    focus_shift_mm : numpy.ndarray, shape (n, 3)
        The best-fit focus's shift in the dish frame, mm (lateral x, y; axial z).
    axis_tilt_arcsec : numpy.ndarray, shape (n, 2)
        The best-fit axis's tilt about the dish's x and y, arc seconds.
    focal_change_mm : numpy.ndarray, shape (n,)
        ΔF, mm.
    residual_um : numpy.ndarray, shape (n, S)
        Each surface node's half-path error left by the best fit, µm.
    """

    elevations_deg: np.ndarray
    rigging_deg: float
    rms_um: np.ndarray
    focus_shift_mm: np.ndarray
    axis_tilt_arcsec: np.ndarray
    focal_change_mm: np.ndarray
    residual_um: np.ndarray

    def ruze(self, frequency_hz: float) -> np.ndarray:
        """Ruze's efficiency of the surface at each elevation, at ``frequency_hz``.

        Parameters
        ----------
        frequency_hz : float
            The frequency, Hz.
        """
        return np.array([ruze_efficiency(r * 1e-6, frequency_hz) for r in self.rms_um])


def homology(
    scene: Scene,
    surface: ReflectorSurface,
    elevations_deg: Sequence[float],
    rigging_deg: float,
    azimuth_deg: float = 0.0,
    side: str = "textbook",
) -> Homology:
    """The surface at the static equilibrium under gravity at each elevation (module docstring).

    Parameters
    ----------
    scene : Scene
        A scene with a mount (``<rt70:mount>``) and a modal body with a surface.
    surface : ReflectorSurface
        The surface (:func:`rt70.model.surface_outputs.reflector_surface`).
    elevations_deg : sequence of float
        The elevations, degrees (within the mount's range).
    rigging_deg : float
        The rigging elevation, degrees.
    azimuth_deg : float
        The azimuth, degrees.
    side : {"textbook", "reference"}
        Whose kinematics place the nodes and whose forces the equilibrium's stiffness
        is differenced from.
    """
    outs = surface_outputs(surface, prefix="s")
    names = ("s_focus_shift", "s_axis_tilt", "s_focal_change", "s_residual")

    def at(elevation: float) -> list[np.ndarray]:
        held = pointing(scene, elevation, azimuth_deg)
        q = equilibrium(scene, held, side=side)
        values = evaluate(scene, q, outs, side)
        return [values[n] for n in names]

    rigged = at(rigging_deg)
    rows = [[a - b for a, b in zip(at(e), rigged, strict=True)] for e in elevations_deg]
    focus, tilt, focal, residual = (np.array([r[i] for r in rows]) for i in range(4))
    return Homology(
        np.asarray(elevations_deg, dtype=float), float(rigging_deg),
        np.atleast_1d(surface_rms(surface, residual)), focus, tilt, focal[:, 0], residual,
    )  # fmt: skip
