"""A 12-m antenna with a flexible reflector: the ``antenna_12m`` preset carrying a dish.

One job: the second antenna scene with a reflecting surface (docs/surface.md) — the
``antenna_12m`` preset (rt70.scenes.antenna_presets: an ALMA-class 12-m Cassegrain
antenna, f = 4.8 m) whose reflector link carries a parametric dish
(:func:`rt70.fe.reflector.paraboloid_dish`) as a modal body, its vertex at the preset's
primary vertex, the reflector's wind spread over its surface. The preset's reflector is a
uniform thin disk (derived there); the dish replaces that idealisation: the link keeps
the rest of the reflector's mass (hub, counterweight) as a solid sphere of the hub's
radius at the centre that keeps the total centre of mass (:data:`HUB_RADIUS`).

Every number of the dish is an assumption, stated here, not an ALMA figure: a 1-m deep
backup structure of carbon-fibre tubes (10 cm², E = 100 GPa, ρ = 1600 kg/m³) under
aluminium panels of 10 kg/m².
"""

from __future__ import annotations

import numpy as np

from rt70.fe.reflector import paraboloid_dish
from rt70.scenes.antenna import antenna_urdf
from rt70.scenes.antenna_presets import PRESETS
from rt70.scenes.reflector_scenes import dish_body, with_flexible_reflector
from rt70.urdf.modal_file import ModalArrays

#: The dish: D and F (the preset's), hub ring radius, depth (m), rings and ribs.
DISH = {"diameter": 12.0, "focal_length": 4.8, "hub_radius": 1.0, "depth": 1.0,
        "rings": 3, "ribs": 8}  # fmt: skip
#: Its bars: carbon-fibre tubes of 10 cm² (E = 1e11 Pa, ρ = 1600 kg/m³): EA (N), ρA (kg/m).
BAR = {"EA": 1e11 * 1e-3, "rho_A": 1600.0 * 1e-3}
#: Its panels, kg/m² of aperture.
PANEL_MASS = 10.0
#: Fixed-interface modes kept (plus the 9 load shapes) and their damping ratio (2 %,
#: assumed, as the preset's structure).
MODES, DAMPING = 12, 0.02
#: The rest of the reflector's mass: a solid sphere of the hub ring's radius, m.
HUB_RADIUS = DISH["hub_radius"]
#: The modal body file beside the scene.
DISH_FILE = "antenna_12m_dish.npz"


def antenna_12m_dish_body() -> ModalArrays:
    """The 12-m dish as a modal body file's arrays."""
    dish = paraboloid_dish(**DISH, **BAR, panel_mass=PANEL_MASS)
    return dish_body(
        dish, MODES, f"{dish.fe.name} (rt70.scenes.antenna_dish), clamped at its hub ring"
    )


def antenna_12m_dish_scene() -> str:
    """The URDF text: the ``antenna_12m`` preset with its reflector a flexible dish."""
    spec = PRESETS["antenna_12m"]
    text = antenna_urdf(spec).replace(
        '<robot name="antenna_12m"', '<robot name="antenna_12m_dish"', 1
    )
    vertex = next(p for p in _optical_points(text) if p[0] == "primary_vertex")[1]
    return with_flexible_reflector(
        text, "reflector", vertex, antenna_12m_dish_body(), "dish", DISH_FILE, DAMPING,
        wind="reflector", hub_radius=HUB_RADIUS,
    )  # fmt: skip


def _optical_points(text: str) -> list[tuple[str, np.ndarray]]:
    """The ``<rt70:optical_point>`` names and positions of a URDF text."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(text)
    ns = "{urn:rt70:urdf-extensions:1}"
    return [
        (e.get("name"), np.array([float(v) for v in e.get("xyz").split()]))
        for e in root.iter(f"{ns}optical_point")
    ]
