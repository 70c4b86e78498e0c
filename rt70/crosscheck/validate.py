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

The states and the probes compared at each: :mod:`rt70.crosscheck.samples`; the scale
each row's error is measured against: :mod:`rt70.crosscheck.scales`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass

import numpy as np

from rt70.crosscheck.compiled_check import UNITS as COMPILED_UNITS
from rt70.crosscheck.compiled_check import compiled_pairs, compiled_quantities
from rt70.crosscheck.impact_check import impact_pairs
from rt70.crosscheck.loop_check import loop_pairs, loop_quantities
from rt70.crosscheck.reaction_check import reaction_pair
from rt70.crosscheck.samples import (
    WIND,
    compared_points,
    random_state,
    state_drive,
    state_wind,
    state_wrench,
)
from rt70.crosscheck.scales import natural_scales
from rt70.errors import Rt70Error
from rt70.mechanics.nonholonomic_scene import ROWS as NONHOLONOMIC
from rt70.mechanics.nonholonomic_scene import validate_pairs as nonholonomic_pairs
from rt70.model.outputs import evaluate
from rt70.model.scene import Scene, require_coordinates
from rt70.simulation.closure import require_closable
from rt70.textbook import drives as tb_drives
from rt70.textbook import dynamics, forces, points

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


#: The unit of each row's values and ``max_abs_err`` (``max_rel_err`` is a pure number,
#: the times are seconds). "Per coordinate" rows mix the units of the coordinates' kinds:
#: revolute (rad) and prismatic (m) coordinates give N·m and N, rad/s² and m/s², …
QUANTITY_UNITS = {
    "mass_matrix": "kg·m², kg·m or kg (per pair of coordinates)",
    "bias": "N·m or N (per coordinate)",
    "gravity": "N·m or N (per coordinate)",
    "spring_force": "N·m or N (per coordinate)",
    "damper_force": "N·m or N (per coordinate)",
    "forward_dynamics": "rad/s² or m/s² (per coordinate)",
    "kinetic_energy": "J",
    "potential_energy": "J",
    "points": "m",
    "load_force": "N·m or N (per coordinate)",
    "drives": "rad (drive angles), then N·m or N per N·m of reducer torque (per coordinate)",
    "reactions": "N (forces) and N·m (moments)",
    "impact": "rad/s or m/s (velocities after the impacts, per coordinate)",
    "impulse": "N·s or N·m·s",
    WIND: "N·m or N (per coordinate)",
    "loop_residual": "m and rad",
    "loop_jacobian": "1 or m per coordinate",
    "loop_bias": "m/s² and rad/s²",
    "loop_dynamics": "rad/s² or m/s² (per coordinate)",
    "loop_reaction": "N·m or N (per coordinate)",
    "no_slip": "1 or m per coordinate (A), then m/s² or rad/s² (Ȧq̇)",
    "reduced_dynamics": "rad/s² or m/s² (per coordinate), then N or N·m (multipliers)",
    **COMPILED_UNITS,
}


def quantities(scene: Scene) -> tuple[str, ...]:
    """The rows of ``scene``'s report.

    :data:`QUANTITIES`, :data:`rt70.crosscheck.samples.WIND` if it has wind,
    :data:`rt70.crosscheck.compiled_check.ROWS` if the compiled kernels cover it, the loop
    rows (:func:`rt70.crosscheck.loop_check.loop_quantities`) if it has ``<rt70:loop>``
    closures, and :data:`rt70.mechanics.nonholonomic_scene.ROWS` if it has
    ``<rt70:no_slip>`` constraints.
    """
    rows = QUANTITIES + ((WIND,) if scene.description.winds else ()) + compiled_quantities(scene)
    return rows + loop_quantities(scene) + (NONHOLONOMIC if scene.description.no_slips else ())


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
        """The record as a JSON-ready dict, with the unit of its values.

        Infinite errors are the string ``"inf"``; ``unit`` is from :data:`QUANTITY_UNITS`.
        """
        out = asdict(self)
        out["unit"] = QUANTITY_UNITS[self.quantity]
        for key in ("max_abs_err", "max_rel_err"):
            if not math.isfinite(out[key]):
                out[key] = str(out[key])
        return out


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

    The load of ``load_force`` is :func:`rt70.crosscheck.samples.state_wrench`.
    """
    from rt70 import reference
    from rt70.reference import drives as ref_drives
    from rt70.reference import points as ref_points

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
            lambda: dynamics.kinetic_energy(tm, td, q, qd),
            lambda: reference.kinetic_energy(ref, rd, q, qd),
        ),
        "potential_energy": (
            lambda: dynamics.gravity_potential(tm, td, q) + forces.spring_potential(tm, td, q),
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
    pairs |= impact_pairs(scene, q, qd)  # a random brake and stow pin (15)
    pairs |= _wind_pairs(scene, q)
    pairs |= compiled_pairs(scene, q, qd)  # the large-model path's kernels
    pairs |= loop_pairs(scene, q, qd)  # rt70.crosscheck.loop_check: Φ, B_c, C, (14) with (2.2)
    if scene.description.no_slips:  # A(q), Ȧq̇; reduced q̈ and reactions (source 002)
        pairs.update(nonholonomic_pairs(scene, q, qd))
    return pairs


def _wind_pairs(scene: Scene, q: np.ndarray) -> dict[str, tuple[Callable, Callable]]:
    """``Q_w = S W`` and ``Jᵀ f`` (4.132)–(4.136) of a random wind, if the scene has wind."""
    if not scene.description.winds:
        return {}
    from rt70.reference import wind as ref_wind
    from rt70.textbook import wind as tb_wind

    tm, td, ref, rd = scene.textbook, scene.textbook_data, scene.reference, scene.reference_data
    wind = state_wind(q)
    return {
        WIND: (
            lambda: tb_wind.wind_force(tm, td, q, wind),
            lambda: ref_wind.wind_force(ref, rd, q, wind),
        )
    }


def _stacked_drives(drive_force: Callable, model, data, q: np.ndarray, drives) -> np.ndarray:
    """One side's ``[θ_d, Q]`` at unit torque of every drive, stacked."""
    return np.concatenate([np.hstack(drive_force(model, data, q, d)) for d in drives])


#: Every value is measured against at least this fraction of its natural scale: with the
#: default tolerance 10⁻¹⁰ an error passes against the floor only below 10⁻¹⁴ of the
#: scale, about 45 ε — the rounding bound γ_n ≈ n ε of a sum of a few tens of rounded
#: terms (Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1).
FLOOR = 1e-4


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
    the state (:func:`rt70.crosscheck.scales.natural_scales`). A NaN or infinite value
    on either side makes the row's errors infinite and names the side in
    :attr:`Record.nonfinite`: such a row never passes.

    Parameters
    ----------
    scene : Scene
        The scene compared, both sides built from its one file.
    samples : int
        Random states (:func:`rt70.crosscheck.samples.random_state`), at least 1.
    seed : int
        Seed of the states' generator.
    repeat : int
        Timed calls of each evaluation after a warm-up call, averaged (fewer when they
        would take longer than :data:`REPEAT_BUDGET_S`: :func:`_timed`; 0: not timed).

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
    tally = _Tally(quantities(scene))
    for _ in range(samples):
        q, qd = random_state(scene.textbook.nv, rng)
        values = tally.evaluate(_pairs(scene, q, qd), repeat, samples)
        if tally.any_nonfinite():  # no scale from non-finite values
            scales = dict.fromkeys(tally.rows, 0.0)
        else:
            scales = natural_scales(scene, values, q, qd)
        tally.compare(values, scales)
    return tally.records(scene.name, scene.textbook.nv)


class _Tally:
    """Per row of the report: the largest errors so far, the mean times, the bad sides."""

    def __init__(self, rows: tuple[str, ...]) -> None:
        self.rows = rows
        self.abs_err = dict.fromkeys(rows, 0.0)
        self.rel_err = dict.fromkeys(rows, 0.0)
        self.t_tb = dict.fromkeys(rows, 0.0)
        self.t_ref = dict.fromkeys(rows, 0.0)
        self.bad: dict[str, set[str]] = {name: set() for name in rows}

    def evaluate(
        self, pairs: dict[str, tuple[Callable, Callable]], repeat: int, samples: int
    ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Both sides' values of every row at one state, timed (:func:`_timed`)."""
        values = {}
        for name, (tb_fn, ref_fn) in pairs.items():
            x_tb, dt_tb = _timed(tb_fn, repeat)
            x_ref, dt_ref = _timed(ref_fn, repeat)
            values[name] = np.asarray(x_tb, dtype=float), np.asarray(x_ref, dtype=float)
            self.t_tb[name] += dt_tb / samples
            self.t_ref[name] += dt_ref / samples
            for side, x in zip(("textbook", "reference"), values[name], strict=True):
                if _nonfinite(x):
                    self.bad[name].add(side)
        return values

    def any_nonfinite(self) -> bool:
        """Whether some row was NaN or infinite on some side, at any state so far."""
        return any(self.bad[name] for name in self.rows)

    def compare(self, values: dict[str, tuple[np.ndarray, np.ndarray]], scales: dict) -> None:
        """Fold one state's errors in: absolute, and relative to ``FLOOR ·`` the scales."""
        for name, (x_tb, x_ref) in values.items():
            if self.bad[name]:
                self.abs_err[name] = self.rel_err[name] = math.inf
                continue
            err = float(np.max(np.abs(x_tb - x_ref))) if x_ref.size else 0.0
            self.abs_err[name] = max(self.abs_err[name], err)
            rel = _relative_error(x_tb, x_ref, FLOOR * np.asarray(scales[name]))
            self.rel_err[name] = max(self.rel_err[name], rel)

    def records(self, target: str, nv: int) -> list[Record]:
        """One :class:`Record` per row, in report order."""
        return [
            Record(
                target,
                nv,
                name,
                self.abs_err[name],
                self.rel_err[name],
                self.t_tb[name],
                self.t_ref[name],
                " and ".join(sorted(self.bad[name])),
            )
            for name in self.rows
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
