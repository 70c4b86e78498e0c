"""Mode shapes on the structure: where every link goes when a mode moves the scene.

One job: turn a mode (a vector over the linear model's coordinates) into the positions
of the structure's link frames, so a mode can be drawn on the structure as structural
engineers look at it (:mod:`rt70.plotting.structure`, ``rt70 modes SCENE --plot FILE``).

The structure is drawn as its tree: one line per joint, from the parent link's frame to
the child link's (a beam's rigid elements form its centreline), and each modal body as
its nodes joined by the edges of its file, moved by its modes. A mode ``v`` moves the
scene to ``q0 + a sin(φ) v`` (coordinates the linear model locked stay at ``q0``); the
positions are the side's forward kinematics there (:func:`rt70.textbook.points.
point_positions`), not a linear extrapolation, so large drawn amplitudes stay rigid where
the structure is. The amplitude ``a`` makes the largest drawn link displacement a given
fraction of the structure's size (the diagonal of its bounding box).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rt70.model.scene import Scene
from rt70.textbook import points

#: Largest drawn displacement of a link, as a fraction of the structure's size.
DRAWN_FRACTION = 0.08
#: Step of the finite difference that estimates a mode's link displacements, per unit mode.
_PROBE = 1e-6
#: How close the drawn largest displacement comes to its target (relative).
DRAWN_RTOL = 1e-6
#: Most corrections of the drawn amplitude on the nonlinear kinematics.
_MAX_CORRECTIONS = 50


@dataclass(frozen=True)
class StructureLines:
    """The structure as line segments between points of its links.

    Attributes
    ----------
    points : list of (str, numpy.ndarray)
        The points drawn: each link's frame origin, then each massive link's centre of
        mass off its origin (link, point in the link's frame in m).
    segments : numpy.ndarray, shape (n, 2)
        Index pairs into :attr:`points`: each link's frame joined to its parent's, and to
        its centre of mass; a modal body's edges between its nodes.
    nodes : list of (int, int, int)
        The points that are nodes of modal bodies: the point's index, the body's (in the
        description's ``modal_bodies``) and the node's; they move by their mode shapes.
    """

    points: list[tuple[str, np.ndarray]]
    segments: np.ndarray
    nodes: list[tuple[int, int, int]] = field(default_factory=list)


@dataclass(frozen=True)
class DrawnMode:
    """One mode as positions of the link frames over a cycle.

    Attributes
    ----------
    label : str
        ``mode k, f Hz``.
    amplitude : float
        ``a``: the mode's multiple drawn at ``sin φ = 1`` (its coordinates' units).
    peak : float
        The largest link displacement drawn, m (the drawing is not to scale).
    positions : numpy.ndarray, shape (n_phases, n_points, 3)
        Link frame positions at the phases, m (ground axes).
    phases : numpy.ndarray, shape (n_phases,)
        φ, rad.
    """

    label: str
    amplitude: float
    peak: float
    positions: np.ndarray
    phases: np.ndarray


def structure_lines(scene: Scene) -> StructureLines:
    """The scene's link frames and centres of mass, joined along the tree.

    A link the textbook model merged into a pair's end link (the massless links inside a
    six-coordinate pair) is not drawn; its child is joined to the link above it.
    """
    known = scene.textbook.link_frames
    links = [name for name in scene.description.links if name in known]
    index = {name: i for i, name in enumerate(links)}
    parent = {j.child: j.parent for j in scene.description.joints}
    where = [(name, np.zeros(3)) for name in links]
    segments = []
    for name in links:
        above = parent.get(name)
        while above is not None and above not in index:
            above = parent.get(above)
        if above is not None:
            segments.append((index[above], index[name]))
        inertial = scene.description.links[name].inertial
        if inertial is not None and inertial.mass > 0.0 and np.any(inertial.com != 0.0):
            segments.append((index[name], len(where)))
            where.append((name, np.asarray(inertial.com, dtype=float)))
    nodes = []
    for b, body in enumerate(scene.description.modal_bodies):
        first = len(where)
        for n, x in enumerate(body.nodes):
            nodes.append((len(where), b, n))
            where.append((body.link, np.asarray(x, dtype=float)))
        segments.extend((first + int(i), first + int(j)) for i, j in body.edges)
    return StructureLines(where, np.array(segments, dtype=int).reshape(-1, 2), nodes)


def link_positions(scene: Scene, q: np.ndarray, lines: StructureLines) -> np.ndarray:
    """Ground-axis positions (n, 3) of the points of ``lines`` at q, m (textbook side).

    A modal body's node is at ``x_n + Φ_n η`` in its link's frame.

    Parameters
    ----------
    scene : Scene
        The scene.
    q : numpy.ndarray, shape (nv,)
        The state, in the scene's coordinates (rad or m).
    lines : StructureLines
        The points: a link and the point in its frame, m (and which are modal nodes).
    """
    model, data = scene.textbook, scene.textbook_data
    positions = points.point_positions(model, data, q, lines.points)
    for i, b, n in lines.nodes:  # the forward pass above left the links' orientations
        body = scene.description.modal_bodies[b]
        mb = model.modal[b]
        pair, _, c = model.link_frames[body.link]
        rotation = c if pair < 0 else data.R[pair] @ c
        positions[i] += rotation @ (body.shapes[n] @ q[mb.coords])
    return positions


def draw_modes(
    scene: Scene,
    q0: np.ndarray,
    coordinates: list[str],
    shapes: np.ndarray,
    labels: list[str],
    phases: np.ndarray,
    fraction: float = DRAWN_FRACTION,
) -> tuple[StructureLines, np.ndarray, list[DrawnMode]]:
    """The structure at rest and each mode moving it over ``phases``.

    Parameters
    ----------
    scene : Scene
        The scene the modes are of.
    q0 : numpy.ndarray, shape (nv,)
        The state linearised about, in the scene's coordinates (rad or m).
    coordinates : list of str
        The linear model's coordinates (rows of ``shapes``); those the scene does not
        have (a motor's angle) move no link and are left out.
    shapes : numpy.ndarray, shape (len(coordinates), n_modes)
        The modes, one per column.
    labels : list of str
        One label per mode.
    phases : numpy.ndarray
        The phases φ drawn, rad.
    fraction : float
        The largest link displacement drawn, as a fraction of the structure's size.

    Returns
    -------
    lines : StructureLines
        The links and the segments between them.
    rest : numpy.ndarray, shape (n_points, 3)
        The link positions at ``q0``, m.
    modes : list of DrawnMode
        One per column of ``shapes``.
    """
    lines = structure_lines(scene)
    rest = link_positions(scene, q0, lines)
    size = float(np.linalg.norm(np.ptp(rest, axis=0))) or 1.0
    where = {name: i for i, name in enumerate(scene.coordinate_names)}
    rows = [k for k, name in enumerate(coordinates) if name in where]
    columns = [where[coordinates[k]] for k in rows]
    drawn = []
    for v, label in zip(shapes.T, labels, strict=True):
        full = np.zeros(len(q0))
        full[columns] = v[rows]
        amplitude = _amplitude(scene, q0, full, lines, rest, fraction * size)
        positions = np.array(
            [link_positions(scene, q0 + amplitude * np.sin(p) * full, lines) for p in phases]
        )
        peak = float(np.linalg.norm(positions - rest, axis=2).max())
        drawn.append(DrawnMode(label, amplitude, peak, positions, np.asarray(phases, dtype=float)))
    return lines, rest, drawn


def _amplitude(
    scene: Scene,
    q0: np.ndarray,
    full: np.ndarray,
    lines: StructureLines,
    rest: np.ndarray,
    target: float,
) -> float:
    """The multiple ``a`` of ``full`` whose largest link displacement is ``target``, m.

    First from the linear estimate (a finite difference of the positions), then scaled by
    target / drawn on the kinematics themselves until within :data:`DRAWN_RTOL` (the
    drawn displacement grows monotonically with ``a`` at drawing amplitudes).
    """
    probe = _PROBE / max(float(np.abs(full).max()), 1e-300)
    moved = link_positions(scene, q0 + probe * full, lines) - rest
    per_unit = float(np.linalg.norm(moved, axis=1).max()) / probe
    if per_unit <= 0.0:
        return 0.0
    amplitude = target / per_unit
    for _ in range(_MAX_CORRECTIONS):
        drawn = link_positions(scene, q0 + amplitude * full, lines) - rest
        peak = float(np.linalg.norm(drawn, axis=1).max())
        if peak <= 0.0 or abs(peak / target - 1.0) <= DRAWN_RTOL:
            break
        amplitude *= target / peak
    return amplitude
