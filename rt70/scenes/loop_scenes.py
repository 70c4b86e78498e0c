"""The closed-chain test mechanisms (docs/loops.md): four-bar, crank–slider.

Both are planar in the x-y plane, every revolute joint about z, links as uniform rods
(``I_c = m L²/12`` about y and z, a small axial moment about x). The four-bar hangs in a
vertical plane (gravity along −y); the crank–slider lies on a horizontal table (gravity
along −z, normal to its plane, carried by the joints and doing no work), so that its
crank, started at 10 rad/s, keeps turning — in a vertical plane the rod's weight would
stop it and swing it back. Each is a tree plus one ``<rt70:loop type="point">``: three
rows, of which two are independent (the z row is identically zero in a planar
mechanism — rt70.physics.kkt and Pinocchio's proximal solver take the dependent row). The
scenes are written by :mod:`rt70.scenes.generate` like every other scene.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.scenes import urdf_writer as uw
from rt70.scenes.urdf_writer import ROOT_LINK, ZERO3, check_name, fmt_vec

#: Axial moment of inertia of every rod, kg·m² (thin rods; it only has to be positive).
ROD_AXIAL = 1e-4

#: Four-bar linkage (our data): ground link d between the pivots, crank a, coupler b,
#: rocker c. Grashof crank–rocker: a + b = 0.7 ≤ c + d = 0.85 with a the shortest.
FOUR_BAR = {
    "ground": 0.4,
    "links": (  # name, joint, length m, mass kg
        ("crank", "crank_joint", 0.2, 1.0),
        ("coupler", "coupler_joint", 0.5, 2.0),
        ("rocker", "rocker_joint", 0.45, 1.5),
    ),
    "gravity": (0.0, -9.81, 0.0),
}

#: Crank–slider of the companion sources: crank 0.1 m, rod 0.4 m; masses 1, 2, 0.5 kg.
CRANK_SLIDER = {
    "crank": (0.1, 1.0),
    "rod": (0.4, 2.0),
    "slider": 0.5,
    "slider_size": 0.05,  # cube edge, m (its inertia only)
    "gravity": (0.0, 0.0, -9.81),  # normal to the plane: carried by the joints, no work
    "crank_speed": 10.0,  # rad/s, the initial crank speed of the spec
}


def loop(
    w: uw.Writer,
    name: str,
    link1: str,
    link2: str,
    xyz1: Sequence[float] = ZERO3,
    xyz2: Sequence[float] = ZERO3,
    kind: str = "point",
) -> None:
    """Write an ``<rt70:loop>``: the origins (point) or frames (frame) of two links coincide.

    Parameters
    ----------
    w : Writer
        The scene being written.
    name : str
        Name of the loop.
    link1, link2 : str
        Links of the two frames (``link2`` may be ``world``, the ground).
    xyz1, xyz2 : sequence of float, optional
        Origins of the two frames in their links, m (rpy zero).
    kind : {"point", "frame"}, optional
        ``point``: the origins coincide (3 rows); ``frame``: the frames coincide (6 rows).
    """
    w.open("rt70:loop", ("name", check_name(name)), ("type", kind))
    w.empty("rt70:frame1", ("link", check_name(link1)), ("xyz", fmt_vec(xyz1)), ("rpy", "0 0 0"))
    w.empty("rt70:frame2", ("link", check_name(link2)), ("xyz", fmt_vec(xyz2)), ("rpy", "0 0 0"))
    w.close("rt70:loop")


def _rod(w: uw.Writer, name: str, length: float, mass: float) -> None:
    i_c = mass * length**2 / 12.0
    uw.massive_link(w, name, mass, (ROD_AXIAL, i_c, i_c), com=(length / 2.0, 0.0, 0.0))


def four_bar_scene() -> str:
    """Planar four-bar: crank and rocker pivoted on the ground.

    The coupler's end closes the loop on the rocker's end (``<rt70:loop>``).
    """
    d = FOUR_BAR
    (crank, cj, a, ma), (coupler, kj, b, mb), (rocker, rj, c, mc) = d["links"]
    w = uw.Writer()
    uw.begin(
        w,
        "four_bar",
        f"Planar four-bar (crank {a} m, coupler {b} m, rocker {c} m, ground {d['ground']} m) "
        "in the x-y plane, gravity along -y; closed by <rt70:loop>",
    )
    uw.joint(w, cj, "revolute", ROOT_LINK, crank)
    _rod(w, crank, a, ma)
    uw.joint(w, kj, "revolute", crank, coupler, xyz=(a, 0.0, 0.0))
    _rod(w, coupler, b, mb)
    uw.joint(w, rj, "revolute", ROOT_LINK, rocker, xyz=(d["ground"], 0.0, 0.0))
    _rod(w, rocker, c, mc)
    w.blank()
    uw.gravity(w, d["gravity"])
    loop(w, "coupler_rocker", coupler, rocker, xyz1=(b, 0.0, 0.0), xyz2=(c, 0.0, 0.0))
    return uw.end(w)


def crank_slider_scene() -> str:
    """Crank–slider: crank and rod in series, the slider on a prismatic joint along x.

    The rod's end closes the loop on the slider's origin (``<rt70:loop>``).
    """
    d = CRANK_SLIDER
    (a, ma), (b, mb), ms, s = d["crank"], d["rod"], d["slider"], d["slider_size"]
    w = uw.Writer()
    uw.begin(
        w,
        "crank_slider",
        f"Crank-slider (crank {a} m {ma} kg, rod {b} m {mb} kg, slider {ms} kg) in the x-y "
        "plane, slider along x, gravity along -z (normal to the plane); closed by <rt70:loop>",
    )
    uw.joint(w, "crank_joint", "revolute", ROOT_LINK, "crank")
    _rod(w, "crank", a, ma)
    uw.joint(w, "rod_joint", "revolute", "crank", "rod", xyz=(a, 0.0, 0.0))
    _rod(w, "rod", b, mb)
    uw.joint(w, "slide", "prismatic", ROOT_LINK, "slider", axis=(1, 0, 0))
    i_s = ms * s**2 / 6.0
    uw.massive_link(w, "slider", ms, (i_s, i_s, i_s))
    w.blank()
    uw.gravity(w, d["gravity"])
    loop(w, "rod_slider", "rod", "slider", xyz1=(b, 0.0, 0.0))
    return uw.end(w)


#: Guesses ``rt70 simulate`` closes (:func:`start_state`): q, q̇ and the kept coordinates.
STARTS = {
    "crank_slider": ((0.0, 0.0, 0.5), (CRANK_SLIDER["crank_speed"], 0.0, 0.0), ("crank_joint",)),
    "four_bar": ((np.pi / 2, -1.0, 1.5), (0.0, 0.0, 0.0), ("crank_joint",)),
}


def start_state(scene) -> tuple[np.ndarray, np.ndarray] | None:
    """The closed start of a mechanism of this module (crank at 10 rad/s), else None.

    The crank–slider starts at crank angle 0 turning at 10 rad/s, the four-bar at rest
    with the crank vertical; both closed by :func:`rt70.simulation.closed_chains.assemble` keeping
    the crank.
    """
    from rt70.simulation.closed_chains import assemble

    guess = STARTS.get(scene.name)
    if guess is None or not scene.description.loops:
        return None
    q, qd, keep = guess
    if len(q) != scene.textbook.nv:
        return None
    return assemble(scene, np.array(q), np.array(qd), keep=keep)
