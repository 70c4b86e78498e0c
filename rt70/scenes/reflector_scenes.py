"""A reflector as a flexible body in a scene: a dish on its link, mass and inertia kept.

One job: turn a scene's rigid reflector link into the same link carrying a parametric
dish (:func:`rt70.fe.reflector.paraboloid_dish`) as a modal body with a reflecting
surface (docs/surface.md), without changing the link's mass, centre of mass or inertia:
the dish takes its share and the link keeps the rest (the hub, the counterweights, the
parts the truss does not model).

- :func:`dish_body` — the dish clamped at its hub ring, its lowest modes augmented by the
  static shapes of its weight and of a wind pressure (:func:`rt70.fe.modal_body.clamped_modes`),
  with its surface nodes, their aperture weights and F;
- :func:`rigid_properties` — the dish's mass, centre and inertia as a rigid body;
- :func:`with_flexible_reflector` — the URDF text with the link's inertial reduced by the
  dish's, a frame ``<dish>_link`` at the paraboloid's vertex welded to the link, and the
  ``<rt70:modal_body>`` on it.

The RT-70's (``rt70_mirror``) is :mod:`rt70.scenes.rt70_mirror`, a 12-m antenna's
:mod:`rt70.scenes.antenna_dish`.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from rt70.errors import Rt70Error
from rt70.fe.modal_body import clamped_modes
from rt70.fe.reflector import Dish
from rt70.scenes import urdf_writer as uw
from rt70.urdf import read_urdf_string
from rt70.urdf.modal_file import ModalArrays
from rt70.urdf.modal_record import Surface

#: The namespace of rt70's URDF elements.
RT70_NAMESPACE = "urn:rt70:urdf-extensions:1"
#: Tolerance of the residual inertia's triangle inequality, relative to its trace.
TRIANGLE_RTOL = 1e-12


def load_patterns(dish: Dish) -> np.ndarray:
    """Nodal force patterns (9, N, 3) of the dish's weight and of the wind's pressure.

    The weight along x, y, z (each node's mass times a unit acceleration), and the
    wind's pressure field over the surface nodes (:mod:`rt70.surface.pressure`): by
    their aperture weights along x, y, z, and ``w_n (e_k × ρ_n)`` about the weighted
    centre for k = x, y, z. Their static shapes make the dish's response to gravity at
    any elevation and to any wind wrench spread by :func:`rt70.surface.pressure.nodal_forces`
    exact in the modal body (:func:`dish_body`).

    Parameters
    ----------
    dish : rt70.fe.reflector.Dish
        The dish.
    """
    masses = dish.fe.M.diagonal()[::3]
    out = np.zeros((9, masses.size, 3))
    w = dish.weights / dish.weights.sum()
    x = np.asarray(dish.fe.node_xyz, dtype=float)[dish.surface]
    rho = x - w @ x
    for k, e in enumerate(np.eye(3)):
        out[k, :, k] = masses
        out[3 + k, dish.surface, k] = w
        out[6 + k, dish.surface] = w[:, None] * np.cross(e, rho)
    return out


def dish_body(dish: Dish, modes: int, source: str) -> ModalArrays:
    """The dish clamped at its hub ring as a modal body file's arrays, with its surface.

    Parameters
    ----------
    dish : rt70.fe.reflector.Dish
        The dish (its front layer is the surface).
    modes : int
        Fixed-interface modes kept; the 9 static shapes of :func:`load_patterns` are added.
    source : str
        Where the dish came from (stored in the file).
    """
    body = clamped_modes(dish.fe, dish.hub, modes, loads=load_patterns(dish))
    surface = Surface(np.asarray(dish.surface, dtype=np.int64), dish.weights, dish.focal_length)
    return ModalArrays(
        body.nodes, body.masses, body.shapes, body.stiffness, np.zeros_like(body.stiffness),
        source, body.edges, surface=surface,
    )  # fmt: skip


def rigid_properties(nodes: np.ndarray, masses: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """``(m, c, I_c)`` of point masses: total, centre and inertia about the centre.

    Parameters
    ----------
    nodes : numpy.ndarray, shape (N, 3)
        Positions, m.
    masses : numpy.ndarray, shape (N,)
        Masses, kg.
    """
    m = math.fsum(masses)  # exactly rounded sums: the same digits on any CPU
    c = np.array([math.fsum(masses * nodes[:, i]) for i in range(3)]) / m
    r = nodes - c
    r2 = r[:, 0] * r[:, 0] + r[:, 1] * r[:, 1] + r[:, 2] * r[:, 2]
    inertia = np.array(
        [[math.fsum(masses * ((r2 if i == j else 0.0) - r[:, i] * r[:, j])) for j in range(3)]
         for i in range(3)]
    )  # fmt: skip
    return m, c, inertia


def _shifted(inertia: np.ndarray, mass: float, offset: np.ndarray) -> np.ndarray:
    """Inertia about a point ``offset`` from the centre of mass (parallel axes)."""
    square = math.fsum(offset * offset)
    return inertia + mass * (square * np.eye(3) - np.outer(offset, offset))


def _rest_mass(link: tuple, dish: tuple, name: str) -> tuple[float, np.ndarray]:
    """``(m, c)`` the link keeps beside the dish: the mass left and where the total stays."""
    (m, c, _), (md, cd, _) = link, dish
    mh = m - md
    if not mh > 0.0:
        raise Rt70Error(f"link '{name}': the dish's {md:.6g} kg is not less than its {m:.6g} kg")
    return mh, (m * c - md * cd) / mh


def residual_properties(
    link: tuple[float, np.ndarray, np.ndarray],
    dish: tuple[float, np.ndarray, np.ndarray],
    name: str,
) -> tuple[float, np.ndarray, np.ndarray]:
    """The link's mass properties less the dish's: ``(m, c, I_c)`` of what the link keeps.

    Parameters
    ----------
    link, dish : (float, numpy.ndarray, numpy.ndarray)
        ``(m, c, I_c)`` of the rigid link and of the dish, in the link's frame.
    name : str
        The link's name (for the message).

    Raises
    ------
    Rt70Error
        If what is left is not a body: a mass ≤ 0, or an inertia that is not positive
        definite or breaks the triangle inequality (the dish is heavier, or spread wider,
        than the link it replaces).
    """
    (m, c, inertia), (md, cd, Id) = link, dish
    mh, ch = _rest_mass(link, dish, name)
    about_origin = _shifted(inertia, m, c) - _shifted(Id, md, cd)
    Ih = about_origin - _shifted(np.zeros((3, 3)), mh, ch)
    moments = np.linalg.eigvalsh(0.5 * (Ih + Ih.T))
    slack = TRIANGLE_RTOL * moments.sum()
    if moments[0] <= 0.0 or moments[0] + moments[1] < moments[2] - slack:
        raise Rt70Error(
            f"link '{name}': its inertia less the dish's has principal moments "
            f"{', '.join(f'{x:.4g}' for x in moments)} kg·m², not a body's: the dish is "
            "too heavy or too wide for the link (lighten its members or panels)"
        )
    return mh, ch, 0.5 * (Ih + Ih.T)


def with_flexible_reflector(
    text: str, link: str, vertex: np.ndarray, body: ModalArrays, name: str, file: str,
    damping_ratio: float, wind: str | None = None, hub_radius: float | None = None,
) -> str:  # fmt: skip
    """The URDF ``text`` with the dish ``body`` on ``link``, the link's totals kept.

    Parameters
    ----------
    text : str
        The scene's URDF text.
    link : str
        The rigid reflector link (its z the paraboloid's axis).
    vertex : numpy.ndarray, shape (3,)
        The paraboloid's vertex in the link's frame, m.
    body : rt70.urdf.modal_file.ModalArrays
        The dish (:func:`dish_body`), nodes in the paraboloid's frame.
    name : str
        The modal body's name; its frame link is ``<name>_link``.
    file : str
        The modal body file's name, beside the URDF file.
    damping_ratio : float
        Every mode's ratio of critical damping.
    wind : str, optional
        The ``<rt70:wind>`` of the reflector, to be spread over the dish's surface
        (its ``surface`` attribute set to ``name``).
    hub_radius : float, optional
        When the link's inertia is an idealisation the dish replaces (a uniform disk):
        the link keeps the rest of the mass, at the centre that keeps the total centre of
        mass, as a solid sphere of this radius (m); the total inertia is then the dish's
        and the sphere's. By default the link keeps its inertia less the dish's.

    Raises
    ------
    Rt70Error
        If ``link`` has no inertial or cannot give up the dish's mass
        (:func:`residual_properties`).
    """
    ET.register_namespace("rt70", RT70_NAMESPACE)
    root = ET.fromstring(text, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    found = [e for e in root.findall("link") if e.get("name") == link]
    inertial = found[0].find("inertial") if found else None
    if inertial is None:
        raise Rt70Error(f"no link '{link}' with an <inertial> in the scene")
    read = read_urdf_string(text, f"<{link}>").links[link].inertial  # the reader's numbers
    m = read.mass
    vertex = np.round(np.asarray(vertex, dtype=float), 9) + 0.0  # nm: the same on any CPU
    dish = rigid_properties(body.nodes + vertex, body.masses)
    length = float(np.max(np.abs(body.nodes)))
    mh = _keep_the_rest(inertial, link, (m, read.com, read.inertia), dish, hub_radius, length)
    if wind is not None:
        found_wind = [e for e in root.iter(f"{{{RT70_NAMESPACE}}}wind") if e.get("name") == wind]
        if not found_wind:
            raise Rt70Error(f"no <rt70:wind name='{wind}'> in the scene")
        found_wind[0].set("surface", name)
    ET.indent(root, space="  ")
    body_text = "\n".join(
        [
            f"  <!-- {name}: a flexible dish on '{link}' (rt70.scenes.reflector_scenes); "
            f"'{link}' keeps {mh:.6g} kg of the {m:.6g} kg -->",
            f'  <link name="{name}_link"/>',
            f'  <joint name="{name}_weld" type="fixed"><parent link="{link}"/>'
            f'<child link="{name}_link"/><origin xyz="{uw.fmt_vec(vertex)}" '
            'rpy="0 0 0"/></joint>',
            f'  <rt70:modal_body name="{name}" link="{name}_link" file="{file}" '
            f'damping_ratio="{uw.fmt(damping_ratio)}"/>',
        ]
    )
    out = text[: text.index("<robot")] + ET.tostring(root, encoding="unicode")
    return out.replace("</robot>", body_text + "\n</robot>\n")


def _keep_the_rest(
    inertial: ET.Element,
    link: str,
    properties: tuple[float, np.ndarray, np.ndarray],
    dish: tuple,
    hub_radius: float | None,
    length: float,
) -> float:
    """Set the link's ``<inertial>`` to what it keeps of its body beside the dish; its mass.

    The link's mass properties ``(m, c, I_c)`` (as the URDF reader gives them) less the
    dish's (:func:`residual_properties`), or, with ``hub_radius``, the rest of the mass as
    a solid sphere at the centre that keeps the total centre
    (:func:`with_flexible_reflector`); written to :data:`WRITTEN_DIGITS`.
    """
    origin = inertial.find("origin")
    if origin is not None and any(float(v) for v in origin.get("rpy", "0 0 0").split()):
        raise Rt70Error(f"link '{link}': an inertial with rpy is not supported here")
    if hub_radius is None:
        mh, ch, Ih = residual_properties(properties, dish, link)
    else:
        mh, ch = _rest_mass(properties, dish, link)
        Ih = 0.4 * mh * hub_radius**2 * np.eye(3)
    mh, ch, Ih = _written(mh, ch, Ih, length)
    inertial.find("mass").set("value", uw.fmt(mh))
    if origin is None:
        origin = ET.SubElement(inertial, "origin")
    origin.set("xyz", uw.fmt_vec(ch))
    origin.set("rpy", "0 0 0")
    for key, (i, j) in {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2),
                        "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}.items():  # fmt: skip
        inertial.find("inertia").set(key, uw.fmt(Ih[i, j]))
    return mh


#: Digits kept of the link's derived mass properties, relative to their scale: the sums
#: behind them round differently on another CPU in the last bits, and a scene file must
#: come out the same everywhere (tests/test_scenes_generated.py); 12 digits keep the
#: totals to 1e-12.
WRITTEN_DIGITS = 12


def _written(
    mass: float, centre: np.ndarray, inertia: np.ndarray, length: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """The mass properties as written: :data:`WRITTEN_DIGITS` digits of their scales."""
    scale = float(np.trace(inertia))
    return (
        float(f"{mass:.{WRITTEN_DIGITS}g}"),
        np.round(centre / length, WRITTEN_DIGITS) * length + 0.0,
        np.round(inertia / scale, WRITTEN_DIGITS) * scale + 0.0,
    )
