"""Outputs of a deformable reflector: its best-fit paraboloid and surface error (book §4.1.8).

One job: the :class:`~rt70.model.outputs.Output` s of a modal body's reflecting surface
(docs/surface.md). Their points are the body frame (its link's origin and unit offsets)
and the surface nodes (``"<body>/node<n>"``, :func:`rt70.urdf.modal_record.node_point`),
so each side places them with its own kinematics; the formulas are the shared
post-processing of :mod:`rt70.surface`:

- each node's displacement in the body frame, ``Δ_n = Rᵀ(p_n − o) − x_n``;
- its half-path-length error ``h_n = H_n · Δ_n``;
- the best fit ``β = P h`` and the residual ``r = R h`` (:func:`rt70.surface.best_fit.fit_maps`).

Every formula is smooth, so :func:`rt70.model.outputs.output_matrix` linearises them
exactly for the plant. The surface RMS and Ruze's efficiency are not outputs (a norm has
no derivative at zero): :func:`surface_summary` computes them from the residual.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.outputs import Output
from rt70.model.scene import Scene
from rt70.surface.best_fit import FitMaps, fit_maps
from rt70.surface.ruze import ruze_efficiency
from rt70.units import ARCSEC_PER_RAD, MM_PER_M
from rt70.urdf.modal_record import ModalBody, node_point

#: Micrometres per metre (the residual's unit).
UM_PER_M = 1e6
#: The body frame's points: its origin and offsets along x, y, z, in units of the
#: aperture's radius (link frame). Its axes are read off their differences, rounded by
#: ε times the points' distance from the ground origin (some 2e-14 m at 90 m), which
#: turns the axes by that over the offsets' length: over the radius it moves a rim node
#: by the same 2e-14 m, where unit offsets moved it by 35 times that on the RT-70
#: (7e-13 m, 1e-9 of a millimetre deformation).
FRAME_POINTS = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
#: Ruze's fit of the beam deviation factor of a paraboloid (IEEE Trans. AP-13:660–665,
#: 1965): ``BDF = (1 + k (D/4F)²) / (1 + (D/4F)²)`` with ``k = 0.36``.
BDF_K = 0.36


@dataclass(frozen=True)
class ReflectorSurface:
    """A modal body's reflecting surface and the linear maps of its best fit.

    Attributes
    ----------
    body : rt70.urdf.modal_record.ModalBody
        The modal body.
    nodes : numpy.ndarray, shape (S,)
        The surface nodes' indices in the body's file.
    xyz : numpy.ndarray, shape (S, 3)
        Their nominal positions in the body frame, m (on the paraboloid).
    focal_length : float
        F, m.
    maps : rt70.surface.best_fit.FitMaps
        ``A, P, R, H`` and the normalised weights.
    """

    body: ModalBody
    nodes: np.ndarray
    xyz: np.ndarray
    focal_length: float
    maps: FitMaps

    @property
    def diameter(self) -> float:
        """The aperture's diameter: twice the largest radius of a surface node, m."""
        return float(2.0 * np.max(np.hypot(self.xyz[:, 0], self.xyz[:, 1])))

    @property
    def beam_deviation_factor(self) -> float:
        """Ruze's BDF of the paraboloid's F/D (:data:`BDF_K`)."""
        a2 = (self.diameter / (4.0 * self.focal_length)) ** 2
        return (1.0 + BDF_K * a2) / (1.0 + a2)


def has_surface(scene: Scene) -> bool:
    """Whether a modal body of ``scene`` has a reflecting surface (its file declares one).

    Parameters
    ----------
    scene : Scene
        The scene.
    """
    return any(b.surface is not None for b in scene.description.modal_bodies)


def reflector_surface(scene: Scene, body: str | None = None) -> ReflectorSurface:
    """The reflecting surface of the modal body ``body`` (or the scene's only one).

    Parameters
    ----------
    scene : Scene
        The scene.
    body : str, optional
        The ``<rt70:modal_body>``'s name; by default the one body whose file has a surface.

    Raises
    ------
    Rt70Error
        If no body (or several, with ``body`` not given) has a surface, or ``body`` has none.
    """
    bodies = scene.description.modal_bodies
    with_surface = [b for b in bodies if b.surface is not None]
    if body is None:
        if len(with_surface) != 1:
            names = ", ".join(b.name for b in with_surface) or "none"
            raise Rt70Error(
                f"{scene.name}: {len(with_surface)} modal bodies have a reflecting surface "
                f"({names}); exactly one is needed, or name it"
            )
        found = with_surface[0]
    else:
        named = [b for b in bodies if b.name == body]
        if not named or named[0].surface is None:
            raise Rt70Error(
                f"{scene.name}: no modal body '{body}' with a reflecting surface (its file "
                "needs surface_nodes, surface_weights and focal_length, docs/surface.md)"
            )
        found = named[0]
    s = found.surface
    xyz = found.nodes[s.nodes]
    return ReflectorSurface(
        found, s.nodes, xyz, s.focal_length, fit_maps(xyz, s.focal_length, s.weights)
    )


def _path_errors(surface: ReflectorSurface, p: np.ndarray) -> np.ndarray:
    """The half-path errors h of the surface nodes from the stacked frame and node positions."""
    o = p[0]
    length = 0.5 * surface.diameter  # the offsets' length (FRAME_POINTS)
    R = np.column_stack([p[1] - o, p[2] - o, p[3] - o]) / length  # the body frame's axes
    delta = (p[4:] - o) @ R - surface.xyz  # Rᵀ (p_n − o) − x_n, row by row
    return np.sum(surface.maps.H * delta, axis=1)


def surface_outputs(surface: ReflectorSurface, prefix: str | None = None) -> list[Output]:
    """The best fit's parameters, the beam's deviation and the residual as outputs.

    ``<prefix>`` is the body's name by default. All in the body frame's axes:

    ============================ ====== ==== ==============================================
    output                       unit   size meaning
    ============================ ====== ==== ==============================================
    ``<prefix>_vertex_shift``    mm     3    the BFP vertex's translation ``t``
    ``<prefix>_axis_tilt``       arcsec 2    ``(φ_x, φ_y)``: the angular defocus
    ``<prefix>_focal_change``    mm     1    ΔF
    ``<prefix>_focus_shift``     mm     3    the BFP focus's shift: lateral and axial
                                             defocus
    ``<prefix>_beam_deviation``  arcsec 2    the beam's turn about x and y, the feed fixed
                                             to the body frame: ``(1 + BDF) φ`` plus
                                             ``BDF (u, v)/F``, as rotations
    ``<prefix>_residual``        um     S    each node's half-path error left by the BFP
    ============================ ====== ==== ==============================================

    The beam deviation is a prime-focus reading (Ruze 1965's BDF for a feed displaced
    from the BFP's focus): the feed stays at the nominal focus while the surface's BFP
    turns by φ and moves by ``(u, v)``.

    Parameters
    ----------
    surface : ReflectorSurface
        The surface (:func:`reflector_surface`).
    prefix : str, optional
        The outputs' names start with it; the body's name by default.
    """
    b = surface.body
    prefix = b.name if prefix is None else prefix
    length = 0.5 * surface.diameter
    points = tuple((b.link, tuple(length * x for x in xyz)) for xyz in FRAME_POINTS) + tuple(
        (node_point(b.name, int(n)), (0.0, 0.0, 0.0)) for n in surface.nodes
    )
    P, R, F = surface.maps.P, surface.maps.R, surface.focal_length
    bdf = surface.beam_deviation_factor

    def beta(p):
        return P @ _path_errors(surface, p)

    def focus(p):
        u, v, w, phi_x, phi_y, dF = beta(p)
        return MM_PER_M * np.array([u + F * phi_y, v - F * phi_x, w + dF])

    def beam(p):
        u, v, _, phi_x, phi_y, _ = beta(p)
        return ARCSEC_PER_RAD * np.array(
            [(1.0 + bdf) * phi_x - bdf * v / F, (1.0 + bdf) * phi_y + bdf * u / F]
        )

    def residual(p):
        return UM_PER_M * R @ _path_errors(surface, p)

    size = len(surface.nodes)
    return [
        Output(f"{prefix}_vertex_shift", "mm", 3, points, lambda p: MM_PER_M * beta(p)[:3]),
        Output(f"{prefix}_axis_tilt", "arcsec", 2, points, lambda p: ARCSEC_PER_RAD * beta(p)[3:5]),
        Output(f"{prefix}_focal_change", "mm", 1, points, lambda p: MM_PER_M * beta(p)[5:]),
        Output(f"{prefix}_focus_shift", "mm", 3, points, focus),
        Output(f"{prefix}_beam_deviation", "arcsec", 2, points, beam),
        Output(f"{prefix}_residual", "um", size, points, residual),
    ]  # fmt: skip


def surface_rms(surface: ReflectorSurface, residual_um: np.ndarray) -> float:
    """The weighted RMS ``sqrt(Σ w r²/Σ w)`` of a residual (µm, the output's unit), in µm.

    Parameters
    ----------
    surface : ReflectorSurface
        The surface whose weights apply.
    residual_um : numpy.ndarray, shape (S,) or (n_t, S)
        The ``<prefix>_residual`` output, µm; one RMS per row of a trajectory.
    """
    r = np.asarray(residual_um, dtype=float)
    if r.shape[-1] != len(surface.nodes) or not np.all(np.isfinite(r)):
        raise Rt70Error(
            f"the residual must be finite with {len(surface.nodes)} entries per row, got {r.shape}"
        )
    return np.sqrt(r**2 @ surface.maps.weights)


def surface_summary(
    surface: ReflectorSurface, residual_um: np.ndarray, frequencies_hz: list[float]
) -> dict[str, float]:
    """The surface RMS (µm) and Ruze's efficiency at each frequency, by name.

    Parameters
    ----------
    surface : ReflectorSurface
        The surface whose weights apply.
    residual_um : numpy.ndarray, shape (S,)
        The ``<prefix>_residual`` output, µm.
    frequencies_hz : list of float
        The frequencies, Hz.
    """
    rms = float(surface_rms(surface, residual_um))
    out = {"surface_rms_um": rms}
    for f in frequencies_hz:
        out[f"ruze_{f / 1e9:g}GHz"] = ruze_efficiency(rms / UM_PER_M, f)
    return out
