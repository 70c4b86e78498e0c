"""Single beams as scenes: the test structures of the beam element (docs/beams.md).

A uniform member written as one ``<rt70:beam>``, clamped to the ground (a cantilever) or
on a massless floating base (free–free), and its bending frequencies in one principal
plane, the other coordinates locked — what :mod:`rt70.fe.beam_theory` gives exactly.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.scene import scene_from_text

#: A 10 mm square steel bar (SI units): E, G, ρ, A, I_y = I_z = h⁴/12, J ≈ 0.1406 h⁴.
STEEL_BAR = {
    "E": 2.1e11,
    "G": 8.1e10,
    "rho": 7850.0,
    "A": 1e-4,
    "Iy": 8.333e-10,
    "Iz": 3.3e-9,
    "J": 1.4e-9,
}

#: Supports a beam scene can have.
BEAM_SUPPORTS = ("cantilever", "free-free")


def beam_text(
    segments: int,
    support: str = "cantilever",
    length: float = 2.0,
    section: Mapping[str, float] = STEEL_BAR,
    extra: str = "",
) -> str:
    """The URDF text of one beam named ``b`` along the ground x axis, gravity off.

    Parameters
    ----------
    segments : int
        The beam's primary segments.
    support : {"cantilever", "free-free"}
        Clamped to the ground, or on a massless base with a floating joint.
    length : float
        L, m.
    section : mapping
        The beam's material and section attributes (``E``, ``G``, ``rho``, ``A``, …).
    extra : str
        More attributes of the beam element, written as they are (``axial="false"``).
    """
    if support not in BEAM_SUPPORTS:
        raise ValueError(f"support {support!r} is not one of {', '.join(BEAM_SUPPORTS)}")
    attributes = " ".join(f'{k}="{float(v)!r}"' for k, v in section.items())
    base = (
        '<link name="free_base"/><joint name="float" type="floating"><parent link="world"/>'
        '<child link="free_base"/></joint>'
        if support == "free-free"
        else ""
    )
    parent = "free_base" if support == "free-free" else "world"
    return (
        '<?xml version="1.0"?>\n<robot name="beam" xmlns:rt70="urn:rt70:urdf-extensions:1">\n'
        f'<link name="world"/>{base}<rt70:gravity xyz="0 0 0"/>\n'
        f'<rt70:beam name="b" parent="{parent}" length="{float(length)!r}" '
        f'segments="{segments}" {attributes} {extra}/>\n</robot>\n'
    )


def xz_bending_frequencies(text: str, count: int = 3) -> np.ndarray:
    """The lowest frequencies of bending in the x–z plane of the text's one beam, Hz.

    Every coordinate but the beam's bending rotations about y (``{name}_sde{i}_ry``), its
    shear along z (``_uz``) and a floating base's z and ry is locked
    (:func:`rt70.linear.linearize.linearize`); rigid modes (below 1e-6 of the highest
    frequency) are dropped.
    """
    scene = scene_from_text(text)
    (beam,) = scene.description.beams
    keep = {f"{beam.name}_sde{i}_{c}" for i in range(1, beam.segments + 1) for c in ("ry", "uz")}
    locked = tuple(
        n for n in scene.coordinate_names if n not in keep and not n.endswith((":z", ":ry"))
    )
    lm = lin.linearize(scene, np.zeros(len(scene.coordinate_names)), locked=locked)
    f = modal.modes(lm.M, lm.K).freq_hz
    return f[f > 1e-6 * f.max()][:count]
