"""A paraboloidal reflector's backup structure as a space truss: size a dish before its FE model.

One job: the FE model (rt70's neutral form, :class:`rt70.fe.neutral.FEModel`) of a
parametric dish, for a user who has a diameter, a focal length and member sizes but no
FE model yet (docs/surface.md). The dish is the classic radial-rib backup
structure of large antennas: ``ribs`` radial trusses joined by ``rings`` hoops.

- **Front layer**: nodes on the paraboloid ``z = r²/(4F)`` at the radii
  ``r_k = r_hub + k (D/2 − r_hub) / rings`` (k = 0 … rings) and the angles
  ``2π j / ribs``. They carry the panels and are the surface nodes of the best fit
  (:mod:`rt70.surface.best_fit`).
- **Back layer**: the same (x, y), ``depth`` below (z − depth).
- **Bars**: radial chords and hoops in both layers, a diagonal across each front and each
  back panel, verticals, and the web diagonals front (k, j) to back (k+1, j) and to back
  (k, j+1). This makes a stable truss: free, it has six rigid-body modes and no mechanism
  (tested).
- **Mass**: each bar's mass lumped half to each end (:func:`rt70.fe.truss.assemble`),
  plus the panels, ``panel_mass`` (kg/m²) times the aperture area each front node stands
  for.
- **Weights**: the aperture areas, annuli between the radii's midpoints divided among
  the ribs. They are the weights of the best fit, and they sum to
  ``π (D²/4 − r_hub²)``.

The hub ring (k = 0, both layers) is where the dish is attached to its elevation
structure: its nodes are the interface nodes (``hub_1`` …), clamped in
:func:`rt70.fe.modal_body.clamped_modes`. Every member has the same EA and ρA here; a
real design sizes them member by member, and its FE model comes in through the neutral
file or Nastran (docs/fe-models.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rt70.errors import Rt70Error
from rt70.fe.neutral import FEModel
from rt70.fe.truss import assemble


@dataclass(frozen=True)
class Dish:
    """A parametric dish: its FE model and what the surface analysis needs of it.

    Attributes
    ----------
    fe : FEModel
        The truss, three translations per node; interface nodes ``hub_1`` … (the hub ring).
    surface : numpy.ndarray of int, shape (S,)
        Indices (into ``fe.node_xyz``) of the front-layer nodes, on the paraboloid.
    weights : numpy.ndarray, shape (S,)
        Each surface node's share of the aperture, m².
    focal_length : float
        F, m.
    hub : list of int
        Node numbers of the hub ring, front and back (where the dish is clamped).
    """

    fe: FEModel
    surface: np.ndarray
    weights: np.ndarray
    focal_length: float
    hub: list[int]


def paraboloid_dish(
    diameter: float,
    focal_length: float,
    hub_radius: float,
    depth: float,
    EA: float,
    rho_A: float,
    panel_mass: float,
    rings: int = 6,
    ribs: int = 24,
) -> Dish:
    """The radial-rib dish of the module docstring.

    Parameters
    ----------
    diameter, focal_length : float
        D and F of the paraboloid, m.
    hub_radius : float
        Radius of the hub ring where the dish is attached, m (0 < r_hub < D/2).
    depth : float
        Depth of the backup structure (front to back layer), m.
    EA, rho_A : float
        Every bar's axial stiffness, N, and mass per length, kg/m.
    panel_mass : float
        The panels' mass per aperture area, kg/m² (≥ 0).
    rings, ribs : int
        Hoops outside the hub ring (≥ 1) and radial ribs (≥ 3).

    Raises
    ------
    Rt70Error
        A size that is not positive (or, for the panels, negative), a hub outside the
        dish, fewer than one ring or three ribs.
    """
    R = 0.5 * diameter
    for name, value in (("diameter", diameter), ("focal_length", focal_length),
                        ("depth", depth), ("EA", EA), ("rho_A", rho_A)):  # fmt: skip
        if not (np.isfinite(value) and value > 0.0):
            raise Rt70Error(f"dish: {name} must be a positive number, got {value}")
    if not (np.isfinite(panel_mass) and panel_mass >= 0.0):
        raise Rt70Error(f"dish: panel_mass must be ≥ 0 kg/m², got {panel_mass}")
    if not 0.0 < hub_radius < R:
        raise Rt70Error(f"dish: hub_radius must be between 0 and D/2 = {R:g} m, got {hub_radius}")
    if rings < 1 or ribs < 3:
        raise Rt70Error(f"dish: at least 1 ring and 3 ribs, got {rings} and {ribs}")
    radii = np.linspace(hub_radius, R, rings + 1)
    angles = 2.0 * np.pi * np.arange(ribs) / ribs
    r, a = np.meshgrid(radii, angles, indexing="ij")  # (rings + 1, ribs)
    x, y = (r * np.cos(a)).ravel(), (r * np.sin(a)).ravel()
    front = np.column_stack([x, y, (x**2 + y**2) / (4.0 * focal_length)])
    xyz = np.vstack([front, front - [0.0, 0.0, depth]])
    bars = _bars(rings, ribs)
    M, K = assemble(xyz, bars, EA, rho_A)
    edges = np.concatenate([[hub_radius], 0.5 * (radii[:-1] + radii[1:]), [R]])
    annulus = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2) / ribs  # per node of each ring
    weights = np.repeat(annulus, ribs)
    panels = np.zeros(xyz.shape[0])
    panels[: front.shape[0]] = panel_mass * weights
    M = sp.csr_array(M + sp.diags_array(np.repeat(panels, 3)))  # the panels on the front
    ids = np.arange(1, xyz.shape[0] + 1)
    n_front = front.shape[0]
    hub = [int(i) for i in ids[:ribs]] + [int(i) for i in ids[n_front : n_front + ribs]]
    fe = FEModel(
        M,
        K,
        ids,
        xyz,
        np.repeat(ids, 3),
        np.tile(np.arange(1, 4), xyz.shape[0]),
        {f"hub_{k + 1}": node for k, node in enumerate(hub)},
        name=f"paraboloid dish D {diameter:g} m, F {focal_length:g} m, {rings} rings × {ribs} ribs",
    )
    return Dish(fe, np.arange(n_front), weights, float(focal_length), hub)


def _bars(rings: int, ribs: int) -> np.ndarray:
    """The bars (node index pairs) of the dish's truss (module docstring)."""
    k, j = np.meshgrid(np.arange(rings + 1), np.arange(ribs), indexing="ij")
    front = k * ribs + j
    back = front + (rings + 1) * ribs
    nxt = k * ribs + (j + 1) % ribs  # the next rib's node on the same ring
    out = []
    for layer in (0, (rings + 1) * ribs):
        out.append(np.column_stack([front[:-1].ravel(), front[1:].ravel()]) + layer)  # radial
        out.append(np.column_stack([front.ravel(), nxt.ravel()]) + layer)  # hoops
        out.append(np.column_stack([front[:-1].ravel(), nxt[1:].ravel()]) + layer)  # panels
    out.append(np.column_stack([front.ravel(), back.ravel()]))  # verticals
    out.append(np.column_stack([front[:-1].ravel(), back[1:].ravel()]))  # radial web
    out.append(np.column_stack([front.ravel(), (nxt + (rings + 1) * ribs).ravel()]))  # hoop web
    return np.vstack(out)
