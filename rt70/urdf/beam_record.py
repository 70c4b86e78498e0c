"""The record of one ``<rt70:beam>``: a member's material, section and division.

One job: the plain data the beam element is written from (:mod:`rt70.urdf.beams`) and
that the description keeps (:attr:`rt70.urdf.description.RobotDescription.beams`), with
the division's lengths and the stiffness of each spring-damping element (docs/beams.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Coordinates of one spring-damping element of a beam (:mod:`rt70.urdf.beams`), in their
#: joint order, each with its joint type and axis in the beam frame.
SDE_COORDINATES = (
    ("ux", "prismatic", "1 0 0"),
    ("uy", "prismatic", "0 1 0"),
    ("uz", "prismatic", "0 0 1"),
    ("rx", "revolute", "1 0 0"),
    ("ry", "revolute", "0 1 0"),
    ("rz", "revolute", "0 0 1"),
)


@dataclass(frozen=True)
class Beam:
    """One ``<rt70:beam>``: a prismatic member's material, section and division.

    Attributes
    ----------
    name : str
        The beam's name: its links are ``{name}_seg0`` … ``{name}_seg{n}``.
    parent : str
        The link the beam starts from (clamped to it).
    child : str or None
        A link fixed to the beam's end (its frame the beam frame at x = L), if any.
    xyz, rpy : numpy.ndarray
        The beam frame at its start, in the parent link: x along the member, y and z the
        section's principal axes.
    length : float
        L, m.
    segments : int
        n, the number of primary segments (spring-damping elements).
    E, G : float
        Young's and shear modulus, Pa.
    rho : float
        Density, kg/m³.
    A, Iy, Iz, J : float
        Area (m²), second moments about y and z (``∫z² dA``, ``∫y² dA``, m⁴), torsion
        constant (m⁴).
    Asy, Asz : float or None
        Shear areas along y and z (``κ A``, m²); None: the section does not shear.
    axial : bool
        Whether the member stretches (an axial coordinate per spring-damping element).
    beta : float
        Stiffness-proportional damping ``β``, s (a mode at ω gets ζ = β ω / 2).
    """

    name: str
    parent: str
    child: str | None
    xyz: np.ndarray
    rpy: np.ndarray
    length: float
    segments: int
    E: float
    G: float
    rho: float
    A: float
    Iy: float
    Iz: float
    J: float
    Asy: float | None = None
    Asz: float | None = None
    axial: bool = True
    beta: float = 0.0

    @property
    def step(self) -> float:
        """ℓ = L/n, the primary segment's length, m."""
        return self.length / self.segments

    @property
    def links(self) -> list[str]:
        """The rigid elements' links from the clamp to the free end."""
        return [f"{self.name}_seg{i}" for i in range(self.segments + 1)]

    @property
    def end_link(self) -> str:
        """The massless link at the beam's end (x = L), to hang other bodies on."""
        return f"{self.name}_end"

    @property
    def mass(self) -> float:
        """ρ A L, kg."""
        return self.rho * self.A * self.length

    def element_lengths(self) -> np.ndarray:
        """``ℓ_e`` of rigid elements 0 … n: half, n − 1 full and half segments, m."""
        lengths = np.full(self.segments + 1, self.step)
        lengths[[0, -1]] = self.step / 2
        return lengths

    def coordinates(self) -> list[tuple[str, str, str, float]]:
        """``(name, joint type, axis, stiffness)`` of one spring-damping element, joint order.

        Stiffness of one primary segment ℓ: axial EA/ℓ, shear G A_s/ℓ, torsion GJ/ℓ,
        bending EI/ℓ (N/m or N·m/rad).
        """
        ell = self.step
        stiffness = {
            "ux": self.E * self.A / ell if self.axial else None,
            "uy": None if self.Asy is None else self.G * self.Asy / ell,
            "uz": None if self.Asz is None else self.G * self.Asz / ell,
            "rx": self.G * self.J / ell,
            "ry": self.E * self.Iy / ell,
            "rz": self.E * self.Iz / ell,
        }
        return [(c, t, a, stiffness[c]) for c, t, a in SDE_COORDINATES if stiffness[c] is not None]
