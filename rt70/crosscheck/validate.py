"""Cross-check of the textbook algorithm against Pinocchio: error against run time.

For each scene and each of N random states (q, q̇) both sides compute the same
quantities — the dynamics, the positions of the links' origins and of the scene's
optical points (:mod:`rt70.model.outputs`), the generalised force of a random load
(:mod:`rt70.physics.loads`) and the angle and generalised force at unit torque of the
scene's drives (``<rt70:drive>``) and of a random gear sector, and, for a scene with
``<rt70:wind>`` elements, the wind's generalised force under a random steady wind (row
``wind``), and a random brake and stow pin engaging (rows ``impact`` and ``impulse``,
:mod:`rt70.crosscheck.impact_check`); every row of the report gives the largest absolute
error, the largest error relative to the reference's max-norm, and the mean wall time per
evaluation of each side.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass

import numpy as np

from rt70.crosscheck.impact_check import impact_pairs, impact_scales
from rt70.crosscheck.loop_check import loop_pairs, loop_quantities, loop_scales
from rt70.crosscheck.reaction_check import reaction_pair, reaction_scale
from rt70.errors import Rt70Error
from rt70.mechanics.nonholonomic_scene import ROWS as NONHOLONOMIC
from rt70.mechanics.nonholonomic_scene import validate_pairs as nonholonomic_pairs
from rt70.model.outputs import Output, evaluate, optical_point_outputs, position_output
from rt70.model.scene import Scene, require_coordinates
from rt70.physics.aerodynamics import WindCondition
from rt70.physics.loads import Wrench
from rt70.simulation.closure import require_closable
from rt70.textbook import drives as tb_drives
from rt70.textbook import dynamics, forces, points
from rt70.urdf.description import DRIVE_PARAMETERS, Drive, DriveSector

#: Default agreement tolerance, relative to the reference's max-norm.
DEFAULT_TOLERANCE = 1e-10

#: Quantities compared, in report order.
QUANTITIES = (
    "mass_matrix",
    "bias",
    "gravity",
    "spring_force",
    "damper_force",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
    "points",
    "load_force",
    "drives",
    "reactions",
    "impact",
    "impulse",
)

#: Compared after :data:`QUANTITIES` for a scene with ``<rt70:wind>`` elements only.
WIND = "wind"


def quantities(scene: Scene) -> tuple[str, ...]:
    """The rows of ``scene``'s report.

    :data:`QUANTITIES`, :data:`WIND` if it has wind, the loop rows
    (:func:`rt70.crosscheck.loop_check.loop_quantities`) if it has ``<rt70:loop>`` closures, and
    :data:`rt70.mechanics.nonholonomic_scene.ROWS` if it has ``<rt70:no_slip>`` constraints.
    """
    rows = QUANTITIES + ((WIND,) if scene.description.winds else ()) + loop_quantities(scene)
    return rows + (NONHOLONOMIC if scene.description.no_slips else ())


@dataclass(frozen=True)
class Record:
    """One row of the cross-check report.

    ``nonfinite`` names the side(s) on which the quantity was NaN or infinite in some
    sample (empty when every value was finite); such a row has infinite errors and
    never passes.
    """

    target: str
    nv: int
    quantity: str
    max_abs_err: float
    max_rel_err: float
    t_textbook_s: float
    t_reference_s: float
    nonfinite: str = ""

    def passed(self, tolerance: float = DEFAULT_TOLERANCE) -> bool:
        """Whether every value was finite and the relative error is within ``tolerance``."""
        return (
            not self.nonfinite
            and math.isfinite(self.max_rel_err)
            and (self.max_rel_err <= tolerance)
        )

    def as_dict(self) -> dict:
        """The record as a JSON-ready dict (infinite errors as the string ``"inf"``)."""
        out = asdict(self)
        for key in ("max_abs_err", "max_rel_err"):
            if not math.isfinite(out[key]):
                out[key] = str(out[key])
        return out


def random_state(nv: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random state: ``q`` uniform in ±0.5 (rad or m), ``q̇`` uniform in ±1."""
    return rng.uniform(-0.5, 0.5, nv), rng.uniform(-1.0, 1.0, nv)


def random_wrench(scene: Scene, rng: np.random.Generator) -> Wrench:
    """A random load for the cross-check (:class:`rt70.physics.loads.Wrench`).

    On a moving link drawn uniformly, at a point within ±1 m of its origin, with force
    and torque uniform in ±1 N and ±1 N·m per ground axis.
    """
    links = [name for name, (body, _, _) in scene.textbook.link_frames.items() if body >= 0]
    link = links[int(rng.integers(len(links)))]
    xyz, force, torque = rng.uniform(-1.0, 1.0, (3, 3))
    return Wrench(link, xyz, force, torque)


def state_wrench(scene: Scene, q: np.ndarray) -> Wrench:
    """The random load compared at the state q (row ``load_force``).

    :func:`random_wrench` drawn from a generator seeded with the bits of q: reproducible,
    new at every sampled state, and apart from the stream the states are drawn from.
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    return random_wrench(scene, np.random.default_rng(bits))


def state_drive(scene: Scene, q: np.ndarray) -> Drive:
    """A random gear-sector drive compared at the state q (row ``drives``).

    Seeded from q as :func:`state_wrench`: the sector on a moving link drawn uniformly,
    its stator another link with a frame (the ground too), mesh point within ±1 m,
    random unit tangent and an axis normal to it, radius in [0.5, 2] m. Only its
    geometry is used (the motor's parameters are ones), so every scene has a drive to
    compare.
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    rng = np.random.default_rng(bits[::-1].copy())
    frames = scene.textbook.link_frames
    moving = [name for name, (body, _, _) in frames.items() if body >= 0]
    link = moving[int(rng.integers(len(moving)))]
    others = [name for name, (body, _, _) in frames.items() if body != frames[link][0]]
    stator = others[int(rng.integers(len(others)))] if others else scene.description.root
    xyz, direction, axis = rng.uniform(-1.0, 1.0, (3, 3))
    direction /= np.linalg.norm(direction)
    axis -= (axis @ direction) * direction
    axis /= np.linalg.norm(axis)
    sector = DriveSector(link, xyz, direction, axis, float(rng.uniform(0.5, 2.0)), stator)
    return Drive("probe", "", *np.ones(len(DRIVE_PARAMETERS)), sector=sector)


def state_wind(q: np.ndarray) -> WindCondition:
    """The steady wind compared at the state q (row ``wind``).

    Seeded from q as :func:`state_wrench` (the bits in another order): speed uniform in
    [1, 40] m/s, direction uniform in [0°, 360°), the scene's air density.
    """
    bits = np.frombuffer(np.ascontiguousarray(q, dtype=float).tobytes(), dtype=np.uint32)
    rng = np.random.default_rng(np.roll(bits, 1))
    return WindCondition(float(rng.uniform(1.0, 40.0)), float(rng.uniform(0.0, 360.0)))


def compared_points(scene: Scene) -> list[Output]:
    """The positions compared in row ``points``.

    The scene's optical points (its outputs, :func:`rt70.model.outputs.optical_point_outputs`)
    and the origin of every link with a frame on both sides (``link:<name>``), so that
    every scene has points to compare.
    """
    links = scene.textbook.link_frames
    origins = [position_output(f"link:{link}", link, np.zeros(3)) for link in links]
    return optical_point_outputs(scene) + origins


def _stacked(values: dict[str, np.ndarray]) -> np.ndarray:
    return np.concatenate(list(values.values())) if values else np.zeros(0)


#: Wall time the repeated calls of one timed evaluation may take: a call slower than this
#: is timed by its value call alone (:func:`_timed`), so a model whose evaluations take
#: seconds (20 000 bushings) is not evaluated ``repeat`` more times for its timing.
REPEAT_BUDGET_S = 0.1


def _timed(fn: Callable[[], object], repeat: int) -> tuple[object, float]:
    """Value of ``fn()`` and its mean wall time over up to ``repeat`` calls after one warm-up.

    The repeats are as many as fit in :data:`REPEAT_BUDGET_S` at the warm-up call's pace
    (at most ``repeat``); none when that call alone took longer, and then its own time
    is the one reported. With ``repeat = 0`` only the value is computed and the time is
    reported as 0. Only the timing depends on the machine's pace: the value is always
    the first call's.
    """
    start = time.perf_counter()
    out = fn()
    first = time.perf_counter() - start
    if repeat < 1:
        return out, 0.0
    repeats = min(repeat, int(REPEAT_BUDGET_S / first)) if first > 0.0 else repeat
    if repeats < 1:
        return out, first
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return out, (time.perf_counter() - start) / repeats


def _pairs(scene: Scene, q: np.ndarray, qd: np.ndarray) -> dict[str, tuple[Callable, Callable]]:
    """Per quantity: (textbook evaluation, reference evaluation), in the user's coordinate order.

    The load of ``load_force`` is :func:`state_wrench`.
    """
    from rt70 import reference
    from rt70.reference import drives as ref_drives
    from rt70.reference import points as ref_points
    from rt70.reference import wind as ref_wind
    from rt70.textbook import wind as tb_wind

    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    wrench = state_wrench(scene, q)
    located = compared_points(scene)
    compared_drives = [*scene.description.drives, state_drive(scene, q)]

    def tb_forward():
        Qc, Qd = forces.spring_damper_force(tm, td, q, qd)
        return dynamics.forward_dynamics(tm, td, q, qd, Qc + Qd)

    pairs = {
        "mass_matrix": (
            lambda: dynamics.mass_matrix(tm, td, q),
            lambda: reference.mass_matrix(ref, rd, q),
        ),
        "bias": (
            lambda: dynamics.bias_force(tm, td, q, qd),
            lambda: reference.bias_force(ref, rd, q, qd),
        ),
        "gravity": (
            lambda: dynamics.gravity_force(tm, td, q),
            lambda: reference.gravity_force(ref, rd, q),
        ),
        "spring_force": (
            lambda: forces.spring_damper_force(tm, td, q, qd)[0],
            lambda: reference.spring_damper_force(ref, rd, q, qd)[0],
        ),
        "damper_force": (
            lambda: forces.spring_damper_force(tm, td, q, qd)[1],
            lambda: reference.spring_damper_force(ref, rd, q, qd)[1],
        ),
        "forward_dynamics": (tb_forward, lambda: reference.forward_dynamics(ref, rd, q, qd)),
        "kinetic_energy": (
            lambda: forces.kinetic_energy(tm, td, q, qd),
            lambda: reference.kinetic_energy(ref, rd, q, qd),
        ),
        "potential_energy": (
            lambda: forces.gravity_potential(tm, td, q) + forces.spring_potential(tm, td, q),
            lambda: (
                reference.gravity_potential(ref, rd, q) + reference.spring_potential(ref, rd, q)
            ),
        ),
        "points": (
            lambda: _stacked(evaluate(scene, q, located, "textbook")),
            lambda: _stacked(evaluate(scene, q, located, "reference")),
        ),
        "load_force": (
            lambda: points.generalized_force(tm, td, q, wrench),
            lambda: ref_points.generalized_force(ref, rd, q, wrench),
        ),
        # θ_d and Q at unit reducer torque (4.143), (4.150): the scene's drives and a probe
        "drives": (
            lambda: _stacked_drives(tb_drives.drive_force, tm, td, q, compared_drives),
            lambda: _stacked_drives(ref_drives.drive_force, ref, rd, q, compared_drives),
        ),
        # joint reaction wrenches, source 004 (9)–(13) (rt70.crosscheck.reaction_check)
        "reactions": reaction_pair(scene, q, qd, wrench),
    }
    pairs.update(impact_pairs(scene, q, qd))  # a random brake and stow pin (15)
    if scene.description.winds:  # Q_w = S W and Jᵀ f (4.132)–(4.136), a random wind
        wind = state_wind(q)
        pairs[WIND] = (
            lambda: tb_wind.wind_force(tm, td, q, wind),
            lambda: ref_wind.wind_force(ref, rd, q, wind),
        )
    pairs.update(loop_pairs(scene, q, qd))  # rt70.crosscheck.loop_check: Φ, B_c, C, (14) with (2.2)
    if scene.description.no_slips:  # A(q), Ȧq̇; reduced q̈ and reactions (source 002)
        pairs.update(nonholonomic_pairs(scene, q, qd))
    return pairs


def _stacked_drives(drive_force: Callable, model, data, q: np.ndarray, drives) -> np.ndarray:
    """One side's ``[θ_d, Q]`` at unit torque of every drive, stacked."""
    return np.concatenate([np.hstack(drive_force(model, data, q, d)) for d in drives])


#: Every value is measured against at least this fraction of its natural scale: with the
#: default tolerance 10⁻¹⁰ an error passes against the floor only below 10⁻¹⁴ of the
#: scale, about 45 ε — the rounding bound γ_n ≈ n ε of a sum of a few tens of rounded
#: terms (Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1).
FLOOR = 1e-4

#: Mass matrices whose condition number passes this leave q̈ undetermined in doubles.
MAX_CONDITION = 1e14


def natural_scales(scene: Scene, values: dict, q: np.ndarray, qd: np.ndarray) -> dict:
    """The size of the terms each compared quantity is computed from, at this state.

    A quantity that nearly cancels (the velocity-product force of joints that barely
    couple, the gravity torque of a wheel whose centre of mass is on its axis, the
    accelerations of a balanced robot) carries the rounding error of its terms, about
    ε times their size, so its error relative to its own tiny value means nothing. Each
    quantity is therefore measured against ``max(own max-norm, FLOOR · scale)``; with a
    tolerance of 10⁻¹⁰ any error above 10⁻¹⁴ of the scale (about 45 ε, see
    :data:`FLOOR`) — anything beyond rounding — still fails. Each scale is the size of
    that quantity's own terms (max-norms, Pinocchio's values), so a huge spring force
    does not excuse an error of gravity:

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
    - points (:func:`compared_points`): the largest distance of a compared point from
      the ground origin (a position is a sum of the bodies' offsets);
    - load force (the wrench ``f = [F; M]`` of :func:`state_wrench`):
      ``‖|J_v|ᵀ|F| + |J_ω|ᵀ|M|‖``, the terms of ``Jᵀ f`` before they cancel;
    - drives (``[θ_d, Q]`` of the scene's drives and :func:`state_drive`), per entry: the
      positions θ_d is computed from over the mesh radius, and the mesh forces' terms
      ``|J_v|ᵀ|F|`` (:func:`_drive_scale`);
    - impact, impulse (q̇⁺ and Λ of a random brake and stow pin): their first-order
      rounding bounds, entry by entry (:func:`rt70.crosscheck.impact_check.impact_scales`);
    - the loop rows of a scene with ``<rt70:loop>``: :func:`rt70.crosscheck.loop_check.loop_scales`.

    Raises
    ------
    Rt70Error
        If Pinocchio's mass matrix at this state is numerically singular: its
        Jacobi-scaled form ``D^-½ A D^-½`` (D = diag A, which removes mere differences
        of scale, van der Sluis) has a condition number above :data:`MAX_CONDITION`
        or a non-positive eigenvalue — q̈ is then not determined in double precision.
    """

    def norm(name: str) -> float:
        x = values[name][1]
        return float(np.max(np.abs(x))) if x.size else 0.0

    A = values["mass_matrix"][1]
    d = np.sqrt(np.abs(np.diag(A)))
    with np.errstate(divide="ignore", invalid="ignore"):
        eig = np.linalg.eigvalsh(A / np.outer(d, d)) if A.size else np.ones(1)
    if not (np.all(d > 0.0) and eig[0] > 0.0 and eig[-1] <= MAX_CONDITION * eig[0]):
        raise Rt70Error(
            f"{scene.path}: the mass matrix is singular at a sampled state (scaled "
            f"eigenvalues {eig[0]:.3g} … {eig[-1]:.3g}): the forward dynamics is not "
            "determined"
        )
    from rt70 import reference

    ref, rd = scene.reference, scene.reference_data
    speed2 = float(np.max(np.abs(qd), initial=0.0)) ** 2
    g0 = reference.weight_moment(ref, rd, q)
    Sc, Sd = reference.spring_damper_magnitudes(ref, rd, q, qd)
    Q_b, Q_g = np.abs(values["bias"][1]), np.abs(values["gravity"][1])
    f = np.abs(A).sum(axis=1) * speed2 + Q_b + g0 + Q_g + Sc + Sd
    qdd = np.abs(values["forward_dynamics"][1])
    qdd_scale = np.abs(np.linalg.inv(A)) @ (f + np.abs(A) @ qdd)
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
    }


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


def _relative_error(x_tb: np.ndarray, x_ref: np.ndarray, floor) -> float:
    """``max_i |x_tb − x_ref|_i / max(‖x_ref‖, floor_i)`` (floor scalar or per entry)."""
    if not x_ref.size:
        return 0.0
    err = np.abs(x_tb - x_ref).ravel()
    scale = np.maximum(float(np.max(np.abs(x_ref))), np.broadcast_to(floor, err.shape))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(err == 0.0, 0.0, err / scale)
    return float(np.max(ratio))


def _nonfinite(x: np.ndarray) -> bool:
    return bool(x.size) and not bool(np.all(np.isfinite(x)))


def cross_check(scene: Scene, samples: int = 10, seed: int = 0, repeat: int = 3) -> list[Record]:
    """Compare every quantity of :func:`quantities` (scene's rows) on ``samples`` random states.

    The relative error is the max-norm of the difference over the larger of the
    max-norm of Pinocchio's value and ``FLOOR`` times the quantity's natural scale at
    the state (:func:`natural_scales`). A NaN or infinite value on either side makes
    the row's errors infinite and names the side in :attr:`Record.nonfinite`: such a
    row never passes. Each evaluation is timed as the mean of ``repeat`` calls after a
    warm-up call (fewer when they would take longer than :data:`REPEAT_BUDGET_S`:
    :func:`_timed`).

    Raises
    ------
    Rt70Error
        If the scene has no degree of freedom, ``samples`` < 1, or the mass matrix is
        numerically singular at a sampled state.
    LoopClosureError
        If the scene's loops cannot close (:func:`rt70.simulation.closure.require_closable`),
        before anything is compared.
    """
    require_coordinates(scene)
    if samples < 1:
        raise Rt70Error(f"samples must be at least 1, got {samples}")
    require_closable(scene)  # loops that cannot close: a model error, not a disagreement
    rng = np.random.default_rng(seed)
    nv = scene.textbook.nv
    rows = quantities(scene)
    abs_err = dict.fromkeys(rows, 0.0)
    rel_err = dict.fromkeys(rows, 0.0)
    t_tb = dict.fromkeys(rows, 0.0)
    t_ref = dict.fromkeys(rows, 0.0)
    bad: dict[str, set[str]] = {name: set() for name in rows}
    for _ in range(samples):
        q, qd = random_state(nv, rng)
        values = {}
        for name, (tb_fn, ref_fn) in _pairs(scene, q, qd).items():
            x_tb, dt_tb = _timed(tb_fn, repeat)
            x_ref, dt_ref = _timed(ref_fn, repeat)
            values[name] = np.asarray(x_tb, dtype=float), np.asarray(x_ref, dtype=float)
            t_tb[name] += dt_tb / samples
            t_ref[name] += dt_ref / samples
            for side, x in zip(("textbook", "pinocchio"), values[name], strict=True):
                if _nonfinite(x):
                    bad[name].add(side)
        if any(bad[name] for name in rows):  # no scale from non-finite values
            scales = dict.fromkeys(rows, 0.0)
        else:
            scales = natural_scales(scene, values, q, qd)
        for name, (x_tb, x_ref) in values.items():
            if bad[name]:
                abs_err[name] = rel_err[name] = math.inf
                continue
            err = float(np.max(np.abs(x_tb - x_ref))) if x_ref.size else 0.0
            abs_err[name] = max(abs_err[name], err)
            rel = _relative_error(x_tb, x_ref, FLOOR * np.asarray(scales[name]))
            rel_err[name] = max(rel_err[name], rel)
    return [
        Record(
            scene.name,
            nv,
            name,
            abs_err[name],
            rel_err[name],
            t_tb[name],
            t_ref[name],
            " and ".join(sorted(bad[name])),
        )
        for name in rows
    ]


def format_table(records: Iterable[Record], tolerance: float = DEFAULT_TOLERANCE) -> str:
    """The error-against-run-time table as plain text."""
    header = (
        f"{'target':<26} {'nv':>4} {'quantity':<17} {'max abs err':>11} {'max rel err':>11} "
        f"{'textbook µs':>12} {'pinocchio µs':>12} {'ratio':>7}  ok"
    )
    lines = [header, "-" * len(header)]
    for r in records:
        ratio = r.t_textbook_s / r.t_reference_s if r.t_reference_s > 0 else float("inf")
        lines.append(
            f"{r.target:<26} {r.nv:>4} {r.quantity:<17} {r.max_abs_err:>11.2e} "
            f"{r.max_rel_err:>11.2e} {r.t_textbook_s * 1e6:>12.1f} {r.t_reference_s * 1e6:>12.1f} "
            f"{ratio:>7.1f}  {'yes' if r.passed(tolerance) else 'NO'}"
            + (f"  (NaN/inf on the {r.nonfinite} side)" if r.nonfinite else "")
        )
    return "\n".join(lines)
