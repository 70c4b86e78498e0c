"""The RT-70 with a flexible main mirror: the scene ``rt70_mirror`` (docs/surface.md).

One job: the RT-70 control object (``rt70_servo``) whose main mirror carries a
parametric 70-m dish as a modal body with a reflecting surface
(:mod:`rt70.scenes.reflector_scenes`), the main mirror's link keeping the rest of the
listing's mass, centre and inertia, and its wind spread over the dish's surface. Every
number of the dish not in the book is stated below with its reason.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import Rt70Error
from rt70.fe.reflector import Dish
from rt70.scenes.reflector_scenes import dish_body, rigid_properties, with_flexible_reflector
from rt70.urdf.modal_file import ModalArrays

#: The RT-70's main mirror as a dish: D (the telescope's 70 m), F, hub ring radius and
#: truss depth (m), rings and ribs. F = 21 m is F/D = 0.3, stated, not from an RT-70
#: source: the book calls the mirror system a long-focus Gregorian (§2.2) without a
#: number, and the listing's optical points (focus 5 m from the vertex mark) are marks
#: of the lumped model, not the optics (a 70-m paraboloid with F = 5 m would be 61 m
#: deep). 0.3 is Effelsberg's 100-m primary (f = 30 m) and common for large dishes.
RT70_DISH = {"diameter": 70.0, "focal_length": 21.0, "hub_radius": 6.0, "depth": 8.0,
             "rings": 3, "ribs": 8}  # fmt: skip
#: Every bar: a steel tube of 4 cm² (E = 2.1e11 Pa, ρ = 7850 kg/m³): EA (N), ρA (kg/m).
#: Bars alone of 6.5 cm² would fill the dish's share of the polar moment in this layout.
RT70_BAR = {"EA": 2.1e11 * 4e-4, "rho_A": 7850.0 * 4e-4}
#: The dish's share of the listing main mirror's polar moment (the rest stays lumped on
#: the link: the listing's body is heavier at its centre than a uniform dish).
RT70_DISH_SHARE = 0.75
#: Fixed-interface modes of the dish kept (plus the 9 static shapes of its loads).
RT70_DISH_MODES = 16
#: The dish's modal damping ratio (the RT-70's structural damping is not in the source;
#: 1 % is the usual figure for welded steel structures, stated).
RT70_DISH_DAMPING = 0.01
#: The dish's modal body file, beside the scene's URDF file.
RT70_DISH_FILE = "rt70_mirror_dish.npz"


def rt70_dish(panel_mass: float | None = None, **layout: int) -> Dish:
    """The RT-70's main-mirror dish (:data:`RT70_DISH`, :data:`RT70_BAR`).

    Parameters
    ----------
    panel_mass : float, optional
        The panels' kg/m²; by default the value that gives the dish
        :data:`RT70_DISH_SHARE` of the listing main mirror's polar moment (derived:
        the polar moment is linear in it).
    **layout : int
        ``rings`` and ``ribs`` instead of :data:`RT70_DISH`'s (a finer dish for the
        textbook side, whose cost grows with the modes, not the nodes).
    """
    geometry = {**RT70_DISH, **layout}
    from rt70.fe.reflector import paraboloid_dish
    from rt70.scenes.rt70_data import LISTING_BODIES

    if panel_mass is None:
        bare = rigid_properties(
            *_nodes_masses(paraboloid_dish(**geometry, **RT70_BAR, panel_mass=0))
        )
        unit = rigid_properties(
            *_nodes_masses(paraboloid_dish(**geometry, **RT70_BAR, panel_mass=1))
        )
        target = RT70_DISH_SHARE * _listing_main_mirror(LISTING_BODIES)[2][2, 2]
        panel_mass = (target - bare[2][2, 2]) / (unit[2][2, 2] - bare[2][2, 2])
        if not panel_mass >= 0.0:
            raise Rt70Error("the RT-70 dish's bars alone exceed its share of the main mirror")
    return paraboloid_dish(**geometry, **RT70_BAR, panel_mass=panel_mass)


def _nodes_masses(dish: Dish) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(dish.fe.node_xyz, dtype=float), dish.fe.M.diagonal()[::3]


def _listing_main_mirror(bodies) -> tuple[float, np.ndarray, np.ndarray]:
    """``(m, c, I_c)`` of the listing's main mirror (body 5)."""
    body = [b for b in bodies if b["name"] == "main_mirror"][0]
    return body["mass"], np.asarray(body["com"], dtype=float), np.diag(body["moments"])


def rt70_mirror_body(modes: int = RT70_DISH_MODES, **layout: int) -> ModalArrays:
    """The RT-70 main mirror's dish as a modal body file's arrays (:func:`dish_body`).

    Parameters
    ----------
    modes : int
        Fixed-interface modes kept (plus the 9 load shapes).
    **layout : int
        ``rings`` and ``ribs`` (:func:`rt70_dish`).
    """
    dish = rt70_dish(**layout)
    return dish_body(
        dish, modes,
        f"{dish.fe.name}, the RT-70 main mirror (rt70.scenes.reflector_scenes): clamped at "
        f"its hub ring, {modes} fixed-interface modes and 9 load shapes",
    )  # fmt: skip


def rt70_mirror_scene(body: ModalArrays | None = None, file: str = RT70_DISH_FILE) -> str:
    """The RT-70 control object (``rt70_servo``) with its main mirror a flexible dish.

    The dish's centre of mass sits at the main mirror's (its vertex below it on the
    axis), so the link keeps the listing's mass, centre and inertia in total.

    Parameters
    ----------
    body : rt70.urdf.modal_file.ModalArrays, optional
        The dish (:func:`rt70_mirror_body`); the shipped one by default.
    file : str
        The name its file has beside the URDF file.
    """
    from rt70.scenes.rt70_scenes import rt70_servo_scene

    body = rt70_mirror_body() if body is None else body
    _, c, _ = rigid_properties(body.nodes, body.masses)
    text = rt70_servo_scene()
    head = text[: text.index("<robot")]
    text = text.replace('<robot name="rt70_servo"', '<robot name="rt70_mirror"', 1)
    text = text.replace(
        head.splitlines()[1],
        f"<!-- RT-70 as a control object (rt70_servo) with a flexible main mirror: the dish "
        f"of {file} on the main mirror's pair, the main mirror's wind spread over its "
        "surface -->",
        1,
    )
    return with_flexible_reflector(
        text, "main_mirror", np.array([0.0, 0.0, -c[2]]), body, "main_dish", file,
        RT70_DISH_DAMPING, wind="main_mirror",
    )  # fmt: skip
