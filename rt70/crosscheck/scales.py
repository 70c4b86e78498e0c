"""The natural scale of every compared quantity: the size of the terms it is computed from.

A quantity that nearly cancels (the velocity-product force of joints that barely
couple, the gravity torque of a wheel whose centre of mass is on its axis, the
accelerations of a balanced robot) carries the rounding error of its terms, about ε
times their size, so its error relative to its own tiny value means nothing.
:func:`rt70.crosscheck.validate.cross_check` therefore measures each quantity against
``max(own max-norm, FLOOR · scale)`` (:data:`rt70.crosscheck.validate.FLOOR`); with a
tolerance of 10⁻¹⁰ any error above 10⁻¹⁴ of the scale (about 45 ε) — anything beyond
rounding — still fails. Each scale is the size of that quantity's own terms (max-norms,
Pinocchio's values), so a huge spring force does not excuse an error of gravity:

- mass matrix: ``‖A‖`` (positive definite, nothing cancels);
- bias ``B q̇``: ``‖A‖ ‖q̇‖² + ‖B q̇‖``, the size of the velocity products;
- gravity: ``G₀ + ‖Q_g‖`` with ``G₀ = Σ_b m_b |g| |c_b|``, the moment of the
  weights about the ground origin (``c_b`` the bodies' centres of mass): gravity
  torques are differences of such moments;
- springs, dampers: ``‖Σ_e |J_e|ᵀ |C_e δ_e|‖`` and ``‖Σ_e |J_e|ᵀ |D_e δ̇_e|‖``, the
  elements' forces before they cancel (:func:`rt70.reference.spring_damper_magnitudes`);
- q̈, per coordinate: ``|A⁻¹| (f + |A| |q̈|)`` with ``f_i`` the sum of the force
  scales above for coordinate i (``‖A_i‖₁ ‖q̇‖² + |B q̇|_i + G₀ + |Q_g|_i`` and the
  springs' and dampers' terms): the first-order bound of how far a rounding of the
  forces and of A moves q̈ = A⁻¹ Q (Higham §7.1), coordinate by coordinate, so a
  badly scaled A (a mimic factor of 10³⁰, mixed units) excuses no other coordinate;
- kinetic energy: ``‖A‖ ‖q̇‖²``; potential energy: ``G₀ + U_c`` (the terms
  ``m_b g·c_b`` and the spring energy);
- points (:func:`rt70.crosscheck.samples.compared_points`): the largest distance of a
  compared point from the ground origin (a position is a sum of the bodies' offsets);
- load force (the wrench ``f = [F; M]`` of :func:`rt70.crosscheck.samples.state_wrench`):
  ``‖|J_v|ᵀ|F| + |J_ω|ᵀ|M|‖``, the terms of ``Jᵀ f`` before they cancel;
- drives (``[θ_d, Q]`` of the scene's drives and
  :func:`rt70.crosscheck.samples.state_drive`), per entry: the positions θ_d is computed
  from over the mesh radius, and the mesh forces' terms ``|J_v|ᵀ|F|``
  (:func:`_drive_scale`);
- wind: the wind wrenches' terms, as the load force's (:func:`_wind_scale`);
- impact, impulse (q̇⁺ and Λ of a random brake and stow pin): their first-order
  rounding bounds, entry by entry (:func:`rt70.crosscheck.impact_check.impact_scales`);
- reactions: :func:`rt70.crosscheck.reaction_check.reaction_scale`;
- the loop rows of a scene with ``<rt70:loop>``: :func:`rt70.crosscheck.loop_check.loop_scales`;
- the nonholonomic rows: their own max-norm.
"""

from __future__ import annotations

import numpy as np

from rt70.crosscheck.compiled_check import compiled_scales
from rt70.crosscheck.impact_check import impact_scales
from rt70.crosscheck.loop_check import loop_scales
from rt70.crosscheck.reaction_check import reaction_scale
from rt70.crosscheck.samples import WIND, state_drive, state_wind, state_wrench
from rt70.errors import Rt70Error
from rt70.mechanics.nonholonomic_scene import ROWS as NONHOLONOMIC
from rt70.model.scene import Scene

#: Mass matrices whose condition number passes this leave q̈ undetermined in doubles.
MAX_CONDITION = 1e14


def natural_scales(scene: Scene, values: dict, q: np.ndarray, qd: np.ndarray) -> dict:
    """The size of the terms each compared quantity is computed from, at this state.

    The scales of the module docstring, row by row.

    Parameters
    ----------
    scene : Scene
        The scene compared (Pinocchio's side gives the terms).
    values : dict of str to (numpy.ndarray, numpy.ndarray)
        Every row's ``(textbook value, reference value)`` at this state, in the row's
        units; the reference's values are the ones used.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates in the file's order, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities, rad/s or m/s.

    Returns
    -------
    dict
        Per row: a float, or an array with one scale per entry (``forward_dynamics``,
        ``drives``, ``impact``, ``impulse``), in the row's units.

    Raises
    ------
    Rt70Error
        If Pinocchio's mass matrix at this state is numerically singular
        (:func:`_require_determined`).
    """
    from rt70 import reference

    def norm(name: str) -> float:
        x = values[name][1]
        return float(np.max(np.abs(x))) if x.size else 0.0

    A = values["mass_matrix"][1]
    _require_determined(scene, A)
    ref, rd = scene.reference, scene.reference_data
    speed2 = float(np.max(np.abs(qd), initial=0.0)) ** 2
    g0 = reference.weight_moment(ref, rd, q)
    Sc, Sd = reference.spring_damper_magnitudes(ref, rd, q, qd)
    qdd_scale = _acceleration_scale(values, speed2, g0, Sc, Sd)
    return {
        "mass_matrix": norm("mass_matrix"),
        "bias": norm("mass_matrix") * speed2 + norm("bias"),
        "gravity": g0 + norm("gravity"),
        "spring_force": float(np.max(Sc, initial=0.0)),
        "damper_force": float(np.max(Sd, initial=0.0)),
        "forward_dynamics": qdd_scale,
        "kinetic_energy": norm("mass_matrix") * speed2,
        "potential_energy": g0 + reference.spring_potential(ref, rd, q),
        "points": float(np.max(np.linalg.norm(values["points"][1].reshape(-1, 3), axis=1))),
        "load_force": _load_scale(scene, q),
        "drives": _drive_scale(scene, q),
        "reactions": reaction_scale(scene, q, qd, state_wrench(scene, q)),
        **impact_scales(scene, q, qd, {k: values[k][1] for k in ("impact", "impulse")}),
        **({WIND: _wind_scale(scene, q)} if WIND in values else {}),
        **loop_scales(scene, values, q, qd, qdd_scale),
        **{row: norm(row) for row in NONHOLONOMIC if row in values},
        **compiled_scales(values, g0, Sc, Sd),
    }


def _require_determined(scene: Scene, A: np.ndarray) -> None:
    """Refuse a mass matrix that leaves q̈ undetermined in double precision.

    Its Jacobi-scaled form ``D^-½ A D^-½`` (D = diag A, which removes mere differences
    of scale, van der Sluis) must have a condition number below :data:`MAX_CONDITION`
    and positive eigenvalues.
    """
    d = np.sqrt(np.abs(np.diag(A)))
    with np.errstate(divide="ignore", invalid="ignore"):
        eig = np.linalg.eigvalsh(A / np.outer(d, d)) if A.size else np.ones(1)
    if not (np.all(d > 0.0) and eig[0] > 0.0 and eig[-1] <= MAX_CONDITION * eig[0]):
        raise Rt70Error(
            f"{scene.path}: the mass matrix is singular at a sampled state (scaled "
            f"eigenvalues {eig[0]:.3g} … {eig[-1]:.3g}): the forward dynamics is not "
            "determined"
        )


def _acceleration_scale(
    values: dict, speed2: float, g0: float, Sc: np.ndarray, Sd: np.ndarray
) -> np.ndarray:
    """``|A⁻¹| (f + |A| |q̈|)`` per coordinate: the first-order bound of q̈'s rounding.

    ``f_i = ‖A_i‖₁ ‖q̇‖² + |B q̇|_i + G₀ + |Q_g|_i`` plus the springs' and dampers' terms
    ``Sc``, ``Sd`` (Pinocchio's values).
    """
    A = values["mass_matrix"][1]
    Q_b, Q_g = np.abs(values["bias"][1]), np.abs(values["gravity"][1])
    f = np.abs(A).sum(axis=1) * speed2 + Q_b + g0 + Q_g + Sc + Sd
    qdd = np.abs(values["forward_dynamics"][1])
    return np.abs(np.linalg.inv(A)) @ (f + np.abs(A) @ qdd)


def _load_scale(scene: Scene, q: np.ndarray) -> float:
    """``‖|J_v|ᵀ|F| + |J_ω|ᵀ|M|‖`` of the state's load, Pinocchio's Jacobian."""
    from rt70.reference import points as ref_points

    w = state_wrench(scene, q)
    Jv, Jw = ref_points.point_jacobian(scene.reference, scene.reference_data, q, w.link, w.xyz)
    terms = np.abs(Jv).T @ np.abs(w.force) + np.abs(Jw).T @ np.abs(w.torque)
    return float(np.max(terms, initial=0.0))


def _drive_scale(scene: Scene, q: np.ndarray) -> np.ndarray:
    """Per entry of the ``drives`` row (``[θ_d, Q]`` per drive): the size of its terms.

    A gear sector's ``θ_d = atan2(v·d, u·d)`` with ``d = P − centre`` and P the mesh
    point in the stator's axes, ``R_sᵀ (p_l + R_l xyz − p_s)``: a rounding of those
    positions moves θ_d by ε times ``(|p_l| + |xyz| + |p_s| + |centre|) / |d|``. Its
    ``Q = Σ J_vᵀ F`` of the mesh force on the link and its reaction on the stator:
    ``Σ |J_v|ᵀ |F|``, the terms before they cancel — which they do exactly when the
    link and the stator move as one (a mimic joint with multiplier 0 between them, say:
    then θ_d and Q are zero and both sides compute rounding). A torque drive's θ_d and
    Q (the coordinate and a unit vector) are exact on both sides: 0, their own size.
    Pinocchio's poses and Jacobians.
    """
    from rt70.reference import drives as ref_drives
    from rt70.reference import points as ref_points

    ref, rd = scene.reference, scene.reference_data
    scales = []
    for drive in [*scene.description.drives, state_drive(scene, q)]:
        if drive.sector is None:
            scales.append(np.zeros(1 + ref.nv))
            continue
        s = drive.sector
        mesh = ref_drives.sector_mesh(ref, rd, drive)
        link = ref_drives.link_pose(ref, rd, q, s.link)
        stator = ref_drives.link_pose(ref, rd, q, s.stator)
        _, _, P = mesh.angle(s.xyz, link, stator)
        lengths = np.linalg.norm([link[1], s.xyz, stator[1], mesh.centre], axis=1).sum()
        angle = lengths / float(np.linalg.norm(P - mesh.centre))
        terms = np.zeros(ref.nv)
        for w in mesh.wrenches(s.link, s.stator, s.xyz, 1.0, link, stator):
            Jv, _ = ref_points.point_jacobian(ref, rd, q, w.link, w.xyz)
            terms += np.abs(Jv).T @ np.abs(np.asarray(w.force))
        scales.append(np.concatenate([[angle], terms]))
    return np.concatenate(scales)


def _wind_scale(scene: Scene, q: np.ndarray) -> float:
    """``‖Σ_i |J_v,i|ᵀ|F_i| + |J_ω,i|ᵀ|M_i|‖`` of the state's wind, Pinocchio's Jacobians."""
    from rt70.reference import points as ref_points
    from rt70.reference import wind as ref_wind

    ref, rd = scene.reference, scene.reference_data
    terms = np.zeros(ref.nv)
    for w in ref_wind.wind_wrenches(ref, rd, q, state_wind(q)).values():
        Jv, Jw = ref_points.point_jacobian(ref, rd, q, w.link, w.xyz)
        terms += np.abs(Jv).T @ np.abs(w.force) + np.abs(Jw).T @ np.abs(w.torque)
    return float(np.max(terms, initial=0.0))
